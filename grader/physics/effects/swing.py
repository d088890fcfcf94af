"""A swing on a cord: a body on a light inextensible cord of length L, moving at v at the lowest point,
swings up to the angle theta from the vertical where it stops.

The cord pulls at right angles to the motion and does no work, so energy gives
``v**2 = 2 g L (1 - cos theta)``. The kernels use ``1 - cos theta = 2 sin(theta/2)**2``, so
``v = 2 sqrt(g L) sin(theta/2)``: ``1 - cos theta`` of a swing of 1e-4 degrees cancels to a few
digits in float64, the sine of the half angle keeps them all. Above 90 degrees the cord would go
slack before the body got there (a cord pulls, it cannot push): such a swing is refused.

Force law (simulation): a pendulum in polar coordinates, ``phi'' = -(g/L) sin phi``; the cord's
tension is the constraint force that keeps the body on the circle, and gravity acts along the
path. The swing starts at the lowest point with the speed and ends at the located event where it
stops (``phi' = 0``), or where the cord's tension would fall to zero (``L phi'**2 + g cos phi = 0``:
it goes slack, above 90 degrees, and the swing is refused). A swing whose speed is unknown runs from
the angle down: released there at rest, it reaches the lowest point with the speed it needs.

Mistakes: the height risen taken as ``L cos theta`` (from the pivot down) or as ``L sin theta``
instead of ``L (1 - cos theta)``.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from grader.model.quantities import ANGLE, LENGTH, SPEED
from grader.physics.effects.base import Condition, Effect, Field, Mistake, Relation, Stable

if TYPE_CHECKING:
    from grader.model.scene import Stage
    from grader.physics.record import Run
    from grader.physics.symbolic import Context

_FIELDS = (
    Field("body", "body", doc="the body on the cord"),
    Field("speed", "expr", doc="speed at the lowest point, >= 0", dimension=SPEED),
    Field("length", "expr", doc="length L of the cord, from the pivot to the body's centre", dimension=LENGTH),
    Field("angle", "expr", doc="angle from the vertical at which the body stops, 0 to 90 degrees", dimension=ANGLE),
)


def _energy(stage: Stage, ctx: Context, height: str = "1 - cos") -> list[Relation]:
    """The swing's relation; ``height`` "cos" or "sin" writes it as a student who takes the height
    risen as ``L cos theta`` or ``L sin theta`` does."""
    import sympy as sp

    body = stage.fields["body"]
    speed, length, angle = (ctx.sym(stage.fields[key]) for key in ("speed", "length", "angle"))
    g = ctx.gravity_symbol(stage)
    risen = {"1 - cos": 1 - sp.cos(angle), "cos": sp.cos(angle), "sin": sp.sin(angle)}[height]
    bottom_speed = sp.Pow(2 * g * length * risen, sp.Rational(1, 2), evaluate=False)
    solutions: dict[Any, Any] = {}
    stable: dict[Any, Any] = {}
    if isinstance(speed, sp.Symbol):
        solutions[speed] = bottom_speed
        if height == "1 - cos":  # 1 - cos(theta) = 2 sin(theta/2)**2: no cancellation at small angles
            stable[speed] = (Stable(2 * sp.sqrt(g * length) * sp.sin(angle / 2)),)
    if isinstance(length, sp.Symbol):
        solutions[length] = speed**2 / (2 * g * risen)
        if height == "1 - cos":
            stable[length] = (Stable(speed**2 / (4 * g * sp.sin(angle / 2) ** 2)),)
    if isinstance(angle, sp.Symbol) and height == "1 - cos":
        # sin(theta/2) = v/(2 sqrt(g L)), written with atan2: the kernels have no asin.
        reach = 2 * sp.sqrt(g * length)
        solutions[angle] = 2 * sp.atan2(speed, sp.sqrt((reach - speed) * (reach + speed)))
    elif isinstance(angle, sp.Symbol):  # as the mistake writes it: cos theta (or sin theta) = v**2/(2 g L)
        rise, across = speed**2, sp.sqrt((2 * g * length - speed**2) * (2 * g * length + speed**2))
        solutions[angle] = sp.atan2(across, rise) if height == "cos" else sp.atan2(rise, across)
    degrees = angle * 180 / sp.pi
    return [Relation(
        f"conservation of energy in the swing of {body} on its cord of length {stage.text('length')} (the cord "
        f"does no work): it rises L(1 − cos θ) to stop at {stage.text('angle')} from the vertical",
        speed, bottom_speed, solutions=solutions, stable=stable, general=False,
        requires=(
            Condition(sp.Ge(speed, 0), f"{body} must move at the lowest point ({stage.text('speed')} >= 0) to "
                      "swing up"),
            Condition(sp.Gt(length, 0), f"the cord's length {stage.text('length')} must be positive"),
            Condition(sp.Ge(angle, 0), "the swing angle is {value} degrees; it is measured from the vertical and "
                      "cannot be negative", subject=degrees),
            Condition(sp.Le(angle, sp.pi / 2), "the swing angle is {value} degrees: above 90 degrees the cord would "
                      f"go slack before {body} got there (a cord pulls, it cannot push), and {body} would leave the "
                      "circle", subject=degrees),
        ))]


def _swing(stage: Stage, ctx: Context) -> list[Relation]:
    return _energy(stage, ctx)


def _mistakes(stage: Stage, ctx: Context) -> list[Mistake]:
    return [Mistake("swing.height_cos", "the height risen taken as L cos θ instead of L(1 − cos θ)",
                    tuple(_energy(stage, ctx, "cos"))),
            Mistake("swing.height_sin", "the height risen taken as L sin θ instead of L(1 − cos θ)",
                    tuple(_energy(stage, ctx, "sin")))]


def pendulum(g: float, length: float) -> Any:
    """The force law of the swing on a state ``[phi, phi']`` (angle from the vertical, its rate):
    gravity along the path; the cord's tension, along the cord, keeps the body on the circle."""
    def rhs(_: float, y: Any) -> Any:
        return np.array([y[1], -(g / length) * math.sin(y[0])])
    return rhs


def _simulate_swing(stage: Stage, run: Run) -> None:
    from grader.physics.integrate import Mode  # the simulator's part: loading a template needs none of it

    body, length, g = stage.fields["body"], run.value(stage.fields["length"]), run.gravity()
    if not run.known(stage.fields["speed"]) and run.known(stage.fields["angle"]):
        _swing_down(stage, run, length, g)
        return
    speed = run.value(stage.fields["speed"])
    run.uses("gravity")
    run.uses("cord tension (pendulum)")
    if speed <= 0 or length <= 0:
        if speed < 0 or length <= 0:
            run.problems.append(f"{body} does not move at the lowest point, so it cannot swing up" if speed < 0 else
                                f"the cord's length {length:g} m is not positive")
        run.output(stage.fields["angle"], 0.0)
        return
    period = math.sqrt(length / g)

    def stops_or_slackens(y: Any) -> float:
        # The first to reach zero: the rate (the swing stops), the tension per unit mass over g (the
        # cord goes slack), or the height left to the top (fast enough, the body loops the loop on a
        # taut cord); all start positive at the lowest point.
        return float(min(y[1] * period, math.cos(y[0]) + length * y[1] * y[1] / g, math.pi - y[0]))

    swing = Mode("swing", pendulum(g, length), stops_or_slackens, -1, scale=period)
    path = run.integrate([swing], np.array([0.0, speed / length]))
    run.record(f"{body} swings on its cord", ("angle", "rate"), path)
    angle, rate = (float(v) for v in path.y[-1])
    if math.cos(angle) + length * rate * rate / g <= rate * period:  # stopped by the tension, not the rate
        # Past the slack point the swing is no pendulum; the angle reported grows with the energy
        # left (so a search for a speed still brackets its root). Just above 90 degrees the cord
        # slackens as the body stops: within 1e-8 rad that is a swing to 90 degrees.
        angle += length * rate * rate / g
    if angle > math.pi / 2 + 1e-8:
        run.problems.append(f"the cord goes slack at {math.degrees(angle):.4g} degrees from the vertical: {body} "
                            "leaves the circle, so it does not swing up to a stop" if angle < math.pi else
                            f"{body} loops the loop on its cord: it does not swing up to a stop")
    run.output(stage.fields["angle"], angle)


def _swing_down(stage: Stage, run: Run, length: float, g: float) -> None:
    """Released at rest at the angle, the body swings down to the lowest point: its speed there."""
    from grader.physics.integrate import Mode

    angle = run.value(stage.fields["angle"])
    run.uses("gravity")
    run.uses("cord tension (pendulum)")
    if not 0 <= angle <= math.pi / 2:
        run.problems.append(f"the swing angle {math.degrees(angle):g} degrees is outside 0 to 90 degrees")
        run.output(stage.fields["speed"], math.nan)
        return
    if angle == 0:
        run.output(stage.fields["speed"], 0.0)
        return
    period = math.sqrt(length / g)
    scale = angle * np.array([1.0, 1.0 / period])
    down = Mode("swing down", pendulum(g, length), lambda y: y[0], -1, scale=period, sizes=lambda y: scale)
    path = run.integrate([down], np.array([angle, 0.0]))
    run.record(f"{stage.fields['body']} swings down on its cord", ("angle", "rate"), path)
    run.output(stage.fields["speed"], -float(path.y[-1][1]) * length)


SWING = Effect(
    "swing",
    "a body on a light cord of length L swings up from the lowest point to theta from the vertical: "
    "v^2 = 2 g L (1 - cos theta)",
    _FIELDS,
    _swing,
    _simulate_swing,
    _mistakes,
    force_law="a pendulum, phi'' = -(g/L) sin phi: gravity along the path, the cord's tension the constraint that "
              "keeps the body on the circle; from the lowest point until it stops (phi' = 0) or the cord would go "
              "slack (refused); with the speed unknown, released at rest at the angle and swung down",
)
