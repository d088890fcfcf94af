"""``details.csv``: a row per (student, part), written a column at a time.

A class of 100,000 has a million rows of 18 cells. Each cell is the report's rule for its field (text guarded
against formulas with its control characters shown, :mod:`grader.grade.report`; a number as its shortest text;
an error to 6 significant figures), and the rule is applied a column at a time, over a piece of students: a
column of a few distinct values (verdicts, credits, units, tolerances) is worked out once per value, and a
column of text is checked for control characters in one call before each cell is guarded. The rows are the
columns zipped, written by the one CSV writer (:func:`grader.base.spreadsheet.csv_pieces`), so the bytes are
those a row at a time gives (``tests/test_fast_paths.py`` holds the two to the same bytes on hostile text).
"""

from __future__ import annotations

import itertools
import math
import operator
from collections.abc import Callable, Iterable, Iterator, Sequence

from grader.base.errors import visible
from grader.base.spreadsheet import csv_columns_text, csv_text, number_cell, safe_cell, safe_cells
from grader.grade.compare import number_text
from grader.grade.grading import Graded, Row

DETAILS_HEADER = ("student_id", "label", "submitted", "verdict", "credit", "points", "score", "expected", "parsed",
                  "unit", "abs_error", "rel_error", "tolerance", "feedback", "diagnosis", "source", "late", "deduction")


def details_csv(graded: Graded, students_per_piece: int = 2000) -> Iterator[str]:
    """One row per (student, part): what was submitted, the verdict and why, and how many minutes late the
    row it came from was (empty: not known) with the points the late policy took. The text comes in pieces
    of ``students_per_piece`` students, to be written as it comes (a class of 100,000 has a million rows)."""
    yield csv_text([DETAILS_HEADER])
    students, labels, late = graded.key.students, graded.key.labels, graded.late
    numbers = _Cells(report_cell)  # credits, points, scores, minutes, shares: a few values
    words = _Cells(report_cell)  # verdicts, units, tolerances, diagnoses: a few texts
    guarded, step = [safe_cell(label) for label in labels], max(1, students_per_piece)
    for start in range(0, len(students), step):
        piece = slice(start, start + step)
        ids = [safe_cell(student.id) for student in students[piece]]
        by_label = [_label_cells(graded.columns[label][piece], numbers, words) for label in labels]
        for index, label in enumerate(labels):
            unknown = [None] * len(ids)  # no due time: no lateness, no deduction
            minutes = late.minutes[label][piece] if late else unknown
            shares = late.shares[label][piece] if late else unknown
            by_label[index][16:] = _mapped(minutes, numbers), _mapped([share or 0.0 for share in shares], numbers)
        columns = [[who for who in ids for _ in labels], guarded * len(ids)]
        columns += [_interleaved([cells[field] for cells in by_label]) for field in range(2, 18)]
        yield csv_columns_text(columns)


def _label_cells(rows: Sequence[Row], numbers: _Cells, words: _Cells) -> list[list[str]]:
    """The cells of one part's rows, by details.csv's column (the first two, and the last two, left empty)."""
    if not rows:
        return [[] for _ in DETAILS_HEADER]
    (submitted, verdict, credit, points, expected, parsed, unit, abs_error, rel_error, tolerance, feedback, diagnosis,
     source) = zip(*rows, strict=True)
    return [[], [], _texts(["" if text is None else text for text in submitted]), _mapped(verdict, words),
            _mapped(credit, numbers), _mapped(points, numbers),
            _mapped(list(map(operator.mul, credit, points)), numbers),
            safe_cells(expected), _texts(parsed), _mapped(unit, words), _errors(abs_error),
            _errors(rel_error), _mapped(tolerance, words), _texts(feedback), _mapped(diagnosis, words),
            _texts(source), [], []]


def _interleaved(columns: Sequence[Sequence[str]]) -> list[str]:
    """The parts' cells of one field, student by student: the first part's first cell, the second part's, ..."""
    return list(itertools.chain.from_iterable(zip(*columns, strict=True)))


def _texts(texts: Sequence[str]) -> list[str]:
    """Each text guarded and its control characters shown (``safe_cell(visible(text))``); the texts are checked
    for control characters in one call (most columns have none)."""
    if "".join(texts).isprintable():  # every text printable: visible() returns each as it is
        return safe_cells(texts)
    return [safe_cell(visible(text)) for text in texts]


def report_pieces(rows: Iterable[Sequence[object]], rows_per_piece: int = 2000) -> Iterator[str]:
    """The CSV text of ``rows``, each value a report's cell (:func:`report_cell`), in pieces of
    ``rows_per_piece`` rows written as they come; a piece's cells a column at a time, where its rows are
    equally long (a column of text checked for control characters in one call)."""
    rows = iter(rows)
    while piece := list(itertools.islice(rows, max(1, rows_per_piece))):
        if len(set(map(len, piece))) > 1 or not piece[0]:  # rows of one length, and not empty, as columns
            yield csv_text([list(map(report_cell, row)) for row in piece])
        else:
            yield csv_columns_text([_column_cells(column) for column in zip(*piece, strict=True)])


def _column_cells(column: Sequence[object]) -> list[str]:
    """A column's report cells: text checked for control characters in one call; numbers of one type (scores,
    totals: a few hundred distinct values in a class) formatted once per value."""
    kinds = set(map(type, column))
    if kinds == {str}:
        return _texts(column)  # type: ignore[arg-type]  # every cell a str
    if kinds <= _FLOATS or kinds <= _INTS:  # equal values of one type have one text (0.0 and -0.0 both "0")
        return _mapped(column, _Cells(report_cell))
    return list(map(report_cell, column))


_FLOATS, _INTS = {float, type(None)}, {int, type(None)}  # exactly: a bool is an int equal to 1 or 0, not its text


def _mapped(values: Sequence[object], cells: _Cells) -> list[str]:
    return list(map(cells.__getitem__, values))


def report_cell(value: object) -> str:
    """A report's cell: text guarded against formulas with its control characters shown; a number as its
    shortest exact text; None as empty.

    >>> report_cell("=1+1"), report_cell(2.0), report_cell(None), report_cell("a\\x1b")
    ("'=1+1", '2', '', 'a\\\\x1b')
    """
    if value is None:
        return ""
    if isinstance(value, float):
        return number_cell(value)
    if isinstance(value, int):
        return str(value)
    return safe_cell(visible(str(value)))


def _errors(values: Sequence[float | None]) -> list[str]:
    """``abs_error`` or ``rel_error``, for people: 6 significant figures, as ``expected`` and ``parsed`` (the
    verdict was decided on the numbers unrounded)."""
    if not all(map(math.isfinite, filter(None, values))):  # 0.0 and None left out: both finite
        raise ValueError("a report cell is not a finite number")  # a bug: verdicts never hold one
    return ["" if value is None else number_text(value) for value in values]


class _Cells(dict[object, str]):
    """A cell rule applied to each distinct value once: for the columns that hold a few."""

    def __init__(self, rule: Callable[[object], str]) -> None:
        super().__init__()
        self.rule = rule

    def __missing__(self, value: object) -> str:
        self[value] = self.rule(value)
        return self[value]
