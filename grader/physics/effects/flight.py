"""Free fall from rest and rise to a height: ``v = sqrt(2 g h)`` under gravity alone.

Force law: gravity, ``a = -g`` upward. The simulation starts the body at the height (fall) or at
the bottom with the speed (rise) and ends at the located event: reaching the bottom, or the apex.

Mistakes: ``v = sqrt(g h)`` or ``v = 2 g h``; the other system's ``g`` (32.2 in a problem in metres,
9.81 in one in feet); a height printed in mm used as metres.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from grader.model.expr import Sym
from grader.model.quantities import LENGTH, SPEED
from grader.physics.effects.base import Condition, Effect, Field, Mistake, Relation

if TYPE_CHECKING:
    from grader.model.scene import Stage
    from grader.physics.record import Run
    from grader.physics.symbolic import Context

_FIELDS = (
    Field("body", "body", doc="the body that moves"),
    Field("height", "expr", doc="height fallen or risen (m)", dimension=LENGTH),
    Field("speed", "expr", doc="speed at the bottom of the path, >= 0", dimension=SPEED),
)


def _energy(stage: Stage, ctx: Context, verb: str, law: str = "sqrt(2gh)", g: Any = None,
            height_scale: Any = 1) -> list[Relation]:
    """The stage's relation: ``v = sqrt(2 g h)``, or as a student who makes a mistake writes it
    (``law`` ``sqrt(gh)`` or ``2gh``; another value of ``g``; the height scaled: mm read as m)."""
    import sympy as sp

    height, speed = ctx.sym(stage.fields["height"]), ctx.sym(stage.fields["speed"])
    g = ctx.gravity_symbol(stage) if g is None else g
    body = stage.fields["body"]
    used = height * height_scale
    bottom_speed = {"sqrt(2gh)": sp.Pow(2 * g * used, sp.Rational(1, 2), evaluate=False),
                    "sqrt(gh)": sp.Pow(g * used, sp.Rational(1, 2), evaluate=False), "2gh": 2 * g * used}[law]
    solutions = {}
    if isinstance(height, sp.Symbol):
        solutions[height] = {"sqrt(2gh)": speed**2 / (2 * g), "sqrt(gh)": speed**2 / g,
                             "2gh": speed / (2 * g)}[law] / height_scale
    if isinstance(speed, sp.Symbol):
        solutions[speed] = bottom_speed
    return [Relation(
        label=f"conservation of energy, {body} {verb} through {stage.text('height')}",
        lhs=speed, rhs=bottom_speed,
        solutions=solutions,
        requires=(
            Condition(sp.Ge(height, 0), f"the {verb} height {stage.text('height')} must not be negative"),
            Condition(sp.Ge(speed, 0), f"{body} must move {'down' if verb == 'falls' else 'up'} "
                      f"({stage.text('speed')} >= 0) to {verb.rstrip('s')} through a height"),
        ),
    )]


def _free_fall(stage: Stage, ctx: Context) -> list[Relation]:
    return _energy(stage, ctx, "falls")


def _rise(stage: Stage, ctx: Context) -> list[Relation]:
    return _energy(stage, ctx, "rises")


def _mistakes(stage: Stage, ctx: Context, verb: str) -> list[Mistake]:
    """A fall and a rise share their mistakes (one id each), so a student makes them in every flight stage."""
    import sympy as sp

    gravity = ctx.scene.gravity
    customary = gravity is not None and "ft" in gravity.text  # the problem's g is given in ft/s^2
    mistakes = [
        Mistake("flight.sqrt_gh", "v = √(gh) instead of v = √(2gh)", tuple(_energy(stage, ctx, verb, "sqrt(gh)"))),
        Mistake("flight.two_gh", "v = 2gh instead of v = √(2gh)", tuple(_energy(stage, ctx, verb, "2gh"))),
        # The other system's number for g, in this problem's units.
        Mistake("flight.g_metric", "g = 9.81 (the value in m/s²) in a problem in feet",
                tuple(_energy(stage, ctx, verb, g=sp.Rational(981, 100) * sp.Rational(381, 1250)))) if customary else
        Mistake("flight.g_customary", "g = 32.2 (the value in ft/s²) in a problem in metres",
                tuple(_energy(stage, ctx, verb, g=sp.Rational(161, 5)))),
    ]
    height = stage.fields["height"]
    unit = ctx.units.get(height.name) if isinstance(height, Sym) else None
    if unit is not None and unit.text == "mm":
        mistakes.append(Mistake("flight.mm_as_m", "the height in mm used as metres",
                                tuple(_energy(stage, ctx, verb, height_scale=1000))))
    return mistakes


def _fall_mistakes(stage: Stage, ctx: Context) -> list[Mistake]:
    return _mistakes(stage, ctx, "falls")


def _rise_mistakes(stage: Stage, ctx: Context) -> list[Mistake]:
    return _mistakes(stage, ctx, "rises")


def gravity(g: float) -> Any:
    """The force law of flight, per unit mass, on a state ``[height, velocity]`` (up positive)."""
    def rhs(_: float, y: Any) -> Any:
        return np.array([y[1], -g])
    return rhs


def _simulate_fall(stage: Stage, run: Run) -> None:
    from grader.physics.integrate import Mode  # the simulator's part: loading a template needs none of it

    height, g, body = run.value(stage.fields["height"]), run.gravity(), stage.fields["body"]
    run.uses("gravity")
    if height <= 0:
        if height < 0:
            run.problems.append(f"{body} cannot fall through a negative height")
        run.output(stage.fields["speed"], 0.0)
        return
    # The time scale only sets fixed step sizes; the motion itself is integrated.
    landing = Mode("free fall", gravity(g), lambda y: y[0], -1, scale=math.sqrt(2 * height / g))
    path = run.integrate([landing], np.array([height, 0.0]))
    run.record(f"{body} falls", ("height", "velocity"), path)
    run.output(stage.fields["speed"], -float(path.y[-1][1]))


def _simulate_rise(stage: Stage, run: Run) -> None:
    from grader.physics.integrate import Mode  # the simulator's part: loading a template needs none of it

    speed, g, body = run.value(stage.fields["speed"]), run.gravity(), stage.fields["body"]
    run.uses("gravity")
    if speed <= 0:
        if speed < 0:
            run.problems.append(f"{body} does not move up after the previous stage, so it cannot rise to "
                                f"{stage.text('height')}")
        # A body moving down at |v| is where a rise of -v^2/(2 g) would have started: continuing the
        # height below 0 keeps a search for e strictly monotone through a measured rise of 0, so it
        # finds the e at which the body just stops (the closed form's), not any e at which it
        # moves on down. The run has a problem then, so this never becomes an answer.
        run.output(stage.fields["height"], -speed * speed / (2 * g))
        return
    apex = Mode("rise", gravity(g), lambda y: y[1], -1, scale=speed / g)
    path = run.integrate([apex], np.array([0.0, speed]))
    run.record(f"{body} rises", ("height", "velocity"), path)
    run.output(stage.fields["height"], float(path.y[-1][0]))


FREE_FALL = Effect("free_fall", "a body falls from rest through a height: v = sqrt(2 g h)", _FIELDS, _free_fall,
                   _simulate_fall, _fall_mistakes,
                   force_law="gravity alone, a = -g upward, from rest at the height until the located event of "
                             "reaching the bottom")
RISE = Effect("rise", "a body moving up at a speed rises to a height where it stops: h = v^2/(2 g)", _FIELDS, _rise,
              _simulate_rise, _rise_mistakes,
              force_law="gravity alone, a = -g upward, from the bottom at the speed until the located event of "
                        "the apex (velocity 0)")
