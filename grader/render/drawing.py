"""Drawing calls in centimetres, y up, as Typst (see ``templates/figures.typ``): the primitives the
problem figures (:mod:`grader.render.figures`) are built from. Nothing here knows about physics.

Geometry is built in centimetres with y up, then shifted so the drawing's bounding box (labels
included, by an estimate of their size) starts at the origin, and flipped for Typst.

>>> canvas = Drawing()
>>> canvas.line((0, 0), (2, 1))
>>> canvas.typst().startswith("fig-canvas(2.10, 1.10")
True
"""

from __future__ import annotations

import itertools
import math as _m
from collections.abc import Sequence
from dataclasses import dataclass, field

from grader.render.typst_text import Typ, body_name, string

Point = tuple[float, float]
PAD = 0.05
MAX_WIDTH = 7.6
CHAR = 0.15  # cm per character of a label at the figure's text size, an estimate for the bounding box
LINE = 0.42  # cm per line of a label
GAP = 0.15  # cm between a label and what it labels that a drawing scaled down keeps
PARTICLE = 0.09  # cm: the radius of a particle's dot


@dataclass(frozen=True)
class VelocityArrow:
    """A velocity drawn: the arrow's direction (a unit vector, y up), the label beside it, and the
    direction in which the quantity its label names is positive (None: a speed, never negative)."""

    direction: Point
    label: tuple[str, ...]
    positive: Point | None


def _fmt(value: float) -> str:
    return f"{value:.2f}"


@dataclass
class Drawing:
    """Drawing calls with their coordinates (cm, y up), what they cover, and what labels must avoid."""

    calls: list[tuple[str, list[Point], float, str]] = field(default_factory=list)
    points: list[Point] = field(default_factory=list)
    labels: list[tuple[Point, tuple[float, float, float, float]]] = field(default_factory=list)
    occupied: list[tuple[float, float, float, float]] = field(default_factory=list)
    strokes: list[tuple[Point, Point]] = field(default_factory=list)
    bodies: list[str] = field(default_factory=list)  # the scene's bodies named, in the order drawn: the record
    velocities: list[VelocityArrow] = field(default_factory=list)  # the velocity arrows drawn: the record

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

    def polygon(self, points: Sequence[Point], gray: bool = False, fill: str | None = None) -> None:
        """A filled polygon (black, gray, or ``fill``), without outline."""
        self._add("fig-poly", points, f"fill: {fill}" if fill else "fill: luma(150)" if gray else "")

    def circle(self, center: Point, radius: float, dash: str | None = None, fill: bool = True) -> None:
        """A circle (a body)."""
        self._add("fig-circle", [center], f"{_stroke(0.8, dash, False)}{', fill: luma(235)' if fill else ''}", radius)

    def rect(self, low: Point, high: Point, dash: str | None = None, fill: str = "luma(235)") -> None:
        """A rectangle between two corners (a block, a plate)."""
        self._add("fig-rect", [(low[0], high[1]), (high[0], low[1])], f"{_stroke(0.8, dash, False)}, fill: {fill}")
        self.occupied.append((low[0], low[1], high[0], high[1]))

    def body_shape(self, shape: str, center: Point, half: tuple[float, float], dash: str | None = None,
                   filled: bool = True) -> None:
        """A body drawn as its shape (see ``grader.model.scene.SHAPES``) about ``center``: a ``block``, the
        rectangle ``half`` (width, height) out from it either way; a ``sphere``, the circle of the smaller
        half; a ``particle``, a small dot (filled unless dashed)."""
        if shape == "block":
            low, high = (center[0] - half[0], center[1] - half[1]), (center[0] + half[0], center[1] + half[1])
            self.rect(low, high, dash, "luma(235)" if filled else "none")
        elif shape == "sphere":
            self.circle(center, min(half), dash, fill=filled)
        else:
            self.circle(center, PARTICLE, dash, fill=filled and dash is None)

    def reserve(self, low: Point, high: Point) -> None:
        """Keep the box between two corners clear of the labels placed where they :meth:`fits` (a sphere)."""
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
        return self.clear(self._label_box(at, anchor, lines))

    def clear(self, box: tuple[float, float, float, float]) -> bool:
        """Whether the box (left, bottom, right, top) is clear of the labels, blocks and arrows drawn so far."""
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

    def name(self, at: Point, anchor: str, body: str, more: Sequence[str] = ()) -> None:
        """A body's name (and ``more`` lines, its mass), placed as :meth:`label` places lines, and
        kept in :attr:`bodies`, the record of the scene's bodies this drawing shows."""
        self.bodies.append(body)
        self.label(at, anchor, [str(string(body_name(body))), *more])

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

    def velocity(self, tail: Point, tip: Point, lines: Sequence[str], positive: Point | None = None,
                 width: float = 0.9, head: float = 0.22) -> None:
        """A velocity's arrow, from ``tail`` the way the body moves to ``tip``, kept in :attr:`velocities`
        with ``lines``, the label its caller places beside it, and ``positive``, the direction in which the
        quantity named there is positive (None for a speed)."""
        length = _m.hypot(tip[0] - tail[0], tip[1] - tail[1]) or 1.0
        self.velocities.append(VelocityArrow(((tip[0] - tail[0]) / length, (tip[1] - tail[1]) / length),
                                             tuple(lines), positive))
        self.arrow(tail, tip, width, head)

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
        """A vertical dimension line from ``low`` to ``high`` with arrows, labelled on ``side`` (no
        ``lines``: not labelled)."""
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
        if not lines:
            return
        # Beside a short one, clear of its arrows' heads and the lines out to it, on one line; beside a
        # tall one "h = 1.20 m" as two lines, "h" over "= 1.20 m": narrower beside a tall figure.
        gap = 0.2 if length > 0.6 else 0.3
        middle = (x + (-gap if side == "left" else gap), (low[1] + high[1]) / 2)
        split = [part for line in lines for part in ([line] if " = " not in line or length <= 0.6 else
                                                      [line.split(" = ", 1)[0], "= " + line.split(" = ", 1)[1]])]
        self.label(middle, "e" if side == "left" else "w", split)

    def _extent(self, scale: float) -> tuple[float, float, float, float]:
        """The bounding box with the geometry scaled by ``scale`` and the labels at their size."""
        placed = [(_anchored(at, box, scale), box) for at, box in self.labels]
        xs = [x * scale for x, _ in self.points] + [a[0] + d for a, box in placed for d in box[::2]]
        ys = [y * scale for _, y in self.points] + [a[1] + d for a, box in placed for d in box[1::2]]
        return (min(xs), min(ys), max(xs), max(ys)) if xs else (0.0, 0.0, 0.0, 0.0)

    def natural_width(self) -> float:
        """The drawing's width (cm) unscaled, labels and margins included."""
        x0, _, x1, _ = self._extent(1.0)
        return x1 - x0 + 2 * PAD

    def typst(self, max_width: float = MAX_WIDTH) -> Typ:
        """A ``fig-canvas`` call drawing everything, shifted to start at the origin; a drawing wider
        than ``max_width`` has its geometry (not its labels) scaled down until it fits."""
        scale = 1.0
        while scale > 0.25 and self._extent(scale)[2] - self._extent(scale)[0] + 2 * PAD > max_width:
            scale -= 0.05
        x0, y0, x1, y1 = self._extent(scale)

        def place(point: Point) -> str:
            return f"({_fmt(point[0] * scale - x0 + PAD)}, {_fmt(y1 - point[1] * scale + PAD)})"
        labels = iter(self.labels)  # in the order of their calls
        width, height = x1 - x0 + 2 * PAD, y1 - y0 + 2 * PAD

        def place_label(point: Point) -> str:
            # The offset from where the label's alignment in the canvas puts it (``fig-label``): the
            # label is placed by its anchor directly, with nothing to measure and no box around it.
            box = next(labels)[1]
            x, y = _anchored(point, box, scale)
            across = 0.0 if abs(box[0]) < 1e-9 else 1.0 if abs(box[2]) < 1e-9 else 0.5
            down = 0.0 if abs(box[3]) < 1e-9 else 1.0 if abs(box[1]) < 1e-9 else 0.5
            return f"({_fmt(x - x0 + PAD - across * width)}, {_fmt(y1 - y + PAD - down * height)})"
        body = []
        # Lines drawn one after another with one stroke are one curve (the ground's hatching: 25 lines).
        for (kind, options), calls in itertools.groupby(self.calls, key=lambda call: (call[0], call[3])):
            if kind == "fig-line":
                arguments = [f"({place(a)}, {place(b)})" for _, (a, b), _, _ in calls]
                body.append(f"  fig-lines({', '.join([*arguments, options])})")
                continue
            for _, points, radius, _ in calls:
                arguments = [(place_label if kind == "fig-label" else place)(p) for p in points] + \
                    ([_fmt(radius * scale)] if radius else []) + ([options] if options else [])
                body.append(f"  {kind}({', '.join(arguments)})")
        return Typ(f"fig-canvas({_fmt(width)}, {_fmt(height)}, {{\n" + "\n".join(body) + "\n})")


def _anchored(at: Point, box: tuple[float, float, float, float], scale: float) -> Point:
    """Where a label's anchor goes when the geometry is scaled by ``scale`` (the text is not): the point
    scaled, then moved ``(1 - scale) * GAP`` the way the label reaches from it (its box, relative to the
    anchor, says which), so that a label placed a gap away from a line keeps that gap once shrunk
    (an incline's angle under its foot, in a strip).

    >>> _anchored((1.0, 1.0), (-0.5, -0.4, 0.5, 0.0), 0.5)  # reaches down from its anchor
    (0.5, 0.425)
    >>> _anchored((1.0, 1.0), (-0.5, -0.2, 0.5, 0.2), 0.5)  # centred: only scaled
    (0.5, 0.5)
    """
    shift = (1 - scale) * GAP
    dx = shift if abs(box[0]) < 1e-9 else -shift if abs(box[2]) < 1e-9 else 0.0
    dy = shift if abs(box[1]) < 1e-9 else -shift if abs(box[3]) < 1e-9 else 0.0
    return at[0] * scale + dx, at[1] * scale + dy


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
