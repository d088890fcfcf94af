"""A Canvas gradebook export (Grades > Export), read for ``grader grade --canvas``: its students matched
to the key's and the key's assignment found among its columns, so that ``canvas.csv`` carries Canvas'
own rows, names and ids and updates the assignment that already exists.

Canvas writes the student columns ``Student, ID, SIS User ID, SIS Login ID, Section`` (``LastName,
FirstName`` for ``Student`` where a course shows names so; ``SIS User ID``, ``Integration ID`` and
``Root Account`` only for some users and accounts), then custom columns, a ``Title (id)`` column per
assignment and the totals. Then come rows that are no students (``    Points Possible``; a row of
``Manual Posting`` or ``Muted`` marks), the students, and the test student (``Student, Test``) last.
Its import finds a row's student by ``ID`` (then SIS User ID, SIS Login ID, name) and reads the student
columns by position, so ``canvas.csv`` writes the ones the export has, in Canvas' order; it finds the
assignment by the id in ``Title (id)``, else by the exact title, else creates one.

A row's student in the key is the one whose id is the row's SIS User ID (exactly, or once leading zeros
a spreadsheet ate are restored: a caveat), else whose id or email is its SIS Login ID (ignoring case),
else whose email is in an ``Email`` column. A Canvas student who is nobody in the key keeps the export's
own score, so that the import changes nothing for them (Canvas reads an empty cell as "remove the
grade" when there is one). That, a key student absent from the export, and an excused (``EX``) student
whose ``EX`` is kept are caveats in ``problems.csv``: every submission row was still graded, and students
who dropped or joined late are routine, so they do not change the exit code.

>>> import pathlib, tempfile
>>> from grader.grade.key import Key, KeyStudent
>>> key = Key("key.json", 2, "Homework 3", True, (), (KeyStudent("00123", "Jane Doe", "jd@uni.edu", "1", {}),
...                                                   KeyStudent("s2", "Li Wei", "li@uni.edu", "1", {})))
>>> path = pathlib.Path(tempfile.mkdtemp()) / "export.csv"
>>> _ = path.write_text("Student,ID,SIS User ID,SIS Login ID,Section,Homework 3 (12345),Current Score\\n"
...                     "    Points Possible,,,,,10.00,(read only)\\n"
...                     '"Doe, Jane",4321,123,jdoe,Sec 1,,\\n"Roe, Sam",4322,,sroe,Sec 1,7.50,75\\n')
>>> export = read_export(path, key)
>>> export.columns, export.assignment
(('Student', 'ID', 'SIS User ID', 'SIS Login ID', 'Section'), 'Homework 3 (12345)')
>>> [(row.identity[0], row.key_id, row.kept) for row in export.rows]
[('Doe, Jane', '00123', None), ('Roe, Sam', None, 7.5)]
>>> [(p.line, p.student_id, p.reason.split(" (")[0]) for p in export.problems]  # doctest: +NORMALIZE_WHITESPACE
[(3, '00123', 'leading zeros restored: 123 -> 00123'), (4, 'sroe', "Canvas student 'Roe, Sam' is not in the key"),
 (0, 's2', 'in the key but not in the Canvas export: no score can be imported for them')]
"""

from __future__ import annotations

import math
import re
from collections import defaultdict
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

from grader.base.errors import GraderError, shown
from grader.base.files import shown_path
from grader.base.inputs import CsvRow, CsvStream, open_csv
from grader.grade.columns import EMAIL, normalized
from grader.grade.key import Key
from grader.grade.submissions import TEST_STUDENTS, Roster, RowProblem, StudentRef

STUDENT_COLUMNS = ("Student", "LastName", "FirstName", "ID", "SIS User ID", "SIS Login ID", "Integration ID",
                   "Root Account", "Section")  # in the order Canvas' import reads them
_REQUIRED = ("ID", "SIS Login ID", "Section")
_TITLE_ID = re.compile(r"(?P<title>.*)\s\((?P<id>\d+)\)")  # Canvas' own pattern for "Title (id)"
_POSTING = re.compile(r"\s*(?:muted|manual posting.*)?\s*", re.I)  # every cell of Canvas' posting row
_SCORE = re.compile(r"-?\d+(?:\.\d+)?")  # a score as Canvas exports it; "7,50" (decimal comma) stays text
_EXPECTED = ("a Canvas gradebook export (Grades > Export) with the columns Student (or LastName and FirstName), "
             "ID, SIS Login ID and Section")
_KEPT = "no score written, the export's score kept"
MAX_ROWS = 100_000
"""Rows an export may have: more than any course has students (tens of thousands at most). The rows kept
take a few hundred bytes a student; a 64 MiB file of short rows would be millions of them."""


@dataclass(frozen=True, slots=True)
class CanvasRow:
    """A student row of the export: its student columns as exported, and the key student whose score
    it takes, or (``key_id`` None) the export's own score ``kept``: a number, text such as ``EX``, or
    None when empty."""

    line: int
    identity: tuple[str, ...]
    key_id: str | None
    kept: float | str | None = None


@dataclass(frozen=True)
class CanvasExport:
    """What ``canvas.csv`` takes from an export: the student columns (Canvas' names, in its order),
    the assignment column's header (the export's ``Title (id)``, or the key's title when it has
    none), the student rows in export order, the caveats for ``problems.csv`` and notes."""

    path: Path
    columns: tuple[str, ...]
    assignment: str
    rows: tuple[CanvasRow, ...]
    problems: tuple[RowProblem, ...]
    notes: tuple[str, ...]


def read_export(path: Path, key: Key) -> CanvasExport:
    """Read a Canvas gradebook export and match its students to ``key``'s.

    The export is read row by row, and of each student row only what ``canvas.csv`` writes is kept
    (:class:`CanvasRow`): the memory it takes is its text and a few hundred bytes a student.

    Raises :class:`GraderError` for a file that is no usable export: unreadable, without Canvas'
    student columns, with no student rows or none the key knows, with more than :data:`MAX_ROWS` rows,
    or with two columns of the key's assignment.
    """
    stream = open_csv(path, exports=True)
    columns = _student_columns(stream)
    assignment = _assignment_column(stream, key.title)
    finder = _Finder(key, next((h for h in stream.header if normalized(h) in EMAIL), None))
    read = _read_rows(stream, columns, assignment, finder)
    if not read.taken:
        raise _unrelated(path, key, len(read.rows))
    missing = [s.id for s in key.students if s.id not in read.taken]
    problems = [*read.problems, *(RowProblem(shown_path(path), 0, student_id, "", "in the key but not in the Canvas "
                                             "export: no score can be imported for them (dropped the course, or "
                                             "enrolled under another id?)", caveat=True) for student_id in missing)]
    notes = [*_assignment_notes(stream, assignment, key), *_points_notes(stream, assignment, read.points, key),
             f"{path}: {len(read.rows)} Canvas students, {sum(r.key_id is not None for r in read.rows)} scored from "
             f"the key; key students not in the export: {len(missing)} (see problems.csv)"]
    return CanvasExport(path, tuple(columns), assignment or key.title, tuple(read.rows), tuple(problems), tuple(notes))


@dataclass(slots=True)
class _Read:
    """What the rows of an export gave: its student rows and caveats, the key students taken (and the
    line that took each), and the assignment's cell of Canvas' points-possible row (None without one)."""

    rows: list[CanvasRow] = field(default_factory=list)
    problems: list[RowProblem] = field(default_factory=list)
    taken: dict[str, int] = field(default_factory=dict)
    points: str | None = None


def _read_rows(stream: CsvStream, columns: Mapping[str, str], assignment: str | None, finder: _Finder) -> _Read:
    """The export's rows, read one at a time; refused beyond :data:`MAX_ROWS` (before the rest is read)."""
    read, file, first = _Read(), shown_path(stream.path), stream.header[0]
    for count, row in enumerate(stream.rows(), 1):
        if count > MAX_ROWS:
            raise GraderError(f"{stream.path}: line {row.line}: more than {MAX_ROWS:,} rows; expected a Canvas "
                              "gradebook export, a row per student of one course (tens of thousands at most)")
        if read.points is None and "points possible" in row.cells[first].lower():
            read.points = row.cells[assignment] if assignment else ""
        who = {name: row.cells[header] for name, header in columns.items()}
        name = who.get("Student") or f"{who.get('LastName', '')}, {who.get('FirstName', '')}"
        if not _is_student(row, name):
            continue
        if row.problem is not None:
            read.problems.append(RowProblem(file, row.line, _canvas_id(who), "",
                                            f"{row.problem.split(': ', 1)[-1]}: left out of canvas.csv", caveat=True))
            continue
        current = row.cells[assignment] if assignment else ""
        key_id, caveat = finder.find(who, row.cells)
        reason = _not_scored(key_id, name, read.taken, current)
        if key_id is not None:
            read.taken.setdefault(key_id, row.line)
        if reason or caveat:
            read.problems.append(RowProblem(file, row.line, key_id or _canvas_id(who), "", reason or caveat,
                                            caveat=True))
        read.rows.append(CanvasRow(row.line, tuple(who.values()), None if reason else key_id,
                                   _kept(current) if reason else None))
    return read


def _unrelated(path: Path, key: Key, students: int) -> GraderError:
    """The refusal of an export none of whose students is in the key."""
    if not students:
        return GraderError(f"{path}: no student rows; expected {_EXPECTED}, and a row per student")
    return GraderError(f"{path}: none of its {students} students is in the key {key.where} (by SIS User ID, SIS "
                       "Login ID or email); expected the Canvas gradebook export of this assignment's course")


def _student_columns(stream: CsvStream) -> dict[str, str]:
    """Canvas' student columns the export has, in Canvas' order: Canvas' name -> the header as written."""
    written = {normalized(header): header for header in stream.header}
    found = {name: written[normalized(name)] for name in STUDENT_COLUMNS if normalized(name) in written}
    if "Student" in found:  # Canvas writes Student, or LastName and FirstName
        found = {name: header for name, header in found.items() if name not in ("LastName", "FirstName")}
    named = "Student" in found or {"LastName", "FirstName"} <= found.keys()
    if not named or any(name not in found for name in _REQUIRED):
        raise GraderError(f"{stream.path}: line {stream.header_line}: expected {_EXPECTED}; got the columns "
                          f"{shown(list(stream.header), 160)}")
    return found


def _assignment_column(stream: CsvStream, title: str) -> str | None:
    """The export's ``Title (id)`` column of the key's assignment: its title exactly, else ignoring
    case and spacing; None when there is none. Two are refused: the import would update one of them."""
    titled = [(header, match["title"]) for header in stream.header if (match := _TITLE_ID.fullmatch(header))]
    found = ([header for header, text in titled if text == title]
             or [header for header, text in titled if _folded(text) == _folded(title)])
    if len(found) > 1:
        raise GraderError(f"{stream.path}: line {stream.header_line}: the columns {shown(found[0])} and "
                          f"{shown(found[1])} both have the key's assignment title {shown(title)}; expected one "
                          "(delete the other assignment's column from the export, or retitle it in Canvas)")
    return found[0] if found else None


def _folded(title: str) -> str:
    return " ".join(title.split()).casefold()


def _is_student(row: CsvRow, name: str) -> bool:
    """Whether a row is a student's: not Canvas' points-possible or posting row, nor its test student."""
    if "points possible" in name.lower() or all(_POSTING.fullmatch(cell) for cell in row.cells.values()):
        return False
    return " ".join(name.split()).lower() not in TEST_STUDENTS


class _Finder:
    """The key student a Canvas row names: by SIS User ID, then SIS Login ID, then email."""

    def __init__(self, key: Key, email_column: str | None) -> None:
        self.roster = Roster([StudentRef(s.id, s.email) for s in key.students])
        self.logins: dict[str, list[str]] = defaultdict(list)
        for student in key.students:
            self.logins[student.id.casefold()].append(student.id)
        self.email_column = email_column

    def find(self, who: Mapping[str, str], cells: Mapping[str, str]) -> tuple[str | None, str]:
        """The key student's id, or None; and a caveat ("" if none)."""
        if who.get("SIS User ID"):
            found, why, _ = self.roster.find(who["SIS User ID"], by_email=False)
            if found is not None:
                return found, why
        login = who["SIS Login ID"]
        if len(self.logins.get(login.casefold(), [])) == 1:
            return self.logins[login.casefold()][0], ""
        for text in (login, cells[self.email_column] if self.email_column else ""):
            found = self.roster.find(text, by_email=True)[0] if text else None
            if found is not None:
                return found, ""
        return None, ""


def _not_scored(key_id: str | None, name: str, taken: Mapping[str, int], current: str) -> str:
    """Why a student row gets no score from the key, or ""."""
    if key_id is None:
        return f"Canvas student {shown(name)} is not in the key (by SIS User ID, SIS Login ID or email): {_KEPT}"
    if key_id in taken:
        return f"names the key student {key_id}, as line {taken[key_id]} does: {_KEPT}"
    if current.upper() == "EX":
        return "excused (EX) in Canvas: EX kept, the key's score not written"
    return ""


def _canvas_id(who: Mapping[str, str]) -> str:
    """The id a student row shows: SIS User ID, else SIS Login ID, else Canvas' own."""
    return who.get("SIS User ID") or who["SIS Login ID"] or who["ID"]


def _kept(text: str) -> float | str | None:
    """An export's score as ``canvas.csv`` writes it back: a number stays a number (so ``-1.5`` is not
    guarded as if it were a formula), other text stays text (a number of 400 digits too: as a float
    it would be infinite), empty is None."""
    score = _score(text)
    return text or None if score is None else score


def _score(text: str) -> float | None:
    """A score as Canvas exports it, as a finite number; None for any other text."""
    if not _SCORE.fullmatch(text):
        return None
    score = float(text)
    return score if math.isfinite(score) else None


def _assignment_notes(stream: CsvStream, column: str | None, key: Key) -> list[str]:
    if column is None:
        return [f"{stream.path}: no column {shown(key.title + ' (id)')}; canvas.csv's column is titled "
                f"{shown(key.title)}: Canvas updates the assignment of exactly that title, or creates one"]
    match = _TITLE_ID.fullmatch(column)
    if match and match["title"] != key.title:
        return [f"{stream.path}: the column {shown(column)} taken as the key's assignment {shown(key.title)} "
                "(the titles differ in case or spacing)"]
    return []


def _points_notes(stream: CsvStream, column: str | None, points_cell: str | None, key: Key) -> list[str]:
    """A note when Canvas' points possible for the assignment (``points_cell``: its cell of Canvas'
    points-possible row) are not what the key's students can earn (the import does not change an existing
    assignment's points: scores would read as a fraction of Canvas' points)."""
    points = _score(points_cell.replace(",", ".")) if points_cell and column else None
    if points is None or math.isclose(points, key.possible):
        return []
    return [f"{stream.path}: Canvas gives {shown(column)} {points:g} points possible, the key's students can "
            f"earn {key.possible:g}: change the assignment's points in Canvas, or the scores read as a fraction of "
            f"{points:g}"]
