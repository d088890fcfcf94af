"""What the integrity check (:mod:`grader.grade.integrity`) found, kept in columns: a class of a million students
lists millions of matches and pairs, about 200 and 400 bytes each as records, 24 and 40 in columns. A match or
a pair is read as a record (:class:`Match`, :class:`Pair`) when it is written out.

>>> found = Integrity.of((Match(0, "1a", 2, 6.0, 1),), (Pair(0, 2, ("1a", "1b"), 2, 1e-5, 0.001),), 42, 0.01, 2, 1)
>>> found.pair(0, 2).labels, found.flagged == found.pairs, found.pair(2, 0)
(('1a', '1b'), True, None)
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
import numpy.typing as npt

from grader.grade.class_grades import Coder

Floats = npt.NDArray[np.float64]
Ints = npt.NDArray[np.int64]
Small = npt.NDArray[np.int32]  # a student's index, a count, a label's number: well under 2**31


class Match(NamedTuple):
    """A wrong answer that another student's key accepts: who answered (index in the key), the part, whose
    variant it matches (index), that student's value, and how many students' values it matches in all."""

    student: int
    label: str
    partner: int
    value: float
    matches: int


class Pair(NamedTuple):
    """A student's wrong answers against another student's key: the parts matched, how many of the first
    student's parts were wrong (and so could match), the chance of so many matches by accident, and that
    chance corrected for the pairs examined; and what the chance counted: the closest matches, how many, and
    how close the least close of them is, in half-units of the student's typed answers (inf: not read)."""

    student: int
    partner: int
    labels: tuple[str, ...]
    wrong: int
    chance: float
    corrected: float
    closest: int = 0
    closeness: float = math.inf


@dataclass(frozen=True, eq=False)
class Matches:
    """Matches (:class:`Match`) as columns, the part a number in ``labels``."""

    labels: tuple[str, ...]
    student: Small
    label: Small
    partner: Small
    value: Floats
    matches: Small

    @classmethod
    def of(cls, records: Sequence[Match]) -> Matches:
        """The columns of ``records``."""
        labels: Coder[str] = Coder()
        label = labels.codes([match.label for match in records]).astype(np.int32)
        return cls(tuple(labels), np.array([match.student for match in records], np.int32), label,
                   np.array([match.partner for match in records], np.int32),
                   np.array([match.value for match in records], np.float64),
                   np.array([match.matches for match in records], np.int32))

    def __len__(self) -> int:
        return len(self.student)

    def records(self, start: int = 0, stop: int | None = None) -> list[Match]:
        """The matches ``start`` to ``stop`` as records."""
        rows = slice(start, stop)
        return [Match(student, self.labels[label], partner, value, matches) for student, label, partner, value, matches
                in zip(self.student[rows].tolist(), self.label[rows].tolist(), self.partner[rows].tolist(),
                       self.value[rows].tolist(), self.matches[rows].tolist(), strict=True)]


@dataclass(frozen=True, eq=False)
class Pairs:
    """Pairs (:class:`Pair`) as columns, in their order; the parts matched a number in ``patterns`` (each
    pattern's labels)."""

    patterns: tuple[tuple[str, ...], ...]
    student: Small
    partner: Small
    pattern: Small
    wrong: Small
    chance: Floats
    corrected: Floats
    closest: Small
    closeness: Floats

    @classmethod
    def of(cls, records: Sequence[Pair]) -> Pairs:
        """The columns of ``records``."""
        patterns: Coder[tuple[str, ...]] = Coder()
        pattern = patterns.codes([pair.labels for pair in records]).astype(np.int32)
        columns = {name: np.array([getattr(pair, name) for pair in records], _COLUMNS[name])
                   for name in _COLUMNS if name != "pattern"}
        return cls(tuple(patterns), pattern=pattern, **columns)

    @classmethod
    def joined(cls, pieces: Sequence[Pairs]) -> Pairs:
        """The pairs of ``pieces``, one after another."""
        patterns: dict[tuple[str, ...], int] = {}
        numbers = [np.array([patterns.setdefault(labels, len(patterns)) for labels in piece.patterns], np.int32)
                   for piece in pieces]
        columns = {name: np.concatenate([getattr(piece, name) for piece in pieces] or [np.zeros(0, kind)])
                   for name, kind in _COLUMNS.items() if name != "pattern"}
        pattern = np.concatenate([number[piece.pattern] for number, piece in zip(numbers, pieces, strict=True)]
                                 or [np.zeros(0, np.int32)])
        return cls(tuple(patterns), pattern=pattern, **columns)

    def take(self, rows: Ints) -> Pairs:
        """The pairs ``rows``, in their order."""
        return Pairs(self.patterns, **{name: getattr(self, name)[rows] for name in _COLUMNS})

    def __len__(self) -> int:
        return len(self.student)

    def records(self, rows: Sequence[int] | Ints | slice = slice(None)) -> list[Pair]:
        """The pairs ``rows`` (positions, or a slice) as records."""
        patterns = self.patterns
        return [Pair(student, partner, patterns[pattern], wrong, chance, corrected, closest, closeness)
                for student, partner, pattern, wrong, chance, corrected, closest, closeness in zip(
                    self.student[rows].tolist(), self.partner[rows].tolist(), self.pattern[rows].tolist(),
                    self.wrong[rows].tolist(), self.chance[rows].tolist(), self.corrected[rows].tolist(),
                    self.closest[rows].tolist(), self.closeness[rows].tolist(), strict=True)]

    def parts(self) -> Small:
        """How many parts each pair matched in."""
        return np.array([len(labels) for labels in self.patterns], np.int32)[self.pattern]

    def flagged(self, threshold: float) -> npt.NDArray[np.bool_]:
        """Which pairs are flagged: two or more matched parts and a corrected chance at most ``threshold``."""
        return np.asarray((self.parts() >= 2) & (self.corrected <= threshold))

    def find(self, students: Ints | Small, partners: Ints | Small) -> Ints:
        """The position of each pair (``students[i]``, ``partners[i]``) (-1: not listed)."""
        keys, order = self._sorted
        wanted = students.astype(np.int64) << 32 | partners.astype(np.int64)
        at = np.minimum(np.searchsorted(keys, wanted), max(len(keys) - 1, 0))
        if not len(keys):
            return np.full(len(wanted), -1, np.int64)
        return np.where(keys[at] == wanted, order[at], -1)

    @functools.cached_property
    def _sorted(self) -> tuple[Ints, Ints]:
        """The pairs' keys (student and partner), sorted, and their positions."""
        keys = self.student.astype(np.int64) << 32 | self.partner.astype(np.int64)
        order = np.argsort(keys, kind="stable")
        return keys[order], order


_COLUMNS = {"student": np.int32, "partner": np.int32, "pattern": np.int32, "wrong": np.int32, "chance": np.float64,
            "corrected": np.float64, "closest": np.int32, "closeness": np.float64}


@dataclass(frozen=True, eq=False)
class Integrity:
    """What the check found: each wrong answer's listed matches (``listed``), every pair with two or more
    matched parts (and the pairs of the listed matches), most suspicious first (``ranked``); the number of
    pairs examined; the threshold; and how many wrong answers were compared (and matched anyone)."""

    listed: Matches
    ranked: Pairs
    examined: int
    threshold: float
    wrong: int
    matched: int

    @classmethod
    def of(cls, matches: Sequence[Match], pairs: Sequence[Pair], examined: int, threshold: float, wrong: int,
           matched: int) -> Integrity:
        """The check's findings from records (``pairs``: most suspicious first)."""
        return cls(Matches.of(matches), Pairs.of(pairs), examined, threshold, wrong, matched)

    def __eq__(self, other: object) -> bool:
        """The same findings, record by record (as two checks of a small class are compared)."""
        if not isinstance(other, Integrity):
            return NotImplemented
        return (self.matches, self.pairs, self.examined, self.threshold, self.wrong, self.matched) == (
            other.matches, other.pairs, other.examined, other.threshold, other.wrong, other.matched)

    __hash__ = None  # type: ignore[assignment]

    @property
    def matches(self) -> tuple[Match, ...]:
        """The listed matches as records (a class's worth of them: for a small class or a test)."""
        return tuple(self.listed.records())

    @property
    def pairs(self) -> tuple[Pair, ...]:
        """The pairs as records, most suspicious first (for a small class or a test)."""
        return tuple(self.ranked.records())

    @property
    def flagged(self) -> tuple[Pair, ...]:
        """The pairs whose corrected chance is at most the threshold."""
        return tuple(self.ranked.records(np.flatnonzero(self.ranked.flagged(self.threshold))))

    def pair(self, student: int, partner: int) -> Pair | None:
        """The pair of two students (by index), if it is listed."""
        (at,) = self.ranked.find(np.array([student]), np.array([partner])).tolist()
        return None if at < 0 else self.ranked.records([at])[0]
