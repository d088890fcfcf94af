"""The figure of a ``swing`` stage: a body hanging from a cord, struck (or not) at the lowest point, and
the arc it swings up along to its greatest angle, to scale.

The cord is drawn at a fixed length; the angle is the variant's own, so a swing of 8 degrees and one of
40 look as they should. The body at rest at the lowest point is dashed, at the top of its swing solid.
A body that strikes it (an ``impact`` stage before the swing) comes in from the left along the
horizontal, with its velocity labelled as the statement names it.
"""

from __future__ import annotations

import math as _m

from grader.model.scene import Stage
from grader.render.drawing import PARTICLE, Drawing
from grader.render.scene_view import SceneView
from grader.render.typst_math import math

CORD = 3.6  # cm: the cord's length on the page
HALF_WIDTH, HALF_HEIGHT = 0.42, 0.3  # cm: the block hanging from it (a sphere: radius HALF_HEIGHT)
ASKED_ANGLE = _m.radians(35)  # how an asked angle is drawn


def swing_figure(canvas: Drawing, scene: SceneView, swing: Stage, impact: Stage | None) -> bool:
    """The pivot, the cord at rest and at its greatest angle, the arc between, and the striking body;
    False when the angle cannot be drawn."""
    body = swing.fields["body"]
    theta = scene.value(swing.fields["angle"])
    if not (_m.isfinite(theta) and 0 <= theta <= _m.pi / 2):
        return False
    if not scene.is_given(swing.fields["angle"]):
        theta = ASKED_ANGLE  # an asked angle is drawn, not to scale: the figure must not give it away
    canvas.ground(-0.9, 0.9, 0.0, below=False)  # short: at 90 degrees the block reaches the pivot's height
    canvas.circle((0.0, 0.0), 0.06)
    low = (0.0, -CORD)
    high = (CORD * _m.sin(theta), -CORD * _m.cos(theta))
    shape = scene.shape(body, "block")
    reach = HALF_WIDTH if shape == "block" else HALF_HEIGHT if shape == "sphere" else PARTICLE  # right of centre
    canvas.line((0.0, 0.0), (low[0], low[1] + min(reach, HALF_HEIGHT)), width=0.4, dash="dashed", gray=True)
    canvas.body_shape(shape, low, (HALF_WIDTH, HALF_HEIGHT), "dashed", filled=False)
    canvas.line((0.0, 0.0), high, width=0.6)
    canvas.body_shape(shape, high, (HALF_WIDTH, HALF_HEIGHT))
    canvas.name((high[0] + reach + 0.12, high[1]), "w", body, [*scene.mass(body)])
    steps = max(6, int(theta / 0.05))
    canvas.path([(CORD * _m.sin(theta * i / steps), -CORD * _m.cos(theta * i / steps)) for i in range(steps + 1)],
                width=0.4, dash="dashed")
    mark = 0.9
    if theta > 0.02:
        canvas.arc((0.0, 0.0), mark, -_m.pi / 2, -_m.pi / 2 + theta)
    # The angle's name left of the vertical, the cord's length right of the cord: neither crosses a line.
    canvas.label((-0.12, -mark), "e", scene.given(swing.fields["angle"]))
    middle, normal = (0.5 * high[0], 0.5 * high[1]), (_m.cos(theta), _m.sin(theta))  # normal: away from the arc
    steep = theta < _m.pi / 4
    canvas.label((middle[0] + 0.25 * normal[0], middle[1] + 0.25 * normal[1]), "w" if steep else "sw",
                 scene.given(swing.fields["length"]))
    if impact is not None:
        _striker(canvas, scene, impact, low)
    return True


def _striker(canvas: Drawing, scene: SceneView, impact: Stage, target: tuple[float, float]) -> None:
    """The first body of the impact, small, coming in from the left at the block's height."""
    first = impact.fields["bodies"][0]
    x = target[0] - HALF_WIDTH - 1.9
    shape = scene.template.scene.bodies[first].shape
    if shape is None:  # a slug, as a bullet is drawn
        canvas.rect((x - 0.2, target[1] - 0.06), (x + 0.2, target[1] + 0.06), fill="luma(120)")
    else:
        canvas.body_shape(shape, (x, target[1]), (0.2, 0.15))
    canvas.name((x, target[1] - (0.15 if shape is None or shape == "particle" else 0.25)), "n", first,
                [*scene.mass(first)])
    velocity = impact.fields["before"].get(first)
    lines = [math(velocity.n)] if velocity is not None else []
    canvas.velocity((x + 0.35, target[1]), (x + 1.35, target[1]), lines, (1.0, 0.0), width=0.7, head=0.18)
    if lines:
        canvas.label((x + 0.85, target[1] + 0.15), "s", lines)
