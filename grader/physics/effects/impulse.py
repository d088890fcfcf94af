"""The impulse on a body over an impact, ``J = m (v' - v)`` as a vector, and the average force over a contact
time or a stopping distance (a body stopped by a cushion).

Components along n and t, the magnitude with ``hypot`` and the direction (from n toward t) with ``atan2``.
The average force: over a contact time, ``F = |J|/dt``; over a stopping distance (work-energy),
``F d = 1/2 m (v**2 - v'**2)`` with the speeds' difference of squares formed as a product. Where the scene
declares the weight during the contact (``weight: true``, n pointing up), the force asked is the surface's
normal force, ``J_n/dt + m g`` or ``(1/2 m (v**2 - v'**2) + m g d)/d``.

Force law (simulation): none: kinematics. The impulse is ``m (v' - v)`` of the velocities the scene gives; the
average force is the impulse over the time (the time average of whatever the contact force was), or the
work-energy over the distance.

Mistakes: speeds for velocities (``m(|v'| - |v|)``: the rebound's sign lost); the weight left in or out against
what the scene declares.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

from grader.base.errors import TemplateError
from grader.model.expr import to_text
from grader.model.quantities import ANGLE, FORCE, IMPULSE, LENGTH, SPEED, TIME
from grader.physics.effects.base import Condition, Effect, Field, Mistake, Relation

if TYPE_CHECKING:
    from grader.model.scene import Stage
    from grader.physics.record import Run
    from grader.physics.symbolic import Context

_FIELDS = (
    Field("body", "body", doc="the body the impulse acts on"),
    Field("velocity", "vector", doc="{n: .., t: ..}: its velocity just before", dimension=SPEED),
    Field("velocity_after", "vector", doc="{n: .., t: ..}: its velocity just after", dimension=SPEED),
    Field("components", "vector", required=False, doc="{n: .., t: ..}: names for the impulse's components",
          dimension=IMPULSE, default="J_n, J_t"),
    Field("impulse", "expr", required=False, doc="the impulse's magnitude", dimension=IMPULSE,
          default="not named: no step for it"),
    Field("angle", "expr", required=False, doc="the impulse's direction, measured from n toward t", dimension=ANGLE,
          default="not named: no step for it"),
    Field("time", "expr", required=False, doc="the contact time the average force acts over", dimension=TIME,
          default="none"),
    Field("distance", "expr", required=False, doc="the distance the average force acts over (a cushion)",
          dimension=LENGTH, default="none"),
    Field("force", "expr", required=False, doc="the average force (with `time` or `distance`)", dimension=FORCE,
          default="not named: no step for it"),
    Field("weight", "flag", required=False, doc="the weight acts during the contact, n pointing up: the force asked "
          "is the surface's normal force", default="false"),
)


def check_fields(stage: Stage, where: str) -> None:
    """An average force over a time or a distance, not both, and only with a force to name."""
    fields, key = stage.fields, f"stages[{stage.index}]"
    if "time" in fields and "distance" in fields:
        raise TemplateError(where, f"{key}.distance", "a contact time or a stopping distance, not both",
                            "both")
    if "force" in fields and not ("time" in fields or "distance" in fields):
        raise TemplateError(where, f"{key}.force", "a contact time (time:) or a stopping distance (distance:) to "
                            "average over", "neither")


@dataclass(frozen=True)
class _Impulse:
    """One stage's quantities; a mistake is the same stage with one changed."""

    stage: Stage
    mass: Any
    before: tuple[Any, Any]
    after: tuple[Any, Any]
    components: tuple[Any, Any]
    g: Any  # g where the weight acts during the contact, else 0
    speeds: bool = False  # speeds for velocities: m(|v'| - |v|)

    @classmethod
    def of(cls, stage: Stage, ctx: Context) -> _Impulse:
        """The impulse a stage describes."""
        import sympy as sp

        check_fields(stage, ctx.scene.where)
        fields = stage.fields
        mass = ctx.mass(stage, fields["body"], "body")
        named = fields.get("components")
        direct = all(ctx.sym(fields[key].t) == 0 for key in ("velocity", "velocity_after"))
        components = (ctx.sym(named.n), ctx.sym(named.t)) if named is not None else (
            ctx.symbol(ctx.unused_name("J_n", stage)),
            sp.Integer(0) if direct else ctx.symbol(ctx.unused_name("J_t", stage)))  # direct: no t-impulse
        g = ctx.gravity_symbol(stage) if fields.get("weight", False) else sp.Integer(0)
        before, after = fields["velocity"], fields["velocity_after"]
        return cls(stage, mass, (ctx.sym(before.n), ctx.sym(before.t)), (ctx.sym(after.n), ctx.sym(after.t)),
                   components, g)

    def relations(self, ctx: Context) -> list[Relation]:
        """The stage's relations as a student writes them."""
        relations = [self._momentum(axis) for axis in (0, 1) if axis == 0 or self.components[1] != 0]
        fields = self.stage.fields
        if "impulse" in fields:
            relations.append(self._magnitude(ctx.sym(fields["impulse"])))
        if "angle" in fields:
            relations.append(self._direction(ctx.sym(fields["angle"])))
        if "force" in fields:
            relations.append(self._force(ctx))
        return relations

    def _momentum(self, axis: int) -> Relation:
        import sympy as sp

        m, u, v, j = self.mass, self.before[axis], self.after[axis], self.components[axis]
        change = sp.Abs(v) - sp.Abs(u) if self.speeds else v - u
        solutions: dict[Any, Any] = {}
        if isinstance(j, sp.Symbol):
            solutions[j] = m * change
        if isinstance(v, sp.Symbol) and not self.speeds:
            solutions[v] = u + j / m
        if isinstance(u, sp.Symbol) and not self.speeds:
            solutions[u] = v - j / m
        words = "speeds" if self.speeds else "velocities"
        return Relation(f"impulse-momentum along {'nt'[axis]} for {self.stage.fields['body']}: the impulse is the "
                        f"change of its momentum ({words})", j, m * change, solutions=solutions, general=False)

    def _magnitude(self, impulse: Any) -> Relation:
        import sympy as sp

        from grader.physics.symbolic import hypot

        form = hypot(*self.components)
        return Relation("magnitude of the impulse", impulse, form,
                        solutions={impulse: form} if isinstance(impulse, sp.Symbol) else {}, general=False)

    def _direction(self, angle: Any) -> Relation:
        import sympy as sp

        from grader.physics.symbolic import hypot

        n, t = self.components
        return Relation("direction of the impulse, from the n-axis", sp.tan(angle), t / n,
                        solutions={angle: sp.atan2(t, n)} if isinstance(angle, sp.Symbol) else {}, general=False,
                        undefined={angle: (sp.Le(hypot(n, t), 0), "the impulse is zero, so it has no direction")}
                        if isinstance(angle, sp.Symbol) else {})

    def _force(self, ctx: Context) -> Relation:
        import sympy as sp

        from grader.physics.symbolic import hypot

        fields, m, g = self.stage.fields, self.mass, self.g
        force = ctx.sym(fields["force"])
        weight = m * g
        if "time" in fields:
            dt = ctx.sym(fields["time"])
            average = self.components[0] / dt + weight if g != 0 else hypot(*self.components) / dt
            label = (f"average normal force over the contact time {self.stage.text('time')}: (F − m g) Δt = J_n"
                     if g != 0 else f"average force over the contact time "
                     f"{self.stage.text('time')}: F Δt = |J|")
            requires = (Condition(sp.Gt(dt, 0), f"the contact time {self.stage.text('time')} must be positive"),)
        else:
            d = ctx.sym(fields["distance"])
            speed, speed_after = hypot(*self.before), hypot(*self.after)
            average = m * (speed - speed_after) * (speed + speed_after) / (2 * d) + weight
            label = (f"work-energy over the stopping distance {self.stage.text('distance')}: (F − m g) d = "
                     "½ m (v² − v′²)" if g != 0 else f"work-energy over the stopping distance "
                     f"{self.stage.text('distance')}: F d = ½ m (v² − v′²)")
            requires = (Condition(sp.Gt(d, 0), f"the stopping distance {self.stage.text('distance')} must be "
                                  "positive"),)
        return Relation(label, force, average, solutions={force: average} if isinstance(force, sp.Symbol) else {},
                        general=False, requires=requires)


def _impulse(stage: Stage, ctx: Context) -> list[Relation]:
    return _Impulse.of(stage, ctx).relations(ctx)


def _mistakes(stage: Stage, ctx: Context) -> list[Mistake]:
    real = _Impulse.of(stage, ctx)
    found = [Mistake("impulse.speeds_for_velocities", "speeds for velocities, m(|v′| − |v|): the rebound's sign "
                     "lost", tuple(replace(real, speeds=True).relations(ctx)))]
    if "force" in stage.fields and ctx.scene.gravity is not None:
        import sympy as sp

        declared = stage.fields.get("weight", False)
        other = sp.Integer(0) if declared else ctx.gravity_symbol(stage)
        found.append(Mistake("impulse.weight", "the weight left out of the average force" if declared else
                             "the weight added to the average force, which the scene neglects",
                             tuple(replace(real, g=other).relations(ctx))))
    return found


def _simulate_impulse(stage: Stage, run: Run) -> None:
    """Kinematics, not a force: the impulse from the velocities the scene gives, the average force from it."""
    fields = stage.fields
    mass = run.value(run.scene.bodies[fields["body"]].mass)  # type: ignore[arg-type]
    before = (run.value(fields["velocity"].n), run.value(fields["velocity"].t))
    after = (run.value(fields["velocity_after"].n), run.value(fields["velocity_after"].t))
    j = (mass * (after[0] - before[0]), mass * (after[1] - before[1]))
    if "components" in fields:
        run.output(fields["components"].n, j[0])
        run.output(fields["components"].t, j[1])
    size = math.hypot(*j)
    if "impulse" in fields:
        run.output(fields["impulse"], size)
    if "angle" in fields:
        if size > 0:
            run.output(fields["angle"], math.atan2(j[1], j[0]))
        else:
            run.undefined[to_text(fields["angle"])] = "the impulse is zero, so it has no direction"
            run.output(fields["angle"], math.nan)
    if "force" in fields:
        weight = mass * run.gravity() if fields.get("weight", False) else 0.0
        if "time" in fields:
            dt = run.value(fields["time"])
            average = j[0] / dt + weight if weight else size / dt
        else:
            d = run.value(fields["distance"])
            speed, speed_after = math.hypot(*before), math.hypot(*after)
            average = mass * (speed - speed_after) * (speed + speed_after) / (2 * d) + weight
        run.output(fields["force"], average)


IMPULSE_EFFECT = Effect(
    "impulse",
    "the impulse on a body, J = m (v' - v) as a vector, and the average force over a contact time or a stopping "
    "distance",
    _FIELDS,
    _impulse,
    _simulate_impulse,
    _mistakes,
    force_law="none: kinematics; the impulse is m (v' - v) of the velocities the scene gives, the average force the "
              "impulse over the contact time, or the work-energy over the stopping distance",
)
