"""A Canvas gradebook export (Grades > Export), read for ``grader grade --canvas``: its students matched
to the key's and the key's assignment found among its columns, so that ``canvas.csv`` carries Canvas'
own rows, names and ids and updates the assignment that already exists (:mod:`grader.grade.canvas_file`
decides each cell).

Canvas writes the student columns ``Student, ID, SIS User ID, SIS Login ID, Section`` (``LastName,
FirstName`` for ``Student`` where a course shows names so; ``SIS User ID``, ``Integration ID`` and
``Root Account`` only for some users and accounts), then custom columns, a ``Title (id)`` column per
assignment and the totals. Then come rows that are no students (``    Points Possible``; a row of
``Manual Posting`` marks), the students, and the test student (``Student, Test``) last. Its import
(``lib/gradebook_importer.rb``) reads the student columns by position, so ``canvas.csv`` writes the ones
the export has, in Canvas' order; it finds the assignment by the id in ``Title (id)``, else by the exact
title among published assignments, else creates one.

A row's student in the key is found as Canvas' import finds its own (``process_student``): by ``ID``
(a key made from Canvas ids), then ``SIS User ID`` (exactly, or once leading zeros a spreadsheet ate are
restored: a caveat), then ``SIS Login ID`` (the key's id or email, exactly: Canvas compares logins with
their case), and last by name or sortable name (``Raman, Priya`` for Priya Raman), only where the name is
one key student's and one unmatched row's: a caveat says so. A Canvas student who is nobody in the key,
a second row of one key student, and a key student absent from the export are caveats in
``problems.csv``: every submission row was still graded, and students who dropped or joined late are
routine, so they do not change the exit code.

>>> import pathlib, tempfile
>>> from grader.grade.key import Key, KeyStudent
>>> key = Key("key.json", 2, "Homework 3", True, (), (KeyStudent("00123", "Jane Doe", "jd@uni.edu", "1", {}),
...                                                   KeyStudent("s2", "Li Wei", "li@uni.edu", "1", {})))
>>> path = pathlib.Path(tempfile.mkdtemp()) / "export.csv"
>>> _ = path.write_text("Student,ID,SIS User ID,SIS Login ID,Section,Homework 3 (12345),Current Score\\n"
...                     "    Points Possible,,,,,10.00,(read only)\\n"
...                     '"Doe, Jane",4321,123,jdoe,Sec 1,,\\n"Wei, Li",4322,,lwei,Sec 1,7.50,75\\n')
>>> export = read_export(path, key)
>>> export.columns, export.assignment, export.points
(('Student', 'ID', 'SIS User ID', 'SIS Login ID', 'Section'), 'Homework 3 (12345)', '10.00')
>>> [(row.identity[0], row.key_id, row.current, row.by_name) for row in export.rows]
[('Doe, Jane', '00123', '', False), ('Wei, Li', 's2', '7.50', True)]
>>> [(p.line, p.student_id, p.reason.split(":")[0]) for p in export.problems]
[(3, '00123', 'leading zeros restored'), (4, 's2', "matched by name, 'Wei, Li' is the key's Li Wei")]
"""

from __future__ import annotations

import re
from collections import Counter, defaultdict
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path

from grader.base.errors import GraderError, shown
from grader.base.files import shown_path
from grader.base.inputs import CsvStream, open_csv
from grader.grade.columns import normalized
from grader.grade.key import Key
from grader.grade.submissions import TEST_STUDENTS, Roster, RowProblem, StudentRef

STUDENT_COLUMNS = ("Student", "LastName", "FirstName", "ID", "SIS User ID", "SIS Login ID", "Integration ID",
                   "Root Account", "Section")  # in the order Canvas' export writes and its import reads them
_REQUIRED = ("ID", "SIS Login ID", "Section")
TITLE_ID = re.compile(r"(?P<title>.*)\s\((?P<id>\d+)\)")  # Canvas' Assignment.title_and_id: "Title (id)"
_SKIPPED = frozenset(";, ")  # what a line Canvas' import skips is made of
_POSTING = re.compile(r"\s*(?:muted|manual posting.*)?\s*", re.I)  # every cell of Canvas' posting row
_EXPECTED = ("a Canvas gradebook export (Grades > Export) with the columns Student (or LastName and FirstName), "
             "ID, SIS Login ID and Section")
_KEPT = "no score written, the export's cell kept"
_BY = "by ID, SIS User ID, SIS Login ID or a name of one key student"
MAX_ROWS = 100_000
"""Rows an export may have: more than any course has students (tens of thousands at most). The rows kept
take a few hundred bytes a student; a 64 MiB file of short rows would be millions of them."""
_SUFFIXES = re.compile(r"(Sn?r\.?|Senior|Jn?r\.?|Junior|II|III|IV|V|VI|Esq\.?|Esquire)", re.I)  # Canvas' User


@dataclass(frozen=True, slots=True)
class CanvasRow:
    """A student row of the export: its student columns as exported, its cell of the assignment as
    exported (``current``: stripped, as Canvas' import strips it; "" without a column), and the key
    student whose score it may take (None: nobody's, its cell stays as exported); ``by_name``: matched by
    name, as Canvas' import matches last."""

    line: int
    identity: tuple[str, ...]
    key_id: str | None
    current: str = ""
    by_name: bool = False


@dataclass(frozen=True)
class CanvasExport:
    """What ``canvas.csv`` takes from an export: the student columns (Canvas' names, in its order),
    the assignment column's header (the export's ``Title (id)``, or the key's title when it has
    none) and its cells of Canvas' points-possible and posting rows (None without the row or the column),
    the student rows in export order, the caveats for ``problems.csv`` and notes."""

    path: Path
    columns: tuple[str, ...]
    assignment: str
    found: bool  # whether the export has the assignment's column
    points: str | None
    posting: str | None
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
    finder = _Finder(key)
    read = _read_rows(stream, columns, assignment, finder)
    _match_by_name(read, finder, shown_path(path))
    if not read.taken:
        raise _unrelated(path, key, len(read.rows))
    missing = [s for s in key.students if s.id not in read.taken]
    named = _unmatched_lines(read)
    problems = sorted((*read.problems, *(_absent(shown_path(path), s.id, named.get(s.name.strip(), []) or
                                                 named.get(sortable_name(s.name), [])) for s in missing)),
                      key=lambda p: (p.line == 0, p.line))
    by_name = sum(row.by_name for row in read.rows)
    notes = [*_assignment_notes(stream, assignment, key),
             f"{path}: {len(read.rows)} Canvas students, {sum(r.key_id is not None for r in read.rows)} matched to "
             f"the key ({by_name} by name); key students not in the export: {len(missing)} (see problems.csv)"]
    return CanvasExport(path, tuple(columns), assignment or key.title, assignment is not None, read.points,
                        read.posting, tuple(read.rows), tuple(problems), tuple(notes))


@dataclass(slots=True)
class _Read:
    """What the rows of an export gave: its student rows and caveats, the key students taken (and the
    line that took each), the assignment's cells of Canvas' points-possible and posting rows (None without
    one), and each unmatched row's name and shown id (by its place in ``rows``), for the match by name."""

    rows: list[CanvasRow] = field(default_factory=list)
    problems: list[RowProblem] = field(default_factory=list)
    taken: dict[str, int] = field(default_factory=dict)
    points: str | None = None
    posting: str | None = None
    unmatched: dict[int, tuple[str, str]] = field(default_factory=dict)


def _read_rows(stream: CsvStream, columns: Mapping[str, str], assignment: str | None, finder: _Finder) -> _Read:
    """The export's rows, read one at a time; refused beyond :data:`MAX_ROWS` (before the rest is read)."""
    read, file, first = _Read(), shown_path(stream.path), stream.header[0]
    for count, row in enumerate(stream.rows(), 1):
        if count > MAX_ROWS:
            raise GraderError(f"{stream.path}: line {row.line}: more than {MAX_ROWS:,} rows; expected a Canvas "
                              "gradebook export, a row per student of one course (tens of thousands at most)")
        if "Points Possible" in row.cells[first]:  # as Canvas' import tells the row
            read.points = row.cells[assignment] if assignment and read.points is None else read.points
            continue
        if all(_SKIPPED.issuperset(cell) for cell in row.cells.values()):  # Canvas' skip_lines: /^[;, ]+$/
            continue
        if all(_POSTING.fullmatch(cell) for cell in row.cells.values()):
            read.posting = row.cells[assignment] if assignment else None
            continue
        who = {name: row.cells[header] for name, header in columns.items()}
        if not _is_student(who):
            continue
        if row.problem is not None:
            read.problems.append(RowProblem(file, row.line, _canvas_id(who), "",
                                            f"{row.problem.split(': ', 1)[-1]}: left out of canvas.csv", caveat=True))
            continue
        current = row.cells[assignment] if assignment else ""
        key_id, caveat = finder.by_id(who)
        if key_id is not None and key_id in read.taken:
            read.problems.append(RowProblem(file, row.line, key_id, "", f"names the key student {key_id}, as line "
                                            f"{read.taken[key_id]} does: {_KEPT}", caveat=True))
            key_id = None
        elif key_id is not None:
            read.taken[key_id] = row.line
            if caveat:
                read.problems.append(RowProblem(file, row.line, key_id, "", caveat, caveat=True))
        else:
            read.unmatched[len(read.rows)] = (_name(who), _canvas_id(who))
        read.rows.append(CanvasRow(row.line, tuple(who.values()), key_id, current))
    return read


def _match_by_name(read: _Read, finder: _Finder, file: str) -> None:
    """Match the rows no id matched by name (Canvas' import: ``s.name == name || s.sortable_name == name``),
    where the name is one key student's, not taken by an id, and no other unmatched row's."""
    rows_named = Counter(name for name, _ in read.unmatched.values())
    for index, (name, canvas_id) in read.unmatched.items():
        row, fits = read.rows[index], finder.named(name)
        if len(fits) == 1 and fits[0] not in read.taken and rows_named[name] == 1:
            read.taken[fits[0]] = row.line
            read.rows[index] = replace(row, key_id=fits[0], by_name=True)
            read.problems.append(RowProblem(file, row.line, fits[0], "", f"matched by name, {shown(name)} is the key's "
                                            f"{finder.names[fits[0]]}: no ID, SIS User ID or SIS Login ID of the row "
                                            "is the key's; check it is the same student", caveat=True))
        else:
            read.problems.append(RowProblem(file, row.line, canvas_id, "", f"Canvas student {shown(name)} is not in "
                                            f"the key ({_BY}){_why_not(fits, rows_named[name], read.taken)}: {_KEPT}",
                                            caveat=True))


def _unmatched_lines(read: _Read) -> dict[str, list[int]]:
    """The lines of the rows still matched to nobody, by their name."""
    lines: dict[str, list[int]] = defaultdict(list)
    for index, (name, _) in read.unmatched.items():
        if read.rows[index].key_id is None:
            lines[name].append(read.rows[index].line)
    return lines


def _why_not(fits: list[str], rows_named: int, taken: Mapping[str, int]) -> str:
    """Why a row whose name is a key student's is not matched by it ("" when no key student has it)."""
    if len(fits) > 1:
        return f"; its name is {len(fits)} key students' ({', '.join(fits[:5])}), so it is not matched by name"
    if fits and rows_named > 1:
        return f"; {rows_named} rows of the export have its name, so none is matched by name"
    if fits:
        return f"; the key student of its name, {fits[0]}, is line {taken[fits[0]]}'s by id"
    return ""


def _absent(file: str, student_id: str, lines: list[int]) -> RowProblem:
    """The caveat of a key student no row of the export matched (``lines``: unmatched rows of their name)."""
    named = f"; line {', '.join(map(str, lines[:5]))} has their name, not matched by it (see that line)" if lines \
        else ""
    return RowProblem(file, 0, student_id, "", f"in the key but not in the Canvas export ({_BY}){named}: no score "
                      "can be imported for them (dropped the course, or enrolled under another id?)", caveat=True)


def _unrelated(path: Path, key: Key, students: int) -> GraderError:
    """The refusal of an export none of whose students is in the key."""
    if not students:
        return GraderError(f"{path}: no student rows; expected {_EXPECTED}, and a row per student")
    return GraderError(f"{path}: none of its {students} students is in the key {key.where} ({_BY}); expected the "
                       "Canvas gradebook export of this assignment's course")


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
    titled = [(header, match["title"]) for header in stream.header if (match := TITLE_ID.fullmatch(header))]
    found = ([header for header, text in titled if text == title]
             or [header for header, text in titled if _folded(text) == _folded(title)])
    if len(found) > 1:
        raise GraderError(f"{stream.path}: line {stream.header_line}: the columns {shown(found[0])} and "
                          f"{shown(found[1])} both have the key's assignment title {shown(title)}; expected one "
                          "(delete the other assignment's column from the export, or retitle it in Canvas)")
    return found[0] if found else None


def _folded(title: str) -> str:
    return " ".join(title.split()).casefold()


def _is_student(who: Mapping[str, str]) -> bool:
    """Whether a row is a student's, not Canvas' test student."""
    name = who.get("Student") or f"{who.get('LastName', '')}, {who.get('FirstName', '')}"
    return " ".join(name.split()).lower() not in TEST_STUDENTS


def _name(who: Mapping[str, str]) -> str:
    """The name Canvas' import matches a row by: ``Student``, or ``FirstName LastName``."""
    return who["Student"] if "Student" in who else f"{who['FirstName']} {who['LastName']}".strip()


def sortable_name(name: str) -> str:
    """A name as Canvas sorts it (``User.last_name_first``): the surname first, then a comma; a suffix
    stays with the given names; a name with a comma already is one.

    >>> sortable_name("Priya Raman"), sortable_name("John Doe Jr."), sortable_name("Raman, Priya")
    ('Raman, Priya', 'Doe, John Jr.', 'Raman, Priya')
    """
    words = name.split()
    if "," in name or len(words) < 2:
        return name.strip()
    suffix = [words.pop()] if len(words) > 2 and _SUFFIXES.fullmatch(words[-1]) else []
    surname = words.pop()
    return f"{surname}, {' '.join(words + suffix)}"


class _Finder:
    """The key student a Canvas row names, in the order Canvas' import finds its own: by ID, SIS User ID,
    SIS Login ID (the key's id or email, exactly); and the key students a name fits."""

    def __init__(self, key: Key) -> None:
        self.ids = {s.id for s in key.students}
        self.roster = Roster([StudentRef(s.id, s.email) for s in key.students])
        self.logins: dict[str, list[str]] = defaultdict(list)
        self.named_as: dict[str, list[str]] = defaultdict(list)
        self.names = {s.id: s.name for s in key.students}
        for student in key.students:
            for login in dict.fromkeys(filter(None, (student.id, student.email.strip()))):
                self.logins[login].append(student.id)
            for name in dict.fromkeys(filter(None, (student.name.strip(), sortable_name(student.name)))):
                self.named_as[name].append(student.id)

    def by_id(self, who: Mapping[str, str]) -> tuple[str | None, str]:
        """The key student's id, or None; and a caveat ("" if none)."""
        if who["ID"] in self.ids:
            return who["ID"], ""
        if who.get("SIS User ID"):
            found, why, _ = self.roster.find(who["SIS User ID"], by_email=False)
            if found is not None and (found == who["SIS User ID"] or why.startswith("leading zeros")):
                return found, why
        found_by_login = self.logins.get(who["SIS Login ID"], []) if who["SIS Login ID"] else []
        return (found_by_login[0], "") if len(found_by_login) == 1 else (None, "")

    def named(self, name: str) -> list[str]:
        """The key students whose name or sortable name is ``name``."""
        return self.named_as.get(name, []) if name else []


def _canvas_id(who: Mapping[str, str]) -> str:
    """The id a student row shows: SIS User ID, else SIS Login ID, else Canvas' own."""
    return who.get("SIS User ID") or who["SIS Login ID"] or who["ID"]


def _assignment_notes(stream: CsvStream, column: str | None, key: Key) -> list[str]:
    if column is None:
        return [f"{stream.path}: no column {shown(key.title + ' (id)')}; canvas.csv's column is titled "
                f"{shown(key.title)}: Canvas updates the published assignment of exactly that title, or creates one"]
    match = TITLE_ID.fullmatch(column)
    if match and match["title"] != key.title:
        return [f"{stream.path}: the column {shown(column)} taken as the key's assignment {shown(key.title)} "
                "(the titles differ in case or spacing)"]
    return []

