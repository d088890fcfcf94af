"""The answer key as grading reads it: ``key.json`` (schema ``grader-key`` versions 1 and 2, see
:mod:`grader.assign.keyfile`) parsed and checked into frozen objects. Grading never regenerates.

>>> import json, pathlib, tempfile
>>> path = pathlib.Path(tempfile.mkdtemp()) / "key.json"
>>> _ = path.write_text(json.dumps({"schema": "grader-key", "version": 1,
...     "assignment": {"title": "HW"}, "problems": [{"key": "1", "title": "Drop",
...         "answers": [{"name": "e", "label": "1a", "unit": "", "points": 2}]}],
...     "students": [{"id": "007", "name": "Ana", "email": "a@x", "section": "1", "problems": [{"key": "1",
...         "answers": {"e": {"value": 0.7, "unit": "", "label": "1a", "points": 2,
...                           "tolerance": {"rtol": 0.01, "atol": 0}}}}]}]}))
>>> key = load_key(path)
>>> key.labels, key.students[0].id, key.students[0].parts["1a"].value, key.students[0].parts["1a"].tolerance
(('1a',), '007', 0.7, {'mode': 'rtol', 'rtol': 0.01, 'atol': 0})

A student's printed parameters (``params``), where the key has them, are kept for the class report:

>>> raw = json.loads(path.read_text())
>>> raw["students"][0]["problems"][0]["params"] = {"h_drop": 2.5, "h_rebound": 1.2}
>>> _ = path.write_text(json.dumps(raw))
>>> load_key(path).students[0].params("1")
{'h_drop': 2.5, 'h_rebound': 1.2}
"""

from __future__ import annotations

import functools
import itertools
import json
import math
import re
import sys
import zoneinfo
from array import array
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from datetime import UTC, datetime, tzinfo
from pathlib import Path
from typing import Any, TypeVar

import numpy as np

from grader.assign.assignment import MAX_POINTS, Grading, grading_from
from grader.assign.deadlines import DEFAULT_ZONE, LatePolicy, late_from, zone_from
from grader.assign.key_columns import (
    NONE,
    NUMBER,
    TEXT,
    UNIT,
    KeyColumns,
    read_key_columns,
    sidecar,
)
from grader.base.errors import GraderError, TemplateError, shown
from grader.base.inputs import CELL_CHARS, decode_text, read_bytes, regular_size
from grader.base.numbering import numbered, numbered_first, numbered_rows
from grader.grade.key_parts import KeyPart as KeyPart  # grading's parts, made here
from grader.grade.key_parts import PartTable, StudentParts
from grader.grade.notation import ReadError, check_powers
from grader.model.expr import names, parse
from grader.model.quantities import parse_unit
from grader.model.tolerance import SYMBOL_RANGE, Tolerance

VERSIONS = (1, 2)  # the key schema versions grading reads
# 1 GiB: the most of key.json read whole and decoded, which a key needs when it has no sidecar made from it
# (key.columns.npz); 2,000 students take about 6 MB, 100,000 about 290 MB. A key with its sidecar has no
# limit of size: it is hashed a piece at a time and graded from the sidecar.
KEY_BYTES = 1 << 30

_T = TypeVar("_T")


@dataclass(frozen=True, slots=True)
class KeyStudent:
    """A student of the key, their answer parts by label, and their parameters as printed, by problem key."""

    id: str
    name: str
    email: str
    section: str
    parts: Mapping[str, KeyPart]
    # The parameters printed on the student's sheet, kept flat (a class of 100,000 has 1.5 million):
    # ``values[i]`` is parameter ``parameters[i]``, a (problem key, name) pair; the class shares one
    # ``parameters`` tuple. A key without ``params`` (or a value that is no number) leaves them out.
    parameters: tuple[tuple[str, str], ...] = ()
    values: Sequence[float] = ()  # a key read from a file gives them as an array('d'): 8 bytes each
    due: datetime | None = None  # the student's own due time (an extension), if any

    @property
    def possible(self) -> float:
        """The points this student could earn."""
        if isinstance(self.parts, StudentParts):
            return self.parts.possible()  # without making the parts
        return sum(part.points for part in self.parts.values())

    def params(self, problem: str) -> dict[str, float]:
        """The parameters printed for one problem (its key, ``1``), by name."""
        return {name: value for (key, name), value in zip(self.parameters, self.values, strict=True) if key == problem}


@dataclass(frozen=True)
class KeyProblem:
    """A problem: its key (``1``), title, its parts' labels in order, its template's id and its parameters'
    units."""

    key: str
    title: str
    labels: tuple[str, ...]
    template: str = ""
    units: Mapping[str, str] = field(default_factory=dict)  # each parameter's unit (a key before them has none)


@dataclass(frozen=True)
class Key:
    """A loaded answer key."""

    where: str
    version: int
    title: str
    numeric_expressions: bool
    problems: tuple[KeyProblem, ...]
    students: tuple[KeyStudent, ...]
    templates: Mapping[str, str] = field(default_factory=dict)  # id -> SHA-256 of the file the key was made from
    ecf_credit: float = 1.0  # of a part right for the student's own earlier answer (0: no error carried forward)
    mistake_credit: float = 0.0  # of a part that matches a diagnosed mistake
    # id -> the bank folder its file was in, as the key records it (relative to the key's folder where it could
    # be; none for the shipped bank's templates, nor in a key written before it was recorded)
    banks: Mapping[str, str] = field(default_factory=dict)
    attempts: str = "latest"  # which submission counts: latest, best or first
    deadline: datetime | None = None  # the assignment's due time (None: lateness is not measured)
    zone: tzinfo = UTC  # of timestamps that give none
    late: LatePolicy | None = None  # None: late work is accepted as on time
    integrity_threshold: float = 0.05  # pairs whose matches are at most this likely by accident are flagged
    # Where :attr:`students` are in the key they were read with, for a piece of it (:meth:`piece`): (start, stop).
    span: tuple[int, int] | None = field(default=None, compare=False, repr=False)

    @functools.cached_property
    def labels(self) -> tuple[str, ...]:
        """Every part's label, in the order of the sheet (worked out once: ``check --batch`` reads it a line)."""
        return tuple(label for problem in self.problems for label in problem.labels)

    @property
    def possible(self) -> float:
        """The most points a student can earn (Canvas' "points possible" of the assignment)."""
        return max((student.possible for student in self.students), default=0.0)

    def part_column(self, label: str) -> list[KeyPart]:
        """Every student's part ``label``, in the students' order: made together where the key was read from
        its sidecar (a part at a time, each looked up, takes five times as long)."""
        table = self._table()
        if table is not None:
            return table.column(label, *self.span or (0, len(self.students)))
        return [student.parts[label] for student in self.students]

    def part_entries(self, label: str, field: str) -> list[Any]:
        """Every student's entry ``field`` (``value``, ``tolerance``, any of :class:`KeyPart`'s) of their part
        ``label``, in the students' order: where the key was read from its sidecar, without making the parts."""
        table = self._table()
        if table is not None:
            return table.entries(label, field, *self.span or (0, len(self.students)))
        return [getattr(student.parts[label], field) for student in self.students]

    def _table(self) -> PartTable | None:
        """The sidecar's table the students' parts are rows of (None: the key was not read from one)."""
        first = self.students[0].parts if self.students else None
        if not isinstance(first, StudentParts):
            return None
        table = first.table
        return table if table.students is self.students or self.span is not None else None

    def piece(self, start: int, stop: int) -> Key:
        """The key of students ``start`` to ``stop`` (in its order) alone, as grading takes a class a piece at a
        time: their parts read from the same columns, their parameters the same columns' rows."""
        base = self.span[0] if self.span else 0
        found = replace(self, students=self.students[start:stop], span=(base + start, base + stop))
        found.__dict__["timed"] = self.timed  # a piece whose students have no due time is still the class's
        if "parameter_columns" in self.__dict__:  # worked out for the class: its rows, not worked out again
            found.__dict__["parameter_columns"] = {name: column[start:stop]
                                                   for name, column in self.parameter_columns.items()}
        return found

    @functools.cached_property
    def timed(self) -> bool:
        """Whether the class has due times (the assignment's, or a student's own): then every answer's lateness
        is measured (a student without a due time: not known). A piece of the key (:meth:`piece`) is timed as its
        class is, though none of its own students has a due time."""
        return self.deadline is not None or any(student.due for student in self.students)

    @functools.cached_property
    def positions(self) -> dict[str, int]:
        """Each student's place in :attr:`students`, by id; worked out once (``grader check --batch`` looks
        a student up a line)."""
        return {student.id: index for index, student in enumerate(self.students)}

    @functools.cached_property
    def parameter_columns(self) -> dict[tuple[str, str], np.ndarray]:
        """Each (problem key, name) of a parameter any student has, with its value per student (NaN where
        a student has none); worked out once (the diagnosis and the class report both read it). Students
        share their ``parameters`` tuple: one layout is placed at a time."""
        students = self.students
        layouts: dict[int, tuple[tuple[tuple[str, str], ...], list[int]]] = {}
        for index, student in enumerate(students):
            layouts.setdefault(id(student.parameters), (student.parameters, []))[1].append(index)
        # Each name's column found by a dict, once per layout: a search of the list per name was
        # quadratic (20,000 names took 7 s).
        column_of = {name: column for column, name in enumerate(dict.fromkeys(
            name for layout, _ in layouts.values() for name in layout))}
        table = np.full((len(students), len(column_of)), np.nan)
        for layout, members in layouts.values():
            if layout:
                values = itertools.chain.from_iterable(students[index].values for index in members)
                table[np.array(members)[:, None], [column_of[name] for name in layout]] = np.fromiter(
                    values, np.float64, len(members) * len(layout)).reshape(len(members), len(layout))
        return {name: table[:, column] for name, column in column_of.items()}


def load_key(path: Path) -> Key:
    """Read and check a key file; a file that is not a grader key is refused with the reason."""
    where = str(path)
    columns = read_key_columns(path)  # the sidecar grader generate wrote, if it was made from these bytes
    key = None if columns is None else _key_from_columns(columns, where)
    if key is not None:
        return key
    del columns
    data = read_bytes(_within_limit(path), KEY_BYTES)
    text = decode_text(data, path)
    del data
    try:
        if _ESCAPED_SURROGATE.search(text):  # rare: JSON escapes a character beyond U+FFFF as two; one alone is none
            _refuse_lone_surrogates(json.loads(text), where)
        raw = _decode(text)
    except (ValueError, RecursionError) as error:
        raise GraderError(f"{where}: expected a key.json that grader wrote, got invalid JSON ({error})") from None
    del text  # the students are read: the text can go before the key is checked
    if not isinstance(raw, dict) or raw.get("schema") != "grader-key":
        raise GraderError(f"{where}: expected a grader answer key (schema grader-key, written by grader generate), "
                          f"got {shown(raw.get('schema') if isinstance(raw, dict) else type(raw).__name__)}")
    version = raw.get("version")
    if type(version) is not int or version not in VERSIONS:  # not True, nor 2.0: no grader writes those
        why = " (a newer grader wrote it? update grader)" if type(version) is int else " (not the whole number 1 or 2)"
        raise GraderError(f"{where}: expected key schema version 1 or 2, got {shown(version)}{why}")
    try:
        return _key(raw, where, version)
    except _MalformedError as error:
        raise GraderError(f"{where}: a grader key with a missing or malformed entry ({error}); "
                          "regenerate it with grader generate") from None
    except _EntryError as error:
        raise GraderError(f"{where}: {error}; correct it, or regenerate the key with grader generate") from None


_ESCAPED_SURROGATE = re.compile(r"\\u[dD][89a-fA-F]")


def _within_limit(path: Path) -> Path:
    """``path``, unless it is a regular file over :data:`KEY_BYTES`: that is refused with the way out."""
    size = regular_size(path)
    if size > KEY_BYTES:
        beside = sidecar(path).name
        raise GraderError(f"{path}: {size:,} bytes, more than the {KEY_BYTES:,} a key.json is read whole within; a "
                          f"larger key is graded from the {beside} beside it, which is missing, unreadable or made "
                          f"from another key.json: regenerate the key with grader generate, which writes {beside} "
                          "beside it")
    return path


def _refuse_lone_surrogates(raw: Any, where: str) -> None:
    r"""Refuse a text holding half of a character (``"\ud800"`` alone): no report could write it as UTF-8.

    >>> _refuse_lone_surrogates({"students": [{"name": "Ana \U0001f600"}]}, "k.json")  # a whole pair: text
    >>> _refuse_lone_surrogates({"students": [{"name": "Ana \ud800"}]}, "k.json")
    Traceback (most recent call last):
    ...
    grader.base.errors.GraderError: k.json: students[0].name: expected text, got half of a character ('\ud800'); ...
    """
    stack: list[tuple[str, Any]] = [("", raw)]
    while stack:
        here, value = stack.pop()
        if isinstance(value, dict):
            stack.extend((f"{here}.{name}" if here else str(name), item) for name, item in value.items())
            stack.extend((f"{here}: a key", name) for name in value)
        elif isinstance(value, list):
            stack.extend((f"{here}[{index}]", item) for index, item in enumerate(value))
        elif isinstance(value, str) and any("\ud800" <= character <= "\udfff" for character in value):
            half = next(character for character in value if "\ud800" <= character <= "\udfff")
            raise GraderError(f"{where}: {here}: expected text, got half of a character ({half!a}); "
                              "regenerate the key with grader generate")


class _EntryError(ValueError):
    """An entry of the key that is present but unusable (a tolerance, unit, expression, points or text no
    grader key holds); the message says which and why."""


class _MalformedError(_EntryError):
    """The key's JSON lacks an entry grader writes, or has one of another type; the message says which.
    Every entry is checked before it is used, so an exception of another kind while reading is a bug."""


def _object(value: Any, what: str) -> dict[str, Any]:
    if type(value) is not dict:
        raise _MalformedError(f"{what}: expected an object, got {shown(value)}")
    return value


def _array(value: Any, what: str) -> list[Any]:
    if type(value) is not list:
        raise _MalformedError(f"{what}: expected a list, got {shown(value)}")
    return value


def _field(raw: Mapping[str, Any], name: str, what: str) -> Any:
    """The entry ``name`` of the object ``raw`` (``what``, for the message)."""
    if type(raw) is not dict:
        raise _MalformedError(f"{what}: expected an object, got {shown(raw)}")
    if name not in raw:
        raise _MalformedError(f"{what}: no entry {name!r}")
    return raw[name]


def _no_constant(name: str) -> float:
    raise ValueError(f"{name} is not a number a key holds")


# --- decoding: a key of 100,000 students is 250 MB of JSON ---------------------------------------

_SPACE = re.compile(r"[ \t\n\r]*")  # JSON's whitespace


class _UnusualLayoutError(Exception):
    """The text is not laid out as :func:`_streamed` expects; :func:`json.loads` reads it instead."""


def _decode(text: str) -> Any:
    """``json.loads(text)``, except that students come back as :class:`KeyStudent` where they can be
    read as they are decoded (each student's JSON objects are dropped at once: decoded whole, a big
    key's objects take six times its text). Invalid JSON raises what ``json.loads`` raises.

    >>> _decode('{"schema": "x", "students": [{"id": 1}, 2]}')
    {'schema': 'x', 'students': [{'id': 1}, 2]}
    """
    decoder = json.JSONDecoder(parse_constant=_no_constant)
    try:
        return _streamed(text, decoder)
    except (_UnusualLayoutError, ValueError, RecursionError):
        return decoder.decode(text)  # the whole text again: its result, or the error json.loads gives


def _streamed(text: str, decoder: json.JSONDecoder) -> dict[str, Any]:
    """The top-level object read entry by entry, its ``students`` array student by student."""
    raw: dict[str, Any] = {}
    position = _expect(text, 0, "{")
    while True:
        if text[position:position + 1] != '"':
            raise _UnusualLayoutError
        name, position = decoder.raw_decode(text, position)
        position = _expect(text, position, ":")
        if name in raw:
            raise _UnusualLayoutError  # a name given twice: json.loads's rule (the last one wins) decides
        if name == "students" and text[position:position + 1] == "[":
            raw[name], position = _students(text, position + 1, decoder, _reader(raw))
        else:
            raw[name], position = decoder.raw_decode(text, position)
        position = _skip(text, position)
        if text[position:position + 1] == "}":
            break
        position = _expect(text, position, ",")
    if _skip(text, position + 1) != len(text):
        raise _UnusualLayoutError
    return raw


def _students(text: str, position: int, decoder: json.JSONDecoder,
              read: Callable[[Any], Any]) -> tuple[list[Any], int]:
    items: list[Any] = []
    position = _skip(text, position)
    if text[position:position + 1] == "]":
        return items, position + 1
    while True:
        student, position = decoder.raw_decode(text, position)
        items.append(read(student))
        position = _skip(text, position)
        if text[position:position + 1] == "]":
            return items, position + 1
        position = _expect(text, position, ",")


def _skip(text: str, position: int) -> int:
    """The position after the whitespace at ``position``."""
    space = _SPACE.match(text, position)
    return space.end() if space else position


def _expect(text: str, position: int, char: str) -> int:
    """The position after ``char`` and the whitespace after it, at ``position`` after whitespace."""
    position = _skip(text, position)
    if text[position:position + 1] != char:
        raise _UnusualLayoutError
    return _skip(text, position + 1)


def _reader(header: Mapping[str, Any]) -> Callable[[Any], Any]:
    """What becomes of each student as it is decoded: a :class:`KeyStudent` when the entries before
    the students make a usable key; otherwise, or when a student does not read, the student's JSON,
    for :func:`_key` to read and refuse in order, as it would without this shortcut."""
    usable = header.get("schema") == "grader-key" and type(header.get("version")) is int \
        and header.get("version") in VERSIONS and "problems" in header
    try:
        symbols = _symbols(header["problems"]) if usable else None
    except _EntryError:  # refused later, in order, by _key
        symbols = None
    if symbols is None:
        return lambda student: student
    shared: dict[Any, Any] = {}

    def read(student: Any) -> Any:
        try:
            return _student(_object(student, "a student"), symbols, shared)
        except _EntryError:  # refused later, in order, by _key
            return student

    return read


# --- the key's objects ----------------------------------------------------------------------------

def _key(raw: Mapping[str, Any], where: str, version: int) -> Key:
    problems = _problems(_field(raw, "problems", "the key"))
    symbols = _symbols(raw["problems"])
    shared: dict[Any, Any] = {}
    students = tuple(s if isinstance(s, KeyStudent) else _student(_object(s, "a student"), symbols, shared)
                     for s in _array(_field(raw, "students", "the key"), "students"))
    if not students or not problems:
        raise _EntryError(f"expected at least one {'student' if not students else 'problem'}, got none (grader "
                          "generate writes a key for a roster of students and an assignment of problems)")
    _once([s.id for s in students], lambda index: f"students[{index}].id", "the student id", "each student once")
    labels = {label for problem in problems for label in problem.labels}
    for student in students:
        if set(student.parts) != labels:
            raise _MalformedError(f"student {student.id} has parts {sorted(student.parts)}, the problems "
                                  f"{sorted(labels)}")
    assignment = _object(_field(raw, "assignment", "the key"), "assignment")
    grading = _grading(assignment.get("grading"), where)
    entries = {name: _object(entry, f"templates.{name}")
               for name, entry in _object(raw.get("templates", {}), "templates").items()}
    templates = {name: str(entry.get("sha256", "")) for name, entry in entries.items()}
    banks = {name: _text(entry["bank"], f"templates.{name}.bank") for name, entry in entries.items() if "bank" in entry}
    zone, deadline, late = _deadline(assignment, where)
    return Key(where, version, _text(_field(assignment, "title", "assignment"), "assignment.title"),
               grading.numeric_expressions, problems, students, templates, grading.ecf_credit, grading.mistake_credit,
               banks, grading.attempts, deadline, zone, late, grading.integrity_threshold)


def _deadline(assignment: Mapping[str, Any], where: str) -> tuple[zoneinfo.ZoneInfo, datetime | None,
                                                                   LatePolicy | None]:
    """The key's zone, due time and late policy, checked as an assignment's are (a key without them, as
    keys before deadlines: UTC, none, none)."""
    try:
        zone = zone_from(assignment.get("timezone", DEFAULT_ZONE), where, "assignment.timezone")
        late = None if assignment.get("late") is None else late_from(assignment["late"], where, "assignment.late")
    except TemplateError as error:
        raise _EntryError(f"{error.key}: expected {error.expected}, got {error.got}") from None
    deadline = assignment.get("deadline")
    if deadline is None:
        if late is not None:
            raise _EntryError("assignment.late: a late policy without a deadline")
        return zone, None, None
    return zone, _instant(deadline, "assignment.deadline"), late


def _instant(value: Any, what: str) -> datetime:
    """A due time as the key writes it: ISO 8601 with its offset."""
    try:
        when = datetime.fromisoformat(value) if isinstance(value, str) else None
    except ValueError:
        when = None
    if when is None or when.tzinfo is None:
        raise _EntryError(f"{what}: expected a date-time with its offset such as 2026-12-04T23:59:00-06:00, got "
                          f"{shown(value)}")
    return when


def _problems(raw: Any) -> tuple[KeyProblem, ...]:
    """The key's problems, each key and each part's label given once (two problems with one key would
    be graded, and totalled, twice; two parts with one label would share one column of answers)."""
    problems = tuple(KeyProblem(str(_field(p, "key", f"problems[{index}]")), _text(p.get("title", ""),
                                                                                   "a problem's title"),
                                tuple(_label(_field(a, "label", f"problems[{index}].answers[{number}]"),
                                             f"problems[{index}].answers[{number}].label")
                                      for number, a in enumerate(_answers(p, index))),
                                _text(p.get("template", ""), "a problem's template"), _units(p, index))
                     for index, p in enumerate(_array(raw, "problems")))
    _once([p.key for p in problems], lambda index: f"problems[{index}].key", "the problem key", "each problem once")
    places = [f"problems[{index}].answers[{number}].label" for index, p in enumerate(problems)
              for number in range(len(p.labels))]
    _once([label for p in problems for label in p.labels], places.__getitem__, "the label",
          "each part's label once")
    return problems


def _units(problem: Mapping[str, Any], index: int) -> dict[str, str]:
    """A problem's parameters' units, by name (a key written before they were recorded has none)."""
    where = f"problems[{index}].parameters"
    return {_text(name, where): _text(unit, f"{where}.{name}")
            for name, unit in _object(problem.get("parameters", {}), where).items()}


def _once(values: list[str], place: Callable[[int], str], what: str, expected: str) -> None:
    """Refuse the second of two equal ``values``, naming both places.

    >>> _once(["1", "2", "1"], lambda index: f"problems[{index}].key", "the problem key", "each problem once")
    Traceback (most recent call last):
    ...
    grader.grade.key._EntryError: problems[2].key: the problem key '1' appears twice (also problems[0].key); ...
    """
    first: dict[str, int] = {}
    for index, value in enumerate(values):
        earlier = first.setdefault(value, index)
        if earlier != index:
            raise _EntryError(f"{place(index)}: {what} {shown(value)} appears twice (also {place(earlier)}); "
                              f"expected {expected}")


def _label(value: Any, where: str) -> str:
    """A part's label: text with something to type (submissions name parts by it)."""
    label = _text(value, where)
    if not label.strip():
        raise _EntryError(f"{where}: expected a label such as 1a, got {shown(label)}")
    return label


def _grading(raw: Any, where: str) -> Grading:
    """The key's copy of the assignment's ``grading``, checked as an assignment's is."""
    try:
        return grading_from(raw, where, "assignment.grading")
    except TemplateError as error:
        raise _EntryError(f"{error.key}: expected {error.expected}, got {error.got}") from None


def _answers(problem: Any, index: int) -> list[dict[str, Any]]:
    """The answers of the key's problem ``index`` (its entry in ``problems``), each an object."""
    where = f"problems[{index}]"
    answers = _array(_field(_object(problem, where), "answers", where), f"{where}.answers")
    return [_object(answer, f"{where}.answers[{number}]") for number, answer in enumerate(answers)]


def _symbols(problems: Any) -> dict[str, dict[str, tuple[float, float]]]:
    """Per label, where each name of a symbolic answer is drawn (empty for numeric answers)."""
    return {str(_field(a, "label", "an answer")): {n: _range(a["label"], n, r)
                                                   for n, r in _object(a.get("symbols", {}), "symbols").items()}
            for index, p in enumerate(_array(problems, "problems")) for a in _answers(p, index)}


def _range(label: str, name: str, bounds: Any) -> tuple[float, float]:
    """A symbol's range: two finite numbers, low below high, whose span is finite too (random points are
    drawn across it)."""
    numbers = isinstance(bounds, list) and len(bounds) == 2 and all(
        type(bound) in (int, float) and abs(bound) <= sys.float_info.max for bound in bounds)  # not 10**400, NaN
    low, high = (float(bounds[0]), float(bounds[1])) if numbers else (0.0, 0.0)
    if not (low < high and math.isfinite(high - low)):
        raise _EntryError(f"answer {label}: symbols.{name}: expected [LOW, HIGH] with LOW < HIGH, finite, got "
                          f"{shown(bounds)}")
    return low, high


def _text(value: Any, what: str, field: str = "") -> str:
    """A text entry (an id, name, label, unit, title): text of at most CELL_CHARS characters, as in a
    roster (half a character anywhere in the key is refused as it is read: :func:`_refuse_lone_surrogates`).
    ``what`` and ``field`` name it in the message (``answer e``, ``label``): joined only if there is one."""
    if not isinstance(value, str) or len(value) > CELL_CHARS:
        where = f"{what}: {field}" if field else what
        raise _EntryError(f"{where}: expected text of at most {CELL_CHARS} characters, got {shown(value)}")
    return value


def _student(raw: Mapping[str, Any], symbols: Mapping[str, Mapping[str, tuple[float, float]]],
             shared: dict[Any, Any]) -> KeyStudent:
    student_id = _text(_field(raw, "id", "a student"), "a student's id")
    if not student_id.strip():
        raise _EntryError(f"a student's id: expected an id, got {shown(student_id)}")
    parts: dict[str, KeyPart] = {}
    parameters: list[tuple[str, str]] = []
    values: list[float] = []
    keys: set[str] = set()
    for number, problem in enumerate(_array(_field(raw, "problems", f"student {student_id}"),
                                            f"student {student_id}: problems")):
        where = f"student {student_id}: problems[{number}]"
        problem = _object(problem, where)
        key = _one(shared, str(_field(problem, "key", where)))
        if key in keys:
            raise _EntryError(f"student {student_id}: the problem key {shown(key)} appears twice; expected each "
                              "problem once")
        keys.add(key)
        for name, answer in _object(_field(problem, "answers", where), f"{where}.answers").items():
            try:
                part = _part(key, _one(shared, name), _object(answer, f"answer {name}"), symbols, shared)
            except _EntryError as error:
                raise type(error)(f"student {student_id}: {error}") from None
            if part.label in parts:
                raise _EntryError(f"student {student_id}: answer {name}: the label {shown(part.label)} appears twice "
                                  f"(also answer {parts[part.label].name}); expected each part's label once")
            parts[part.label] = part
        printed = problem.get("params")
        for name, value in printed.items() if isinstance(printed, dict) else ():
            if type(value) in (int, float) and _printable(value):  # not bool
                parameters.append((key, str(name)))
                values.append(float(value))
    name, email, section = (_text(raw.get(entry, ""), f"student {student_id}: {entry}")
                            for entry in ("name", "email", "section"))
    due = None if raw.get("due") is None else _instant(raw["due"], f"student {student_id}: due")
    return KeyStudent(student_id, name, email, section, parts, _one(shared, ("parameters", tuple(parameters)))[1],
                      array("d", values), due)


def _part(problem: str, name: str, raw: Mapping[str, Any],
          symbols: Mapping[str, Mapping[str, tuple[float, float]]], shared: dict[Any, Any]) -> KeyPart:
    what = f"answer {name}"  # in a message, if there is one
    value = _field(raw, "value", what)
    if type(value) is not float:  # a float is the usual value, and needs only the check below
        if isinstance(value, bool) or not (value is None or isinstance(value, (int, float, str))):
            raise _MalformedError(f"answer {name}: a value that is no number, expression or null")
        if isinstance(value, int) and abs(value) > sys.float_info.max:
            raise _MalformedError(f"answer {name}: a value beyond float64")
        value = float(value) if isinstance(value, (int, float)) else value
    if isinstance(value, float) and not math.isfinite(value):
        raise _MalformedError(f"answer {name}: a value that is not finite")
    label = _text(_field(raw, "label", what), what, "label")
    label = _one(shared, label)
    unit = _unit(raw.get("unit", ""), name, shared)
    points = _one(shared, _points(_field(raw, "points", what), name))
    domains = symbols.get(label, {})  # the label's own: one mapping for the whole class
    if isinstance(value, str):
        used = shared.get(("names", value))
        if used is None:
            used = shared[("names", value)] = _names(value, name)
        if not domains:
            domains = shared.get(("symbols", value)) or shared.setdefault(
                ("symbols", value), dict.fromkeys(sorted(used), SYMBOL_RANGE))
        elif not used <= domains.keys():
            raise _EntryError(f"answer {name}: the expression {shown(value)} uses "
                              f"{', '.join(sorted(used - domains.keys()))}, not among its symbols "
                              f"({', '.join(domains)})")
    undefined = raw.get("undefined")
    if not (undefined is None or isinstance(undefined, str)):
        raise _EntryError(f"answer {name}: undefined: expected the reason as text, got {shown(undefined)}")
    return KeyPart(problem, name, label, value, unit, points,
                   _tolerance(_field(raw, "tolerance", what), name, shared), undefined, domains)


def _names(expression: str, name: str) -> frozenset[str]:
    """The names a symbolic answer of the key uses; an expression the allow-list parser refuses, or with a
    power too large to evaluate (``v**9**9``), is refused."""
    try:
        tree = parse(expression)
        check_powers(tree)
    except (GraderError, ReadError) as error:
        raise _EntryError(f"answer {name}: {error}") from None
    return frozenset(names(tree))


def _unit(text: Any, name: str, shared: dict[Any, Any]) -> str:
    """An answer's unit, checked once per distinct text: one a key can hold (``m/s``, ``deg``, ``%``)."""
    unit = shared.get(("unit", text)) if isinstance(text, str) else None
    if unit is None:
        try:
            parse_unit(_text(text, f"answer {name}: unit"))
        except GraderError as error:
            raise _EntryError(f"answer {name}: unit: {error}") from None
        unit = shared[("unit", text)] = text
    return unit  # type: ignore[no-any-return]


def _points(value: Any, name: str) -> float:
    """An answer's points: a number from 0 to MAX_POINTS, as an assignment gives them."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0 <= value <= MAX_POINTS:
        raise _EntryError(f"answer {name}: points: expected a number from 0 to {MAX_POINTS:,}, got {shown(value)}")
    return float(value)


def _one(shared: dict[Any, Any], value: _T) -> _T:
    """One object for all equal texts and numbers (labels, units, points of 100,000 students)."""
    return shared.setdefault(value, value)  # type: ignore[no-any-return]


def _tolerance(raw: Any, name: str, shared: dict[Any, Any]) -> Mapping[str, Any]:
    """The part's tolerance (version 1 has no mode: ``{"rtol", "atol"}``), one mapping for equal ones,
    each checked once (a tolerance grading would refuse is refused here, naming the answer)."""
    if type(raw) is not dict:
        raise _MalformedError(f"answer {name}: tolerance: expected an object, got {shown(raw)}")
    key: tuple[Any, ...] | None = ("tolerance", tuple(raw.items()), tuple(map(type, raw.values())))  # True is not 1
    try:
        found = shared.get(key)
    except TypeError:  # a list or an object among the values cannot be a key: Tolerance.from_json refuses it
        key, found = None, None
    if found is None:
        found = {"mode": "rtol", **raw}
        try:
            Tolerance.from_json(found)
        except GraderError as error:
            raise _EntryError(f"answer {name}: {error}") from None
        if key is not None:
            shared[key] = found
    return found


def _printable(value: float) -> bool:
    """Whether a printed parameter is kept: not NaN, nor beyond float64."""
    return abs(value) < 1.7e308


# --- the sidecar: the same students from columns (grader.assign.key_columns) ------------------------


def _key_from_columns(columns: KeyColumns, where: str) -> Key | None:
    """The key the sidecar's columns hold, checked as :func:`load_key` checks ``key.json``; None where any
    check fails: ``key.json`` is then read, and refused with its own message, in its own order."""
    header = columns.header
    version = header.get("version") if type(header) is dict else None
    if type(header) is not dict or header.get("schema") != "grader-key" or type(version) is not int \
            or version not in VERSIONS:
        return None
    try:
        students, table = _columns_students(columns, _symbols(_field(header, "problems", "the key")))
        key = _key({**header, "students": students}, where, version)
    except _EntryError:
        return None
    table.students = key.students  # Key.part_column reads the table's columns for these students
    return key


def _columns_students(columns: KeyColumns, symbols: Mapping[str, Mapping[str, tuple[float, float]]]
                      ) -> tuple[list[KeyStudent], PartTable]:
    """The students of the columns, each entry checked as :func:`_student` checks it (once per distinct
    text, unit, tolerance and points), and the table their parts are rows of; :class:`_EntryError` where one
    fails. Parts are not made here: a student's are made when they are asked for."""
    shared: dict[Any, Any] = {}
    kinds = columns.code[:, TEXT]
    if not np.isfinite(columns.value[kinds == NUMBER]).all():
        raise _EntryError("a value that is not finite")
    layouts = [_layout(shape, shared) for shape in columns.shapes]
    sizes = np.array([size for _, _, size in layouts] or [0], np.int64)
    counts = sizes[columns.shape]
    starts = np.cumsum(counts) - counts  # each student's first row
    shapes, shape_of = _shapes(columns, layouts, sizes, starts, counts, symbols, shared)
    others = np.flatnonzero(kinds != NUMBER)  # rows whose value is an expression, or null
    specials = {row: _valued(shapes[shape], None if kind == NONE else columns.texts[kind], shared)
                for row, kind, shape in zip(others.tolist(), kinds[others].tolist(), shape_of[others].tolist(),
                                            strict=True)}
    table = PartTable(shapes, shape_of, columns.value, specials)
    layout_of, offsets = _label_layouts(columns.shape, layouts, starts, shapes, shape_of)
    parts = table.place(starts, layout_of, offsets)
    _check_people(columns)
    params = array("d", np.ascontiguousarray(columns.params, np.float64).tobytes())
    every_printed = bool((np.abs(columns.params) < 1.7e308).all())
    dues: dict[str, datetime] = {}
    sections: dict[str, str] = {}  # one text a section (a class has a few), not one a student
    students, parameter = [], 0
    for student_id, name, email, section, due, shape, own in zip(columns.ids, columns.names, columns.emails,
                                                                 columns.sections, columns.dues, columns.shape.tolist(),
                                                                 parts, strict=True):
        names = layouts[shape][1]
        printed = params[parameter:parameter + len(names)]
        parameter += len(names)
        if not every_printed:
            names = _one(shared, ("parameters", tuple(pair for pair, number in zip(names, printed, strict=True)
                                                      if _printable(number))))[1]
            printed = array("d", [number for number in printed if _printable(number)])
        when = None if due is None else dues.get(due) or dues.setdefault(due, _instant(due, "due"))
        students.append(KeyStudent(student_id, name, email, sections.setdefault(section, section), own, names, printed,
                                   when))
    return students, table


def _shapes(columns: KeyColumns, layouts: list[tuple[list[tuple[str, list[str]]], Any, int]], sizes: np.ndarray,
            starts: np.ndarray, counts: np.ndarray, symbols: Mapping[str, Mapping[str, tuple[float, float]]],
            shared: dict[Any, Any]) -> tuple[list[KeyPart], np.ndarray]:
    """The distinct parts of the class but their values (each checked once, as :func:`_part` checks it) and
    which of them each row is. A row's part is told by its place in its student's layout (the problem and the
    answer's name) and its combination of entries (:func:`_combinations`)."""
    places = [(problem, name) for answers, _, _ in layouts for problem, names in answers for name in names]
    rows = len(columns.value)
    place = np.repeat((np.cumsum(sizes) - sizes)[columns.shape] - starts, counts) + np.arange(rows)
    first, which = _combinations(columns)
    distinct, inverse, at = numbered_first(place * len(first) + which)
    rests, points = columns.code[first, UNIT:].tolist(), columns.points[first].tolist()
    shapes: list[KeyPart] = []
    found: dict[tuple[Any, ...], int] = {}
    number = np.zeros(len(distinct), np.int32)
    # In the order the rows first have them: -0.0 points are 0.0's, one shape, the first found (as before).
    for index in np.argsort(at, kind="stable").tolist():
        slot, combination = divmod(int(distinct[index]), len(first))
        key = (*places[slot], *rests[combination], points[combination])
        if key not in found:
            found[key] = len(shapes)
            shapes.append(_part_shape(key, columns.texts, columns.tolerances, symbols, shared))
        number[index] = found[key]
    return shapes, number[inverse]


def _label_layouts(shape: np.ndarray, layouts: list[tuple[Any, Any, int]], starts: np.ndarray,
                   shapes: list[KeyPart], shape_of: np.ndarray) -> tuple[np.ndarray, list[dict[str, int]]]:
    """Each student's labels in order, as the place of each label among their rows (one mapping for the
    students who share it) and which of them each student has; :class:`_EntryError` where a student has a
    label twice."""
    label_numbers: dict[str, int] = {}
    label_of = np.array([label_numbers.setdefault(part.label, len(label_numbers)) for part in shapes], np.int64)
    labels = list(label_numbers)
    layout_of = np.zeros(len(shape), np.int64)
    offsets: list[dict[str, int]] = []
    for layout, (_, _, size) in enumerate(layouts):
        members = np.flatnonzero(shape == layout)
        if not members.size:
            continue
        grid = label_of[shape_of[starts[members][:, None] + np.arange(size)]] if size else np.zeros((1, 0), np.int64)
        distinct, inverse, _ = numbered_rows(grid)
        layout_of[members] = len(offsets) + inverse
        for found in distinct.tolist():
            offsets.append({labels[number]: place for place, number in enumerate(found)})
            if len(offsets[-1]) != size:
                raise _EntryError("a label appears twice in a student's parts")
    return layout_of, offsets


def _check_people(columns: KeyColumns) -> None:
    """The students' ids, names, emails and sections: text of at most CELL_CHARS characters, each id some."""
    for entries, what in ((columns.ids, "id"), (columns.names, "name"), (columns.emails, "email"),
                          (columns.sections, "section")):
        if set(map(type, entries)) - {str} or max(map(len, entries), default=0) > CELL_CHARS:
            raise _EntryError(f"a student's {what}: expected text of at most {CELL_CHARS} characters")
    if not all(map(str.strip, columns.ids)):
        raise _EntryError("a student's id: expected an id")


def _combinations(columns: KeyColumns) -> tuple[np.ndarray, np.ndarray]:
    """Each answer's entries but its value (unit, label, tolerance, reason, points) as one index into the
    combinations the class has (a few thousand), and where each is first found: a list of five numbers an
    answer took, for a moment, half again what the key then holds (points compared by their bits: -0.0 is not
    0.0 here, and :func:`_shapes` makes them one shape, as equal points).

    >>> import types
    >>> code = np.array([[-1, 0, 1, 0, -2], [-1, 0, 2, 0, -2], [-1, 0, 1, 0, -2]], dtype=np.int32)
    >>> first, which = _combinations(types.SimpleNamespace(code=code, points=np.array([2.0, 2.0, 2.0])))
    >>> first.tolist(), which.tolist()
    ([0, 1], [0, 1, 0])
    """
    combined = np.zeros(len(columns.points), np.int64)
    for column in (*columns.code[:, UNIT:].T, columns.points.view(np.int64)):
        distinct, index = numbered(column)
        if combined.size and int(combined.max()) >= (1 << 62) // len(distinct):
            combined = numbered(combined)[1]  # numbered afresh from 0: fits again
        combined = combined * len(distinct) + index
    _, inverse, first = numbered_first(combined)
    return first, inverse


def _layout(shape: list[tuple[str, list[str], list[str]]], shared: dict[Any, Any]
            ) -> tuple[list[tuple[str, list[str]]], tuple[tuple[str, str], ...], int]:
    """A shape of the columns: its problems' keys (each once) and answers' names, its parameters (shared by
    the students of the shape) and how many parts it has."""
    keys = [key for key, _, _ in shape]
    if len(set(keys)) != len(keys):
        raise _EntryError("a problem key appears twice")
    parameters = tuple((_one(shared, key), name) for key, _, names in shape for name in names)
    return ([(_one(shared, key), answers) for key, answers, _ in shape], _one(shared, ("parameters", parameters))[1],
            sum(len(answers) for _, answers, _ in shape))


def _part_shape(key: tuple[Any, ...], texts: list[str], tolerances: list[Any],
                symbols: Mapping[str, Mapping[str, tuple[float, float]]], shared: dict[Any, Any]) -> KeyPart:
    """A part's entries but its value (None here), checked as :func:`_part` checks them."""
    problem, name, unit, label, tolerance, undefined, points = key
    label = _one(shared, _text(texts[label], f"answer {name}", "label"))
    return KeyPart(problem, _one(shared, name), label, None, _unit(texts[unit], name, shared),
                   _one(shared, _points(points, name)), _tolerance(tolerances[tolerance], name, shared),
                   None if undefined == NONE else texts[undefined], symbols.get(label, {}))


def _valued(part: KeyPart, value: str | None, shared: dict[Any, Any]) -> tuple[str | None, Mapping[str, Any]]:
    """The value and symbols' ranges of a part whose value is an expression (its names checked, and drawn where
    :func:`_part` draws them) or null."""
    domains = part.symbols
    if isinstance(value, str):
        used = shared.get(("names", value))
        if used is None:
            used = shared[("names", value)] = _names(value, part.name)
        if not domains:
            domains = shared.get(("symbols", value)) or shared.setdefault(
                ("symbols", value), dict.fromkeys(sorted(used), SYMBOL_RANGE))
        elif not used <= domains.keys():
            raise _EntryError(f"answer {part.name}: the expression uses names not among its symbols")
    return value, domains
