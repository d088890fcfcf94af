"""The figure of an impact followed by a slide to rest (see :mod:`grader.render.figures`, which chooses
the figure): two rows on one horizontal scale, the bodies at the impact above (the striking body's
velocity, the struck one at rest) and at rest below, with the skid mark from the point of impact and
its length dimensioned. The skid is to the variant's scale; the statement gives no car's length, so
each car is drawn as long as a 4.5 m car of 1500 kg scaled by the cube root of its mass (3.5 to 6 m).
"""

from __future__ import annotations

import math as _m

from grader.model.scene import Stage
from grader.render.drawing import Drawing
from grader.render.scene_view import SceneView
from grader.render.typst_text import string

WIDTH = 6.0  # cm the road may take (the figure's column is 7.6 cm, labels included)
CAR_LENGTH, CAR_MASS = 4.5, 1500.0  # m, kg: a typical car, what a car's drawn length is scaled from
ROW = 2.3  # cm between the road of the upper row (at the impact) and the lower (at rest)


def car_length(mass: float) -> float:
    """The drawn length (m) of a car of ``mass`` kg.

    >>> car_length(1500.0), car_length(1e9), round(car_length(1000.0), 3)
    (4.5, 6.0, 3.931)
    """
    if not (_m.isfinite(mass) and mass > 0):
        return CAR_LENGTH
    return min(6.0, max(3.5, CAR_LENGTH * _m.cbrt(mass / CAR_MASS)))


def skid(canvas: Drawing, scene: SceneView, impact: Stage, slide: Stage) -> bool:
    """The bodies of ``impact`` at the impact and at rest after ``slide``; False when it cannot be drawn."""
    first, second = impact.fields["bodies"]
    distance = scene.value(slide.fields["distance"])
    bodies = scene.template.scene.bodies
    if bodies[second].mass is None or not (_m.isfinite(distance) and distance >= 0):
        return False
    lengths = [car_length(scene.value(bodies[body].mass)) for body in (first, second)]
    scale = min(0.6, WIDTH / (sum(lengths) + distance))
    a, b = lengths[0] * scale, lengths[1] * scale
    d = distance * scale
    right = a + b + d + 0.3

    # At the impact: the cars touching, the striking one's velocity above it, the other at rest.
    canvas.ground(-0.3, right, ROW)
    tall = _body_height(scale)
    _car(canvas, 0.0, a, ROW, tall, None)
    _car(canvas, a, a + b, ROW, tall, None)
    before = impact.fields["before"].get(first)
    height = ROW + tall + 0.25
    lines, positive = scene.moving(before.n, (1.0, 0.0)) if before is not None else (["v"], None)
    canvas.velocity((a / 2 - 0.55, height + 0.15), (a / 2 + 0.55, height + 0.15), lines, positive)
    canvas.label((a / 2, height + 0.35), "s", lines)
    canvas.label((a + b / 2, height + 0.1), "s", ["v = 0"])
    for x, body in ((a / 2, first), (a + b / 2, second)):
        canvas.name((x, ROW + 0.2 + tall / 2), "c", body, [])
    canvas.label((-0.3, ROW + tall + 1.3), "w", [str(string("at the impact"))])
    given = [*scene.mass(first), *scene.mass(second), *scene.given(slide.fields["friction"])]
    canvas.label((a + b + 0.4, ROW + 0.15), "sw", given)

    # At rest: the skid mark from the point of impact, the cars where they stopped, the length dimensioned.
    canvas.ground(-0.3, right, 0.0)
    canvas.line((a, 0.04), (a + d, 0.04), width=3.0, gray=True)
    canvas.line((a, 0.0), (a, ROW), width=0.4, dash="dashed", gray=True)
    _car(canvas, d, d + a, 0.0, tall, None)
    _car(canvas, d + a, d + a + b, 0.0, tall, None)
    for x, body in ((d + a / 2, first), (d + a + b / 2, second)):
        canvas.name((x, 0.2 + tall / 2), "c", body, [])
    canvas.label((-0.3, tall + 0.9), "w", [str(string("at rest"))])
    horizontal_dimension(canvas, a, a + d, -0.55, scene.given(slide.fields["distance"]))
    return True


def _body_height(scale: float) -> float:
    return max(0.35, 1.4 * scale)


def _car(canvas: Drawing, x0: float, x1: float, road: float, height: float, dash: str | None) -> None:
    """A car from ``x0`` to ``x1`` on the road at height ``road``: a body ``height`` tall over two wheels."""
    wheel = 0.12
    canvas.rect((x0, road + 2 * wheel - 0.04), (x1, road + 2 * wheel - 0.04 + height), dash,
                "luma(235)" if dash is None else "none")
    for x in (x0 + 0.22 * (x1 - x0), x1 - 0.22 * (x1 - x0)):
        canvas.circle((x, road + wheel), wheel, dash, fill=dash is None)


def horizontal_dimension(canvas: Drawing, x0: float, x1: float, y: float, lines: list[str]) -> None:
    """A horizontal dimension line from ``x0`` to ``x1`` at height ``y``, labelled below."""
    middle = (x0 + x1) / 2
    if x1 - x0 > 0.6:
        canvas.arrow((middle, y), (x0, y), width=0.5, head=0.15)
        canvas.arrow((middle, y), (x1, y), width=0.5, head=0.15)
    else:  # too short for arrows inside: they point in from outside
        canvas.arrow((x0 - 0.4, y), (x0, y), width=0.5, head=0.15)
        canvas.arrow((x1 + 0.4, y), (x1, y), width=0.5, head=0.15)
    for x in (x0, x1):
        canvas.line((x, y - 0.12), (x, y + 0.12), width=0.4)
    canvas.label((middle, y - 0.12), "n", lines)
