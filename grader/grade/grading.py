"""Grading: every part of every student in the key against what they submitted, one verdict each.

A verdict records what was typed, what it was read as (in the expected unit), what was expected,
the errors, the tolerance that decided it in words, the credit and a sentence that explains it.
Cells are read once per distinct text (a class types the same few forms).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import lru_cache

from grader.grade.cells import (
    CellBlank,
    CellExpression,
    CellInvalid,
    CellNumber,
    CellWrongUnit,
    read_expression,
    read_number,
    undefined_word,
)
from grader.grade.compare import equivalent, errors, feedback, is_correct
from grader.grade.key import Key, KeyPart
from grader.grade.submissions import Answer, RowProblem, Submissions
from grader.model.expr import Node, parse
from grader.model.tolerance import Tolerance

VERDICTS = ("correct", "incorrect", "invalid", "missing")


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
    source: str = ""  # "file:line" of the row the answer came from

    @property
    def score(self) -> float:
        """Points earned."""
        return self.credit * self.points


@dataclass(frozen=True)
class Graded:
    """A grading run: a verdict per (student in the key, part), and every row not graded."""

    key: Key
    verdicts: tuple[Verdict, ...]
    problems: tuple[RowProblem, ...]
    ignored_columns: tuple[str, ...]
    notes: tuple[str, ...]


def grade(key: Key, submissions: Submissions) -> Graded:
    """Grade every student of the key; a part nobody answered is ``missing``."""
    submitted = {(a.student_id, a.label): a for a in submissions.answers}
    verdicts = tuple(grade_part(part, student.id, submitted.get((student.id, part.label)), key)
                     for student in key.students for part in (student.parts[label] for label in key.labels))
    return Graded(key, verdicts, submissions.problems, submissions.ignored_columns, submissions.notes)


@dataclass(frozen=True)
class _Part:
    """One part being graded: what the verdict needs besides its outcome."""

    part: KeyPart
    student_id: str
    text: str | None
    source: str
    tolerance: Tolerance

    def verdict(self, kind: str, credit: float, said: str, parsed: str = "",
                errs: tuple[float | None, float | None] = (None, None)) -> Verdict:
        words = "equal expressions" if self.part.symbolic else self.tolerance.describe()
        return Verdict(self.student_id, self.part.label, self.text, kind, credit, self.part.points,
                       _expected(self.part), parsed, self.part.unit, errs[0], errs[1], words, said, self.source)


def grade_part(part: KeyPart, student_id: str, answer: Answer | None, key: Key) -> Verdict:
    """One part: the key's expectation against the answer (None: nothing submitted)."""
    text = None if answer is None else answer.text
    graded = _Part(part, student_id, text, "" if answer is None else f"{answer.file}:{answer.line}",
                   Tolerance.from_json(part.tolerance))
    if part.value is None:
        if text is None or undefined_word(text):
            return graded.verdict("correct", 1.0, f"right: there is no value here ({part.undefined})")
        return graded.verdict("incorrect", 0.0, f"there is no value here ({part.undefined}); expected a blank "
                                                "or 'undefined'")
    if text is None or answer is None:
        return graded.verdict("missing", 0.0, "no answer was submitted")
    if part.symbolic:
        return _symbolic(graded, text, answer.delimiter, key)
    cell = _number(text, part.unit, answer.delimiter, key.numeric_expressions, (part.name, part.label))
    if isinstance(cell, CellBlank):
        return graded.verdict("missing", 0.0, "the answer was blank")
    if isinstance(cell, CellInvalid):
        return graded.verdict("invalid", 0.0, f"could not read this answer: {cell.reason}")
    if isinstance(cell, CellWrongUnit):
        return graded.verdict("incorrect", 0.0, cell.reason)
    expected = float(part.value)
    angle = part.unit if part.unit in ("deg", "rad") else None
    right = bool(is_correct([cell.value], [expected], graded.tolerance, angle_unit=angle)[0])
    absolute, relative = (float(e[0]) for e in errors([cell.value], [expected], angle_unit=angle))
    said = feedback(cell.value, expected, part.unit, graded.tolerance, right, angle_unit=angle)
    return graded.verdict("correct" if right else "incorrect", 1.0 if right else 0.0, said, _show(cell.value),
                          (absolute, relative))


def _symbolic(graded: _Part, text: str, delimiter: str, key: Key) -> Verdict:
    part = graded.part
    symbols = tuple(part.symbols)
    cell = _expression(text, symbols, delimiter)
    if isinstance(cell, CellBlank):
        return graded.verdict("missing", 0.0, "the answer was blank")
    if isinstance(cell, CellInvalid):
        return graded.verdict("invalid", 0.0, f"could not read this answer: {cell.reason}")
    same = equivalent(cell.tree, _key_tree(str(part.value)), part.symbols, seed=f"{key.title}/{part.label}")
    if isinstance(same, str):
        return graded.verdict("invalid", 0.0, f"could not compare this expression: {same}", cell.text)
    names = " and ".join(symbols)
    said = (f"equal to the expected expression at every sampled value of {names}" if same else
            f"not equal to the expected expression: they differ at sampled values of {names}")
    return graded.verdict("correct" if same else "incorrect", 1.0 if same else 0.0, said, cell.text)


@lru_cache(maxsize=65536)
def _number(text: str, unit: str, delimiter: str, numeric_expressions: bool,
            names: tuple[str, ...]) -> CellBlank | CellInvalid | CellWrongUnit | CellNumber:
    return read_number(text, unit, delimiter=delimiter, numeric_expressions=numeric_expressions, names=names)


@lru_cache(maxsize=65536)
def _expression(text: str, symbols: tuple[str, ...], delimiter: str) -> CellBlank | CellInvalid | CellExpression:
    return read_expression(text, symbols, delimiter=delimiter)


@lru_cache(maxsize=4096)
def _key_tree(text: str) -> Node:
    """The key's expression, parsed once per distinct text (comparisons are cached in compare)."""
    return parse(text)


def _expected(part: KeyPart) -> str:
    if part.value is None:
        return f"undefined ({part.undefined})"
    return part.value if isinstance(part.value, str) else _show(part.value)


def _show(value: float) -> str:
    """A number as a person reads it: 6 significant figures, never ``-0``."""
    return f"{value + 0.0:.6g}"


def totals(graded: Graded) -> Mapping[str, Mapping[str, float]]:
    """Per student, per problem key: the score."""
    problem_of = {label: problem.key for problem in graded.key.problems for label in problem.labels}
    result: dict[str, dict[str, float]] = {s.id: dict.fromkeys((p.key for p in graded.key.problems), 0.0)
                                           for s in graded.key.students}
    for verdict in graded.verdicts:
        result[verdict.student_id][problem_of[verdict.label]] += verdict.score
    return result


def counts(verdicts: Sequence[Verdict]) -> dict[str, int]:
    """How many verdicts of each kind."""
    return {kind: sum(v.verdict == kind for v in verdicts) for kind in VERDICTS}
