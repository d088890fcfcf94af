"""The panels of a body falling onto a surface or a pile and rising again (see :mod:`grader.render.panels`):
the body at its drop height, dashed at its rebound height, heights dimensioned (given ones to scale, an
asked one drawn but not to scale), and the path as arcs when it rebounds more than once.
"""

from __future__ import annotations

import math as _m
from collections.abc import Sequence

from grader.model.expr import Node
from grader.model.scene import Stage
from grader.render.drawing import PARTICLE, Drawing, Point
from grader.render.scene_view import SceneView
from grader.render.typst_text import string


def drop(canvas: Drawing, scene: SceneView, fall: Stage, impact: Stage | None, rise: Stage | None) -> bool:
    """A body at its drop height above a floor or a pile (or the ground, without an impact), and
    dashed at its rebound height."""
    first = fall.fields["body"]
    second = impact.fields["bodies"][1] if impact is not None else None
    drop = scene.value(fall.fields["height"])
    rebound = scene.value(rise.fields["height"]) if rise is not None else _m.nan
    if rise is not None and not scene.is_given(rise.fields["height"]) and _m.isfinite(rebound):
        rebound = 0.6 * drop  # an asked height is drawn, not to scale: the figure must not give it away
    heights = [h for h in (drop, rebound) if _m.isfinite(h) and h > 0]
    if not (_m.isfinite(drop) and drop > 0):
        return False
    scale = 4.2 / max(heights)
    fixed = second is None or scene.template.scene.bodies[second].mass is None
    x_body, x_ghost = 2.6, 4.0

    # A ball onto a floor; falling alone or onto a pile, a block (as the other panels draw it).
    shape = scene.shape(first, "sphere" if fixed and second is not None else "block")
    half = {"sphere": (0.3, 0.3), "block": (0.4, 0.25), "particle": (PARTICLE, PARTICLE)}[shape]

    def body(x: float, bottom: float, dash: str | None) -> float:
        canvas.body_shape(shape, (x, bottom + half[1]), half, dash, filled=dash is None)
        return bottom + 2 * half[1]

    top = body(x_body, drop * scale, None)
    canvas.name((x_body, top + 0.15), "s", first, [*scene.mass(first)])
    canvas.line((x_body, 0), (x_body, drop * scale), width=0.4, dash="dashed", gray=True)
    canvas.arrow((x_body, drop * scale * 0.55), (x_body, drop * scale * 0.45), width=0.4, head=0.16)
    canvas.dimension((1.7, 0), (1.7, drop * scale), scene.given(fall.fields["height"]), "left")
    canvas.line((1.55, drop * scale), (x_body - 0.35, drop * scale), width=0.3)
    if rise is not None and _m.isfinite(rebound) and rebound >= 0:
        body(x_ghost, rebound * scale, "dashed")
        canvas.line((x_ghost, 0), (x_ghost, rebound * scale), width=0.4, dash="dashed", gray=True)
        if rebound * scale > 0.5:
            canvas.arrow((x_ghost, rebound * scale * 0.45), (x_ghost, rebound * scale * 0.55), width=0.4, head=0.16)
        canvas.dimension((4.75, 0), (4.75, rebound * scale), scene.given(rise.fields["height"]), "right")
        canvas.line((x_ghost + 0.35, rebound * scale), (4.9, rebound * scale), width=0.3)
    moving = impact.fields["before"].get(second) if impact is not None and second is not None else None
    if fixed and moving is not None:  # a driven plate: a slab, with its velocity (n points down)
        canvas.rect((0.9, -0.35), (5.2, 0.0), fill="luma(215)")
        canvas.name((3.3, -0.4), "n", str(second), [])
        _vertical_velocity(canvas, scene, (5.75, -0.2), -scene.value(moving.n), moving.n)
    elif fixed:
        canvas.ground(0.9, 5.2, 0.0)
        if second is None:
            canvas.label((3.3, -0.3), "n", [str(string("ground"))])
        else:
            canvas.name((3.3, -0.3), "n", second, [])
    else:  # a pile: its top is the impact surface, driven into the ground
        canvas.rect((x_body - 0.45, -1.6), (x_body + 0.45, 0.0))
        canvas.ground(1.2, x_body - 0.45, -0.45)
        canvas.ground(x_body + 0.45, 5.0, -0.45)
        canvas.line((x_body + 0.45, 0.0), (4.9, 0.0), width=0.3, dash="dashed")
        canvas.name((x_body + 0.6, -1.05), "w", str(second), [*scene.mass(str(second))])
    return True


def _vertical_velocity(canvas: Drawing, scene: SceneView, at: Point, upward: float, given: Node) -> None:
    """An arrow through ``at`` the way a surface moves (up or down), labelled with what gives its velocity
    (``given``, along n, which points down): ``u`` for ``-u``, its magnitude when negative."""
    lines, positive = scene.moving(given, (0.0, -1.0))
    if not _m.isfinite(upward) or upward == 0:
        canvas.label(at, "w", [*lines, "(at rest)"])
        return
    sign = 1.0 if upward > 0 else -1.0
    canvas.velocity((at[0], at[1] - 0.45 * sign), (at[0], at[1] + 0.45 * sign), lines, positive)
    canvas.label((at[0] + 0.15, at[1]), "w", lines)


def bounces(canvas: Drawing, scene: SceneView, fall: Stage, rises: Sequence[Stage], surface: str) -> bool:
    """A body dropped onto a fixed surface and rebounding again and again: its path as arcs, the
    given heights to scale, an asked one drawn (not to scale) and labelled with its name only."""
    first = fall.fields["body"]
    heights = [fall.fields["height"], *(rise.fields["height"] for rise in rises)]
    values = [scene.value(h) for h in heights]
    known = [v for h, v in zip(heights, values, strict=True) if scene.is_given(h) and _m.isfinite(v) and v > 0]
    if not known:
        return False
    scale = 4.2 / max(known)
    drawn = []
    for index, (height, value) in enumerate(zip(heights, values, strict=True)):
        if scene.is_given(height) and _m.isfinite(value) and value >= 0:
            drawn.append(value * scale)
        else:  # asked: above the first rebound for the drop, between its neighbours for a rebound
            drawn.append(5.5 if index == 0 else 0.6 * drawn[-1])
    x, radius = 1.2, 0.3
    canvas.circle((x, drawn[0] + radius), radius)
    canvas.name((x, drawn[0] + 2 * radius + 0.15), "s", first, [*scene.mass(first)])
    canvas.line((x, 0.0), (x, drawn[0]), width=0.4, dash="dashed", gray=True)
    canvas.arrow((x, drawn[0] * 0.55), (x, drawn[0] * 0.45), width=0.4, head=0.16)
    canvas.dimension((0.4, 0.0), (0.4, drawn[0]), scene.given(heights[0]), "left")
    canvas.line((0.25, drawn[0]), (x - 0.35, drawn[0]), width=0.3)
    for height, top in zip(heights[1:], drawn[1:], strict=True):
        width = 1.6 + 0.6 * _m.sqrt(top)
        apex = x + width / 2
        canvas.path([(x + width * i / 24, top * (1 - (2 * i / 24 - 1) ** 2)) for i in range(25)], width=0.4,
                    dash="dashed")
        canvas.circle((apex, top + radius), radius, "dashed", fill=False)
        canvas.dimension((apex, 0.0), (apex, top), [], "right")
        canvas.label((apex + radius + 0.1, top + radius), "w", scene.given(height))
        x += width
    canvas.ground(0.0, x + 0.4, 0.0)
    canvas.name(((x + 1.2) / 2, -0.3), "n", surface, [])
    return True
