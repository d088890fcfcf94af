"""The answer key: ``key.json`` (versioned schema, what re-grading reads) and ``key.csv`` (for people).

Re-grading reads the key; it never regenerates variants. Nothing in the key depends on the time
of the run, so generating twice gives byte-identical files.

Schema ``grader-key`` version 2 (version 1, still read by grading, lacks ``grading``, ``symbols``,
and the tolerance's ``mode``: its tolerances are ``{"rtol", "atol"}``; a version 2 key from before
``ecf_credit``, ``mistake_credit``, ``attempts`` and ``integrity_threshold`` is graded with their defaults,
1, 0, latest and 0.05; one without ``deadline`` measures no lateness, as before)::

    {"schema": "grader-key", "version": 2, "generator": "grader X.Y.Z",
     "assignment": {"title", "course", "seed", "due", "instructions", "source_sha256",
                    "deadline": "2026-12-04T23:59:00-06:00", "timezone": "America/Chicago" (only when
                        due is a date-time), "late": {"grace", "deduct", "per", "lowest", "after"} or null,
                    "grading": {"numeric_expressions": true, "ecf_credit": 1.0, "mistake_credit": 0.0,
                                "intermediate_sig_figs": 4, "max_tolerance": 0.05, "attempts": "latest",
                                "integrity_threshold": 0.05}},
     "templates": {ID: {"version", "sha256", "bank": the folder it came from, relative to the key's folder
                        where possible (only a template from outside the shipped bank; a key before it has none)}},
     "problems": [{"key", "template", "title", "parameters": {NAME: its unit, as printed},
                   "answers": [{"name", "label", "unit", "points",
                                "symbols": {NAME: [low, high]} (symbolic answers only: where each
                                           name is drawn to compare expressions)}]}],
     "collisions": {PROBLEM_KEY: number of students sharing their numbers with another},
     "students": [{"id", "name", "email", "section", "due" (an extension: the student's own due time),
                   "problems": [{"key", "template", "variant_seed",
                                 "params": {NAME: value as printed, a number},
                                 "printed": {NAME: the text on the page, e.g. "2.10"},
                                 "answers": {NAME: {"value", "unit", "label", "points",
                                                    "tolerance": {"mode": "rtol", "rtol", "atol"}
                                                        or {"mode": "sigfigs" | "decimals", "digits"},
                                                        with "reason" where it was widened for rounding,
                                                    "undefined": reason (only when there is no value)}}}]}]}
"""

from __future__ import annotations

import hashlib
import itertools
import json
import os
import shutil
import tempfile
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from functools import lru_cache
from pathlib import Path
from typing import Any

from grader import __version__
from grader.assign.assignment import Assignment, ProblemSpec, Student
from grader.assign.deadlines import student_due, zone
from grader.assign.variants import AnswerPart, Generation, ProblemVariant, StudentVariants
from grader.bank.template import Template
from grader.base.files import atomic_file
from grader.base.resources import bank_dir
from grader.base.spreadsheet import csv_pieces, csv_text, number_cell, safe_cell
from grader.model.tolerance import SYMBOL_RANGE, Tolerance

SCHEMA, VERSION = "grader-key", 2


def key_document(assignment: Assignment, generation: Generation, bank: Mapping[str, Template],
                 key_folder: Path | None = None) -> dict[str, Any]:
    """The key as a JSON-ready dictionary; ``key_folder``, where it is written: the bank folders of the
    templates are recorded relative to it (grading finds them again from the key)."""
    first = generation.students[0].problems if generation.students else ()
    tolerances = _shared_tolerances(first)
    return {**_head(assignment, first, generation.collisions, bank, key_folder),
            "students": [_student(s, assignment, tolerances) for s in generation.students]}


def _head(assignment: Assignment, first: Sequence[ProblemVariant], collisions: Mapping[str, int],
          bank: Mapping[str, Template], key_folder: Path | None) -> dict[str, Any]:
    """Everything in the key before its students; ``first``, the first student's variants."""
    used = {p.template: bank[p.template] for p in assignment.problems}
    return {
        "schema": SCHEMA, "version": VERSION, "generator": f"grader {__version__}",
        "assignment": {"title": assignment.title, "course": assignment.course, "seed": assignment.seed,
                       "due": assignment.due, **_deadline(assignment), "instructions": assignment.instructions,
                       "source_sha256": hashlib.sha256(Path(assignment.where).read_bytes()).hexdigest(),
                       "grading": {"numeric_expressions": assignment.grading.numeric_expressions,
                                   "ecf_credit": assignment.grading.ecf_credit,
                                   "mistake_credit": assignment.grading.mistake_credit,
                                   "intermediate_sig_figs": assignment.grading.intermediate_sig_figs,
                                   "max_tolerance": assignment.grading.max_tolerance,
                                   "attempts": assignment.grading.attempts,
                                   "integrity_threshold": assignment.grading.integrity_threshold}},
        "templates": {t.id: {"version": t.version, "sha256": t.source_hash, **_bank_folder(t, key_folder)}
                      for t in used.values()},
        "problems": [{"key": v.key, "template": v.template, "title": used[v.template].title,
                      "parameters": {name: p.unit.text for name, p in used[v.template].parameters.items()},
                      "answers": [_part(a, used[v.template], spec) for a in v.answers]}
                     for v, spec in zip(first, assignment.problems, strict=False)],
        "collisions": dict(collisions),
    }


def _shared_tolerances(first: Sequence[ProblemVariant]) -> dict[tuple[Tolerance, str], dict[str, Any]]:
    """One tolerance dict per distinct tolerance (and reason: equality leaves it out) of the first student's
    parts, shared by every student's part that has it (the encoder only reads it)."""
    return {(t, t.reason): t.to_json() for s in first for t in {a.tolerance for a in s.answers}}


def _student(entry: StudentVariants, assignment: Assignment,
             tolerances: dict[tuple[Tolerance, str], dict[str, Any]]) -> dict[str, Any]:
    s = entry.student
    return {"id": s.id, "name": s.name, "email": s.email, "section": s.section, **_extension(s, assignment),
            "problems": [{"key": v.key, "template": v.template, "variant_seed": v.variant_seed,
                          "params": v.params, "printed": v.printed,
                          "answers": {a.name: _answer(a, tolerances) for a in v.answers}}
                         for v in entry.problems]}


def write_key_files(folder: Path, assignment: Assignment, chunks: Iterable[Sequence[StudentVariants]],
                    collisions: Callable[[], Mapping[str, int]], bank: Mapping[str, Template],
                    key_folder: Path | None = None) -> None:
    """Write ``folder/key.json`` and ``folder/key.csv`` a piece of the class at a time, as ``chunks`` come
    (:class:`grader.assign.variants.ClassDraws`), the same bytes as :func:`key_json` and :func:`key_csv` of the
    class drawn whole. ``collisions`` is asked after the last piece: key.json's head, which holds them, is
    written then, before the students' lines, which wait in an unnamed temporary file in ``folder``."""
    first: Sequence[ProblemVariant] | None = None
    tolerances: dict[tuple[Tolerance, str], dict[str, Any]] = {}
    with tempfile.TemporaryFile(dir=folder) as students, atomic_file(folder / "key.csv") as table:
        table.write(csv_text([KEY_CSV_HEADER]).encode("utf-8"))
        for chunk in chunks:
            if not chunk:
                continue
            separator = b"" if first is None else b",\n  "
            if first is None:
                first = chunk[0].problems
                tolerances = _shared_tolerances(first)
            lines = ",\n  ".join(json.dumps(_student(s, assignment, tolerances), ensure_ascii=False, allow_nan=False)
                                 for s in chunk)
            with _blamed_on(folder / "key.json"):  # the students' lines are key.json's, not key.csv's, whose
                students.write(separator + lines.encode("utf-8"))  # block would otherwise take a failed write
            for piece in csv_pieces(_csv_rows(chunk)):
                table.write(piece.encode("utf-8"))
        head = json.dumps(_head(assignment, first or (), collisions(), bank, key_folder), ensure_ascii=False,
                          indent=1, allow_nan=False)
        with _blamed_on(folder / "key.json"):
            students.seek(0)  # writes what is buffered
        with atomic_file(folder / "key.json") as key:
            key.write(_opening(head).encode())
            shutil.copyfileobj(students, key, COPY_BLOCK)
            key.write(_CLOSING.encode())


COPY_BLOCK = 1 << 20  # bytes of the students' lines copied at a time into key.json


@contextmanager
def _blamed_on(path: Path) -> Iterator[None]:
    """An ``OSError`` that names no file (a failed ``write()``) names ``path``."""
    try:
        yield
    except OSError as error:
        if error.filename is not None:
            raise
        raise OSError(error.errno, error.strerror, str(path)) from None


def _bank_folder(template: Template, key_folder: Path | None) -> dict[str, str]:
    """``{"bank": FOLDER}``: the folder a template's file is in, relative to the key's folder where it can be
    (a key moved with its bank still finds it), else absolute; nothing for the shipped bank's templates,
    which grading finds without being told."""
    folder = Path(template.where).parent.resolve()
    if folder == bank_dir().resolve():
        return {}
    try:
        where = os.path.relpath(folder, (key_folder or Path.cwd()).resolve())
    except ValueError:  # another drive (Windows): no relative path
        where = str(folder)
    return {"bank": Path(where).as_posix()}


def _deadline(assignment: Assignment) -> dict[str, Any]:
    """The assignment's due time (with its offset), zone and late policy, when its due is a date-time."""
    if assignment.deadline is None:
        return {}
    late = None if assignment.late is None else assignment.late.to_json()
    return {"deadline": assignment.deadline.isoformat(), "timezone": assignment.timezone, "late": late}


def _extension(student: Student, assignment: Assignment) -> dict[str, str]:
    """A student's own due time (with its offset), when the roster gives one."""
    due = student_due(student.due, assignment.deadline, zone(assignment.timezone))
    return {} if due is None else {"due": due.isoformat()}


def _part(part: AnswerPart, template: Template, problem: ProblemSpec) -> dict[str, Any]:
    data: dict[str, Any] = {"name": part.name, "label": part.label, "unit": part.unit, "points": part.points}
    symbolic = template.answers[part.name].symbolic
    if symbolic:
        data["symbols"] = {name: list(_symbol_range(name, template, problem)) for name in symbolic}
    return data


def _symbol_range(name: str, template: Template, problem: ProblemSpec) -> tuple[float, float]:
    """Where a name of a symbolic answer varies: its narrowed or sampled range; a symbol, 1 to 10."""
    if name in problem.narrowed:
        return problem.narrowed[name]
    parameter = template.parameters.get(name)
    if parameter is None:
        return SYMBOL_RANGE
    values = parameter.sample.values
    return (min(values), max(values))


def _answer(part: AnswerPart, tolerances: dict[tuple[Tolerance, str], dict[str, Any]]) -> dict[str, Any]:
    tolerance = tolerances.get((part.tolerance, part.tolerance.reason))
    data: dict[str, Any] = {"value": part.value, "unit": part.unit, "label": part.label, "points": part.points,
                            "tolerance": part.tolerance.to_json() if tolerance is None else tolerance}
    if part.undefined is not None:
        data["undefined"] = part.undefined
    return data


def _tolerance_text(tolerance: Tolerance, unit: str) -> str:
    return _explained(tolerance, tolerance.reason, unit)


@lru_cache(maxsize=256)
def _explained(tolerance: Tolerance, reason: str, unit: str) -> str:  # reason: equal tolerances may differ in it
    return tolerance.explained(unit)


def key_json(document: Mapping[str, Any]) -> str:
    """``key.json`` text: stable order, UTF-8; the header indented, then one line per student (an
    indented dump of 2,000 students goes through the slow pure-Python encoder).

    >>> json.loads(key_json({"schema": "grader-key", "students": [{"id": "1"}, {"id": "2"}]}))["students"][1]
    {'id': '2'}
    """
    head = json.dumps({k: v for k, v in document.items() if k != "students"}, ensure_ascii=False, indent=1,
                      allow_nan=False)
    students = ",\n  ".join(json.dumps(s, ensure_ascii=False, allow_nan=False) for s in document["students"])
    return f"{_opening(head)}{students}{_CLOSING}"


def _opening(head: str) -> str:
    """key.json up to its first student: the indented head (``head``, a dump without the students) reopened
    for the students' list."""
    return f'{head[:-2]},\n "students": [\n  '


_CLOSING = "\n ]\n}\n"  # key.json after its last student


KEY_CSV_HEADER = ("student_id", "name", "section", "problem", "template", "label", "answer", "value", "unit",
                  "points", "tolerance", "parameters")


def key_csv(generation: Generation) -> str:
    """``key.csv``: one row per student and answer part, for people and spreadsheets."""
    return csv_text(itertools.chain([KEY_CSV_HEADER], _csv_rows(generation.students)))


def _csv_rows(students: Iterable[StudentVariants]) -> Iterator[Sequence[object]]:
    for entry in students:
        student = entry.student
        who = [safe_cell(student.id), safe_cell(student.name), safe_cell(student.section)]
        for variant in entry.problems:
            given = "; ".join(f"{name}={text}" for name, text in variant.printed.items())
            yield from ([*who, variant.key, variant.template, part.label, part.name, _csv_value(part), part.unit,
                         part.points, _tolerance_text(part.tolerance, part.unit), given]
                        for part in variant.answers)


VALUE_FIGURES = 12
"""key.csv is for people: its ``value`` is the answer rounded to this many significant figures, which hides
the float's binary noise (``0.7999999999999999``) and keeps more than any tolerance needs; key.json keeps
the value exactly, and grading reads that."""


def _csv_value(part: AnswerPart) -> str:
    if part.value is None:
        return safe_cell(f"undefined: {part.undefined}")
    return number_cell(part.value, VALUE_FIGURES) if isinstance(part.value, float) else safe_cell(part.value)
