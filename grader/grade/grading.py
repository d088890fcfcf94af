"""Grading: every part of every student in the key against what they submitted, one verdict each.

A verdict records what was typed, what it was read as (in the expected unit), what was expected,
the errors, the tolerance that decided it in words, the credit, a sentence that explains it and, for
``ecf`` and ``mistake``, the diagnosis (:mod:`grader.grade.diagnosis`). Grading is columnar: a part's
answers are graded for the whole class at once, each distinct text read once and the numbers compared
in one vectorised call per tolerance and unit, the wrong ones then reconsidered by the physics in one
pass; the verdicts are kept as rows of plain values (a class of 100,000 has a million) and become
:class:`Verdict` objects only when asked for. :func:`grade_part` grades one answer the same way.
"""

from __future__ import annotations

import functools
import itertools
import operator
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field, replace
from datetime import datetime
from typing import Any, NamedTuple

import numpy as np

from grader.base.inputs import CELL_CHARS
from grader.grade.answer_columns import AnswerColumns
from grader.grade.cells import (
    CellBlank,
    CellInvalid,
    CellNumber,
    CellWrongUnit,
    read_expression,
    read_number,
    undefined_word,
)
from grader.grade.compare import errors, feedbacks, is_correct, number_text, number_texts
from grader.grade.diagnosis import Earlier, Physics, ProblemPhysics, physics_for, reconsider
from grader.grade.equivalence import equivalent, refused
from grader.grade.key import Key, KeyPart
from grader.grade.lateness import deductions, intervals, late_by, minutes, part_deduction
from grader.grade.notation import cut
from grader.grade.submissions import Answer, RowProblem, Submissions
from grader.grade.timestamps import instant
from grader.model.tolerance import EQUAL_EXPRESSIONS, Tolerance

VERDICTS = ("correct", "ecf", "mistake", "incorrect", "invalid", "missing")
"""The kinds of verdict: right; right for the student's own earlier answer (error carried forward); a
diagnosed mistake; wrong; unreadable; not given."""


@dataclass(frozen=True)
class Verdict:
    """One part of one student, graded."""

    student_id: str
    label: str
    submitted: str | None  # None: nothing was submitted
    verdict: str  # one of VERDICTS
    credit: float  # 0..1
    points: float
    expected: str
    parsed: str
    unit: str
    abs_error: float | None
    rel_error: float | None
    tolerance: str
    feedback: str
    diagnosis: str = ""  # ecf: "ecf:" and the part carried forward (ecf:3a); mistake: its id (impact.e_squared)
    source: str = ""  # "file:line" of the row the answer came from
    late: int | None = None  # minutes late (None: no due time, no answer, or a row without a timestamp)
    deduction: float = 0.0  # points the late policy took for it (its share of the student's deduction)

    @property
    def score(self) -> float:
        """Points earned."""
        return self.credit * self.points


class Row(NamedTuple):
    """A verdict's fields after ``student_id`` and ``label``, in :class:`Verdict`'s order: what a class's
    columns keep (a tuple with names: a million of them cost what tuples cost)."""

    submitted: str | None
    verdict: str
    credit: float
    points: float
    expected: str
    parsed: str
    unit: str
    abs_error: float | None
    rel_error: float | None
    tolerance: str
    feedback: str
    diagnosis: str
    source: str

    @property
    def score(self) -> float:
        """Points earned."""
        return self.credit * self.points


@dataclass(frozen=True)
class LateWork:
    """How late the answers that count came, for a key with due times: per part label, per student of the
    key in its order, the minutes late (None: nothing submitted, or no timestamp) and the part's share of
    the deduction; per student id, the points the late policy took (only those who lost any). Kept beside
    the verdicts, not in them: a class of 100,000 has a million."""

    minutes: Mapping[str, Sequence[int | None]]
    shares: Mapping[str, Sequence[float]]
    deductions: Mapping[str, float]
    unknown: int = 0  # answers with a due time whose lateness is not known (no timestamp, or one that does not read)


@dataclass(frozen=True)
class Graded:
    """A grading run: per part label, in the key's order, a verdict row for every student of the key,
    in its order; every row not graded; and how late the answers were (None: the key has no due time)."""

    key: Key
    columns: Mapping[str, Sequence[Row]]
    problems: tuple[RowProblem, ...]
    ignored_columns: tuple[str, ...]
    notes: tuple[str, ...]
    # What each diagnosed mistake a part may get says, in words (completing "your answer matches …"), by
    # (label, the mistake's id): the class report says the mistakes, not only their ids.
    mistakes: Mapping[tuple[str, str], str] = field(default_factory=dict)
    late: LateWork | None = None
    # Per part label, the number each student's answer was read as, in the sheet's unit (NaN: no number):
    # what the integrity check compares with the other students' keys (:mod:`grader.grade.integrity`).
    numbers: Mapping[str, np.ndarray] = field(default_factory=dict)
    # Per problem of the attempts not counted (a key's ``attempts: best``), its student's first answer to the
    # part: the class's problems come in the order of these (:func:`graded_pieces`).
    first_given: tuple[Answer, ...] = ()

    @property
    def deductions(self) -> Mapping[str, float]:
        """Per student id, the points the late policy took (only those who lost any)."""
        return {} if self.late is None else self.late.deductions

    @property
    def verdicts(self) -> tuple[Verdict, ...]:
        """Every verdict, student by student, part by part (built on each call: the reports read the rows)."""
        labels, late = self.key.labels, self.late
        return tuple(Verdict(student.id, label, *self.columns[label][index],
                             *((late.minutes[label][index], late.shares[label][index]) if late else ()))
                     for index, student in enumerate(self.key.students) for label in labels)


def grade(key: Key, submissions: Submissions, physics: Physics | None = None) -> Graded:
    """Grade every student of the key; a part nobody answered is ``missing``. ``physics`` carries errors
    forward and diagnoses mistakes (by default from the shipped bank, :func:`physics_for`). Where a
    student gave several answers to a part (the key's ``attempts`` is ``best``), the best counts; then
    the key's late policy is applied (:func:`_late_work`)."""
    physics = physics_for(key) if physics is None else physics
    problems_read, ignored, notes_read = submissions.problems, submissions.ignored_columns, submissions.notes
    graded = grade_piece(key, submissions.answers, physics)
    return replace(graded, problems=(*problems_read, *graded.problems), ignored_columns=ignored,
                   notes=(*notes_read, *physics.notes, *late_notes(graded.late.unknown if graded.late else 0)))


PIECE = 20_000
"""Students graded at a time by :func:`graded_pieces`: a piece's verdicts (about 0.5 KiB a cell) are written and
let go before the next piece is graded."""


def graded_pieces(key: Key, submissions: Submissions, physics: Physics, size: int = PIECE) -> Iterator[Graded]:
    """The class graded ``size`` students at a time, in the key's order: each piece as :func:`grade_piece` grades
    it (its key :meth:`Key.piece`, its students' answers, the physics' rows of its students). What a student gets
    depends on their own answers alone, so the pieces' verdicts are the class's. The submissions' problems and
    notes are the caller's (:attr:`Submissions.problems`): a piece has its own (the attempts not counted).

    Where answers of a student are let go (``submissions`` handed over, not kept), a piece's are let go once it
    is graded."""
    count, answers = len(key.students), submissions.answers
    del submissions
    if count <= size:
        yield grade_piece(key, answers, physics)
        return
    pieces = _by_piece(key, answers, size)
    del answers  # the pieces' answers are all that is kept of them
    for start, mine in pieces:
        stop = min(start + size, count)
        yield grade_piece(key.piece(start, stop), mine, physics.piece(start, stop))
        del mine


def _by_piece(key: Key, answers: Sequence[Answer], size: int) -> Iterator[tuple[int, tuple[Answer, ...]]]:
    """The answers of each piece of ``size`` students of the key (its first student's index, and theirs, in the
    order given); answers of students the key lacks are left out. Answers in columns are made a piece at a
    time; others are sorted into pieces at once (and let go here, where the caller keeps no reference)."""
    count = len(key.students)
    if isinstance(answers, AnswerColumns):  # each answer's student is a number already
        student = answers.student.astype(np.int64)
    else:
        positions = key.positions
        student = np.fromiter(map(positions.get, map(_STUDENT, answers), itertools.repeat(-size)), np.int64,
                              len(answers))
    piece_of = student // size
    order = np.argsort(piece_of, kind="stable")
    bounds = np.searchsorted(piece_of[order], np.arange(count // size + 2)).tolist()
    del student, piece_of
    if isinstance(answers, AnswerColumns):
        for index, start in enumerate(range(0, count, size)):
            yield start, tuple(answers.take(order[bounds[index]:bounds[index + 1]]))
        return
    made: list[list[Answer] | None] = [list(map(answers.__getitem__, order[low:high].tolist()))
                                       for low, high in itertools.pairwise(bounds)]
    del answers, order
    for index, start in enumerate(range(0, count, size)):
        mine, made[index] = made[index], None
        yield start, tuple(mine or ())


_STUDENT = operator.attrgetter("student_id")


def grade_piece(key: Key, answers: Sequence[Answer], physics: Physics) -> Graded:
    """Every student of ``key`` graded against ``answers`` (theirs): the verdicts, the attempts not counted
    (problems, routine) and the lateness; no notes (the class's are the caller's, :func:`late_notes`)."""
    # Per label, each student's first answer; and, for a part a student answered more than once, all of them.
    by_label: dict[str, dict[str, Answer]] = {label: {} for label in key.labels}
    again: dict[str, dict[str, list[Answer]]] = {label: {} for label in key.labels}
    for answer in answers:
        first = by_label[answer.label].setdefault(answer.student_id, answer)
        if first is not answer:
            again[answer.label].setdefault(answer.student_id, [first]).append(answer)
    del answers
    problems: list[RowProblem] = []
    firsts: list[Answer] = []
    columns: dict[str, list[Row]] = {}
    numbers: dict[str, np.ndarray] = {}
    stamps: dict[str, list[datetime | None]] = {}
    everyone = np.arange(len(key.students))
    ids = [student.id for student in key.students]
    timed = key.timed  # else no answer's lateness is measured: its timestamp is not kept
    for problem in key.problems:
        earlier: list[Earlier] = []
        for label in problem.labels:
            answers_to = _best(key, label, by_label.pop(label), again.pop(label), physics.problems.get(problem.key),
                               problems, firsts)
            parts, given = key.part_column(label), list(map(answers_to.get, ids))
            columns[label], numbers[label] = _grade_label(parts, given, key, everyone,
                                                          physics.problems.get(problem.key), earlier)
            if timed:
                stamps[label] = [None if answer is None else answer.timestamp for answer in given]
    return Graded(key, columns, tuple(problems), (), (), mistake_words(key, physics), _late_work(key, columns, stamps),
                  numbers, tuple(firsts))


def late_notes(unknown: int) -> list[str]:
    """The notes of a class's lateness: ``unknown`` answers whose lateness is not known."""
    return [f"{unknown:,} answers have no timestamp (or one that does not read): how late they were is not "
            "known, and they lose nothing; see problems.csv"] if unknown else []


def mistake_words(key: Key, physics: Physics) -> dict[tuple[str, str], str]:
    """What each diagnosed mistake of each part says, by (label, the mistake's id)."""
    words: dict[tuple[str, str], str] = {}
    first = key.students[0].parts if key.students else {}
    for problem in key.problems:
        found = physics.problems.get(problem.key)
        if found is None:
            continue
        for label in problem.labels:
            for alternative in found.alternatives.for_answer(first[label].name):
                if alternative.kind == "mistake":
                    words.setdefault((label, alternative.id), alternative.says)
    return words


def _due(key: Key, index: int) -> datetime | None:
    """Student ``index``'s due time: their extension, else the assignment's."""
    return key.students[index].due or key.deadline


def _best(key: Key, label: str, chosen: dict[str, Answer], several: Mapping[str, list[Answer]],
          physics: ProblemPhysics | None, problems: list[RowProblem], firsts: list[Answer]) -> dict[str, Answer]:
    """Per student, the answer to ``label`` that counts (``chosen``: each one's first, which this updates):
    the only one, or, of ``several`` (``attempts: best``), the one that scores most after its own late
    deduction (ties: the earliest). Every attempt is graded on its own (an error is not carried forward
    while choosing: the earlier parts are not chosen yet); each one not counted is a problem (routine)
    naming the one that is, and its student's first answer to the part is added to ``firsts``."""
    if not several:
        return chosen
    positions = key.positions
    parts: list[KeyPart] = []
    attempts: list[Answer] = []
    students: list[int] = []
    for student_id in [student_id for student_id in chosen if student_id in several]:  # in the order first given
        found = several[student_id]
        parts += [key.students[positions[student_id]].parts[label]] * len(found)
        attempts += found
        students += [positions[student_id]] * len(found)
    rows, _ = _grade_label(parts, attempts, key, np.array(students), physics, [])
    scored: dict[str, list[tuple[float, Answer]]] = {}
    for part, answer, index, row in zip(parts, attempts, students, rows, strict=True):
        lost = 0.0 if key.late is None else float(part_deduction(
            key.late, row.score, part.points, intervals(key.late, late_by(answer.timestamp, _due(key, index)))))
        scored.setdefault(answer.student_id, []).append((row.score - lost, answer))
    for student_id, tried in scored.items():
        tried.sort(key=lambda pair: (-pair[0], instant(pair[1].timestamp), pair[1].line))
        (best, winner), *others = tried
        firsts += [chosen[student_id]] * len(others)
        chosen[student_id] = winner
        problems.extend(RowProblem(answer.file, answer.line, student_id, label, f"not counted: {winner.file} line "
                                   f"{winner.line} scored more ({best:g} points, this one {score:g}; the best "
                                   "attempt counts)" if score < best else f"not counted: {winner.file} line "
                                   f"{winner.line}, submitted first, scored as much (the best attempt counts)",
                                   routine=True) for score, answer in others)
    return chosen


def _late_work(key: Key, columns: Mapping[str, Sequence[Row]],
               stamps: Mapping[str, Sequence[datetime | None]]) -> LateWork | None:
    """How late each answer was and what the key's late policy takes for it (:mod:`grader.grade.lateness`);
    None for a key without due times."""
    if not key.timed:
        return None
    policy, everyone = key.late, range(len(key.students))
    dues = [_due(key, index) for index in everyone]
    found: dict[tuple[datetime | None, datetime | None], tuple[int | None, int]] = {}  # rows share stamps
    minutes_late, charged, unknown = {}, {}, 0
    for label, rows in columns.items():
        late: list[int | None] = [None] * len(dues)
        charges = [0] * len(dues)
        for index, (row, stamp, due) in enumerate(zip(rows, stamps[label], dues, strict=True)):
            if row.submitted is None:
                continue
            known = found.get((stamp, due))
            if known is None:
                by = late_by(stamp, due)
                known = found[stamp, due] = (minutes(by), 0 if policy is None else intervals(policy, by))
            late[index], charges[index] = known
            unknown += known[0] is None and due is not None  # a student with no due time: nothing to know
        minutes_late[label], charged[label] = late, charges
    shares = {label: [0.0] * len(dues) for label in columns}
    deducted = {}
    if policy is not None:
        for index in sorted({index for charges in charged.values() for index, charge in enumerate(charges) if charge}):
            total, exact = deductions(policy, tuple((rows[index].score, rows[index].points, charged[label][index])
                                                    for label, rows in columns.items()))
            deducted[key.students[index].id] = float(total)
            for label, share in zip(columns, exact, strict=True):
                shares[label][index] = float(share)
    return LateWork(minutes_late, shares, deducted, unknown)


def grade_part(part: KeyPart, student_id: str, answer: Answer | None, key: Key,
               physics: Physics | None = None) -> Verdict:
    """One part: the key's expectation against the answer (None: nothing submitted). With ``physics``, a
    wrong number may be a diagnosed mistake (an earlier answer to carry forward is not known here)."""
    return grade_parts([Request(part, student_id, answer)], key, physics)[0]


class Request(NamedTuple):
    """A part to grade on its own (``grader check``): the key's expectation, whose it is, the answer."""

    part: KeyPart
    student_id: str
    answer: Answer | None


def grade_parts(requests: Sequence[Request], key: Key, physics: Physics | None = None) -> list[Verdict]:
    """:func:`grade_part` for each request, in order: the requests of one label (and of students the key
    has, or not) are graded together, as ``grader grade`` grades a column, each on its own (no error is
    carried forward from another request)."""
    positions = key.positions
    groups: dict[tuple[str, bool], list[int]] = {}
    for index, request in enumerate(requests):
        groups.setdefault((request.part.label, request.student_id in positions), []).append(index)
    verdicts: list[Verdict | None] = [None] * len(requests)
    for (_, known), members in groups.items():
        first = requests[members[0]].part
        found = physics.problems.get(first.problem) if physics is not None and known else None
        students = np.array([positions.get(requests[index].student_id, 0) for index in members])
        parts, answers = [requests[index].part for index in members], [requests[index].answer for index in members]
        for index, row in zip(members, _grade_label(parts, answers, key, students, found, [])[0], strict=True):
            verdicts[index] = Verdict(requests[index].student_id, requests[index].part.label, *row)
    return verdicts  # type: ignore[return-value]  # every request is in one group


def _grade_label(parts: Sequence[KeyPart], answers: Sequence[Answer | None], key: Key, students: np.ndarray,
                 physics: ProblemPhysics | None, earlier: list[Earlier]) -> tuple[list[Row], np.ndarray]:
    """The rows of one part, a cell for each of ``parts`` (the key's) and ``answers`` (None: nothing given)
    (``students``: each cell's student, by index in the key), the wrong numbers reconsidered by the problem's
    ``physics``, which then adds the part to ``earlier``; and the number each cell was read as (NaN: none)."""
    column = _grade_column(parts, answers, key)
    rows = column.rows
    if physics is None or not parts:
        return rows, column.numbers
    part = parts[0]
    wrong = [index for _, indices in column.wrong for index in indices]
    if wrong:
        members, groups, start = np.array(wrong), [], 0
        for tolerance, indices in column.wrong:
            groups.append((tolerance, np.arange(start, start + len(indices))))
            start += len(indices)
        found = reconsider(physics, key, part.name, part.label, part.unit, groups, students[members],
                           column.numbers[members], column.right[members], [rows[index].feedback for index in wrong],
                           earlier)
        for position, finding in found.items():
            index = wrong[position]
            rows[index] = rows[index]._replace(verdict=finding.kind, credit=finding.credit, feedback=finding.feedback,
                                               diagnosis=finding.diagnosis)
    earlier.append(Earlier(part.label, part.name, part.unit, column.numbers, column.right))
    return rows, column.numbers


Outcome = tuple[str, float, str, str]
"""A verdict decided without comparing numbers: its kind, credit, sentence and what was read."""


class _Group(NamedTuple):
    """Cells compared together (one rule and unit): their indices, answers and points, the numbers read, the
    key's, what was typed in another unit, and the words of each one's tolerance (one rule; reasons may differ)."""

    members: list[int]
    answers: list[Answer]
    points: list[float]
    submitted: list[float]
    expected: list[float]
    typed: list[str | None]
    words: list[str]


@dataclass(frozen=True)
class _Column:
    """A part graded for a class: a row per cell; the number each cell was read as and the key's number
    (NaN where either is not a number); and the cells whose number is wrong, grouped by tolerance."""

    rows: list[Row]
    numbers: np.ndarray
    right: np.ndarray
    wrong: list[tuple[Tolerance, list[int]]]


def _grade_column(parts: Sequence[KeyPart], answers: Sequence[Answer | None], key: Key) -> _Column:
    """A row for each part and answer: outcomes decided once per distinct text, numbers compared by group.
    The cells are taken a run at a time (one tolerance, unit and answer name: a column has a few runs), each
    step of a run a column at a time."""
    rows: list[Row | None] = [None] * len(parts)
    # The key's tolerance mappings, by value (a few distinct ones): the rule and its words. Rules equal but for
    # their reasons (widened alike for different reasons) are equal Tolerances: compared in one group.
    tolerances: dict[tuple[tuple[str, Any], ...], tuple[Tolerance, str]] = {}
    groups: dict[tuple[Tolerance, str], _Group] = {}
    # What each distinct text typed for a number reads as (a class types a few thousand), by the part's unit and
    # answer name, then by the text and the file's delimiter: nothing else decides it.
    read: dict[tuple[str, str], dict[tuple[str, str], Outcome | CellNumber]] = {}
    for start, stop in _runs(parts):
        kept, given = parts[start:stop], answers[start:stop]
        first = kept[0]
        unit, mapping = first.unit, first.tolerance
        written = tuple(mapping.items())
        rule, words = tolerances.get(written) or tolerances.setdefault(written, _rule(mapping))
        readings = read.setdefault((unit, first.name), {})
        outcomes = [readings.get(typed := (answer.text, answer.delimiter))
                    or readings.setdefault(typed, _outcome(part, answer, key))
                    if answer is not None and type(part.value) is float else _outcome(part, answer, key)
                    for part, answer in zip(kept, given, strict=True)]
        numbered = [offset for offset, outcome in enumerate(outcomes) if isinstance(outcome, CellNumber)]
        if numbered:  # groups come in the order of their first numbers
            group = groups.get((rule, unit)) or groups.setdefault((rule, unit), _Group([], [], [], [], [], [], []))
            found: list[CellNumber] = [outcomes[offset] for offset in numbered]  # type: ignore[misc]  # numbers
            their_parts = [kept[offset] for offset in numbered]
            their_answers: list[Answer] = [given[offset] for offset in numbered]  # type: ignore[misc]  # given
            group.members.extend([start + offset for offset in numbered] if start else numbered)
            group.answers.extend(their_answers)
            group.points.extend(map(_POINTS, their_parts))
            group.submitted.extend(map(_VALUE, found))
            group.expected.extend([float(part.value) for part in their_parts])  # type: ignore[arg-type]  # numbers
            group.typed.extend([None if cell.unit_given is None or cell.unit_given == unit else
                                _converted(cell, part, answer)
                                for cell, part, answer in zip(found, their_parts, their_answers, strict=True)])
            group.words.extend([words] * len(numbered))
        if len(numbered) < len(outcomes):
            for offset, outcome in enumerate(outcomes):
                if not isinstance(outcome, CellNumber):
                    part, answer = kept[offset], given[offset]
                    rows[start + offset] = _row(part, answer, _expected(part),
                                                EQUAL_EXPRESSIONS if part.symbolic else words, *outcome)
    numbers, right = np.full(len(parts), np.nan), np.full(len(parts), np.nan)
    wrong = []
    for (rule, unit), group in groups.items():
        numbers[group.members], right[group.members] = group.submitted, group.expected
        wrong.append((rule, _compare(group, rule, unit, rows)))
    return _Column(rows, numbers, right, wrong)  # type: ignore[arg-type]  # every row is filled, here or by _compare


def _runs(parts: Sequence[KeyPart]) -> list[tuple[int, int]]:
    """Where a column's parts are alike (one tolerance mapping, unit and answer name), as (start, stop). Most
    columns are one run, their parts sharing these objects: found so without a Python step per part."""
    if not parts:
        return []
    first = parts[0]
    if all(all(map(operator.is_, map(field, parts), itertools.repeat(field(first)))) for field in _SHAPE):
        return [(0, len(parts))]
    bounds = [0, *(index for index, (before, part) in enumerate(itertools.pairwise(parts), start=1)
                   if part.tolerance is not before.tolerance or part.unit != before.unit or part.name != before.name)]
    return list(itertools.pairwise([*bounds, len(parts)]))


_SHAPE = tuple(map(operator.attrgetter, ("tolerance", "unit", "name")))  # what decides how a part's cells are read
_POINTS, _VALUE = operator.attrgetter("points"), operator.attrgetter("value")


def _rule(mapping: Mapping[str, Any]) -> tuple[Tolerance, str]:
    """A key's tolerance mapping as a rule, and its words."""
    tolerance = Tolerance.from_json(mapping)
    return tolerance, tolerance.explained()


def _converted(cell: CellNumber, part: KeyPart, answer: Answer | None) -> str | None:
    """What the student typed, when its unit is not the sheet's (``17.0 mph`` for ft/s), for the feedback."""
    if answer is None or cell.unit_given is None or cell.unit_given == part.unit:
        return None
    return cut(" ".join(answer.text.split()), 40)


def _compare(group: _Group, tolerance: Tolerance, unit: str, rows: list[Row | None]) -> list[int]:
    """The rows of a group of cells of one tolerance and unit: verdicts, errors and sentences, each in one pass
    over the group; returns the cells found wrong."""
    members, answers, points, submitted, expected, typed, words = group
    angle = unit if unit in ("deg", "rad") else None
    given, key = np.array(submitted), np.array(expected)
    right = is_correct(given, key, tolerance, angle_unit=angle)
    absolute, relative = errors(given, key, angle_unit=angle)
    expected_texts = number_texts(expected)
    said = feedbacks(given, key, unit, tolerance, right, angle_unit=angle, typed=typed, expected_texts=expected_texts)
    shown: dict[float, str] = {}  # the numbers a class typed: a few thousand
    verdicts = right.tolist()
    # The rows' fields a column at a time, zipped in Row's order (tuple.__new__: no Python call per row). A
    # number's text is never longer than CELL_CHARS (such a text does not read); a group's rows share its unit.
    fields = zip([answer.text for answer in answers], map(_KINDS.__getitem__, verdicts),
                 map(_CREDITS.__getitem__, verdicts), points, expected_texts,
                 [shown.get(value) or shown.setdefault(value, number_text(value)) for value in submitted],
                 itertools.repeat(unit), absolute.tolist(), relative.tolist(), words, said, itertools.repeat(""),
                 [f"{answer.file}:{answer.line}" for answer in answers], strict=False)  # repeat: endless
    for index, row in zip(members, map(functools.partial(tuple.__new__, Row), fields), strict=True):
        rows[index] = row
    return [index for index, ok in zip(members, verdicts, strict=True) if not ok]


_KINDS, _CREDITS = {True: "correct", False: "incorrect"}, {True: 1.0, False: 0.0}  # a number's verdict


def _shown_answer(text: str) -> str:
    """An answer as a verdict shows it: a longer one than CELL_CHARS is invalid, its first characters say which."""
    return cut(text, CELL_CHARS)


def _outcome(part: KeyPart, answer: Answer | None, key: Key) -> Outcome | CellNumber:
    """The verdict of a part that needs no comparison of numbers, or the number to compare."""
    text = None if answer is None else answer.text
    if part.value is None:
        if text is None or undefined_word(text):
            return "correct", 1.0, f"right: there is no value here ({part.undefined})", ""
        return "incorrect", 0.0, f"there is no value here ({part.undefined}); expected a blank or 'undefined'", ""
    if text is None or answer is None:
        return "missing", 0.0, "no answer was submitted", ""
    if part.symbolic:
        return _symbolic(part, text, answer.delimiter, key)
    cell = _number(text, part.unit, answer.delimiter, key.numeric_expressions, (part.name, part.label))
    if isinstance(cell, CellBlank):
        return "missing", 0.0, "the answer was blank", ""
    if isinstance(cell, CellInvalid):
        return "invalid", 0.0, f"could not read this answer: {cell.reason}", ""
    if isinstance(cell, CellWrongUnit):
        return "incorrect", 0.0, cell.reason, ""
    return cell


def _row(part: KeyPart, answer: Answer | None, expected: str, words: str, kind: str, credit: float, said: str,
         parsed: str = "", absolute: float | None = None, relative: float | None = None) -> Row:
    """The verdict's fields; ``expected``: what the key holds, in words; ``words``: the tolerance that decided it."""
    shown_text = None if answer is None else _shown_answer(answer.text)
    source = "" if answer is None else f"{answer.file}:{answer.line}"
    # tuple.__new__: a million rows a class, and the named tuple's own __new__ is a Python call (~0.4 µs each).
    return tuple.__new__(Row, (shown_text, kind, credit, part.points, expected, parsed, part.unit, absolute, relative,
                               words, said, "", source))


def _symbolic(part: KeyPart, text: str, delimiter: str, key: Key) -> Outcome:
    domains = tuple((name, (float(low), float(high))) for name, (low, high) in part.symbols.items())
    return symbolic_outcome(text, delimiter, domains, str(part.value), f"{key.title}/{part.label}")


@functools.lru_cache(maxsize=65536)
def symbolic_outcome(text: str, delimiter: str, domains: tuple[tuple[str, tuple[float, float]], ...],
                     expected_text: str, seed: str) -> Outcome:
    """A symbolic answer's verdict, credit, sentence and what it was read as; ``domains``: where each name is
    drawn, in the key's order. Worked out once per distinct answer, keyed by text (a tree is slow to hash)."""
    symbols = tuple(name for name, _ in domains)
    cell = read_expression(text, symbols, delimiter=delimiter)
    if isinstance(cell, CellBlank):
        return "missing", 0.0, "the answer was blank", ""
    if isinstance(cell, CellInvalid):
        return "invalid", 0.0, f"could not read this answer: {cell.reason}", ""
    refusal = refused(cell.tree, expected_text, cell.text)
    if refusal is not None:
        return "invalid", 0.0, f"could not read this answer: {refusal}", cell.text
    same = equivalent(cell.tree, expected_text, dict(domains), seed=seed)
    if isinstance(same, str):
        return "invalid", 0.0, f"could not compare this expression: {same}", cell.text
    names = " and ".join(symbols)
    said = (f"equal to the expected expression at every sampled value of {names}" if same else
            f"not equal to the expected expression: they differ at sampled values of {names}")
    return "correct" if same else "incorrect", 1.0 if same else 0.0, said, cell.text


@functools.lru_cache(maxsize=65536)
def _number(text: str, unit: str, delimiter: str, numeric_expressions: bool,
            names: tuple[str, ...]) -> CellBlank | CellInvalid | CellWrongUnit | CellNumber:
    return read_number(text, unit, delimiter=delimiter, numeric_expressions=numeric_expressions, names=names)


def _expected(part: KeyPart) -> str:
    if part.value is None:
        return f"undefined ({part.undefined})"
    return part.value if isinstance(part.value, str) else number_text(part.value)
