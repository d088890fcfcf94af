"""The one root of a residual in an interval, for every row at once: the numeric blocks of the kernels.

A block of equations with no closed form is reduced by the solver to one equation ``r(x) = 0`` in one
unknown (docs/design.md, The solver). Here ``r`` is scanned on a fixed grid over the unknown's interval for
every row at once; each sign change is a bracket, closed by false position (Illinois) with a bisection
whenever a step fails to halve the bracket, until the bracket is :data:`TOLERANCE` of its ends wide (or no
float lies between them). A bracket across a jump or a pole, where ``r`` does not vanish, is no root. A row
with exactly one root gets it; a row with none, or more than one, gets NaN, which the block's check refuses.

>>> import numpy as np
>>> root = find_root(lambda x, rows: x * x - np.array([2.0, 9.0])[rows], 0.0, 10.0, 2)
>>> [round(float(r), 12) for r in root]
[1.414213562373, 3.0]
>>> find_root(lambda x, rows: np.cos(x) + 0 * rows, -4.0, 4.0, 1).tolist()  # two roots: none named
[nan]
"""

from __future__ import annotations

import math
from collections.abc import Callable
from itertools import pairwise

import numpy as np

TOLERANCE = 1e-15
"""How narrow a bracket is closed, relative to its ends (a few units in the last place of float64)."""
TOLERANCE_TEXT = "1e−15"
""":data:`TOLERANCE` as worked solutions and ``grader show`` state it."""
UNIFORM = 256
"""The intervals of the grid on an interval at most :data:`UNIFORM_WIDTH` wide (an angle, a ratio)."""
UNIFORM_WIDTH = 100.0
PER_DECADE = 8
"""Grid points per decade of magnitude on a wider interval, from :data:`SMALLEST` to its ends."""
SMALLEST = 1e-9
LIMIT = 1e12
"""The end of an interval that has none (SI): beyond any quantity of these problems."""
_ITERATIONS = 200

Residual = Callable[[np.ndarray, np.ndarray], np.ndarray]
"""``residual(x, rows)``: the residual at ``x[i]`` for row ``rows[i]``."""


def grid(low: float, high: float) -> np.ndarray:
    """The points where the residual's sign is looked at: uniform on a short interval, else spread
    logarithmically from :data:`SMALLEST` outwards on each side of 0.

    >>> grid(0.0, 1.0)[:3].tolist(), len(grid(0.0, 1.0))
    ([0.0, 0.00390625, 0.0078125], 257)
    >>> points = grid(0.0, LIMIT)
    >>> float(points[0]), float(points[1]), float(points[-1])
    (0.0, 1e-09, 1000000000000.0)
    """
    if high - low <= UNIFORM_WIDTH:
        return np.linspace(low, high, UNIFORM + 1)
    bottom, top = math.log10(SMALLEST), math.log10(max(abs(low), abs(high)))
    magnitudes = 10.0 ** np.linspace(bottom, top, round((top - bottom) * PER_DECADE) + 1)
    points = np.concatenate([-magnitudes[::-1], [0.0], magnitudes, [low, high]])
    return np.unique(points[(points >= low) & (points <= high)])


def find_root(residual: Residual, low: float, high: float, count: int) -> np.ndarray:
    """The one root in ``[low, high]`` of each of ``count`` rows' residual, or NaN where there is not
    exactly one (see the module's docstring)."""
    row, root = _roots(residual, low, high, count)
    found = np.bincount(row, minlength=count)
    result = np.full(count, np.nan)
    single = found[row] == 1
    result[row[single]] = root[single]
    return result


def every_root(residual: Callable[[np.ndarray], np.ndarray], low: float, high: float) -> list[float]:
    """Every root in ``[low, high]`` of one residual that the grid brackets, in order.

    >>> [round(r, 12) for r in every_root(np.cos, -4.0, 4.0)]
    [-1.570796326795, 1.570796326795]
    """
    return sorted(float(r) for r in _roots(lambda x, rows: residual(x), low, high, 1)[1])


def _roots(residual: Residual, low: float, high: float, count: int) -> tuple[np.ndarray, np.ndarray]:
    """Each root the grid brackets, closed: the rows and the roots."""
    points = grid(low, high)
    every = np.arange(count)
    rows, starts, ends, at_start, at_end = [], [], [], [], []
    before = residual(np.full(count, points[0]), every)
    for left, right in pairwise(points):
        after = residual(np.full(count, right), every)
        # A zero on the grid is a root of its own (a bracket of width 0); a sign change is a bracket.
        changes = np.flatnonzero((before * after < 0) | ((after == 0) & np.isfinite(before)))
        if left == points[0]:
            changes = np.union1d(changes, np.flatnonzero(before == 0))
        rows.append(changes)
        starts.append(np.where(before[changes] == 0, left, np.where(after[changes] == 0, right, left)))
        ends.append(np.where(before[changes] == 0, left, right))
        at_start.append(before[changes])
        at_end.append(after[changes])
        before = after
    row, start, end = np.concatenate(rows), np.concatenate(starts), np.concatenate(ends)
    size = np.maximum(np.abs(np.concatenate(at_start)), np.abs(np.concatenate(at_end)))
    root = _closed(residual, row, start, end)
    with np.errstate(invalid="ignore"):
        # A bracket across a jump or a pole closes where the residual is still about as large as at its ends.
        real = np.abs(residual(root, row)) <= 1e-8 * size
    return row[real], root[real]


def _closed(residual: Residual, rows: np.ndarray, low: np.ndarray, high: np.ndarray) -> np.ndarray:
    """Each bracket ``[low, high]`` of row ``rows`` closed onto its root (a bracket of width 0 is its root)."""
    a, b = low.astype(float), high.astype(float)
    fa, fb = np.array(residual(a, rows), dtype=float), np.array(residual(b, rows), dtype=float)
    bisect = np.zeros(a.shape, dtype=bool)
    for _ in range(_ITERATIONS):
        middle = a + (b - a) / 2
        open_ = ((b - a) > TOLERANCE * np.maximum(np.abs(a), np.abs(b))) & (middle != a) & (middle != b) \
            & (fa != 0) & (fb != 0)
        active = np.flatnonzero(open_)
        if not active.size:
            break
        a_, b_, fa_, fb_ = a[active], b[active], fa[active], fb[active]
        with np.errstate(all="ignore"):
            secant = b_ - fb_ * (b_ - a_) / (fb_ - fa_)
        inside = (secant > a_) & (secant < b_) & ~bisect[active]
        x = np.where(inside, secant, middle[active])
        fx = residual(x, rows[active])
        left = np.sign(fx) == np.sign(fa_)  # the root is in [x, b]
        width = b_ - a_
        # Illinois: the end that stays has its value halved, so false position does not stall on it.
        a[active] = np.where(left, x, a_)
        fa[active] = np.where(left, fx, fa_ / 2)
        b[active] = np.where(left, b_, x)
        fb[active] = np.where(left, fb_ / 2, fx)
        bisect[active] = (b[active] - a[active]) > width / 2
    return np.where(fa == 0, a, np.where(fb == 0, b, a + (b - a) / 2))
