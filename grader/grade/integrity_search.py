"""The band search of the integrity check (:mod:`grader.grade.integrity`): which students' accepted bands hold
a wrong answer, never over all pairs.

A part's key values are sorted once (angles reduced to one turn); with the lowest band start from each sorted
position on and the highest band end up to it, two binary searches (``numpy.searchsorted``) give, for each
answer, a range of sorted positions whose bands may hold it, and only those candidates are tested; bands closed
at both ends are counted from their sorted starts and ends without being listed. A class of 100,000 costs a few
seconds.

>>> from grader.model.tolerance import Tolerance
>>> tolerance = Tolerance().to_json()
>>> part = bands("1a", np.array([2.0, 3.0, 5.0]), [tolerance] * 3, "m/s")
>>> owners, partners = matches(part, np.array([0]), np.array([4.98]))
>>> owners.tolist(), partners.tolist()
([0], [2])
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from grader.grade.compare import accepted_distance, distances, errors
from grader.grade.integrity_chance import class_density
from grader.model.tolerance import Tolerance

Floats = npt.NDArray[np.float64]
Ints = npt.NDArray[np.int64]

CHUNK = 1 << 19  # candidate pairs tested at a time (about 100 bytes each): memory bounded, whatever the class
BY_ENDS = True  # count an answer's matches from the sorted ends of the bands (False: test each candidate)
PERIOD = {"deg": 360.0, "rad": 2 * math.pi}


@dataclass(frozen=True)
class Bands:
    """A numeric part over the class: each student's key value (NaN: none), accepted distance, whether the
    bound is strict (sigfigs, decimals), the chance ``p`` of their band; the students with a value sorted
    by it (angles reduced to one turn)."""

    label: str
    unit: str
    values: Floats
    reach: Floats
    strict: npt.NDArray[np.bool_]
    chance: Floats
    order: Ints
    sorted_values: Floats

    @property
    def period(self) -> float | None:
        return PERIOD.get(self.unit)


def bands(label: str, values: Floats, tolerances: Sequence[Mapping[str, Any]], unit: str) -> Bands:
    """A part's bands: each student's accepted distance (worked out per tolerance: a part has a few)."""
    reach, strict = np.full(len(values), np.nan), np.zeros(len(values), dtype=bool)
    groups: dict[tuple[tuple[str, Any], ...], list[int]] = {}
    mapping: Mapping[str, Any] | None = None
    members: list[int] = []
    for index, tolerance in enumerate(tolerances):
        if tolerance is not mapping:  # the key shares one mapping between equal rules
            mapping, members = tolerance, groups.setdefault(tuple(tolerance.items()), [])
        members.append(index)
    for written, members in groups.items():
        rule = Tolerance.from_json(dict(written))
        reach[members] = accepted_distance(values[members], rule)
        strict[members] = rule.mode != "rtol"
    period = PERIOD.get(unit)
    have = np.flatnonzero(np.isfinite(values) & np.isfinite(reach))
    placed = values[have] if period is None else np.mod(values[have], period)
    order = have[np.argsort(placed, kind="stable")]
    sorted_values = np.sort(placed, kind="stable")
    return Bands(label, unit, values, reach, strict, class_density(values, reach, order, sorted_values), order,
                 sorted_values)


def _ranges(part: Bands, numbers: Floats) -> Iterator[tuple[Ints, Ints]]:
    """For each number, the positions in the part's sorted order that may hold it in their band: one
    range, or, for an angle, one for each neighbouring turn. From the lowest band start from each sorted
    position on and the highest band end up to it (a search over them finds a superset of the bands that hold
    a number; worked out here, not kept: a class's part takes 16 bytes a student)."""
    bands = part.reach[part.order]
    sorted_values = part.sorted_values
    low = np.minimum.accumulate((sorted_values - bands)[::-1])[::-1] if len(bands) else sorted_values
    high = np.maximum.accumulate(sorted_values + bands) if len(bands) else sorted_values
    del bands
    period = part.period
    shifts = (0.0,) if period is None else (0.0, -period, period)
    placed = numbers if period is None else np.mod(numbers, period)
    for shift in shifts:
        target = placed + shift
        yield (np.searchsorted(high, target, side="left").astype(np.int64),
               np.searchsorted(low, target, side="right").astype(np.int64))


def accepts(part: Bands, owners: Ints, partners: Ints, numbers: Floats) -> npt.NDArray[np.bool_]:
    """Whether each partner's band holds the owner's number, the partner being another student whose value
    the owner's own band does not hold."""
    unit = part.unit if part.period is not None else None
    distance = distances(numbers[owners], part.values[partners], angle_unit=unit)
    reach = part.reach[partners]
    inside = np.where(part.strict[partners], distance < reach, distance <= reach)
    own = distances(part.values[partners], part.values[owners], angle_unit=unit)
    mine = np.where(part.strict[owners], own < part.reach[owners], own <= part.reach[owners])
    return np.asarray(inside & ~mine & (owners != partners), dtype=bool)


def distinct(keys: Ints) -> Ints:
    """The distinct keys, sorted: ``numpy.unique`` of whole numbers by a sort (numpy 2's hashing is many times
    slower on a million keys).

    >>> distinct(np.array([5, 1, 5, 3, 1])).tolist()
    [1, 3, 5]
    """
    ordered = np.sort(keys)
    first = np.ones(len(ordered), dtype=bool)
    np.not_equal(ordered[1:], ordered[:-1], out=first[1:])
    return ordered[first]


def expanded(starts: Ints, ends: Ints) -> Iterator[tuple[Ints, Ints]]:
    """Each range's index and the positions in it, in blocks of about :data:`CHUNK` positions."""
    sizes = np.maximum(ends - starts, 0)
    begin = 0
    while begin < len(sizes):
        total = np.cumsum(sizes[begin:])
        end = begin + max(1, int(np.searchsorted(total, CHUNK, side="right")))
        block = sizes[begin:end]
        owner = np.repeat(np.arange(begin, end), block)
        offsets = np.arange(int(block.sum())) - np.repeat(np.cumsum(block) - block, block)
        yield owner, starts[owner] + offsets
        begin = end


def blocks(sizes: Ints, size: int) -> Iterator[slice]:
    """Consecutive runs of ``sizes`` whose sum is at most ``size`` (one entry if it alone is more).

    >>> [(run.start, run.stop) for run in blocks(np.array([2, 3, 1, 9, 1]), 5)]
    [(0, 2), (2, 3), (3, 4), (4, 5)]
    """
    total = np.cumsum(sizes)
    begin = 0
    while begin < len(sizes):
        before = int(total[begin - 1]) if begin else 0
        end = max(begin + 1, int(np.searchsorted(total, before + size, side="right")))
        yield slice(begin, end)
        begin = end


def candidates(parts: Sequence[Bands], wrong: Mapping[str, Ints], numbers: Mapping[str, Floats],
               ranges: Sequence[Sequence[tuple[Ints, Ints]]], chosen: Sequence[Ints],
               inside: npt.NDArray[np.bool_]) -> tuple[Ints, Ints]:
    """The pairs (owner, partner), in order, whose partner's band holds a wrong answer of the owner's: per
    part, the answers ``chosen`` (rows of ``wrong``) of the owners ``inside``, searched over their ranges."""
    students, keys = len(inside), [np.zeros(0, dtype=np.int64)]
    for part, part_ranges, rows in zip(parts, ranges, chosen, strict=True):
        members = wrong[part.label]
        rows = rows[inside[members[rows]]]
        for starts, ends in part_ranges:
            for which, positions in expanded(starts[rows], ends[rows]):
                owners, partners = members[rows[which]], part.order[positions]
                ok = accepts(part, owners, partners, numbers[part.label])
                keys.append(distinct(owners[ok] * students + partners[ok]))
    pairs = distinct(np.concatenate(keys))
    return pairs // students, pairs % students


def matches(part: Bands, owners: Ints, numbers: Floats) -> tuple[Ints, Ints]:
    """Every (owner, partner) whose partner's band holds ``numbers`` (one per owner); for a test's eyes."""
    full = np.full(len(part.values), np.nan)
    full[owners] = numbers
    found_owners, found_partners = [], []
    for starts, ends in _ranges(part, numbers):
        for which, positions in expanded(starts, ends):
            who, partner = owners[which], part.order[positions]
            ok = accepts(part, who, partner, full)
            found_owners.append(who[ok])
            found_partners.append(partner[ok])
    return np.concatenate(found_owners or [np.zeros(0, np.int64)]), np.concatenate(found_partners or
                                                                                  [np.zeros(0, np.int64)])


def holding(part: Bands, wrong: Ints, numbers: Floats) -> tuple[Ints, list[tuple[Ints, Ints]]]:
    """Per wrong answer (of ``wrong``), how many students' bands hold it, and its candidate ranges.

    Bands closed at both ends (not an angle's, nor a strict bound's) are counted without being listed (in a
    class of 100,000 a wrong answer may fall in thousands): the bands holding ``a`` are those that start at or
    below it less those that end below it, two binary searches in the sorted starts and ends. The bands not
    counted as matches (the student's own, and those of values the student's own band holds) can hold only an
    answer within the student's reach plus the widest reach of the values their band holds: those answers are
    tested one by one (past the values their own band surely holds: :func:`_inner`), as are all of a strict
    bound's; an angle's are counted by :func:`_angle_counts`."""
    counts = np.zeros(len(wrong), dtype=np.int64)
    ranges = list(_ranges(part, numbers[wrong]))
    tested = np.arange(len(wrong))
    if BY_ENDS and part.period is None and not part.strict.any():
        typed, bands = numbers[wrong], part.reach[part.order]
        # The bands' starts and ends, each sorted (worked out here, not kept).
        counts = (np.searchsorted(np.sort(part.sorted_values - bands), typed, side="right")
                  - np.searchsorted(np.sort(part.sorted_values + bands), typed, side="left")).astype(np.int64)
        del bands
        own, mine = part.values[wrong], part.reach[wrong]
        widest = -range_least(-part.reach[part.order], np.searchsorted(part.sorted_values, own - mine, side="left"),
                               np.searchsorted(part.sorted_values, own + mine, side="right"))
        tested = np.flatnonzero(np.abs(typed - own) <= mine + np.maximum(widest, 0.0))
        counts[tested] = 0
    elif BY_ENDS and part.period is not None and len(part.order) and 4 * part.reach[part.order].max() < part.period:
        counts, tested = _angle_counts(part, wrong, numbers, ranges)
    inner = _inner(part, wrong[tested])
    for starts, ends in ranges:
        starts, ends = starts[tested], ends[tested]
        # Past the values the student's own band surely holds (none counts), on either side.
        for first, last in ((starts, np.minimum(ends, inner[0])), (np.maximum(starts, inner[1]), ends)):
            for which, positions in expanded(first, last):
                ok = accepts(part, wrong[tested[which]], part.order[positions], numbers)
                counts += np.bincount(tested[which[ok]], minlength=len(wrong))
    return counts, ranges


def _inner(part: Bands, owners: Ints) -> tuple[Ints, Ints]:
    """Per owner, sorted positions (from, to) whose values the owner's own band surely holds (:func:`accepts`
    counts none of them): those more than a millionth of its reach inside its edges, where that is far above
    the rounding of a difference (none for an angle, or where the reach is not so)."""
    count = len(owners)
    if part.period is not None or not count:
        return np.zeros(count, dtype=np.int64), np.zeros(count, dtype=np.int64)
    own, mine = part.values[owners], part.reach[owners]
    with np.errstate(invalid="ignore"):
        margin = np.where(part.strict[owners], 1e-6, 0.0) + 1e-6
        usable = np.isfinite(own) & np.isfinite(mine) & (mine * 1e-6 > 1e-12 * np.abs(own))
    inside = np.where(usable, mine * (1 - margin), 0.0)
    low, high = np.where(usable, own - inside, 0.0), np.where(usable, own + inside, 0.0)
    first = np.searchsorted(part.sorted_values, low, side="left")
    last = np.searchsorted(part.sorted_values, high, side="right")
    return np.where(usable, first, 0).astype(np.int64), np.where(usable, last, 0).astype(np.int64)


def _angle_counts(part: Bands, wrong: Ints, numbers: Floats, ranges: Sequence[tuple[Ints, Ints]]
                  ) -> tuple[Ints, Ints]:
    """An angle's :func:`holding` counts, from the bands' sorted ends on the circle (each band narrower than a
    quarter turn, so it holds an answer in at most one turn), and the answers to test one by one.

    A band counts as holding ``a`` when it starts at or below it and does not end below it, in the turn
    before, this or the next; that is what :func:`accepts` finds, but for rounding at an end within a
    billionth of a turn of ``a``: those bands are tested one by one in its place, and counted, as the search
    one by one counts them, when in the answer's ``ranges`` too (which an answer on a band's end across the
    turn may not be, by the rounding of its place in the turn). The bands not counted as
    matches (the student's own, and those of values the student's own band holds) can hold only an answer
    within the student's reach plus the widest: those answers are counted one by one (returned)."""
    period = float(part.period or 0.0)
    typed, reach, count = numbers[wrong], part.reach[part.order], len(part.order)
    placed = np.mod(typed, period)
    first, last = part.sorted_values - reach, part.sorted_values + reach  # by sorted position
    by_first, by_last = np.argsort(first, kind="stable"), np.argsort(last, kind="stable")
    firsts, lasts = first[by_first], last[by_last]
    slack = 1e-9 * period  # far above the rounding of a turn's difference, far below any reach
    counts = np.zeros(len(wrong), dtype=np.int64)
    near = [np.zeros(0, dtype=np.int64)]
    for shift in (0.0, -period, period):
        target = placed + shift
        counts += np.searchsorted(firsts, target, side="right") - np.searchsorted(lasts, target, side="left")
        for ends, by in ((firsts, by_first), (lasts, by_last)):
            for which, positions in expanded(np.searchsorted(ends, target - slack, side="left"),
                                             np.searchsorted(ends, target + slack, side="right")):
                near.append(which * count + by[positions])
    edges = distinct(np.concatenate(near))
    rows, positions = edges // count, edges % count
    counted = np.zeros(len(edges), dtype=np.int64)
    for shift in (0.0, -period, period):
        target = placed[rows] + shift
        counted += (first[positions] <= target).astype(np.int64) - (last[positions] < target)
    held = accepts(part, wrong[rows], part.order[positions], numbers)
    held &= np.any([(starts[rows] <= positions) & (positions < ends[rows]) for starts, ends in ranges], axis=0)
    np.add.at(counts, rows, held.astype(np.int64) - counted)
    own, mine = part.values[wrong], part.reach[wrong]
    distance = errors(typed, own, angle_unit=part.unit)[0]
    tested = np.flatnonzero(distance <= (mine + reach.max()) * (1 + 1e-9) + slack)
    counts[tested] = 0
    return counts, tested


def range_least(values: Floats, starts: Ints, ends: Ints) -> Floats:
    """The least of ``values[start:end]`` per range (inf: empty), from a table of the least of each run of
    ``2^k`` values (a sparse table: two look-ups a range).

    >>> range_least(np.array([5.0, 3.0, 4.0, 1.0, 2.0]), np.array([0, 0, 2, 4, 3]), np.array([1, 3, 4, 5, 3]))
    array([ 5.,  3.,  1.,  2., inf])
    """
    return ranges_least(values, [(starts, ends)])[0]


def ranges_least(values: Floats, ranges: Sequence[tuple[Ints, Ints]]) -> list[Floats]:
    """:func:`range_least` of each ``(starts, ends)`` of ``ranges``, the table built once for them all."""
    levels: list[Floats] = []
    found = []
    for starts, ends in ranges:
        least = np.full(len(starts), np.inf)
        sizes = ends - starts
        if len(values) and (sizes > 0).any():
            if not levels:
                levels.append(values)
                while 2 ** len(levels) <= len(values):
                    run = 2 ** (len(levels) - 1)
                    levels.append(np.minimum(levels[-1][:-run], levels[-1][run:]))
            some = np.flatnonzero(sizes > 0)
            level = np.floor(np.log2(sizes[some])).astype(np.int64)
            for k in distinct(level).tolist():
                rows = some[level == k]
                least[rows] = np.minimum(levels[k][starts[rows]], levels[k][ends[rows] - 2 ** k])
        found.append(least)
    return found


def nearest(part: Bands, owners: Ints, numbers: Floats, count: int) -> Ints:
    """Per owner, up to ``count`` students whose bands hold the owner's number, nearest first (by
    distance over the band), among the values sorted next to it (-1: none)."""
    if not len(owners) or not len(part.order):
        return np.full((len(owners), count), -1, dtype=np.int64)
    period = part.period
    placed = numbers[owners] if period is None else np.mod(numbers[owners], period)
    middle = np.searchsorted(part.sorted_values, placed)
    positions = np.clip(middle[:, None] + np.arange(-2 * count, 2 * count)[None, :], 0, len(part.order) - 1)
    partners = part.order[positions]
    who = np.repeat(owners, positions.shape[1])
    ok = accepts(part, who, partners.ravel(), numbers).reshape(positions.shape)
    unit = part.unit if period is not None else None
    with np.errstate(divide="ignore", invalid="ignore"):
        score = errors(numbers[who], part.values[partners.ravel()], angle_unit=unit)[0].reshape(positions.shape)
        score = score / part.reach[partners]
    score = np.where(ok, score, np.inf)
    # Clipped positions repeat the ends: a repeated partner is listed once (the first of equal scores).
    first = np.ones(positions.shape, dtype=bool)
    first[:, 1:] = positions[:, 1:] != positions[:, :-1]
    score = np.where(first, score, np.inf)
    best = np.argsort(score, axis=1, kind="stable")[:, :count]
    chosen = np.take_along_axis(partners, best, axis=1)
    return np.where(np.isfinite(np.take_along_axis(score, best, axis=1)), chosen, -1)
