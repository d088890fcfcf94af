"""One body becomes two: an explosion or a spring-loaded separation, from rest or in flight, and a gun's or a
cannon's recoil; the inverse of a perfectly plastic impact.

The parts A and B separate along n (from A toward B) at the relative velocity ``u = v_B - v_A``, given, or
from the energy released, ``E = 1/2 mu u**2`` with the reduced mass ``mu = 1/(w_A + w_B)`` (``w = 1/m``: the
kinetic energy of the relative motion; the centre of mass keeps its velocity), or from one part's motion.
Momentum with the relative velocity gives each part, in the mass-centre form the kernels use:
``v_A = V - w_A u/(w_A + w_B)``, ``v_B = V + w_B u/(w_A + w_B)``. Along t (in a plane) both parts keep the
whole's velocity.

Force law (simulation): a compressed spring between the parts (Hooke's law, equal and opposite forces on
them), its stiffness from the contact duration and the reduced mass and its compression storing the energy
released, from the whole moving as one until the located event where the spring is back at its natural length.

Mistakes: the energy shared in the mass ratio instead of its inverse (each part's speed relative to the centre
of mass ``sqrt(2 E/(m_A + m_B))``); the relative velocity taken as the second part's absolute velocity.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from grader.model.expr import Sym
from grader.model.quantities import ENERGY, SPEED
from grader.physics.effects.base import Condition, Effect, Field, Mistake, Relation, Stable, TwoBodyStage

if TYPE_CHECKING:
    from grader.model.scene import Stage
    from grader.physics.record import Run
    from grader.physics.symbolic import Context

_FIELDS = (
    Field("bodies", "bodies", doc="[A, B]: the two parts (both with a mass); n points from A toward B"),
    Field("whole", "vector", required=False, doc="{n: .., t: ..}: the whole's velocity before it separates",
          dimension=SPEED, default="at rest"),
    Field("after", "velocities", required=False, doc="per part: names for its velocity after (n, or {n:, t:})",
          dimension=SPEED, default="v_<part>_n_after (and v_<part>_t_after in a plane)"),
    Field("energy", "expr", required=False, doc="the energy released (the kinetic energy the parts gain)",
          dimension=ENERGY, default="not named: no step for it"),
    Field("relative", "expr", required=False, doc="the relative velocity of separation along n, v_B - v_A, >= 0",
          dimension=SPEED, default="u_rel"),
)


@dataclass(frozen=True)
class _Separation(TwoBodyStage):
    """One stage's quantities; a mistake is the same stage with one changed."""

    before: tuple[Any, Any]
    after: tuple[tuple[Any, Any], tuple[Any, Any]]
    relative: Any
    share: str = "inverse"  # the energy shared as it is ("inverse" mass ratio), or in the "mass" ratio
    absolute: bool = False  # the relative velocity taken as B's absolute velocity

    @classmethod
    def of(cls, stage: Stage, ctx: Context) -> _Separation:
        """The separation a stage describes."""
        import sympy as sp

        fields = stage.fields
        bodies, inverse = cls.pair(stage, ctx)
        whole = fields.get("whole")
        before = (ctx.sym(whole.n), ctx.sym(whole.t)) if whole is not None else (sp.Integer(0), sp.Integer(0))
        plane = before[1] != 0 or any(v.t is not None for v in fields.get("after", {}).values())

        def after(body: str, axis: str) -> Any:
            given = fields.get("after", {}).get(body)
            if given is not None and getattr(given, axis) is not None:
                return ctx.sym(getattr(given, axis))
            return ctx.symbol(ctx.unused_name(f"v_{body}_{axis}_after", stage)) if axis == "n" or plane else None

        relative = ctx.sym(fields["relative"]) if "relative" in fields else ctx.symbol(ctx.unused_name("u_rel", stage))
        parts = tuple((after(body, "n"), after(body, "t")) for body in bodies)
        return cls(stage, bodies, inverse, before, parts, relative)  # type: ignore[arg-type]

    def relations(self, ctx: Context) -> list[Relation]:
        """The stage's relations as a student writes them."""
        relations = []
        if "energy" in self.stage.fields:
            relations.append(self._energy(ctx.sym(self.stage.fields["energy"])))
        relations += [self._part(0, ctx), self._part(1, ctx)]
        for index, (_, t) in enumerate(self.after):
            if t is not None:
                relations.append(Relation(f"along t {self.bodies[index]} keeps the whole's velocity", t, self.before[1],
                                          solutions={t: self.before[1]} if _is_symbol(t) else {}, general=False))
        return relations

    def _energy(self, energy: Any) -> Relation:
        import sympy as sp

        (w_a, w_b), u = self.inverse, self.relative
        solutions: dict[Any, Any] = {}
        if _is_symbol(u):
            solutions[u] = sp.sqrt(2 * energy * (w_a + w_b))
        if _is_symbol(energy):
            solutions[energy] = u**2 / (2 * (w_a + w_b))
        return Relation("energy released: the kinetic energy of the parts' relative motion, ½ μ u² with μ the "
                        "reduced mass, the product of the two masses over their sum", energy, u**2 / (2 * (w_a + w_b)),
                        solutions=solutions, general=False,
                        requires=(Condition(sp.Ge(energy, 0), f"the energy released {self.stage.text('energy')} "
                                            "must not be negative"),
                                  Condition(sp.Ge(u, 0), "the relative velocity of separation must not be negative: "
                                            "B moves off along n from A")))

    def _part(self, index: int, ctx: Context) -> Relation:
        """A part's velocity along n from momentum and the relative velocity (or as a mistake writes it)."""
        import sympy as sp

        (w_a, w_b), u, whole = self.inverse, self.relative, self.before[0]
        v = self.after[index][0]
        body = self.bodies[index]
        if self.share == "mass":
            energy = ctx.sym(self.stage.fields["energy"])
            offset = sp.sqrt(2 * energy / (1 / w_a + 1 / w_b)) * (1 if index else -1)
            form = whole + offset
            label = f"{body}'s share of the energy released: ½ m (v − V)² = E m/(m_A + m_B)"
        elif self.absolute and index == 1:
            form, label = u, f"{body} leaves at the relative velocity, taken as its own"
        elif self.absolute:
            form = whole * (1 + w_a / w_b) - u * w_a / w_b
            label = f"conservation of momentum: {body}'s velocity after"
        else:
            w = (w_a, w_b)[index]
            form = whole + (1 if index else -1) * w * u / (w_a + w_b)
            label = (f"conservation of momentum with the parts separating at the relative velocity "
                     f"{self.stage.text('relative') or 'u'}: {body}'s velocity after")
        solutions: dict[Any, Any] = {}
        stable: dict[Any, Any] = {}
        if _is_symbol(v):
            solutions[v] = form
            if not self.absolute and self.share != "mass":  # no (m_A + m_B) V to overflow or cancel
                own, other = (w_a, w_b) if index == 0 else (w_b, w_a)
                stable[v] = (Stable(whole + (1 if index else -1) * u / (1 + other / own)),)
        if not self.absolute and self.share != "mass":
            w, sign = (w_a, w_b)[index], (1 if index else -1)
            if _is_symbol(whole):
                solutions[whole] = v - sign * w * u / (w_a + w_b)
            if _is_symbol(u):
                solutions[u] = sign * (v - whole) * (w_a + w_b) / w
        return Relation(label, v, form, solutions=solutions, stable=stable, general=False)


def _is_symbol(expr: Any) -> bool:
    import sympy as sp

    return isinstance(expr, sp.Symbol)


def _separation(stage: Stage, ctx: Context) -> list[Relation]:
    return _Separation.of(stage, ctx).relations(ctx)


def _mistakes(stage: Stage, ctx: Context) -> list[Mistake]:
    real = _Separation.of(stage, ctx)
    found = []
    if "energy" in stage.fields:
        found.append(Mistake("separation.mass_ratio", "the energy shared in the ratio of the masses instead of its "
                             "inverse", tuple(replace(real, share="mass").relations(ctx))))
    if "relative" in stage.fields:
        found.append(Mistake("separation.relative_as_absolute", "the relative velocity taken as the second part's "
                             "absolute velocity", tuple(replace(real, absolute=True).relations(ctx))))
    return found


def _simulate_separation(stage: Stage, run: Run) -> None:
    """A compressed spring between the parts, released: equal and opposite forces, until it is slack."""
    from grader.physics.integrate import Mode  # the simulator's part: loading a template needs none of it

    fields = stage.fields
    first, second = fields["bodies"]
    w_a, w_b = (1.0 / run.value(run.scene.bodies[body].mass) for body in (first, second))  # type: ignore[arg-type]
    whole = fields.get("whole")
    v_n, v_t = (run.value(whole.n), run.value(whole.t)) if whole is not None else (0.0, 0.0)
    reduced = 1 / (w_a + w_b)
    # What sets the relative velocity is an input: giving it back would only check the run against itself.
    if "relative" in fields and run.known(fields["relative"]):
        u, source = run.value(fields["relative"]), "relative"
    else:
        u = math.sqrt(2 * run.value(fields["energy"]) / reduced) if "energy" in fields else \
            run.value(Sym("u_rel"))  # neither given: the stage waits (nothing produces u_rel)
        source = "energy"
    if u < 0:
        run.problems.append(f"the relative velocity of separation {u:g} m/s is negative")
        u = 0.0
    after = [v_n, v_n]
    if u > 0:
        run.uses("spring between the parts (Hooke's law)")
        omega = math.pi / (2 * run.options.contact_duration)  # released over the contact duration
        stretch = u / omega  # 1/2 k x0^2 = 1/2 mu u^2 with k = mu omega^2

        def pushed(_: float, y: Any) -> Any:
            force = omega * omega * reduced * (stretch - (y[1] - y[0]))  # the spring's push, per its compression
            return np.array([y[2], y[3], -w_a * force, w_b * force])

        speed = max(abs(v_n), u)
        sizes = np.array([stretch, stretch, speed, speed])
        release = Mode("separation", pushed, lambda y: y[1] - y[0] - stretch, 1, scale=1 / omega, omega=omega,
                       sizes=lambda y: sizes)
        path = run.integrate([release], np.array([0.0, 0.0, v_n, v_n]))
        run.record(f"{first} and {second} separate", ("xA", "xB", "vA", "vB"), path)
        after = [float(v) for v in path.y[-1][2:]]
    _output(stage, run, (w_a, w_b), after, v_t, source)


def _output(stage: Stage, run: Run, inverse: tuple[float, float], after: list[float], v_t: float,
            source: str) -> None:
    fields = stage.fields
    for index, body in enumerate(fields["bodies"]):
        given = fields.get("after", {}).get(body)
        if given is not None:
            run.output(given.n, after[index])
            if given.t is not None:
                run.output(given.t, v_t)
    separating = after[1] - after[0]
    if "relative" in fields and source != "relative":
        run.output(fields["relative"], separating)
    if "energy" in fields and source != "energy":
        run.output(fields["energy"], separating * separating / (2 * (inverse[0] + inverse[1])))


SEPARATION = Effect(
    "separation",
    "one body becomes two (an explosion, a spring-loaded separation, a recoil): momentum kept, the parts separate "
    "at u = v_B - v_A, with E = 1/2 mu u^2",
    _FIELDS,
    _separation,
    _simulate_separation,
    _mistakes,
    force_law="a compressed spring between the parts (Hooke's law, equal and opposite forces), its stiffness from the "
              "contact duration and the reduced mass, its compression storing the energy released, until the located "
              "event where it is slack",
)
