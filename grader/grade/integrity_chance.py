"""How likely a wrong answer is to land in another student's accepted band by accident: the model behind
the chances of :mod:`grader.grade.integrity` (docs/grading.md, *Answers from another student's variant*).

A wrong answer is taken to be one of two kinds, estimated from how the class's answers spread:

- **related to the student's own value** (a slip, a step done wrong: 6 % low, twice as much), with the
  share ``1 - UNRELATED``: its ratio to the student's own value is drawn as the class's wrong answers'
  ratios are (all numeric parts pooled, a Gaussian kernel density of ``log |ratio|``, each sign apart,
  Silverman's bandwidth), so the chance of landing in a band is that density's mass over the band's
  ratios to the student's own value (:class:`Spread`);
- **unrelated** (anything among the class's values), with the share ``UNRELATED``: the band's width times
  the density of the class's key values around it (:func:`class_density`).

>>> spread = Spread.of(np.array([1.2, 1.2, 0.8, 0.8]), np.ones(4), np.arange(4), 5)
>>> round(float(spread.chance(np.array([1.0]), np.array([1.19]), np.array([1.21]), np.array([4]))[0]), 3)
0.022
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

Floats = npt.NDArray[np.float64]
Ints = npt.NDArray[np.int64]

UNRELATED = 0.05  # the share of wrong answers taken to land anywhere among the class's values
SMALLEST_WIDTH = 0.01  # of the kernel, in log |ratio|: a class whose wrong answers are all alike is not sure
_STEPS = 8  # grid cells per kernel width
_REACH = 5  # kernel widths the kernel is drawn out to


def class_density(values: Floats, reach: Floats, order: Ints, sorted_values: Floats) -> Floats:
    """Per student, the chance that an unrelated wrong answer lands in their band: the band's width times
    the density of the class's values around it, over the ``√n`` nearest values on each side, and at least
    the share of the other students' values inside the band (NaN: no value).

    >>> values = np.array([1.0, 2.0, 3.0, 4.0, 5.0])
    >>> class_density(values, 0.01 * values, np.arange(5), values).round(6).tolist()
    [0.005, 0.01, 0.015, 0.02, 0.025]
    """
    chance = np.full(len(values), np.nan)
    count = len(order)
    if count < 2:
        return chance
    side = max(1, math.ceil(math.sqrt(count)))
    rank = np.arange(count)
    lowest, highest = np.maximum(rank - side, 0), np.minimum(rank + side, count - 1)
    width = sorted_values[highest] - sorted_values[lowest]
    bands = reach[order]
    with np.errstate(divide="ignore", invalid="ignore"):
        density = np.where(width > 0, (highest - lowest) / (count - 1) / width, 0.0)
    inside = (np.searchsorted(sorted_values, sorted_values + bands, side="right")
              - np.searchsorted(sorted_values, sorted_values - bands, side="left") - 1) / (count - 1)
    chance[order] = np.clip(np.maximum(density * 2 * bands, inside), 0.0, 1.0)
    return chance


@dataclass(frozen=True)
class Spread:
    """The class's wrong answers as ratios to their own values: per sign (the same as the student's own
    value, or the other), the cumulative distribution of ``log |ratio|`` on a grid (a Gaussian kernel
    density, binned), as shares of all the answers; and each student's own answers, on the grid, so that the
    chance of a student's answer is worked out without that student's answers (leave one out: the answers
    tested do not make themselves likely)."""

    start: float  # the grid's first cell boundary
    step: float
    same: Floats  # the cumulative distribution of the answers of the same sign, at each cell boundary
    other: Floats
    kernel: Floats  # one answer's cumulative kernel, at the boundaries of the cells around it
    answers: int
    cells: Floats  # the grid cells of the students' answers, a student's after another's (:meth:`own`)
    signs: npt.NDArray[np.bool_]  # of the same sign as their own value
    starts: Ints  # where each student's begin in ``cells``, and where the last one's end
    width: int  # the most answers of a student (at least 1)

    @classmethod
    def of(cls, answers: Floats, own: Floats, students: Ints, count: int) -> Spread:
        """From the wrong answers, their students' own values and the students (by index, of ``count``);
        pairs with a zero are left out."""
        usable = (answers != 0) & (own != 0) & np.isfinite(answers) & np.isfinite(own)
        # log |a| - log |o|, not log |a/o|: a ratio of two finite numbers may overflow (1.6e308 typed for 0.47).
        logs = np.log(np.abs(answers[usable])) - np.log(np.abs(own[usable]))
        same = np.sign(answers[usable]) == np.sign(own[usable])
        width = _bandwidth(logs)
        start = (float(logs.min()) if len(logs) else 0.0) - _REACH * width
        stop = (float(logs.max()) if len(logs) else 0.0) + _REACH * width
        step = width / _STEPS
        points = int((stop - start) / step) + 2
        kernel = np.exp(-0.5 * (np.arange(-_REACH * _STEPS, _REACH * _STEPS + 1) / _STEPS) ** 2)
        kernel /= kernel.sum()
        where = np.clip((logs - start) / step, 0, points - 2)  # in cells: each answer shared by the two nearest
        below = where.astype(np.int64)
        share = where - below
        tables = []
        for group in (same, ~same):
            counts = (np.bincount(below[group], 1 - share[group], minlength=points)
                      + np.bincount(below[group] + 1, share[group], minlength=points))
            smooth = np.convolve(counts, kernel, mode="same") / max(len(logs), 1)
            tables.append(np.concatenate([[0.0], np.cumsum(smooth)]))
        owners = students[usable]
        by_owner = np.argsort(owners, kind="stable")  # each student's answers in their order
        starts = np.searchsorted(owners[by_owner], np.arange(count + 1), side="left").astype(np.int64)
        return cls(start - step / 2, step, tables[0], tables[1], np.concatenate([[0.0], np.cumsum(kernel)]),
                   len(logs), where[by_owner], same[by_owner], starts, max(int(np.diff(starts).max(initial=0)), 1))

    def own(self, owners: Ints) -> tuple[Floats, npt.NDArray[np.bool_]]:
        """Per student of ``owners`` (a row), the grid cells of their answers, one column each, in their order
        (NaN: none), and whether each is of the same sign as their own value; :attr:`width` columns (a class's
        cells kept a student's after another's, not as a matrix of the most any student has)."""
        first = self.starts[owners]
        sizes = self.starts[owners + 1] - first
        rows = np.repeat(np.arange(len(owners)), sizes)
        columns = np.arange(int(sizes.sum())) - np.repeat(np.cumsum(sizes) - sizes, sizes)
        cells, signs = np.full((len(owners), self.width), np.nan), np.zeros((len(owners), self.width), dtype=bool)
        at = first[rows] + columns
        cells[rows, columns], signs[rows, columns] = self.cells[at], self.signs[at]
        return cells, signs

    def answered(self, owners: Ints) -> Ints:
        """How many answers each of ``owners`` has among the class's."""
        return np.asarray(self.starts[owners + 1] - self.starts[owners])

    def chance(self, own: Floats, low: Floats, high: Floats, owners: Ints, at_least: bool = False) -> Floats:
        """The chance that a wrong answer of student ``owners`` related to their ``own`` value lands in
        ``[low, high]``, from the other students' answers; 1 where the band holds zero or ``own`` is zero (no
        ratio tells). ``at_least``: a bound from below of that chance over ``[low, high]`` and over any interval
        that holds it, the student's own answers taken off whole wherever they are (their kernels not
        looked up: cheaper, and it cannot grow as the interval narrows)."""
        with np.errstate(divide="ignore", invalid="ignore"):
            first, second = low / own, high / own
            ends = np.log(np.abs(np.stack([first, second])))
        same = (first > 0) & (second > 0)
        other = (first < 0) & (second < 0)
        # fmin and fmax skip a NaN end as nanmin and nanmax do, without their warning where both are NaN (an
        # undefined own value, a null in the key: no ratio tells, and the chance is 1 below)
        a, b = np.fmin(ends[0], ends[1]), np.fmax(ends[0], ends[1])
        whole = np.where(same, self._mass(self.same, a, b), self._mass(self.other, a, b))
        left = self.answers - self.answered(owners)
        if at_least:  # each of the student's answers' kernels holds at most their whole mass
            whole = whole - (self.answers - left) * float(self.kernel[-1] - self.kernel[0]) * (1 + 1e-9) / max(
                self.answers, 1)
            return self._share(whole, left, same | other)
        mine, signs = self.own(owners)
        signed = np.where(np.isfinite(mine), signs == same[:, None], False)
        # A student's own answers' kernels, over the band: in grid cells, the band's ends from each answer's.
        low_cell, high_cell = (a - self.start) / self.step - 0.5, (b - self.start) / self.step - 0.5
        offsets = np.arange(len(self.kernel)) - (len(self.kernel) - 1) / 2
        with np.errstate(invalid="ignore"):
            own_mass = (np.interp(high_cell[:, None] - mine, offsets, self.kernel)
                        - np.interp(low_cell[:, None] - mine, offsets, self.kernel))
        own_mass = np.where(signed, own_mass, 0.0).sum(axis=1) / max(self.answers, 1)
        return self._share(whole - own_mass, left, same | other)

    def _share(self, others: Floats, left: Ints, signed: npt.NDArray[np.bool_]) -> Floats:
        """The other students' mass ``others`` (a share of all the answers) as a share of their own answers
        (``left`` of them); 1 where the band is not on one side of zero (``signed``), or no ratio tells."""
        with np.errstate(divide="ignore", invalid="ignore"):
            found = np.where(left > 0, others * self.answers / left, 0.0)
        found = np.where(signed, found, 1.0)
        return np.asarray(np.clip(np.nan_to_num(found, nan=1.0), 0.0, 1.0))

    def _mass(self, table: Floats, a: Floats, b: Floats) -> Floats:
        grid = self.start + self.step * np.arange(len(table))
        return np.asarray(np.interp(b, grid, table) - np.interp(a, grid, table))


def _bandwidth(logs: Floats) -> float:
    """Silverman's rule of thumb, and never below :data:`SMALLEST_WIDTH`."""
    if len(logs) < 2:
        return 1.0
    quartiles = np.percentile(logs, [25, 75])
    scale = min(float(np.std(logs, ddof=1)), float(quartiles[1] - quartiles[0]) / 1.34) or float(np.std(logs, ddof=1))
    width: float = 0.9 * scale * len(logs) ** -0.2
    return max(SMALLEST_WIDTH, width)
