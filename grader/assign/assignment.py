"""An assignment (YAML) and a class roster (CSV), parsed and validated into frozen objects.

>>> from grader.base.resources import sample_dir
>>> assignment = load_assignment(sample_dir() / "assignment.yaml")
>>> [p.key for p in assignment.problems], assignment.problems[0].template
(['1', '2', '3', '4', '5'], 'drop-rebound')
>>> len(load_roster(sample_dir() / "roster.csv"))
30
"""

from __future__ import annotations

import difflib
import re
import unicodedata
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path
from typing import Any

from grader.assign.asked import question_start
from grader.assign.deadlines import (
    DEFAULT_ZONE,
    LatePolicy,
    extension,
    late_from,
    local_time,
    student_due,
    zone,
    zone_from,
)
from grader.bank.template import Parameter, Template, tolerance_in
from grader.base.errors import GraderError, TemplateError, refuse_unknown_fields, shown
from grader.base.inputs import read_csv, read_yaml
from grader.model.tolerance import ANSWER_SIG_FIGS, FORMS

_KEY = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_-]{0,15}$")
_ROSTER_COLUMNS = ("id", "name", "email", "section")
_ROSTER_REQUIRED = ("id", "name")  # email and section may be left out: empty for everyone
MAX_POINTS = 1_000_000  # per answer part: any class's totals stay exact in float64
_NUMBER_WORDS = ("zero", "one", "two", "three", "four", "five", "six", "seven", "eight", "nine", "ten")


@dataclass(frozen=True)
class ProblemSpec:
    """One problem of an assignment: a template, its key (``1``), points per answer part, and
    parameters fixed or narrowed for everyone, tolerance overrides per answer; ``parts``, the answers asked
    (by name; None: every answer of the template)."""

    key: str
    template: str
    points: Mapping[str, float]
    fixed: Mapping[str, float]
    narrowed: Mapping[str, tuple[float, float]]
    tolerances: Mapping[str, Mapping[str, Any]]  # answer name -> the override as written
    parts: tuple[str, ...] | None = None

    def asked(self, template: Template) -> list[str]:
        """The answers of ``template`` this problem asks, in the template's order (a later part may use an
        earlier one, and error carried forward follows that order).

        >>> from grader.bank.template import load_bank
        >>> pile = load_bank()["pile-driver"]
        >>> ProblemSpec("3", "pile-driver", {}, {}, {}, {}, ("e", "v_pile")).asked(pile)
        ['v_pile', 'e']
        """
        return [name for name in template.answers if self.parts is None or name in self.parts]


@dataclass(frozen=True)
class Grading:
    """How answers are read and credited: ``numeric_expressions``, whether ``sqrt(2*9.81*2)`` counts as a
    number; ``ecf_credit``, the credit of a part right for the student's own earlier answer (error carried
    forward; 0 turns it off); ``mistake_credit``, that of a part matching a diagnosed mistake;
    ``intermediate_sig_figs``, the significant figures the sheet asks students to keep in intermediate
    steps (answers are given to three), from which each variant's rounding allowance is bounded;
    ``max_tolerance``, the widest relative tolerance a variant may get for that allowance (a variant that
    would need more is redrawn); ``attempts``, which of a student's submissions counts when a form allows
    resubmission (``latest``, ``best`` or ``first``; per submission in a wide file, per part in a long one);
    ``integrity_threshold``, the chance of so many matches by accident (corrected for the pairs examined) at
    or below which a pair of students, one's wrong answers matching the other's numbers, is flagged in the
    class report (:mod:`grader.grade.integrity`; it never changes a grade)."""

    numeric_expressions: bool = True
    ecf_credit: float = 1.0
    mistake_credit: float = 0.0
    intermediate_sig_figs: int = 4
    max_tolerance: float = 0.05
    attempts: str = "latest"
    integrity_threshold: float = 0.05

    @property
    def rounding_rule(self) -> str:
        """How the sheet asks students to round, as its instructions print it.

        >>> Grading().rounding_rule
        'Keep four significant figures in intermediate steps; give answers to three.'
        """
        return (f"Keep {_NUMBER_WORDS[self.intermediate_sig_figs]} significant figures in intermediate steps; "
                f"give answers to {_NUMBER_WORDS[ANSWER_SIG_FIGS]}.")


@dataclass(frozen=True)
class Assignment:
    """An assignment: what every student gets, and the seed their variants come from; ``due`` as printed,
    and when it reads as a date-time, ``deadline``, in the IANA zone ``timezone``; how ``late`` work is
    credited (None: accepted as on time, its lateness reported)."""

    where: str
    title: str
    course: str
    seed: str
    due: str
    instructions: str
    problems: tuple[ProblemSpec, ...]
    grading: Grading = Grading()
    timezone: str = DEFAULT_ZONE
    deadline: datetime | None = None
    late: LatePolicy | None = None


@dataclass(frozen=True)
class Student:
    """A roster row; ``due``: the student's extension as the roster writes it (a date-time in the
    assignment's zone, or a delay such as ``+2 days``), or ""."""

    id: str
    name: str
    email: str
    section: str
    due: str = ""


def load_assignment(path: Path) -> Assignment:
    """Read and validate an assignment file (problems are checked against the bank separately)."""
    where = str(path)
    raw = read_yaml(path)
    if not isinstance(raw, Mapping):
        raise TemplateError(where, "(file)", "a mapping with title, course, seed, problems", type(raw).__name__)
    allowed = {"title", "course", "seed", "due", "timezone", "late", "instructions", "problems", "grading"}
    if set(raw) - allowed:
        raise TemplateError(where, ", ".join(sorted(map(str, set(raw) - allowed))),
                            f"only {', '.join(sorted(allowed))}", "unknown key(s)")
    problems_raw = raw.get("problems")
    if not isinstance(problems_raw, list) or not problems_raw:
        raise TemplateError(where, "problems", "a non-empty list of problems", shown(problems_raw))
    problems = tuple(_problem(item, index, where) for index, item in enumerate(problems_raw))
    keys = [p.key for p in problems]
    duplicated = sorted({k for k in keys if keys.count(k) > 1})
    if duplicated:
        raise TemplateError(where, "problems", "a different key for each problem", f"{', '.join(duplicated)} twice")
    seed = raw.get("seed")
    if isinstance(seed, bool) or not isinstance(seed, (int, str)) or not str(seed).strip():
        raise TemplateError(where, "seed", "a number or text (the assignment seed)", shown(seed))
    due = _text(raw, "due", where, required=False)
    timezone = zone_from(raw.get("timezone", DEFAULT_ZONE), where)
    deadline = local_time(due, timezone)
    late = None if raw.get("late") is None else late_from(raw["late"], where)
    if deadline is None and (late is not None or "timezone" in raw):
        needs = "the late policy" if late is not None else "the timezone"
        raise TemplateError(where, "due", f"a date-time such as 2026-12-04 23:59 ({needs} needs one)", shown(due))
    return Assignment(where, _text(raw, "title", where), _text(raw, "course", where), str(seed).strip(),
                      due, _text(raw, "instructions", where, required=False),
                      problems, grading_from(raw.get("grading"), where), str(timezone), deadline, late)


ATTEMPTS = ("latest", "best", "first")
GRADING_FIELDS = {"numeric_expressions": "true or false", "ecf_credit": "0 to 1", "mistake_credit": "0 to 1",
                  "intermediate_sig_figs": "2 to 10", "max_tolerance": "0.001 to 0.5",
                  "attempts": " | ".join(ATTEMPTS), "integrity_threshold": "0 to 1"}
"""The fields of ``grading`` (in an assignment, and in the key that copies it) and their ranges."""


def grading_from(raw: Any, where: str, field: str = "grading") -> Grading:
    """The ``grading`` mapping of an assignment (or, as ``field``, of a key), checked: an unknown field
    is refused with the nearest known one, a value out of range with its range.

    >>> grading_from({"max_tolerance": 0.1}, "a.yaml").max_tolerance
    0.1
    >>> grading_from({"max_tolerence": 0.1}, "a.yaml")
    Traceback (most recent call last):
    ...
    grader.base.errors.TemplateError: a.yaml: grading.max_tolerence: ... (did you mean max_tolerance?)...
    >>> grading_from({"max_tolerance": -1}, "a.yaml")
    Traceback (most recent call last):
    ...
    grader.base.errors.TemplateError: a.yaml: grading.max_tolerance: expected a relative tolerance ..., got -1
    """
    if raw is None:
        return Grading()
    if not isinstance(raw, Mapping):
        raise TemplateError(where, field, "a mapping {" + ", ".join(f"{name}: {values}" for name, values
                                                                      in GRADING_FIELDS.items()) + "}", shown(raw))
    refuse_unknown_fields(raw, sorted(GRADING_FIELDS), where, field)
    value = raw.get("numeric_expressions", True)
    if not isinstance(value, bool):
        raise TemplateError(where, f"{field}.numeric_expressions", "true or false", shown(value))
    credits = {}
    for name, default in (("ecf_credit", Grading.ecf_credit), ("mistake_credit", Grading.mistake_credit)):
        credit = raw.get(name, default)
        if not (_number(credit) and 0 <= credit <= 1):
            raise TemplateError(where, f"{field}.{name}", "a credit from 0 to 1 (a fraction of the part's points)",
                                shown(credit))
        credits[name] = float(credit)
    figures = raw.get("intermediate_sig_figs", Grading.intermediate_sig_figs)
    if isinstance(figures, bool) or not isinstance(figures, int) or not 2 <= figures <= 10:
        raise TemplateError(where, f"{field}.intermediate_sig_figs",
                            "a whole number of significant figures from 2 to 10", shown(figures))
    widest = raw.get("max_tolerance", Grading.max_tolerance)
    if not (_number(widest) and 0.001 <= widest <= 0.5):
        raise TemplateError(where, f"{field}.max_tolerance",
                            "a relative tolerance from 0.001 to 0.5 (0.05 is ±5 %)", shown(widest))
    attempts = raw.get("attempts", Grading.attempts)
    if attempts not in ATTEMPTS:
        raise TemplateError(where, f"{field}.attempts", "latest, best or first (which of a student's submissions "
                            "counts)", shown(attempts))
    threshold = raw.get("integrity_threshold", Grading.integrity_threshold)
    if not (_number(threshold) and 0 <= threshold <= 1):
        raise TemplateError(where, f"{field}.integrity_threshold", "a chance from 0 to 1 (0.05: pairs whose "
                            "matches would come about by accident at most 1 time in 20 are flagged)", shown(threshold))
    return Grading(numeric_expressions=value, **credits, intermediate_sig_figs=figures,
                   max_tolerance=float(widest), attempts=attempts, integrity_threshold=float(threshold))


def _text(raw: Mapping[str, Any], key: str, where: str, required: bool = True) -> str:
    value = raw.get(key, "" if not required else None)
    if not isinstance(value, (str, int, float)) or isinstance(value, bool) or (required and not str(value).strip()):
        raise TemplateError(where, key, "text", shown(value))
    return str(value).strip()


def _problem(raw: Any, index: int, where: str) -> ProblemSpec:
    key = f"problems[{index}]"
    allowed = {"key", "template", "points", "fixed", "narrow", "tolerance", "parts"}
    if not isinstance(raw, Mapping) or "template" not in raw or set(raw) - allowed:
        raise TemplateError(where, key, f"a mapping with template and only {', '.join(sorted(allowed))}", shown(raw))
    problem_key = str(raw.get("key", index + 1))
    if not _KEY.match(problem_key):
        raise TemplateError(where, f"{key}.key", "a short label of letters and digits, like 1 or 2b",
                            shown(problem_key))
    points = raw.get("points", 1)
    if isinstance(points, (int, float)) and not isinstance(points, bool):
        points = {"*": points}
    if not isinstance(points, Mapping) or not all(_number(v) and 0 <= v <= MAX_POINTS for v in points.values()):
        raise TemplateError(where, f"{key}.points", f"a number, or answer name -> number (0 to {MAX_POINTS:,})",
                            shown(raw.get("points", 1)))
    fixed = raw.get("fixed") or {}
    if not isinstance(fixed, Mapping) or not all(_number(v) for v in fixed.values()):
        raise TemplateError(where, f"{key}.fixed", "parameter name -> number", shown(fixed))
    narrowed = raw.get("narrow") or {}
    if not isinstance(narrowed, Mapping) or not all(
            isinstance(v, list) and len(v) == 2 and all(_number(x) for x in v) and v[0] <= v[1]
            for v in narrowed.values()):
        raise TemplateError(where, f"{key}.narrow", "parameter name -> [low, high] with low <= high", shown(narrowed))
    tolerances = raw.get("tolerance") or {}
    if not isinstance(tolerances, Mapping):
        raise TemplateError(where, f"{key}.tolerance", "answer name -> tolerance", shown(tolerances))
    tolerance_specs = {str(k): _tolerance(v, where, f"{key}.tolerance.{k}") for k, v in tolerances.items()}
    return ProblemSpec(problem_key, str(raw["template"]), {str(k): float(v) for k, v in points.items()},
                       {str(k): float(v) for k, v in fixed.items()},
                       {str(k): (float(v[0]), float(v[1])) for k, v in narrowed.items()},
                       tolerance_specs, _parts(raw, where, f"{key}.parts"))


def _parts(raw: Mapping[str, Any], where: str, key: str) -> tuple[str, ...] | None:
    """The answers a problem asks, as listed (checked against the template with the bank)."""
    if "parts" not in raw:
        return None
    parts = raw["parts"]
    if not isinstance(parts, list) or not parts or not all(isinstance(p, str) and p.strip() for p in parts):
        raise TemplateError(where, key, "a non-empty list of the template's answer names, such as [v_pile, e] "
                            "(leave parts out to ask every answer)", shown(parts))
    twice = sorted({p for p in parts if parts.count(p) > 1})
    if twice:
        raise TemplateError(where, key, "each answer name once", f"{', '.join(twice)} twice")
    return tuple(p.strip() for p in parts)


def _tolerance(raw: Any, where: str, key: str) -> Mapping[str, Any]:
    """An answer's override as written, checked: ``{rtol: X, atol: Y}`` (either alone keeps the template's
    other), ``{sigfigs: N}`` or ``{decimals: N}`` (PrairieLearn's rules)."""
    if not isinstance(raw, Mapping) or not raw:
        raise TemplateError(where, key, FORMS, shown(raw))
    tolerance_in(raw, where, key)
    return dict(raw)


def _number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and value == value and abs(value) != float(
        "inf")


def check_against_bank(assignment: Assignment, bank: Mapping[str, Template]) -> None:
    """Every problem's template exists; fixed and narrowed parameters exist and lie in the domain."""

    for index, problem in enumerate(assignment.problems):
        key = f"problems[{index}]"
        if problem.template not in bank:
            close = difflib.get_close_matches(problem.template, list(bank), n=3, cutoff=0.5)
            raise TemplateError(assignment.where, f"{key}.template", f"a template id of the bank"
                                f"{' (did you mean ' + ' or '.join(close) + '?)' if close else ''}",
                                shown(problem.template))
        template = bank[problem.template]
        for label, names in (("fixed", problem.fixed), ("narrow", problem.narrowed)):
            unknown = set(names) - set(template.parameters)
            if unknown:
                raise TemplateError(assignment.where, f"{key}.{label}", f"parameters of {template.id} "
                                    f"({', '.join(template.parameters)})", ", ".join(sorted(unknown)))
        for name, value in problem.fixed.items():
            _admitted(template.parameters[name], value, assignment.where, f"{key}.fixed.{name}")
        for name, (low, high) in problem.narrowed.items():
            for value in (low, high):
                _admitted(template.parameters[name], value, assignment.where, f"{key}.narrow.{name}")
        available = f"answer names of {template.id} ({', '.join(template.answers)})"
        unasked = sorted(set(problem.parts or ()) - set(template.answers))
        if unasked:
            raise TemplateError(assignment.where, f"{key}.parts (problem {problem.key})", available, ", ".join(unasked))
        if problem.parts is not None and question_start(template.statement) is None:
            raise TemplateError(assignment.where, f"{key}.parts (problem {problem.key})", f"no parts: every answer "
                                f"of {template.id}, since its statement's question is not a sentence beginning Find "
                                "or Determine that can be restated for some of them (or a copy of the template "
                                "that asks only those)", ", ".join(problem.parts))
        unnamed = sorted((set(problem.points) - {"*"} | set(problem.tolerances)) - set(template.answers))
        if unnamed:
            raise TemplateError(assignment.where, key, available, ", ".join(unnamed))
        unasked = sorted((set(problem.points) - {"*"} | set(problem.tolerances)) - set(problem.asked(template)))
        if unasked:
            raise TemplateError(assignment.where, key, f"points and tolerances only for the parts asked "
                                f"({', '.join(problem.asked(template))})", f"{', '.join(unasked)}, not in parts")


def check_extensions(assignment: Assignment, roster: Sequence[Student], path: Path) -> None:
    """Every extension of the roster has a due time: a delay (``+2 days``) needs the assignment's."""
    for student in roster:
        try:
            student_due(student.due, assignment.deadline, zone(assignment.timezone))
        except ValueError as error:
            raise GraderError(f"{path}: student {shown(student.id)}: due: {error}; give the assignment a due "
                              "date-time, or the student a date-time") from None


def _admitted(parameter: Parameter, value: float, where: str, key: str) -> None:
    refusal = parameter.refusal(value)
    if refusal is not None:
        raise TemplateError(where, key, refusal, f"{value:g}")


def load_roster(path: Path) -> tuple[Student, ...]:
    """Read a roster: columns id and name, and optionally email, section and due, a student's extension
    (UTF-8 with or without BOM; , ; or tab)."""
    table = read_csv(path)
    columns = {name.lower(): name for name in table.header}
    missing = [c for c in _ROSTER_REQUIRED if c not in columns]
    if missing:
        raise GraderError(f"{path}: missing column(s) {', '.join(missing)}; expected a header with "
                          f"{', '.join(_ROSTER_REQUIRED)}, and optionally {', '.join(_ROSTER_COLUMNS[2:])} and due "
                          f"(got {', '.join(table.header)})")
    students, seen = [], set()
    for row in table.rows:
        if row.problem is not None:
            raise GraderError(f"{path}: {row.problem}")
        values = {c: row.cells[columns[c]] if c in columns else "" for c in _ROSTER_COLUMNS}
        _check_id(values["id"], f"{path}: line {row.line}")
        _check_name(values["name"], f"{path}: line {row.line}")
        due = row.cells[columns["due"]].strip() if "due" in columns else ""
        try:
            extension(due)
        except ValueError as error:
            raise GraderError(f"{path}: line {row.line}: due: {error}") from None
        if values["id"] in seen:
            raise GraderError(f"{path}: line {row.line}: student id '{values['id']}' appears twice")
        seen.add(values["id"])
        students.append(Student(values["id"], values["name"], values["email"], values["section"], due))
    if not students:
        raise GraderError(f"{path}: the roster has no students")
    return tuple(students)


_BIDI = set("\u202a\u202b\u202c\u202d\u202e\u2066\u2067\u2068\u2069")


def _check_name(name: str, where: str) -> None:
    """A name is printed on the sheet: no control characters or bidi overrides (which reorder what
    follows), and something visible when it is not empty."""
    bad = next((c for c in name if unicodedata.category(c) == "Cc" or c in _BIDI), None)
    if bad is not None:
        raise GraderError(f"{where}: the name {shown(name)} holds the control character U+{ord(bad):04X} "
                          f"({unicodedata.name(bad, 'unnamed')}); expected a name as printed")
    if name and all(unicodedata.category(c)[0] in "CZ" for c in name):
        raise GraderError(f"{where}: the name {shown(name)} has no visible character; expected a name, or none")


def _check_id(student_id: str, where: str) -> None:
    """An id names files and matches submissions: printable, not a path's ``.``/``..``."""
    if not student_id:
        raise GraderError(f"{where}: empty student id (every student needs one)")
    hidden = next((c for c in student_id if unicodedata.category(c)[0] in "CZ" and c != " "), None)
    if hidden is not None:
        raise GraderError(f"{where}: student id {shown(student_id)} holds the invisible or control character "
                          f"U+{ord(hidden):04X} ({unicodedata.name(hidden, 'unnamed')}); expected visible "
                          "characters (letters, digits, punctuation, spaces)")
    if set(student_id) == {"."}:
        raise GraderError(f"{where}: student id {shown(student_id)} would name a hidden or parent folder; "
                          "expected letters or digits")
