"""A class's verdicts as the reports over the whole class read them (:class:`ClassGrades`), kept in columns.

Grading takes a class a piece of students at a time (:func:`grader.grade.grading.graded_pieces`): a piece's
verdict rows (about 0.5 KiB a cell: the sentence, the source, the expected value's text) are written to
``details.csv`` and let go, and only what ``grades.csv``, ``canvas.csv``, ``integrity.csv`` and the class report
read is kept, a part's cells in a few arrays (:class:`Outcomes`): the verdicts as numbers, the credit and points,
what was typed (all of a part's texts in one string), the tolerance and diagnosis as numbers, and the feedback and
what was read only of the cells that need them. A million students' 15 million cells take about 60 bytes each.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from operator import attrgetter

import numpy as np
import numpy.typing as npt

from grader.grade.diagnosis import Physics
from grader.grade.grading import PIECE, VERDICTS, Graded, LateWork, Row, graded_pieces, late_notes
from grader.grade.key import Key
from grader.grade.latest import Answer
from grader.grade.submissions import RowProblem, Submissions
from grader.grade.texts import Texts

Floats = npt.NDArray[np.float64]
Ints = npt.NDArray[np.int64]


class Coder(dict[str, int]):
    """Numbers for the few distinct texts of a column (a verdict, a tolerance in words), shared by its pieces."""

    def codes(self, texts: Sequence[str]) -> npt.NDArray[np.int32]:
        """Each text's number (new texts numbered as they come)."""
        for text in dict.fromkeys(texts):
            self.setdefault(text, len(self))
        return np.fromiter(map(self.__getitem__, texts), np.int32, len(texts))

    def words(self) -> tuple[str, ...]:
        """The texts, by number."""
        return tuple(self)


@dataclass(frozen=True)
class Some:
    """The texts of some cells of a column: ``cells`` (in order) and theirs."""

    cells: Ints
    texts: Texts

    def take(self, indices: Sequence[int] | Ints) -> list[str | None]:
        """The texts of cells ``indices``, each one of :attr:`cells`."""
        at = np.searchsorted(self.cells, np.asarray(indices, np.int64))
        if len(at) and (at.max() >= len(self.cells) or (self.cells[at] != indices).any()):
            raise KeyError("a cell without its text kept")
        return self.texts.take(at)


@dataclass(frozen=True)
class Outcomes:
    """One part's verdicts for the class, a cell per student of the key in its order: the kind (a number in
    ``kinds``), credit and points, what was typed, the tolerance in words and the diagnosis (numbers in their
    words); what was read, for the ``incorrect`` cells; the feedback, for the ``invalid`` ones."""

    verdict: npt.NDArray[np.int32]
    kinds: tuple[str, ...]
    credit: Floats
    points: Floats
    submitted: Texts
    tolerance: npt.NDArray[np.int32]
    tolerances: tuple[str, ...]
    diagnosis: npt.NDArray[np.int32]
    diagnoses: tuple[str, ...]
    parsed: Some  # of the incorrect cells
    feedback: Some  # of the invalid cells

    def __len__(self) -> int:
        return len(self.verdict)

    def are(self, kind: str) -> npt.NDArray[np.bool_]:
        """Which cells' verdict is ``kind``."""
        return self.verdict == self.kinds.index(kind) if kind in self.kinds else np.zeros(len(self), bool)

    def counted(self) -> dict[str, int]:
        """How many cells of each kind there are (kinds with none left out)."""
        return {self.kinds[code]: count for code, count in enumerate(np.bincount(self.verdict,
                                                                                 minlength=len(self.kinds)).tolist())
                if count}

    def tolerance_counts(self) -> dict[str, int]:
        """How many cells each tolerance in words decided."""
        return {self.tolerances[code]: count for code, count in enumerate(np.bincount(
            self.tolerance, minlength=len(self.tolerances)).tolist()) if count}

    def diagnosed(self, kind: str) -> list[str]:
        """The diagnosis of each cell of ``kind``, in the cells' order."""
        return list(map(self.diagnoses.__getitem__, self.diagnosis[self.are(kind)].tolist()))


class _Part:
    """The numbers shared by a part's pieces as they are kept (:class:`Outcomes` of each piece, joined at the end)."""

    def __init__(self) -> None:
        self.kinds, self.tolerances, self.diagnoses = Coder({kind: index for index, kind in enumerate(VERDICTS)}), \
            Coder(), Coder({"": 0})
        self.pieces: list[Outcomes] = []
        self.start = 0

    def add(self, rows: Sequence[Row]) -> None:
        verdicts = list(map(_VERDICT, rows))
        codes = self.kinds.codes(verdicts)
        incorrect = np.flatnonzero(codes == self.kinds["incorrect"])
        invalid = np.flatnonzero(codes == self.kinds["invalid"])
        self.pieces.append(Outcomes(
            codes, (), np.fromiter(map(_CREDIT, rows), np.float64, len(rows)),
            np.fromiter(map(_POINTS, rows), np.float64, len(rows)), Texts.of(list(map(_SUBMITTED, rows))),
            self.tolerances.codes(list(map(_TOLERANCE, rows))), (), self.diagnoses.codes(list(map(_DIAGNOSIS, rows))),
            (), Some(incorrect + self.start, Texts.of([rows[index].parsed for index in incorrect.tolist()])),
            Some(invalid + self.start, Texts.of([rows[index].feedback for index in invalid.tolist()]))))
        self.start += len(rows)

    def joined(self) -> Outcomes:
        pieces = self.pieces
        return Outcomes(_joined(pieces, "verdict", np.int32), self.kinds.words(), _joined(pieces, "credit"),
                        _joined(pieces, "points"), Texts.joined([piece.submitted for piece in pieces]),
                        _joined(pieces, "tolerance", np.int32), self.tolerances.words(),
                        _joined(pieces, "diagnosis", np.int32), self.diagnoses.words(),
                        _some([piece.parsed for piece in pieces]), _some([piece.feedback for piece in pieces]))


_VERDICT, _CREDIT, _POINTS = attrgetter("verdict"), attrgetter("credit"), attrgetter("points")
_SUBMITTED, _TOLERANCE, _DIAGNOSIS = attrgetter("submitted"), attrgetter("tolerance"), attrgetter("diagnosis")


def _joined(pieces: Sequence[Outcomes], name: str, dtype: type = np.float64) -> np.ndarray:
    return np.concatenate([getattr(piece, name) for piece in pieces] or [np.zeros(0, dtype)])


def _some(pieces: Sequence[Some]) -> Some:
    return Some(np.concatenate([piece.cells for piece in pieces] or [np.zeros(0, np.int64)]),
                Texts.joined([piece.texts for piece in pieces]))


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
    late: LateWork | None = None
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
        return kept.joined(graded.problems[:len(graded.problems) - len(graded.first_given)], graded.ignored_columns,
                           graded.notes[:len(graded.notes) - len(late_notes(graded.late))])


def grade_class(key: Key, read: Callable[[], Submissions], physics: Physics,
                each: Callable[[Graded], object] | None = None, size: int = PIECE) -> ClassGrades:
    """Grade every student of ``key`` against the submissions ``read`` gives (called once here, so that nothing
    else holds them: a piece's answers are let go once it is graded), ``size`` students at a time
    (:func:`~grader.grade.grading.graded_pieces`); each piece is handed to ``each`` (which writes its rows), then
    let go but for what the class's reports read."""
    submissions = read()
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
    return kept.joined(problems, ignored, (*notes, *physics.notes), files)


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
        self.lates: list[LateWork] = []
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
            self.lates.append(graded.late)
        for found, says in graded.mistakes.items():
            self.mistakes.setdefault(found, says)
        self.pieces += 1

    def joined(self, problems: Iterable[RowProblem], ignored: tuple[str, ...], notes: Iterable[str],
               files: Sequence[str] = ()) -> ClassGrades:
        """The class: ``problems``, ``ignored`` and ``notes`` the submissions' (and the physics'), then the
        pieces' own (the attempts not counted, in the order grading the class at once finds them: by part, then
        by where each student first answered it, ``files`` the order of the files; and the answers whose
        lateness is not known)."""
        own = self.problems
        if self.pieces > 1 and own:
            labels = {label: index for index, label in enumerate(self.key.labels)}
            order = {name: index for index, name in enumerate(files)}
            ranks = [(labels[problem.label], order[first.file], first.line)
                     for problem, first in zip(own, self.firsts, strict=True)]
            own = [own[index] for index in sorted(range(len(own)), key=ranks.__getitem__)]
        late = _late(self.lates) if self.lates else None
        return ClassGrades(self.key, {label: part.joined() for label, part in self.parts.items()},
                           (*problems, *own), ignored, (*notes, *late_notes(late)), self.mistakes, late,
                           {label: np.concatenate(found) for label, found in self.numbers.items() if found})


def _late(lates: Sequence[LateWork]) -> LateWork:
    """The lateness of the pieces, one after another."""
    labels = list(lates[0].minutes)
    return LateWork({label: [minutes for late in lates for minutes in late.minutes[label]] for label in labels},
                    {label: [share for late in lates for share in late.shares[label]] for label in labels},
                    {student: points for late in lates for student, points in late.deductions.items()},
                    sum(late.unknown for late in lates))


def totals(graded: ClassGrades) -> dict[str, Floats]:
    """Per problem key, each student's score (in the key's order) before any late deduction: its parts' scores
    added in the key's order."""
    count = len(graded.key.students)
    sums: dict[str, Floats] = {}
    for problem in graded.key.problems:
        scores = sums.get(problem.key, np.zeros(count))
        for label in problem.labels:
            column = graded.columns[label]
            scores = scores + column.credit * column.points
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


def lateness(graded: ClassGrades) -> list[int | None]:
    """Per student of the key, in its order, the minutes late of their latest answer that counts (None:
    no answer whose lateness is known)."""
    found: list[int | None] = [None] * len(graded.key.students)
    for late in graded.late.minutes.values() if graded.late else ():
        found = [mine if theirs is None else max(theirs, mine or 0) for mine, theirs in zip(found, late, strict=True)]
    return found


def counts(graded: ClassGrades) -> dict[str, int]:
    """How many verdicts of each kind."""
    found = dict.fromkeys(VERDICTS, 0)
    for column in graded.columns.values():
        for verdict, count in column.counted().items():
            found[verdict] = found.get(verdict, 0) + count
    return found


def answered(graded: ClassGrades) -> npt.NDArray[np.bool_]:
    """Per student of the key, in its order, whether they answered any part (submitted anything)."""
    found = np.zeros(len(graded.key.students), bool)
    for column in graded.columns.values():
        found |= column.submitted.given
    return found
