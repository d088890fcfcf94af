"""Answers that belong to another student's variant: evidence of copying, reported, never graded.

Every student has their own numbers, so a wrong answer that another student's key accepts, for the same part
and within that student's tolerance, is worth a look. A wrong answer here is one graded ``incorrect`` with a
number: not the student's own value (that is ``correct``), and not a diagnosed mistake or an error carried
forward of their own (those are ``mistake`` and ``ecf``). An answer is also not counted against a student
whose value the answering student's own key accepts (two variants with the same numbers).

The search sorts each part's key values once and finds, for each wrong answer, the students whose accepted
band holds it by binary search (``numpy.searchsorted``): never all pairs, so a class of 100,000 costs a few
seconds. A pair (who answered, whose variant) with two or more matched parts gets the chance of so many
matches by accident (docs/grading.md, *Answers from another student's variant*):

- per part, ``p``: the chance that a wrong answer lands in a given student's accepted band by accident, that
  band's width times the density of the class's key values around it (counted over the ``√n`` nearest
  values on each side), and never less than the share of the class's values inside the band;
- how close: each match's distance, in half-units of the last digit the answering student typed, from what
  the partner typed when it was right with no fewer digits (a copy typed as its source typed it is at 0), else
  from the partner's value; for the ``j`` closest matches, the least close of them narrows every part's band
  to that point ± (that many half-units + 1), and ``p`` is taken over it;
- for the pair, the chance of at least ``j`` of the answering student's wrong parts in their narrowed bands,
  each a coin with its own ``p`` (a Poisson binomial tail), the least over ``j`` from 2 to the matches;
- corrected for the choice of ``j`` (times the wrong parts less one) and for the pairs examined
  (Bonferroni: times the number of ordered pairs whose first student has two or more wrong parts, only
  those can match twice), at most 1.

A pair whose corrected chance is at most the assignment's ``grading.integrity_threshold`` is flagged.

The band search (which students' bands hold an answer) is :mod:`grader.grade.integrity_search`; of the candidate
pairs, only those that could be kept are formed (:mod:`grader.grade.integrity_close`), about :data:`PAIRS` at a
time, so time and memory grow with the class, not its square; of those, a bound from below of the corrected
chance (:func:`_at_least`) lets go those that could not be kept before their chances are worked out.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping, Sequence
from typing import Any, NamedTuple

import numpy as np
import numpy.typing as npt

from grader.grade.class_grades import ClassGrades, classwide
from grader.grade.compare import errors
from grader.grade.grading import Graded
from grader.grade.integrity_chance import UNRELATED, Spread
from grader.grade.integrity_close import MARGIN, close_pairs
from grader.grade.integrity_found import Integrity, Match, Matches, Pair, Pairs, Small
from grader.grade.integrity_search import (
    Bands,
    Floats,
    Ints,
    accepts,
    bands,
    blocks,
    candidates,
    distinct,
    holding,
    nearest,
    range_least,
)
from grader.grade.integrity_typed import halves
from grader.grade.texts import Texts

LISTED = 5  # students named per wrong answer in integrity.csv; the rest are counted
KEPT = 1.0  # pairs with two or more matched parts are kept when their corrected chance is below this
PAIRS = 1 << 19  # candidate pairs worked out at a time (a few hundred bytes each): memory bounded, whatever the class
FIGURED = 1 << 16  # pairs whose chances are worked out at a time (about 500 bytes each while they are)
ROWS = 1 << 14  # students whose figures per part are laid out in a matrix at a time

__all__ = ["LISTED", "Integrity", "Match", "Pair", "check"]


class _Right(Mapping[str, Floats]):
    """Per part label, each student's number when their answer was right (NaN: not right): worked out from the
    verdicts and numbers the run keeps when asked, not kept (8 bytes a student and part)."""

    def __init__(self, graded: ClassGrades, labels: Sequence[str]) -> None:
        self._graded, self._labels = graded, tuple(labels)
        self._codes = {label: graded.columns[label].verdict.words.index("correct")
                       if "correct" in graded.columns[label].verdict.words else -1 for label in labels}

    def of(self, label: str, students: Ints | slice) -> Floats:
        """The right numbers of ``students`` for the part."""
        numbers = self._graded.numbers[label][students]
        right = (self._graded.columns[label].verdict.codes[students] == self._codes[label]) & np.isfinite(numbers)
        return np.where(right, numbers, np.nan)

    def __getitem__(self, label: str) -> Floats:
        return self.of(label, slice(None))

    def __iter__(self) -> Iterator[str]:
        return iter(self._labels)

    def __len__(self) -> int:
        return len(self._labels)


class _Answers(NamedTuple):
    """The class's answers the check compares: per part label, the students whose answer was wrong, each
    student's number (NaN: none), the half-unit of the last typed digit of each wrong one in the sheet's
    unit, in the order of the wrong ones (inf: not a plain number, so no closeness can be read from it), the
    right ones' numbers (NaN: not right) and what each student typed; and each student's count of wrong
    parts."""

    wrong: Mapping[str, Ints]
    numbers: Mapping[str, Floats]
    steps: Mapping[str, Floats]
    right: _Right
    typed: Mapping[str, Texts]
    per_student: Ints
    read: dict[str, Floats]  # per part and student, the half-unit of the right answer, once read (NaN: not yet)
    answering: dict[str, npt.NDArray[np.bool_]]  # per part, :meth:`answered`, once worked out

    def step(self, label: str, owners: Ints) -> Floats:
        """The half-unit of the typed answers of ``owners``, each one of the part's wrong ones."""
        return self.steps[label][np.searchsorted(self.wrong[label], owners)]

    def centres(self, part: Bands, owners: Ints, partners: Ints) -> Floats:
        """Where each owner's answer's closeness to the partner's is measured from: the number the partner
        typed for the part, when it was right and typed with no fewer digits than the owner's (a copy typed
        as its source typed it is there exactly), else the partner's value. An angle's is taken within half a
        turn of the value."""
        values, typed = part.values[partners], self.right.of(part.label, partners)
        have = np.isfinite(typed)
        read = self.read.get(part.label)
        if read is None:
            read = self.read[part.label] = np.full(len(self.per_student), np.nan)  # NaN: not read (a step never is)
        asked = distinct(partners[have])
        asked = asked[np.isnan(read[asked])]
        read[asked] = halves(self.typed[part.label].take(asked), self.numbers[part.label][asked])
        half_units = np.where(have, read[partners], np.inf)
        return _turned(part, values, np.where(have & (half_units <= self.step(part.label, owners)), typed, values))

    def either(self, part: Bands, partners: Ints) -> tuple[Floats, Floats]:
        """The two centres :meth:`centres` chooses between, without reading how the right answers were typed:
        the number each partner typed when it was right (else their value), and their value."""
        values, typed = part.values[partners], self.right.of(part.label, partners)
        return _turned(part, values, np.where(np.isfinite(typed), typed, values)), values

    def answered(self, label: str) -> npt.NDArray[np.bool_]:
        """Per student, whether their answer to the part is one of the wrong ones (worked out once a part)."""
        found = self.answering.get(label)
        if found is None:
            found = self.answering[label] = np.zeros(len(self.per_student), dtype=bool)
            found[self.wrong[label]] = True
        return found


def check(graded: Graded | ClassGrades, block: int = PAIRS) -> Integrity:
    """The integrity check of a grading run (the key's numeric parts; symbolic ones are left out), its
    candidate pairs worked out about ``block`` at a time (the findings are the same whatever the block)."""
    graded = classwide(graded)
    matches, pieces, examined, wrong, matched = _search(graded, block)  # what the search held is let go
    pairs = Pairs.joined(pieces)
    del pieces
    return Integrity(matches, pairs.take(_ranked(pairs)), examined, graded.key.integrity_threshold, wrong, matched)


def _search(graded: ClassGrades, block: int) -> tuple[Matches, list[Pairs], int, int, int]:
    """The listed matches; the pairs, in pieces; the pairs examined; the wrong answers compared, and those that
    matched anyone."""
    key = graded.key
    students = len(key.students)
    parts: list[Bands] = []
    wrong: dict[str, Ints] = {}
    for label in key.labels:
        first = key.students[0].parts[label] if students else None
        if first is None or first.symbolic or label not in graded.numbers:
            continue
        values = np.fromiter(map(_number, key.part_entries(label, "value")), dtype=np.float64, count=students)
        part = bands(label, values, key.part_entries(label, "tolerance"), first.unit)
        numbers = graded.numbers[label]
        wrong[label] = np.flatnonzero(graded.columns[label].verdict.are("incorrect") & np.isfinite(numbers)
                                      & np.isfinite(values))
        parts.append(part)
    per_student = np.zeros(students, dtype=np.int64)
    for members in wrong.values():
        per_student[members] += 1
    texts = {label: column.submitted for label, column in graded.columns.items()}
    typed = {part.label: np.array(halves(texts[part.label].take(wrong[part.label]),
                                         graded.numbers[part.label][wrong[part.label]]), np.float64).reshape(-1)
             for part in parts}
    spread = Spread.of(np.concatenate([graded.numbers[p.label][wrong[p.label]] for p in parts] or [np.zeros(0)]),
                       np.concatenate([p.values[wrong[p.label]] for p in parts] or [np.zeros(0)]),
                       np.concatenate([wrong[p.label] for p in parts] or [np.zeros(0, np.int64)]), students)
    examined = int(np.count_nonzero(per_student >= 2)) * max(students - 1, 0)
    found = [holding(part, wrong[part.label], graded.numbers[part.label]) for part in parts]
    answers = _Answers(wrong, graded.numbers, typed, _Right(graded, list(wrong)), texts, per_student, {}, {})
    kept = _pairs(parts, answers, spread, found, examined, block)
    kept = kept.take(_ranked(kept))
    matches = _listed(parts, wrong, graded.numbers, found, kept)
    # Every listed match has its pair's figures.
    listed = distinct(matches.student.astype(np.int64) * students + matches.partner)
    known = np.sort(kept.student.astype(np.int64) * students + kept.partner)
    others = listed[~_among(listed, known)]
    del listed, known
    # The chances are counted up to the most wrong parts of any of these pairs' students, whatever the block.
    most = int(per_student[distinct(others // students)].max()) if len(others) else 0
    step = max(FIGURED, 1)
    more = [_figures(parts, answers, spread, others[start:start + step] // students,
                     others[start:start + step] % students, examined, most=most)
            for start in range(0, len(others), step)]
    return (matches, [kept, *more], examined, sum(len(members) for members in wrong.values()),
            sum(int(np.count_nonzero(counts)) for counts, _ in found))


def _turned(part: Bands, values: Floats, found: Floats) -> Floats:
    """An angle's ``found`` taken within half a turn of ``values`` (any other part's as they are)."""
    period = part.period
    return found if period is None else values + np.mod(found - values + period / 2, period) - period / 2


def _ranked(pairs: Pairs) -> Ints:
    """The order of the pairs, most suspicious first: by corrected chance, chance, student and partner (a sort
    of arrays, not of a million tuples)."""
    corrected, chance, student, partner = pairs.corrected, pairs.chance, pairs.student, pairs.partner
    if np.isnan(corrected).any() or np.isnan(chance).any():  # not ordered as Python orders them: none is NaN
        keys = list(zip(corrected.tolist(), chance.tolist(), student.tolist(), partner.tolist(), strict=True))
        return np.array(sorted(range(len(keys)), key=keys.__getitem__), np.int64)
    return np.lexsort((partner, student, chance, corrected))


def _among(keys: Ints, known: Ints) -> npt.NDArray[np.bool_]:
    """Whether each key is one of ``known`` (sorted)."""
    at = np.minimum(np.searchsorted(known, keys), max(len(known) - 1, 0))
    return np.asarray(known[at] == keys) if len(known) else np.zeros(len(keys), dtype=bool)


def _number(value: object) -> float:
    if type(value) is float:
        return value
    return float(value) if isinstance(value, float | int) and not isinstance(value, bool) else math.nan


def _pairs(parts: Sequence[Bands], answers: _Answers, spread: Spread,
           found: Sequence[tuple[Ints, list[tuple[Ints, Ints]]]], examined: int,
           block: int = PAIRS) -> Pairs:
    """Every pair with two or more matched parts whose corrected chance is below :data:`KEPT`.

    A pair needs as many matched parts as the fewest whose chance could be that small (:func:`_needed`); a
    partner that matches ``n`` of a student's parts is in the band search of at least one part other than
    the ``n - 1`` that matched the most students: the pairs of those searches are the candidates. Of them, only
    those the close search finds are formed (:mod:`grader.grade.integrity_close`: a pair whose every matched
    part is far from its centre cannot be kept), about ``block`` at a time, so the pairs formed grow with the
    class, not its square. The chances are counted up to as many wrong parts as the most of any candidate's
    student with two matched parts (:func:`_figures`'s ``most``), as one block of all candidates would."""
    wrong, students, per_student = answers.wrong, len(answers.per_student), answers.per_student
    needed = _needed(parts, answers, spread, found, examined)
    columns = [(wrong[part.label], found_counts) for part, (found_counts, _) in zip(parts, found, strict=True)]
    candidate = np.zeros((students, len(parts)), dtype=bool)
    ranks = np.zeros((students, len(parts)), dtype=np.int8)  # a class has at most a few dozen parts
    for rows in _row_blocks(students):
        counts = _laid_out(rows, columns, 0)  # per student and part, the students matched
        matched = np.count_nonzero(counts, axis=1)
        # Each part's rank among the student's, most students matched first: the needed - 1 first are not searched.
        rank = np.argsort(np.argsort(-counts, axis=1, kind="stable"), axis=1, kind="stable")
        ranks[rows] = rank
        candidate[rows] = ((counts > 0) & (matched >= needed[rows])[:, None] & (rank >= (needed[rows] - 1)[:, None])
                           )[:, :len(parts)]
    del columns
    ranges = [part_ranges for _, part_ranges in found]
    owners_in: npt.NDArray[np.bool_] = np.any(candidate, axis=1)
    searched = [np.flatnonzero((found_counts > 0) & owners_in[wrong[part.label]])
                for part, (found_counts, _) in zip(parts, found, strict=True)]
    kept: list[tuple[Ints, Ints, npt.NDArray[np.bool_]]] = []
    for owners, partners in close_pairs(parts, spread, wrong, answers.numbers, answers.right, ranges, searched,
                                        ranks, needed, examined, KEPT, block):
        hits = _hits(parts, answers, owners, partners)
        two = (hits & candidate[owners]).any(axis=1) & (hits.sum(axis=1) >= 2)
        if two.any():
            kept.append((owners[two], partners[two], hits[two]))
    if not kept:
        return Pairs.of(())
    owners = np.concatenate([owners for owners, _, _ in kept])
    partners = np.concatenate([partners for _, partners, _ in kept])
    hits = np.concatenate([hits for _, _, hits in kept])
    del kept
    most = _most(parts, answers, found, candidate, int(per_student[owners].max()), block)
    possible = np.concatenate([_possible(parts, answers, spread, owners[start:start + FIGURED],
                                         partners[start:start + FIGURED], hits[start:start + FIGURED], examined,
                                         KEPT) for start in range(0, len(owners), FIGURED)])
    owners, partners, hits = owners[possible], partners[possible], hits[possible]
    step = max(min(block, FIGURED), 1)
    return Pairs.joined([_figures(parts, answers, spread, owners[start:start + step], partners[start:start + step],
                                  examined, 2, KEPT, hits[start:start + step], most)
                         for start in range(0, len(owners), step)])


def _most(parts: Sequence[Bands], answers: _Answers, found: Sequence[tuple[Ints, list[tuple[Ints, Ints]]]],
          candidate: npt.NDArray[np.bool_], least: int, block: int) -> int:
    """The most wrong parts of any student with a candidate pair of two or more matched parts, at least
    ``least`` (such a student's): the students with more are searched whole, most wrong parts first, until one
    has such a pair (usually none has more, or the first does)."""
    wrong, per_student = answers.wrong, answers.per_student
    students = len(per_student)
    chosen, sizes = [], np.zeros(students, dtype=np.int64)
    for index, (part, (_, ranges)) in enumerate(zip(parts, found, strict=True)):
        members = wrong[part.label]
        chosen.append(np.flatnonzero(candidate[members, index] & (per_student[members] > least)))
        for starts, ends in ranges:
            sizes += np.bincount(members[chosen[-1]], minlength=students,
                                 weights=np.maximum(ends - starts, 0)[chosen[-1]]).astype(np.int64)
    searched = np.flatnonzero(sizes > 0)
    searched = searched[np.argsort(-per_student[searched], kind="stable")]
    for group in blocks(sizes[searched], block):
        inside = np.zeros(students, dtype=bool)
        inside[searched[group]] = True
        owners, partners = candidates(parts, wrong, answers.numbers, [ranges for _, ranges in found], chosen,
                                      inside)
        two = _hits(parts, answers, owners, partners).sum(axis=1) >= 2
        if two.any():
            return max(least, int(per_student[owners[two]].max()))
    return least


def _needed(parts: Sequence[Bands], answers: _Answers, spread: Spread,
            found: Sequence[tuple[Ints, list[tuple[Ints, Ints]]]], examined: int) -> Ints:
    """Per student, the fewest matched parts (at least 2) whose corrected chance could be under :data:`KEPT`
    (more than their wrong parts: none could). ``k`` matches have a chance of at least the product of the
    ``k`` least of their parts' chances (:func:`_least`), and the correction is at least ``examined``."""
    students = len(answers.per_student)
    columns = [(answers.wrong[part.label], _least(part, spread, answers.wrong[part.label],
                                                  answers.numbers[part.label][answers.wrong[part.label]],
                                                  answers.steps[part.label], ranges))
               for part, (_, ranges) in zip(parts, found, strict=True)]
    needed = np.zeros(students, dtype=np.int64)
    for rows in _row_blocks(students):
        least = _laid_out(rows, columns, np.inf)
        # log 0 = -inf (a part no chance bounds) then log inf (a part that matches nobody) make NaN: not possible.
        with np.errstate(divide="ignore", invalid="ignore"):
            bound = math.log(max(examined, 1)) + np.cumsum(np.log(np.sort(least, axis=1)), axis=1)
        possible = ((bound < math.log(KEPT)) | (KEPT > 1)) & (np.arange(least.shape[1]) >= 1)  # > 1: every pair
        needed[rows] = np.where(possible.any(axis=1), np.argmax(possible, axis=1) + 1, least.shape[1] + 1)
    return needed


def _row_blocks(students: int) -> Iterator[slice]:
    """The students in runs of :data:`ROWS`.

    >>> [(rows.start, rows.stop) for rows in _row_blocks(ROWS + 1)] == [(0, ROWS), (ROWS, ROWS + 1)]
    True
    """
    return (slice(start, min(start + ROWS, students)) for start in range(0, students, ROWS))


def _laid_out(rows: slice, columns: Sequence[tuple[Ints, npt.NDArray[Any]]], fill: float) -> npt.NDArray[Any]:
    """Per student of ``rows`` (a row) and part (a column; one column of ``fill`` when there are no parts), the
    part's entry of that student (``fill``: none); ``columns``: per part, its students (sorted) and their
    entries.

    >>> _laid_out(slice(1, 3), [(np.array([0, 2]), np.array([5.0, 6.0]))], np.inf).tolist()
    [[inf], [6.0]]
    """
    dtype = np.result_type(*(entries.dtype for _, entries in columns)) if columns else np.float64
    found = np.full((rows.stop - rows.start, max(len(columns), 1)), fill, dtype=dtype)
    for index, (members, entries) in enumerate(columns):
        first, last = np.searchsorted(members, (rows.start, rows.stop))
        found[members[first:last] - rows.start, index] = entries[first:last]
    return found


def _least(part: Bands, spread: Spread, owners: Ints, numbers: Floats, steps: Floats,
           ranges: Sequence[tuple[Ints, Ints]]) -> Floats:
    """Per wrong answer, at most the chance (:func:`_chance`) of the answer in the band of any student whose
    band may hold it (the search's range: inf where it is empty), however close the pair's matches are.

    The band narrowed to ``(λ + 1) h`` around the partner's value holds the answer with ``h`` to spare, or is
    the whole band, which holds it with at least half its width to spare on one side: either way it holds
    ``[a - η, a]`` or ``[a, a + η]`` with ``η = min(h, the least reach in the range)``, so the related kind's
    chance is at least its mass over the lighter of the two (halved against the grid's rounding); the
    unrelated kind's is at least the least of ``c`` and ``h c / reach`` in the range."""
    order = part.order
    chance, reach = part.chance[order], part.reach[order]
    with np.errstate(divide="ignore", invalid="ignore"):
        per_width = np.where(reach > 0, chance / reach, np.inf)
    least_chance, least_width, least_reach = (np.full(len(owners), np.inf) for _ in range(3))
    for starts, ends in ranges:
        least_chance = np.minimum(least_chance, range_least(chance, starts, ends))
        least_width = np.minimum(least_width, range_least(per_width, starts, ends))
        least_reach = np.minimum(least_reach, range_least(reach, starts, ends))
    with np.errstate(invalid="ignore"):
        unrelated = np.nan_to_num(np.minimum(least_chance, steps * least_width), nan=0.0, posinf=0.0)
    related = np.zeros(len(owners))
    if part.period is None:
        spread_out = np.minimum(steps, least_reach)
        inside = np.isfinite(spread_out)
        own, number, width = part.values[owners][inside], numbers[inside], spread_out[inside]
        related[inside] = 0.5 * np.minimum(spread.chance(own, number - width, number, owners[inside]),
                                           spread.chance(own, number, number + width, owners[inside]))
    found = (1 - UNRELATED) * related + UNRELATED * unrelated
    return np.where(np.isfinite(least_reach), found, np.inf)


def _hits(parts: Sequence[Bands], answers: _Answers, owners: Ints, partners: Ints) -> npt.NDArray[np.bool_]:
    """Per pair (a row) and part (a column), whether the owner's wrong answer is in the partner's band."""
    hits = np.zeros((len(owners), len(parts)), dtype=bool)
    for index, part in enumerate(parts):
        rows = np.flatnonzero(answers.answered(part.label)[owners])
        hits[rows, index] = accepts(part, owners[rows], partners[rows], answers.numbers[part.label])
    return hits


def _figures(parts: Sequence[Bands], answers: _Answers, spread: Spread, owners: Ints, partners: Ints,
             examined: int, least: int = 0, below: float = math.inf, hits: npt.NDArray[np.bool_] | None = None,
             most: int | None = None) -> Pairs:
    """Each pair's matched parts and chances; only the pairs with ``least`` matched parts or more and a
    corrected chance under ``below``. For ``j`` from 2 to the matches (1 for a pair of one match): the chance
    that ``j`` or more of the owner's wrong parts land by accident as close to the partner's values as the
    pair's ``j`` closest matches, closeness counted in half-units of the owner's typed answers (the
    least close of those ``j`` sets it for every part); the pair's chance is the least of these. ``hits``:
    :func:`_hits` of the pairs, if worked out already; ``most``: the wrong parts the chances are counted up to
    (:func:`_tails`), if not the most of the pairs kept."""
    per_student = answers.per_student
    hits = _hits(parts, answers, owners, partners) if hits is None else hits
    matched = hits.sum(axis=1)
    kept = matched >= least  # the chances are worked out only for the pairs that could be kept
    owners, partners, hits, matched = owners[kept], partners[kept], hits[kept], matched[kept]
    units = np.full(hits.shape, np.inf)
    for index, part in enumerate(parts):
        rows = np.flatnonzero(hits[:, index])
        units[rows, index] = _closeness(part, answers, owners[rows], partners[rows])
    ordered = np.sort(units, axis=1)
    chances, counted, closeness = np.ones(len(owners)), matched.copy(), np.full(len(owners), np.inf)
    for closest in range(1, int(matched.max()) + 1 if len(matched) else 1):
        rows = np.flatnonzero((matched >= closest) & ((closest >= 2) | (matched == 1)))
        tails = _tails(parts, answers, spread, owners[rows], partners[rows], ordered[rows, closest - 1])
        tails = tails[:, min(closest, tails.shape[1] - 1)]
        better = tails < chances[rows]
        chances[rows[better]], counted[rows[better]] = tails[better], closest
        closeness[rows[better]] = ordered[rows[better], closest - 1]
    # The closeness and the number of matches counted were read off the answers: paid for over every number
    # ``j`` a pair could be counted with, each at most the chance of ``j`` matches anywhere in the bands.
    anywhere = _tails(parts, answers, spread, owners, partners, np.full(len(owners), np.inf), most)
    first = np.where(matched >= 2, 2, 1)
    counts = np.arange(anywhere.shape[1])
    paid = np.where(counts >= first[:, None], np.minimum(chances[:, None], anywhere), 0.0).sum(axis=1)
    corrected = np.minimum(np.maximum(paid, chances) * max(examined, 1), 1.0)
    kept = corrected < below
    owners, partners, hits, chances = owners[kept], partners[kept], hits[kept], chances[kept]
    corrected, counted, closeness = corrected[kept], counted[kept], closeness[kept]
    # The matched parts' labels, worked out once per pattern of parts (a class has a few hundred patterns).
    patterns = hits.astype(np.int64) @ (np.int64(1) << np.arange(len(parts), dtype=np.int64))
    table = distinct(patterns)
    named = tuple(tuple(part.label for index, part in enumerate(parts) if pattern >> index & 1)
                  for pattern in table.tolist())
    return Pairs(named, owners.astype(np.int32), partners.astype(np.int32),
                 np.searchsorted(table, patterns).astype(np.int32), per_student[owners].astype(np.int32), chances,
                 corrected, counted.astype(np.int32), closeness)


def _closeness(part: Bands, answers: _Answers, owners: Ints, partners: Ints,
               centres: Floats | None = None) -> Floats:
    """How close each owner's matched answer to the part is to the partner's (:meth:`_Answers.centres`), in
    half-units of the owner's typed answer."""
    centres = answers.centres(part, owners, partners) if centres is None else centres
    distance = errors(answers.numbers[part.label][owners], centres,
                      angle_unit=part.unit if part.period is not None else None)[0]
    # inf / inf (a number typed as arithmetic) is NaN: such a match claims no closeness (0 sets none).
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.nan_to_num(distance / answers.step(part.label, owners), nan=0.0, posinf=np.inf)


def _possible(parts: Sequence[Bands], answers: _Answers, spread: Spread, owners: Ints, partners: Ints,
              hits: npt.NDArray[np.bool_], examined: int, below: float) -> npt.NDArray[np.bool_]:
    """Whether each pair's corrected chance could be under ``below``, by :func:`_at_least`, loosened by
    :data:`~grader.grade.integrity_close.MARGIN` against rounding (every pair, when ``below`` is over 1: a
    corrected chance is at most 1)."""
    if below > 1:
        return np.ones(len(owners), dtype=bool)
    # Not "under": a bound that came out NaN lets nothing go.
    return np.asarray(~(_at_least(parts, answers, spread, owners, partners, hits, examined)
                        >= math.log(MARGIN * below)))


def _at_least(parts: Sequence[Bands], answers: _Answers, spread: Spread, owners: Ints, partners: Ints,
              hits: npt.NDArray[np.bool_], examined: int) -> Floats:
    """The log of a bound from below of each pair's corrected chance before it is capped at 1, far cheaper
    than :func:`_figures` (it does not read how anyone's answers were typed). The chance of ``j`` or more of
    the owner's wrong parts landing is at least that of the ``j`` matched parts :func:`_figures` counts all
    landing, each within the closeness of the least close of them, so at least the product of every matched
    part's chance within its own closeness (:func:`_chance` ``at_least``: a chance grows with the closeness),
    from whichever centre gives the less; ``examined`` times that is at most the corrected chance."""
    logs = np.full(len(owners), math.log(max(examined, 1)))
    for index, part in enumerate(parts):
        rows = np.flatnonzero(hits[:, index])
        who, partner = owners[rows], partners[rows]
        steps = answers.step(part.label, who)
        chance = np.minimum(*(_chance(part, spread, who, partner, _closeness(part, answers, who, partner, centres),
                                      steps, centres, at_least=True) for centres in answers.either(part, partner)))
        with np.errstate(divide="ignore"):
            logs[rows] += np.log(np.minimum(chance, 1.0))
    return logs


def _tails(parts: Sequence[Bands], answers: _Answers, spread: Spread, owners: Ints, partners: Ints,
           closeness: Floats, most: int | None = None) -> Floats:
    """Per pair (a row), the chance that ``j`` (a column, up to ``most``: by default the most wrong parts of
    the owners) or more of the owner's wrong parts land within ``closeness`` half-units of the partner's
    (:func:`_chance`; inf: anywhere in the bands): the tails of the Poisson binomial distribution of the
    count, built a part at a time."""
    count = len(owners)
    if most is None:
        most = int(answers.per_student[owners].max()) if count else 0
    distribution = np.zeros((count, most + 1))
    distribution[:, 0] = 1.0
    for part in parts:
        rows = np.flatnonzero(answers.answered(part.label)[owners])
        if not len(rows):
            continue
        chance = _chance(part, spread, owners[rows], partners[rows], closeness[rows],
                         answers.step(part.label, owners[rows]),
                         answers.centres(part, owners[rows], partners[rows]))[:, None]
        shifted = np.zeros((len(rows), most + 1))
        shifted[:, 1:] = distribution[rows, :-1]
        distribution[rows] = distribution[rows] * (1 - chance) + shifted * chance
    return np.asarray(np.minimum(np.cumsum(distribution[:, ::-1], axis=1)[:, ::-1], 1.0))


def _chance(part: Bands, spread: Spread, owners: Ints, partners: Ints, closeness: Floats, steps: Floats,
            centres: Floats, at_least: bool = False) -> Floats:
    """The chance that each owner's wrong answer to the part lands by accident in the partner's band and
    within ``closeness`` half-units ``steps`` of the owner's typed answer from ``centres``
    (:meth:`_Answers.centres`), widened by one more (a number rounded as typed is within a half-unit of where
    it was headed): over the band narrowed to that (:mod:`grader.grade.integrity_chance`; an angle's answers
    are all taken as unrelated to their own, and its chance is the narrowed share of the band's). ``at_least``:
    a bound from below of it that no wider closeness goes under (:meth:`Spread.chance`'s)."""
    middle, reach = part.values[partners], part.reach[partners]
    with np.errstate(invalid="ignore"):
        half = np.nan_to_num((closeness + 1) * steps, nan=np.inf)
    low, high = np.maximum(centres - half, middle - reach), np.minimum(centres + half, middle + reach)
    with np.errstate(divide="ignore", invalid="ignore"):
        share = np.where(reach > 0, np.clip((high - low) / (2 * reach), 0.0, 1.0), 1.0)
    unrelated = np.nan_to_num(part.chance[partners], nan=0.0) * share
    if part.period is not None:
        return np.asarray(unrelated)
    related = spread.chance(part.values[owners], low, np.maximum(low, high), owners, at_least)
    return np.asarray((1 - UNRELATED) * related + UNRELATED * unrelated)


def _listed(parts: Sequence[Bands], wrong: Mapping[str, Ints], numbers: Mapping[str, Floats],
            found: Sequence[tuple[Ints, list[tuple[Ints, Ints]]]], ranked: Pairs) -> Matches:
    """Each wrong answer that matches anyone, with up to :data:`LISTED` of the students it matches: the
    partners of its pairs (``ranked``: most suspicious first, :func:`_ranked`) first, then the nearest values
    (by distance over the band); by student, then label."""
    labels = [part.label for part in parts]
    columns: list[tuple[Small, Small, Small, Floats]] = []  # per part: students, partners, counts, values
    for part, (counts, _) in zip(parts, found, strict=True):
        some = np.flatnonzero(counts > 0)
        answering = wrong[part.label][some]  # sorted, as the wrong answers are
        # The partners of the answers' pairs, each answer's in their order, then their nearest values.
        having = np.array([part.label in named for named in ranked.patterns], bool)[ranked.pattern]
        rows = np.flatnonzero(having)
        at = np.minimum(np.searchsorted(answering, ranked.student[rows]), max(len(answering) - 1, 0))
        mine = np.asarray(answering[at] == ranked.student[rows]) if len(answering) else np.zeros(len(rows), bool)
        rows, at = rows[mine], at[mine]
        by_answer = np.argsort(at, kind="stable")
        first, first_partner = at[by_answer], ranked.partner[rows[by_answer]].astype(np.int64)
        place = _places(first)
        first, first_partner, place = first[place < LISTED], first_partner[place < LISTED], place[place < LISTED]
        closest = nearest(part, answering, numbers[part.label], LISTED)
        near = np.repeat(np.arange(len(answering)), LISTED)
        near_partner = closest.ravel()
        chosen = np.sort(first * len(part.values) + first_partner)
        fresh = (near_partner >= 0) & ~_among(near * len(part.values) + near_partner, chosen)
        every = np.concatenate([first, near[fresh]])
        order = np.lexsort((np.concatenate([place, LISTED + np.tile(np.arange(LISTED), len(answering))[fresh]]),
                            every))
        every, partners = every[order], np.concatenate([first_partner, near_partner[fresh]])[order]
        shown = _places(every) < LISTED
        every, partners = every[shown], partners[shown]
        columns.append((answering[every].astype(np.int32), partners.astype(np.int32),
                        counts[some][every].astype(np.int32), part.values[partners]))
    # By student, then label (as Python orders them), each answer's in the order chosen (the sort is stable).
    in_words: Ints = (np.argsort(np.argsort(np.array(labels, dtype=object), kind="stable"), kind="stable") if labels
                      else np.zeros(0, np.int64))
    part_of = np.concatenate([np.full(len(column[0]), in_words[index], np.int64)
                              for index, column in enumerate(columns)] or [np.zeros(0, np.int64)])
    order = np.argsort(np.concatenate([column[0] for column in columns] or [np.zeros(0, np.int32)]).astype(np.int64)
                       * max(len(labels), 1) + part_of, kind="stable")
    del part_of
    label = np.concatenate([np.full(len(column[0]), index, np.int32) for index, column in enumerate(columns)]
                           or [np.zeros(0, np.int32)])[order]
    student, partner, matched, value = (
        np.concatenate([column[at] for column in columns] or [np.zeros(0, kind)])[order]
        for at, kind in enumerate((np.int32, np.int32, np.int32, np.float64)))
    return Matches(tuple(labels), student, label, partner, value, matched)


def _places(groups: Ints) -> Ints:
    """Each entry's place in its run of equal ``groups`` (sorted): 0, 1, ...

    >>> _places(np.array([0, 0, 3, 5, 5, 5])).tolist()
    [0, 1, 0, 0, 1, 2]
    """
    starts = np.flatnonzero(np.r_[True, groups[1:] != groups[:-1]]) if len(groups) else np.zeros(0, np.int64)
    return np.arange(len(groups)) - np.repeat(starts, np.diff(np.r_[starts, len(groups)]))
