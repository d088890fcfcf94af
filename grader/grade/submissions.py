"""Students' submissions, read from the CSV files LMSs and Google Forms export, into one answer per
(student, label), with every data row accounted for: its answers are used, or a :class:`RowProblem`
says why not.

Two layouts, told apart by the header: **long**, one row per answer (``student_id, label, answer``,
optionally ``timestamp``), and **wide**, one row per submission (a student column and one column per
label; ``1a. Speed of the pile (m/s)`` is the column of ``1a``). When a student submitted several times
the latest submission wins: in a wide file the whole row, in a long file the row of that label.

>>> import tempfile, pathlib
>>> path = pathlib.Path(tempfile.mkdtemp()) / "answers.csv"
>>> _ = path.write_text("student_id,label,answer\\n00123,1a,6.26\\n00123,1b,0.5 m\\n00123,1a,6.3\\n77,1a,1\\n")
>>> result = read_submissions([path], [StudentRef("00123", "ann@uni.edu")], ["1a", "1b"])
>>> [(a.line, a.label, a.text) for a in result.answers]
[(3, '1b', '0.5 m'), (4, '1a', '6.3')]
>>> [(p.line, p.reason) for p in result.problems]  # doctest: +NORMALIZE_WHITESPACE
[(2, 'superseded by .../answers.csv line 4 (no timestamps: the last row wins)'),
 (5, "unknown student '77' (not in the answer key)")]

Rules of accounting (a test checks them on every file): each data line is either the line of one or
more answers, or of exactly one problem whose ``caveat`` is false. Caveats (``caveat=True``: leading
zeros restored, an unreadable timestamp, one answer of a wide row superseded by a later long row) may
accompany either.

Timestamps: ISO 8601 (``2026-12-04 23:59:07``, ``2026-12-04T23:59:07Z``, ``... UTC``) and Google Forms'
``12/4/2026 23:59:07`` (month first, optional ``AM``/``PM``), each with or without a zone. Times
without a zone are taken as UTC when compared with times that have one (a note says so). When every
competing row has a timestamp, the latest wins (ties: the later row); when any of them has none
(or one that does not read: a caveat), the last row wins, in file order, then argument order.
"""

from __future__ import annotations

import os
import re
from collections import defaultdict
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from datetime import UTC, datetime, timedelta, timezone
from pathlib import Path
from typing import Literal

from grader.errors import GraderError, shown
from grader.files import shown_path
from grader.grade.columns import Layout, find_layout
from grader.inputs import CELL_CHARS, CsvRow, CsvTable, read_csv


@dataclass(frozen=True)
class StudentRef:
    """A student of the answer key, as submissions name them: by id, or by email."""

    id: str
    email: str


@dataclass(frozen=True, slots=True)
class Answer:
    """One answer a student gave: where it came from (``line``: the line its row starts on, the
    header being line 1, blank lines counted), and the file's ``delimiter`` (with ``;`` or a tab,
    ``6,26`` may be a decimal comma)."""

    file: str
    line: int
    student_id: str
    label: str
    text: str
    delimiter: str
    timestamp: datetime | None


@dataclass(frozen=True)
class RowProblem:
    """Why a row (``label == ""``) or one answer of it was not used; ``caveat``: the row's answers
    were used all the same, and this is said so that nobody is surprised; ``routine``: not used by rule,
    with nothing for anyone to do (superseded by the same student's later answer, or one of Canvas' rows
    that are no student's), so it does not make a run end with "rows not graded"."""

    file: str
    line: int
    student_id: str
    label: str
    reason: str
    caveat: bool = False
    routine: bool = False

    @property
    def not_graded(self) -> bool:
        """Whether a submitted answer went ungraded for a reason someone should look at."""
        return not self.caveat and not self.routine


@dataclass(frozen=True)
class Submissions:
    """The answers to grade, the rows (or answers) not used, the columns no rule claimed, and notes
    about the files as a whole (an encoding guessed, time zones assumed)."""

    answers: tuple[Answer, ...]
    problems: tuple[RowProblem, ...]
    ignored_columns: tuple[str, ...]
    notes: tuple[str, ...]


@dataclass(slots=True)
class _Row:
    """One data row that names a known student, with its non-empty answers as (label, text) pairs (a
    long row's one answer may be empty: a blank submitted). A class of 100,000 has a million rows:
    they hold no more than they need."""

    file: str
    index: int  # of the file, in argument order
    line: int
    student_id: str
    answers: tuple[tuple[str, str], ...]
    timestamp: datetime | None
    delimiter: str
    wide: bool
    lost: list[tuple[str, str]] | None = None  # (label, why) taken by a later long row

    @property
    def order(self) -> tuple[int, int]:
        """Where the row is: argument order, then file order."""
        return self.index, self.line

    def text(self, label: str) -> str:
        """The row's answer to ``label``."""
        return dict(self.answers)[label]


def read_submissions(paths: Sequence[Path], students: Sequence[StudentRef], labels: Sequence[str],
                     fmt: Literal["auto", "long", "wide"] = "auto", names: Sequence[str] = ()) -> Submissions:
    """Every answer of ``paths`` to one of ``labels`` by one of ``students``, the latest of each.
    Answers and problems name their file as in ``names`` when given (one per path), else by its path.

    Raises :class:`GraderError` for a file that cannot be used as a whole (unreadable, neither UTF-8
    nor UTF-16 nor clean Windows-1252, no recognisable header); a bad row is a :class:`RowProblem`.
    """
    _refuse_repeated(paths)
    roster = Roster(students)
    rows: list[_Row] = []
    problems: list[RowProblem] = []
    ignored: dict[str, None] = {}
    notes: list[str] = []
    shown_as = [shown_path(name) for name in names or paths]
    for index, (path, name) in enumerate(zip(paths, shown_as, strict=True)):
        table = read_csv(path, exports=True)
        layout = find_layout(table, labels, fmt, roster.known)
        ignored.update(dict.fromkeys(layout.ignored))
        if table.encoding == "Windows-1252":
            notes.append(f"{name}: not UTF-8; read as Windows-1252 (Latin-1): check accented text, or save the "
                         'file as "CSV UTF-8"')
        for row in table.rows:
            _read_row(name, index, row, table, layout, labels, roster, rows, problems)
        del table  # its rows are read: the next file's need not wait beside them
    stamps = [row.timestamp for row in rows if row.timestamp is not None]
    if any(s.tzinfo is None for s in stamps) and any(s.tzinfo is not None for s in stamps):
        notes.append("some timestamps have a time zone and some do not: those without were taken as UTC "
                     "to compare them")
    answers = _latest(rows, problems, labels)
    del rows
    order = {name: index for index, name in enumerate(shown_as)}
    position = {label: index for index, label in enumerate(labels)}
    return Submissions(tuple(sorted(answers, key=lambda a: (order[a.file], a.line, position[a.label]))),
                       tuple(sorted(problems, key=lambda p: (order[p.file], p.line, p.caveat, p.label))),
                       tuple(ignored), tuple(notes))


def _refuse_repeated(paths: Sequence[Path]) -> None:
    """One file given twice (``answers.csv`` beside ``*.csv``) would have each row "superseded" by itself."""
    seen: dict[str, Path] = {}
    for path in paths:
        real = os.path.realpath(path)
        if real in seen:
            same = "given twice" if str(seen[real]) == str(path) else f"the same file as {seen[real]}"
            raise GraderError(f"{path}: {same}; expected each submissions file once")
        seen[real] = path


class Roster:
    """The key's students, found by id (exact, or once leading zeros are restored) or by email."""

    def __init__(self, students: Sequence[StudentRef]) -> None:
        self.ids = {s.id for s in students}
        self.stripped: dict[str, list[str]] = defaultdict(list)
        for s in students:
            self.stripped[s.id.lstrip("0")].append(s.id)
        self.emails: dict[str, list[str]] = defaultdict(list)
        for s in students:
            if s.email.strip():
                self.emails[s.email.strip().lower()].append(s.id)

    def find(self, text: str, by_email: bool) -> tuple[str | None, str]:
        """The student ``text`` names, and a caveat ("" if none) or why nobody (when ``None``)."""
        if by_email:
            found = self.emails.get(text.lower(), [])
            if len(found) == 1:
                return found[0], ""
            return None, (f"unknown student email {shown(text)} (not in the answer key)" if not found
                          else f"the email {shown(text)} belongs to {len(found)} students of the answer key")
        if text in self.ids:
            return text, ""
        found = self.stripped.get(text.lstrip("0"), []) if text.strip("0") else []
        if len(found) == 1:
            return found[0], f"leading zeros restored: {text} -> {found[0]}"
        if found:
            return None, (f"student {shown(text)} is ambiguous: with its leading zeros restored it could be "
                          f"{' or '.join(sorted(found))}; write the id in full")
        return None, f"unknown student {shown(text)} (not in the answer key)"

    def known(self, text: str, by_email: bool) -> bool:
        return self.find(text, by_email)[0] is not None


_CANVAS_ROWS = ("points possible", "manual posting", "muted")
TEST_STUDENTS = ("student, test", "test student")  # Canvas' test student, as its name is exported


def _read_row(file: str, index: int, row: CsvRow, table: CsvTable, layout: Layout, labels: Sequence[str],
              roster: Roster, rows: list[_Row], problems: list[RowProblem]) -> None:
    """Append ``row`` to ``rows`` (with its caveats to ``problems``), or its problem to ``problems``."""
    who = row.cells[layout.student]
    label = ""
    if not layout.wide:
        label = find_label(row.cells[layout.label or ""], labels) or row.cells[layout.label or ""]
    if row.problem is not None and not _only_long_answers(row, layout):
        problems.append(RowProblem(file, row.line, who, label, row.problem.split(": ", 1)[-1]))
        return
    student_id, why = roster.find(who, layout.by_email) if who else (None, "no student given")
    if student_id is None:
        nobody = _not_a_student(row, layout)
        problems.append(RowProblem(file, row.line, who, label, nobody or why, routine=bool(nobody)))
        return
    if why:
        problems.append(RowProblem(file, row.line, student_id, "", why, caveat=True))
    if layout.wide:
        answers = tuple((label, row.cells[column]) for column, label in layout.labels.items() if row.cells[column])
        if not answers:
            problems.append(RowProblem(file, row.line, student_id, "", "no answers in this row"))
            return
    elif label not in labels:
        problems.append(RowProblem(file, row.line, student_id, label,
                                   f"unknown label {shown(label)} (expected one of {', '.join(labels)})"))
        return
    else:
        answers = ((label, row.cells[layout.answer or ""]),)
    stamp = _timestamp(row.cells[layout.timestamp]) if layout.timestamp else None
    if isinstance(stamp, str):
        problems.append(RowProblem(file, row.line, student_id, "", stamp, caveat=True))
        stamp = None
    rows.append(_Row(file, index, row.line, student_id, answers, stamp, table.delimiter, layout.wide))


def _only_long_answers(row: CsvRow, layout: Layout) -> bool:
    """Whether a row's only fault is an answer longer than ``CELL_CHARS``: the answer is then graded, and
    found too long with the limit said, where the student's other answers are."""
    if row.problem is None or not row.problem.startswith(f"line {row.line}: a cell of "):
        return False
    answers = set(layout.labels) if layout.wide else {layout.answer}
    return all(column in answers for column, text in row.cells.items() if len(text) > CELL_CHARS)


def find_label(text: str, labels: Sequence[str]) -> str | None:
    """The label ``text`` names: exactly, else ignoring case and spaces around it."""
    if text in labels:
        return text
    folded = [label for label in labels if label.lower() == text.strip().lower()]
    return folded[0] if len(folded) == 1 else None


def _not_a_student(row: CsvRow, layout: Layout) -> str:
    """Why a row that names no known student is none (Canvas' extra rows, the header again where two
    files were pasted into one), or ""."""
    if " ".join(row.cells.get(layout.student, "").split()).lower() == " ".join(layout.student.split()).lower():
        return "not a student row (the header repeated: were two files pasted into one?)"
    for column in (layout.student, *layout.ignored):
        value = " ".join(row.cells.get(column, "").split()).lower()
        if value in _CANVAS_ROWS:
            return f"not a student row (Canvas' {shown(row.cells[column].strip())} row)"
        if value in TEST_STUDENTS:
            return "not a student row (Canvas' test student)"
    return ""


# --- timestamps ---------------------------------------------------------------------------------

_ZONE = r"(?:\s*(?P<zone>Z|UTC|GMT|(?:UTC|GMT)?\s*(?P<sign>[+-])(?P<zh>\d{1,2})(?::?(?P<zm>\d{2}))?))?"
_ISO = re.compile(r"(?P<base>\d{4}-\d{2}-\d{2}(?:[T ]\d{1,2}:\d{2}(?::\d{2}(?:[.,]\d+)?)?)?)" + _ZONE, re.I)
_FORMS = re.compile(r"(?P<month>\d{1,2})/(?P<day>\d{1,2})/(?P<year>\d{4})(?:[T ]+(?P<hour>\d{1,2}):(?P<minute>\d{2})"
                    r"(?::(?P<second>\d{2})(?:\.\d+)?)?(?:\s*(?P<half>AM|PM))?)?" + _ZONE, re.I)


def _timestamp(text: str) -> datetime | str | None:
    """A timestamp cell read: the time, ``None`` when empty, or why it does not read (a caveat).

    >>> _timestamp("12/4/2026 11:59:07 PM"), _timestamp("2026-12-04T23:59:07Z")
    (datetime.datetime(2026, 12, 4, 23, 59, 7), datetime.datetime(2026, 12, 4, 23, 59, 7, tzinfo=datetime.timezone.utc))
    """
    text = text.strip()
    if not text:
        return None
    try:
        iso, forms = _ISO.fullmatch(text), _FORMS.fullmatch(text)
        if iso:
            when = datetime.fromisoformat(iso["base"].replace(",", "."))
        elif forms:
            hour = int(forms["hour"] or 0)
            if forms["half"]:
                hour = hour % 12 + (12 if forms["half"].upper() == "PM" else 0)
            when = datetime(int(forms["year"]), int(forms["month"]), int(forms["day"]), hour,
                            int(forms["minute"] or 0), int(forms["second"] or 0))
        else:
            raise ValueError(text)
        return _zoned(when, iso or forms)
    except (ValueError, OverflowError):
        return (f"timestamp {shown(text)} not understood (expected ISO 8601 like 2026-12-04 23:59:07 or "
                "12/4/2026 23:59:07); the row is taken as having none")


def _zoned(when: datetime, match: re.Match[str] | None) -> datetime:
    if match is None or match["zone"] is None:
        return when
    if match["sign"] is None:
        return when.replace(tzinfo=UTC)
    offset = timedelta(hours=int(match["zh"]), minutes=int(match["zm"] or 0))
    return when.replace(tzinfo=timezone(-offset if match["sign"] == "-" else offset))


# --- the latest submission wins -------------------------------------------------------------------

def _latest(rows: list[_Row], problems: list[RowProblem], labels: Sequence[str]) -> list[Answer]:
    """The winning answers; every row or answer that lost goes to ``problems`` with its winner.

    A wide row is one submission: per student, the latest wide row wins whole. Then, per (student,
    label), the winning wide row's answer competes with the long rows of that label.
    """
    by_student: dict[str, list[_Row]] = defaultdict(list)
    for row in rows:
        if row.wide:
            by_student[row.student_id].append(row)
    contenders = [row for row in rows if not row.wide]
    for group in by_student.values():
        winner, losers, why = _pick(group)
        contenders.append(winner)
        problems.extend(RowProblem(row.file, row.line, row.student_id, "", why, routine=True) for row in losers)
    first: dict[tuple[str, str], tuple[_Row, str]] = {}  # most answers have one row: no list for them
    more: dict[tuple[str, str], list[_Row]] = {}
    for row in contenders:
        for label, text in row.answers:
            found = first.setdefault((row.student_id, label), (row, text))[0]
            if found is not row:
                more.setdefault((row.student_id, label), [found]).append(row)
    answers = []
    for (student_id, label), (winner, text) in first.items():
        if (student_id, label) in more:
            winner, losers, why = _pick(more[student_id, label])
            text = winner.text(label)
            for row in losers:
                if row.wide:
                    row.lost = row.lost or []
                    row.lost.append((label, why))
                else:
                    problems.append(RowProblem(row.file, row.line, student_id, label, why, routine=True))
        answers.append(Answer(winner.file, winner.line, student_id, label, text, winner.delimiter, winner.timestamp))
    for row in contenders:
        if row.wide and row.lost:
            problems.extend(_lost_answers(row, labels))
    return answers


def _pick(group: Iterable[_Row]) -> tuple[_Row, list[_Row], str]:
    """The latest row of ``group``, the others, and the reason they lost."""
    group = sorted(group, key=lambda row: row.order)
    timed = all(row.timestamp is not None for row in group)
    if timed:
        group.sort(key=lambda row: (_instant(row.timestamp), row.order))
    winner = group[-1]
    rule = ("submitted later" if timed else "no timestamps: the last row wins" if all(
        row.timestamp is None for row in group) else "not every row has a timestamp: the last row wins")
    return winner, group[:-1], f"superseded by {winner.file} line {winner.line} ({rule})"


def _instant(when: datetime | None) -> datetime:
    """``when`` comparable with any other: without a zone, taken as UTC."""
    when = when or datetime.min
    return when if when.tzinfo is not None else when.replace(tzinfo=UTC)


def _lost_answers(row: _Row, labels: Sequence[str]) -> list[RowProblem]:
    """A winning wide row some of whose answers a later long row replaced: a caveat per answer, or,
    when it kept none, one problem for the row."""
    lost = sorted(row.lost or (), key=lambda pair: labels.index(pair[0]))
    if len(lost) < len(row.answers):
        return [RowProblem(row.file, row.line, row.student_id, label, why, caveat=True) for label, why in lost]
    whys = "; ".join(f"{label}: {why}" for label, why in lost)
    return [RowProblem(row.file, row.line, row.student_id, "", f"every answer superseded ({whys})", routine=True)]
