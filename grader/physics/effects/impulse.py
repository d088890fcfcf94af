"""The impulse on a body over an impact, ``J = m (v' - v)`` as a vector, and the average force over a contact
time or a stopping distance (a body stopped by a cushion).

Components along n and t, the magnitude with ``hypot`` and the direction (from n toward t) with ``atan2``.
The average force: over a contact time, ``F = |J|/dt``; over a stopping distance (work-energy),
``F d = 1/2 m (v**2 - v'**2)`` with the speeds' difference of squares formed as a product. Where the scene
declares the weight during the contact (``weight: true``, n pointing up), the force asked is the surface's
normal force, ``J_n/dt + m g`` or ``(1/2 m (v**2 - v'**2) + m g d)/d``.

Force law (simulation): a force on the body, integrated with its weight where the scene declares it: over a
contact time, a parabolic pulse ``F(t) = 6 F_avg (t/dt)(1 - t/dt)`` (the given contact time, else the
simulation's contact duration), whose mean is ``F_avg``; over a stopping distance, a constant force, ended where
the body has travelled ``d``. ``F_avg`` is the force the scene gives (along n where the weight acts, else at the
impulse's angle where given, else against the motion), or else the one that takes the body from its velocity
before to the velocity after the scene gives, as an impact's contact is calibrated to ``e``; a constant force
then acts for ``2 d/(|v| + |v'|)`` and the distance the body travels is checked against ``d``. The impulse is the
body's simulated change of momentum, the average force that impulse over the time, or the work over the distance
travelled (``F d = 1/2 m (v**2 - v'**2)`` of the simulated speeds).

Mistakes: speeds for velocities (``m(|v'| - |v|)``: the rebound's sign lost); the weight left in or out against
what the scene declares.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from grader.base.errors import TemplateError
from grader.model.expr import Num
from grader.model.quantities import ANGLE, FORCE, IMPULSE, LENGTH, SPEED, TIME
from grader.physics.effects.base import Condition, Effect, Field, Mistake, Relation
from grader.physics.effects.velocity import output_polar

if TYPE_CHECKING:
    from grader.model.scene import Stage
    from grader.physics.integrate import Mode
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


@dataclass(frozen=True)
class _Push:
    """What the simulation integrates for one impulse stage (SI): the body's mass and velocity before, the mean
    ``net`` of the force on it beyond what holds up its weight (n and t) and its shape, and what ends it: a time
    (``duration``) or, for a given force over a stopping distance, the distance travelled (``distance``). The
    surface's force is ``m g + shape(t) net`` along n, so the body's acceleration is ``shape(t) net/m``: no ``g``
    to cancel against a small change of velocity."""

    mass: float
    before: tuple[float, float]
    net: tuple[float, float]
    gravity: float  # along -n, where the scene declares the weight during the contact
    pulse: bool  # a parabolic pulse over a contact time; else a constant force over a distance
    duration: float = 0.0
    distance: float = 0.0

    @classmethod
    def of(cls, stage: Stage, run: Run) -> _Push:
        """The force a stage describes: the one given, or else the one that takes the body to its velocity after."""
        fields = stage.fields
        mass = run.value(run.scene.bodies[fields["body"]].mass)  # type: ignore[arg-type]
        before = (run.value(fields["velocity"].n), run.value(fields["velocity"].t))
        gravity = run.gravity() if fields.get("weight", False) else 0.0
        pulse = "distance" not in fields
        given = fields["velocity_after"]
        if run.known(given.n) and run.known(given.t):
            return cls._calibrated(stage, run, mass, before, (run.value(given.n), run.value(given.t)), gravity)
        if "force" not in fields:
            run.value(given.n), run.value(given.t)  # the stage waits for the velocity after
        size = run.value(fields["force"])
        direction = cls._direction(stage, run, before)
        net = (size * direction[0] - mass * gravity, size * direction[1])
        if pulse:
            return cls(mass, before, net, gravity, pulse, duration=_contact_time(stage, run))
        return cls(mass, before, net, gravity, pulse, distance=run.value(fields["distance"]))

    @classmethod
    def _calibrated(cls, stage: Stage, run: Run, mass: float, before: tuple[float, float],
                    after: tuple[float, float], gravity: float) -> _Push:
        """The mean force that takes the body from ``before`` to ``after``: over the contact time, or constant over
        the distance, which it then crosses in ``2 d/(|v| + |v'|)``."""
        if "distance" in stage.fields:
            speeds = math.hypot(*before) + math.hypot(*after)
            duration = 2 * run.value(stage.fields["distance"]) / speeds if speeds > 0 else 0.0
        else:
            duration = _contact_time(stage, run)
        if duration == 0:
            return cls(mass, before, (0.0, 0.0), gravity, "distance" not in stage.fields)
        net = (mass * (after[0] - before[0]) / duration, mass * (after[1] - before[1]) / duration)
        return cls(mass, before, net, gravity, "distance" not in stage.fields, duration=duration)

    @staticmethod
    def _direction(stage: Stage, run: Run, before: tuple[float, float]) -> tuple[float, float]:
        """A given force's direction: the surface's normal force along n where the weight acts; else the impulse's
        direction where the scene gives it; else against the body's motion."""
        fields = stage.fields
        if fields.get("weight", False):
            return 1.0, 0.0
        if "angle" in fields and run.known(fields["angle"]):
            angle = run.value(fields["angle"])
            return math.cos(angle), math.sin(angle)
        speed = math.hypot(*before)
        if speed == 0:
            from grader.physics.integrate import SimulationError  # the simulator's: loading a template needs none

            raise SimulationError(f"{run.scene.where}: stages[{stage.index}]: the force {stage.text('force')} on a "
                                  "body at rest has no direction: give the impulse's angle or the velocity after")
        return -before[0] / speed, -before[1] / speed

    def mode(self) -> Mode:
        """The body under the force (and its weight): ``[x_n, x_t, v_n, v_t]`` from ``t = 0``, for the contact time
        or until the distance is travelled."""
        from grader.physics.integrate import Mode  # the simulator's part: loading a template needs none of it

        (net_n, net_t), mass, duration, shape = self.net, self.mass, self.duration, self.shape

        def pushed(t: float, y: Any) -> Any:
            share = shape(t) / mass
            return np.array([y[2], y[3], net_n * share, net_t * share])

        scale = duration or self.distance / math.hypot(*self.before)
        speed = max(math.hypot(*self.before), math.hypot(*self.net) * scale / mass)
        sizes = np.array([speed * scale, speed * scale, speed, speed])
        if duration:
            return Mode("force on the body", pushed, None, 1, scale=scale, sizes=lambda y: sizes, lasts=duration)
        return Mode("force on the body", pushed, lambda y: math.hypot(y[0], y[1]) - self.distance, 1, scale=scale,
                    sizes=lambda y: sizes)

    def shape(self, t: float) -> float:
        """The force's share of its mean at time ``t``: a parabolic pulse's, ``6 s (1 - s)`` at ``s = t/dt`` (zero at
        both ends, 3/2 at its peak, 1 on average), or all of it. Its velocity is a cubic in time, which the
        adaptive method's 8th-order steps follow in a few steps."""
        if not self.pulse:
            return 1.0
        share = t / self.duration
        return 6 * share * (1 - share)

    def normal_force(self, t: float) -> float:
        """The surface's force along n at time ``t`` (what a plot shows): the weight held up and the pulse."""
        return self.mass * self.gravity + self.shape(t) * self.net[0]

    def stopped_short(self) -> float | None:
        """Where a given force over a distance stops the body before it has travelled it (None: it does not)."""
        speed = math.hypot(*self.before)
        if speed == 0:
            return 0.0
        along = (self.net[0] * self.before[0] + self.net[1] * self.before[1]) / (self.mass * speed)
        stop = speed * speed / (-2 * along) if along < 0 else math.inf
        return stop if stop <= self.distance else None


def _contact_time(stage: Stage, run: Run) -> float:
    """The stage's contact time, or the simulation's contact duration where the scene gives none."""
    return run.value(stage.fields["time"]) if "time" in stage.fields else run.options.contact_duration


def _simulate_impulse(stage: Stage, run: Run) -> None:
    """The body under the force over the contact, integrated (see :class:`_Push`); the impulse is the change of its
    simulated momentum, the average force the impulse over the time or the work over the distance."""
    fields = stage.fields
    push = _Push.of(stage, run)
    if not (push.duration or push.distance):
        if push.pulse:
            run.problems.append(f"the contact time {stage.text('time')} is not positive")
        else:  # at rest before and after: nothing moves, and the surface holds up the weight alone
            _output(stage, run, push, push.before, run.value(fields["distance"]), 0.0)
        return
    if not push.pulse and not push.duration and (short := push.stopped_short()) is not None:
        run.problems.append(f"the force {stage.text('force')} stops {fields['body']} within {short:.4g} m, before "
                            f"it has moved the distance {stage.text('distance')}")
        return
    run.uses("force pulse over the contact time (parabolic)" if push.pulse else "constant force over a distance")
    if push.gravity:
        run.uses("gravity")
    path = run.integrate([push.mode()], np.array([0.0, 0.0, *push.before]))
    path.force = [push.normal_force(t) for t in path.t]  # a function of time, which a mode's force(y) cannot see
    run.record(f"the force on {fields['body']}", ("xn", "xt", "vn", "vt"), path)
    end = path.y[-1]
    after = (float(end[2]), float(end[3]))
    run.speed_scale = max(run.speed_scale, *map(abs, push.before), *map(abs, after))
    for axis, value in zip(("n", "t"), after, strict=True):
        part = getattr(fields["velocity_after"], axis)
        if not isinstance(part, Num):  # a number is the scene's: no outcome to find anything from
            run.output(part, value)
    _output(stage, run, push, after, math.hypot(float(end[0]), float(end[1])), path.t[-1])


def _output(stage: Stage, run: Run, push: _Push, after: tuple[float, float], travelled: float,
            elapsed: float) -> None:
    # The distance travelled is not given back: where the force was found from the velocity after, it is the
    # distance the force was calibrated over, and a second outcome would leave a search nothing to choose by.
    """The impulse from the simulated change of momentum, its size and direction, and the average force."""
    fields, mass = stage.fields, push.mass
    j = (mass * (after[0] - push.before[0]), mass * (after[1] - push.before[1]))
    if "components" in fields:
        run.output(fields["components"].n, j[0])
        run.output(fields["components"].t, j[1])
    output_polar(run, j, fields.get("impulse"), fields.get("angle"), "the impulse is zero, so it has no direction",
                 math.hypot(*j) / mass)
    if "force" not in fields:
        return
    weight = mass * push.gravity
    if push.pulse:
        average = j[0] / elapsed + weight if weight else math.hypot(*j) / elapsed
    else:
        speed, speed_after = math.hypot(*push.before), math.hypot(*after)
        average = mass * (speed - speed_after) * (speed + speed_after) / (2 * travelled) + weight
    run.output(fields["force"], average)


IMPULSE_EFFECT = Effect(
    "impulse",
    "the impulse on a body, J = m (v' - v) as a vector, and the average force over a contact time or a stopping "
    "distance",
    _FIELDS,
    _impulse,
    _simulate_impulse,
    _mistakes,
    force_law="a force on the body (and its weight, where the scene declares it): a parabolic pulse over the "
              "contact time, or a constant force until the body has travelled the stopping distance; its mean the "
              "force given, or else the one that takes the body to the velocity after the scene gives; the impulse "
              "is the simulated change of momentum",
)
