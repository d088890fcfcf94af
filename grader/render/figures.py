"""Figures of a scene, to one variant's scale, as Typst drawing calls (see ``templates/figures.typ``).

The kind of figure follows from the scene's structure, never from the template's id:

* a body falls (``free_fall``) onto a fixed surface or onto a second body, maybe rising again after
  the impact: the surface (or a pile, drawn under a block), the body at its drop height and, dashed,
  at its rebound height, with dimension lines; heights to scale;
* an oblique ``impact`` (a ``velocity`` stage gives the components) with a fixed body: the surface,
  the incoming and rebound velocity arrows at their angles, lengths proportional to the speeds;
* an oblique impact of two bodies: two touching circles, the line of centres n and the tangent t,
  the incoming velocity at its angle to n;
* a direct impact of two bodies: two blocks whose areas follow the mass ratio, the velocity arrows
  of the moving bodies, the bodies at rest marked so;
* anything else: the bodies in a row, labelled.

Geometry is built in centimetres with y up, then shifted so the drawing's bounding box (labels
included, by an estimate of their size) starts at the origin, and flipped for Typst.

>>> canvas = Canvas()
>>> canvas.line((0, 0), (2, 1))
>>> canvas.typst().startswith("fig-canvas(2.10, 1.10")
True
"""

from __future__ import annotations

import math as _m
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from grader.assign.variants import ProblemVariant
from grader.bank.template import Template
from grader.model.expr import Node, Sym, names
from grader.model.kernel import evaluate
from grader.model.scene import Stage, Velocity
from grader.render.worked import Typ, math, name, string

Point = tuple[float, float]
PAD = 0.05
MAX_WIDTH = 7.6
CHAR = 0.15  # cm per character of a label at the figure's text size, an estimate for the bounding box
LINE = 0.42  # cm per line of a label


def _fmt(value: float) -> str:
    return f"{value:.2f}"


@dataclass
class Canvas:
    """Drawing calls with their coordinates (cm, y up), what they cover, and what labels must avoid."""

    calls: list[tuple[str, list[Point], float, str]] = field(default_factory=list)
    points: list[Point] = field(default_factory=list)
    labels: list[tuple[Point, tuple[float, float, float, float]]] = field(default_factory=list)
    occupied: list[tuple[float, float, float, float]] = field(default_factory=list)
    strokes: list[tuple[Point, Point]] = field(default_factory=list)

    def _add(self, kind: str, points: Sequence[Point], options: str = "", radius: float = 0.0) -> None:
        for x, y in points:
            self.points += [(x - radius, y - radius), (x + radius, y + radius)]
        self.calls.append((kind, list(points), radius, options))

    def line(self, a: Point, b: Point, width: float = 0.6, dash: str | None = None, gray: bool = False) -> None:
        """A straight line."""
        self._add("fig-line", [a, b], _stroke(width, dash, gray))

    def path(self, points: Sequence[Point], width: float = 0.6, dash: str | None = None) -> None:
        """An open polyline."""
        self._add("fig-path", points, _stroke(width, dash, False))

    def polygon(self, points: Sequence[Point], gray: bool = False) -> None:
        """A filled polygon."""
        self._add("fig-poly", points, "fill: luma(150)" if gray else "")

    def circle(self, center: Point, radius: float, dash: str | None = None, fill: bool = True) -> None:
        """A circle (a body)."""
        self._add("fig-circle", [center], f"{_stroke(0.8, dash, False)}{', fill: luma(235)' if fill else ''}", radius)

    def rect(self, low: Point, high: Point, dash: str | None = None, fill: str = "luma(235)") -> None:
        """A rectangle between two corners (a block, a plate)."""
        self._add("fig-rect", [(low[0], high[1]), (high[0], low[1])], f"{_stroke(0.8, dash, False)}, fill: {fill}")
        self.occupied.append((low[0], low[1], high[0], high[1]))

    def _label_box(self, at: Point, anchor: str, lines: Sequence[str]) -> tuple[float, float, float, float]:
        width = max(_visible(line) for line in lines) * CHAR
        height = LINE * len(lines)
        fx = 0.0 if "w" in anchor else 1.0 if "e" in anchor else 0.5
        fy = 0.0 if "n" in anchor else 1.0 if "s" in anchor else 0.5
        left, top = at[0] - fx * width, at[1] + fy * height
        return left, top - height, left + width, top

    def fits(self, at: Point, anchor: str, lines: Sequence[str]) -> bool:
        """Whether a label placed so would stay clear of the labels and blocks drawn so far."""
        box = self._label_box(at, anchor, lines)
        x0, y0, x1, y1 = box
        return not any(x0 < b[2] and b[0] < x1 and y0 < b[3] and b[1] < y1 for b in self.occupied) and \
            not any(_crosses(box, a, b) for a, b in self.strokes)

    def label(self, at: Point, anchor: str, lines: Sequence[str]) -> None:
        """Math lines stacked, placed so that ``anchor`` (c, n, s, e, w, ne, nw, se, sw) of the
        label is at ``at``."""
        box = self._label_box(at, anchor, lines)
        self.labels.append((at, (box[0] - at[0], box[1] - at[1], box[2] - at[0], box[3] - at[1])))
        self.occupied.append(box)
        body = ", ".join(f"${line}$" for line in lines)
        self.calls.append(("fig-label", [at], 0.0, f"{string(anchor)}, ({body},)"))

    def arrow(self, tail: Point, tip: Point, width: float = 0.9, head: float = 0.22) -> None:
        """An arrow: a line and a triangular head."""
        dx, dy = tip[0] - tail[0], tip[1] - tail[1]
        length = _m.hypot(dx, dy) or 1.0
        ux, uy = dx / length, dy / length
        base = (tip[0] - ux * head, tip[1] - uy * head)
        self.strokes.append((tail, tip))
        self.line(tail, (tip[0] - ux * head * 0.8, tip[1] - uy * head * 0.8), width)
        self.polygon([tip, (base[0] - uy * head * 0.38, base[1] + ux * head * 0.38),
                      (base[0] + uy * head * 0.38, base[1] - ux * head * 0.38)])

    def arc(self, center: Point, radius: float, start: float, end: float) -> None:
        """A circular arc between two angles (radians, counter-clockwise from +x)."""
        steps = max(4, int(abs(end - start) / 0.08))
        self.path([(center[0] + radius * _m.cos(start + (end - start) * i / steps),
                    center[1] + radius * _m.sin(start + (end - start) * i / steps)) for i in range(steps + 1)],
                  width=0.5)

    def ground(self, x0: float, x1: float, y: float, below: bool = True) -> None:
        """A fixed surface: a line hatched on the side of the body."""
        self.line((x0, y), (x1, y), width=1.0)
        sign = -1 if below else 1
        x = x0 + 0.1
        while x < x1:
            self.line((x, y), (x - 0.16, y + sign * 0.16), width=0.4)
            x += 0.18

    def dimension(self, low: Point, high: Point, lines: Sequence[str], side: str) -> None:
        """A vertical dimension line from ``low`` to ``high`` with arrows, labelled on ``side``."""
        x = low[0]
        length = high[1] - low[1]
        if length > 0.6:
            self.arrow((x, (low[1] + high[1]) / 2), (x, high[1]), width=0.5, head=0.15)
            self.arrow((x, (low[1] + high[1]) / 2), (x, low[1]), width=0.5, head=0.15)
        else:  # too short for arrows inside: they point in from outside
            self.arrow((x, high[1] + 0.4), (x, high[1]), width=0.5, head=0.15)
            self.arrow((x, low[1] - 0.4), (x, low[1]), width=0.5, head=0.15)
            if length > 0:
                self.line(low, high, width=0.5)
        middle = (x + (-0.15 if side == "left" else 0.15), (low[1] + high[1]) / 2)
        # "h = 1.20 m" as two lines, "h" over "= 1.20 m": narrower beside a tall figure
        split = [part for line in lines for part in ([line] if " = " not in line else
                                                      [line.split(" = ", 1)[0], "= " + line.split(" = ", 1)[1]])]
        self.label(middle, "e" if side == "left" else "w", split)

    def _extent(self, scale: float) -> tuple[float, float, float, float]:
        """The bounding box with the geometry scaled by ``scale`` and the labels at their size."""
        xs = [x * scale for x, _ in self.points] + [a[0] * scale + d for a, box in self.labels for d in box[::2]]
        ys = [y * scale for _, y in self.points] + [a[1] * scale + d for a, box in self.labels for d in box[1::2]]
        return (min(xs), min(ys), max(xs), max(ys)) if xs else (0.0, 0.0, 0.0, 0.0)

    def typst(self) -> Typ:
        """A ``fig-canvas`` call drawing everything, shifted to start at the origin; a drawing wider
        than ``MAX_WIDTH`` has its geometry (not its labels) scaled down until it fits."""
        scale = 1.0
        while scale > 0.5 and self._extent(scale)[2] - self._extent(scale)[0] + 2 * PAD > MAX_WIDTH:
            scale -= 0.05
        x0, y0, x1, y1 = self._extent(scale)

        def place(point: Point) -> str:
            return f"({_fmt(point[0] * scale - x0 + PAD)}, {_fmt(y1 - point[1] * scale + PAD)})"
        body = []
        for kind, points, radius, options in self.calls:
            arguments = [place(p) for p in points] + ([_fmt(radius * scale)] if radius else []) + \
                ([options] if options else [])
            body.append(f"  {kind}({', '.join(arguments)})")
        return Typ(f"fig-canvas({_fmt(x1 - x0 + 2 * PAD)}, {_fmt(y1 - y0 + 2 * PAD)}, {{\n" + "\n".join(body) + "\n})")


def _crosses(box: tuple[float, float, float, float], a: Point, b: Point) -> bool:
    """Whether the segment from ``a`` to ``b`` passes through the box (Liang-Barsky clipping)."""
    dx, dy = b[0] - a[0], b[1] - a[1]
    low, high = 0.0, 1.0
    for p, q in ((-dx, a[0] - box[0]), (dx, box[2] - a[0]), (-dy, a[1] - box[1]), (dy, box[3] - a[1])):
        if p == 0:
            if q < 0:
                return False
            continue
        t = q / p
        if p < 0:
            low = max(low, t)
        else:
            high = min(high, t)
        if low > high:
            return False
    return True


def _stroke(width: float, dash: str | None, gray: bool) -> str:
    parts = [f"w: {width}pt"]
    if dash:
        parts.append(f"dash: {string(dash)}")
    if gray:
        parts.append("paint: luma(140)")
    return ", ".join(parts)


def _visible(line: str) -> int:
    """A rough count of the characters a math line shows (for the bounding box)."""
    shown = line.replace('"', "").replace(" thin ", " ").replace(" degree", "°").replace("_", "")
    for word in ("theta", "alpha", "beta", "phi", "omega", "mu"):
        shown = shown.replace(word, "x")
    return len(shown)


# --- what the scene says ------------------------------------------------------------------------

@dataclass(frozen=True)
class _Scene:
    """One variant's scene: values of every quantity (SI, symbols at 1) and how to label them."""

    template: Template
    variant: ProblemVariant
    values: Mapping[str, float]

    def value(self, node: Node | None) -> float:
        if node is None:
            return 0.0
        try:
            with np.errstate(all="ignore"):
                return float(evaluate(node, self.values))
        except KeyError:
            return _m.nan

    def given(self, node: Node) -> list[str]:
        """``h_drop = 1863 mm`` for a parameter, the name (or expression) otherwise."""
        if isinstance(node, Sym) and node.name in self.template.parameters:
            unit = self.template.parameters[node.name].unit.text
            printed = self.variant.printed[node.name]
            shown = " degree" if unit == "deg" else f" thin {string(unit)}" if unit else ""
            return [f"{name(node.name)} = {printed}{shown}"]
        return [math(node)]

    def mass_value(self, body: str) -> list[str]:
        """A body's mass as its printed value and unit (``1.5 kg``) when a parameter gives it."""
        mass = self.template.scene.bodies[body].mass
        if isinstance(mass, Sym) and mass.name in self.template.parameters:
            return [self.given(mass)[0].split(" = ", 1)[1]]
        return self.mass(body)

    def mass(self, body: str) -> list[str]:
        """A body's mass as given: ``m_1 = 1.5 kg``, or ``p m = 1.67 m``."""
        mass = self.template.scene.bodies[body].mass
        if mass is None:
            return []
        if isinstance(mass, Sym):
            return self.given(mass)
        printed = {n: self.variant.printed[n] for n in names(mass) if n in self.template.parameters}
        shown = math(mass)
        substituted = math(mass, printed)
        return [shown if substituted == shown else f"{shown} = {substituted}"]


def _stage(stages: Sequence[Stage], effect: str, before: int | None = None, after: int | None = None,
           body: str | None = None) -> Stage | None:
    for stage in stages:
        if stage.effect != effect or (before is not None and stage.index >= before) or \
                (after is not None and stage.index <= after):
            continue
        if body is None or stage.fields.get("body") == body:
            return stage
    return None


def _velocity_stage(stages: Sequence[Stage], velocity: Velocity | None) -> Stage | None:
    """The ``velocity`` stage that gives (or takes) the components of ``velocity``."""
    if velocity is None:
        return None
    wanted = set().union(*(names(part) for part in (velocity.n, velocity.t) if part is not None))
    for stage in stages:
        if stage.effect == "velocity" and (names(stage.fields["n"]) | names(stage.fields["t"])) & wanted:
            return stage
    return None


def figure(template: Template, variant: ProblemVariant, values: Mapping[str, float]) -> Typ:
    """The figure of one variant's scene, as a Typst expression (code mode)."""
    scene = _Scene(template, variant, values)
    stages = template.scene.stages
    impact = _stage(stages, "impact")
    canvas = Canvas()
    if impact is None:
        fall = _stage(stages, "free_fall")
        if fall is None or not _drop(canvas, scene, fall, None, None):
            canvas = Canvas()
            _row(canvas, scene)
        return canvas.typst()
    first, second = impact.fields["bodies"]
    fall = _stage(stages, "free_fall", before=impact.index, body=first)
    drawn = False
    if fall is not None:
        drawn = _drop(canvas, scene, fall, impact, _stage(stages, "rise", after=impact.index, body=first))
    elif impact.is_oblique and template.scene.bodies[second].mass is None:
        drawn = _surface(canvas, scene, impact)
    elif impact.is_oblique:
        drawn = _spheres(canvas, scene, impact)
    else:
        drawn = _direct(canvas, scene, impact)
    if not drawn:
        canvas = Canvas()
        _row(canvas, scene)
    return canvas.typst()


# --- the figures --------------------------------------------------------------------------------

def _drop(canvas: Canvas, scene: _Scene, fall: Stage, impact: Stage | None, rise: Stage | None) -> bool:
    """A body at its drop height above a floor or a pile (or the ground, without an impact), and
    dashed at its rebound height."""
    first = fall.fields["body"]
    second = impact.fields["bodies"][1] if impact is not None else None
    drop = scene.value(fall.fields["height"])
    rebound = scene.value(rise.fields["height"]) if rise is not None else _m.nan
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
    if fixed:
        canvas.ground(0.9, 5.2, 0.0)
        canvas.label((3.3, -0.3), "n", [str(string(second or "ground"))])
    else:  # a pile: its top is the impact surface, driven into the ground
        canvas.rect((x_body - 0.45, -1.6), (x_body + 0.45, 0.0))
        canvas.ground(1.2, x_body - 0.45, -0.45)
        canvas.ground(x_body + 0.45, 5.0, -0.45)
        canvas.line((x_body + 0.45, 0.0), (4.9, 0.0), width=0.3, dash="dashed")
        canvas.label((x_body + 0.6, -1.05), "w", [str(string(second)), *scene.mass(str(second))])
    return True


def _axes(canvas: Canvas, origin: Point, n: Point, t: Point) -> None:
    """A small n-t axis glyph."""
    for direction, label in ((n, "n"), (t, "t")):
        tip = (origin[0] + 0.6 * direction[0], origin[1] + 0.6 * direction[1])
        canvas.arrow(origin, tip, width=0.5, head=0.13)
        canvas.label((tip[0] + 0.15 * direction[0], tip[1] + 0.15 * direction[1]), "c", [label])


def _screen(velocity: Velocity, scene: _Scene, n: Point, t: Point) -> Point:
    vn, vt = scene.value(velocity.n), scene.value(velocity.t)
    return vn * n[0] + vt * t[0], vn * n[1] + vt * t[1]


def _nearest_axis(ray: Point, axes: Sequence[Point]) -> Point:
    """Of the axes (either sign), the one closest in direction to ``ray``."""
    return max(((s * a[0], s * a[1]) for a in axes for s in (1, -1)), key=lambda a: a[0] * ray[0] + a[1] * ray[1])


def _axis(stage: Stage, n: Point, t: Point) -> Point:
    """The axis a velocity stage measures its angle from."""
    return t if stage.fields.get("from", "t") == "t" else n


def _angle_mark(canvas: Canvas, center: Point, ray: Point, axes: Sequence[Point], radius: float,
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


def _speed_mark(canvas: Canvas, tail: Point, tip: Point, away: Point, lines: Sequence[str],
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


def _speed_label(scene: _Scene, stage: Stage | None, fallback: str) -> list[str]:
    return scene.given(stage.fields["speed"]) if stage is not None else [fallback]


def _angle_label(scene: _Scene, stage: Stage | None) -> list[str]:
    return scene.given(stage.fields["angle"]) if stage is not None else []


def _surface(canvas: Canvas, scene: _Scene, impact: Stage) -> bool:
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
    canvas.label((2.9, -0.35), "ne", [str(string(impact.fields["bodies"][1]))])
    canvas.line((-2.9, radius), (2.9, radius), width=0.4, dash="dashed", gray=True)
    canvas.circle(center, radius)
    stages = scene.template.scene.stages
    arrows = [(incoming, -1, _velocity_stage(stages, before), "v")]
    if speeds[1] > 0:
        arrows.append((outgoing, 1, _velocity_stage(stages, after), "v'"))
    for vector, sign, stage, fallback in arrows:
        length = _m.hypot(*vector)
        ray = (sign * vector[0] / length, sign * vector[1] / length)  # from the body toward the arrow
        near = (center[0] + ray[0] * (radius + 0.05), center[1] + ray[1] * (radius + 0.05))
        far = (near[0] + ray[0] * length * scale, near[1] + ray[1] * length * scale)
        if sign < 0:
            canvas.arrow(far, near)
        else:
            canvas.arrow(near, far)
        # The speed at the arrow's far end, clear of the angle marks near the body.
        end = (far[0] + 0.1 * ray[0], far[1] + 0.1 * ray[1])
        canvas.label(end, _anchor(_m.atan2(ray[1], ray[0])), _speed_label(scene, stage, fallback))
        if stage is not None:
            _angle_mark(canvas, center, ray, [_axis(stage, n, t)], 0.95, _angle_label(scene, stage))
    _axes(canvas, (3.4, 1.6), n, t)
    return True


def _spheres(canvas: Canvas, scene: _Scene, impact: Stage) -> bool:
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
        canvas.label(center, "c", [str(string(body)), *scene.mass_value(body)])
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
        canvas.arrow(tail, tip)
        stage = _velocity_stage(stages, velocity)
        axis = _nearest_axis((-ux, -uy), [_axis(stage, n, t) if stage is not None else n])
        _speed_mark(canvas, tail, tip, (-ux - axis[0], -uy - axis[1]), _speed_label(scene, stage, "v"), 0.2)
        if stage is not None:
            _angle_mark(canvas, center, (-ux, -uy), [_axis(stage, n, t)], radius + 0.45, _angle_label(scene, stage))
    return True


def _direct(canvas: Canvas, scene: _Scene, impact: Stage) -> bool:
    """Two blocks on a line, areas in the ratio of the masses; the moving ones with an arrow."""
    first, second = impact.fields["bodies"]
    masses = {b: scene.value(scene.template.scene.bodies[b].mass) for b in (first, second)}
    fixed = scene.template.scene.bodies[second].mass is None
    mean = _m.sqrt(masses[first] * masses[second]) if not fixed else masses[first]
    sides = {b: 1.1 * min(2.0, max(0.5, _m.sqrt(m / mean))) if _m.isfinite(m) and m > 0 and mean > 0 else 1.1
             for b, m in masses.items()}
    x = 0.0
    canvas.line((-0.3, 0.0), (sides[first] + 2.2 + (0 if fixed else sides[second] + 0.3), 0.0), width=1.0)
    for index, body in enumerate((first, second)):
        if index == 1:
            x += 2.2
        if fixed and body == second:  # a wall, hatched on its far side
            canvas.line((x, 0.0), (x, 1.8), width=1.0)
            for y in (0.15, 0.4, 0.65, 0.9, 1.15, 1.4, 1.65):
                canvas.line((x, y), (x + 0.16, y + 0.16), width=0.4)
            canvas.label((x + 0.3, 1.0), "w", [str(string(body))])
            continue
        side = sides[body]
        canvas.rect((x, 0.0), (x + side, side))
        canvas.label((x + side / 2, side / 2), "c", [str(string(body))])
        canvas.label((x + side / 2, -0.12), "n", scene.mass(body))
        velocity = impact.fields["before"].get(body)
        if velocity is None:
            canvas.label((x + side / 2, side + 0.1), "s", ["v = 0"])
        else:
            start = (x + side + 0.1, side / 2)
            canvas.arrow(start, (start[0] + 1.6, start[1]))
            canvas.label((start[0] + 0.8, side / 2 + 0.12), "s", scene.given(velocity.n or Sym("v")))
        x += side
    return True


def _row(canvas: Canvas, scene: _Scene) -> None:
    """Bodies side by side, named, with their masses: the figure of a scene of no known kind."""
    x = 0.0
    for body in scene.template.scene.bodies:
        canvas.circle((x + 0.5, 0.5), 0.5)
        canvas.label((x + 0.5, 0.5), "c", [str(string(body))])
        canvas.label((x + 0.5, -0.1), "n", scene.mass(body) or ["(fixed)"])
        x += 1.8

