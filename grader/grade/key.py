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
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeVar

from grader.errors import GraderError, shown
from grader.inputs import decode_text, read_bytes
from grader.model.expr import names, parse

KEY_BYTES = 1 << 30  # 1 GiB: a key holds every student's numbers; 2,000 students take about 2 MB
SYMBOL_RANGE = (1.0, 10.0)  # version 1 keys give no ranges: a symbolic answer's names are drawn here

_T = TypeVar("_T")


@dataclass(frozen=True, slots=True)
class KeyPart:
    """One answer part of one student: what is expected and how it is graded."""

    problem: str
    name: str
    label: str
    value: float | str | None  # a number, an expression's text (symbolic), or None (undefined)
    unit: str
    points: float
    tolerance: Mapping[str, Any]  # the key's form: {"mode", "rtol", "atol"} or {"mode", "digits"}
    undefined: str | None
    symbols: Mapping[str, tuple[float, float]]  # symbolic answers: where each name is drawn

    @property
    def symbolic(self) -> bool:
        """Whether an expression, not a number, is expected."""
        return isinstance(self.value, str)


@dataclass(frozen=True)
class KeyStudent:
    """A student of the key, their answer parts by label, and their parameters as printed, by problem key."""

    id: str
    name: str
    email: str
    section: str
    parts: Mapping[str, KeyPart]
    params: Mapping[str, Mapping[str, float]] = field(default_factory=dict)

    @property
    def possible(self) -> float:
        """The points this student could earn."""
        return sum(part.points for part in self.parts.values())


@dataclass(frozen=True)
class KeyProblem:
    """A problem: its key (``1``), title, its parts' labels in order, and its template's id."""

    key: str
    title: str
    labels: tuple[str, ...]
    template: str = ""


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

    @property
    def labels(self) -> tuple[str, ...]:
        """Every part's label, in the order of the sheet."""
        return tuple(label for problem in self.problems for label in problem.labels)

    @property
    def possible(self) -> float:
        """The most points a student can earn (Canvas' "points possible" of the assignment)."""
        return max((student.possible for student in self.students), default=0.0)


def load_key(path: Path) -> Key:
    """Read and check a key file; a file that is not a grader key is refused with the reason."""
    where = str(path)
    text = decode_text(read_bytes(path, KEY_BYTES), path)
    try:
        raw = _decode(text)
    except (ValueError, RecursionError) as error:
        raise GraderError(f"{where}: expected a key.json that grader wrote, got invalid JSON ({error})") from None
    del text  # the students are read: the text can go before the key is checked
    if not isinstance(raw, dict) or raw.get("schema") != "grader-key":
        raise GraderError(f"{where}: expected a grader answer key (schema grader-key, written by grader generate), "
                          f"got {shown(raw.get('schema') if isinstance(raw, dict) else type(raw).__name__)}")
    version = raw.get("version")
    if version not in (1, 2):
        raise GraderError(f"{where}: expected key schema version 1 or 2, got {shown(version)} (a newer grader "
                          "wrote it? update grader)")
    try:
        return _key(raw, where, version)
    except (KeyError, TypeError, ValueError, AttributeError) as error:
        raise GraderError(f"{where}: a grader key with a missing or malformed entry ({type(error).__name__}: "
                          f"{shown(str(error))}); regenerate it with grader generate") from None


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
    try:
        usable = header.get("schema") == "grader-key" and header.get("version") in (1, 2)
        symbols = _symbols(header["problems"]) if usable else None
    except Exception:  # refused later, in order, by _key
        symbols = None
    if symbols is None:
        return lambda student: student
    shared: dict[Any, Any] = {}

    def read(student: Any) -> Any:
        try:
            return _student(student, symbols, shared)
        except Exception:  # refused later, in order, by _key
            return student

    return read


# --- the key's objects ----------------------------------------------------------------------------

def _key(raw: Mapping[str, Any], where: str, version: int) -> Key:
    problems = tuple(KeyProblem(str(p["key"]), str(p.get("title", "")), tuple(str(a["label"]) for a in p["answers"]),
                                str(p.get("template", ""))) for p in raw["problems"])
    symbols = _symbols(raw["problems"])
    shared: dict[Any, Any] = {}
    students = tuple(s if isinstance(s, KeyStudent) else _student(s, symbols, shared) for s in raw["students"])
    ids = [s.id for s in students]
    if len(set(ids)) != len(ids):
        raise ValueError("a student id appears twice")
    labels = {label for problem in problems for label in problem.labels}
    for student in students:
        if set(student.parts) != labels:
            raise ValueError(f"student {student.id} has parts {sorted(student.parts)}, the problems {sorted(labels)}")
    grading = raw["assignment"].get("grading", {})
    templates = {str(name): str(entry.get("sha256", "")) for name, entry in raw.get("templates", {}).items()}
    return Key(where, version, str(raw["assignment"]["title"]), bool(grading.get("numeric_expressions", True)),
               problems, students, templates, _credit(grading, "ecf_credit", 1.0),
               _credit(grading, "mistake_credit", 0.0))


def _credit(grading: Mapping[str, Any], name: str, default: float) -> float:
    value = grading.get(name, default)
    if isinstance(value, bool) or not isinstance(value, int | float) or not 0 <= value <= 1:
        raise ValueError(f"assignment.grading.{name} is {value!r}, not a credit from 0 to 1")
    return float(value)


def _symbols(problems: Any) -> dict[str, dict[str, tuple[float, float]]]:
    """Per label, where each name of a symbolic answer is drawn (empty for numeric answers)."""
    return {str(a["label"]): {str(n): (float(r[0]), float(r[1])) for n, r in a.get("symbols", {}).items()}
            for p in problems for a in p["answers"]}


def _student(raw: Mapping[str, Any], symbols: Mapping[str, Mapping[str, tuple[float, float]]],
             shared: dict[Any, Any]) -> KeyStudent:
    parts, params = {}, {}
    for problem in raw["problems"]:
        key = _one(shared, str(problem["key"]))
        for name, answer in problem["answers"].items():
            part = _part(key, _one(shared, str(name)), answer, symbols, shared)
            parts[part.label] = part
        given = problem.get("params", {})
        if not isinstance(given, dict):
            raise ValueError(f"problem {key}: params that are not an object")
        params[key] = given  # the decoded object itself: checked where it is used (a number or not)
    return KeyStudent(str(raw["id"]), str(raw.get("name", "")), str(raw.get("email", "")),
                      str(raw.get("section", "")), parts, params)


def _part(problem: str, name: str, raw: Mapping[str, Any],
          symbols: Mapping[str, Mapping[str, tuple[float, float]]], shared: dict[Any, Any]) -> KeyPart:
    value = raw["value"]
    if type(value) is not float:  # a float is the usual value, and needs only the check below
        if isinstance(value, bool) or not (value is None or isinstance(value, (int, float, str))):
            raise ValueError(f"answer {name}: a value that is no number, expression or null")
        value = float(value) if isinstance(value, (int, float)) else value
    if isinstance(value, float) and not math.isfinite(value):
        raise ValueError(f"answer {name}: a value that is not finite")
    label, unit, points = _one(shared, str(raw["label"])), _one(shared, str(raw.get("unit", ""))), _one(
        shared, float(raw["points"]))
    domains = symbols.get(label, {})  # the label's own: one mapping for the whole class
    if isinstance(value, str) and not domains:
        domains = shared.get(("symbols", value)) or shared.setdefault(
            ("symbols", value), dict.fromkeys(sorted(names(parse(value))), SYMBOL_RANGE))
    return KeyPart(problem, name, label, value, unit, points, _tolerance(raw["tolerance"], shared),
                   raw.get("undefined"), domains)


def _one(shared: dict[Any, Any], value: _T) -> _T:
    """One object for all equal texts and numbers (labels, units, points of 100,000 students)."""
    return shared.setdefault(value, value)  # type: ignore[no-any-return]


def _tolerance(raw: Mapping[str, Any], shared: dict[Any, Any]) -> Mapping[str, Any]:
    """The part's tolerance (version 1 has no mode: ``{"rtol", "atol"}``), one mapping for equal ones."""
    try:
        key = ("tolerance", tuple(raw.items()), tuple(map(type, raw.values())))  # True is not 1 here
        found = shared.get(key)
    except TypeError:  # a value that cannot be hashed: Tolerance.from_json says what is wrong with it
        return {"mode": "rtol", **raw}
    if found is None:
        found = shared[key] = {"mode": "rtol", **raw}
    return found
