"""The figure of a ``bounces`` stage: a body dropped onto a floor, bouncing until it rests, to scale.

Heights to the scale of the drop height, and time along the floor to one scale too, so each arc is
the parabola the body flies (its width grows as the square root of its height): the decay the series
sums is what the reader sees. The bounce whose rebound height is asked is marked with its name only.
"""

from __future__ import annotations

import math as _m

from grader.model.scene import Stage
from grader.render.drawing import Drawing
from grader.render.scene_view import SceneView
from grader.render.typst_math import math

TALL, WIDE = 3.8, 6.4  # cm: the drop height, and the time until the last arc drawn
SMALLEST = 0.04  # arcs lower than this share of the drop height are left out (they would be a line)


def bounce_series(canvas: Drawing, scene: SceneView, stage: Stage) -> bool:
    """The drop and the decaying arcs; False when the numbers cannot be drawn."""
    body, floor = stage.fields["bodies"]
    h0, e = scene.value(stage.fields["height"]), scene.value(stage.fields["restitution"])
    count = scene.value(stage.fields["count"]) if "count" in stage.fields else 0.0
    if not (_m.isfinite(h0) and h0 > 0 and _m.isfinite(e) and 0 <= e < 1 and _m.isfinite(count)):
        return False
    ratio = e * e
    # The arcs that show (at most 7), and always the asked one (up to the 12th).
    shown = sum(1 for k in range(1, 8) if ratio**k >= SMALLEST)
    arcs = [h0 * ratio**k for k in range(1, min(max(int(count), shown), 12) + 1)]
    # Time to scale: the fall takes sqrt(h0), each arc 2 sqrt(h) (in units of sqrt(2/g)).
    span = _m.sqrt(h0) + sum(2 * _m.sqrt(h) for h in arcs)
    x_scale, y_scale = WIDE / span, TALL / h0
    x0, radius = 0.9, 0.18
    canvas.circle((x0, TALL + radius), radius)
    canvas.name((x0, TALL + 2 * radius + 0.12), "s", body, [])
    canvas.dimension((0.3, 0.0), (0.3, TALL), scene.given(stage.fields["height"]), "left")
    fall = _m.sqrt(h0) * x_scale
    canvas.path([(x0 + fall * (i / 16), TALL * (1 - (i / 16) ** 2)) for i in range(17)], width=0.5, dash="dashed")
    x = x0 + fall
    for number, height in enumerate(arcs, 1):
        width, top = 2 * _m.sqrt(height) * x_scale, height * y_scale
        canvas.path([(x + width * i / 20, top * (1 - (2 * i / 20 - 1) ** 2)) for i in range(21)], width=0.5,
                    dash="dashed")
        if number == int(count) and "rebound" in stage.fields:
            apex = x + width / 2
            canvas.dimension((apex, 0.0), (apex, top), [], "right")
            canvas.label((apex + 0.12, top + 0.3), "sw", [math(stage.fields["rebound"])])
        if number <= 3 or number == int(count):  # the impact that starts the arc
            canvas.label((x, -0.12), "n", [str(number)])
        x += width
    canvas.ground(0.0, max(x, x0 + fall) + 0.4, 0.0)
    canvas.name((x + 0.55, -0.05), "w", floor, [])  # past the floor's end: clear of the arcs
    canvas.label((x0 + fall + 0.15, TALL * 0.75), "w", scene.given(stage.fields["restitution"]))
    return True
