"""Which attempt counts: rows that answer the same thing compete, and every row that loses is a
routine :class:`~grader.grade.row_problems.RowProblem` naming its winner. The rule is the key's
``attempts``: ``latest`` (the default), ``first`` or ``best``.

For ``latest`` and ``first``, a wide row is one submission: per student, the latest (first) wide row wins
whole. Then, per (student, label), the winning wide row's answer competes with the long rows of that
label. When every competing row has a timestamp, the latest (earliest) wins (ties: the later row; for
``first``, the earlier); when any of them has none, the last (first) row wins, in file order, then argument
order.

For ``best``, every answer competes per (student, label), whichever row it came in (as PrairieLearn counts
each question's best submission): grading decides (:func:`grader.grade.grading.grade`), so every distinct
answer is kept, and of equal answers the earliest (by timestamp, then place), which scores no less.

Rows are entered as they are read, and a contest keeps only the rows that may still win (the last row,
and while every row has a timestamp, the latest): five million resubmissions of one answer cost the
memory of two rows.

>>> from datetime import datetime
>>> def row(line, stamp=None):
...     return SubmittedRow("a.csv", 0, line, "456", (("1a", str(line)),), stamp, ",", False)
>>> contest = Contest.of(row(2, datetime(2026, 12, 4)))
>>> [r.line for r in contest.add(row(3, datetime(2026, 12, 3)))], contest.winner.line
([], 2)
>>> [r.line for r in contest.add(row(4))], contest.winner.line, contest.why()
([3, 2], 4, 'superseded by a.csv line 4 (not every row has a timestamp: the last row wins)')
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from datetime import datetime
from typing import NamedTuple, TypeVar

from grader.grade.row_problems import REPLACED, SAME, SUPERSEDED, Order, ProblemLog, RowProblem
from grader.grade.timestamps import instant

_K = TypeVar("_K", str, tuple[str, str])


class Answer(NamedTuple):
    """One answer a student gave: where it came from (``line``: the line its row starts on, the
    header being line 1, blank lines counted), and the file's ``delimiter`` (with ``;`` or a tab,
    ``6,26`` may be a decimal comma). A named tuple: a file of a million rows makes a million, and a frozen
    dataclass takes ten times as long to make one."""

    file: str
    line: int
    student_id: str
    label: str
    text: str
    delimiter: str
    timestamp: datetime | None


@dataclass(slots=True)
class SubmittedRow:
    """One data row that names a known student, with its non-empty answers as (label, text) pairs (a
    long row's one answer may be empty: a blank submitted). Only the rows that may still win are kept."""

    file: str
    index: int  # of the file, in argument order
    line: int
    student_id: str
    answers: tuple[tuple[str, str], ...]
    timestamp: datetime | None
    delimiter: str
    wide: bool
    lost: list[tuple[str, Contest]] | None = None  # (label, where it lost) taken by a later long row

    @property
    def order(self) -> Order:
        """Where the row is: argument order, then file order."""
        return self.index, self.line

    def text(self, label: str) -> str:
        """The row's answer to ``label``."""
        return dict(self.answers)[label]


@dataclass(slots=True)
class Contest:
    """The rows competing for one answer: the last row, the latest while every row has a timestamp, and
    how many rows have a timestamp and how many have none; with ``first``, the first row and the earliest
    in their places."""

    last: SubmittedRow
    latest: SubmittedRow | None
    timed: int
    untimed: int
    first: bool = False

    @classmethod
    def of(cls, row: SubmittedRow, first: bool = False) -> Contest:
        """A contest of one row (``first``: the first attempt counts, not the latest)."""
        timed = row.timestamp is not None
        return cls(row, row if timed else None, int(timed), int(not timed), first)

    def add(self, row: SubmittedRow) -> list[SubmittedRow]:
        """Enter ``row``; returns the rows that can no longer win."""
        before = (self.last, self.latest, row)
        if row.timestamp is None:
            self.untimed += 1
        else:
            self.timed += 1
            if self.latest is None or _later(row, self.latest) != self.first:
                self.latest = row
        if (row.order > self.last.order) != self.first:
            self.last = row
        if self.untimed:
            self.latest = None  # a row without a timestamp: the last row wins, whatever the others say
        lost: list[SubmittedRow] = []
        for candidate in before:
            if candidate is not None and candidate is not self.last and candidate is not self.latest \
                    and all(candidate is not other for other in lost):
                lost.append(candidate)
        return lost

    @property
    def winner(self) -> SubmittedRow:
        """The row that wins, of the rows entered so far."""
        return self.latest if self.latest is not None and not self.untimed else self.last

    def why(self) -> str:
        """Why the other rows lost."""
        if self.first:
            rule = ("submitted earlier: the first attempt counts" if not self.untimed
                    else "no timestamps: the first row counts" if not self.timed
                    else "not every row has a timestamp: the first row counts")
        else:
            rule = ("submitted later" if not self.untimed else "no timestamps: the last row wins" if not self.timed
                    else "not every row has a timestamp: the last row wins")
        return f"superseded by {self.winner.file} line {self.winner.line} ({rule})"


@dataclass(slots=True)
class Attempts:
    """The answers competing for one (student, label) when the best counts: of each distinct text, the
    earliest row (an equal answer submitted later scores no more)."""

    label: str
    rows: dict[str, SubmittedRow]

    def add(self, row: SubmittedRow) -> SubmittedRow | None:
        """Enter ``row``; returns the row its answer's text no longer needs (``row`` or the one it replaces)."""
        text = row.text(self.label)
        kept = self.rows.setdefault(text, row)
        if kept is row:
            return None
        if _earlier(row, kept):
            self.rows[text] = row
            return kept
        return row


def _later(row: SubmittedRow, than: SubmittedRow) -> bool:
    return (instant(row.timestamp), row.order) > (instant(than.timestamp), than.order)


def _earlier(row: SubmittedRow, than: SubmittedRow) -> bool:
    """Whether ``row`` came before ``than``: by timestamp when both have one, else by place."""
    if row.timestamp is not None and than.timestamp is not None and row.timestamp != than.timestamp:
        return instant(row.timestamp) < instant(than.timestamp)
    return row.order < than.order


class Contests:
    """Every contest of a run, as rows are entered: per student of wide rows, per (student, label) of long
    rows. The rows that lose go to ``log``, each listed with its winner once the winner is known."""

    def __init__(self, log: ProblemLog, attempts: str = "latest") -> None:
        self.log, self.first = log, attempts == "first"
        self.wide: dict[str, Contest] = {}
        self.long: dict[tuple[str, str], Contest] = {}
        self.best: dict[tuple[str, str], Attempts] | None = {} if attempts == "best" else None

    def enter(self, row: SubmittedRow) -> None:
        """A row read: it competes with the student's others of its kind (when the best counts, each of
        its answers with the student's others of that label)."""
        if self.best is not None:
            for label, _ in row.answers:
                attempts = self.best.setdefault((row.student_id, label), Attempts(label, {}))
                dropped = attempts.add(row)
                if dropped is not None:
                    self._same(dropped, label, attempts.rows[dropped.text(label)])
        elif row.wide:
            self._enter(self.wide, row.student_id, row, "")
        else:
            self._enter(self.long, (row.student_id, row.answers[0][0]), row, row.answers[0][0])

    def _enter(self, contests: dict[_K, Contest], key: _K, row: SubmittedRow, label: str) -> None:
        contest = contests.get(key)
        if contest is None:
            contests[key] = Contest.of(row, self.first)
            return
        for lost in contest.add(row):
            self._lost(lost, label, contest)

    def _lost(self, row: SubmittedRow, label: str, contest: Contest) -> None:
        if row.wide and label:  # one answer of a winning wide row: said with the row's others (answers)
            row.lost = row.lost or []
            row.lost.append((label, contest))
            return
        if self.log.wants(SUPERSEDED, row.order):
            self.log.add(SUPERSEDED, row.order, row.file, _superseded(row, label, contest))
        else:
            self.log.count(SUPERSEDED, row.file)

    def _same(self, row: SubmittedRow, label: str, kept: SubmittedRow) -> None:
        """An answer the same as one submitted before it: the earlier counts, if the best of them does."""
        if self.log.wants(SAME, row.order):
            self.log.add(SAME, row.order, row.file, RowProblem(
                row.file, row.line, row.student_id, label, f"the same answer as {kept.file} line {kept.line}, "
                "submitted before it (the best attempt counts: of equal ones, the first)", caveat=row.wide,
                routine=not row.wide))
        else:
            self.log.count(SAME, row.file)

    def answers(self, labels: Sequence[str]) -> list[Answer]:
        """The winning answers, once every row is entered: the winning wide rows' answers compete with the
        long rows of their labels; every row or answer that lost goes to the log. When the best counts,
        every answer kept competes: grading chooses."""
        if self.best is not None:
            return [Answer(row.file, row.line, student_id, label, text, row.delimiter, row.timestamp)
                    for (student_id, label), attempts in self.best.items() for text, row in attempts.rows.items()]
        for student_id, contest in self.wide.items():
            self._finish(contest, "")
            for label, _ in contest.winner.answers:
                self._enter(self.long, (student_id, label), contest.winner, label)
        answers = []
        for (student_id, label), contest in self.long.items():
            self._finish(contest, label)
            winner = contest.winner
            answers.append(Answer(winner.file, winner.line, student_id, label, winner.text(label), winner.delimiter,
                                  winner.timestamp))
        position = {label: index for index, label in enumerate(labels)}
        for contest in self.wide.values():
            if contest.winner.lost:
                self._lost_answers(contest.winner, position)
        return answers

    def _finish(self, contest: Contest, label: str) -> None:
        """The row kept as the last that does not win (the latest, by timestamp, does) loses."""
        if contest.last is not contest.winner:
            self._lost(contest.last, label, contest)

    def _lost_answers(self, row: SubmittedRow, position: Mapping[str, int]) -> None:
        """A winning wide row some of whose answers a later long row replaced: a caveat per answer, or,
        when it kept none, one routine problem for the row."""
        lost = sorted(row.lost or (), key=lambda pair: position[pair[0]])
        if len(lost) < len(row.answers):
            for label, contest in lost:
                self.log.add(REPLACED, row.order, row.file,
                             RowProblem(row.file, row.line, row.student_id, label, contest.why(), caveat=True))
            return
        whys = "; ".join(f"{label}: {contest.why()}" for label, contest in lost)
        self.log.add(SUPERSEDED, row.order, row.file, RowProblem(
            row.file, row.line, row.student_id, "", f"every answer superseded ({whys})", routine=True))



def _superseded(row: SubmittedRow, label: str, contest: Contest) -> Callable[[], RowProblem]:
    """The problem of a row that lost, made at the end: its reason names the winner."""
    return lambda: RowProblem(row.file, row.line, row.student_id, label, contest.why(), routine=True)
