"""Figures of a scene, to one variant's scale, as Typst drawing calls (see ``templates/figures.typ``).

The kind of figure follows from the scene's structure, never from the template's id:

* a body falls (``free_fall``) onto a fixed surface or onto a second body, maybe rising again after
  the impact: the surface (a plate moving at constant velocity with its arrow, or a pile, drawn under
  a block), the body at its drop height and, dashed, at its rebound height, with dimension lines;
  given heights to scale, an asked one drawn but not to scale (it would give the answer away);
* a body falls onto a fixed surface and rebounds more than once: its path as arcs, each height
  dimensioned, given ones to scale;
* a body falls onto a fixed surface and strikes it obliquely: an incline at the angle its velocity
  makes with n, the body at its drop height, the rebound drawn with its angle to the surface (asked,
  so not to scale);
* an oblique ``impact`` (a ``velocity`` stage gives the components) with a fixed body: the surface,
  the incoming and rebound velocity arrows at their angles, lengths proportional to the speeds;
* an oblique impact of two spheres whose line of centres an ``impact_geometry`` stage gives: the
  spheres at contact, radii in their ratio, the offset dimensioned, n at its angle to the path;
* another oblique impact of two bodies: two touching circles, the line of centres n and the tangent t,
  the incoming velocity at its angle to n;
* direct impacts of bodies in a line (two, or a chain: 1 strikes 2, 2 strikes 3): blocks whose areas
  follow the masses, above each the velocity before it is struck, an arrow the way it moves with
  lengths in the ratio of the speeds, the bodies at rest marked so;
* a body bouncing until it rests (``bounces``): the drop and the decaying arcs, heights and time to
  scale (:mod:`grader.render.series`);
* a body swinging up on a cord (``swing``), struck at the lowest point maybe: the cord at rest and at its
  greatest angle, to scale, and the arc between (:mod:`grader.render.pendulum`);
* an impact and a slide to rest after it: the bodies at the impact and at rest, the skid mark from
  the point of impact dimensioned (:mod:`grader.render.skid`);
* a projectile's flight to a wall, its rebound and its flight to the ground: the path to scale
  (:mod:`grader.render.trajectory`);
* anything else: the bodies in a row, labelled.

The oblique figures are :mod:`grader.render.oblique`'s, the drawing primitives
:class:`grader.render.drawing.Drawing`'s.
"""

from __future__ import annotations

import math as _m
from collections.abc import Mapping, Sequence

from grader.assign.variants import ProblemVariant
from grader.bank.template import Template
from grader.model.expr import Node, Op
from grader.model.scene import Stage, Velocity
from grader.render.drawing import Drawing, Point
from grader.render.oblique import incline, offset_spheres, spheres, surface
from grader.render.pendulum import swing_figure
from grader.render.scene_view import SceneView, find_stage
from grader.render.series import bounce_series
from grader.render.skid import skid
from grader.render.trajectory import trajectory
from grader.render.typst_text import Typ, string

STAGE_FIGURES: Mapping[str, str] = {
    "free_fall": "the body at its drop height above what it falls onto (the ground, a fixed floor, a driven plate "
                 "with its velocity, or a pile drawn under it), the height dimensioned, to scale when given; onto a "
                 "fixed surface it strikes obliquely, an incline at its angle; followed by two or more rises, the "
                 "path as arcs",
    "rise": "after a fall and an impact only: the body dashed at its rebound height, dimensioned (an asked height "
            "drawn at 0.6 of the drop, not to scale); two or more rises after impacts on a fixed surface, the path as "
            "arcs, each height dimensioned; in no other scene",
    "impact": "direct: the bodies as blocks in a line, areas following the masses (a fixed one a hatched wall), each "
              "with its velocity before as an arrow; oblique against a fixed body: the surface with the incoming "
              "and rebound velocities at their angles; oblique between two bodies: two touching circles with n, t "
              "and the incoming velocity (a scene with a fall, swing, slide, flight or bounces is drawn by that "
              "figure instead)",
    "velocity": "not drawn on its own: its speed and angle label the velocity arrows of the oblique impact figures "
                "and a projectile's throw",
    "angle_between": "not drawn: no figure reads it",
    "impact_geometry": "with an oblique impact after it: the two spheres at contact, radii in their ratio, the "
                       "offset dimensioned and n at its angle to the path",
    "bounces": "the drop and the decaying arcs until the body rests, heights and time along the floor to scale, the "
               "bounce whose height is asked marked by its name",
    "swing": "the cord at rest and at its greatest angle, to scale, and the arc between; a body that strikes the "
             "hanging one (an impact before the swing) comes in from the left with its velocity",
    "slide": "after an impact: two rows on one scale, the bodies at the impact and at rest, the skid from the point "
             "of impact dimensioned; without an impact, the bodies in a row",
    "flight": "a flight to a wall before an impact: the path to scale, solid to the wall, dashed from the wall to "
              "the ground (the flight after the impact); in no other scene",
    "slope": "not drawn yet: a scene with a slope is drawn by the figure its other stages choose (an impact's), "
             "or as its bodies in a row",
    "impulse": "not drawn yet: a scene with an impulse is drawn by the figure its other stages choose (an "
               "impact's or a fall's), or as its bodies in a row",
    "separation": "not drawn yet: a scene where a body separates in two is drawn as its bodies in a row",
    "stick": "not drawn yet: a scene with bodies that stick in a plane is drawn as its bodies in a row",
    "spring": "not drawn yet: a scene with a spring is drawn by the figure its other stages choose (an impact's), "
              "or as its bodies in a row",
}
"""How a stage of each effect is drawn today, one sentence each (``grader effects`` shows them): the figure
is chosen for the whole scene by :func:`figure`, so a stage is drawn only in the scenes it lists. A scene
no figure fits is drawn as its bodies in a row, labelled."""


def figure(template: Template, variant: ProblemVariant, values: Mapping[str, float]) -> Typ:
    """The figure of one variant's scene, as a Typst expression (code mode)."""
    scene = SceneView(template, variant, values)
    stages = template.scene.stages
    impact = find_stage(stages, "impact")
    canvas = Drawing()
    bounces, swing = find_stage(stages, "bounces"), find_stage(stages, "swing")
    if bounces is not None and bounce_series(canvas, scene, bounces):
        return canvas.typst()
    if swing is not None and swing_figure(canvas, scene, swing, impact):
        return canvas.typst()
    if impact is None:
        fall = find_stage(stages, "free_fall")
        if fall is None or not _drop(canvas, scene, fall, None, None):
            canvas = Drawing()
            _row(canvas, scene)
        return canvas.typst()
    flight = find_stage(stages, "flight", before=impact.index)
    if flight is not None and flight.fields["until"] == "wall" and trajectory(
            canvas, scene, flight, find_stage(stages, "flight", after=impact.index)):
        return canvas.typst()
    slide = find_stage(stages, "slide", after=impact.index)
    if slide is not None and skid(canvas, scene, impact, slide):
        return canvas.typst()
    first, second = impact.fields["bodies"]
    fall = find_stage(stages, "free_fall", before=impact.index, body=first)
    rises = [s for s in stages if s.effect == "rise" and s.index > impact.index and s.fields["body"] == first]
    drawn = False
    fixed = template.scene.bodies[second].mass is None
    geometry = find_stage(stages, "impact_geometry", before=impact.index)
    if fall is not None and len(rises) > 1 and fixed:
        drawn = _bounces(canvas, scene, fall, rises, second)
    elif fall is not None and impact.is_oblique and fixed:
        drawn = incline(canvas, scene, impact)
    elif fall is not None:
        drawn = _drop(canvas, scene, fall, impact, rises[0] if rises else None)
    elif impact.is_oblique and fixed:
        drawn = surface(canvas, scene, impact)
    elif impact.is_oblique and geometry is not None:
        drawn = offset_spheres(canvas, scene, geometry, impact)
    elif impact.is_oblique:
        drawn = spheres(canvas, scene, impact)
    else:
        drawn = _direct(canvas, scene, [s for s in stages if s.effect == "impact" and not s.is_oblique])
    if not drawn:
        canvas = Drawing()
        _row(canvas, scene)
    return canvas.typst()


# --- the figures --------------------------------------------------------------------------------

def _drop(canvas: Drawing, scene: SceneView, fall: Stage, impact: Stage | None, rise: Stage | None) -> bool:
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

    def body(x: float, bottom: float, dash: str | None) -> float:
        if fixed:
            canvas.circle((x, bottom + 0.3), 0.3, dash, fill=dash is None)
            return bottom + 0.6
        canvas.rect((x - 0.4, bottom), (x + 0.4, bottom + 0.5), dash, "luma(235)" if dash is None else "none")
        return bottom + 0.5

    top = body(x_body, drop * scale, None)
    canvas.label((x_body, top + 0.15), "s", [str(string(first)), *scene.mass(first)])
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
        canvas.label((3.3, -0.4), "n", [str(string(second))])
        _vertical_velocity(canvas, scene, (5.75, -0.2), -scene.value(moving.n), moving.n)
    elif fixed:
        canvas.ground(0.9, 5.2, 0.0)
        canvas.label((3.3, -0.3), "n", [str(string(second or "ground"))])
    else:  # a pile: its top is the impact surface, driven into the ground
        canvas.rect((x_body - 0.45, -1.6), (x_body + 0.45, 0.0))
        canvas.ground(1.2, x_body - 0.45, -0.45)
        canvas.ground(x_body + 0.45, 5.0, -0.45)
        canvas.line((x_body + 0.45, 0.0), (4.9, 0.0), width=0.3, dash="dashed")
        canvas.label((x_body + 0.6, -1.05), "w", [str(string(second)), *scene.mass(str(second))])
    return True


def _vertical_velocity(canvas: Drawing, scene: SceneView, at: Point, upward: float, given: Node) -> None:
    """An arrow through ``at`` the way a surface moves (up or down), labelled with what gives its velocity."""
    if not _m.isfinite(upward) or upward == 0:
        canvas.label(at, "w", [*scene.given(_parameter_of(given)), "(at rest)"])
        return
    sign = 1.0 if upward > 0 else -1.0
    canvas.arrow((at[0], at[1] - 0.45 * sign), (at[0], at[1] + 0.45 * sign), width=0.9)
    canvas.label((at[0] + 0.15, at[1]), "w", scene.given(_parameter_of(given)))


def _parameter_of(node: Node) -> Node:
    """``u`` for ``-u``: a velocity given with its sign turned (an axis pointing the other way) is
    labelled with the parameter, whose positive sense the statement names."""
    return node.args[0] if isinstance(node, Op) and node.op == "neg" else node


def _bounces(canvas: Drawing, scene: SceneView, fall: Stage, rises: Sequence[Stage], surface: str) -> bool:
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
    canvas.label((x, drawn[0] + 2 * radius + 0.15), "s", [str(string(first)), *scene.mass(first)])
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
    canvas.label(((x + 1.2) / 2, -0.3), "n", [str(string(surface))])
    return True


def _line_of_bodies(impacts: Sequence[Stage]) -> list[str]:
    """The bodies of direct impacts in the order they are struck: ``[1, 2]`` then ``[2, 3]`` is 1, 2, 3."""
    order: list[str] = []
    for stage in impacts:
        order += [body for body in stage.fields["bodies"] if body not in order]
    return order


def _direct(canvas: Drawing, scene: SceneView, impacts: Sequence[Stage]) -> bool:
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
    x = 0.0
    for index, body in enumerate(bodies):
        if index:
            x += gap
        if body not in masses:  # a wall, hatched on its far side
            canvas.line((x, 0.0), (x, 1.8), width=1.0)
            for y in (0.15, 0.4, 0.65, 0.9, 1.15, 1.4, 1.65):
                canvas.line((x, y), (x + 0.16, y + 0.16), width=0.4)
            canvas.label((x + 0.3, 1.0), "w", [str(string(body))])
            continue
        side = sides[body]
        canvas.rect((x, 0.0), (x + side, side))
        canvas.label((x + side / 2, side / 2), "c", [str(string(body))])
        canvas.label((x + side / 2, -0.12), "n", scene.mass(body))
        _horizontal_velocity(canvas, scene, (x + side / 2, side + 0.3), before[body], fastest)
        x += side
    canvas.line((-0.3, 0.0), (x + 0.3, 0.0), width=1.0)
    return True


def _horizontal_velocity(canvas: Drawing, scene: SceneView, at: Point, velocity: Velocity | None,
                         fastest: float) -> None:
    """Above a body: an arrow centred on ``at`` the way it moves, 1.6 cm for the fastest body of the
    figure (at least 0.5 cm), labelled with its velocity as given; ``v = 0`` for a body at rest."""
    given = velocity.n if velocity is not None else None
    value = scene.value(given) if given is not None else 0.0
    if given is None or not (_m.isfinite(value) and value != 0 and fastest > 0):
        canvas.label((at[0], at[1] - 0.2), "s", ["v = 0"] if given is None else scene.given(given))
        return
    half = max(0.25, 0.8 * abs(value) / fastest) * (1 if value > 0 else -1)
    canvas.arrow((at[0] - half, at[1]), (at[0] + half, at[1]))
    canvas.label((at[0], at[1] + 0.2), "s", scene.given(given))


def _row(canvas: Drawing, scene: SceneView) -> None:
    """Bodies side by side, named, with their masses: the figure of a scene of no known kind."""
    x = 0.0
    for body in scene.template.scene.bodies:
        canvas.circle((x + 0.5, 0.5), 0.5)
        canvas.label((x + 0.5, 0.5), "c", [str(string(body))])
        canvas.label((x + 0.5, -0.1), "n", scene.mass(body) or ["(fixed)"])
        x += 1.8

