"""What ``canvas.csv`` holds, cell by cell, so that Canvas' gradebook import (``lib/gradebook_importer.rb``
and the upload page, ``ui/features/gradebook_uploads``) does what the instructor means and nothing else.

- Every cell is written exactly: Canvas reads cells as data, never as formulas, and matches students and
  the assignment on the text (a guard ``'`` would make ``@Home Lab`` a new assignment and ``-2026174`` no
  student's SIS User ID). ``canvas.csv`` is for Canvas; ``grades.csv`` is the file to open in a spreadsheet.
- A student who submitted nothing (``missing``): ``zero`` gives 0, ``blank`` no score of grader's (with an
  export, the cell as exported: Canvas changes nothing; without, an empty cell, which removes a grade Canvas
  has). By default, 0 unless an export shows a grade for them, which is kept.
- The export's ``EX`` (excused) and ``N/A`` (the assignment is not assigned to the student: Canvas ignores a
  score) are kept, with a caveat; so is every cell when Canvas hides the assignment's scores from instructors
  (``Manual Posting (scores hidden from instructors)``): Canvas refuses grades for it then.
- A score kept from the export is written as Canvas' import reads it: ``17,50`` (a decimal comma) is 17.5.
- ``Points Possible`` is the export's own (another value marks the assignment as changed, and the upload
  page never changes it), else the key's.

>>> from grader.grade.key import Key, KeyStudent
>>> key = Key("key.json", 2, "@Home Lab", True, (), (KeyStudent("-2026174", "Priya Raman", "pr@uni.edu", "1", {}),))
>>> made = canvas_file(key, {"-2026174": 0.0}, set(), None, None)
>>> made.title, made.identities, made.cells, made.points
('@Home Lab', [('Priya Raman', '', '-2026174', 'pr@uni.edu', '1')], [0.0], 0.0)
>>> kept_cell("17,50"), kept_cell("EX"), kept_cell(""), kept_cell("1.234,5")
(17.5, 'EX', None, 1234.5)
"""

from __future__ import annotations

import math
import re
from collections import Counter
from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass

from grader.base.errors import shown
from grader.base.files import shown_path
from grader.grade.canvas import TITLE_ID, CanvasExport, CanvasRow
from grader.grade.key import Key
from grader.grade.submissions import RowProblem

MISSING = ("zero", "blank")
"""What ``--missing`` may say canvas.csv gives a student who submitted nothing."""
NO_EXPORT_COLUMNS = ("Student", "ID", "SIS User ID", "SIS Login ID", "Section")
_NUMBER = re.compile(r"-?[0-9.,]+")  # Canvas' decimal_comma_to_period converter takes these (and a %)
Cell = float | str | None


@dataclass(frozen=True)
class CanvasFile:
    """``canvas.csv``: its student columns and assignment title, the ``Points Possible`` cell, a row of
    student cells (``identities``) and the assignment's cell (``cells``) per student, the caveats for
    ``problems.csv`` (the export's, in line order) and notes."""

    columns: tuple[str, ...]
    title: str
    points: Cell
    identities: Sequence[tuple[str, ...]]
    cells: Sequence[Cell]
    problems: tuple[RowProblem, ...]
    notes: tuple[str, ...]


def canvas_file(key: Key, scores: Mapping[str, float], submitted: Collection[str], export: CanvasExport | None,
                missing: str | None) -> CanvasFile:
    """``canvas.csv`` of a grading run: ``scores`` per key student (after any late deduction), ``submitted``
    the ids of students who submitted anything, on an ``export`` (or the key's students and title),
    ``missing`` ``zero``, ``blank`` or None (the default: see the module)."""
    if export is None:
        return _without_export(key, scores, submitted, missing)
    hidden = _hidden(export)
    decided = [_cell(row, scores, submitted, missing, hidden) for row in export.rows]
    file = shown_path(export.path)
    problems = [RowProblem(file, row.line, row.key_id or "", "", why, caveat=True)
                for row, (_, why, _) in zip(export.rows, decided, strict=True) if why]
    kinds = Counter(kind for _, _, kind in decided if kind)
    points = kept_cell(export.points) if export.found and export.points is not None else float(key.possible)
    notes = [*export.notes, *_points_notes(export, points, key), *_missing_notes(export, kinds, missing)]
    if hidden:
        notes.append(f"{export.path}: Canvas hides {shown(export.assignment)}'s scores from instructors "
                     f"({shown(export.posting)}) and refuses grades for it until they are posted: canvas.csv keeps the "
                     "export's cells; post the grades in Canvas, export again and grade again with it")
    return CanvasFile(export.columns, export.assignment, points, [row.identity for row in export.rows],
                      [cell for cell, _, _ in decided], tuple(sorted((*export.problems, *problems),
                                                                    key=lambda p: (p.line == 0, p.line))), tuple(notes))


def _hidden(export: CanvasExport) -> bool:
    """Whether Canvas' posting row says the assignment's scores are hidden from instructors: "Manual
    Posting" followed by more (the exporter's ``hidden_assignment_text``; the words after it are translated)."""
    text = (export.posting or "").strip()
    return text.lower().startswith("manual posting") and len(text) > len("manual posting")


def _cell(row: CanvasRow, scores: Mapping[str, float], submitted: Collection[str], missing: str | None,
          hidden: bool) -> tuple[Cell, str, str]:
    """A row's cell of the assignment, why it is not the key's score ("" if it is, or the row is nobody's)
    and what was done for a student who submitted nothing ("" otherwise)."""
    kept = kept_cell(row.current)
    if row.key_id is None or hidden:
        return kept, "", ""
    if row.current.upper() == "EX":
        return kept, "excused (EX) in Canvas: EX kept, the key's score not written", ""
    if row.current.upper() == "N/A":
        return kept, ("N/A in Canvas: the assignment is not assigned to this student, and Canvas ignores a score "
                      "for them: N/A kept, the key's score not written"), ""
    if row.key_id in submitted:
        return scores[row.key_id], "", ""
    if missing == "zero" or (missing is None and kept is None):
        return 0.0, "", "zero"
    return kept, "", "kept" if kept is not None else "blank"


def kept_cell(text: str) -> Cell:
    """An export's cell as ``canvas.csv`` writes it back: as Canvas' import reads it (its
    ``decimal_comma_to_period`` converter: the last ``,`` or ``.`` of a number is its decimal point), a
    number as a plain number, other text as it is (a number of 400 digits too: as a float it would be
    infinite), empty as None."""
    if not text:
        return None
    if not _NUMBER.fullmatch(text):
        return text
    *whole, last = re.split(r"[,.]", text)
    number = f"{''.join(whole)}.{last}" if whole else last
    try:
        value = float(number)
    except ValueError:  # "1,,2", "-", ".": not a number Canvas reads either
        return text
    return value if math.isfinite(value) else text


def _without_export(key: Key, scores: Mapping[str, float], submitted: Collection[str],
                    missing: str | None) -> CanvasFile:
    absent = [s.id for s in key.students if s.id not in submitted]
    blank = missing == "blank"
    cells: list[Cell] = [None if blank and s.id not in submitted else scores[s.id] for s in key.students]
    title = key.title
    by_id = f"; Canvas reads the title's {shown(m['id'])} as an assignment's id" if (m := TITLE_ID.fullmatch(title)) \
        else ""
    notes = [f"canvas.csv, made without a Canvas export: Canvas updates only a published assignment titled exactly "
             f"{shown(title)}{by_id} (else it creates one), and finds students by SIS User ID (the key's ids), "
             "SIS Login ID (emails), then name; to update the assignment by its id and keep grades Canvas has, "
             "grade with --canvas EXPORT.csv (Canvas: Grades > Export)"]
    if absent:
        done = ("an empty cell (--missing blank), which removes a grade Canvas has for them" if blank else
                "0, which replaces a grade or EX Canvas has for them (--missing blank: an empty cell, which "
                "removes it)")
        notes.append(f"canvas.csv: {_students(len(absent))} submitted nothing and got {done}; with --canvas "
                     "EXPORT.csv their grades and EX in Canvas are kept")
    return CanvasFile(NO_EXPORT_COLUMNS, title, float(key.possible),
                      [(s.name, "", s.id, s.email, s.section) for s in key.students], cells, (), tuple(notes))


def _students(n: int) -> str:
    return f"{n} student{'' if n == 1 else 's'}"


def _missing_notes(export: CanvasExport, kinds: Mapping[str, int], missing: str | None) -> list[str]:
    """What was done for the matched students who submitted nothing."""
    if not sum(kinds.values()):
        return []
    parts = [f"{kinds['zero']} got 0" + (" (--missing zero)" if missing else " (the export shows no grade for them)"),
             f"{kinds['kept']} kept the grade the export shows" + ("" if missing else " (--missing zero writes 0)"),
             f"{kinds['blank']} got no score (--missing blank)"]
    return [f"{export.path}: of the key's students who submitted nothing, "
            f"{', '.join(part for part in parts if not part.startswith('0 '))}"]


def _points_notes(export: CanvasExport, points: Cell, key: Key) -> list[str]:
    """A note when Canvas' points possible for the assignment are not what the key's students can earn
    (canvas.csv writes Canvas' own: the import does not change an existing assignment's points, and
    scores would read as a fraction of Canvas' points)."""
    if not export.found or not isinstance(points, float) or math.isclose(points, key.possible):
        return []
    return [f"{export.path}: Canvas gives {shown(export.assignment)} {points:g} points possible, the key's students "
            f"can earn {key.possible:g}: canvas.csv keeps Canvas' {points:g}; change the assignment's points in "
            f"Canvas, or the scores read as a fraction of {points:g}"]
