"""The figure of a projectile's flight to a wall and back to the ground (see :mod:`grader.render.figures`,
which chooses it): the ground, the wall, the point of release with its height and the throw's velocity
at its angle, and the path: solid to the wall, dashed from the wall to the ground. Given lengths are
drawn to the variant's scale and dimensioned with their values; asked ones (the height where the ball
strikes the wall, where it lands) are drawn but not to scale, and dimensioned by their names only: the
path leaves at the throw's angle and bends down to a height chosen without the answer, so nothing asked
can be measured off the page.
"""

from __future__ import annotations

import math as _m
from collections.abc import Sequence
from itertools import pairwise

from grader.model.scene import Stage
from grader.render.drawing import Drawing, Point
from grader.render.scene_view import SceneView
from grader.render.skid import horizontal_dimension
from grader.render.typst_text import string

WIDTH, HEIGHT = 5.6, 3.6  # cm the path may take at most


def flight_time(vy: float, drop: float, g: float) -> float:
    """The later root of ``drop + vy t - g t**2/2 = 0`` (the landing), without cancellation.

    >>> round(flight_time(0.0, 4.905, 9.81), 12), round(flight_time(-3.0, 1e-12, 9.81) * 3e12, 9)
    (1.0, 1.0)
    """
    root = _m.sqrt(vy * vy + 2 * g * drop)
    return (vy + root) / g if vy >= 0 else 2 * drop / (root - vy)


def _path(x0: float, direction: float, y0: float, vx: float, vy: float, g: float, duration: float) -> list[Point]:
    steps = 32
    return [(x0 + direction * vx * duration * i / steps,
             y0 + vy * duration * i / steps - g * (duration * i / steps) ** 2 / 2) for i in range(steps + 1)]


def _drawn_hit(h0: float, slope: float, distance: float) -> float:
    """The height at which an asked strike on the wall is drawn: a little over half the height the throw
    aims at, whatever the speed (which decides the true one), so the figure does not give it away."""
    return 0.55 * max(h0 + slope * distance, 0.2 * distance)


def _bent(h0: float, slope: float, distance: float, end: float) -> list[Point]:
    """A parabola from ``(0, h0)`` leaving at ``slope`` and reaching ``end`` at ``distance``: the path's
    shape, not to scale."""
    bend = (h0 + slope * distance - end) / distance ** 2
    return [(distance * i / 32, h0 + slope * distance * i / 32 - bend * (distance * i / 32) ** 2) for i in range(33)]


def _falling(wall: float, start: float, reach: float) -> list[Point]:
    """A half parabola from ``start`` high on the wall down to the ground ``reach`` from it: the rebound's
    shape, not to scale."""
    return [(wall - reach * i / 32, start * (1 - (i / 32) ** 2)) for i in range(33)]


def trajectory(canvas: Drawing, scene: SceneView, to_wall: Stage, to_ground: Stage | None,
               impact: Stage | None = None) -> bool:
    """The flight ``to_wall`` (x toward the wall), the ``impact`` there and, after the rebound, ``to_ground``
    (x away from it)."""
    g = scene.values.get("g", _m.nan)
    vx, vy, h0, distance = (scene.value(to_wall.fields[key]) for key in ("horizontal", "vertical", "height",
                                                                          "distance"))
    if not all(_m.isfinite(v) for v in (g, vx, vy, h0, distance)) or vx <= 0 or distance <= 0:
        return False
    hit_given = scene.is_given(to_wall.fields["end_height"])
    before = _path(0.0, 1.0, h0, vx, vy, g, distance / vx) if hit_given else \
        _bent(h0, vy / vx, distance, _drawn_hit(h0, vy / vx, distance))
    after: list[Point] = []
    if to_ground is not None:
        ux, uy, start = (scene.value(to_ground.fields[key]) for key in ("horizontal", "vertical", "height"))
        if hit_given and scene.is_given(to_ground.fields["distance"]):
            if all(_m.isfinite(v) for v in (ux, uy, start)) and start >= 0:
                after = _path(distance, -1.0, start, ux, uy, g, flight_time(uy, start, g))
        else:
            land = scene.value(to_ground.fields["distance"])
            shown = land if scene.is_given(to_ground.fields["distance"]) and _m.isfinite(land) else 0.6 * distance
            after = _falling(distance, before[-1][1], shown)
    points = before + after
    low_x, top = min(x for x, _ in points), max(y for _, y in points)
    if top <= 0:
        return False
    scale = min(WIDTH / (distance - min(0.0, low_x)), HEIGHT / top)

    def at(point: Point) -> Point:
        return point[0] * scale, point[1] * scale

    left, wall, hit = min(0.0, low_x) * scale, distance * scale, before[-1][1] * scale
    canvas.ground(left - 0.5, wall, 0.0)
    canvas.line((wall, 0.0), (wall, top * scale + 0.3), width=1.0)
    y = 0.15
    while y < top * scale + 0.3:
        canvas.line((wall, y), (wall + 0.16, y + 0.16), width=0.4)
        y += 0.25
    for path, dash in ((before, None), (after, "dashed")):
        if path:
            drawn = [at(p) for p in path]
            canvas.path(drawn, width=0.8, dash=dash)
            canvas.strokes += list(pairwise(drawn))  # labels keep clear of the path
    if after:  # where it lands
        canvas.circle(at(after[-1]), 0.09, fill=True)
    canvas.circle((wall - 0.09, hit), 0.09, fill=True)
    _release(canvas, scene, to_wall, h0 * scale, _m.atan2(vy, vx), (left, top * scale + 0.3), min(1.1, 0.7 * wall))
    canvas.dimension((wall + 0.5, 0.0), (wall + 0.5, hit), scene.given(to_wall.fields["end_height"]), "right")
    canvas.line((wall, hit), (wall + 0.65, hit), width=0.3)
    horizontal_dimension(canvas, 0.0, wall, -0.5, scene.given(to_wall.fields["distance"]))
    if after and to_ground is not None:
        horizontal_dimension(canvas, after[-1][0] * scale, wall, -1.25, scene.given(to_ground.fields["distance"]))
    body = [str(string(to_wall.fields["body"]))]  # named where it strikes, clear of the paths and dimensions
    spots = [((wall - 0.3, hit + 0.2), "se"), ((wall - 0.3, hit - 0.2), "ne"), ((wall - 0.3, hit + 0.6), "se"),
             ((wall - 0.3, hit - 0.6), "ne"), ((wall * 0.5, -0.9), "n")]
    canvas.name(*next((spot for spot in spots if canvas.fits(*spot, body)), spots[-1]), to_wall.fields["body"])
    restitution = _restitution(scene, impact)
    if restitution:
        canvas.name((wall + 0.3, max(top * scale, hit + 0.9) + 0.2), "w", restitution[-1], restitution[:-1])
    return True


def _release(canvas: Drawing, scene: SceneView, stage: Stage, height: float, angle: float, corner: Point,
             length: float) -> None:
    """The thrower's point at ``height`` (cm) above the ground, dimensioned, and the throw's velocity (an
    arrow ``length`` cm long), labelled beside it, or at ``corner`` (above the path) where the path leaves
    no room."""
    canvas.circle((0.0, height), 0.09, fill=True)
    if height > 0:
        canvas.line((0.0, 0.0), (0.0, height), width=0.4, dash="dashed", gray=True)
        canvas.dimension((-0.35, 0.0), (-0.35, height), scene.given(stage.fields["height"]), "left")
    tip = (length * _m.cos(angle), height + length * _m.sin(angle))
    lines = _launch(scene, stage)
    canvas.velocity((0.0, height), tip, lines[:1])
    if angle > 0.02:  # the angle from the horizontal, marked
        canvas.line((0.0, height), (0.75 * length, height), width=0.4, dash="dashed", gray=True)
        canvas.arc((0.0, height), 0.55 * length, 0.0, angle)
    places = [((-0.15, height + 0.2), "se"), ((-0.5, height + 0.1), "e")]
    spot, anchor = next((p for p in places if canvas.fits(*p, lines)), (corner, "sw"))
    canvas.label(spot, anchor, lines)


def _launch(scene: SceneView, stage: Stage) -> Sequence[str]:
    """The velocity of the throw as the statement gives it: ``v_0 = 15.0 m/s`` and ``alpha = 25°``, or its
    horizontal velocity where it starts level (thrown horizontally, or leaving a wall)."""
    for other in scene.template.scene.stages:
        if other.effect == "velocity" and {other.fields["n"], other.fields["t"]} == {stage.fields["horizontal"],
                                                                                      stage.fields["vertical"]}:
            return [*scene.given(other.fields["speed"]), *scene.given(other.fields["angle"])]
    return scene.moving(stage.fields["horizontal"], (1.0, 0.0))[0]


def _restitution(scene: SceneView, impact: Stage | None) -> list[str]:
    """``e = 0.7`` and the wall's name: of ``impact``, or of the scene's first impact."""
    for stage in [impact] if impact is not None else scene.template.scene.stages:
        if stage.effect == "impact":
            return [*scene.given(stage.fields["restitution"]), stage.fields["bodies"][1]]
    return []
