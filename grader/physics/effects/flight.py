"""Free fall from rest and rise to a height: ``v = sqrt(2 g h)`` under gravity alone.

Force law: gravity, ``a = -g`` upward. The simulation starts the body at the height (fall) or at
the bottom with the speed (rise) and ends at the located event: reaching the bottom, or the apex.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from grader.model.units import LENGTH, SPEED
from grader.physics.effects.base import Condition, Effect, Field, Relation

if TYPE_CHECKING:
    from grader.model.scene import Stage
    from grader.physics.run import Run
    from grader.physics.symbolic import Context

_FIELDS = (
    Field("body", "body", doc="the body that moves"),
    Field("height", "expr", doc="height fallen or risen (m)", dimension=LENGTH),
    Field("speed", "expr", doc="speed at the bottom of the path, >= 0", dimension=SPEED),
)


def _energy(stage: Stage, ctx: Context, verb: str) -> list[Relation]:
    import sympy as sp

    height, speed = ctx.sym(stage.fields["height"]), ctx.sym(stage.fields["speed"])
    g = ctx.gravity_symbol(stage)
    body = stage.fields["body"]
    solutions = {}
    if isinstance(height, sp.Symbol):
        solutions[height] = speed**2 / (2 * g)
    if isinstance(speed, sp.Symbol):
        solutions[speed] = sp.Pow(2 * g * height, sp.Rational(1, 2), evaluate=False)
    return [Relation(
        label=f"conservation of energy, {body} {verb} through {stage.text('height')}",
        lhs=speed, rhs=sp.Pow(2 * g * height, sp.Rational(1, 2), evaluate=False),
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
                   _simulate_fall)
RISE = Effect("rise", "a body moving up at a speed rises to a height where it stops: h = v^2/(2 g)", _FIELDS, _rise,
              _simulate_rise)
