"""Two bodies moving in a plane collide and move on as one (cars that lock together at an intersection):
the common velocity, its speed and direction, and the energy lost; and the inverse questions an accident
reconstruction asks (one car's speed before, from the direction the wreck moved off in).

Axes: n and t are any two perpendicular axes of the plane (east and north); a body's velocity before is
``{n: .., t: ..}``. Momentum is conserved along each: ``m1 u1 + m2 u2 = (m1 + m2) v`` as vectors. The common
velocity's direction is measured from the n-axis toward t (or from t, ``from: t``).

The kernels take the common velocity in the mass-centre form ``(w2 u1 + w1 u2)/(w1 + w2)`` with ``w = 1/m``
(exact for mass ratios of 1e12), its speed with ``hypot`` and its direction with ``atan2``; the energy lost
is ``1/2 mu |u1 - u2|**2`` with the reduced mass ``mu = 1/(w1 + w2)``, the relative velocity's magnitude from
``hypot``: never ``T - T'``, which cancels when the bodies were already moving nearly together.

Force law (simulation): a perfectly plastic contact (Kelvin-Voigt, e = 0) along the bodies' relative velocity:
it removes the whole relative velocity, and the bodies move on together.

Mistakes: the speeds added as scalars, ``(m1 |u1| + m2 |u2|)/(m1 + m2)``; the direction measured from the
other axis.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

from grader.model.expr import Sym
from grader.model.quantities import ANGLE, ENERGY, PURE, SPEED
from grader.physics.effects.base import Condition, Effect, Field, Mistake, Relation, Stable, TwoBodyStage
from grader.physics.effects.velocity import output_polar

if TYPE_CHECKING:
    from grader.model.scene import Stage
    from grader.physics.record import Run
    from grader.physics.symbolic import Context

_FROM = "n"  # the axis the common velocity's direction is measured from when a stage does not say
_FIELDS = (
    Field("bodies", "bodies", doc="[first, second]: the two bodies (both with a mass) that collide and lock"),
    Field("before", "velocities", doc="per body: {n: .., t: ..} along two perpendicular axes of the plane (east "
          "and north); a number or a name alone is along n; omitted = at rest", dimension=SPEED),
    Field("common", "vector", required=False, doc="{n: .., t: ..}: names for the common velocity's components",
          dimension=SPEED, default="v_common_n, v_common_t"),
    Field("speed", "expr", required=False, doc="the common velocity's speed", dimension=SPEED,
          default="not named: no step for it"),
    Field("angle", "expr", required=False, doc="the common velocity's direction, measured from the `from` axis "
          "toward the other", dimension=ANGLE, default="not named: no step for it"),
    Field("from", "choice:n|t", required=False, doc="the axis the direction is measured from", default=_FROM),
    Field("energy_lost", "name", required=False, doc="name for the kinetic energy lost", dimension=ENERGY,
          default="not named: no step for it"),
    Field("loss_fraction", "name", required=False, doc="name for the fraction of the kinetic energy lost",
          dimension=PURE, default="not named: no step for it"),
)


@dataclass(frozen=True)
class _Stick(TwoBodyStage):
    """One stage's quantities; a mistake is the same stage with a field changed."""

    before: tuple[tuple[Any, Any], tuple[Any, Any]]  # (n, t) of each
    common: tuple[Any, Any]
    speeds: str = "vector"  # the common speed from the momentum vector, or as a student who adds "scalar" speeds
    other_axis: bool = False  # the direction measured from the other axis

    @classmethod
    def of(cls, stage: Stage, ctx: Context) -> _Stick:
        """The collision a stage describes."""
        import sympy as sp

        (first, second), inverse = cls.pair(stage, ctx)  # a fixed surface does not move on with a body

        def component(body: str, axis: str) -> Any:
            given = stage.fields.get("before", {}).get(body)
            part = None if given is None else getattr(given, axis)
            return sp.Integer(0) if part is None else ctx.sym(part)

        named = stage.fields.get("common")
        common = (ctx.sym(named.n), ctx.sym(named.t)) if named is not None else tuple(
            ctx.symbol(ctx.unused_name(f"v_common_{axis}", stage)) for axis in ("n", "t"))
        return cls(stage, (first, second), inverse,
                   ((component(first, "n"), component(first, "t")), (component(second, "n"), component(second, "t"))),
                   common)

    def relations(self, ctx: Context) -> list[Relation]:
        """The stage's relations as a student writes them."""
        relations = [self._momentum(axis) for axis in (0, 1)]
        fields = self.stage.fields
        if "speed" in fields:
            relations.append(self._speed(ctx.sym(fields["speed"])))
        if "angle" in fields:
            relations.append(self._direction(ctx.sym(fields["angle"])))
        if "energy_lost" in fields or "loss_fraction" in fields:
            relations += self._energy(ctx)
        return relations

    def _momentum(self, axis: int) -> Relation:
        import sympy as sp

        (first, second), (w1, w2) = self.bodies, self.inverse
        u1, u2, v = self.before[0][axis], self.before[1][axis], self.common[axis]
        m1, m2 = 1 / w1, 1 / w2
        solutions: dict[Any, Any] = {}
        stable: dict[Any, Any] = {}
        if isinstance(v, sp.Symbol):
            solutions[v] = (m1 * u1 + m2 * u2) / (m1 + m2)
            stable[v] = (Stable((w2 * u1 + w1 * u2) / (w1 + w2)),)
        if isinstance(u1, sp.Symbol):
            solutions[u1] = ((m1 + m2) * v - m2 * u2) / m1
            stable[u1] = (Stable(v + (v - u2) * w1 / w2),)
        if isinstance(u2, sp.Symbol):
            solutions[u2] = ((m1 + m2) * v - m1 * u1) / m2
            stable[u2] = (Stable(v + (v - u1) * w2 / w1),)
        name = "nt"[axis]
        return Relation(f"conservation of momentum along {name}: {first} and {second} move on together",
                        m1 * u1 + m2 * u2, (m1 + m2) * v, solutions=solutions, stable=stable, general=False)

    def _speed(self, speed: Any) -> Relation:
        import sympy as sp

        from grader.physics.symbolic import hypot

        (w1, w2), (n, t) = self.inverse, self.common
        if self.speeds == "scalar":
            form = (hypot(*self.before[0]) / w1 + hypot(*self.before[1]) / w2) / (1 / w1 + 1 / w2)
            return Relation("speed after: the speeds before added as scalars", speed, form,
                            solutions={speed: form} if isinstance(speed, sp.Symbol) else {}, general=False)
        return Relation("speed of the wreck: magnitude of the common velocity", speed, hypot(n, t),
                        solutions={speed: hypot(n, t)} if isinstance(speed, sp.Symbol) else {}, general=False,
                        requires=(Condition(sp.Ge(speed, 0), f"the speed {self.stage.text('speed')} must not be "
                                            "negative"),))

    def _direction(self, angle: Any) -> Relation:
        import sympy as sp

        from grader.physics.symbolic import hypot

        n, t = self.common
        from_n = (self.stage.fields.get("from", _FROM) == "n") != self.other_axis
        along, across = (n, t) if from_n else (t, n)
        solutions: dict[Any, Any] = {}
        if isinstance(angle, sp.Symbol):
            solutions[angle] = sp.atan2(across, along)
        if isinstance(across, sp.Symbol):
            solutions[across] = along * sp.tan(angle)
        if isinstance(along, sp.Symbol):
            solutions[along] = across / sp.tan(angle)
        axis = ("n" if from_n else "t") + ("; measured from the other axis" if self.other_axis else "")
        return Relation(f"direction of the wreck, from the {axis}-axis", sp.tan(angle), across / along,
                        solutions=solutions, general=False,
                        undefined={angle: (sp.Le(hypot(n, t), 0), "the wreck does not move, so it has no direction")}
                        if isinstance(angle, sp.Symbol) else {})

    def _energy(self, ctx: Context) -> list[Relation]:
        from grader.physics.symbolic import hypot

        fields, (w1, w2) = self.stage.fields, self.inverse
        (u1n, u1t), (u2n, u2t) = self.before
        lost_form = hypot(u1n - u2n, u1t - u2t) ** 2 / (2 * (w1 + w2))
        lost = ctx.symbol(fields["energy_lost"]) if "energy_lost" in fields else lost_form
        relations = []
        if "energy_lost" in fields:
            relations.append(Relation("energy lost: 1/2 μ |u1 − u2|² with the reduced mass μ = m1 m2/(m1 + m2)", lost,
                                      lost_form, solutions={lost: lost_form}, general=False))
        if "loss_fraction" in fields:
            fraction = ctx.symbol(fields["loss_fraction"])
            before = hypot(u1n, u1t) ** 2 / (2 * w1) + hypot(u2n, u2t) ** 2 / (2 * w2)
            relations.append(Relation("fraction of the kinetic energy lost", fraction, lost / before,
                                      solutions={fraction: lost / before}, general=False))
        return relations


def _stick(stage: Stage, ctx: Context) -> list[Relation]:
    return _Stick.of(stage, ctx).relations(ctx)


def _mistakes(stage: Stage, ctx: Context) -> list[Mistake]:
    real = _Stick.of(stage, ctx)
    found = []
    if "speed" in stage.fields:
        found.append(Mistake("stick.speeds_added", "the speeds before added as scalars, (m1 |u1| + m2 |u2|)/(m1 + m2), "
                             "not as vectors", tuple(replace(real, speeds="scalar").relations(ctx))))
    if "angle" in stage.fields:
        found.append(Mistake("stick.angle_other_axis", "the direction measured from the other axis (90° − θ)",
                             tuple(replace(real, other_axis=True).relations(ctx))))
    return found


def _simulate_stick(stage: Stage, run: Run) -> None:
    """A perfectly plastic contact along the relative velocity, in the frame it sets: the velocities are
    turned so that n is along u1 - u2, the contact (e = 0) removes that component, and they turn back."""
    from grader.physics.effects.impact import simulate_contact  # the simulator's: loading needs none of it

    first, second = stage.fields["bodies"]
    inverse = tuple(1.0 / run.value(run.scene.bodies[body].mass) for body in (first, second))  # type: ignore[arg-type]
    before = [_component(run, stage, body, axis) for body in (first, second) for axis in ("n", "t")]
    relative = math.hypot(before[0] - before[2], before[1] - before[3])
    run.speed_scale = max(run.speed_scale, *map(abs, before))
    if relative == 0:
        after = before  # already moving together
    else:
        c, s = (before[0] - before[2]) / relative, (before[1] - before[3]) / relative
        turned = [before[0] * c + before[1] * s, before[1] * c - before[0] * s,
                  before[2] * c + before[3] * s, before[3] * c - before[2] * s]
        moved = simulate_contact(stage, run, (first, second), inverse, 0.0, turned,  # type: ignore[arg-type]
                                 f"{first} and {second} collide and lock")
        after = [moved[0] * c - moved[1] * s, moved[1] * c + moved[0] * s,
                 moved[2] * c - moved[3] * s, moved[3] * c + moved[2] * s]
    common = ((after[0] * inverse[1] + after[2] * inverse[0]) / (inverse[0] + inverse[1]),
              (after[1] * inverse[1] + after[3] * inverse[0]) / (inverse[0] + inverse[1]))
    _output(stage, run, inverse, before, after, common)


def _component(run: Run, stage: Stage, body: str, axis: str) -> float:
    given = stage.fields.get("before", {}).get(body)
    part = None if given is None else getattr(given, axis)
    return 0.0 if part is None else run.value(part)


def _output(stage: Stage, run: Run, inverse: tuple[float, ...], before: list[float], after: list[float],
            common: tuple[float, float]) -> None:
    fields = stage.fields
    if "common" in fields:
        run.output(fields["common"].n, common[0])
        run.output(fields["common"].t, common[1])
    along_across = common if fields.get("from", _FROM) == "n" else (common[1], common[0])
    output_polar(run, along_across, fields.get("speed"), fields.get("angle"),
                 "the wreck does not move, so it has no direction", math.hypot(*common))
    # The loss from the relative velocity the contact took away, 1/2 mu (a - s)(a + s) with a = |u1 - u2| and
    # s = |v1 - v2| as simulated: never T - T', which cancels when the bodies nearly moved together already.
    approach = math.hypot(before[0] - before[2], before[1] - before[3])
    left = math.hypot(after[0] - after[2], after[1] - after[3])
    lost = (approach - left) * (approach + left) / (2 * (inverse[0] + inverse[1]))
    if "energy_lost" in fields:
        run.output(Sym(fields["energy_lost"]), lost)
    if "loss_fraction" in fields:
        total = sum(math.hypot(before[2 * i], before[2 * i + 1]) ** 2 / (2 * w) for i, w in enumerate(inverse))
        run.output(Sym(fields["loss_fraction"]), lost / total if total else math.nan)


STICK = Effect(
    "stick",
    "two bodies moving in a plane collide and move on as one: (m1 + m2) v = m1 u1 + m2 u2 as vectors",
    _FIELDS,
    _stick,
    _simulate_stick,
    _mistakes,
    force_law="a perfectly plastic contact (Kelvin-Voigt, e = 0) along the bodies' relative velocity, which it "
              "removes: the bodies move on together; no gravity, no friction",
)
