"""Figures of oblique impacts, to one variant's scale (see :mod:`grader.render.figures`, which chooses
the figure): a body striking a fixed surface, a body dropped onto an incline, two spheres at contact.
Angles are drawn as the scene gives them, an asked one not to scale."""

from __future__ import annotations

import math as _m
from collections.abc import Sequence

from grader.model.scene import Stage, Velocity
from grader.render.drawing import Drawing, Point
from grader.render.scene_view import SceneView, find_stage, velocity_stage
from grader.render.typst_text import string


def _axes(canvas: Drawing, origin: Point, n: Point, t: Point) -> None:
    """A small n-t axis glyph."""
    for direction, label in ((n, "n"), (t, "t")):
        tip = (origin[0] + 0.6 * direction[0], origin[1] + 0.6 * direction[1])
        canvas.arrow(origin, tip, width=0.5, head=0.13)
        canvas.label((tip[0] + 0.15 * direction[0], tip[1] + 0.15 * direction[1]), "c", [label])


def _screen(velocity: Velocity, scene: SceneView, n: Point, t: Point) -> Point:
    vn, vt = scene.value(velocity.n), scene.value(velocity.t)
    return vn * n[0] + vt * t[0], vn * n[1] + vt * t[1]


def _nearest_axis(ray: Point, axes: Sequence[Point]) -> Point:
    """Of the axes (either sign), the one closest in direction to ``ray``."""
    return max(((s * a[0], s * a[1]) for a in axes for s in (1, -1)), key=lambda a: a[0] * ray[0] + a[1] * ray[1])


def _axis(stage: Stage, n: Point, t: Point) -> Point:
    """The axis a velocity stage measures its angle from."""
    return t if stage.fields.get("from", "t") == "t" else n


def _angle_mark(canvas: Drawing, center: Point, ray: Point, axes: Sequence[Point], radius: float,
                lines: Sequence[str]) -> None:
    """The arc between ``ray`` and the nearest of ``axes``, labelled outside it."""
    axis = _nearest_axis(ray, axes)
    reference = _m.atan2(axis[1], axis[0])
    end = reference + _wrap(_m.atan2(ray[1], ray[0]) - reference)
    if abs(end - reference) < 1e-3:
        return
    canvas.arc(center, radius, reference, end)
    span = end - reference
    places = [((reference + end) / 2, radius + 0.12)]
    if abs(span) < 0.45:  # a narrow angle: farther out inside it, else just beyond the ray, or the axis
        inside = 0.3 / _m.sin(abs(span) / 2)
        places = [((reference + end) / 2, inside)] if inside < radius + 1.2 else []
        places += [(end + _m.copysign(0.3, span), radius + 0.12), (reference - _m.copysign(0.3, span), radius + 0.12)]
    for middle, distance in places:
        at = (center[0] + distance * _m.cos(middle), center[1] + distance * _m.sin(middle))
        if canvas.fits(at, _anchor(middle), lines) or (middle, distance) == places[-1]:
            canvas.label(at, _anchor(middle), lines)
            return


def _speed_mark(canvas: Drawing, tail: Point, tip: Point, away: Point, lines: Sequence[str],
                along: float = 0.5) -> None:
    """An arrow's label beside it (``along``: where, from the tail), on the side of ``away``."""
    dx, dy = tip[0] - tail[0], tip[1] - tail[1]
    length = _m.hypot(dx, dy) or 1.0
    side = (-dy / length, dx / length)
    if side[0] * away[0] + side[1] * away[1] < 0:
        side = (-side[0], -side[1])
    at = (tail[0] + along * dx + 0.12 * side[0], tail[1] + along * dy + 0.12 * side[1])
    canvas.label(at, _anchor(_m.atan2(side[1], side[0])), lines)


def _wrap(angle: float) -> float:
    return (angle + _m.pi) % (2 * _m.pi) - _m.pi


def _anchor(direction: float) -> str:
    """The label anchor that keeps a label placed in ``direction`` from a point off that point."""
    c, s = _m.cos(direction), _m.sin(direction)
    return ("s" if s > 0.3 else "n" if s < -0.3 else "") + ("w" if c > 0.3 else "e" if c < -0.3 else "") or "c"


def _speed_label(scene: SceneView, stage: Stage | None, fallback: str) -> list[str]:
    return scene.given(stage.fields["speed"]) if stage is not None else [fallback]


def _angle_label(scene: SceneView, stage: Stage | None) -> list[str]:
    return scene.given(stage.fields["angle"]) if stage is not None else []


def surface(canvas: Drawing, scene: SceneView, impact: Stage) -> bool:
    """A body striking a fixed surface obliquely: incoming and rebound velocities to scale."""
    first = impact.fields["bodies"][0]
    before = impact.fields["before"].get(first)
    after = impact.fields.get("after", {}).get(first)
    n, t = (0.0, -1.0), (1.0, 0.0)
    incoming = _screen(before, scene, n, t)
    outgoing = _screen(after, scene, n, t) if after is not None else (0.0, 0.0)
    speeds = [_m.hypot(*incoming), _m.hypot(*outgoing)]
    if not all(_m.isfinite(s) for s in speeds) or speeds[0] <= 0:
        return False
    scale = 2.3 / max(speeds)
    radius = 0.28
    center = (0.0, radius)
    canvas.rect((-3.0, -0.3), (3.0, 0.0), fill="luma(215)")
    canvas.name((2.9, -0.35), "ne", impact.fields["bodies"][1], [])
    canvas.line((-2.9, radius), (2.9, radius), width=0.4, dash="dashed", gray=True)
    canvas.circle(center, radius)
    stages = scene.template.scene.stages
    arrows = [(incoming, -1, velocity_stage(stages, before), "v")]
    if speeds[1] > 0:
        arrows.append((outgoing, 1, velocity_stage(stages, after), "v'"))
    for vector, sign, stage, fallback in arrows:
        length = _m.hypot(*vector)
        ray = (sign * vector[0] / length, sign * vector[1] / length)  # from the body toward the arrow
        near = (center[0] + ray[0] * (radius + 0.05), center[1] + ray[1] * (radius + 0.05))
        far = (near[0] + ray[0] * length * scale, near[1] + ray[1] * length * scale)
        lines = _speed_label(scene, stage, fallback)
        canvas.velocity(*((far, near) if sign < 0 else (near, far)), lines)
        # The speed at the arrow's far end, clear of the angle marks near the body.
        end = (far[0] + 0.1 * ray[0], far[1] + 0.1 * ray[1])
        canvas.label(end, _anchor(_m.atan2(ray[1], ray[0])), lines)
        if stage is not None:
            _angle_mark(canvas, center, ray, [_axis(stage, n, t)], 0.95, _angle_label(scene, stage))
    # Apart from the rebound's label, which it would read on from ("v_out n").
    origin = next((o for o in ((3.4, 1.6), (3.9, 1.9), (4.4, 1.9)) if _axes_fit(canvas, o, n, t, 0.4)), (4.4, 1.9))
    _axes(canvas, origin, n, t)
    spots = [((0.0, 2 * radius + 0.12), "s"), ((0.0, -0.35), "n")]  # above the body, or under the surface
    canvas.name(*next((s for s in spots if canvas.fits(*s, [str(string(first))])), spots[-1]), first)
    return True


def spheres(canvas: Drawing, scene: SceneView, impact: Stage) -> bool:
    """Two touching spheres, the line of centres n and the tangent t, the incoming velocity."""
    first, second = impact.fields["bodies"]
    radius = 0.85
    n, t = (1.0, 0.0), (0.0, 1.0)
    centers = {first: (0.0, 0.0), second: (2 * radius, 0.0)}
    canvas.line((-radius - 1.2, 0.0), (4 * radius + 0.3, 0.0), width=0.4, dash="dashed", gray=True)
    canvas.arrow((3 * radius, 0.0), (4 * radius + 0.6, 0.0), width=0.5, head=0.15)
    canvas.label((4 * radius + 0.7, 0.0), "w", ["n"])
    canvas.line((radius, -radius - 0.4), (radius, radius + 0.3), width=0.4, dash="dashed", gray=True)
    canvas.arrow((radius, radius + 0.3), (radius, radius + 0.9), width=0.5, head=0.15)
    canvas.label((radius, radius + 1.0), "s", ["t"])
    for body, center in centers.items():
        canvas.circle(center, radius)
        canvas.name(center, "c", body, [*scene.mass_value(body)])
    stages = scene.template.scene.stages
    for body, velocity in impact.fields["before"].items():
        vector = _screen(velocity, scene, n, t)
        speed = _m.hypot(*vector)
        if not _m.isfinite(speed) or speed <= 0:
            continue
        ux, uy = vector[0] / speed, vector[1] / speed
        center = centers[body]
        tip = (center[0] - ux * (radius + 0.08), center[1] - uy * (radius + 0.08))
        tail = (tip[0] - ux * 2.0, tip[1] - uy * 2.0)
        stage = velocity_stage(stages, velocity)
        canvas.velocity(tail, tip, _speed_label(scene, stage, "v"))
        axis = _nearest_axis((-ux, -uy), [_axis(stage, n, t) if stage is not None else n])
        _speed_mark(canvas, tail, tip, (-ux - axis[0], -uy - axis[1]), _speed_label(scene, stage, "v"), 0.2)
        if stage is not None:
            _angle_mark(canvas, center, (-ux, -uy), [_axis(stage, n, t)], radius + 0.45, _angle_label(scene, stage))
    return True


def incline(canvas: Drawing, scene: SceneView, impact: Stage) -> bool:
    """A body dropped onto a fixed incline: the incline at its angle (the body arrives straight down, so
    the angle its velocity makes with n is the incline's), the body at the drop height above the point
    of impact, and its rebound velocity with the angle to the surface, drawn but not to scale (the
    figure must not give the answer): halfway between the surface and a mirror reflection."""
    first, surface = impact.fields["bodies"]
    before, after = impact.fields["before"].get(first), impact.fields.get("after", {}).get(first)
    slope = _m.atan2(scene.value(before.t), scene.value(before.n)) if before is not None else _m.nan
    if not (_m.isfinite(slope) and 0 < slope < _m.pi / 2):
        return False
    down = (_m.cos(slope), -_m.sin(slope))  # t: down the slope
    out = (_m.sin(slope), _m.cos(slope))  # -n: out of the incline
    length, radius, drop = 4.4, 0.25, 2.6
    # The contact a little above the incline's middle: deep enough under it for the n-t axes there.
    top = (-0.45 * length * down[0], -0.45 * length * down[1])
    bottom = (0.55 * length * down[0], 0.55 * length * down[1])
    corner = (top[0], bottom[1])
    canvas.polygon([top, bottom, corner], fill="luma(215)")
    canvas.path([corner, top, bottom, corner], width=0.6)
    canvas.name(((corner[0] + bottom[0]) / 2, bottom[1] - 0.1), "n", surface, [])
    stages = scene.template.scene.stages
    center = (radius * out[0], radius * out[1])
    release = (center[0], center[1] + drop)
    canvas.reserve((center[0] - radius, center[1] - radius), (center[0] + radius, center[1] + radius))
    _contact_axes(canvas, out, down, bottom)  # before the incline's angle, whose label then keeps clear of them
    incoming = velocity_stage(stages, before)
    if incoming is not None:  # a wider arc for a flat incline: its label then fits inside the wedge
        _angle_mark(canvas, bottom, (-down[0], -down[1]), [(1.0, 0.0)], 0.9 if slope > 0.45 else 1.4,
                    _angle_label(scene, incoming))
    canvas.circle(center, radius)
    canvas.circle(release, radius, "dashed", fill=False)
    canvas.name((release[0], release[1] + radius + 0.1), "s", first, [*scene.mass(first)])
    canvas.line(center, release, width=0.4, dash="dashed", gray=True)
    canvas.strokes.append((center, release))  # the n-t glyph keeps clear of the fall
    canvas.arrow((center[0], center[1] + 0.55 * drop), (center[0], center[1] + 0.45 * drop), width=0.4, head=0.16)
    fall = find_stage(stages, "free_fall", before=impact.index, body=first)
    side = center[0] + 2.6  # beyond the rebound arrow and its label
    canvas.line((center[0] + radius + 0.1, release[1]), (side + 0.15, release[1]), width=0.3)
    canvas.line((center[0] + radius + 0.1, center[1]), (side + 0.15, center[1]), width=0.3, dash="dashed", gray=True)
    canvas.dimension((side, center[1]), (side, release[1]), scene.given(fall.fields["height"]) if fall else [], "right")
    # The rebound: a drawn direction, halfway between the surface and the mirror image of the fall.
    mirror = _m.pi / 2 - slope
    ray = (_m.cos(mirror / 2) * down[0] + _m.sin(mirror / 2) * out[0],
           _m.cos(mirror / 2) * down[1] + _m.sin(mirror / 2) * out[1])
    near = (center[0] + ray[0] * (radius + 0.05), center[1] + ray[1] * (radius + 0.05))
    far = (near[0] + 1.3 * ray[0], near[1] + 1.3 * ray[1])
    canvas.line((center[0] - 0.6 * down[0], center[1] - 0.6 * down[1]),
                (center[0] + 1.9 * down[0], center[1] + 1.9 * down[1]), width=0.4, dash="dashed", gray=True)
    rebound = velocity_stage(stages, after)
    canvas.velocity(near, far, _speed_label(scene, rebound, "v'"))
    canvas.label((far[0] + 0.1 * ray[0], far[1] + 0.1 * ray[1]), _anchor(_m.atan2(ray[1], ray[0])),
                 _speed_label(scene, rebound, "v'"))
    if rebound is not None:
        _angle_mark(canvas, center, ray, [down], 1.0, _angle_label(scene, rebound))
    return True


def _contact_axes(canvas: Drawing, out: Point, down: Point, bottom: Point) -> None:
    """n and t at the point of contact (the origin), where they are defined: t along the surface down the
    slope, n into the incline, as long as the incline is deep there (it is shallow on a gentle slope),
    their labels beside their tips where they are clear (inside the incline, n's up the slope)."""
    depth = abs(bottom[1]) * out[1]  # from the contact to the incline's base, at right angles to it
    reach = max(0.25, min(0.6, depth - 0.2))
    for direction, length in ((down, 0.6), ((-out[0], -out[1]), reach)):
        canvas.arrow((0.0, 0.0), (length * direction[0], length * direction[1]), width=0.5, head=0.13)
    t_tip, n_tip = (0.6 * down[0], 0.6 * down[1]), (-reach * out[0], -reach * out[1])
    n_beside = ((-0.2, 0.0), (-0.4, 0.0), (-0.6, 0.0), (0.2, 0.0), (-0.25, 0.15), (-0.5, 0.2))  # (down, out)
    for tip, label, offsets in ((t_tip, "t", ((0.0, -0.2), (0.2, -0.15), (0.15, 0.2))), (n_tip, "n", n_beside)):
        beside = [(tip[0] + a * down[0] + b * out[0], tip[1] + a * down[1] + b * out[1]) for a, b in offsets]
        canvas.label(next((at for at in beside if canvas.fits(at, "c", [label])), beside[0]), "c", [label])


def _axes_fit(canvas: Drawing, origin: Point, n: Point, t: Point, margin: float = 0.12) -> bool:
    """Whether the n-t glyph at ``origin`` (and ``margin`` around it) is clear of what is drawn."""
    xs = [origin[0] + s * d[0] for d in (n, t) for s in (0.0, 0.8)]
    ys = [origin[1] + s * d[1] for d in (n, t) for s in (0.0, 0.8)]
    return canvas.clear((min(xs) - margin, min(ys) - margin, max(xs) + margin, max(ys) + margin))


def offset_spheres(canvas: Drawing, scene: SceneView, geometry: Stage, impact: Stage) -> bool:
    """Two spheres at contact, the line of centres to scale: sphere 1 on its line of travel, sphere 2's
    centre the offset from it (dimensioned), the line of centres n at its angle to the velocity and the
    tangent t. Radii in their ratio, neither drawn below a fifth of their sum (the angle stays exact)."""
    first, second = geometry.fields["bodies"]
    bodies = scene.template.scene.bodies
    radii = [scene.value(bodies[body].radius) for body in (first, second)]
    offset = scene.value(geometry.fields["offset"])
    if not (all(_m.isfinite(r) and r > 0 for r in radii) and _m.isfinite(offset) and 0 <= offset < sum(radii)):
        return False
    reach = 1.8
    share = min(0.8, max(0.2, radii[0] / sum(radii)))
    drawn = (share * reach, (1 - share) * reach)
    across = reach * offset / sum(radii)
    along = _m.sqrt((reach - across) * (reach + across))
    one, two = (-along, 0.0), (0.0, across)
    n, t = (along / reach, across / reach), (across / reach, -along / reach)

    def at(origin: Point, direction: Point, distance: float) -> Point:
        return origin[0] + distance * direction[0], origin[1] + distance * direction[1]

    contact = at(one, n, drawn[0])
    for center, radius in ((one, drawn[0]), (two, drawn[1])):
        canvas.circle(center, radius)
    side = max(drawn[1] + 0.45, n[0] * (drawn[1] + 0.9) + 0.3)  # beyond the label n of a nearly head-on impact
    canvas.line(at(one, (1.0, 0.0), -drawn[0] - 2.1), (side + 0.15, 0.0), width=0.4, dash="dashed", gray=True)
    canvas.line(two, (side + 0.15, across), width=0.3)
    canvas.dimension((side, 0.0), (side, across), scene.given(geometry.fields["offset"]), "right")
    canvas.line(at(one, n, -0.5), at(two, n, drawn[1]), width=0.4, dash="dashed", gray=True)
    canvas.arrow(at(two, n, drawn[1]), at(two, n, drawn[1] + 0.6), width=0.5, head=0.15)
    canvas.label(at(two, n, drawn[1] + 0.7), _anchor(_m.atan2(n[1], n[0])), ["n"])
    canvas.line(at(contact, t, -0.8), at(contact, t, 0.8), width=0.4, dash="dashed", gray=True)
    canvas.arrow(at(contact, t, 0.8), at(contact, t, 1.2), width=0.5, head=0.15)
    canvas.label(at(contact, t, 1.3), _anchor(_m.atan2(t[1], t[0])), ["t"])
    canvas.name((one[0], -drawn[0] - 0.1), "n", first, [*scene.mass_value(first)])
    if n[1] < 0.7:  # above sphere 2, or left of it where the line of centres leaves it upward
        canvas.name((0.0, across + drawn[1] + 0.1), "s", second, [*scene.mass_value(second)])
    else:
        canvas.name((-drawn[1] - 0.1, across + 0.5 * drawn[1]), "e", second, [*scene.mass_value(second)])
    tip = at(one, (1.0, 0.0), -drawn[0] - 0.1)
    tail = at(tip, (1.0, 0.0), -1.8)
    stage = velocity_stage(scene.template.scene.stages, impact.fields["before"].get(first))
    canvas.velocity(tail, tip, _speed_label(scene, stage, "v"))
    canvas.label(((tail[0] + tip[0]) / 2, 0.15), "s", _speed_label(scene, stage, "v"))
    canvas.reserve((-drawn[1], across - drawn[1]), (drawn[1], across + drawn[1]))  # the angle's label: not on sphere 2
    _angle_mark(canvas, one, n, [(1.0, 0.0)], 0.55 * drawn[0], scene.given(geometry.fields["angle"]))
    return True
