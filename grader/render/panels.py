"""A figure is the scene's panels in stage order: each effect draws its own panel, so a template written
tomorrow gets a true figure with no drawing code of its own.

The stages are read in order. The effect of the first stage not yet drawn claims its panel
(:data:`PANELS`, keyed by effect): its own stage, and the stages that its panel draws with it — a fall
claims the impact it ends in and the rises after it (one panel: the body at its drop height and its
rebound height), an impact the slide to rest or the swing of the struck body that follows (the skid;
the ballistic pendulum), a run of direct impacts (a line of bodies), a flight to a wall the impact
there and the flight after. The stages that only name quantities (``velocity``, ``angle_between``,
``impact_geometry``) are drawn in the panel of the impact they describe. One panel is the figure; two
or more are a strip, each titled with what happens in it ("1 · A swings", "2 · A strikes B; B swings"),
each body named the same in every panel.

Given values are labelled with the variant's numbers and drawn to scale; an asked quantity is drawn
but not to scale, and labelled with its name only. Each panel keeps a record of the bodies it named
(:class:`~grader.render.drawing.Drawing`), and the figure a record of its panels
(:class:`FigureRecord`): the tests check it against the scene.

The drawing lives here, in ``render``, keyed by effect name, and not in the effects' modules
(``physics/effects``): physics must not import render (docs/design.md, "Figures").
"""

from __future__ import annotations

import math as _m
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from itertools import pairwise

from grader.model.scene import Stage
from grader.render.direct import direct, row
from grader.render.drawing import Drawing, VelocityArrow
from grader.render.drop import bounces, drop
from grader.render.oblique import incline, offset_spheres, spheres, surface
from grader.render.pendulum import swing_figure
from grader.render.scene_view import SceneView, find_stage
from grader.render.series import bounce_series
from grader.render.skid import horizontal_dimension, skid
from grader.render.trajectory import flight_time, trajectory
from grader.render.typst_text import Typ, string
from grader.render.work_impulse import impulse, separation, slope, spring, stick

ANNOTATIONS = frozenset({"velocity", "angle_between", "impact_geometry"})
STRIP_WIDTH = 5.2  # cm a panel of a strip may take (two side by side beside the answer blanks)


@dataclass(frozen=True)
class PanelRecord:
    """What a panel drew: its title (empty for a figure of one panel), the stages (their indices in
    the scene), the bodies it named, in the order named, and its velocity arrows."""

    title: str
    stages: tuple[int, ...]
    bodies: tuple[str, ...]
    velocities: tuple[VelocityArrow, ...] = ()


@dataclass(frozen=True)
class FigureRecord:
    """A figure's panels, in stage order."""

    panels: tuple[PanelRecord, ...]


Claim = Callable[[Sequence[Stage], int], int]
Draw = Callable[[Drawing, SceneView, Sequence[Stage]], bool]


@dataclass(frozen=True)
class PanelKind:
    """How an effect's stage is drawn: ``claim(stages, i)`` is how many stages from ``stages[i]`` (the
    scene's stages that are drawn, in order) its panel draws; ``draw`` draws them (False: it cannot,
    and the panel is the bodies named in a row); ``drawn`` says it in words (``grader effects``)."""

    claim: Claim
    draw: Draw
    drawn: str


# --- claims -------------------------------------------------------------------------------------

def _one(stages: Sequence[Stage], i: int) -> int:
    return 1


def _bodies(stage: Stage) -> tuple[str, ...]:
    if "bodies" in stage.fields:
        return tuple(stage.fields["bodies"])
    return tuple(b for b in (stage.fields.get("body"), stage.fields.get("with")) if b)


def _moves_on(stage: Stage | None, bodies: Sequence[str]) -> bool:
    """Whether ``stage`` carries a body of ``bodies`` on sideways (a slide, a swing, a flight)."""
    if stage is None or stage.effect not in ("slide", "swing", "flight"):
        return False
    return bool(set(_bodies(stage)) & set(bodies))


def _claim_fall(stages: Sequence[Stage], i: int) -> int:
    """A fall, the impact it ends in (unless a body then moves on sideways: that impact is its own
    panel) and the rises, falls and impacts of the same body on the same surface after it."""
    body = stages[i].fields["body"]
    j = i + 1
    if j >= len(stages) or stages[j].effect != "impact" or stages[j].fields["bodies"][0] != body:
        return 1
    pair = tuple(stages[j].fields["bodies"])
    if _moves_on(stages[j + 1] if j + 1 < len(stages) else None, pair):
        return 1
    k = j + 1
    while k < len(stages) and ((stages[k].effect in ("rise", "free_fall") and stages[k].fields["body"] == body)
                               or (stages[k].effect == "impact" and tuple(stages[k].fields["bodies"]) == pair)):
        k += 1
    return k - i


def _claim_impact(stages: Sequence[Stage], i: int) -> int:
    """An impact; with the slide to rest of both bodies together after it (a skid); with the swing of the
    struck body after it when the striking body does nothing else in the scene (a bullet); a run of
    direct impacts."""
    impact = stages[i]
    after = stages[i + 1] if i + 1 < len(stages) else None
    if impact.is_oblique:
        return 1
    bodies = tuple(impact.fields["bodies"])
    if after is not None and after.effect == "slide" and set(_bodies(after)) == set(bodies):
        return 2  # the bodies locked together, skidding to rest: the skid, from the point of impact
    if after is not None and after.effect == "spring" and set(_bodies(after)) == set(bodies):
        return 2  # a body that embeds in a block on a spring: the spring, the body coming in
    striker_came = any(set(_bodies(s)) & {bodies[0]} for s in stages[:i])
    if after is not None and after.effect == "swing" and after.fields["body"] == bodies[1] and not striker_came:
        return 2  # a body that only strikes (a bullet) and the pendulum it strikes: the ballistic pendulum
    k = i + 1
    while k < len(stages) and stages[k].effect == "impact" and not stages[k].is_oblique:
        k += 1
    return k - i


def _claim_flight(stages: Sequence[Stage], i: int) -> int:
    """A flight to a wall, the impact there and the flight back to the ground (a flight back to another wall is
    the next panel's: a ball bouncing between two walls)."""
    flight = stages[i]
    if flight.fields["until"] != "wall" or i + 1 >= len(stages) or stages[i + 1].effect != "impact":
        return 1
    back = stages[i + 2] if i + 2 < len(stages) else None
    return 3 if back is not None and back.effect == "flight" and back.fields["body"] == flight.fields["body"] \
        and back.fields["until"] == "ground" else 2


# --- drawings -----------------------------------------------------------------------------------

def _draw_fall(canvas: Drawing, scene: SceneView, group: Sequence[Stage]) -> bool:
    fall = group[0]
    impact = next((s for s in group if s.effect == "impact"), None)
    rises = [s for s in group if s.effect == "rise"]
    if impact is None:
        return drop(canvas, scene, fall, None, None)
    fixed = scene.template.scene.bodies[impact.fields["bodies"][1]].mass is None
    if len(rises) > 1 and fixed:
        return bounces(canvas, scene, fall, rises, impact.fields["bodies"][1])
    if impact.is_oblique and fixed:
        return incline(canvas, scene, impact)
    return drop(canvas, scene, fall, impact, rises[0] if rises else None)


def _draw_impact(canvas: Drawing, scene: SceneView, group: Sequence[Stage]) -> bool:
    impact = group[0]
    if len(group) == 2 and group[1].effect == "slide":
        return skid(canvas, scene, impact, group[1])
    if len(group) == 2 and group[1].effect == "swing":
        return swing_figure(canvas, scene, group[1], impact)
    if len(group) == 2 and group[1].effect == "spring":
        return spring(canvas, scene, group[1], impact)
    if not impact.is_oblique:
        return direct(canvas, scene, group)
    if scene.template.scene.bodies[impact.fields["bodies"][1]].mass is None:
        return surface(canvas, scene, impact)
    geometry = find_stage(scene.template.scene.stages, "impact_geometry", before=impact.index)
    if geometry is not None and tuple(geometry.fields["bodies"]) == tuple(impact.fields["bodies"]):
        return offset_spheres(canvas, scene, geometry, impact)
    return spheres(canvas, scene, impact)


def _draw_flight(canvas: Drawing, scene: SceneView, group: Sequence[Stage]) -> bool:
    flight = group[0]
    if flight.fields["until"] == "wall":
        return trajectory(canvas, scene, flight, group[2] if len(group) == 3 else None,
                          group[1] if len(group) > 1 else None)
    return _flight(canvas, scene, flight)


def _flight(canvas: Drawing, scene: SceneView, flight: Stage) -> bool:
    """A flight to the ground: the path to scale from the start, its height and distance dimensioned."""
    g = scene.values.get("g", _m.nan)
    vx, vy, h0 = (scene.value(flight.fields[key]) for key in ("horizontal", "vertical", "height"))
    if not all(_m.isfinite(v) for v in (g, vx, vy, h0)) or h0 < 0 or g <= 0 or vx == 0:
        return False
    time = flight_time(vy, h0, g)
    points = [(abs(vx) * time * i / 32, h0 + vy * time * i / 32 - g * (time * i / 32) ** 2 / 2) for i in range(33)]
    reach, top = points[-1][0], max(y for _, y in points)
    if not (_m.isfinite(reach) and reach > 0 and top > 0):
        return False
    scale = min(4.6 / reach, 3.2 / top)
    drawn = [(x * scale, y * scale) for x, y in points]
    canvas.ground(-0.4, drawn[-1][0] + 0.4, 0.0)
    canvas.path(drawn, width=0.8)
    canvas.strokes += list(pairwise(drawn))
    canvas.circle(drawn[0], 0.12)
    canvas.name((drawn[0][0], drawn[0][1] + 0.25), "s", flight.fields["body"])
    if h0 > 0:
        canvas.dimension((-0.35, 0.0), (-0.35, drawn[0][1]), scene.given(flight.fields["height"]), "left")
    horizontal_dimension(canvas, 0.0, drawn[-1][0], -0.5, scene.given(flight.fields["distance"]))
    return True


def _draw_swing(canvas: Drawing, scene: SceneView, group: Sequence[Stage]) -> bool:
    return swing_figure(canvas, scene, group[0], None)


def _draw_slide(canvas: Drawing, scene: SceneView, group: Sequence[Stage]) -> bool:
    """The body (and what slides with it) at rest at the end of its skid, the distance dimensioned,
    its speed at the start an arrow, the friction coefficient beside it."""
    slide = group[0]
    distance = scene.value(slide.fields["distance"])
    if not (_m.isfinite(distance) and distance >= 0):
        return False
    shown = 3.6 if scene.is_given(slide.fields["distance"]) else 3.0  # one skid: its length is the scale
    sliders = _bodies(slide)
    width = 0.9
    right = shown + width * len(sliders)
    canvas.ground(-0.3, right + 0.3, 0.0)
    canvas.line((0.0, 0.06), (shown, 0.06), width=2.0, gray=True)  # the skid mark
    for number, body in enumerate(sliders):
        x = shown + number * width
        canvas.rect((x, 0.0), (x + width, 0.6))
        canvas.name((x + width / 2, 0.3), "c", body)
    canvas.velocity((0.0, 0.9), (1.2, 0.9), scene.given(slide.fields["speed"]))
    canvas.label((0.6, 1.1), "s", scene.given(slide.fields["speed"]))
    horizontal_dimension(canvas, 0.0, shown, -0.45, scene.given(slide.fields["distance"]))
    canvas.label((right, 0.8), "se", scene.given(slide.fields["friction"]))
    return True


def _draw_rise(canvas: Drawing, scene: SceneView, group: Sequence[Stage]) -> bool:
    """The body at the bottom, its speed up an arrow, and dashed at the height it rises to, dimensioned."""
    rise = group[0]
    height = scene.value(rise.fields["height"])
    if not _m.isfinite(height):
        return False
    top = 3.0 if scene.is_given(rise.fields["height"]) else 2.4
    canvas.ground(0.6, 3.0, 0.0)
    canvas.circle((1.8, 0.3), 0.3)
    canvas.circle((1.8, top + 0.3), 0.3, "dashed", fill=False)
    canvas.velocity((2.4, 0.4), (2.4, 1.4), scene.given(rise.fields["speed"]))
    canvas.label((2.55, 0.9), "w", scene.given(rise.fields["speed"]))
    canvas.name((1.8, top + 0.75), "s", rise.fields["body"])
    canvas.dimension((1.0, 0.0), (1.0, top), scene.given(rise.fields["height"]), "left")
    return True


def _draw_spring(canvas: Drawing, scene: SceneView, group: Sequence[Stage]) -> bool:
    return spring(canvas, scene, group[0], None)


def _draw_slope(canvas: Drawing, scene: SceneView, group: Sequence[Stage]) -> bool:
    return slope(canvas, scene, group[0])


def _draw_stick(canvas: Drawing, scene: SceneView, group: Sequence[Stage]) -> bool:
    return stick(canvas, scene, group[0])


def _draw_separation(canvas: Drawing, scene: SceneView, group: Sequence[Stage]) -> bool:
    return separation(canvas, scene, group[0])


def _draw_impulse(canvas: Drawing, scene: SceneView, group: Sequence[Stage]) -> bool:
    return impulse(canvas, scene, group[0])


def _draw_bounces(canvas: Drawing, scene: SceneView, group: Sequence[Stage]) -> bool:
    return bounce_series(canvas, scene, group[0])


PANELS: dict[str, PanelKind] = {
    "free_fall": PanelKind(_claim_fall, _draw_fall,
                           "the body at its drop height above what it falls onto (the ground, a fixed floor, a "
                           "driven plate with its velocity, or a pile drawn under it), the height dimensioned, to "
                           "scale when given; with the impact it ends in and the rises after it (a rebound dashed at "
                           "its height, two or more as arcs); onto a fixed surface it strikes obliquely, an incline "
                           "at its angle, n and t drawn at the contact"),
    "rise": PanelKind(_one, _draw_rise,
                      "after a fall and its impact: in the fall's panel, the body dashed at its rebound height; "
                      "alone: the body, its speed up, and dashed at the height it rises to, dimensioned"),
    "impact": PanelKind(_claim_impact, _draw_impact,
                        "direct: the bodies in a line (a run of direct impacts, one line), blocks unless the scene "
                        "gives them a shape, areas following the masses (a fixed one a hatched wall; balls that "
                        "hang from cords level on their line of centres), each with its velocity before as an "
                        "arrow the way it moves; oblique against a fixed body: the surface with the incoming and "
                        "rebound velocities at their angles; oblique between two bodies: two touching circles with "
                        "n, t and the incoming velocity; with the slide to rest after it, the skid; with the struck "
                        "body's swing after it, the pendulum and the striking body"),
    "swing": PanelKind(_one, _draw_swing,
                       "the cord at rest and at its greatest angle, to scale, and the arc between, the body a "
                       "block unless the scene gives it a shape; a body that "
                       "strikes the hanging one (the impact before the swing) comes in from the left with its "
                       "velocity"),
    "slide": PanelKind(_one, _draw_slide,
                       "after an impact, in its panel: two rows on one scale, the bodies at the impact and at rest, "
                       "the skid from the point of impact dimensioned; alone: the body at rest at the end of its "
                       "skid mark, the distance dimensioned, its speed at the start an arrow"),
    "flight": PanelKind(_claim_flight, _draw_flight,
                        "the path: to a wall (with the impact there), solid to the wall, dashed from the wall to "
                        "the ground (the flight after the impact), given lengths to scale, an asked height on the "
                        "wall or landing distance drawn but not to scale; to the ground, to scale from its start "
                        "height"),
    "bounces": PanelKind(_one, _draw_bounces,
                         "the drop and the decaying arcs until the body rests, heights and time along the floor to "
                         "scale, the bounce whose height is asked marked by its name"),
    "spring": PanelKind(_one, _draw_spring,
                        "horizontal: the wall, the coils at their natural length, the block (with what is stuck to "
                        "it) moving toward the wall, dashed at the greatest compression, dimensioned; after the "
                        "impact that sets the block moving, in its panel, the striking body coming in with its "
                        "velocity; vertical: the platform on the spring at its static deflection below the natural "
                        "length, what lands on it, the greatest compression dimensioned"),
    "slope": PanelKind(_one, _draw_slope,
                       "the path: an incline at its angle (to scale when given) with the distance along it, a "
                       "smooth ramp with its height dimensioned, or a level floor with the distance dimensioned; "
                       "a rough surface hatched, with its friction coefficient; the body at the start with its "
                       "speed the way it moves, dashed at the end with its speed there"),
    "stick": PanelKind(_one, _draw_stick,
                       "the n (east) and t (north) axes at the point of impact, both bodies coming in along their "
                       "velocities (given speeds to scale), the wreck's direction dashed from the point, its angle "
                       "marked (not to scale when asked)"),
    "separation": PanelKind(_one, _draw_separation,
                            "the whole (the two parts together) with its velocity or at rest, and the energy "
                            "released; then the parts flying apart along n, each with its velocity the way it "
                            "moves"),
    "impulse": PanelKind(_one, _draw_impulse,
                         "the body with its velocity just before coming in and just after going out, and the "
                         "impulse on it a thick arrow labelled with its name (and the average force); a body "
                         "stopped over a distance on the cushion under it, the distance dimensioned"),
}
"""How each effect's stage is drawn, keyed by effect name."""

_SAID = {"free_fall": "{0} falls", "rise": "{0} rises", "impact": "{0} strikes {1}", "slide": "{0} slides",
         "swing": "{0} swings", "flight": "{0} flies", "bounces": "{0} bounces", "spring": "{0} compresses the spring",
         "slope": "{0} slides", "stick": "{0} and {1} stick", "separation": "{0} and {1} separate",
         "impulse": "the impulse on {0}"}


# --- the figure ---------------------------------------------------------------------------------

def panel_groups(stages: Sequence[Stage]) -> list[list[Stage]]:
    """The scene's stages as panels, in order: each panel's stages, those that only name quantities
    with the impact they describe (the nearest, the one after first)."""
    drawn = [s for s in stages if s.effect not in ANNOTATIONS]
    groups: list[list[Stage]] = []
    i = 0
    while i < len(drawn):
        kind = PANELS.get(drawn[i].effect)
        taken = max(1, kind.claim(drawn, i)) if kind is not None else 1
        groups.append(drawn[i:i + taken])
        i += taken
    if not groups:
        return [list(stages)]
    for stage in (s for s in stages if s.effect in ANNOTATIONS):
        impacts = [(abs(s.index - stage.index) + (0.5 if s.index < stage.index else 0), n)
                   for n, group in enumerate(groups) for s in group if s.effect == "impact"]
        near = min(impacts)[1] if impacts else min((abs(g[0].index - stage.index), n) for n, g in enumerate(groups))[1]
        groups[near].append(stage)
    return [sorted(group, key=lambda s: s.index) for group in groups]


def _title(group: Sequence[Stage]) -> str:
    said = [_SAID[s.effect].format(*_bodies(s)) for s in group if s.effect in _SAID]
    return "; ".join(dict.fromkeys(said))


def _panel(scene: SceneView, group: Sequence[Stage]) -> Drawing:
    canvas = Drawing()
    drawn = [s for s in group if s.effect not in ANNOTATIONS]  # the others label what these draw
    kind = PANELS.get(drawn[0].effect) if drawn else None
    if kind is not None and kind.draw(canvas, scene, drawn):
        return canvas
    canvas = Drawing()  # a panel that cannot be drawn: its bodies in a row, named
    bodies = [b for s in group for b in _bodies(s)]
    row(canvas, scene, list(dict.fromkeys(bodies)) or list(scene.template.scene.bodies))
    return canvas


def strip_widths(naturals: Sequence[float]) -> list[float]:
    """The widths (cm) the panels of a strip may take, two columns: each column as wide as its widest
    panel, the two together at most ``2 * STRIP_WIDTH``; where they are wider, a column narrower than
    ``STRIP_WIDTH`` keeps its width and the other takes the rest (a tall fall beside a wide spring: the
    spring is not shrunk until its labels crowd it), else each takes ``STRIP_WIDTH``.

    >>> strip_widths([3.0, 6.5, 4.0])
    [4.0, 6.4, 4.0]
    >>> strip_widths([6.0, 7.0])
    [5.2, 5.2]
    """
    columns = [max(naturals[0::2]), max(naturals[1::2], default=0.0)]
    if sum(columns) > 2 * STRIP_WIDTH:
        narrow = 0 if columns[0] <= columns[1] else 1
        if columns[narrow] >= STRIP_WIDTH:
            columns = [STRIP_WIDTH, STRIP_WIDTH]
        else:
            columns[1 - narrow] = 2 * STRIP_WIDTH - columns[narrow]
    return [columns[n % 2] for n in range(len(naturals))]


def panels_figure(scene: SceneView, groups: Sequence[Sequence[Stage]] | None = None) -> tuple[Typ, FigureRecord]:
    """The figure of a scene (its panels in stage order, or the panels ``groups`` of its stages) as a
    Typst expression (code mode), and the record of what it drew."""
    groups = panel_groups(scene.template.scene.stages) if groups is None else groups
    drawings = [_panel(scene, group) for group in groups]
    titles = [f"{n} · {_title(g)}" if len(groups) > 1 else "" for n, g in enumerate(groups, start=1)]
    record = FigureRecord(tuple(PanelRecord(title, tuple(s.index for s in group), tuple(canvas.bodies),
                                            tuple(canvas.velocities))
                                for title, group, canvas in zip(titles, groups, drawings, strict=True)))
    if len(drawings) == 1:
        return drawings[0].typst(), record
    widths = strip_widths([canvas.natural_width() for canvas in drawings])
    shown = [f"stack(dir: ttb, spacing: 0.2cm, text(size: 8pt, fill: luma(80), {string(title)}), "
             f"{canvas.typst(width)})" for title, canvas, width in zip(titles, drawings, widths, strict=True)]
    columns = min(2, len(shown))
    return Typ(f"grid(columns: {columns}, column-gutter: 0.5cm, row-gutter: 0.4cm, align: bottom + left, "
               + ", ".join(shown) + ")"), record
