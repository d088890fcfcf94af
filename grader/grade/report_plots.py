"""The class report's figures: matplotlib (imported here, and only when a report is drawn) draws each
as SVG text to be placed in the page as it is.

The SVG is the same bytes on every run (no date, ids hashed with a fixed salt, then prefixed with the
figure's name so that the figures of one page share none), its text is text (the page's font, searchable), and none
of it is read as math: a parameter named ``$x`` is shown as typed. Only aggregates are drawn, and
each student as a point only in a class of at most :data:`POINTS_UP_TO`.
"""

from __future__ import annotations

import io
import re
import sys
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from typing import Any

import numpy as np

from grader.grade.class_summary import ClassSummary, Floats, Parameter, ProblemSummary, is_hard

COLORS = {"correct": "#2e7d32", "ecf": "#8bc34a", "mistake": "#f9a825", "incorrect": "#c62828",
          "invalid": "#6a1b9a", "missing": "#9e9e9e"}
OTHER_COLORS = ("#1565c0", "#00838f", "#ad1457", "#4e342e")  # kinds with no color of their own, in turn
INK, MUTED, ACCENT, WARN = "#222222", "#8a94a6", "#1f4e99", "#c62828"
POINTS_UP_TO = 1000  # students drawn as points below the bins' means
PANELS_PER_ROW = 4
_WIDTH = 10.5  # inches: the page's column at 96 px an inch


def _import_matplotlib() -> None:
    """``import matplotlib.figure``, without the docstrings of each artist class's ``set`` that matplotlib
    builds as it imports (a quarter of its import time; only ``help()`` shows them, and the figures do not
    change). Where matplotlib has no ``artist.kwdoc`` to pass over, it is imported as it is."""
    if "matplotlib.figure" in sys.modules:
        return
    import matplotlib.artist

    kwdoc = getattr(matplotlib.artist, "kwdoc", None)
    if kwdoc is not None:
        matplotlib.artist.kwdoc = lambda artist: ""
    try:
        import matplotlib.figure
    finally:
        if kwdoc is not None:
            matplotlib.artist.kwdoc = kwdoc


def color(kind: str, kinds: Sequence[str]) -> str:
    """The color of a verdict kind, the same in the figures and the tables."""
    if kind in COLORS:
        return COLORS[kind]
    others = [k for k in kinds if k not in COLORS]
    return OTHER_COLORS[others.index(kind) % len(OTHER_COLORS)] if kind in others else MUTED


def score_histogram(summary: ClassSummary) -> str:
    """How many students scored what, in 5 % steps, with the mean and the median marked."""
    percent = summary.percent
    with _figure((_WIDTH, 2.6), (0.6, 0.2, 0.5, 0.15)) as figure:
        axes = figure.add_subplot()
        axes.hist(percent, bins=np.linspace(0, 100, 21), color=ACCENT, edgecolor="white", linewidth=0.8)
        if len(percent):
            for value, style, name in ((float(percent.mean()), "--", "mean"),
                                       (float(np.median(percent)), ":", "median")):
                axes.axvline(value, color=INK, linestyle=style, linewidth=1.2, label=f"{name} {value:.0f} %")
            axes.legend(frameon=False, loc="upper left")
        axes.set_xlim(0, 100)
        axes.set_xlabel("score (% of the points possible)")
        axes.set_ylabel("students")
        axes.yaxis.get_major_locator().set_params(integer=True)
        _plain(axes)
        return _svg(figure, "histogram")


def verdict_bars(summary: ClassSummary) -> str:
    """Per part, a bar split into the share of each verdict kind."""
    parts, kinds = summary.parts, summary.kinds
    with _figure((_WIDTH, 0.85 + 0.3 * max(len(parts), 1)), (0.5, 0.2, 0.45, 0.4)) as figure:
        axes = figure.add_subplot()
        places = np.arange(len(parts))
        left = np.zeros(len(parts))
        for kind in kinds:
            share = np.array([100.0 * part.counts[kind] / part.students if part.students else 0.0 for part in parts])
            axes.barh(places, share, left=left, color=color(kind, kinds), label=kind, height=0.7)
            for place, start, width in zip(places.tolist(), left.tolist(), share.tolist(), strict=True):
                if width >= 7:
                    axes.text(start + width / 2, place, f"{width:.0f}", ha="center", va="center", fontsize=8,
                              color="white" if kind not in ("missing", "mistake", "ecf") else INK)
            left += share
        axes.set_yticks(places, [part.label for part in parts])
        axes.invert_yaxis()
        axes.set_xlim(0, 100)
        axes.set_xlabel("% of the class")
        axes.legend(ncols=len(kinds), loc="lower left", bbox_to_anchor=(0, 1.0), frameon=False, fontsize=9,
                    handlelength=1.2, columnspacing=1.2)
        _plain(axes)
        return _svg(figure, "verdicts")


def difficulty(problem: ProblemSummary, name: str) -> str:
    """A panel per parameter that varies: the problem's score against it (bins' means with their
    standard errors, hard bins in red, the problem's mean dashed, each student a point in a small class).
    ``name`` (letters, digits, ``-``) prefixes the figure's ids."""
    shown = problem.drawn
    rows = -(-len(shown) // PANELS_PER_ROW)
    with _figure((_WIDTH, 0.1 + 2.25 * rows), (0.6, 0.15, 0.5, 0.1),
                 (rows, PANELS_PER_ROW), (0.45, 0.5)) as figure:
        for index, parameter in enumerate(shown):
            axes = figure.add_subplot(rows, PANELS_PER_ROW, index + 1)
            _panel(axes, parameter, problem)
            if index % PANELS_PER_ROW == 0:
                axes.set_ylabel("score (%)")
        return _svg(figure, name)


def _panel(axes: Any, parameter: Parameter, problem: ProblemSummary) -> None:
    mean = problem.mean
    values, score = parameter.values[problem.attempted], problem.score[problem.attempted]
    known = np.isfinite(values)
    if known.sum() <= POINTS_UP_TO:
        axes.scatter(values[known], 100 * (score[known] + _jitter(int(known.sum()))), s=10, color=MUTED, alpha=0.6,
                     linewidths=0)
    bins = parameter.bins
    middles = np.array([(b.low + b.high) / 2 for b in bins])
    means = np.array([100 * b.mean for b in bins])
    errors = np.array([100 * b.error for b in bins])
    axes.errorbar(middles, means, yerr=errors, color=ACCENT, marker="o", markersize=4, linewidth=1.4, capsize=2)
    hard = np.array([is_hard(b, mean) for b in bins])
    if hard.any():
        axes.scatter(middles[hard], means[hard], s=46, color=WARN, zorder=5)
    axes.axhline(100 * mean, color=INK, linestyle="--", linewidth=0.9)
    axes.set_ylim(-5, 105)
    axes.set_yticks([0, 25, 50, 75, 100])
    axes.xaxis.get_major_locator().set_params(nbins=4)  # fewer ticks: each costs matplotlib a few ms
    axes.set_xlabel(parameter.axis)
    _plain(axes)


def _jitter(count: int) -> Floats:
    """Small vertical offsets (±2 %), the same on every run, so that equal scores do not hide each other."""
    return (np.arange(count, dtype=np.float64) * 0.6180339887498949 % 1.0 - 0.5) * 0.04


def _plain(axes: Any) -> None:
    axes.spines[["top", "right"]].set_visible(False)
    axes.grid(axis="y", color="#e3e7ee", linewidth=0.8)
    axes.set_axisbelow(True)


@contextmanager
def _figure(size: tuple[float, float], margins: tuple[float, float, float, float],
            grid: tuple[int, int] = (1, 1), gaps: tuple[float, float] = (0.0, 0.0)) -> Iterator[Any]:
    """A figure drawn under the report's settings, laid out by hand (matplotlib's constrained layout
    draws each figure twice): ``margins`` (left, right, bottom, top) and the ``gaps`` between the
    panels of a ``grid`` (rows, columns; gaps across, down) are in inches."""
    _import_matplotlib()
    import matplotlib
    from matplotlib.figure import Figure

    settings: dict[Any, Any] = {
        "svg.hashsalt": "grader-report", "svg.fonttype": "none",
        "text.parse_math": False, "font.size": 9, "axes.titlesize": 10, "axes.labelsize": 9,
        "axes.edgecolor": "#b0b8c4", "xtick.color": "#55606e", "ytick.color": "#55606e",
        "font.family": ["sans-serif"], "font.sans-serif": ["DejaVu Sans"]}
    (width, height), (left, right, bottom, top), (rows, columns) = size, margins, grid
    panel_width = (width - left - right - (columns - 1) * gaps[0]) / columns
    panel_height = (height - bottom - top - (rows - 1) * gaps[1]) / rows
    with matplotlib.rc_context(settings):
        figure = Figure(figsize=size)
        figure.subplots_adjust(left=left / width, right=1 - right / width, bottom=bottom / height,
                               top=1 - top / height, wspace=gaps[0] / panel_width, hspace=gaps[1] / panel_height)
        yield figure


def _svg(figure: Any, name: str) -> str:
    """The figure's ``<svg>`` element for a page: no XML declaration, doctype or metadata (it names
    nothing a reader needs), and every id prefixed with ``name``, so that figures of one page share none.

    The texts matplotlib writes are escaped (``id="`` in a label is ``id=&quot;``): only its own ids change.
    """
    stream = io.StringIO()
    figure.savefig(stream, format="svg", metadata={"Date": None, "Creator": None})
    text = stream.getvalue()
    text = _METADATA.sub("", text[text.index("<svg"):]).strip()
    return _IDS.sub(lambda found: f"{found.group(1)}{name}-", text)


_METADATA = re.compile(r"\s*<metadata>.*?</metadata>", re.S)
_IDS = re.compile(r'( id="|xlink:href="#|url\(#)')
