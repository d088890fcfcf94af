"""Simulated submissions: what a class might type for its variants, for ``grader demo`` to grade.

Each student's answers are drawn from a generator keyed on ``(assignment seed, "sample answers", student
id)`` (:func:`grader.assign.variants.variant_generator`; no problem key has a space), so a generation
always gives the same file. Most answers are right and rounded to three significant figures, as the
sheet asks; the others come in the forms real submissions hold: the unit written, another unit of the
same kind (``283 cm/s``), a decimal comma, ``×10^`` notation, unrounded, wrong (off by 6 to 30 %, a
percentage typed as a fraction, an angle in radians, a speed with no ``/s``), or blank. Symbolic answers are typed with
implicit products (``v(1-0.07p)/(p+1)``), as in the key, or with a sign wrong. One student submits
nothing, one writes ``about 48``, and one resubmits a corrected answer after the deadline.

>>> student_style("v*(1 - 0.07*p)/(p + 1)"), sign_error("1.07*v/(p + 1)")
('v(1-0.07p)/(p+1)', '1.07v/(p-1)')
"""

from __future__ import annotations

import csv
import io
import math
import re
from collections.abc import Sequence
from dataclasses import dataclass
from datetime import datetime, timedelta

import numpy as np

from grader.assign.assignment import Assignment
from grader.assign.variants import AnswerPart, Generation, printed_text, variant_generator

HEADER = ("student_id", "label", "answer", "timestamp")
# The forms of an answer part and how often each is typed; a form a part cannot take (a unit for a
# pure number) is typed as plain 3 significant figures instead.
NUMERIC = (("3 s.f.", 0.51), ("unit", 0.12), ("other unit", 0.08), ("decimal comma", 0.06), ("×10^", 0.04),
           ("unrounded", 0.05), ("wrong", 0.11), ("blank", 0.03))
SYMBOLIC = (("implicit products", 0.55), ("as in the key", 0.25), ("sign error", 0.15), ("blank", 0.05))
_OTHER_UNITS = {"m/s": (("cm/s", 100.0), ("km/h", 3.6)), "ft/s": (("m/s", 0.3048), ("mph", 0.3048 / 0.44704)),
                "deg": (("rad", math.pi / 180),)}
_GLUED = {"deg": "°", "%": "%"}  # written without a space
_KEY = "sample answers"
_WHEN = "%Y-%m-%d %H:%M:%S"
_DEADLINE = datetime(2026, 12, 4, 23, 59)  # for an assignment whose due date is not ISO 8601


@dataclass(frozen=True)
class SampleAnswer:
    """One row of the file, its form, and the verdict a fair grader gives it (``correct``,
    ``incorrect``, ``invalid`` or ``missing``, for relative tolerances of 1 % or more)."""

    student_id: str
    label: str
    text: str
    timestamp: str
    form: str
    deserves: str


def sample_answers(assignment: Assignment, generation: Generation) -> list[SampleAnswer]:
    """Every student's answers, in roster and sheet order; the late resubmission comes last."""
    deadline = _deadline(assignment.due)
    roles = variant_generator(assignment.seed, _KEY, "")[0].permutation(len(generation.students))
    absent, late, vague = (int(i) for i in roles[:3]) if len(roles) >= 3 else (-1, -1, -1)
    rows, resubmitted = [], []
    for index, entry in enumerate(generation.students):
        if index == absent:
            continue
        rng = variant_generator(assignment.seed, _KEY, entry.student.id)[0]
        when = (deadline - timedelta(seconds=int(rng.integers(600, 3 * 86400)))).strftime(_WHEN)
        parts = [part for problem in entry.problems for part in problem.answers]
        numeric = [part for part in parts if isinstance(part.value, float)]
        for part in parts:
            text, form, deserves = _typed(part, rng)
            value = part.value if isinstance(part.value, float) else None
            if value is not None and index == vague and part is numeric[-1]:
                text, form, deserves = f"about {printed_text(value, None, 2)}", "words", "invalid"
            elif value is not None and index == late and part is numeric[0]:
                text, form, deserves = _wrong(value, part.unit, rng)
                later = (deadline + timedelta(seconds=int(rng.integers(600, 43200)))).strftime(_WHEN)
                resubmitted.append(SampleAnswer(entry.student.id, part.label, _three(value), later,
                                                "late resubmission", "correct"))
            rows.append(SampleAnswer(entry.student.id, part.label, text, when, form, deserves))
    return rows + resubmitted


def submissions_csv(answers: Sequence[SampleAnswer]) -> str:
    """The long-format file ``grader grade`` reads: ``student_id,label,answer,timestamp``."""
    stream = io.StringIO()
    writer = csv.writer(stream, lineterminator="\n")
    writer.writerow(HEADER)
    writer.writerows((a.student_id, a.label, a.text, a.timestamp) for a in answers)
    return stream.getvalue()


def student_style(expression: str) -> str:
    """A key's expression as students type it: ``^`` for powers, no ``*`` before a name or a
    parenthesis, no spaces."""
    typed = re.sub(r"(?<=[\w)])\*(?=[A-Za-z(])", "", expression.replace("**", "^"))
    return typed.replace(" ", "")


def sign_error(expression: str) -> str:
    """The expression with its first ``+`` or ``-`` between terms the other way round, as typed."""
    flipped = re.sub(r" ([-+]) ", lambda sign: " + " if sign[1] == "-" else " - ", expression, count=1)
    return student_style(flipped if flipped != expression else f"-({expression})")


def _typed(part: AnswerPart, rng: np.random.Generator) -> tuple[str, str, str]:
    """What the student typed for ``part``: text, form, the verdict it deserves."""
    if part.value is None:
        return "undefined", "undefined", "correct"
    if isinstance(part.value, str):
        form = _pick(SYMBOLIC, rng)
        typed = {"implicit products": student_style(part.value), "as in the key": part.value,
                 "sign error": sign_error(part.value), "blank": ""}[form]
        return typed, form, {"sign error": "incorrect", "blank": "missing"}.get(form, "correct")
    return _numeric(_pick(NUMERIC, rng), part.value, part.unit, rng)


def _numeric(form: str, value: float, unit: str, rng: np.random.Generator) -> tuple[str, str, str]:
    three = _three(value)
    if form == "unit" and unit:
        return (f"{three}{_GLUED[unit]}" if unit in _GLUED else f"{three} {unit}"), form, "correct"
    if form == "other unit" and unit in _OTHER_UNITS:
        other, factor = _OTHER_UNITS[unit][int(rng.integers(len(_OTHER_UNITS[unit])))]
        return f"{_three(value * factor)} {other}", form, "correct"
    if form == "decimal comma" and "." in three:
        return three.replace(".", ","), form, "correct"
    if form == "×10^":
        mantissa, exponent = f"{value:.2e}".split("e")
        return f"{mantissa}×10^{int(exponent)}", form, "correct"
    if form == "unrounded" and len(f"{value:.9g}") > len(three):  # 0.07 has no more digits to show
        return f"{value:.9g}", form, "correct"
    if form == "wrong":
        return _wrong(value, unit, rng)
    if form == "blank":
        return "", form, "missing"
    return three, "3 s.f.", "correct"


def _wrong(value: float, unit: str, rng: np.random.Generator) -> tuple[str, str, str]:
    """A typical mistake: off by 6 to 30 %, or one the unit invites."""
    mistakes = ["off by 6-30 %"]
    mistakes += {"%": ["percentage as a fraction"], "deg": ["radians for degrees"]}.get(unit, [])
    mistakes += ["no /s"] if unit.endswith("/s") else []
    mistake = mistakes[int(rng.integers(len(mistakes)))]
    if mistake == "percentage as a fraction":
        return _three(value / 100), mistake, "incorrect"
    if mistake == "radians for degrees":
        return _three(math.radians(value)), mistake, "incorrect"
    if mistake == "no /s":
        return f"{_three(value)} {unit.removesuffix('/s')}", mistake, "incorrect"
    off = 1 + float(rng.choice([-1, 1])) * float(rng.uniform(0.06, 0.30))
    return _three(value * off), mistake, "incorrect"


def _pick(forms: Sequence[tuple[str, float]], rng: np.random.Generator) -> str:
    draw, total = float(rng.random()), 0.0
    for form, share in forms:
        total += share
        if draw < total:
            return form
    return forms[0][0]


def _three(value: float) -> str:
    return printed_text(value, None, 3)


def _deadline(due: str) -> datetime:
    try:
        return datetime.fromisoformat(due.strip())
    except ValueError:
        return _DEADLINE
