"""``details.csv``: a row per (student, part), written a column at a time.

A class of 100,000 has a million rows of 18 cells. Each cell is the report's rule for its field (text guarded
against formulas with its control characters shown, :mod:`grader.grade.report`; a number as its shortest text;
an error to 6 significant figures), and the rule is applied a column at a time, over a piece of students: the
cells of a few distinct values (a verdict with its credit, points and score; units, tolerances, diagnoses;
lateness) are worked out and quoted as the CSV writer quotes them once per value, the errors are formatted in
one call per column, and a column of text is checked for control characters, and for what the writer quotes,
each in one search of its joined text. A part's rows are joined a row at a time, and the parts' rows interleaved
student by student, so the bytes are those the one CSV writer (:func:`grader.base.spreadsheet.csv_pieces`)
gives a row at a time (``tests/test_fast_paths.py`` holds the two to the same bytes on hostile text).
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Iterable, Iterator, Sequence
from typing import Generic, NamedTuple, TypeVar

import numpy as np

from grader.base.errors import visible
from grader.base.spreadsheet import (
    csv_columns_text,
    csv_text,
    number_cell,
    quoted_cell,
    quoted_cells,
    safe_cell,
    safe_cells,
)
from grader.grade.grading import Graded, Row

DETAILS_HEADER = ("student_id", "label", "submitted", "verdict", "credit", "points", "score", "expected", "parsed",
                  "unit", "abs_error", "rel_error", "tolerance", "feedback", "diagnosis", "source", "late", "deduction")


def details_csv(graded: Graded, students_per_piece: int = 2000) -> Iterator[str]:
    """One row per (student, part): what was submitted, the verdict and why, and how many minutes late the
    row it came from was (empty: not known) with the points the late policy took. The text comes in pieces
    of ``students_per_piece`` students, to be written as it comes (a class of 100,000 has a million rows)."""
    yield DETAILS_HEAD
    yield from details_lines(graded, students_per_piece)


DETAILS_HEAD = csv_text([DETAILS_HEADER])


def details_lines(graded: Graded, students_per_piece: int = 2000) -> Iterator[str]:
    """:func:`details_csv`'s rows without its header (a piece of a class's: :func:`grader.grade.run.run`)."""
    students, labels, late = graded.key.students, graded.key.labels, graded.late
    cells = _Rules(Cells(_marks), Cells(written_cell), Cells(_lateness))
    guarded, step = [quoted_cell(safe_cell(label)) for label in labels], max(1, students_per_piece)
    for start in range(0, len(students), step):
        piece = slice(start, start + step)
        ids = quoted_cells(safe_cells([student.id for student in students[piece]]))
        lines = [_label_lines(ids, label_cell, graded.columns[label][piece],
                              (late.minutes[label][piece], late.shares[label][piece]) if late else None, cells)
                 for label, label_cell in zip(labels, guarded, strict=True)]
        text = "\n".join(itertools.chain.from_iterable(zip(*lines, strict=True)))  # student by student
        yield text + "\n" if text else ""


def _label_lines(ids: Sequence[str], label: str, rows: Sequence[Row],
                 late: tuple[Sequence[int | None], Sequence[float | None]] | None, rules: _Rules) -> list[str]:
    """The lines (without their ends) of one part's rows, one per student of ``ids`` (their cells as written)."""
    if not rows:
        return []
    (submitted, verdict, credit, points, expected, parsed, unit, abs_error, rel_error, tolerance, feedback, diagnosis,
     source) = zip(*rows, strict=True)
    given = ["" if text is None else text for text in submitted] if None in submitted else submitted
    marks = map(rules.marks.__getitem__, zip(verdict, credit, points, strict=True))
    when = map(rules.lateness.__getitem__, zip(*late, strict=True)) if late else itertools.repeat(rules.lateness[()])
    words = rules.words.__getitem__
    cells = (ids, itertools.repeat(label), written_texts(given), marks, quoted_cells(safe_cells(expected)),
             written_texts(parsed), map(words, unit), _errors(abs_error, rel_error), map(words, tolerance),
             written_texts(feedback), map(words, diagnosis), written_texts(source), when)
    return list(map(",".join, zip(*cells, strict=False)))  # strict=False: the label and lateness repeat


def _marks(mark: tuple[str, float, float]) -> str:
    """A verdict's cells ``verdict,credit,points,score``, from (verdict, credit, points)."""
    verdict, credit, points = mark
    return ",".join(quoted_cell(report_cell(cell)) for cell in (verdict, credit, points, credit * points))


def written_cell(value: object) -> str:
    """A report's cell (:func:`report_cell`) as the CSV writer writes it.

    >>> written_cell("±1 %, widened"), written_cell(2.0)
    ('"±1 %, widened"', '2')
    """
    return quoted_cell(report_cell(value))


def _lateness(when: tuple[int | None, float | None] | tuple[()]) -> str:
    """The cells ``late,deduction`` from (minutes late, the part's share of the deduction); () for a key
    without due times (no lateness, no deduction)."""
    minutes, share = when or (None, None)
    return report_cell(minutes) + "," + report_cell(share or 0.0)


def written_texts(texts: Sequence[str]) -> Sequence[str]:
    """A column of text as a report writes it: each text guarded with its control characters shown
    (:func:`_texts`), and quoted where the CSV writer quotes it."""
    return quoted_cells(_texts(texts))


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


def report_columns(columns: Sequence[Sequence[object]]) -> str:
    """The CSV text of the rows that ``columns`` make, each value a report's cell (:func:`report_cell`), worked
    out a column at a time as :func:`report_pieces` does.

    >>> report_columns([["=a", "b"], [1.0, None]])
    "'=a,1\\nb,\\n"
    """
    return csv_columns_text([_column_cells(column) for column in columns])


def _column_cells(column: Sequence[object]) -> list[str]:
    """A column's report cells: text checked for control characters in one call; numbers of one type (scores,
    totals: a few hundred distinct values in a class) formatted once per value."""
    kinds = set(map(type, column))
    if kinds == {str}:
        return _texts(column)  # type: ignore[arg-type]  # every cell a str
    if kinds <= _FLOATS or kinds <= _INTS:  # equal values of one type have one text (0.0 and -0.0 both "0")
        return _mapped(column, Cells[object](report_cell))
    return list(map(report_cell, column))


_FLOATS, _INTS = {float, type(None)}, {int, type(None)}  # exactly: a bool is an int equal to 1 or 0, not its text


def _mapped(values: Sequence[object], cells: Cells[object]) -> list[str]:
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


def _errors(abs_error: Sequence[float | None], rel_error: Sequence[float | None]) -> list[str]:
    """The cells ``abs_error,rel_error`` of a part's rows, for people: each error as :func:`number_text`
    writes it (6 significant figures, as ``expected`` and ``parsed``; the verdict was decided on the numbers
    unrounded; never ``-0``), formatted in one call (None, read as NaN, written as empty)."""
    values = np.array([abs_error, rel_error], dtype=np.float64).T + 0.0  # + 0.0: -0.0 is written "0"
    absent = abs_error.count(None) + rel_error.count(None)
    if int(np.isfinite(values).sum()) != values.size - absent:
        raise ValueError("a report cell is not a finite number")  # a bug: verdicts never hold one
    text = "%.6g,%.6g\n" * len(values) % tuple(values.ravel().tolist())  # number_text's format
    lines = (text.replace("nan", "") if absent else text).split("\n")  # no number written with %g holds "nan"
    lines.pop()  # after the last line end
    return lines


class _Rules(NamedTuple):
    """The cells of the columns of a few distinct values, each value's worked out once."""

    marks: Cells[tuple[str, float, float]]  # (verdict, credit, points): ``verdict,credit,points,score``
    words: Cells[object]  # units, tolerances, diagnoses
    lateness: Cells[tuple[int | None, float | None] | tuple[()]]  # (minutes, share), or (): ``late,deduction``


Value = TypeVar("Value")


class Cells(dict[Value, str], Generic[Value]):
    """A cell rule applied to each distinct value once: for the columns that hold a few."""

    def __init__(self, rule: Callable[[Value], str]) -> None:
        super().__init__()
        self.rule = rule

    def __missing__(self, value: Value) -> str:
        self[value] = self.rule(value)
        return self[value]
