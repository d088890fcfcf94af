"""The panels of the effects of work, energy and momentum in a plane (issue 25's catalogue): a spring, a
slope, two bodies that stick, a body that separates in two, and the impulse on a body. Each draws one stage
(a spring also the impact before it that sets its block moving) and names only its stage's bodies.

As every panel (:mod:`grader.render.panels`): a given value is labelled with the variant's number and drawn
to scale; an asked one is drawn, not to scale, and labelled with its name only; a velocity is an arrow the
way the body moves, labelled with its magnitude.
"""

from __future__ import annotations

import math as _m

from grader.model.expr import Node, Num, Op, Sym
from grader.model.scene import Stage, Velocity
from grader.render.drawing import Drawing, Point
from grader.render.scene_view import SceneView
from grader.render.skid import horizontal_dimension
from grader.render.typst_text import string


def magnitude(node: Node) -> Node:
    """A velocity component as a magnitude: ``-v_b`` is an arrow the negative way labelled ``v_b``."""
    return node.args[0] if isinstance(node, Op) and node.op == "neg" else node


def _said(words: str) -> str:
    """Words before a value in a math label, the colon theirs: ``"before:" v = 0``, not ``"before" : v``
    (in math a bare colon is a relation, spaced as one)."""
    return str(string(f"{words}:"))


def _is_zero(node: Node | None) -> bool:
    return node is None or (isinstance(node, Num) and node.value == 0)


def _components(scene: SceneView, velocity: Velocity | None) -> tuple[float, float]:
    if velocity is None:
        return 0.0, 0.0
    n, t = scene.value(velocity.n), scene.value(velocity.t)
    return (n if _m.isfinite(n) else 0.0), (t if _m.isfinite(t) else 0.0)


def _speed_lines(scene: SceneView, velocity: Velocity | None) -> list[str]:
    """The label of a velocity's arrow: its one component's magnitude, or both components as given."""
    if velocity is None:
        return ["v = 0"]
    parts = [node for node in (velocity.n, velocity.t) if node is not None and not _is_zero(node)]
    if not parts:
        return ["v = 0"]
    if len(parts) == 1:
        return scene.given(magnitude(parts[0]))
    return [line for node in parts for line in scene.given(node)]


def _velocity_arrow(canvas: Drawing, scene: SceneView, at: Point, velocity: Velocity | None, length: float,
                    into: bool, anchor_side: float = 1.0) -> None:
    """An arrow ``length`` cm long for ``velocity`` (n east, t north) ending at ``at`` (``into``) or from
    it, labelled beside its middle; a body at rest: ``v = 0`` beside ``at``."""
    n, t = _components(scene, velocity)
    size = _m.hypot(n, t)
    if size == 0:
        canvas.label((at[0], at[1] + 0.45), "s", ["v = 0"])
        return
    ux, uy = n / size, t / size
    tail = (at[0] - ux * length, at[1] - uy * length) if into else at
    tip = at if into else (at[0] + ux * length, at[1] + uy * length)
    canvas.arrow(tail, tip)
    middle = ((tail[0] + tip[0]) / 2 - uy * 0.2 * anchor_side, (tail[1] + tip[1]) / 2 + ux * 0.2 * anchor_side)
    anchor = ("s" if ux * anchor_side >= 0 else "n") if abs(ux) >= abs(uy) else ("e" if uy * anchor_side > 0 else "w")
    canvas.label(middle, anchor, _speed_lines(scene, velocity))


def _coils(canvas: Drawing, a: Point, b: Point, turns: int = 7, amplitude: float = 0.18) -> None:
    """A spring from ``a`` to ``b``: a short straight end at each side, zigzag coils between."""
    dx, dy = b[0] - a[0], b[1] - a[1]
    length = _m.hypot(dx, dy) or 1.0
    ux, uy = dx / length, dy / length
    end = min(0.15, length / 6)
    points = [a, (a[0] + ux * end, a[1] + uy * end)]
    for i in range(1, 2 * turns):
        s = end + (length - 2 * end) * i / (2 * turns)
        side = amplitude * (1 if i % 2 else -1)
        points.append((a[0] + ux * s - uy * side, a[1] + uy * s + ux * side))
    points += [(b[0] - ux * end, b[1] - uy * end), b]
    canvas.path(points, width=0.7)


def _wall(canvas: Drawing, x: float, y0: float, y1: float) -> None:
    """A fixed wall at ``x``, hatched on its left."""
    canvas.line((x, y0), (x, y1), width=1.0)
    y = y0 + 0.1
    while y < y1:
        canvas.line((x, y), (x - 0.16, y - 0.16), width=0.4)
        y += 0.18


# --- spring -------------------------------------------------------------------------------------

def spring(canvas: Drawing, scene: SceneView, stage: Stage, impact: Stage | None) -> bool:
    """Horizontal: the wall, the spring at its natural length, the block (with what is stuck to it) against
    it moving toward the wall, the block dashed at the greatest compression, dimensioned; with the impact
    that sets it moving, the striking body coming in instead. Vertical: see :func:`_vertical_spring`."""
    if stage.fields.get("vertical", False):
        return _vertical_spring(canvas, scene, stage)
    block, stuck = stage.fields["body"], stage.fields.get("with")
    # The block dashed at the greatest compression stands clear of it at natural length (squeeze > width):
    # the two overlapping read as one block with a line through it.
    natural, width, height, squeeze = 2.8, 1.0, 0.8, 1.25
    canvas.ground(-0.6, natural + width + 2.3, 0.0)
    _wall(canvas, 0.0, 0.0, 1.6)
    _coils(canvas, (0.0, height / 2), (natural, height / 2))
    canvas.rect((natural, 0.0), (natural + width, height))
    canvas.name((natural + width / 2, height / 2), "c", block)
    canvas.rect((natural - squeeze, 0.0), (natural - squeeze + width, height), dash="dashed", fill="none")
    striker = impact.fields["bodies"][1] if impact is not None else None
    if stuck is not None:
        x = natural + width + (1.9 if impact is not None and striker == stuck else 0.2)
        canvas.circle((x + 0.12, height / 2), 0.12)
        canvas.name((x + 0.3, height / 2), "w", stuck)  # beside it: under it, the name sat on the floor
        if impact is not None and striker == stuck:  # it comes in toward the block, before the impact
            velocity = impact.fields.get("before", {}).get(stuck)
            canvas.arrow((x - 0.1, height / 2), (x - 1.3, height / 2))
            canvas.label((x - 0.7, height / 2 + 0.2), "s", _speed_lines(scene, velocity))
    if impact is None or striker != stuck:
        canvas.arrow((natural + width / 2 + 0.6, height + 0.4), (natural + width / 2 - 0.6, height + 0.4))
        canvas.label((natural + width / 2, height + 0.6), "s", scene.given(magnitude(stage.fields["speed"])))
    canvas.line((natural - squeeze, -0.15), (natural - squeeze, -0.75), width=0.4)
    canvas.line((natural, -0.15), (natural, -0.75), width=0.4)
    horizontal_dimension(canvas, natural - squeeze, natural, -0.6, scene.given(stage.fields["compression"]))
    canvas.label((0.15, height + 0.1), "sw", scene.given(stage.fields["stiffness"]))
    return True


def _vertical_spring(canvas: Drawing, scene: SceneView, stage: Stage) -> bool:
    """The spring standing on the ground, the platform on it at its static deflection below the natural
    length (dashed), what it carries on top moving down, the greatest compression dimensioned."""
    body, stuck, supports = stage.fields["body"], stage.fields.get("with"), stage.fields.get("supports")
    natural, deflection, width = 2.6, 0.5, 1.8
    top = natural - deflection if supports is not None else natural
    canvas.ground(-0.4, width + 2.2, 0.0)
    _coils(canvas, (width / 2, 0.0), (width / 2, top), amplitude=0.3)
    canvas.rect((0.0, top), (width, top + 0.25))
    canvas.name((width / 2 + 0.45, top - 0.35), "w", body)  # under it, by the coils: right of it, the lines out
    # to the static deflection's dimension ran through the name
    if stuck is not None:
        canvas.rect((width / 2 - 0.65, top + 0.25), (width / 2 + 0.65, top + 0.85))
        canvas.name((width / 2, top + 0.55), "c", stuck)
    lowest = top - 0.9
    canvas.line((-0.9, lowest), (width + 0.1, lowest), width=0.5, dash="dashed")
    canvas.arrow((width / 2, top + 1.9), (width / 2, top + 1.0))
    canvas.label((width / 2 + 0.15, top + 1.45), "w", scene.given(magnitude(stage.fields["speed"])))
    canvas.label((width / 2 + 0.35, top * 0.3), "w", scene.given(stage.fields["stiffness"]))
    x = width + 1.0  # close beside the platform: a strip gives the panel at most half its width
    if supports is not None:
        canvas.line((width, natural), (x + 0.1, natural), width=0.5, dash="dotted")  # the natural length
        canvas.line((width, top), (x + 0.1, top), width=0.3)
        named = stage.fields.get("static_deflection")
        canvas.dimension((x, top), (x, natural), scene.given(Sym(str(named))) if named else [], "right")
    compression = scene.given(stage.fields["compression"])
    canvas.line((-0.9, top if supports is None else natural), (-0.1, top if supports is None else natural),
                width=0.3, dash="dotted")
    canvas.dimension((-0.8, lowest), (-0.8, top if supports is None else natural), compression, "left")
    return True


# --- slope --------------------------------------------------------------------------------------

def slope(canvas: Drawing, scene: SceneView, stage: Stage) -> bool:
    """The path: at its angle (to scale when given) with the distance along it dimensioned, a smooth ramp
    from its height, or a level floor; a rough surface hatched with its friction coefficient; the body at
    the start with its speed the way it moves, and its speed at the end."""
    fields = stage.fields
    up = fields.get("direction", "down") == "up"
    if "angle" in fields:
        beta = scene.value(fields["angle"])
        beta = beta if scene.is_given(fields["angle"]) and _m.isfinite(beta) and 0 < beta < _m.pi / 2 \
            else _m.radians(30)
    elif "distance" in fields:
        beta = 0.0
    else:
        return _ramp(canvas, scene, stage)
    length = 4.2
    ux, uy = _m.cos(beta), _m.sin(beta)
    low, high = (0.0, 0.0), (length * ux, length * uy)
    rough = "friction" in fields
    canvas.line((-0.3, 0.0), (high[0] + 0.5, 0.0), width=1.0)
    if beta > 0:
        canvas.line(low, high, width=1.0)
        canvas.line(high, (high[0], 0.0), width=0.5)
        canvas.arc(low, 0.9, 0.0, beta)
        canvas.label((0.9, -0.1), "n", scene.given(fields["angle"]))
    if rough:
        s = 0.1
        while s < length:
            x, y = s * ux, s * uy
            if beta > 0:  # hatched into the wedge, across the surface
                canvas.line((x, y), (x + 0.16 * uy, y - 0.16 * ux), width=0.4, gray=True)
            else:
                canvas.line((x, y), (x - 0.16, y - 0.16), width=0.4)
            s += 0.18
    nx, ny = -uy, ux  # the path's normal, away from the surface
    start, end = (high, low) if (beta > 0 and not up) else (low, high)
    if beta == 0:
        start, end = low, high
    direction = 1 if end == high else -1
    size = 0.5

    def block_at(point: Point, dash: str | None) -> Point:
        corners = [(point[0] + a * ux * size + b * nx * size, point[1] + a * uy * size + b * ny * size)
                   for a, b in ((-0.5, 0.0), (0.5, 0.0), (0.5, 1.0), (-0.5, 1.0))]
        canvas.path([*corners, corners[0]], width=0.8, dash=dash)
        return (point[0] + nx * size / 2, point[1] + ny * size / 2)

    inset = 0.5 * direction
    first = (start[0] + inset * ux, start[1] + inset * uy)
    last = (end[0] - inset * ux, end[1] - inset * uy)
    centre = block_at(first, None)
    names = [fields["body"], *([fields["with"]] if "with" in fields else [])]
    canvas.name((centre[0] + nx * 0.5, centre[1] + ny * 0.5), "s", ", ".join(names) if len(names) > 1 else names[0])
    if len(names) > 1:
        canvas.bodies[-1:] = names
    block_at(last, "dashed")
    speed, end_speed = fields["speed"], fields.get("end_speed")
    for at, node in ((first, speed), (last, end_speed)):
        if node is None:
            continue
        lift = (at[0] + nx * 1.45, at[1] + ny * 1.45)
        if _is_zero(node):
            canvas.label(lift, "s", ["v = 0"])
            continue
        tail = (lift[0] - direction * 0.5 * ux, lift[1] - direction * 0.5 * uy)
        tip = (lift[0] + direction * 0.5 * ux, lift[1] + direction * 0.5 * uy)
        canvas.arrow(tail, tip)
        # Above the arrow, clear of its higher end: beside it, the label widened the panel (and a strip
        # then shrank it until the labels touched the slope).
        canvas.label((lift[0], lift[1] + 0.5 * abs(uy) + 0.22), "s", scene.given(magnitude(node)))
    if "distance" in fields:
        off = -0.45 if beta == 0 else 0.0
        if beta == 0:
            horizontal_dimension(canvas, low[0], high[0], off, scene.given(fields["distance"]))
        else:
            mid = (length * 0.6 * ux - nx * 0.35, length * 0.6 * uy - ny * 0.35)
            canvas.label(mid, "nw", scene.given(fields["distance"]))
    if rough:
        _friction_label(canvas, scene.given(fields["friction"]), high, beta)
    return True


def _friction_label(canvas: Drawing, lines: list[str], high: Point, beta: float) -> None:
    """The friction coefficient: on a level floor above it, midway; on an incline under its base at the
    right, or right of its upright side where the angle's label is in the way (a steep one)."""
    if beta == 0:
        canvas.label((high[0] / 2, 0.2), "s", lines)  # a subscript hangs below its box
    elif canvas.fits((high[0], -0.1), "ne", lines):
        canvas.label((high[0], -0.1), "ne", lines)
    else:
        canvas.label((high[0] + 0.15, high[1] / 2), "w", lines)


def _ramp(canvas: Drawing, scene: SceneView, stage: Stage) -> bool:
    """A smooth ramp from its height to the floor: the body at the top, the height dimensioned."""
    fields = stage.fields
    up = fields.get("direction", "down") == "up"
    height = 2.2 if scene.is_given(fields["height"]) else 1.8
    run = 2.6  # cm the ramp runs across: with its labels, the panel fits half a strip unshrunk
    curve = [(run * i / 16, height * (1 + _m.cos(_m.pi * i / 16)) / 2) for i in range(17)]
    canvas.line((-0.4, height), (0.0, height), width=1.0)
    canvas.path(curve, width=1.0)
    canvas.line((run, 0.0), (run + 1.2, 0.0), width=1.0)
    canvas.line((-0.4, 0.0), (run, 0.0), width=0.4, dash="dotted")
    top, bottom = (0.0, height + 0.3), (run + 0.5, 0.3)
    start, end = (bottom, top) if up else (top, bottom)
    shape = scene.shape(fields["body"], "sphere")
    canvas.body_shape(shape, start, (0.35, 0.3))
    canvas.body_shape(shape, end, (0.35, 0.3), "dashed", filled=False)
    names = [fields["body"], *([fields["with"]] if "with" in fields else [])]
    if up:
        canvas.name((start[0], start[1] + 0.4), "s", names[0])
    else:  # above it to the left: above it, the name ran into the speed's label
        canvas.name((start[0] - 0.2, start[1] + (0.3 if shape == "sphere" else 0.38)), "se", names[0])
    canvas.bodies += names[1:]
    for at, node in ((start, fields["speed"]), (end, fields.get("end_speed"))):
        if node is None:
            continue
        if _is_zero(node):
            canvas.label((at[0] + 0.4, at[1]), "w", ["v = 0"])
            continue
        sign = -1 if up else 1
        canvas.arrow((at[0] + 0.45 * sign, at[1]), (at[0] + 1.05 * sign, at[1]))
        canvas.label((at[0] + 0.5 * sign, at[1] + 0.22), "sw" if sign > 0 else "se", scene.given(magnitude(node)))
    # The height's label right of its line, under the ramp's top: left of it, it widened the panel.
    canvas.dimension((-0.7, 0.0), (-0.7, height), scene.given(fields["height"]), "right")
    return True


# --- stick --------------------------------------------------------------------------------------

def stick(canvas: Drawing, scene: SceneView, stage: Stage) -> bool:
    """Axes n (east) and t (north) at the point of impact; each body coming in along its velocity (given
    speeds to scale, the fastest 2 cm), the wreck's direction dashed from the point (to scale when its angle
    is given, else halfway between the bodies' directions), its angle marked."""
    fields = stage.fields
    before = fields["before"]
    bodies = list(fields["bodies"])
    given = {body: all(scene.is_given(node) for node in (v.n, v.t) if node is not None)
             for body, v in ((b, before.get(b)) for b in bodies) if v is not None}
    speeds = {body: _m.hypot(*_components(scene, before.get(body))) for body in bodies}
    fastest = max((speeds[b] for b in bodies if given.get(b)), default=0.0)
    canvas.line((-2.6, 0.0), (2.6, 0.0), width=0.3, dash="dotted")
    canvas.line((0.0, -2.6), (0.0, 2.6), width=0.3, dash="dotted")
    canvas.label((2.65, 0.0), "w", ["n"])
    canvas.label((0.0, 2.65), "s", ["t"])
    directions = []
    for number, body in enumerate(bodies):
        n, t = _components(scene, before.get(body))
        size = _m.hypot(n, t)
        if size == 0:
            canvas.circle((0.45 * (1 if number else -1), -0.45), 0.3)
            canvas.name((0.45 * (1 if number else -1), -0.45), "c", body)
            canvas.label((0.45 * (1 if number else -1), -0.85), "n", ["v = 0"])
            continue
        ux, uy = n / size, t / size
        directions.append((ux, uy))
        length = 2.0 * speeds[body] / fastest if given.get(body) and fastest > 0 else 1.4
        length = max(0.7, length)
        centre = (-ux * (length + 0.5), -uy * (length + 0.5))
        canvas.circle(centre, 0.3)
        canvas.name(centre, "c", body)
        _velocity_arrow(canvas, scene, (-ux * 0.2, -uy * 0.2), before.get(body), length - 0.05, into=True)
    from_n = fields.get("from", "n") == "n"
    angle = fields.get("angle")
    if angle is not None and scene.is_given(angle) and _m.isfinite(scene.value(angle)):
        theta = scene.value(angle)
    else:
        sx, sy = sum(d[0] for d in directions), sum(d[1] for d in directions)
        theta = _m.atan2(sy, sx) if (sx or sy) else _m.pi / 4
        theta = theta if from_n else _m.pi / 2 - theta
    heading = theta if from_n else _m.pi / 2 - theta
    tip = (1.9 * _m.cos(heading), 1.9 * _m.sin(heading))
    canvas.path([(0.0, 0.0), tip], width=0.8, dash="dashed")
    canvas.arrow((tip[0] * 0.8, tip[1] * 0.8), tip)
    wreck = " + ".join(bodies)
    canvas.label((tip[0] + 0.1, tip[1] + 0.1), "sw", [f"{_said(wreck)} {scene.given(fields['speed'])[0]}"
                                                       if "speed" in fields else str(string(wreck))])
    if angle is not None:
        start, end = (0.0, heading) if from_n else (heading, _m.pi / 2)
        canvas.arc((0.0, 0.0), 0.8, min(start, end), max(start, end))
        middle = (start + end) / 2
        canvas.label((1.0 * _m.cos(middle), 1.0 * _m.sin(middle)), "w", scene.given(angle))
    return True


# --- separation ---------------------------------------------------------------------------------

def separation(canvas: Drawing, scene: SceneView, stage: Stage) -> bool:
    """Two states side by side, captioned: before, the whole (the two parts together), its velocity (or at
    rest), the energy released; after, the parts flying apart along n, each with its velocity the way it
    moves (asked: its name, not to scale)."""
    fields = stage.fields
    first, second = fields["bodies"]
    whole = fields.get("whole")
    canvas.rect((0.0, 0.0), (0.8, 0.7))
    canvas.rect((0.8, 0.0), (1.6, 0.7))
    canvas.name((0.4, 0.35), "c", first)
    canvas.name((1.2, 0.35), "c", second)
    if whole is not None and not (_is_zero(whole.n) and _is_zero(whole.t)):
        _velocity_arrow(canvas, scene, (0.2, 1.1), whole, 1.2, into=False)
    else:
        canvas.label((0.8, 0.95), "s", [str(string("at rest"))])
    if "energy" in fields:
        canvas.label((0.8, -0.1), "n", scene.given(fields["energy"]))
    canvas.label((0.8, 1.9), "s", [str(string("before"))])  # two states, side by side: no line joins them
    canvas.label((5.0, 1.9), "s", [str(string("after"))])
    after = fields.get("after", {})
    centre = 5.0
    for body, side in ((first, -1), (second, 1)):
        x = centre + side * 0.9
        canvas.rect((x - 0.4, 0.0), (x + 0.4, 0.7))
        canvas.name((x, 0.35), "c", body)
        velocity = after.get(body)
        n = _components(scene, velocity)[0]
        if velocity is None:
            continue
        way = 1 if n > 0 else -1 if n < 0 else side
        canvas.arrow((x, 1.0), (x + way * 1.0, 1.0))
        canvas.label((x + way * 0.5, 1.2), "s", scene.given(magnitude(velocity.n)))
    if "relative" in fields:
        canvas.label((centre, -0.1), "n", [f"{_said('relative')} " + scene.given(fields["relative"])[0]])
    return True


# --- impulse ------------------------------------------------------------------------------------

def impulse(canvas: Drawing, scene: SceneView, stage: Stage) -> bool:
    """The body, its velocity just before coming in and just after going out (n east, or up when its
    weight acts), and the impulse on it, thick, from the body; a body stopped over a distance, the cushion
    under it, the distance dimensioned."""
    fields = stage.fields
    body = fields["body"]
    before, after = fields["velocity"], fields["velocity_after"]
    up = fields.get("weight", False)

    def turn(v: tuple[float, float]) -> tuple[float, float]:
        return (v[1], v[0]) if up else v  # weight: n up, t east

    b, a = turn(_components(scene, before)), turn(_components(scene, after))
    turned = (lambda vel: Velocity(vel.t, vel.n)) if up else (lambda vel: vel)
    if "distance" in fields:
        canvas.ground(-1.2, 1.2, -0.6)
        canvas.rect((-1.0, -0.6), (1.0, 0.0), fill="luma(200)")
        canvas.label((0.0, -0.3), "c", [str(string("cushion"))])  # inside: beside it, it widened the panel
        canvas.dimension((-1.2, -0.6), (-1.2, 0.0), scene.given(fields["distance"]), "left")
        centre = (0.0, 0.3)
        canvas.body_shape(scene.shape(body, "block"), centre, (0.6, 0.3))
    else:
        centre = (0.0, 0.0)
        canvas.body_shape(scene.shape(body, "sphere"), centre, (0.35, 0.35))
    canvas.name(centre, "c", body)
    # before and after beside the body (above and below it, or right of it when n is up), each centred
    rows = ((centre[0] + 1.2, centre[1] + 0.4), (centre[0] + 1.2, centre[1] + 1.8)) if up else \
        ((centre[0], centre[1] + 1.0), (centre[0], centre[1] - 1.0))
    for at, vector, velocity, word in ((rows[0], b, before, "before"), (rows[1], a, after, "after")):
        # Beside an upright arrow, the word over the value: on one line they widened the panel.
        lines = [_said(word), *_speed_lines(scene, turned(velocity))] if up else \
            [f"{_said(word)} " + line for line in _speed_lines(scene, turned(velocity))]
        if _m.hypot(*vector) == 0:
            canvas.label((at[0] - 0.2, at[1]) if up else at, "w" if up else "c",
                         [_said(word), "v = 0"] if up else [f"{_said(word)} v = 0"])
            continue
        ux, uy = _unit(vector)
        canvas.arrow((at[0] - ux * 0.6, at[1] - uy * 0.6), (at[0] + ux * 0.6, at[1] + uy * 0.6))
        if abs(ux) >= abs(uy):
            canvas.label((at[0], at[1] + 0.15), "s", lines)
        else:
            canvas.label((at[0] + 0.15, at[1]), "w", lines)
    jx, jy = a[0] - b[0], a[1] - b[1]
    if _m.hypot(jx, jy) > 0:
        ux, uy = _unit((jx, jy))
        start = (centre[0] + ux * 0.4, centre[1] + uy * 0.4)
        tip = (start[0] + ux * 1.1, start[1] + uy * 1.1)
        canvas.arrow(start, tip, width=2.0, head=0.3)
        named, force = fields.get("impulse"), fields.get("force")
        lines = scene.given(named) if named is not None else ["J"]
        if force is not None:
            lines += scene.given(force)
        middle = ((start[0] + tip[0]) / 2, (start[1] + tip[1]) / 2)
        if abs(ux) >= abs(uy):
            canvas.label((middle[0], middle[1] + 0.15), "s", [", ".join(lines)])
        else:
            canvas.label((middle[0] - 0.15, middle[1]), "e", [", ".join(lines)])
    if "time" in fields:
        canvas.label((centre[0], centre[1] - 1.5), "n", scene.given(fields["time"]))
    return True


def _unit(v: tuple[float, float]) -> tuple[float, float]:
    size = _m.hypot(*v) or 1.0
    return v[0] / size, v[1] / size
