"""The files a grading run writes: ``grades.csv``, ``details.csv``, ``problems.csv``, ``canvas.csv``,
``integrity.csv`` (wrong answers that another student's key accepts, :mod:`grader.grade.integrity`), and the
class report ``report.html`` (:mod:`grader.grade.class_report`).

Every text cell is guarded against formula injection (:func:`grader.base.spreadsheet.safe_cell`), but
``canvas.csv``'s, which Canvas matches on and writes back exactly (:mod:`grader.grade.canvas_file`); and
what came from a student or an input file shows its control characters as escapes
(:func:`grader.base.errors.visible`: an escape sequence a student typed is not run by the terminal that
prints the file); numbers stay numbers and are never NaN or infinite. Rows come in the key's order, so two runs on
the same inputs give byte-identical files.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Iterable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path

from grader.base.files import atomic_file, write_atomic
from grader.base.heap import hand_back
from grader.base.spreadsheet import csv_columns_text, csv_pieces, csv_text, number_cell, number_cells
from grader.grade.canvas_file import CanvasFile
from grader.grade.class_grades import ClassGrades, classwide, final_scores, lateness, totals
from grader.grade.class_report import REPORT, class_report
from grader.grade.compare import number_texts
from grader.grade.details_file import (
    DETAILS_HEAD,
    Cells,
    details_lines,
    report_cell,
    report_columns,
    report_pieces,
    written_cell,
    written_texts,
)
from grader.grade.grading import Graded
from grader.grade.integrity import Integrity, Match, check

GRADES, DETAILS, PROBLEMS, CANVAS = "grades.csv", "details.csv", "problems.csv", "canvas.csv"
INTEGRITY = "integrity.csv"


@contextmanager
def write_details(folder: Path) -> Iterator[Callable[[Graded], None]]:
    """``details.csv`` in ``folder``, written as a class is graded: the block gets a function to call with each
    piece of the class's verdicts (:func:`grader.grade.class_grades.grade_class`), in the key's order. The
    file appears when the block ends without an error."""
    with atomic_file(folder / DETAILS) as stream:
        stream.write(DETAILS_HEAD.encode("utf-8"))

        def written(graded: Graded) -> None:
            for text in details_lines(graded):
                stream.write(text.encode("utf-8"))

        yield written


def write_reports(graded: Graded | ClassGrades, folder: Path, canvas: CanvasFile) -> list[Path]:
    """Write the files but ``details.csv`` (:func:`write_details`) into ``folder`` (``canvas.csv`` as ``canvas``
    says); returns their paths."""
    graded = classwide(graded)
    integrity = check(graded)
    hand_back()
    files = {GRADES: grades_csv(graded), PROBLEMS: problems_csv(graded, canvas), CANVAS: canvas_csv(canvas),
             INTEGRITY: integrity_csv(graded, integrity), REPORT: class_report(graded, integrity)}
    for name, text in files.items():
        write_atomic(folder / name, text)
    return [folder / name for name in files]


def grades_csv(graded: ClassGrades) -> str:
    """One row per student of the key: a column per problem, the minutes late of their latest answer that
    counts (empty: not known, or nothing submitted), the points the late policy took, the total after it,
    and what was possible."""
    key, students, deductions = graded.key, graded.key.students, graded.deductions
    scores = totals(graded)
    final, ids = final_scores(graded, scores), [student.id for student in students]
    header = ["student_id", "name", "section", *(f"problem {p.key}" for p in key.problems), "late", "deduction",
              "total", "possible"]
    columns: list[Sequence[object]] = [
        ids, [student.name for student in students], [student.section for student in students],
        *(scores[problem.key].tolist() for problem in key.problems), lateness(graded),
        [deductions.get(student_id, 0.0) for student_id in ids], list(map(final.__getitem__, ids)),
        [student.possible for student in students]]
    return _csv([header]) + report_columns(columns)


INTEGRITY_HEADER = ("student_id", "label", "submitted", "parsed", "matches_id", "matches_value", "students_matched",
                    "pair_parts", "pair_labels", "wrong_parts", "close_parts", "closeness", "chance",
                    "corrected_chance", "flagged")


def integrity_csv(graded: Graded | ClassGrades, integrity: Integrity, rows_per_piece: int = 10_000) -> Iterator[str]:
    """A row per wrong answer and student whose key accepts it (up to
    :data:`~grader.grade.integrity.LISTED` per answer): what was typed and read, whose variant it matches
    and that variant's value (6 significant figures, as ``details.csv``'s ``expected``), how many students'
    values it matches in all; and the pair's figures: how many parts (and which) the student's wrong answers
    match that student's values in, how many parts the student had wrong, how many of the closest matches the
    chance counts and how close the least close of them is (in half-units of the last digit the student typed;
    empty: not read), the chance of so many matches so close by accident and that chance corrected for the
    pairs examined, and whether the pair is flagged (``yes``: at
    most the assignment's ``integrity_threshold``). In pieces of ``rows_per_piece`` rows, each cell a report's
    cell (:func:`report_cell`) as the CSV writer writes it. A report: it changes no grade."""
    yield csv_text([list(map(report_cell, INTEGRITY_HEADER))])
    graded = classwide(graded)
    students, listed, ranked = graded.key.students, integrity.listed, integrity.ranked
    flagged = ranked.flagged(integrity.threshold)
    # Most rows are a pair's own and name students, parts, values and figures that other rows name too (a
    # third of the chances are distinct): the cells of each are worked out once a piece (kept for the whole file,
    # a million students' ids, values and chances would take a gigabyte).
    words: Cells[object] = Cells(written_cell)
    counts: Cells[int | None] = Cells(written_cell)
    step = max(1, rows_per_piece)
    for start in range(0, len(listed), step):
        who: Cells[int] = Cells(lambda index: written_cell(students[index].id))
        # A value to 6 significant figures, a figure to 3 (columns for people): a number's text, which neither
        # the formula guard nor the CSV writer changes; the values new to a piece are formatted in one call.
        values: dict[float | None, str] = {}
        shown: dict[float | None, str] = {None: ""}
        piece = listed.records(start, start + step)
        submitted, parsed = _typed(graded, piece)
        at = ranked.find(listed.student[start:start + step], listed.partner[start:start + step])  # -1: not listed
        some = iter(ranked.records(at[at >= 0]))
        pairs = [None if where < 0 else next(some) for where in at.tolist()]
        flags = ["" if where < 0 else "yes" if flag else "no"
                 for where, flag in zip(at.tolist(), flagged[at].tolist(), strict=True)]
        lines = map(",".join, zip(
            map(who.__getitem__, [match.student for match in piece]), map(words.__getitem__, [m.label for m in piece]),
            written_texts(submitted), written_texts(parsed), map(who.__getitem__, [match.partner for match in piece]),
            _formatted([match.value for match in piece], values, number_texts),
            map(counts.__getitem__, [match.matches for match in piece]),
            map(counts.__getitem__, [None if pair is None else len(pair.labels) for pair in pairs]),
            written_texts(["" if pair is None else " ".join(pair.labels) for pair in pairs]),
            map(counts.__getitem__, [None if pair is None else pair.wrong for pair in pairs]),
            map(counts.__getitem__, [None if pair is None else pair.closest for pair in pairs]),
            _formatted([pair.closeness if pair is not None and math.isfinite(pair.closeness) else None
                        for pair in pairs], shown, _figures),
            _formatted([None if pair is None else pair.chance for pair in pairs], shown, _figures),
            _formatted([None if pair is None else pair.corrected for pair in pairs], shown, _figures),
            flags, strict=True))
        yield "\n".join(lines) + "\n"


def _typed(graded: ClassGrades, matches: Sequence[Match]) -> tuple[list[str], list[str]]:
    """What was typed and what it was read as, of each match's answer (one of the incorrect ones)."""
    submitted, parsed = [""] * len(matches), [""] * len(matches)
    by_label: dict[str, list[int]] = {}
    for index, match in enumerate(matches):
        by_label.setdefault(match.label, []).append(index)
    for label, indices in by_label.items():
        column, students = graded.columns[label], [matches[index].student for index in indices]
        for index, typed, read in zip(indices, column.submitted.take(students), column.parsed.take(students),
                                      strict=True):
            submitted[index], parsed[index] = typed or "", read or ""
    return submitted, parsed


def _formatted(column: Sequence[float | None], known: dict[float | None, str],
               rule: Callable[[list[float]], list[str]]) -> list[str]:
    """The cells of a column of numbers (None: empty): those ``known`` has, and the new ones (distinct) by
    ``rule`` in one call, kept in ``known``."""
    new = [value for value in dict.fromkeys(column) if value is not None and value not in known]
    known.update(zip(new, rule(new), strict=True))
    return list(map(known.__getitem__, column))


def _figures(values: list[float]) -> list[str]:
    """Chances and closeness for people: 3 significant figures."""
    return number_cells(values, 3)


def problems_csv(graded: ClassGrades, canvas: CanvasFile | None = None) -> Iterator[str]:
    """Every input row not graded, or graded with a caveat, with the reason; then the Canvas
    export's caveats (line empty: a key student the export lacks). In pieces, as :func:`_csv_pieces`."""
    header = [["file", "line", "student_id", "label", "reason"]]
    rows = ([p.file, p.line or None, p.student_id, p.label, p.reason]
            for p in (*graded.problems, *(canvas.problems if canvas else ())))
    return _csv_pieces(itertools.chain(header, rows))


def canvas_csv(canvas: CanvasFile, rows_per_piece: int = 10_000) -> Iterator[str]:
    """A Canvas gradebook import: the student columns, one column of the assignment, and its ``Points
    Possible`` row, every cell exactly as :class:`CanvasFile` has it (no formula guard: Canvas matches on
    the text), numbers as their shortest text. In pieces (an export may have 100,000 students), a piece's
    cells a column at a time (the scores, a few hundred distinct, each formatted once)."""
    head: list[Sequence[object]] = [[*canvas.columns, canvas.title],
                                    ["Points Possible", *[""] * (len(canvas.columns) - 1), canvas.points]]
    yield csv_text([[_exact(value) for value in row] for row in head])
    identities, cells, width = canvas.identities, canvas.cells, len(canvas.columns)
    if not width or any(len(identity) != width for identity in identities):  # rows not all of two cells or more
        body = ([*identity, cell] for identity, cell in zip(identities, cells, strict=True))
        yield from csv_pieces([_exact(value) for value in row] for row in body)
        return
    scores: Cells[object] = Cells(_exact)
    step = max(1, rows_per_piece)
    for start in range(0, len(identities), step):
        columns = [*zip(*identities[start:start + step], strict=True), cells[start:start + step]]
        yield csv_columns_text([column if set(map(type, column)) == {str} else list(map(_exact, column))
                                for column in columns[:-1]] + [list(map(scores.__getitem__, columns[-1]))])


def _exact(value: object) -> str:
    """A ``canvas.csv`` cell: text as it is, a number as its shortest exact text, None as empty."""
    if value is None:
        return ""
    return number_cell(value) if isinstance(value, float) else str(value)


def _csv(rows: Iterable[Sequence[object]]) -> str:
    return "".join(_csv_pieces(rows))


def _csv_pieces(rows: Iterable[Sequence[object]]) -> Iterator[str]:
    """The CSV text of ``rows``, each value a report's cell (:func:`report_cell`), in pieces written as they come."""
    return report_pieces(rows)
