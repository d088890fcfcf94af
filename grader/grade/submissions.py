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
zeros restored, an unreadable timestamp, a timestamp after the run's time, one answer of a wide row
superseded by a later long row) may accompany either. Of each kind of problem the first
:data:`~grader.grade.row_problems.LISTED` are listed and the rest counted, in one problem per file and
kind (:mod:`grader.grade.row_problems`).

Files are read row by row and nothing is kept per row but the rows that may still win
(:mod:`grader.grade.latest`) and the problems listed: memory is bounded by the file's text and the key,
whatever the number of rows.

Timestamps (:mod:`grader.grade.timestamps`) without a zone are in the assignment's zone (UTC unless the key
says otherwise; a note says so when some rows have a zone and some do not). When every competing row has a
timestamp, the latest wins (ties: the later row); when any of them has none (or one that does not read: a
caveat), the last row wins, in file order, then argument order (the key's ``attempts`` may make it the first,
or the best: :mod:`grader.grade.latest`). A timestamp after the run's own time wins all the same, with a
caveat and a note: a clock was wrong, or the time was typed.
"""

from __future__ import annotations

import itertools
import os
from collections import defaultdict
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from datetime import UTC, datetime, tzinfo
from functools import lru_cache
from operator import itemgetter
from pathlib import Path
from typing import Literal, cast

import numpy as np

from grader.base.errors import GraderError, shown
from grader.base.files import shown_path
from grader.base.inputs import CELL_CHARS, CSV_BYTES, CsvRow, CsvStream, open_csv, regular_size
from grader.grade import timestamps
from grader.grade.answer_columns import AnswerColumns
from grader.grade.columns import Layout, find_layout
from grader.grade.latest import Answer, Contests, SubmittedRow
from grader.grade.row_problems import (
    ASIDE,
    EMAIL_AS_ID,
    EMPTY,
    FUTURE,
    LABEL,
    LISTED,
    MALFORMED,
    UNKNOWN,
    UNREADABLE_TIME,
    ZEROS,
    Kind,
    ProblemLog,
    RowProblem,
)
from grader.grade.texts import Texts
from grader.grade.timestamps import in_zone, instant, read_timestamp

__all__ = ["Answer", "RowProblem", "StudentRef", "Submissions", "find_label", "read_submissions"]



@dataclass(frozen=True)
class StudentRef:
    """A student of the answer key, as submissions name them: by id, or by email."""

    id: str
    email: str


@dataclass(frozen=True)
class Submissions:
    """The answers to grade, the rows (or answers) not used, the columns no rule claimed, and notes
    about the files as a whole (an encoding guessed, time zones assumed)."""

    answers: Sequence[Answer]  # a tuple, or the plain files' in columns (:class:`AnswerColumns`)
    problems: tuple[RowProblem, ...]
    ignored_columns: tuple[str, ...]
    notes: tuple[str, ...]
    files: tuple[str, ...] = ()  # the files as answers name them, in the order given (the answers' order)


def read_submissions(paths: Sequence[Path], students: Sequence[StudentRef], labels: Sequence[str],
                     fmt: Literal["auto", "long", "wide"] = "auto", names: Sequence[str] = (), *,
                     listed: int = LISTED, now: datetime | None = None, zone: tzinfo = UTC,
                     attempts: str = "latest") -> Submissions:
    """Every answer of ``paths`` to one of ``labels`` by one of ``students``, the latest of each (or, as
    ``attempts`` says, the first, or every distinct one for grading to choose the best).
    Answers and problems name their file as in ``names`` when given (one per path), else by its path.
    Of each kind of problem the first ``listed`` are listed, the rest counted; ``now``: the run's time (a
    timestamp after it is a caveat), by default the clock's; ``zone``: that of timestamps that give none.

    Raises :class:`GraderError` for a file that cannot be used as a whole (unreadable, neither UTF-8
    nor UTF-16 nor clean Windows-1252, no recognisable header); a bad row is a :class:`RowProblem`.
    """
    _refuse_repeated(paths)
    reader = _Reader(Roster(students), labels, ProblemLog(listed), instant(now or timestamps.clock()), zone,
                     attempts)
    ignored: dict[str, None] = {}
    notes: list[str] = []
    shown_as = [shown_path(name) for name in names or paths]
    # The files' answers while every file so far is plain, read without the rows' machinery (the usual files);
    # each (student, label) is answered once in all of them.
    plain: list[_Block] | None = []
    taken = np.zeros(len(reader.roster.ids) * len(labels), bool)
    files: list[tuple[str, str]] = []
    for index, (path, name) in enumerate(zip(paths, shown_as, strict=True)):
        table, layout = _opened(path, labels, fmt, reader)
        files.append((name, table.delimiter))
        ignored.update(dict.fromkeys(layout.ignored))
        if table.encoding == "Windows-1252":
            notes.append(f"{name}: not UTF-8; read as Windows-1252 (Latin-1): check accented text, or save the "
                         'file as "CSV UTF-8"')
        # A file the files after it might make read again must be one that can be (not a pipe, <(...)).
        if plain is not None and (index == len(paths) - 1 or path.is_file()):
            found = _plain_answers(table, layout, reader.roster.ids, labels, index, taken)
            if found is not None:
                plain += found
                continue
        if plain is not None:
            for earlier in range(index):  # the files before were plain, this one is not: all are read row by row
                again, again_layout = _opened(paths[earlier], labels, fmt, reader)
                for row in again.rows():
                    reader.read(shown_as[earlier], earlier, row, again, again_layout)
            plain = None
        for row in table.rows():
            reader.read(name, index, row, table, layout)
        del table  # its rows are read: the next file's text need not wait beside it
    if plain is not None:
        # The plain files' answers are one a row, in the files' order: already sorted.
        return Submissions(AnswerColumns.joined(list(reader.roster.ids.values()), labels, files, plain), (),
                           tuple(ignored), tuple(notes), tuple(shown_as))
    answers = reader.contests.answers(labels)
    problems = reader.log.problems()
    order = {name: index for index, name in enumerate(shown_as)}
    position = {label: index for index, label in enumerate(labels)}
    return Submissions(tuple(sorted(answers, key=lambda a: (order[a.file], a.line, position[a.label]))),
                       tuple(sorted(problems, key=lambda p: (order[p.file], p.rows > 1, p.line, p.caveat, p.label))),
                       tuple(ignored), (*notes, *reader.notes()), tuple(shown_as))


def _opened(path: Path, labels: Sequence[str], fmt: Literal["auto", "long", "wide"],
            reader: _Reader) -> tuple[CsvStream, Layout]:
    """A submissions file opened (refused over :data:`SUBMISSIONS_BYTES`), and its layout."""
    table = open_csv(_within_limit(path), exports=True)
    return table, find_layout(table, labels, fmt, reader.roster.known)


def _plain_answers(table: CsvStream, layout: Layout, ids: Mapping[str, str], labels: Sequence[str], file: int,
                   taken: np.ndarray) -> list[_Block] | None:
    """The answers of a long file without timestamps each of whose rows has a cell per column, none too
    long, and names a student of the key by their id and a label as they are written, each student's label
    once (``taken``: each student * len(labels) + label already answered, in this file or one before): an
    answer a row, in the file's order, as :class:`_Reader` would read them (with no problem and no note), in
    blocks of the file (its index ``file``). None for any other file, whose rows are then read one by one."""
    if layout.wide or layout.by_email or layout.timestamp is not None or layout.label is None \
            or layout.answer is None:
        return None
    header = table.header
    wanted = (header.index(layout.student), header.index(layout.label), header.index(layout.answer))
    before = taken.copy()
    try:
        return _answers(_line_pieces(table, wanted), ids, labels, file, taken)
    except _NotALineARowError:  # blank lines, or a quoted cell over several lines: read as records instead
        taken[:] = before  # (what the lines before were taken as)
        return _answers(_record_pieces(table, wanted), ids, labels, file, taken)


def _answers(pieces: Iterator[_Piece | None], ids: Mapping[str, str], labels: Sequence[str], file: int,
             taken: np.ndarray) -> list[_Block] | None:
    """The answers of the rows of ``pieces`` as :func:`_plain_answers` reads them; None where one is not so."""
    # Each (student, label) as one number, student * labels + label: taken once each, checked a piece at a time.
    numbers = {student: index for index, student in enumerate(ids)}
    places = {label: index for index, label in enumerate(labels)}
    blocks: list[_Block] = []
    # A piece of rows at a time (a file of a million rows is not held as cells beside its answers), each cell
    # of the three columns stripped, as _Reader strips them, a column at a time.
    for piece in pieces:
        if piece is None:
            return None
        lines, who_cells, part_cells, typed_cells = piece
        found = list(map(numbers.get, map(str.strip, who_cells))), list(map(places.get, map(str.strip, part_cells)))
        if None in found[0] or None in found[1]:
            return None
        who_number, part_number = cast(tuple[list[int], list[int]], found)
        cells = np.array(who_number, np.int64) * len(labels) + np.array(part_number, np.int64)
        if taken[cells].any() or np.unique(cells).size != cells.size:  # a student's label twice
            return None
        taken[cells] = True
        # Kept as arrays (a list of a million students' numbers takes 36 bytes an answer, an array 4).
        blocks.append((file, np.array(who_number, np.int32), np.array(part_number, np.int16),
                       np.arange(lines.start, lines.stop, dtype=np.int32) if isinstance(lines, range)
                       else np.array(lines, np.int32), Texts.of(list(map(str.strip, typed_cells)))))
    return blocks


_Block = tuple[int, np.ndarray, np.ndarray, np.ndarray, Texts]  # a file's, its students, labels, lines, texts


_Piece = tuple[Sequence[int], list[str], list[str], list[str]]  # rows' lines, and their cells of three columns


class _NotALineARowError(Exception):
    """A file whose data lines are not each one row: it is read as the csv module's records instead."""


def _line_pieces(table: CsvStream, wanted: tuple[int, int, int]) -> Iterator[_Piece | None]:
    """The data rows, about :data:`_PLAIN_PIECE` characters of lines at a time, each line read by the csv module
    as one row (as :meth:`CsvStream.records` reads it: a line's end dropped), with their cells of the ``wanted``
    columns; None where a row has not one cell per column, or one too long; :class:`_NotALineARowError` where a
    line is no row (blank), or not one (a quoted cell over several lines, a quote left open)."""
    import csv  # here: `grader solve --set` and `grader list` read no CSV

    text, width = table.text, len(table.header)
    start, line = text.find("\n") + 1 or len(text), table.header_line + 1  # the header is the text's first line
    if '"' in text[:start]:  # unless a quoted name of it goes on to the next
        raise _NotALineARowError
    while start < len(text):
        end = text.find("\n", start + _PLAIN_PIECE)
        end = len(text) - text.endswith("\n") if end < 0 else end
        lines = text[start:end].split("\n")
        start = end + 1
        try:
            rows = list(csv.reader(lines, delimiter=table.delimiter, strict=True))
        except csv.Error:
            raise _NotALineARowError from None
        if len(rows) != len(lines) or not all(map(str.strip, map("".join, rows))):
            raise _NotALineARowError
        # A row is a line: no cell is longer than its line.
        if set(map(len, rows)) != {width} or (max(map(len, lines)) > CELL_CHARS and max(
                map(len, itertools.chain.from_iterable(rows))) > CELL_CHARS):
            yield None
            return
        yield range(line, line + len(lines)), *(list(map(itemgetter(column), rows)) for column in wanted)  # type: ignore[misc]
        line += len(lines)


def _record_pieces(table: CsvStream, wanted: tuple[int, int, int]) -> Iterator[_Piece | None]:
    """The rows of any file as the csv module reads them (:meth:`CsvStream.records`), 65,536 at a time (of
    :data:`_PLAIN_PIECE` characters, 16 a row), and their cells of the ``wanted`` columns; None where a row has
    not one cell per column, or one too long."""
    records, width = table.records(), len(table.header)
    while piece := list(itertools.islice(records, max(1, _PLAIN_PIECE >> 4))):
        lines, rows = zip(*piece, strict=True)
        if set(map(len, rows)) != {width} or max(map(len, itertools.chain.from_iterable(rows))) > CELL_CHARS:
            yield None
            return
        yield lines, *(list(map(itemgetter(column), rows)) for column in wanted)  # type: ignore[misc]


_PLAIN_PIECE = 1 << 20  # about 50,000 rows of three short cells


# The most of one submissions file: its text is held whole while its rows are read (1 byte a character of
# ASCII, up to 4 of other scripts, and its bytes beside it while they are decoded), and each answer kept takes
# about 150 bytes beside the file's 18 to 30 a row (docs/grading.md): 64 MiB of short rows, each kept, keep
# about 0.5 GiB. A larger class splits its rows over several files, each read in turn.
SUBMISSIONS_BYTES = CSV_BYTES


def _within_limit(path: Path) -> Path:
    """``path``, unless it is a regular file over :data:`SUBMISSIONS_BYTES`: that is refused with the way out."""
    size = regular_size(path)
    if size > SUBMISSIONS_BYTES:
        raise GraderError(f"{path}: {size:,} bytes, more than the {SUBMISSIONS_BYTES:,} a submissions file is read "
                          "within; split its rows into files under that size and give them all to grader grade "
                          "(they are read in turn, a student's rows in any of them)")
    return path


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
    """The key's students, found by id (exact, or once leading zeros are restored) or by email; in an id
    column, a cell that is no id but a student's email (as ``grader check --student`` takes either) is
    that student, with a caveat."""

    def __init__(self, students: Sequence[StudentRef]) -> None:
        self.ids = {s.id: s.id for s in students}  # each id to the key's own text (answers share it)
        self.stripped: dict[str, list[str]] = defaultdict(list)
        for s in students:
            self.stripped[s.id.lstrip("0")].append(s.id)
        self.emails: dict[str, list[str]] = defaultdict(list)
        for s in students:
            if s.email.strip():
                self.emails[s.email.strip().lower()].append(s.id)

    def find(self, text: str, by_email: bool) -> tuple[str | None, str, Kind | None]:
        """The student ``text`` names, and a caveat ("" if none) with its kind, or why nobody (when ``None``)."""
        if by_email:
            return self._by_email(text, None)
        if text in self.ids:
            return text, "", None
        found = self.stripped.get(text.lstrip("0"), []) if text.strip("0") else []
        if len(found) == 1:
            return found[0], f"leading zeros restored: {text} -> {found[0]}", ZEROS
        if found:
            return None, (f"student {shown(text)} is ambiguous: with its leading zeros restored it could be "
                          f"{' or '.join(sorted(found))}; write the id in full"), None
        if text.strip().lower() in self.emails:
            return self._by_email(text, EMAIL_AS_ID)
        return None, f"unknown student {shown(text)} (not in the answer key)", None

    def _by_email(self, text: str, caveat: Kind | None) -> tuple[str | None, str, Kind | None]:
        """The one student whose email is ``text`` (any case); in an id column (``caveat``), said so."""
        found = self.emails.get(text.strip().lower(), [])
        if len(found) == 1:
            return found[0], f"an email in the id column, matched by email: {text.strip()} -> {found[0]}" \
                if caveat else "", caveat
        return None, (f"unknown student email {shown(text)} (not in the answer key)" if not found
                      else f"the email {shown(text)} belongs to {len(found)} students of the answer key"), None

    def known(self, text: str, by_email: bool) -> bool:
        return self.find(text, by_email)[0] is not None


_CANVAS_ROWS = ("points possible", "manual posting", "muted")
TEST_STUDENTS = ("student, test", "test student")  # Canvas' test student, as its name is exported


class _Reader:
    """What reading the rows keeps: the contests of the rows that may still win, the problems, and what the
    notes need (time zones seen, timestamps after the run's time)."""

    def __init__(self, roster: Roster, labels: Sequence[str], log: ProblemLog, now: datetime, zone: tzinfo,
                 attempts: str) -> None:
        self.roster, self.labels, self.log = roster, labels, log
        self.find = lru_cache(maxsize=65536)(roster.find)  # a file of a million rows names a few thousand students
        self.contests = Contests(log, attempts)
        self.now, self.zone, self.zoned, self.unzoned = now, zone, False, False
        self.future: list[tuple[str, int]] = []  # the first row with a timestamp after now, and how many
        self.futures = 0
        self.emailed = 0  # rows whose id column held a student's email

    def read(self, file: str, index: int, row: CsvRow, table: CsvStream, layout: Layout) -> None:
        """Enter ``row`` in its contest (with its caveats to the log), or its problem to the log."""
        who = row.cells[layout.student]
        label = ""
        if not layout.wide:
            label = find_label(row.cells[layout.label or ""], self.labels) or row.cells[layout.label or ""]
        order = (index, row.line)
        if row.problem is not None and not _only_long_answers(row, layout):
            problem = row.problem
            self._problem(MALFORMED, order, file, who, label, lambda: problem.split(": ", 1)[-1])
            return
        student_id, why, caveat = self.find(who, layout.by_email) if who else (None, "no student given", None)
        if student_id is None:
            nobody = _not_a_student(row, layout)
            self._problem(ASIDE if nobody else UNKNOWN, order, file, who, label, lambda: nobody or why)
            return
        if caveat is not None:
            if caveat is EMAIL_AS_ID:
                self.emailed += 1
            self._problem(caveat, order, file, student_id, "", lambda: why)
        if layout.wide:
            answers = tuple((label, row.cells[column]) for column, label in layout.labels.items() if row.cells[column])
            if not answers:
                self._problem(EMPTY, order, file, student_id, "", lambda: "no answers in this row")
                return
        elif label not in self.labels:
            self._problem(LABEL, order, file, student_id, label,
                          lambda: f"unknown label {shown(label)} (expected one of {', '.join(self.labels)})")
            return
        else:
            answers = ((label, row.cells[layout.answer or ""]),)
        stamp = self._timestamp(row.cells[layout.timestamp], order, file, student_id) if layout.timestamp else None
        self.contests.enter(SubmittedRow(file, index, row.line, student_id, answers, stamp, table.delimiter,
                                         layout.wide))

    def _timestamp(self, text: str, order: tuple[int, int], file: str, student_id: str) -> datetime | None:
        stamp = read_timestamp(text)
        if isinstance(stamp, str):
            why = stamp
            self._problem(UNREADABLE_TIME, order, file, student_id, "", lambda: why)
            return None
        if stamp is None:
            return None
        if stamp.tzinfo is None:
            self.unzoned = True
            stamp = in_zone(stamp, self.zone)
        else:
            self.zoned = True
        if stamp > self.now:  # in the assignment's zone, a time without one is no longer a guess
            self.futures += 1
            if not self.future:
                self.future.append((file, order[1]))
            self._problem(FUTURE, order, file, student_id, "", lambda: (
                f"timestamp {shown(text.strip())} is after this run's time ({self.now:%Y-%m-%d %H:%M} UTC): it "
                "wins over every submission of this answer before it, real or not; check the clock that wrote it"))
        return stamp

    def _problem(self, kind: Kind, order: tuple[int, int], file: str, student_id: str, label: str,
                 reason: Callable[[], str]) -> None:
        """A problem of ``kind``; its reason is worked out only if it is listed (millions may not be)."""
        if self.log.wants(kind, order):
            self.log.add(kind, order, file, RowProblem(file, order[1], student_id, label, reason(), kind.caveat,
                                                       kind.routine))
        else:
            self.log.count(kind, file)

    def notes(self) -> list[str]:
        """Notes about the rows as a whole."""
        notes = []
        if self.zoned and self.unzoned:
            notes.append(f"some timestamps have a time zone and some do not: those without were taken as {self.zone} "
                         "(the assignment's zone) to compare them")
        if self.futures:
            file, line = self.future[0]
            notes.append(f"{self.futures:,} row{'s have' if self.futures > 1 else ' has'} a timestamp after this "
                         f"run's time ({self.now:%Y-%m-%d %H:%M} UTC), the first {file} line {line}: such a row "
                         "wins over every submission before it; see problems.csv")
        if self.emailed:
            notes.append(f"{self.emailed:,} row{'s name their' if self.emailed > 1 else ' names its'} student by "
                         "email in the id column: matched by email (see problems.csv)")
        if self.log.unlisted():
            notes.append(f"problems.csv lists the first {self.log.listed:,} rows of each kind of problem; "
                         f"{self.log.unlisted():,} more are counted there, not listed")
        return notes


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
    return _nobody(layout.student, tuple(row.cells.get(column, "") for column in (layout.student, *layout.ignored)))


@lru_cache(maxsize=4096)  # a file of a million rows of nobody repeats the same few cells
def _nobody(student_column: str, cells: tuple[str, ...]) -> str:
    """:func:`_not_a_student` of the cells of the student column and the ignored ones, in that order."""
    if " ".join(cells[0].split()).lower() == " ".join(student_column.split()).lower():
        return "not a student row (the header repeated: were two files pasted into one?)"
    for cell in cells:
        value = " ".join(cell.split()).lower()
        if value in _CANVAS_ROWS:
            return f"not a student row (Canvas' {shown(cell.strip())} row)"
        if value in TEST_STUDENTS:
            return "not a student row (Canvas' test student)"
    return ""


