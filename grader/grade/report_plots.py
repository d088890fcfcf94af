"""The class report's figures, written directly as SVG text (:mod:`grader.grade.svg_figure`) to be placed
in the page as they are: the scores' histogram, the verdicts' bars, and each problem's difficulty panels.

A figure is the same bytes on every run (no date, no ids), its text is text (searchable, in the page's
fonts), and a parameter named ``$x`` or ``<b>`` is shown as typed. Only aggregates are drawn, and each
student as a point only in a class of at most :data:`POINTS_UP_TO`.

>>> from grader.grade.class_summary import Parameter, ParameterBin, ProblemSummary
>>> bins = (ParameterBin(1.0, 1.5, 2, 1.0, 0.0), ParameterBin(2.0, 2.5, 2, 0.5, 0.0))
>>> parameter = Parameter("h <1>", np.array([1.0, 1.5, 2.0, 2.5]), bins, "m")
>>> problem = ProblemSummary("1", "Drop", ("1a",), np.array([1.0, 1.0, 0.5, 0.5]), np.ones(4, bool), (parameter,))
>>> figure = difficulty(problem)
>>> figure.startswith("<svg"), "h &lt;1&gt; (m)</text>" in figure, figure.count("<circle")
(True, True, 6)
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from grader.grade.class_summary import ClassSummary, Floats, Parameter, ProblemSummary, is_hard
from grader.grade.svg_figure import (
    FONT_SIZE,
    PER_INCH,
    Scale,
    circle,
    lines,
    rect,
    svg,
    text,
    tick_labels,
    ticks,
    width,
    with_margins,
)

COLORS = {"correct": "#2e7d32", "ecf": "#8bc34a", "mistake": "#f9a825", "incorrect": "#c62828",
          "invalid": "#6a1b9a", "missing": "#9e9e9e"}
OTHER_COLORS = ("#1565c0", "#00838f", "#ad1457", "#4e342e")  # kinds with no color of their own, in turn
INK, MUTED, ACCENT, WARN = "#222222", "#8a94a6", "#1f4e99", "#c62828"
FRAME, TICK, GRID = "#b0b8c4", "#55606e", "#e3e7ee"
POINTS_UP_TO = 1000  # students drawn as points below the bins' means
PANELS_PER_ROW = 4
WIDTH = 10.5 * PER_INCH  # the page's column
_TICK = 4.7  # px: a tick mark's length, and the gap from it to its label
_DARK_TEXT = ("missing", "mistake", "ecf")  # kinds light enough for dark numbers on their bars


def color(kind: str, kinds: Sequence[str]) -> str:
    """The color of a verdict kind, the same in the figures and the tables."""
    if kind in COLORS:
        return COLORS[kind]
    others = [k for k in kinds if k not in COLORS]
    return OTHER_COLORS[others.index(kind) % len(OTHER_COLORS)] if kind in others else MUTED


@dataclass(frozen=True)
class _Area:
    """A plot's area in the figure, in pixels, with its scales from data to pixels."""

    left: float
    top: float
    width: float
    height: float
    x: Scale
    y: Scale

    @property
    def bottom(self) -> float:
        return self.top + self.height

    @property
    def right(self) -> float:
        return self.left + self.width


def _area(left: float, top: float, size: tuple[float, float], x: tuple[float, float],
          y: tuple[float, float]) -> _Area:
    """The area at (``left``, ``top``) of ``size`` pixels, showing ``x`` across and ``y`` upwards (or
    downwards, when ``y``'s first value is the greater)."""
    across, down = size
    return _Area(left, top, across, down, Scale(x[0], x[1], left, left + across), Scale(y[0], y[1], top + down, top))


def _frame(area: _Area, across: Sequence[tuple[float, str]], up: Sequence[tuple[float, str]], x_title: str,
           y_title: str, grid: bool = True) -> list[str]:
    """The area's axes: light grid lines across at the ``up`` ticks, the left and bottom edges, the ticks
    (each a pixel position and its label) and the axes' titles."""
    shapes = []
    if grid:
        shapes.append(lines([[(area.left, y), (area.right, y)] for y, _ in up], GRID, 1.1))
    marks = ([[(x, area.bottom), (x, area.bottom + _TICK)] for x, _ in across]
             + [[(area.left - _TICK, y), (area.left, y)] for y, _ in up])
    shapes.append(lines(marks, TICK, 1.1))
    shapes.append(lines([[(area.left, area.top), (area.left, area.bottom), (area.right, area.bottom)]], FRAME, 1.1))
    below = area.bottom + 2 * _TICK + 0.8 * FONT_SIZE
    shapes += [text(x, below, label, "middle", f' fill="{TICK}"') for x, label in across]
    shapes += [text(area.left - 2 * _TICK, y + 0.35 * FONT_SIZE, label, "end", f' fill="{TICK}"') for y, label in up]
    if x_title:
        shapes.append(text(area.left + area.width / 2, below + 1.3 * FONT_SIZE, x_title, "middle", f' fill="{INK}"'))
    if y_title:
        widest = max((width(label) for _, label in up), default=0.0)
        x, y = area.left - 2 * _TICK - widest - 0.6 * FONT_SIZE, area.top + area.height / 2
        shapes.append(text(x, y, y_title, "middle", f' fill="{INK}" transform="rotate(-90 {x:.1f} {y:.1f})"'))
    return shapes


def _numbered(values: Sequence[float], scale: Scale) -> list[tuple[float, str]]:
    """Ticks at ``values``, placed by ``scale`` and labelled as an axis prints them."""
    return list(zip((scale(value) for value in values), tick_labels(values), strict=True))


def score_histogram(summary: ClassSummary) -> str:
    """How many students scored what, in 5 % steps, with the mean and the median marked."""
    percent = summary.percent
    counts = np.histogram(percent, bins=np.linspace(0, 100, 21))[0]
    highest = max(int(counts.max()), 1)
    size = (WIDTH, 2.6 * PER_INCH)
    area = _area(0.6 * PER_INCH, 0.15 * PER_INCH, (size[0] - 0.8 * PER_INCH, size[1] - 0.65 * PER_INCH),
                 (0.0, 100.0), (0.0, 1.05 * highest))
    up = ticks(0.0, 1.05 * highest, 5, whole=True)
    shapes = [*_frame(area, _numbered(ticks(0.0, 100.0, 5), area.x), _numbered(up, area.y),
                      "score (% of the points possible)", "students")]
    for low, count in zip(range(0, 100, 5), counts.tolist(), strict=True):
        if count:
            left, right, top = area.x(low), area.x(low + 5), area.y(count)
            shapes.append(rect(left + 0.5, top, right - left - 1.0, area.bottom - top, ACCENT))
    if len(percent):
        marks = ((float(percent.mean()), "5.8 2.5", "mean"), (float(np.median(percent)), "1.6 2.6", "median"))
        for row, (value, dashes, name) in enumerate(marks):
            x = area.x(value)
            shapes.append(lines([[(x, area.top), (x, area.bottom)]], INK, 1.6, dashes))
            y = area.top + 0.9 * FONT_SIZE + 1.4 * FONT_SIZE * row
            shapes.append(lines([[(area.left + 10, y - 4), (area.left + 34, y - 4)]], INK, 1.6, dashes))
            shapes.append(text(area.left + 42, y, f"{name} {value:.0f} %", extra=f' fill="{INK}"'))
    return svg(*size, shapes)


def verdict_bars(summary: ClassSummary) -> str:
    """Per part, a bar split into the share of each verdict kind; the kinds' colors named above."""
    parts, kinds = summary.parts, summary.kinds
    size = (WIDTH, (0.85 + 0.3 * max(len(parts), 1)) * PER_INCH)
    rows = max(len(parts), 1)
    area = _area(0.5 * PER_INCH, 0.4 * PER_INCH, (size[0] - 0.7 * PER_INCH, size[1] - 0.85 * PER_INCH),
                 (0.0, 100.0), (rows - 0.5, -0.5))
    names = [(area.y(place), part.label) for place, part in enumerate(parts)]
    shapes = _frame(area, _numbered(ticks(0.0, 100.0, 5), area.x), names, "% of the class", "", grid=False)
    thick = 0.7 * area.height / rows
    for place, part in enumerate(parts):
        start = 0.0
        for kind in kinds:
            share = 100.0 * part.counts[kind] / part.students if part.students else 0.0
            if share:
                left, right = area.x(start), area.x(start + share)
                shapes.append(rect(left, area.y(place) - thick / 2, right - left, thick, color(kind, kinds)))
            if share >= 7:
                ink = INK if kind in _DARK_TEXT else "white"
                shapes.append(text(area.x(start + share / 2), area.y(place) + 0.35 * 0.9 * FONT_SIZE, f"{share:.0f}",
                                   "middle", f' fill="{ink}" font-size="{0.9 * FONT_SIZE:.1f}"'))
            start += share
    shapes += _legend(kinds, area.left, area.top - 0.8 * FONT_SIZE)
    return svg(*size, shapes)


def _legend(kinds: Sequence[str], left: float, middle: float) -> list[str]:
    """The verdict kinds in a row, each a square of its color and its name."""
    shapes, x = [], left
    for kind in kinds:
        shapes.append(rect(x, middle - 5, 14, 10, color(kind, kinds)))
        shapes.append(text(x + 19, middle + 0.35 * FONT_SIZE, kind, extra=f' fill="{INK}"'))
        x += 19 + width(kind) + 1.2 * FONT_SIZE
    return shapes


def difficulty(problem: ProblemSummary) -> str:
    """A panel per parameter that varies: the problem's score against it (bins' means with their
    standard errors, hard bins in red, the problem's mean dashed, each student a point in a small class)."""
    shown = problem.drawn
    rows = -(-len(shown) // PANELS_PER_ROW)
    size = (WIDTH, (0.1 + 2.25 * rows) * PER_INCH)
    gaps = (0.45 * PER_INCH, 0.5 * PER_INCH)
    across = (size[0] - 0.75 * PER_INCH - (PANELS_PER_ROW - 1) * gaps[0]) / PANELS_PER_ROW
    down = (size[1] - 0.6 * PER_INCH - (rows - 1) * gaps[1]) / rows
    shapes = []
    for index, parameter in enumerate(shown):
        row, column = divmod(index, PANELS_PER_ROW)
        left, top = 0.6 * PER_INCH + column * (across + gaps[0]), 0.1 * PER_INCH + row * (down + gaps[1])
        shapes += _panel(left, top, (across, down), parameter, problem, "score (%)" if column == 0 else "")
    return svg(*size, shapes)


def _panel(left: float, top: float, size: tuple[float, float], parameter: Parameter, problem: ProblemSummary,
           y_title: str) -> list[str]:
    mean = problem.mean
    values, score = parameter.values[problem.attempted], problem.score[problem.attempted]
    known = np.isfinite(values)
    points = int(known.sum()) <= POINTS_UP_TO
    bins = parameter.bins
    middles = [(b.low + b.high) / 2 for b in bins]
    area = _area(left, top, size, with_margins([*middles, *(values[known].tolist() if points else [])]),
                 (-5.0, 105.0))
    shapes = _frame(area, _numbered(ticks(area.x.low, area.x.high, 3), area.x),
                    _numbered([0.0, 25.0, 50.0, 75.0, 100.0], area.y), parameter.axis, y_title)
    if points:
        jittered = 100 * (score[known] + _jitter(int(known.sum())))
        shapes += [circle(area.x(x), area.y(y), 2.1, MUTED, ' fill-opacity="0.6"')
                   for x, y in zip(values[known].tolist(), jittered.tolist(), strict=True)]
    shapes.append(lines([[(area.left, area.y(100 * mean)), (area.right, area.y(100 * mean))]], INK, 1.2, "4.4 1.9"))
    centers = [(area.x(x), area.y(100 * b.mean)) for x, b in zip(middles, bins, strict=True)]
    bars = []
    for (x, _), b in zip(centers, bins, strict=True):
        low, high = area.y(100 * (b.mean - b.error)), area.y(100 * (b.mean + b.error))
        bars += [[(x, low), (x, high)], [(x - 2.7, low), (x + 2.7, low)], [(x - 2.7, high), (x + 2.7, high)]]
    shapes += [lines(bars, ACCENT, 1.3), lines([centers], ACCENT, 1.9)]
    shapes += [circle(x, y, 2.7, ACCENT) for x, y in centers]
    shapes += [circle(x, y, 4.5, WARN) for (x, y), b in zip(centers, bins, strict=True) if is_hard(b, mean)]
    return shapes


def _jitter(count: int) -> Floats:
    """Small vertical offsets (±2 %), the same on every run, so that equal scores do not hide each other."""
    return (np.arange(count, dtype=np.float64) * 0.6180339887498949 % 1.0 - 0.5) * 0.04
