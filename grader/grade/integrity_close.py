"""The close search of the integrity check (:mod:`grader.grade.integrity`): the partners that could make a pair
of matched answers unlikely enough to keep, found without forming the pairs that could not.

A pair is kept when its corrected chance is under 1 (:data:`~grader.grade.integrity.KEPT`), so when its chance is
under ``1 / M`` (``M`` the pairs examined). Its chance is at least the product, over its matched parts, of each
part's chance taken as narrowly as that part's own match allows (the ``j`` closest matches narrow every band to
at least their own distance; a Poisson binomial tail of ``j`` or more is at least the chance that ``j`` given coins
all land); so the matched part whose chance is least has a chance under ``M ** (-1 / k)``, ``k`` the matched parts,
at most the student's parts that match anyone. A part's chance is at least its related kind's share times the
class's wrong answers' mass between the answer ``a`` and the centre ``c`` its closeness is measured from (the
partner's typed answer or value, both in the partner's band, so the narrowed band holds all between them), less
what the student's own answers may add to it (at most their count over the answers). That mass grows as ``c``
moves away from ``a``: inverting the class's cumulative distribution gives, per answer, a window of centres
outside which no partner can be kept, and only partners whose value or typed answer lies inside it are formed.
In a big class the window narrows as ``M`` grows, so the pairs formed grow with the class, not its square.

A partner whose typed right answer lies outside their own band (it cannot, when their tolerance accepted it; a
safeguard), and every partner of an angle's part (its chance has no related kind), or of an answer whose ratio to
the student's own value is not read (zero, none), are searched over the whole range, as before.

>>> window(np.array([0.0, 0.5, 1.0]), np.array([0.0, 1.0, 2.0]), np.array([1.0]), np.array([0.3]))
(array([0.5]), array([inf]))
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping, Sequence
from typing import NamedTuple

import numpy as np
import numpy.typing as npt

from grader.grade.compare import errors
from grader.grade.integrity_chance import UNRELATED, Spread
from grader.grade.integrity_search import Bands, Floats, Ints, accepts, blocks, expanded

MARGIN = 2.0  # the bound is loosened by this factor against floating-point rounding in the chances
WIDEN = 1e-9  # each window's ends are moved out by this share of their size, against rounding in log and exp


def window(grid: Floats, table: Floats, at: Floats, mass: Floats) -> tuple[Floats, Floats]:
    """Per point ``at`` (on the grid's scale), the widest interval around it outside which a cumulative
    distribution ``table`` (on ``grid``, linear between) has at least ``mass`` between the point and any point:
    ``-inf`` / ``inf`` where the distribution has not so much on that side."""
    level = np.interp(at, grid, table)
    below = np.searchsorted(table, level - mass, side="right") - 1
    above = np.searchsorted(table, level + mass, side="left")
    low = np.where(below >= 0, grid[np.clip(below, 0, len(grid) - 1)], -np.inf)
    high = np.where(above < len(table), grid[np.clip(above, 0, len(grid) - 1)], np.inf)
    return np.minimum(low, at), np.maximum(high, at)


def centres_window(part: Bands, spread: Spread, owners: Ints, numbers: Floats, least: Floats) -> tuple[Floats, Floats]:
    """Per answer (``numbers``, of ``owners``), the values of a centre outside which the part's chance is at
    least ``least``: ``(-inf, inf)`` where no such window is read (an angle, a zero, no other answers)."""
    count = len(owners)
    low, high = np.full(count, -np.inf), np.full(count, np.inf)
    if part.period is not None or spread.answers == 0 or not count:
        return low, high
    own = part.values[owners]
    theirs = np.isfinite(spread.cells[owners]).sum(axis=1)
    left = spread.answers - theirs
    total = float(spread.kernel[-1] - spread.kernel[0])
    # The related kind's mass wanted: the chance over its share, plus what the owner's own answers may take off.
    mass = least / (1 - UNRELATED) + theirs * total * (1 + 1e-9) / spread.answers
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = numbers / own
        at = np.log(np.abs(ratio))
    usable = np.isfinite(at) & (ratio != 0) & (left > 0) & np.isfinite(mass)
    grid = spread.start + spread.step * np.arange(len(spread.same))
    for same, table in ((True, spread.same), (False, spread.other)):
        rows = np.flatnonzero(usable & ((ratio > 0) == same))
        if not len(rows):
            continue
        lowest, highest = window(grid, table, at[rows], mass[rows])
        sign = own[rows] * (1.0 if same else -1.0)
        with np.errstate(over="ignore", invalid="ignore"):
            ends = np.stack([sign * np.exp(lowest), sign * np.exp(highest)])
        first, second = np.nanmin(ends, axis=0), np.nanmax(ends, axis=0)
        spare = WIDEN * (np.abs(first) + np.abs(second))
        low[rows], high[rows] = first - spare, second + spare
    return low, high


class Typed:
    """A part's right answers as typed, sorted (the other centre a closeness is read from), and the students
    whose typed right answer lies outside their own band (searched whole)."""

    def __init__(self, part: Bands, right: Floats) -> None:
        have = np.flatnonzero(np.isfinite(right) & np.isfinite(part.values) & np.isfinite(part.reach))
        self.order = have[np.argsort(right[have], kind="stable")]
        self.sorted = right[self.order]
        unit = part.unit if part.period is not None else None
        distance = errors(right[have], part.values[have], angle_unit=unit)[0]
        self.outside = have[~(distance <= part.reach[have])]


class _Source(NamedTuple):
    """Where a part's search looks for each answer (a row of the part's wrong answers): from ``starts`` to
    ``ends`` in the students listed in ``at``."""

    rows: Ints
    starts: Ints
    ends: Ints
    at: Ints


def close_pairs(parts: Sequence[Bands], spread: Spread, wrong: Mapping[str, Ints], numbers: Mapping[str, Floats],
                right: Mapping[str, Floats], ranges: Sequence[Sequence[tuple[Ints, Ints]]],
                searched: Sequence[Ints], chosen: Sequence[Ints], least: Floats, chunk: int
                ) -> Iterator[tuple[Ints, Ints]]:
    """The pairs (owner, partner) whose partner's band holds a wrong answer of the owner's, per owner by the
    cheaper of two searches that both find every pair that could be kept: the close search, over the answers
    ``searched`` (rows of ``wrong``, per part: every part that matches anyone), of the partners whose centre is
    in the answer's window (:func:`centres_window`, for the chance ``least`` per owner); or the band search
    over the answers ``chosen`` (per part), of every partner in their ranges. In pieces of about ``chunk``
    pairs (a block of owners at a time), each sorted and without repeats."""
    students = len(least)
    close, banded = [], []
    cost = np.zeros((2, students))  # per owner, the partners the close and the band search would look at
    for part, part_ranges, rows, rows_chosen in zip(parts, ranges, searched, chosen, strict=True):
        members = wrong[part.label]
        close.append(_close_sources(part, spread, members[rows], numbers[part.label], right[part.label],
                                    part_ranges, rows, least))
        banded.append([_Source(rows_chosen, starts[rows_chosen], ends[rows_chosen], part.order)
                       for starts, ends in part_ranges])
        for which, sources in enumerate((close[-1], banded[-1])):
            for source in sources:
                cost[which] += np.bincount(members[source.rows], minlength=students,
                                           weights=np.maximum(source.ends - source.starts, 0))
    by_close = cost[0] < cost[1]
    owners = np.flatnonzero(cost.min(axis=0) > 0)
    for group in blocks(cost.min(axis=0)[owners].astype(np.int64), chunk):
        inside = np.zeros(students, dtype=bool)
        inside[owners[group]] = True
        keys = [np.zeros(0, dtype=np.int64)]
        for part, close_sources, band_sources in zip(parts, close, banded, strict=True):
            members = wrong[part.label]
            for source, is_close in [*((source, True) for source in close_sources),
                                     *((source, False) for source in band_sources)]:
                who = members[source.rows]
                use = (by_close[who] == is_close) & inside[who]
                for which, positions in expanded(source.starts[use], source.ends[use]):
                    owner, partners = who[use][which], source.at[positions]
                    ok = accepts(part, owner, partners, numbers[part.label])
                    keys.append(np.unique(owner[ok] * students + partners[ok]))
        pairs = np.unique(np.concatenate(keys))
        yield pairs // students, pairs % students


def _close_sources(part: Bands, spread: Spread, owners: Ints, numbers: Floats, right: Floats,
                   part_ranges: Sequence[tuple[Ints, Ints]], rows: Ints, least: Floats) -> list[_Source]:
    """The close search's sources for a part's answers ``rows`` (of ``owners``): the values in each answer's
    window within its range, the typed right answers in it, and the students whose typed right answer is
    outside their band; the whole range where no window is read."""
    typed_numbers = numbers[owners]
    low, high = centres_window(part, spread, owners, typed_numbers, least[owners])
    windowed = np.isfinite(low) | np.isfinite(high)
    sources = []
    for starts, ends in part_ranges:
        starts, ends = starts[rows], ends[rows]
        lowest = np.searchsorted(part.sorted_values, low, side="left")
        highest = np.searchsorted(part.sorted_values, high, side="right")
        sources.append(_Source(rows, np.where(windowed, np.maximum(starts, lowest), starts),
                               np.where(windowed, np.minimum(ends, highest), ends), part.order))
    picked = np.flatnonzero(windowed)
    typed = Typed(part, right)
    if len(picked) and len(typed.order):
        sources.append(_Source(rows[picked], np.searchsorted(typed.sorted, low[picked], side="left"),
                               np.searchsorted(typed.sorted, high[picked], side="right"), typed.order))
    if len(picked) and len(typed.outside):
        sources.append(_Source(rows[picked], np.zeros(len(picked), np.int64),
                               np.full(len(picked), len(typed.outside), np.int64), typed.outside))
    return sources


def bound(examined: int, kept: float, matchable: Ints) -> Floats:
    """Per owner, the chance the least likely matched part of a pair kept (its corrected chance under ``kept``)
    must be under: ``(kept / M) ** (1 / k)`` with ``k`` the owner's parts that match anyone, loosened by
    :data:`MARGIN` (inf: any, when ``kept`` is over 1 or no part matches).

    >>> bound(10_000, 1.0, np.array([2, 4, 0])).tolist()
    [0.02, 0.2, inf]
    """
    if kept > 1:
        return np.full(len(matchable), math.inf)
    exponent = 1.0 / np.maximum(matchable, 1)
    found = MARGIN * np.power(kept / float(max(examined, 1)), exponent)
    return np.where(matchable > 0, found, math.inf)
