"""The files a grading run writes: ``grades.csv``, ``details.csv``, ``problems.csv``, ``canvas.csv``.

Every text cell is guarded against formula injection (:func:`grader.assign.keyfile.safe_cell`);
numbers stay numbers and are never NaN or infinite. Rows come in the key's order, so two runs on
the same inputs give byte-identical files.
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Iterable, Sequence
from pathlib import Path

from grader.assign.keyfile import safe_cell
from grader.files import write_atomic
from grader.grade.canvas import CanvasExport
from grader.grade.grading import Graded, totals

GRADES, DETAILS, PROBLEMS, CANVAS = "grades.csv", "details.csv", "problems.csv", "canvas.csv"


def write_reports(graded: Graded, folder: Path, export: CanvasExport | None = None) -> list[Path]:
    """Write the four files into ``folder`` (``canvas.csv`` after a Canvas ``export`` when one is
    given); returns their paths."""
    files = {GRADES: grades_csv(graded), DETAILS: details_csv(graded), PROBLEMS: problems_csv(graded, export),
             CANVAS: canvas_csv(graded, export)}
    for name, text in files.items():
        write_atomic(folder / name, text)
    return [folder / name for name in files]


def grades_csv(graded: Graded) -> str:
    """One row per student of the key: a column per problem, the total and what was possible."""
    key = graded.key
    scores = totals(graded)
    rows: list[list[object]] = [["student_id", "name", "section", *(f"problem {p.key}" for p in key.problems),
                                 "total", "possible"]]
    for student in key.students:
        per_problem = [scores[student.id][p.key] for p in key.problems]
        rows.append([student.id, student.name, student.section, *per_problem, sum(per_problem), student.possible])
    return _csv(rows)


def details_csv(graded: Graded) -> str:
    """One row per (student, part): what was submitted, the verdict and why."""
    rows: list[list[object]] = [["student_id", "label", "submitted", "verdict", "credit", "points", "score",
                                 "expected", "parsed", "unit", "abs_error", "rel_error", "tolerance", "feedback",
                                 "source"]]
    for v in graded.verdicts:
        rows.append([v.student_id, v.label, "" if v.submitted is None else v.submitted, v.verdict, v.credit,
                     v.points, v.score, v.expected, v.parsed, v.unit, v.abs_error, v.rel_error, v.tolerance,
                     v.feedback, v.source])
    return _csv(rows)


def problems_csv(graded: Graded, export: CanvasExport | None = None) -> str:
    """Every input row not graded, or graded with a caveat, with the reason; then the Canvas
    export's caveats (line empty: a key student the export lacks)."""
    rows: list[list[object]] = [["file", "line", "student_id", "label", "reason"]]
    rows += [[p.file, p.line or None, p.student_id, p.label, p.reason]
             for p in (*graded.problems, *(export.problems if export else ()))]
    return _csv(rows)


def canvas_csv(graded: Graded, export: CanvasExport | None = None) -> str:
    """A Canvas gradebook import: the student columns Canvas wants, one column of the assignment, and
    its ``Points Possible`` row. Without an ``export``, a row per student of the key, named as the key
    names them; with one, its student rows and columns as exported, and its ``Title (id)`` header."""
    key = graded.key
    scores = {student_id: sum(by_problem.values()) for student_id, by_problem in totals(graded).items()}
    columns: tuple[str, ...]
    if export is None:
        columns, title = ("Student", "ID", "SIS User ID", "SIS Login ID", "Section"), key.title
        body: list[list[object]] = [[s.name, "", s.id, s.email, s.section, scores[s.id]] for s in key.students]
    else:
        columns, title = export.columns, export.assignment
        body = [[*row.identity, row.kept if row.key_id is None else scores[row.key_id]] for row in export.rows]
    return _csv([[*columns, title], ["Points Possible", *[""] * (len(columns) - 1), key.possible], *body])


def _csv(rows: Iterable[Sequence[object]]) -> str:
    stream = io.StringIO()
    writer = csv.writer(stream, lineterminator="\n")
    for row in rows:
        writer.writerow([_cell(value) for value in row])
    return stream.getvalue()


def _cell(value: object) -> str:
    """Text guarded against formulas; a number as its shortest exact text; None as empty."""
    if value is None:
        return ""
    if isinstance(value, float):
        if not math.isfinite(value):
            raise ValueError("a report cell is not a finite number")  # a bug: verdicts never hold one
        return repr(value + 0.0).removesuffix(".0") if value.is_integer() and abs(value) < 1e15 else repr(value)
    if isinstance(value, int):
        return str(value)
    return safe_cell(str(value))
