"""The panels of direct impacts of bodies on a line (see :mod:`grader.render.panels`), and of bodies
side by side, named: blocks whose areas follow the masses (spheres, or particles, where the scene's
bodies say so), each with its velocity before as an arrow the way it moves, lengths in the ratio of the
speeds.
"""

from __future__ import annotations

import math as _m
from collections.abc import Sequence

from grader.model.scene import Stage, Velocity
from grader.render.drawing import CHAR, LINE, PARTICLE, Drawing, Point
from grader.render.scene_view import SceneView, find_stage
from grader.render.typst_text import body_name, string


def _line_of_bodies(impacts: Sequence[Stage]) -> list[str]:
    """The bodies of direct impacts in the order they are struck: ``[1, 2]`` then ``[2, 3]`` is 1, 2, 3."""
    order: list[str] = []
    for stage in impacts:
        order += [body for body in stage.fields["bodies"] if body not in order]
    return order


def direct(canvas: Drawing, scene: SceneView, impacts: Sequence[Stage]) -> bool:
    """Bodies on a line in the order they are struck, blocks whose areas follow the masses (a fixed
    one a wall); above each its velocity before it is first struck, an arrow the way it moves with
    lengths in the ratio of the speeds, or ``v = 0``."""
    bodies = _line_of_bodies(impacts)
    before = {body: stage.fields["before"].get(body) for stage in reversed(impacts) for body in stage.fields["bodies"]}
    masses = {b: scene.value(scene.template.scene.bodies[b].mass) for b in bodies
              if scene.template.scene.bodies[b].mass is not None}
    finite = [m for m in masses.values() if _m.isfinite(m) and m > 0]
    mean = _m.exp(sum(_m.log(m) for m in finite) / len(finite)) if finite else 1.0
    # Sides clamped to 0.77..2.2 cm: the smallest still holds its name, the largest fits the column.
    sides = {b: 1.1 * min(2.0, max(0.7, _m.sqrt(m / mean))) if _m.isfinite(m) and m > 0 else 1.1
             for b, m in masses.items()}
    speeds = [abs(scene.value(v.n)) for v in before.values() if v is not None]
    fastest = max((v for v in speeds if _m.isfinite(v)), default=0.0)
    gap = 2.2 if len(bodies) < 3 else 1.9
    # Balls that hang from cords (each swings in the scene) meet with their centres level, on no floor.
    stages = scene.template.scene.stages
    hanging = all(find_stage(stages, "swing", body=body) is not None for body in bodies)
    level = max(sides.values(), default=1.1) / 2 if hanging else None
    if level is not None:  # first, so that the spheres cover it
        end = sum(sides.values()) + gap * (len(bodies) - 1)
        canvas.line((-0.3, level), (end + 0.3, level), width=0.4, dash="dashed", gray=True)
    # Spheres are all named inside, or all above when one is too small for its name.
    inside = all(len(body_name(b)) * CHAR < 0.8 * sides[b] for b in masses if scene.shape(b, "block") == "sphere")
    x = 0.0
    for index, body in enumerate(bodies):
        if index:
            x += gap
        if body not in masses:  # a wall, hatched on its far side
            canvas.line((x, 0.0), (x, 1.8), width=1.0)
            for y in (0.15, 0.4, 0.65, 0.9, 1.15, 1.4, 1.65):
                canvas.line((x, y), (x + 0.16, y + 0.16), width=0.4)
            canvas.name((x + 0.3, 1.0), "w", body, [])
            continue
        side, shape = sides[body], scene.shape(body, "block")
        top = _body(canvas, shape, body, x, side, side / 2 if level is None else level, inside)
        canvas.label((x + side / 2, -0.12), "n", scene.mass(body))
        _horizontal_velocity(canvas, scene, (x + side / 2, top + 0.3), before[body], fastest)
        x += side
    if level is None:
        canvas.line((-0.3, 0.0), (x + 0.3, 0.0), width=1.0)
    return True


def _body(canvas: Drawing, shape: str, body: str, x: float, side: float, middle: float, inside: bool) -> float:
    """A body on the line from ``x``, ``side`` wide, its centre ``middle`` high: a block named inside, a
    sphere inside or above it (``inside``), a particle (a dot) named above; the height its velocity's arrow
    goes above."""
    centre = (x + side / 2, middle if shape != "particle" else PARTICLE)
    canvas.body_shape(shape, centre, (side / 2, side / 2))
    top = centre[1] + (side / 2 if shape != "particle" else PARTICLE)
    if shape == "block" or (shape == "sphere" and inside):
        canvas.name(centre, "c", body, [])
        return top
    canvas.name((centre[0], top + 0.1), "s", body, [])
    return top + 0.1 + LINE


def _horizontal_velocity(canvas: Drawing, scene: SceneView, at: Point, velocity: Velocity | None,
                         fastest: float) -> None:
    """Above a body: an arrow centred on ``at`` the way it moves, 1.6 cm for the fastest body of the
    figure (at least 0.5 cm), labelled with its velocity as given, or its magnitude when the statement gives
    it negative; ``v = 0`` for a body at rest."""
    given = velocity.n if velocity is not None else None
    value = scene.value(given) if given is not None else 0.0
    if given is None or not (_m.isfinite(value) and value != 0 and fastest > 0):
        canvas.label((at[0], at[1] - 0.2), "s", ["v = 0"] if given is None else scene.given(given))
        return
    half = max(0.25, 0.8 * abs(value) / fastest) * (1 if value > 0 else -1)
    lines, positive = scene.moving(given, (1.0, 0.0))
    canvas.velocity((at[0] - half, at[1]), (at[0] + half, at[1]), lines, positive)
    canvas.label((at[0], at[1] + 0.2), "s", lines)


def row(canvas: Drawing, scene: SceneView, bodies: Sequence[str]) -> None:
    """Bodies side by side, named, with their masses: the panel of stages that cannot be drawn otherwise."""
    x = 0.0
    for body in bodies:
        canvas.circle((x + 0.5, 0.5), 0.5)
        canvas.name((x + 0.5, 0.5), "c", body, [])
        canvas.label((x + 0.5, -0.1), "n", scene.mass(body) or [str(string("(fixed)"))])
        x += 1.8
