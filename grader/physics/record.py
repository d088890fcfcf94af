"""What a simulation run writes as it walks a scene: its options, the known quantities, each
phase's path and each contact's record. Effects' force laws read and write it; the scene walker
(:mod:`grader.simulate.walker`) drives it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from grader.model.expr import Node, Op, Sym, names, to_text
from grader.model.kernel import evaluate
from grader.model.scene import Scene
from grader.physics.integrate import TIME_LIMIT, Budget, Mode, Path, Settings, SimulationError, integrate

RESOLUTION = 1e-8  # relative: below this share of a run's speeds, a simulated speed counts as zero
DEFAULT_CONTACT_DURATION = 1e-3  # s: stiffness follows from it and the reduced mass


@dataclass(frozen=True)
class Options:
    """What to simulate with: integration settings, contact duration, and whether the weight acts
    during contact (the textbook, and every template by default, neglects it)."""

    settings: Settings = field(default_factory=Settings)
    contact_duration: float = DEFAULT_CONTACT_DURATION
    weight_during_contact: bool = False
    time_limit: float = TIME_LIMIT  # s of wall time for one simulation, searches included

    def __post_init__(self) -> None:
        if not (math.isfinite(self.contact_duration) and self.contact_duration > 0):
            raise SimulationError(f"the contact duration must be a positive number of seconds, "
                                  f"got {self.contact_duration!r}")
        if not (math.isfinite(self.time_limit) and self.time_limit > 0):
            raise SimulationError(f"the time limit must be a positive number of seconds, got {self.time_limit!r}")


@dataclass(frozen=True)
class PhaseRecord:
    """One stage's simulated path, for plots: state names, times, states and force."""

    label: str
    names: tuple[str, ...]
    path: Path


@dataclass(frozen=True)
class ContactRecord:
    """One simulated contact: the e the law was calibrated to and the e it produced."""

    stage: int
    label: str
    e: float
    measured_e: float
    zeta: float
    duration: float


@dataclass
class Run:
    """The state of one pass through the stages: known quantities (SI), what was simulated."""

    scene: Scene
    options: Options
    values: dict[str, float]
    effects: list[str] = field(default_factory=list)
    phases: list[PhaseRecord] = field(default_factory=list)
    observed: dict[str, tuple[float, float]] = field(default_factory=dict)
    problems: list[str] = field(default_factory=list)
    contacts: list[ContactRecord] = field(default_factory=list)
    undefined: dict[str, str] = field(default_factory=dict)  # quantity -> why it has no value
    waiting: dict[int, str] = field(default_factory=dict)  # stage index -> a quantity it needs that nothing gave
    budget: Budget = field(default_factory=Budget)
    notes: list[str] = field(default_factory=list)  # what a force law tells the reader (a series' tail)
    steps: int = 0
    speed_scale: float = 0.0  # the largest speed an impact of this run involved (SI)

    def resolves(self, speed: float) -> bool:
        """Whether a simulated speed is told apart from zero: above ``RESOLUTION`` of the run's
        speeds, or ten times the relative error its contacts made in reproducing their e
        (a velocity that is 1e-10 of the approach speed is integration error, not motion).

        >>> from grader.model.scene import Scene
        >>> run = Run(Scene("x", {}, (), None), Options(), {}, speed_scale=5.0)
        >>> run.resolves(1e-3), run.resolves(1e-9)
        (True, False)
        """
        error = max((abs(c.measured_e - c.e) for c in self.contacts), default=0.0)
        return speed > self.speed_scale * max(RESOLUTION, 10 * error)

    def value(self, node: Node) -> float:
        """A stage field's value; every name in it must be known by now."""
        unknown = names(node) - set(self.values)
        if unknown:
            raise UnknownQuantityError(sorted(unknown)[0])
        return float(evaluate(node, self.values))

    def known(self, node: Node) -> bool:
        """Whether every name of a field is known."""
        return names(node) <= set(self.values)

    def output(self, node: Node, value: float) -> None:
        """Give a simulated quantity: a new name is assigned (``-v`` assigns ``v``); a known one is an
        observation."""
        if isinstance(node, Sym) and node.name not in self.values:
            self.values[node.name] = value
        elif (negated := _negated(node)) is not None and negated not in self.values:  # a name with its sign turned
            self.values[negated] = -value
        elif self.known(node):
            self.observed[to_text(node)] = (value, self.value(node))
        else:
            raise SimulationError(f"{self.scene.where}: cannot simulate: '{node}' is an expression of "
                                  "quantities nothing has produced yet")

    def integrate(self, modes: Sequence[Mode], y0: Any, settings: Settings | None = None) -> Path:
        """Integrate modes with this run's settings, spending from its budget."""
        return integrate(modes, y0, settings or self.options.settings, budget=self.budget)

    def gravity(self) -> float:
        """g in SI."""
        return self.values["g"]

    def uses(self, effect: str) -> None:
        """Record that a force law was simulated."""
        if effect not in self.effects:
            self.effects.append(effect)

    def record(self, label: str, state_names: tuple[str, ...], path: Path) -> None:
        """Keep a phase's path for plots and count its steps."""
        self.phases.append(PhaseRecord(label, state_names, path))
        self.steps += path.steps


def _negated(node: Node) -> str | None:
    """``v`` for the field ``-v``, else None."""
    if isinstance(node, Op) and node.op == "neg" and isinstance(node.args[0], Sym):
        return node.args[0].name
    return None


class UnknownQuantityError(Exception):
    """A field needs a quantity nothing has produced (a restitution to be found, or a mistake)."""

    def __init__(self, name: str) -> None:
        super().__init__(name)
        self.name = name
