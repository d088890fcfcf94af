"""Re-derive a template's answers in the time domain, simulating only the effects its scene declares.

The stages run forward in order, each through its effect's own phase (gravity for flight, a
compliant contact for an impact, kinematics for a velocity). A template that gives a measured
outcome instead of an input (a rebound height instead of ``e``) is solved by root finding on
the simulation itself: ``e`` is adjusted until the simulated rebound matches, so no closed form
is used. Symbols without a value (a mass that cancels, the speed ``v``) are set to 1 in their
unit; only answers that do not depend on them are compared.

>>> from grader.bank import load_bank
>>> template = load_bank()["pile-driver"]
>>> result = simulate(template, {"m_ram": 800, "m_pile": 2400, "h_drop": 2, "h_rebound": 0.1})
>>> round(result.answers["e"], 4), result.effects
(0.6315, ('gravity', 'contact (Kelvin-Voigt)'))
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping
from dataclasses import dataclass, field

from scipy.optimize import brentq

from grader.bank import Template
from grader.effects import CATALOGUE
from grader.errors import GraderError
from grader.expr import Node, Sym, names
from grader.integrate import Path, Settings, SimulationError
from grader.kernel import evaluate
from grader.scene import Stage

DEFAULT_CONTACT_DURATION = 1e-3  # s: stiffness follows from it and the reduced mass


@dataclass(frozen=True)
class Options:
    """What to simulate with: integration settings, contact duration, and whether the weight acts
    during contact (the textbook, and every template by default, neglects it)."""

    settings: Settings = field(default_factory=Settings)
    contact_duration: float = DEFAULT_CONTACT_DURATION
    weight_during_contact: bool = False

    def __post_init__(self) -> None:
        if not (math.isfinite(self.contact_duration) and self.contact_duration > 0):
            raise SimulationError(f"the contact duration must be a positive number of seconds, "
                                  f"got {self.contact_duration!r}")


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

    template: Template
    options: Options
    values: dict[str, float]
    effects: list[str] = field(default_factory=list)
    phases: list[PhaseRecord] = field(default_factory=list)
    observed: dict[str, tuple[float, float]] = field(default_factory=dict)
    problems: list[str] = field(default_factory=list)
    contacts: list[ContactRecord] = field(default_factory=list)
    steps: int = 0

    def value(self, node: Node) -> float:
        """A stage field's value; every name in it must be known by now."""
        unknown = names(node) - set(self.values)
        if unknown:
            raise _UnknownQuantityError(sorted(unknown)[0])
        return float(evaluate(node, self.values))

    def known(self, node: Node) -> bool:
        """Whether every name of a field is known."""
        return names(node) <= set(self.values)

    def output(self, node: Node, value: float) -> None:
        """Give a simulated quantity: a new name is assigned; a known one is an observation."""
        if isinstance(node, Sym) and node.name not in self.values:
            self.values[node.name] = value
        elif self.known(node):
            self.observed[str(node)] = (value, self.value(node))
        else:
            raise SimulationError(f"{self.template.where}: cannot simulate: '{node}' is an expression of "
                                  "quantities nothing has produced yet")

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


class _UnknownQuantityError(Exception):
    """A field needs a quantity nothing has produced (a restitution to be found, or a mistake)."""

    def __init__(self, name: str) -> None:
        super().__init__(name)
        self.name = name


@dataclass(frozen=True)
class Simulation:
    """Simulated answers (template units) with what produced them."""

    template: str
    params: Mapping[str, float]
    answers: Mapping[str, float | None]
    effects: tuple[str, ...]
    steps: int
    seconds: float
    fitted: Mapping[str, float]
    nominal: Mapping[str, float]
    phases: tuple[PhaseRecord, ...]
    contacts: tuple[ContactRecord, ...] = ()


def simulate(template: Template, params: Mapping[str, float], options: Options | None = None) -> Simulation:
    """Simulate one parameter set (values in the template's units)."""
    options = options or Options()
    _check_force_laws(template)
    started = time.perf_counter()
    base = _si_values(template, params)
    try:
        run, fitted = _solve_for_unknowns(template, options, base)
    except SimulationError as error:
        raise SimulationError(f"{template.id}: {error}") from None
    # A found e is reported as the contact produced it (separation over approach), not as the
    # value the contact law was calibrated to: that is the time-domain answer.
    for contact in run.contacts:
        restitution = template.scene.stages[contact.stage].fields["restitution"]
        if isinstance(restitution, Sym) and restitution.name in fitted:
            run.values[restitution.name] = contact.measured_e
    if run.problems:
        raise SimulationError(f"{template.id}: {run.problems[0]}")
    answers = {name: _answer(run, name) for name, spec in template.answers.items() if not spec.symbolic}
    return Simulation(template.id, dict(params), answers, tuple(run.effects), run.steps,
                      time.perf_counter() - started, fitted, {n: 1.0 for n in template.symbols}, tuple(run.phases),
                      tuple(run.contacts))


def _check_force_laws(template: Template) -> None:
    for stage in template.scene.stages:
        if CATALOGUE[stage.effect].simulate is None:
            raise SimulationError(f"{template.where}: stages[{stage.index}]: the effect '{stage.effect}' has no "
                                  "force law, so this scene cannot be simulated")


def _si_values(template: Template, params: Mapping[str, float]) -> dict[str, float]:
    values: dict[str, float] = {}
    for name, parameter in template.parameters.items():
        value = float(params[name])
        if not (math.isfinite(value) and parameter.domain.contains(value)):
            raise GraderError(f"{name} = {value:g} is outside its domain {parameter.domain}")
        values[name] = value * parameter.unit.to_si
    values.update({name: 1.0 * spec.unit.to_si for name, spec in template.symbols.items()})
    if template.scene.gravity is not None:
        values["g"] = float(template.scene.gravity.si)
    return values


def _walk(template: Template, options: Options, values: dict[str, float]) -> Run:
    run = Run(template, options, dict(values))
    for stage in template.scene.stages:
        simulator = CATALOGUE[stage.effect].simulate
        assert simulator is not None  # checked by _check_force_laws
        simulator(stage, run)
    return run


def _solve_for_unknowns(template: Template, options: Options, base: dict[str, float]) -> tuple[Run, dict[str, float]]:
    """Walk the stages; a restitution nothing gives is found so the simulated observation matches."""
    try:
        return _walk(template, options, base), {}
    except _UnknownQuantityError as missing:
        name = missing.name
    stage = _restitution_stage(template, name)

    def mismatch(e: float) -> float:
        run = _walk(template, options, {**base, name: e})
        observed = list(run.observed.values())
        if len(observed) != 1:
            raise SimulationError(f"{template.where}: cannot simulate: finding {name} needs exactly one "
                                  f"measured outcome, the scene has {len(observed)}")
        simulated, given = observed[0]
        return simulated - given

    low, high = mismatch(0.0), mismatch(1.0)
    if low == 0:
        return _walk(template, options, {**base, name: 0.0}), {name: 0.0}
    if low * high > 0:
        raise SimulationError(f"{template.id}: no coefficient of restitution in [0, 1] reproduces the given "
                              f"outcome of stages[{stage.index}] (with e = 1 the simulated value is still "
                              f"{'below' if high < 0 else 'above'} it)")
    found = brentq(mismatch, 0.0, 1.0, xtol=1e-15, rtol=8.9e-16, maxiter=200)
    return _walk(template, options, {**base, name: found}), {name: found}


def _restitution_stage(template: Template, name: str) -> Stage:
    for stage in template.scene.stages:
        if stage.effect == "impact" and stage.fields["restitution"] == Sym(name):
            return stage
    raise SimulationError(f"{template.where}: cannot simulate: '{name}' is neither given nor produced by an "
                          "earlier stage")


def _answer(run: Run, name: str) -> float | None:
    spec = run.template.answers[name]
    try:
        value = run.value(spec.value)
    except _UnknownQuantityError as missing:
        raise SimulationError(f"{run.template.where}: answers.{name}: the simulation does not produce "
                              f"'{missing.name}'") from None
    return value / spec.unit.to_si if math.isfinite(value) else None

