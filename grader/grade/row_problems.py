"""Rows of submissions not used, or used with a caveat: each a :class:`RowProblem`, listed up to
:data:`LISTED` of each kind (the first in file order) and counted beyond, so that a file of ten million
rows nobody can use costs no memory per row and ``problems.csv`` stays readable.

>>> log = ProblemLog(listed=2)
>>> for line in (2, 3, 4, 5):
...     log.add(UNKNOWN, (0, line), "a.csv", RowProblem("a.csv", line, "x", "1a", "unknown student 'x'"))
>>> [(p.line, p.rows, p.reason) for p in log.problems()]  # doctest: +NORMALIZE_WHITESPACE
[(2, 1, "unknown student 'x'"), (3, 1, "unknown student 'x'"),
 (0, 2, '2 more rows that name no student of the answer key in this file, not listed (problems.csv lists the
  first 2 of each kind)')]
"""

from __future__ import annotations

import heapq
import itertools
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass

LISTED = 1000
"""Of each kind of row problem, problems.csv lists the first this many; the rest are counted."""


@dataclass(frozen=True)
class RowProblem:
    """Why a row (``label == ""``) or one answer of it was not used; ``caveat``: the row's answers
    were used all the same, and this is said so that nobody is surprised; ``routine``: not used by rule,
    with nothing for anyone to do (superseded by the same student's later answer, or one of Canvas' rows
    that are no student's), so it does not make a run end with "rows not graded"; ``rows``: how many rows
    it stands for (more than one for the line that counts the rows of a kind not listed; its ``line`` is 0)."""

    file: str
    line: int
    student_id: str
    label: str
    reason: str
    caveat: bool = False
    routine: bool = False
    rows: int = 1

    @property
    def not_graded(self) -> bool:
        """Whether a submitted answer went ungraded for a reason someone should look at."""
        return not self.caveat and not self.routine


@dataclass(frozen=True, eq=False)  # told apart by identity: hashed once a row, millions of times
class Kind:
    """A kind of row problem: what its rows are, in a few words, and whether it is a caveat or routine."""

    rows: str
    caveat: bool = False
    routine: bool = False


UNKNOWN = Kind("rows that name no student of the answer key")
ASIDE = Kind("rows that are no student's (Canvas' extra rows, a repeated header)", routine=True)
LABEL = Kind("rows whose label is not in the answer key")
EMPTY = Kind("rows with no answers")
MALFORMED = Kind("rows that could not be read")
SUPERSEDED = Kind("rows superseded by a later submission of the same student", routine=True)
ZEROS = Kind("rows whose student id had its leading zeros restored", caveat=True)
EMAIL_AS_ID = Kind("rows whose id column held a student's email, matched by email", caveat=True)
UNREADABLE_TIME = Kind("rows whose timestamp does not read", caveat=True)
FUTURE = Kind("rows with a timestamp after this run's time", caveat=True)
SAME = Kind("answers the same as one the student submitted before (the best attempt counts)", routine=True)
REPLACED = Kind("answers of a wide submission replaced by a later long row", caveat=True)

Order = tuple[int, int]
"""Where a row is: the file's place in argument order, then the line."""


class ProblemLog:
    """Row problems as they are found, in any order: of each kind the first ``listed`` by :data:`Order` are
    kept, the rest only counted, per file. A problem may be given as a function that makes it: it is made
    only if it is listed (a superseded row's reason names the winner, known at the end)."""

    def __init__(self, listed: int = LISTED) -> None:
        self.listed = listed
        self._kept: dict[Kind, list[tuple[Order, int, str, RowProblem | Callable[[], RowProblem]]]] = {}
        self._counts: Counter[tuple[Kind, str]] = Counter()
        self._sequence = itertools.count()

    def wants(self, kind: Kind, order: Order) -> bool:
        """Whether a problem of ``kind`` at ``order`` would be listed (else :meth:`count` it: cheaper)."""
        kept = self._kept.get(kind)
        return kept is None or len(kept) < self.listed or (-order[0], -order[1]) > kept[0][0]

    def count(self, kind: Kind, file: str) -> None:
        """One more problem of ``kind`` in ``file``, not listed."""
        self._counts[kind, file] += 1

    def add(self, kind: Kind, order: Order, file: str, problem: RowProblem | Callable[[], RowProblem]) -> None:
        """A problem of ``kind`` at ``order`` in ``file``: listed if among the first, else counted."""
        self._counts[kind, file] += 1
        kept = self._kept.setdefault(kind, [])
        entry = ((-order[0], -order[1]), next(self._sequence), file, problem)  # a heap whose top is the latest
        if len(kept) < self.listed:
            heapq.heappush(kept, entry)
        elif entry[0] > kept[0][0]:
            heapq.heapreplace(kept, entry)

    def unlisted(self) -> int:
        """How many problems are counted, not listed."""
        return sum(self._counts.values()) - sum(map(len, self._kept.values()))

    def problems(self) -> list[RowProblem]:
        """The listed problems, then per kind and file a line that counts those not listed."""
        listed, shown = [], Counter[tuple[Kind, str]]()
        for kind, kept in self._kept.items():
            for _, _, file, item in sorted(kept, key=lambda entry: (tuple(-n for n in entry[0]), entry[1])):
                listed.append(item if isinstance(item, RowProblem) else item())
                shown[kind, file] += 1
        more = [RowProblem(file, 0, "", "", f"{count - shown[kind, file]:,} more {kind.rows} in this file, not "
                           f"listed (problems.csv lists the first {self.listed:,} of each kind)", kind.caveat,
                           kind.routine, count - shown[kind, file])
                for (kind, file), count in self._counts.items() if count > shown[kind, file]]
        return listed + more
