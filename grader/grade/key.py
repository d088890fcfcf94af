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
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from grader.errors import GraderError, shown
from grader.inputs import decode_text, read_bytes
from grader.model.expr import names, parse

KEY_BYTES = 1 << 30  # 1 GiB: a key holds every student's numbers; 2,000 students take about 2 MB
SYMBOL_RANGE = (1.0, 10.0)  # version 1 keys give no ranges: a symbolic answer's names are drawn here


@dataclass(frozen=True)
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
    """A student of the key, and their answer parts by label."""

    id: str
    name: str
    email: str
    section: str
    parts: Mapping[str, KeyPart]

    @property
    def possible(self) -> float:
        """The points this student could earn."""
        return sum(part.points for part in self.parts.values())


@dataclass(frozen=True)
class KeyProblem:
    """A problem: its key (``1``), title, and its parts' labels in order."""

    key: str
    title: str
    labels: tuple[str, ...]


@dataclass(frozen=True)
class Key:
    """A loaded answer key."""

    where: str
    version: int
    title: str
    numeric_expressions: bool
    problems: tuple[KeyProblem, ...]
    students: tuple[KeyStudent, ...]

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
        raw = json.loads(text, parse_constant=_no_constant)
    except (ValueError, RecursionError) as error:
        raise GraderError(f"{where}: expected a key.json that grader wrote, got invalid JSON ({error})") from None
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


def _key(raw: Mapping[str, Any], where: str, version: int) -> Key:
    problems = tuple(KeyProblem(str(p["key"]), str(p.get("title", "")), tuple(str(a["label"]) for a in p["answers"]))
                     for p in raw["problems"])
    symbols = {str(a["label"]): {str(n): (float(r[0]), float(r[1])) for n, r in a.get("symbols", {}).items()}
               for p in raw["problems"] for a in p["answers"]}
    students = tuple(_student(s, symbols) for s in raw["students"])
    ids = [s.id for s in students]
    if len(set(ids)) != len(ids):
        raise ValueError("a student id appears twice")
    labels = {label for problem in problems for label in problem.labels}
    for student in students:
        if set(student.parts) != labels:
            raise ValueError(f"student {student.id} has parts {sorted(student.parts)}, the problems {sorted(labels)}")
    grading = raw["assignment"].get("grading", {})
    return Key(where, version, str(raw["assignment"]["title"]), bool(grading.get("numeric_expressions", True)),
               problems, students)


def _student(raw: Mapping[str, Any], symbols: Mapping[str, Mapping[str, tuple[float, float]]]) -> KeyStudent:
    parts = {}
    for problem in raw["problems"]:
        for name, answer in problem["answers"].items():
            part = _part(str(problem["key"]), str(name), answer, symbols)
            parts[part.label] = part
    return KeyStudent(str(raw["id"]), str(raw.get("name", "")), str(raw.get("email", "")),
                      str(raw.get("section", "")), parts)


def _part(problem: str, name: str, raw: Mapping[str, Any],
          symbols: Mapping[str, Mapping[str, tuple[float, float]]]) -> KeyPart:
    value = raw["value"]
    if isinstance(value, bool) or not (value is None or isinstance(value, (int, float, str))):
        raise ValueError(f"answer {name}: a value that is no number, expression or null")
    if isinstance(value, (int, float)) and not math.isfinite(value):
        raise ValueError(f"answer {name}: a value that is not finite")
    label = str(raw["label"])
    tolerance = {"mode": "rtol", **raw["tolerance"]}  # version 1 has no mode: {"rtol", "atol"}
    domains = dict(symbols.get(label, {}))
    if isinstance(value, str) and not domains:
        domains = dict.fromkeys(sorted(names(parse(value))), SYMBOL_RANGE)
    return KeyPart(problem, name, label, float(value) if isinstance(value, (int, float)) else value,
                   str(raw.get("unit", "")), float(raw["points"]), tolerance, raw.get("undefined"), domains)
