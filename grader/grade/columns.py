"""What the columns of a submissions file mean: which holds the student, the label, the answer, the
timestamp, which answers which label (wide files), and which no rule claims.

Header names match case-insensitively, with ``_`` read as a space and spaces collapsed. A wide
column belongs to label ``1a`` when its header is ``1a`` or starts with ``1a`` and then a space,
``.``, ``:``, ``)`` or ``(``, as Google Forms writes questions:

>>> [label_of(header, ["1a", "1ab", "11a"]) for header in ["1A", "1a. Speed (m/s)", "1ab (m)", "11a", "1a_b"]]
['1a', '1a', '1ab', '11a', None]
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Literal

from grader.base.errors import GraderError, shown
from grader.base.inputs import CsvStream

STUDENT = ("student id", "id", "sid", "sis user id", "username")  # "student_id" reads as "student id"
EMAIL = ("email", "email address")
LABEL = ("label", "part", "question")
ANSWER = ("answer", "response", "value")
TIMESTAMP = ("timestamp", "submitted", "submitted at", "completion time", "submission time")  # MS Forms, Gradescope
_AFTER_LABEL = " .:)("

_EXPECTED = ("a long file (one answer a row: student_id, label, answer, optionally timestamp) or a wide file "
             "(one submission a row: student_id and a column per label, such as {labels}); the student may be "
             "named by student_id, id, sid, student id, SIS User ID or username, or else by email")


@dataclass(frozen=True)
class Layout:
    """The meaning of one file's columns, by header name as written."""

    wide: bool
    student: str  # the column naming the student: an id, or an email when ``by_email``
    by_email: bool
    label: str | None  # long files
    answer: str | None  # long files
    timestamp: str | None
    labels: dict[str, str]  # wide files: column -> label
    ignored: tuple[str, ...]


def normalized(header: str) -> str:
    """A header as it is matched: lower case, ``_`` as a space, spaces collapsed."""
    return " ".join(header.replace("_", " ").lower().split())


def label_of(header: str, labels: Sequence[str]) -> str | None:
    """The label whose answers a wide column holds (the longest that fits), or ``None``."""
    text = header.strip().lower()
    fits = [label for label in labels if text == label.lower()
            or (text.startswith(label.lower()) and text[len(label)] in _AFTER_LABEL)]
    return max(fits, key=len) if fits else None


def find_layout(table: CsvStream, labels: Sequence[str], fmt: Literal["auto", "long", "wide"],
                known: Callable[[str, bool], bool]) -> Layout:
    """The layout of ``table``; ``known(text, by_email)`` says whether a cell names a key's student
    (used to choose between several id columns: Canvas has both ``ID`` and ``SIS User ID``)."""
    named = {kind: [h for h in table.header if normalized(h) in names]
             for kind, names in (("student", STUDENT), ("email", EMAIL), ("label", LABEL), ("answer", ANSWER),
                                 ("timestamp", TIMESTAMP))}
    wide_columns = {h: label for h in table.header if not _claimed(h, named)
                    and (label := label_of(h, labels)) is not None}
    is_long = bool(named["label"] and named["answer"])
    wide = fmt == "wide" or (fmt == "auto" and not is_long and bool(wide_columns))
    student_columns = named["student"] or named["email"]
    if not student_columns or (not wide and not is_long) or (wide and not wide_columns):
        raise GraderError(f"{table.path}: line {table.header_line}: no recognisable header; expected "
                          f"{_EXPECTED.format(labels=', '.join(labels[:4]))}; got the columns "
                          f"{shown(list(table.header), 160)}")
    by_email = not named["student"]
    student = student_columns[0] if len(student_columns) == 1 else _most_known(table, student_columns, by_email, known)
    used = {student, *(named[kind][0] for kind in ("timestamp",) + (() if wide else ("label", "answer"))
                       if named[kind])}
    if wide:
        _check_one_column_per_label(table, wide_columns)
        used |= set(wide_columns)
    ignored = tuple(h for h in table.header if h not in used)
    return Layout(wide, student, by_email, None if wide else named["label"][0], None if wide else named["answer"][0],
                  named["timestamp"][0] if named["timestamp"] else None, wide_columns if wide else {}, ignored)


def _most_known(table: CsvStream, columns: list[str], by_email: bool, known: Callable[[str, bool], bool]) -> str:
    """The column of ``columns`` whose cells name the most students of the key (the first, of equals), in one
    reading of the rows."""
    found = dict.fromkeys(columns, 0)
    for row in table.rows():
        for column in columns:
            found[column] += known(row.cells[column], by_email)
    return max(columns, key=lambda column: (found[column], -columns.index(column)))


def _claimed(header: str, named: dict[str, list[str]]) -> bool:
    return any(header in columns for columns in named.values())


def _check_one_column_per_label(table: CsvStream, columns: dict[str, str]) -> None:
    seen: dict[str, str] = {}
    for column, label in columns.items():
        if label in seen:
            raise GraderError(f"{table.path}: line {table.header_line}: the columns {seen[label]!r} and {column!r} "
                              f"both answer {label}; expected one column per label")
        seen[label] = column
