"""A figure written directly as SVG text: the plot area's scales, round-numbered ticks and their labels,
and the few shapes the class report draws (rectangles, paths, circles, text).

Everything is in pixels (96 to the inch, as a browser lays out a page), written with one decimal, so
that the same figure is the same bytes on every run. Text is escaped for the page it is placed in
(an HTML page parses inline SVG as HTML: ``<`` and ``&`` in a parameter's name must stay text).

>>> ticks(0.0, 100.0, 5)
[0.0, 20.0, 40.0, 60.0, 80.0, 100.0]
>>> tick_labels(ticks(1.45, 3.05, 4))
['1.5', '2.0', '2.5', '3.0']
>>> text(10, 20, "a < b", anchor="end")
'<text x="10.0" y="20.0" text-anchor="end">a &lt; b</text>'
"""

from __future__ import annotations

import html
import math
from collections.abc import Sequence
from dataclasses import dataclass
from itertools import pairwise

PER_INCH = 96.0
FONT = '"DejaVu Sans", "Segoe UI", Roboto, sans-serif'
FONT_SIZE = 12.0  # px: 9 pt
_STEPS = (1.0, 2.0, 2.5, 5.0, 10.0)  # round steps between ticks, times a power of ten
_MINUS = "\u2212"


def ticks(low: float, high: float, most: int, whole: bool = False) -> list[float]:
    """Round-numbered ticks from ``low`` to ``high``: at most ``most + 1`` of them, a step of 1, 2, 2.5 or 5
    times a power of ten (``whole``: a whole number). An empty or unreadable range has its ends as ticks.

    >>> ticks(-5.0, 105.0, 4), ticks(0.0, 10.5, 5, whole=True)
    ([0.0, 25.0, 50.0, 75.0, 100.0], [0.0, 2.0, 4.0, 6.0, 8.0, 10.0])
    >>> ticks(-1e300, 1e300, 4)
    [-1e+300, -5e+299, 0.0, 5e+299, 1e+300]
    """
    span = high - low
    if not (math.isfinite(span) and span > 0):
        return [low] if low == high and math.isfinite(low) else []
    magnitude = 10.0 ** math.floor(math.log10(span / most))
    if magnitude == 0.0:  # a span among the subnormal numbers: no round step is representable
        return [low, high]
    for factor in _STEPS:
        step = factor * magnitude
        if whole and (step < 1 or step != round(step)):
            continue
        first, last = math.ceil(low / step), math.floor(high / step)
        if last - first <= most:
            return [number * step for number in range(first, last + 1)]
    return [low, high]


def tick_labels(values: Sequence[float]) -> list[str]:
    """The ticks as an axis prints them: the fewest decimals that tell each one apart and say it to
    within a thousandth of the gap to the next; powers of ten from 100,000 up and below 0.001; a minus sign.

    >>> tick_labels([0.0, 0.25, 0.5]), tick_labels([1e300, 2e300]), tick_labels([-2e-5, 0.0, 2e-5])
    (['0.00', '0.25', '0.50'], ['1e300', '2e300'], ['−2e−5', '0', '2e−5'])
    >>> tick_labels([0.1 * 3 - 0.3, 0.1, 0.2])
    ['0.0', '0.1', '0.2']
    """
    if not values:
        return []
    biggest = max(abs(value) for value in values)
    gap = min((b - a for a, b in pairwise(values)), default=biggest) or biggest or 1.0
    scientific = biggest >= 1e5 or 0 < biggest < 1e-3
    for digits in range(17):
        labels = [_label(value, digits, scientific) for value in values]
        if all(abs(float(label.replace(_MINUS, "-")) - value) <= gap * 1e-3 for label, value in zip(
                labels, values, strict=True)) and len(set(labels)) == len(labels):
            return labels
    return labels


def _label(value: float, digits: int, scientific: bool) -> str:
    if scientific:
        if value == 0:
            return "0"
        mantissa, _, exponent = f"{value:.{digits}e}".partition("e")
        written = f"{mantissa}e{int(exponent)}"
    else:
        written = f"{value:.{digits}f}"
        if float(written) == 0:  # -0.00 from a tick a rounding error below zero
            written = written.lstrip("-")
    return written.replace("-", _MINUS)


@dataclass(frozen=True)
class Scale:
    """Data from ``low`` to ``high`` onto pixels from ``start`` to ``end`` (``end`` may be the smaller:
    a vertical axis grows upwards).

    >>> Scale(0.0, 100.0, 50.0, 250.0)(25.0), Scale(-1e300, 1e300, 0.0, 100.0)(0.0)
    (100.0, 50.0)
    """

    low: float
    high: float
    start: float
    end: float

    def __call__(self, value: float) -> float:
        span = self.high - self.low
        share = (value - self.low) / span if span else 0.5
        return self.start + share * (self.end - self.start)


def with_margins(values: Sequence[float], margin: float = 0.05) -> tuple[float, float]:
    """The range of ``values`` widened by ``margin`` of its span on each side (a point is never on the
    frame); a single value, ``margin`` of itself each side (±1 around 0).

    >>> with_margins([2.0, 4.0]), with_margins([3.0]), with_margins([0.0])
    ((1.9, 4.1), (2.85, 3.15), (-1.0, 1.0))
    """
    low, high = min(values), max(values)
    span = high - low
    if not (span > 0 and math.isfinite(span)):
        pad = abs(low) * margin or 1.0
        return low - pad, high + pad
    return low - margin * span, high + margin * span


def svg(width: float, height: float, body: Sequence[str]) -> str:
    """The ``<svg>`` element: its size in pixels, scaled down with the page (``viewBox``)."""
    return (f'<svg xmlns="http://www.w3.org/2000/svg" width="{width:.0f}" height="{height:.0f}" '
            f'viewBox="0 0 {width:.0f} {height:.0f}" font-family=\'{FONT}\' font-size="{FONT_SIZE:.0f}">\n'
            + "\n".join(body) + "\n</svg>")


def rect(x: float, y: float, width: float, height: float, fill: str, extra: str = "") -> str:
    """A filled rectangle (``extra``: more attributes, written as they are)."""
    return f'<rect x="{x:.1f}" y="{y:.1f}" width="{width:.1f}" height="{height:.1f}" fill="{fill}"{extra}/>'


def circle(x: float, y: float, radius: float, fill: str, extra: str = "") -> str:
    return f'<circle cx="{x:.1f}" cy="{y:.1f}" r="{radius:.1f}" fill="{fill}"{extra}/>'


def lines(points: Sequence[Sequence[tuple[float, float]]], stroke: str, width: float, dashes: str = "") -> str:
    """One path of straight strokes: each sequence of points joined in turn (``dashes``: an SVG dash
    pattern, in pixels)."""
    drawn = " ".join("M" + " L".join(f"{x:.1f} {y:.1f}" for x, y in run) for run in points if len(run) > 1)
    dash = f' stroke-dasharray="{dashes}"' if dashes else ""
    return f'<path d="{drawn}" fill="none" stroke="{stroke}" stroke-width="{width:.1f}"{dash}/>'


def text(x: float, y: float, words: str, anchor: str = "start", extra: str = "") -> str:
    """``words`` as text at (``x``, ``y``), anchored at its ``start``, ``middle`` or ``end``."""
    place = f' text-anchor="{anchor}"' if anchor != "start" else ""
    return f'<text x="{x:.1f}" y="{y:.1f}"{place}{extra}>{html.escape(words, quote=False)}</text>'


# DejaVu Sans's advance widths (in ems) of the characters a legend holds most, to lay its entries side by side.
_WIDTHS = {**dict.fromkeys("il", 0.278), **dict.fromkeys("fjt", 0.36), "r": 0.411, "s": 0.521, "c": 0.55, "z": 0.525,
           **dict.fromkeys("kvxy", 0.592), **dict.fromkeys("aegou", 0.615), **dict.fromkeys("bdhnpq", 0.634),
           "w": 0.818, "m": 0.974, " ": 0.318, **dict.fromkeys("0123456789", 0.636)}


def width(words: str, size: float = FONT_SIZE) -> float:
    """About how wide ``words`` are, in pixels, in DejaVu Sans of ``size`` pixels (0.68 em a character it
    does not list).

    >>> round(width("mistake"), 1)
    47.5
    """
    return size * sum(_WIDTHS.get(character, 0.68) for character in words)
