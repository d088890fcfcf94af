"""The close search of the integrity check (:mod:`grader.grade.integrity`): the partners that could make a pair
of matched answers unlikely enough to keep, found without forming the pairs that could not.

A pair is kept when its corrected chance is under 1 (:data:`~grader.grade.integrity.KEPT`), so when its chance is
under ``1 / M`` (``M`` the pairs examined). Its chance is at least the product, over its matched parts, of each
part's chance taken as narrowly as that part's own match allows (the ``j`` closest matches narrow every band to
at least their own distance; a Poisson binomial tail of ``j`` or more is at least the chance that ``j`` given coins
all land); so the matched part whose chance is least has a chance under ``M ** (-1 / k)``, ``k`` the matched parts,
at most the student's wrong parts. A part's chance is at least its related kind's share times the
class's wrong answers' mass between the answer ``a`` and the centre ``c`` its closeness is measured from (the
partner's typed answer or value, both in the partner's band, so the narrowed band holds all between them), less
what the student's own answers may add to it (at most their count over the answers). That mass grows as ``c``
moves away from ``a``: inverting the class's cumulative distribution gives, per answer, a window of centres
outside which no partner can be kept, and only partners whose value or typed answer lies inside it are formed.
In a big class the window narrows as ``M`` grows, so the pairs formed grow with the class, not its square; but
for a student with ``k`` wrong parts only as ``M ** (-1 / k)``, so a partner found is formed into a pair only when
it may also hold another of the student's wrong answers (:class:`Elsewhere`: a pair needs two matched parts).

A partner whose typed right answer lies outside their own band (it cannot, when their tolerance accepted it; a
safeguard), and every partner of an angle's part (its chance has no related kind), or of an answer whose ratio to
the student's own value is not read (zero, none), are searched over the whole range, as before.

>>> window(np.array([0.0, 0.5, 1.0]), np.array([0.0, 1.0, 2.0]), np.array([1.0]), np.array([0.3]))
(array([0.85]), array([inf]))
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping, Sequence
from typing import Literal, NamedTuple

import numpy as np
import numpy.typing as npt

from grader.grade.compare import errors
from grader.grade.integrity_chance import UNRELATED, Spread
from grader.grade.integrity_search import Bands, Floats, Ints, accepts, blocks, distinct, expanded, ranges_least

FEW = 1 << 16  # partners looked at in all under which the band search alone is taken (the findings are the same)
CLOSE = True  # False: the band search alone, as before the close search (for the tests' comparison)
MARGIN = 2.0  # the bound is loosened by this factor against floating-point rounding in the chances
WIDEN = 1e-9  # each window's ends are moved out by this share of their size, against rounding in log and exp


def window(grid: Floats, table: Floats, at: Floats, mass: Floats) -> tuple[Floats, Floats]:
    """Per point ``at`` (on the grid's scale), the widest interval around it outside which a cumulative
    distribution ``table`` (on ``grid``, linear between) has at least ``mass`` between the point and any point:
    ``-inf`` / ``inf`` where the distribution has not so much on that side.

    >>> window(np.array([0.0, 0.5, 1.0]), np.array([0.0, 1.0, 2.0]), np.array([1.0, 0.5]), np.array([0.3, 1.5]))
    (array([0.85, -inf]), array([inf, inf]))
    """
    level = np.interp(at, grid, table)
    return (np.minimum(_inverse(grid, table, level - mass, "right"), at),
            np.maximum(_inverse(grid, table, level + mass, "left"), at))


def _inverse(grid: Floats, table: Floats, level: Floats, side: Literal["left", "right"]) -> Floats:
    """Where the piecewise linear ``table`` reaches ``level``: for ``right``, the highest point at or below
    which it is at most ``level`` (-inf: none); for ``left``, the lowest at or above which it is at least
    ``level`` (inf: none)."""
    found = np.searchsorted(table, level, side=side)
    if side == "right":  # table[k] <= level < table[k + 1]
        below = found - 1
        inside = (below >= 0) & (below < len(table) - 1)
        k = np.clip(below, 0, len(table) - 2)
        edge = np.where(below >= 0, np.inf, -np.inf)  # past the last point: the table is flat at its end
    else:  # table[k - 1] < level <= table[k]
        k = np.clip(found - 1, 0, len(table) - 2)
        inside = (found >= 1) & (found < len(table))
        edge = np.where(found < len(table), -np.inf, np.inf)
    rise = table[k + 1] - table[k]
    with np.errstate(divide="ignore", invalid="ignore"):
        share = np.clip(np.where(rise > 0, (level - table[k]) / rise, 0.0 if side == "right" else 1.0), 0.0, 1.0)
    point = grid[k] + share * (grid[k + 1] - grid[k])
    return np.where(inside, point, edge)


def centres_window(part: Bands, spread: Spread, owners: Ints, numbers: Floats, least: Floats) -> tuple[Floats, Floats]:
    """Per answer (``numbers``, of ``owners``), the values of a centre outside which the part's chance is at
    least ``least``: ``(-inf, inf)`` where no such window is read (an angle, a zero, no other answers)."""
    count = len(owners)
    low, high = np.full(count, -np.inf), np.full(count, np.inf)
    if part.period is not None or spread.answers == 0 or not count:
        return low, high
    own = part.values[owners]
    theirs = spread.answered(owners)
    left = spread.answers - theirs
    total = float(spread.kernel[-1] - spread.kernel[0])
    # The related kind's mass wanted: the chance over its share, plus what the owner's own answers may take off.
    mass = least / (1 - UNRELATED) + theirs * total * (1 + 1e-9) / spread.answers
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = numbers / own
        at = np.log(np.abs(ratio))
    usable = np.isfinite(at) & (ratio != 0) & (left > 0) & np.isfinite(mass)
    grid: Floats = spread.start + spread.step * np.arange(len(spread.same), dtype=np.float64)
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


class Searched:
    """What a part's close search looks up, worked out once a part, not once a window: its right answers as
    typed, sorted (the other centre a closeness is read from; those typed as the value is are found by it), and
    the students whose typed right answer lies outside their own band (searched whole); per wrong answer and
    turn of its range, the widest reach in the range (``reach``) and, for an angle, the widest reach over the
    band's chance (``spread``)."""

    def __init__(self, part: Bands, right: Floats, part_ranges: Sequence[tuple[Ints, Ints]]) -> None:
        have = np.flatnonzero(np.isfinite(right) & np.isfinite(part.values) & np.isfinite(part.reach)
                              & (right != part.values))
        placed = right[have] if part.period is None else np.mod(right[have], part.period)  # as the values
        self.order = have[np.argsort(placed, kind="stable")]
        self.sorted = np.sort(placed, kind="stable")
        unit = part.unit if part.period is not None else None
        distance = errors(right[have], part.values[have], angle_unit=unit)[0]
        self.outside = have[~(distance <= part.reach[have])]
        self.reach = [-least for least in ranges_least(-part.reach[part.order], part_ranges)]
        self.spread: list[Floats] = []
        if part.period is not None:
            chance = part.chance[part.order]
            with np.errstate(divide="ignore", invalid="ignore"):
                spread_out = np.where(chance > 0, part.reach[part.order] / chance, np.inf)
            spread_out = -np.nan_to_num(spread_out, nan=np.inf)
            self.spread = [-least for least in ranges_least(spread_out, part_ranges)]


class _Source(NamedTuple):
    """Where a part's search looks for each answer (a row of the part's wrong answers): from ``starts`` to
    ``ends`` in the students listed in ``at``."""

    rows: Ints
    starts: Ints
    ends: Ints
    at: Ints


def close_pairs(parts: Sequence[Bands], spread: Spread, wrong: Mapping[str, Ints], numbers: Mapping[str, Floats],
                right: Mapping[str, Floats], ranges: Sequence[Sequence[tuple[Ints, Ints]]],
                searched: Sequence[Ints], rank: npt.NDArray[np.int8], needed: Ints, examined: int, kept: float,
                chunk: int) -> Iterator[tuple[Ints, Ints]]:
    """The pairs (owner, partner) whose partner's band holds a wrong answer of the owner's and may hold another
    (:class:`Elsewhere`), that is every pair that could be kept, by two searches split at a number of parts.

    Of a pair, ``r`` is how many of the owner's wrong answers have the partner in their band search's range
    (the answers ``searched``, rows of ``wrong`` per part): at least the matched parts, and at least the
    owner's ``needed`` if the pair can be kept. For a split ``s`` chosen per owner, the pairs with ``r`` up to
    ``s`` are found by the close search: the partners whose centre is in a window around one of the owner's
    answers (:func:`centres_window`) for the chance :func:`bound` gives ``s`` parts (the least likely of ``m``
    matched parts is under the bound of ``m``, and ``m <= r <= s``). The pairs with ``r`` over ``s`` are found
    by the band search over the owner's parts ranked ``s`` or later (``rank``: most students matched first):
    a partner in more than ``s`` of the ranges is in one of those. Each owner takes the split whose searches
    look at the fewest partners (only the band search, as before the close search, when ``CLOSE`` is off).
    In pieces of about ``chunk`` partners looked at (a block of owners at a time), each sorted and without
    repeats."""
    students = len(needed)
    levels = np.zeros(students, dtype=np.int64)  # per owner, the answers searched
    for part, rows in zip(parts, searched, strict=True):
        levels[wrong[part.label][rows]] += 1
    owners = np.flatnonzero(levels >= np.maximum(needed, 2))
    top = int(levels[owners].max(initial=1))
    compact = np.full(students, -1, dtype=np.int64)
    compact[owners] = np.arange(len(owners))
    lookups = [Searched(part, right[part.label], part_ranges) for part, part_ranges in zip(parts, ranges, strict=True)]
    # Per split and owner, the partners the band search would look at: the parts ranked at the split or later.
    band = np.zeros((top + 2) * len(owners))
    rows_of = [rows[compact[wrong[part.label][rows]] >= 0] for part, rows in zip(parts, searched, strict=True)]
    for index, (part, part_ranges, rows) in enumerate(zip(parts, ranges, rows_of, strict=True)):
        who = compact[wrong[part.label][rows]]
        sizes = sum((np.maximum(ends[rows] - starts[rows], 0) for starts, ends in part_ranges), np.zeros(len(rows)))
        band += np.bincount(rank[owners[who], index].astype(np.int64) * len(owners) + who, sizes,
                            minlength=len(band))
    band = np.cumsum(band.reshape(top + 2, len(owners))[::-1], axis=0)[::-1]
    lowest = np.maximum(needed[owners], 2) - 1  # the split of the band search alone
    split, cost = lowest.copy(), band[lowest, np.arange(len(owners))]
    # A class whose band searches look at few partners in all is searched so: weighing the splits costs more.
    for level in range(2, top + 1) if CLOSE and cost.sum() > FEW else ():
        at = (levels[owners] >= level) & (lowest < level)
        if not at.any():
            continue
        looked = np.zeros(len(owners))
        least = np.full(students, float(bound(examined, kept, np.array([level]))[0]))
        for index, (part, part_ranges, rows) in enumerate(zip(parts, ranges, rows_of, strict=True)):
            use = rows[at[compact[wrong[part.label][rows]]]]
            for source in _close_sources(part, spread, wrong[part.label][use], numbers[part.label], lookups[index],
                                         part_ranges, use, least):
                looked += np.bincount(compact[wrong[part.label][source.rows]], minlength=len(owners),
                                      weights=np.maximum(source.ends - source.starts, 0))
        total = looked + band[level]
        better = at & (total < cost)
        split[better], cost[better] = level, total[better]
    yield from _formed(parts, spread, wrong, numbers, lookups, ranges, rows_of, rank, owners, split, cost,
                       np.maximum(needed, 2), examined, kept, chunk)


def _formed(parts: Sequence[Bands], spread: Spread, wrong: Mapping[str, Ints], numbers: Mapping[str, Floats],
            lookups: Sequence[Searched], ranges: Sequence[Sequence[tuple[Ints, Ints]]], rows_of: Sequence[Ints],
            rank: npt.NDArray[np.int8], owners: Ints, split: Ints, cost: Floats, needed: Ints, examined: int,
            kept: float, chunk: int) -> Iterator[tuple[Ints, Ints]]:
    """:func:`close_pairs`'s searches, each owner (of ``owners``) split at ``split``."""
    students = len(needed)
    at = np.full(students, -1, dtype=np.int64)  # each owner's split (-1: not searched)
    at[owners] = split
    least = np.full(students, np.inf)
    searching = owners[cost > 0]
    least[searching] = bound(examined, kept, np.maximum(at[searching], 1))
    groups = list(blocks(cost[cost > 0].astype(np.int64), chunk))
    block_of = np.full(students, -1, dtype=np.int64)
    for number, group in enumerate(groups):
        block_of[searching[group]] = number
    # Each source's answers, by their owner's block (in their order within it): a block takes a run of each.
    runs = []
    for index, (part, part_ranges, rows) in enumerate(zip(parts, ranges, rows_of, strict=True)):
        members = wrong[part.label]
        who = members[rows]
        close = rows[at[who] >= needed[who]]
        band = rows[rank[who, index] >= at[who]]
        for source, is_close in [*((source, True) for source in _close_sources(
                                     part, spread, members[close], numbers[part.label], lookups[index],
                                     part_ranges, close, least)),
                                 *((_Source(band, starts[band], ends[band], part.order), False)
                                   for starts, ends in part_ranges)]:
            who = members[source.rows]
            use = np.flatnonzero(block_of[who] >= 0)
            use = use[np.argsort(block_of[who[use]], kind="stable")]
            bounds = np.searchsorted(block_of[who[use]], np.arange(len(groups) + 1))
            runs.append((index, part, source, is_close, who[use], use, bounds))
    elsewhere = Elsewhere(parts, wrong, ranges, students, rows_of)  # r counts the ranges of the answers searched
    for number in range(len(groups)):
        keys = [np.zeros(0, dtype=np.int64)]
        for index, part, source, is_close, who, use, bounds in runs:
            run = slice(bounds[number], bounds[number + 1])
            owner_of, rows = who[run], use[run]
            for which, positions in expanded(source.starts[rows], source.ends[rows]):
                owner, partners = owner_of[which], source.at[positions]
                first, last = (int(which[0]), int(which[-1]) + 1) if len(which) else (0, 0)
                found = 1 + elsewhere(index, owner_of[first:last], which - first, partners)  # r: ranges holding it
                wanted = ((found >= needed[owner]) & (found <= at[owner]) if is_close
                          else (found >= needed[owner]) & (found > at[owner]))
                owner, partners = owner[wanted], partners[wanted]
                ok = accepts(part, owner, partners, numbers[part.label])
                keys.append(distinct(owner[ok] * students + partners[ok]))
        pairs = distinct(np.concatenate(keys))
        yield pairs // students, pairs % students


class Elsewhere:
    """How many of the owner's other wrong answers a partner may hold: in how many of their band search's ranges
    it is (:func:`~grader.grade.integrity_search.holding`: a range holds every band that holds the answer). A
    pair is kept only with two or more matched parts, so a partner found for one part that is in no other
    range is let go before its band is compared (:func:`close_pairs` counts ``r`` with it); a look-up of the
    partner's place in each of the owner's other wrong parts' orders, not a comparison of bands (4 bytes a
    student and part, twice)."""

    def __init__(self, parts: Sequence[Bands], wrong: Mapping[str, Ints],
                 ranges: Sequence[Sequence[tuple[Ints, Ints]]], students: int,
                 searched: Sequence[Ints] | None = None) -> None:
        # Per part, each student's place in its order (-1: no value) and the number of their wrong answer to it
        # (-1: none, or not among the answers ``searched``, rows of ``wrong`` per part; the answers numbered one
        # part after another), 4 bytes each.
        self.place = np.full((len(parts), students), -1, dtype=np.int32)
        self.answer = np.full((len(parts), students), -1, dtype=np.int32)
        first = 0
        for index, part in enumerate(parts):
            self.place[index, part.order] = np.arange(len(part.order))
            members = wrong[part.label]
            rows = np.arange(len(members)) if searched is None else searched[index]
            self.answer[index, members[rows]] = first + rows
            first += len(members)
        # Each wrong answer's ranges, a turn at a time (a part with fewer turns has empty ones, not looked at).
        self.turns = [len(part_ranges) for part_ranges in ranges]
        turns = max(self.turns, default=0)
        self.starts, self.ends = (np.zeros((turns, first), dtype=np.int32) for _ in range(2))
        first = 0
        for part, part_ranges in zip(parts, ranges, strict=True):
            count = len(wrong[part.label])
            for turn, (starts, ends) in enumerate(part_ranges):
                self.starts[turn, first:first + count], self.ends[turn, first:first + count] = starts, ends
            first += count

    def __call__(self, index: int, owners: Ints, which: Ints, partners: Ints) -> Ints:
        """Per pair (``owners[which[k]]``, ``partners[k]``) found for part ``index``, how many of the owner's other
        wrong answers have the partner in their range (each owner's answers and ranges looked up once, not once
        a pair)."""
        found = np.zeros(len(which), dtype=np.int64)
        for other, (answers, places) in enumerate(zip(self.answer, self.place, strict=True)):
            if other == index:
                continue
            answer = answers[owners]
            some = answer >= 0
            if not some.any():
                continue
            rows = np.flatnonzero(some[which])
            place, at = places[partners[rows]], which[rows]
            answer = np.maximum(answer, 0)
            inside = np.zeros(len(rows), dtype=bool)
            for starts, ends in zip(self.starts[:self.turns[other]], self.ends[:self.turns[other]], strict=True):
                inside |= (starts[answer][at] <= place) & (place < ends[answer][at])
            found[rows[inside]] += 1
        return found


def _close_sources(part: Bands, spread: Spread, owners: Ints, numbers: Floats, lookup: Searched,
                   part_ranges: Sequence[tuple[Ints, Ints]], rows: Ints, least: Floats) -> list[_Source]:
    """The close search's sources for a part's answers ``rows`` (of ``owners``): the values in each answer's
    window within its range, the typed right answers in it, and the students whose typed right answer is
    outside their band; the whole range where no window is read."""
    typed_numbers = numbers[owners]
    if part.period is not None:
        return _angle_sources(part, owners, typed_numbers, lookup, part_ranges, rows, least[owners])
    low, high = centres_window(part, spread, owners, typed_numbers, least[owners])
    windowed = np.isfinite(low) | np.isfinite(high)
    sources = []
    for (starts, ends), reach in zip(part_ranges, lookup.reach, strict=True):
        sources.append(_within(rows, starts[rows], ends[rows], part.sorted_values, low, high, windowed, part.order))
        # A typed centre is in its band, which holds the answer: within twice the widest reach of the range.
        widest = 2 * (1 + WIDEN) * reach[rows]
        low, high = np.maximum(low, typed_numbers - widest), np.minimum(high, typed_numbers + widest)
    sources += _typed_sources(lookup, rows, low, high, windowed)
    return sources


def _angle_sources(part: Bands, owners: Ints, numbers: Floats, lookup: Searched,
                   part_ranges: Sequence[tuple[Ints, Ints]], rows: Ints, least: Floats) -> list[_Source]:
    """An angle's close search. Its chance is the partner's ``p`` times the narrowed share of their band, at
    least ``p |a - c| / 2r`` (the band narrowed holds all between the answer and the centre): a centre can
    make it under ``least`` only within ``2 least r / p`` of the answer, the widest of that over the range,
    a turn at a time as the range is."""
    period = float(part.period or 0.0)
    placed = np.mod(numbers, period)
    sources = []
    for shift, (starts, ends), spread_out, reach_out in zip((0.0, -period, period), part_ranges, lookup.spread,
                                                            lookup.reach, strict=True):
        starts, ends = starts[rows], ends[rows]
        with np.errstate(invalid="ignore"):
            reach = np.maximum(2 * least * spread_out[rows] * (1 + WIDEN), 0.0) + WIDEN * period
        windowed = np.isfinite(reach)
        target = placed + shift
        widest = 2 * (1 + WIDEN) * reach_out[rows]
        low, high = target - np.minimum(reach, widest), target + np.minimum(reach, widest)
        sources.append(_within(rows, starts, ends, part.sorted_values, low, high, windowed, part.order))
        sources += _typed_sources(lookup, rows, low, high, windowed)
    return sources


def _within(rows: Ints, starts: Ints, ends: Ints, sorted_values: Floats, low: Floats, high: Floats,
            windowed: npt.NDArray[np.bool_], order: Ints) -> _Source:
    """The range of each answer, narrowed to the values between ``low`` and ``high`` where ``windowed``."""
    lowest = np.searchsorted(sorted_values, low, side="left")
    highest = np.searchsorted(sorted_values, high, side="right")
    return _Source(rows, np.where(windowed, np.maximum(starts, lowest), starts),
                   np.where(windowed, np.minimum(ends, highest), ends), order)


def _typed_sources(typed: Searched, rows: Ints, low: Floats, high: Floats,
                   windowed: npt.NDArray[np.bool_]) -> list[_Source]:
    """The students whose typed right answer is between ``low`` and ``high``, and those whose typed right
    answer is outside their band, for the answers ``windowed``."""
    picked = np.flatnonzero(windowed)
    sources = []
    if len(picked) and len(typed.order):
        sources.append(_Source(rows[picked], np.searchsorted(typed.sorted, low[picked], side="left"),
                               np.searchsorted(typed.sorted, high[picked], side="right"), typed.order))
    if len(picked) and len(typed.outside):
        sources.append(_Source(rows[picked], np.zeros(len(picked), np.int64),
                               np.full(len(picked), len(typed.outside), np.int64), typed.outside))
    return sources


def bound(examined: int, kept: float, wrong: Ints) -> Floats:
    """Per owner, the chance the least likely matched part of a pair kept (its corrected chance under ``kept``)
    must be under: ``(kept / M) ** (1 / k)`` with ``k`` the owner's wrong parts, loosened by
    :data:`MARGIN` (inf: any, when ``kept`` is over 1 or no part is wrong).

    >>> bound(10_000, 1.0, np.array([2, 4, 0])).tolist()
    [0.02, 0.2, inf]
    """
    if kept > 1:
        return np.full(len(wrong), math.inf)
    exponent = 1.0 / np.maximum(wrong, 1)
    found = MARGIN * np.power(kept / float(max(examined, 1)), exponent)
    return np.where(wrong > 0, found, math.inf)
