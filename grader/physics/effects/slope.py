"""Work and energy along a straight path: a body goes from speed ``v_in`` to ``v_out`` over a distance ``d``
along a slope at angle beta, up or down (0: level), against kinetic friction ``mu_k`` or smooth; or down a
smooth ramp of height ``h`` (a descent, whatever the ramp's shape: its normal force does no work).

Per unit mass (the mass cancels): ``v_out**2 = v_in**2 + 2 g (s h - mu_k cos(beta) d)``, with ``h = d sin(beta)``
the height descended (``s = +1`` down, ``-1`` up). Left without an end speed, the body slides to rest; on a
slope it then stays there only if the static friction holds it, ``tan(beta) <= mu_s`` where ``static`` gives
``mu_s``; down a slope it stops at all only if ``mu_k > tan(beta)``.

The kernels take differences of squares as products, ``(v_in - v_out)(v_in + v_out)``, and the speed at the
foot of a smooth ramp as ``hypot(v_in, sqrt(2 g h))``, a sum of squares that never cancels.

Force law (simulation): gravity's component along the path, ``s g sin(beta)``, and Coulomb kinetic friction
``mu_k g cos(beta)`` against the motion while the body moves, from the start until the located event at the
distance, at the end speed, or at rest (``v = 0``: the stage ends there, so the friction never chatters). A
ramp given by its height alone is integrated along a straight ramp at 30 degrees.

Mistakes: ``mu_k g`` for ``mu_k g cos(beta)``; gravity's component with the wrong sign; friction left out.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from grader.base.errors import TemplateError
from grader.model.quantities import ANGLE, LENGTH, PURE, SPEED
from grader.physics.effects.base import Condition, Effect, Field, Mistake, Relation, Stable

if TYPE_CHECKING:
    from grader.model.scene import Stage
    from grader.physics.record import Run
    from grader.physics.symbolic import Context

_FIELDS = (
    Field("body", "body", doc="the body that moves"),
    Field("with", "body", required=False, doc="a body stuck to it that moves along", default="the body moves alone"),
    Field("speed", "expr", doc="speed at the start, >= 0", dimension=SPEED),
    Field("end_speed", "expr", required=False, doc="speed at the end of the path, >= 0", dimension=SPEED,
          default="0: the body comes to rest"),
    Field("distance", "expr", required=False, doc="distance travelled along the path", dimension=LENGTH,
          default="none: a smooth ramp given by its height"),
    Field("angle", "expr", required=False, doc="angle beta of the path from the horizontal, 0 to 90 degrees",
          dimension=ANGLE, default="0: level"),
    Field("direction", "choice:down|up", required=False, doc="whether the body moves down or up the slope",
          default="down"),
    Field("height", "expr", required=False, doc="height descended (or risen, up), d sin(beta); alone, without "
          "a distance: a smooth ramp of that height", dimension=LENGTH, default="d sin(beta)"),
    Field("friction", "expr", required=False, doc="coefficient of kinetic friction mu_k, >= 0", dimension=PURE,
          default="0: smooth"),
    Field("static", "expr", required=False, doc="coefficient of static friction mu_s: the body, come to rest on "
          "the slope, must stay there (tan(beta) <= mu_s)", dimension=PURE, default="no check"),
)


def check_fields(stage: Stage, where: str) -> None:
    """What the field schema cannot say: a path is a distance or a height; friction needs the distance."""
    fields, key = stage.fields, f"stages[{stage.index}]"
    if "distance" not in fields and "height" not in fields:
        raise TemplateError(where, key, "a distance along the path, or the height of a smooth ramp", "neither")
    if "distance" not in fields and "friction" in fields:
        raise TemplateError(where, f"{key}.friction", "a distance as well (friction works along the path)",
                            "no distance")
    if "static" in fields and "end_speed" in fields:
        raise TemplateError(where, f"{key}.static", "a body that comes to rest (no end_speed) for the check that it "
                            "stays at rest", f"end_speed: {stage.text('end_speed')}")


@dataclass(frozen=True)
class _Slope:
    """One stage's quantities; a mistake is the same stage with one changed."""

    stage: Stage
    v_in: Any
    v_out: Any
    d: Any  # None: a smooth ramp by its height
    beta: Any
    h: Any  # the height's own quantity, or None (then d sin(beta))
    mu: Any
    g: Any
    sign: int  # +1 down, -1 up
    mu_s: Any  # None: no check that it stays at rest
    cosine: bool = True  # friction as mu g cos(beta), or as a student who writes mu g

    @classmethod
    def of(cls, stage: Stage, ctx: Context) -> _Slope:
        """The path a stage describes."""
        import sympy as sp

        check_fields(stage, ctx.scene.where)
        fields = stage.fields

        def given(key: str, default: Any = None) -> Any:
            return ctx.sym(fields[key]) if key in fields else default

        return cls(stage, given("speed"), given("end_speed", sp.Integer(0)), given("distance"),
                   given("angle", sp.Integer(0)), given("height"), given("friction", sp.Integer(0)),
                   ctx.gravity_symbol(stage), 1 if fields.get("direction", "down") == "down" else -1,
                   given("static"))

    def relations(self) -> list[Relation]:
        """The stage's relations as a student writes them."""
        import sympy as sp

        relations = []
        if self.h is not None and self.d is not None and "angle" in self.stage.fields:
            relations.append(self._geometry())
        height = self.h if self.h is not None else self.d * sp.sin(self.beta)
        friction = self.mu * (sp.cos(self.beta) if self.cosine else 1) * (self.d if self.d is not None else 0)
        relations.append(self._work_energy(height, friction))
        return relations

    def _geometry(self) -> Relation:
        import sympy as sp

        solutions = {self.h: self.d * sp.sin(self.beta)} if isinstance(self.h, sp.Symbol) else {}
        if isinstance(self.d, sp.Symbol):
            solutions[self.d] = self.h / sp.sin(self.beta)
        return Relation(f"height of the path: {self.stage.text('distance')} along a slope at "
                        f"{self.stage.text('angle')}", self.h, self.d * sp.sin(self.beta), solutions=solutions,
                        general=False)

    def _work_energy(self, height: Any, friction: Any) -> Relation:
        """``v_out**2 = v_in**2 + 2 g (s h - mu cos(beta) d)``; ``friction`` is ``mu cos(beta) d``."""
        import sympy as sp

        v_in, v_out, g, s, d, mu = self.v_in, self.v_out, self.g, self.sign, self.d, self.mu
        work = s * height - friction  # per unit weight: the height the kinetic energy gains
        solutions: dict[Any, Any] = {}
        stable: dict[Any, Any] = {}
        if isinstance(v_out, sp.Symbol):
            solutions[v_out] = sp.sqrt(v_in**2 + 2 * g * work)
            if friction == 0 and s == 1:
                stable[v_out] = (Stable(_hypot(v_in, sp.sqrt(2 * g * height))),)
        if isinstance(v_in, sp.Symbol):
            solutions[v_in] = sp.sqrt(v_out**2 - 2 * g * work)
            if s == -1 or (friction != 0 and height == 0):  # the work is never positive: no square root of < 0
                stable[v_in] = (Stable(_hypot(v_out, sp.sqrt(-2 * g * work))),)
        lost = (v_in - v_out) * (v_in + v_out) / (2 * g)  # the height the kinetic energy loses
        if isinstance(d, sp.Symbol):
            per_length = sp.expand(work / d) if self.h is None else None
            if per_length is not None and not per_length.has(d):
                solutions[d] = lost / -per_length
            elif self.h is not None and friction != 0:
                solutions[d] = (lost + s * height) / (friction / d)
        if isinstance(mu, sp.Symbol) and friction != 0:
            solutions[mu] = (lost + s * height) / (friction / mu)
        if isinstance(self.h, sp.Symbol):
            solutions[self.h] = s * (friction - lost)
        who = _who(self.stage)
        path = (f"{self.stage.text('distance')} {'down' if s == 1 else 'up'} a slope at {self.stage.text('angle')}"
                if "angle" in self.stage.fields else f"{self.stage.text('distance')} on a level surface"
                if d is not None else f"{'down' if s == 1 else 'up'} a smooth ramp of height "
                f"{self.stage.text('height')}")
        rubbing = "μk m g cos β d" if "angle" in self.stage.fields else "μk m g d"
        terms = ["gravity's work m g h" if height != 0 else "", f"friction's work {rubbing}" if friction != 0 else ""]
        said = " and ".join(t for t in terms if t)
        changes = f"{said} change its kinetic energy" if " and " in said else f"{said} changes its kinetic energy" \
            if said else "nothing changes its kinetic energy"
        relation_words = (f"work-energy per unit mass: {who} goes {path}; {changes}"
                          if friction != 0 or d is not None else
                          f"conservation of energy: {who} descends {path.split(' ', 1)[1]} (the ramp's normal "
                          "force does no work)" if s == 1 else
                          f"conservation of energy: {who} rises {path.split(' ', 1)[1]}")
        requires = [Condition(sp.Ge(v_in, 0), f"{who} must move forward at the start ({self.stage.text('speed')} "
                              ">= 0)")]
        if "end_speed" in self.stage.fields:
            requires.append(Condition(sp.Ge(v_in**2 + 2 * g * work, 0), f"{who} comes to rest before the end of the "
                                      "path: friction (or the climb) takes all its kinetic energy first"))
        requires.append(Condition(sp.Ge(v_out, 0), "the speed at the end of the path must not be negative"))
        if d is not None:
            requires.append(Condition(sp.Ge(d, 0), f"the distance {self.stage.text('distance')} must not be "
                                      "negative"))
        if "friction" in self.stage.fields:
            requires.append(Condition(sp.Ge(mu, 0), f"the coefficient of kinetic friction "
                                      f"{self.stage.text('friction')} must not be negative"))
        requires += self._at_rest()
        return Relation(relation_words, v_out**2, v_in**2 + 2 * g * work, solutions=solutions, stable=stable,
                        general=False, requires=tuple(requires))

    def _at_rest(self) -> list[Condition]:
        """Come to rest on a slope: down it, kinetic friction must be able to stop it; and with ``static``
        given, static friction must hold it there."""
        import sympy as sp

        fields, beta = self.stage.fields, self.beta
        if "end_speed" in fields or "angle" not in fields:
            return []
        found = []
        if self.sign == 1 and "friction" in fields:
            found.append(Condition(sp.Gt(self.mu * sp.cos(beta) - sp.sin(beta), 0), "tan β is {value} times μk: with "
                                   "μk <= tan β the body never stops sliding down the slope",
                                   subject=sp.tan(beta) / self.mu))
        if self.mu_s is not None:
            found.append(Condition(sp.Le(sp.sin(beta), self.mu_s * sp.cos(beta)), "tan β is {value} times μs: come "
                                   "to rest, the body slides off again (it stays at rest only where tan β <= μs)",
                                   subject=sp.tan(beta) / self.mu_s))
        return found


def _hypot(a: Any, b: Any) -> Any:
    from grader.physics.symbolic import hypot

    return hypot(a, b)


def _who(stage: Stage) -> str:
    together = stage.fields.get("with")
    return f"{stage.fields['body']} (with {together} stuck to it)" if together else str(stage.fields["body"])


def _slope(stage: Stage, ctx: Context) -> list[Relation]:
    return _Slope.of(stage, ctx).relations()


def _mistakes(stage: Stage, ctx: Context) -> list[Mistake]:
    real = _Slope.of(stage, ctx)
    fields = stage.fields
    found = []
    if "friction" in fields and "angle" in fields:
        found.append(Mistake("slope.friction_without_cos", "the friction force μk m g instead of μk m g cos β",
                             tuple(replace(real, cosine=False).relations())))
    if "angle" in fields or "height" in fields:
        found.append(Mistake("slope.gravity_sign", "gravity's component along the slope with the wrong sign",
                             tuple(replace(real, sign=-real.sign).relations())))
    if "friction" in fields:
        import sympy as sp

        found.append(Mistake("slope.friction_left_out", "the friction's work left out",
                             tuple(replace(real, mu=sp.Integer(0)).relations())))
    return found


def along_slope(acceleration: float) -> Any:
    """The force law per unit mass on a state ``[distance, speed]`` along the path: gravity's component and
    kinetic friction, constant while the body moves forward (the stage ends at rest)."""
    def rhs(_: float, y: Any) -> Any:
        return np.array([y[1], acceleration])
    return rhs


_RAMP = math.radians(30)  # a ramp given by its height alone: the speed at its foot does not depend on its angle


def _simulate_slope(stage: Stage, run: Run) -> None:
    fields = stage.fields
    speed = run.value(fields["speed"])
    g, sign = run.gravity(), 1 if fields.get("direction", "down") == "down" else -1
    beta = run.value(fields["angle"]) if "angle" in fields else (_RAMP if "distance" not in fields else 0.0)
    mu = run.value(fields["friction"]) if "friction" in fields else 0.0
    acceleration = sign * g * math.sin(beta) - mu * g * math.cos(beta)
    length = None if "end_speed" not in fields else _length(stage, run, beta)
    end = 0.0 if "end_speed" not in fields else None if length is not None else run.value(fields["end_speed"])
    if beta:
        run.uses("gravity along the path")
    if mu:
        run.uses("kinetic friction (Coulomb)")
    if speed < 0:
        run.problems.append(f"{_who(stage)} moves backward ({speed:g} m/s) at the start")
        _output(stage, run, beta, 0.0, 0.0)
    elif end is not None and end != speed and (end - speed) * acceleration <= 0:
        run.problems.append(f"{_who(stage)} never reaches {end:g} m/s: its acceleration along the path is "
                            f"{acceleration:g} m/s^2")
        # A body that never stops is reported as one that stops under a vanishing deceleration: a search
        # for the friction coefficient then sees the distance fall as the friction grows from 0.
        _output(stage, run, beta, speed * speed / (2 * max(-acceleration, 1e-12 * g)), speed)
    else:
        _output(stage, run, beta, *_integrate(stage, run, speed, acceleration, length, end))


def _integrate(stage: Stage, run: Run, speed: float, acceleration: float, length: float | None,
               end: float | None) -> tuple[float, float]:
    """From the start to the path's end (``length``) or to the speed ``end``; the distance and the speed there.
    A body that stops short of the path's end stops there (the located event ``v = 0``)."""
    from grader.physics.integrate import Mode  # the simulator's part: loading a template needs none of it

    reach = max(speed, abs(end or 0.0), math.sqrt(abs(acceleration) * (length or 0.0)))
    scale = reach / abs(acceleration) if acceleration else (length or 0.0) / speed if speed else 1.0
    sizes = np.array([max(length or 0.0, reach * scale), reach]) if reach else np.ones(2)
    if length is not None and speed * speed + 2 * acceleration * length < 0:
        event, direction = (lambda y: y[1]), -1  # it stops short: the run reports it
    elif length is not None:
        event, direction = (lambda y: y[0] - length), 1
    else:
        event, direction = (lambda y: y[1] - end), (-1 if acceleration < 0 else 1)
    mode = Mode("along the path", along_slope(acceleration), event, direction, scale=scale, sizes=lambda y: sizes)
    path = run.integrate([mode], np.array([0.0, speed]))
    run.record(f"{_who(stage)} moves along the path", ("distance", "speed"), path)
    travelled, final = (float(v) for v in path.y[-1])
    if length is not None and travelled < length * (1 - 1e-9):
        run.problems.append(f"{_who(stage)} comes to rest after {travelled:g} m, short of the {length:g} m of the path")
    return travelled, max(final, 0.0)


def _length(stage: Stage, run: Run, beta: float) -> float | None:
    """The path's length where it is known: the distance, or a ramp's height over the sine of its angle."""
    fields = stage.fields
    if "distance" in fields:
        return run.value(fields["distance"]) if run.known(fields["distance"]) else None
    if run.known(fields["height"]):
        return run.value(fields["height"]) / math.sin(beta)
    return None


def _output(stage: Stage, run: Run, beta: float, travelled: float, final: float) -> None:
    fields = stage.fields
    if "distance" in fields:
        run.output(fields["distance"], travelled)
    if "height" in fields:
        run.output(fields["height"], travelled * math.sin(beta))
    if "end_speed" in fields:
        run.output(fields["end_speed"], final)


SLOPE = Effect(
    "slope",
    "work and energy along a straight path: v_out^2 = v_in^2 + 2 g (h - mu_k cos(beta) d), up or down a slope, "
    "level, or a smooth ramp of height h",
    _FIELDS,
    _slope,
    _simulate_slope,
    _mistakes,
    force_law="gravity's component along the path, g sin(beta), and Coulomb kinetic friction mu_k g cos(beta) "
              "against the motion, from the start until the located event at the distance, the end speed or rest "
              "(v = 0); a ramp given by its height alone is integrated along a straight ramp at 30 degrees",
)
