"""A class's verdicts as the reports over the whole class read them (:class:`ClassGrades`), kept in columns.

Grading takes a class a piece of students at a time (:func:`grader.grade.grading.graded_pieces`): a piece's
verdict rows (about 0.5 KiB a cell: the sentence, the source, the expected value's text) are written to
``details.csv`` and let go, and only what ``grades.csv``, ``canvas.csv``, ``integrity.csv`` and the class report
read is kept, a part's cells in a few arrays (:class:`Outcomes`): the verdicts as numbers, the credit and points,
what was typed (all of a part's texts in one string), the tolerance and diagnosis as numbers, and the feedback and
what was read only of the cells that need them. About 30 bytes a cell beside what was typed (88 MiB for 1.5 million).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from operator import attrgetter
from typing import Generic, TypeVar

import numpy as np
import numpy.typing as npt

from grader.base.heap import hand_back
from grader.grade.diagnosis import Physics
from grader.grade.grading import PIECE, VERDICTS, Graded, LateWork, Row, graded_pieces, late_notes
from grader.grade.key import Key
from grader.grade.latest import Answer
from grader.grade.submissions import RowProblem, Submissions
from grader.grade.texts import Texts

Floats = npt.NDArray[np.float64]
Ints = npt.NDArray[np.int64]
Word = TypeVar("Word")


class Coder(dict[Word, int], Generic[Word]):
    """Numbers for the few distinct values of a column (a verdict, a tolerance in words), shared by its pieces."""

    def codes(self, values: Sequence[Word]) -> np.ndarray:
        """Each value's number (new values numbered as they come): 2 bytes each, or 4 past 65,536 values."""
        for value in dict.fromkeys(values):
            self.setdefault(value, len(self))
        return np.fromiter(map(self.__getitem__, values), np.uint16 if len(self) <= 1 << 16 else np.int32,
                           len(values))

    def coded(self, pieces: Sequence[Coded[Word]]) -> Coded[Word]:
        """The pieces' columns (coded by this coder), one after another."""
        return Coded(np.concatenate([piece.codes for piece in pieces] or [np.zeros(0, np.uint16)]), tuple(self))


@dataclass(frozen=True)
class Coded(Generic[Word]):
    """A column of a few distinct values: each cell's number (``codes``) in ``words``."""

    codes: np.ndarray
    words: tuple[Word, ...] = ()

    def __len__(self) -> int:
        return len(self.codes)

    def are(self, word: Word) -> npt.NDArray[np.bool_]:
        """Which cells are ``word``."""
        return self.codes == self.words.index(word) if word in self.words else np.zeros(len(self), bool)

    def counted(self) -> dict[Word, int]:
        """How many cells of each value there are (values with none left out)."""
        return {self.words[code]: count for code, count in enumerate(np.bincount(
            self.codes, minlength=len(self.words)).tolist()) if count}

    def values(self, cells: npt.NDArray[np.bool_] | None = None) -> list[Word]:
        """Each cell's value (of ``cells`` only, when given), in order."""
        return list(map(self.words.__getitem__, (self.codes if cells is None else self.codes[cells]).tolist()))


def _floats(coded: Coded[int]) -> Floats:
    """A column of numbers coded by their bits (:func:`_bits`), as numbers."""
    numbers: Floats = np.array(coded.words or [0], np.int64).view(np.float64)
    found: Floats = numbers[coded.codes]
    return found


def _bits(values: npt.NDArray[np.float64]) -> list[int]:
    """Each number's bits: numbers coded so are told apart exactly (0.0 from -0.0)."""
    return values.view(np.int64).tolist()  # type: ignore[no-any-return]


@dataclass(frozen=True)
class Some:
    """The texts of some cells of a column: ``cells`` (in order) and theirs."""

    cells: npt.NDArray[np.int32]
    texts: Texts

    def take(self, indices: Sequence[int] | Ints) -> list[str | None]:
        """The texts of cells ``indices``, each one of :attr:`cells`."""
        at = np.searchsorted(self.cells, np.asarray(indices, np.int64))
        if len(at) and (at.max() >= len(self.cells) or (self.cells[at] != indices).any()):
            raise KeyError("a cell without its text kept")
        return self.texts.take(at)


@dataclass(frozen=True)
class Outcomes:
    """One part's verdicts for the class, a cell per student of the key in its order: the kind, credit and
    points, what was typed, the tolerance in words and the diagnosis; what was read, for the ``incorrect`` cells;
    the feedback, for the ``invalid`` ones. About 30 bytes a cell."""

    verdict: Coded[str]
    credit: Coded[int]  # the numbers' bits
    points: Coded[int]
    submitted: Texts
    tolerance: Coded[str]
    diagnosis: Coded[str]
    parsed: Some  # of the incorrect cells
    feedback: Some  # of the invalid cells

    def __len__(self) -> int:
        return len(self.verdict)

    def worth(self) -> Floats:
        """Each cell's points."""
        return _floats(self.points)

    def scores(self) -> Floats:
        """Each cell's points earned: its credit times its points."""
        return _floats(self.credit) * _floats(self.points)


class _Part:
    """The numbers shared by a part's pieces as they are kept (:class:`Outcomes` of each piece, joined at the end)."""

    def __init__(self) -> None:
        self.kinds: Coder[str] = Coder({kind: index for index, kind in enumerate(VERDICTS)})
        self.credits: Coder[int] = Coder()
        self.points: Coder[int] = Coder()
        self.tolerances: Coder[str] = Coder()
        self.diagnoses: Coder[str] = Coder({"": 0})
        self.pieces: list[Outcomes] = []
        self.start = 0

    def add(self, rows: Sequence[Row]) -> None:
        count = len(rows)
        codes = self.kinds.codes(list(map(_VERDICT, rows)))
        incorrect = np.flatnonzero(codes == self.kinds["incorrect"])
        invalid = np.flatnonzero(codes == self.kinds["invalid"])
        self.pieces.append(Outcomes(
            Coded(codes), Coded(self.credits.codes(_bits(np.fromiter(map(_CREDIT, rows), np.float64, count)))),
            Coded(self.points.codes(_bits(np.fromiter(map(_POINTS, rows), np.float64, count)))),
            Texts.of(list(map(_SUBMITTED, rows))), Coded(self.tolerances.codes(list(map(_TOLERANCE, rows)))),
            Coded(self.diagnoses.codes(list(map(_DIAGNOSIS, rows)))),
            Some((incorrect + self.start).astype(np.int32),
                 Texts.of([rows[index].parsed for index in incorrect.tolist()])),
            Some((invalid + self.start).astype(np.int32),
                 Texts.of([rows[index].feedback for index in invalid.tolist()]))))
        self.start += count

    def joined(self) -> Outcomes:
        pieces = self.pieces
        return Outcomes(self.kinds.coded([piece.verdict for piece in pieces]),
                        self.credits.coded([piece.credit for piece in pieces]),
                        self.points.coded([piece.points for piece in pieces]),
                        Texts.joined([piece.submitted for piece in pieces]),
                        self.tolerances.coded([piece.tolerance for piece in pieces]),
                        self.diagnoses.coded([piece.diagnosis for piece in pieces]),
                        _some([piece.parsed for piece in pieces]), _some([piece.feedback for piece in pieces]))


_VERDICT, _CREDIT, _POINTS = attrgetter("verdict"), attrgetter("credit"), attrgetter("points")
_SUBMITTED, _TOLERANCE, _DIAGNOSIS = attrgetter("submitted"), attrgetter("tolerance"), attrgetter("diagnosis")


def _some(pieces: Sequence[Some]) -> Some:
    return Some(np.concatenate([piece.cells for piece in pieces] or [np.zeros(0, np.int32)]),
                Texts.joined([piece.texts for piece in pieces]))


@dataclass(frozen=True)
class Lateness:
    """How late a class's answers came: per student of the key, in its order, the minutes late of their latest
    answer that counts (None: no answer whose lateness is known); per student id, the points the late policy took
    (only those who lost any); and how many answers' lateness is not known."""

    latest: Sequence[int | None]
    deductions: Mapping[str, float]
    unknown: int


@dataclass(frozen=True)
class ClassGrades:
    """A grading run as the reports over the whole class read it: per part label, in the key's order, the
    class's :class:`Outcomes`; every row not graded; the columns no rule claimed; notes; what each diagnosed
    mistake says (by label and its id); how late the answers were (None: the key has no due time); and per part
    label the number each student's answer was read as (NaN: none), as :class:`~grader.grade.grading.Graded`
    has them."""

    key: Key
    columns: Mapping[str, Outcomes]
    problems: tuple[RowProblem, ...]
    ignored_columns: tuple[str, ...]
    notes: tuple[str, ...]
    mistakes: Mapping[tuple[str, str], str] = field(default_factory=dict)
    late: Lateness | None = None
    numbers: Mapping[str, Floats] = field(default_factory=dict)

    @property
    def deductions(self) -> Mapping[str, float]:
        """Per student id, the points the late policy took (only those who lost any)."""
        return {} if self.late is None else self.late.deductions

    @classmethod
    def of(cls, graded: Graded) -> ClassGrades:
        """The class's verdicts of one grading run (all of its students graded together)."""
        kept = Keeping(graded.key)
        kept.add(graded)
        late = late_notes(graded.late.unknown if graded.late else 0)  # the last of its notes, made again here
        return kept.joined(graded.problems[:len(graded.problems) - len(graded.first_given)], graded.ignored_columns,
                           graded.notes[:len(graded.notes) - len(late)])


def grade_class(key: Key, read: Callable[[], Submissions], physics: Physics,
                each: Callable[[Graded], object] | None = None, size: int = PIECE) -> ClassGrades:
    """Grade every student of ``key`` against the submissions ``read`` gives (called once here, so that nothing
    else holds them: a piece's answers are let go once it is graded), ``size`` students at a time
    (:func:`~grader.grade.grading.graded_pieces`); each piece is handed to ``each`` (which writes its rows), then
    let go but for what the class's reports read."""
    hand_back()  # what reading the key freed
    submissions = read()
    hand_back()  # what reading the files freed (their text)
    problems, ignored, notes, files = submissions.problems, submissions.ignored_columns, submissions.notes, \
        submissions.files
    pieces = graded_pieces(key, submissions, physics, size)
    del submissions
    kept = Keeping(key)
    for graded in pieces:
        if each is not None:
            each(graded)
        kept.add(graded)
        del graded
        hand_back()
    whole = kept.joined(problems, ignored, (*notes, *physics.notes), files)
    del kept
    hand_back()
    return whole


def classwide(graded: Graded | ClassGrades) -> ClassGrades:
    """``graded`` as the whole class's reports read it."""
    return graded if isinstance(graded, ClassGrades) else ClassGrades.of(graded)


class Keeping:
    """What is kept of a class graded a piece at a time (:func:`grader.grade.grading.graded_pieces`): each piece,
    in the key's order, is :meth:`add` ed, then the whole :meth:`joined`."""

    def __init__(self, key: Key) -> None:
        self.key = key
        self.parts = {label: _Part() for label in key.labels}
        self.numbers: dict[str, list[Floats]] = {label: [] for label in key.labels}
        self.problems: list[RowProblem] = []
        self.firsts: list[Answer] = []
        self.latest: list[int | None] = []
        self.deductions: dict[str, float] = {}
        self.unknown: int | None = None  # None: the key has no due time
        self.mistakes: dict[tuple[str, str], str] = {}
        self.pieces = 0

    def add(self, graded: Graded) -> None:
        """Keep what the class's reports read of a piece (the next students of the key)."""
        for label, part in self.parts.items():
            part.add(graded.columns[label])
            if label in graded.numbers:  # (a run built by hand may have none)
                self.numbers[label].append(np.asarray(graded.numbers[label], np.float64))
        own = len(graded.first_given)
        self.problems += graded.problems[len(graded.problems) - own:] if own else ()
        self.firsts += graded.first_given
        if graded.late is not None:
            self.latest += latest(graded.late, len(graded.key.students))
            self.deductions.update(graded.late.deductions)
            self.unknown = (self.unknown or 0) + graded.late.unknown
        for found, says in graded.mistakes.items():
            self.mistakes.setdefault(found, says)
        self.pieces += 1

    def joined(self, problems: Iterable[RowProblem], ignored: tuple[str, ...], notes: Iterable[str],
               files: Sequence[str] = ()) -> ClassGrades:
        """The class: ``problems``, ``ignored`` and ``notes`` the submissions' (and the physics'), then the
        pieces' own (the attempts not counted, in the order grading the class at once finds them: by part, then
        by where each student first answered it, ``files`` the order of the files; and the answers whose
        lateness is not known). Once: the pieces are let go as they are joined."""
        own = self.problems
        if self.pieces > 1 and own:
            labels = {label: index for index, label in enumerate(self.key.labels)}
            order = {name: index for index, name in enumerate(files)}
            ranks = [(labels[problem.label], order[first.file], first.line)
                     for problem, first in zip(own, self.firsts, strict=True)]
            own = [own[index] for index in sorted(range(len(own)), key=ranks.__getitem__)]
        late = None if self.unknown is None else Lateness(self.latest, self.deductions, self.unknown)
        # A part's pieces let go once joined: the class's columns are not held twice.
        columns = {label: self.parts.pop(label).joined() for label in list(self.parts)}
        return ClassGrades(self.key, columns,
                           (*problems, *own), ignored, (*notes, *late_notes(self.unknown or 0)), self.mistakes, late,
                           {label: np.concatenate(self.numbers.pop(label)) for label in list(self.numbers)
                            if self.numbers[label]})


def latest(late: LateWork, count: int) -> list[int | None]:
    """Per student of ``count``, the minutes late of their latest answer that counts (None: no answer whose
    lateness is known)."""
    found: list[int | None] = [None] * count
    for minutes in late.minutes.values():
        found = [mine if theirs is None else max(theirs, mine or 0)
                 for mine, theirs in zip(found, minutes, strict=True)]
    return found


def totals(graded: ClassGrades) -> dict[str, Floats]:
    """Per problem key, each student's score (in the key's order) before any late deduction: its parts' scores
    added in the key's order."""
    count = len(graded.key.students)
    sums: dict[str, Floats] = {}
    for problem in graded.key.problems:
        scores = sums.get(problem.key, np.zeros(count))
        for label in problem.labels:
            column = graded.columns[label]
            scores = scores + column.scores()
        sums[problem.key] = scores
    return sums


def final_scores(graded: ClassGrades, scores: Mapping[str, Floats] | None = None) -> dict[str, float]:
    """Per student id, the total after the late policy's deduction (what grades.csv and canvas.csv carry);
    ``scores``: the :func:`totals`, when the caller has them."""
    ids = [student.id for student in graded.key.students]
    total = np.zeros(len(ids))
    for found in (totals(graded) if scores is None else scores).values():
        total = total + found
    deductions = graded.deductions
    if not deductions:
        return dict(zip(ids, total.tolist(), strict=True))
    return {student_id: score - deductions.get(student_id, 0.0)
            for student_id, score in zip(ids, total.tolist(), strict=True)}


def lateness(graded: ClassGrades) -> Sequence[int | None]:
    """Per student of the key, in its order, the minutes late of their latest answer that counts (None:
    no answer whose lateness is known)."""
    return graded.late.latest if graded.late else [None] * len(graded.key.students)


def counts(graded: ClassGrades) -> dict[str, int]:
    """How many verdicts of each kind."""
    found = dict.fromkeys(VERDICTS, 0)
    for column in graded.columns.values():
        for verdict, count in column.verdict.counted().items():
            found[verdict] = found.get(verdict, 0) + count
    return found


def answered(graded: ClassGrades) -> npt.NDArray[np.bool_]:
    """Per student of the key, in its order, whether they answered any part (submitted anything)."""
    found = np.zeros(len(graded.key.students), bool)
    for column in graded.columns.values():
        found |= column.submitted.given
    return found
