"""Simulated submissions: what a class might type for its variants, for ``grader demo`` to grade.

Each student's answers to each problem are drawn from a generator keyed on ``(assignment seed, "sample
answers <problem key>", student id)`` (:func:`grader.assign.variants.variant_generator`; no problem key has
a space), so a generation always gives the same file, and a part added to one template changes no other
problem's answers (the time of the student's submission comes from ``"sample answers"`` alone). Most
answers are right and rounded to three significant figures, as the sheet asks; the others come in the
forms real submissions hold: the unit written, another unit of the same kind (``283 cm/s``), a decimal
comma, ``×10^`` notation, unrounded, wrong (off by 6 to 30 %, a percentage typed as a fraction, an angle in
radians, a speed with no ``/s``), or blank. Symbolic answers are typed with implicit products
(``v(1-0.07p)/(p+1)``), as in the key, or with a sign wrong. One student submits nothing, one writes
``about 48``, and one resubmits a corrected answer after the deadline.

A second generator per student and problem (``"sample physics <problem key>"``) turns a few right answers
into what the grader's physics recognises (:mod:`grader.solve.alternatives`): a diagnosed mistake (``e²``
for ``e``, the masses swapped, ...), or, after an earlier wrong answer of the problem, the answer that
follows from it (error carried forward). An answer off by 6 to 30 % is moved off any value the grader would
diagnose, so each answer deserves exactly one verdict.

>>> student_style("v*(1 - 0.07*p)/(p + 1)"), sign_error("1.07*v/(p + 1)")
('v(1-0.07p)/(p+1)', '1.07v/(p-1)')
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from datetime import datetime, timedelta

import numpy as np

from grader.assign.assignment import Assignment
from grader.assign.variants import AnswerPart, Generation, variant_generator
from grader.bank.template import Template
from grader.base.spreadsheet import csv_text
from grader.model.quantities import printed_text, scientific, significant
from grader.solve.alternatives import carries_forward, values
from grader.solve.cache import alternatives_for

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
_PHYSICS_KEY = "sample physics"  # a stream of its own: which right answers become a mistake or carry an error forward
_MISTAKES, _CARRIED = 0.07, 0.5  # of the right answers (the second where an earlier part is wrong)
_WHEN = "%Y-%m-%d %H:%M:%S"
_DEADLINE = datetime(2026, 12, 4, 23, 59)  # for an assignment whose due date is not ISO 8601


@dataclass(frozen=True)
class SampleAnswer:
    """One row of the file, its form, the verdict a fair grader gives it (``correct``, ``ecf``, ``mistake``,
    ``incorrect``, ``invalid`` or ``missing``, for relative tolerances of 1 % or more) and, for ``ecf`` and
    ``mistake``, the diagnosis (``ecf:3a``, ``impact.e_squared``)."""

    student_id: str
    label: str
    text: str
    timestamp: str
    form: str
    deserves: str
    diagnosis: str = ""


@dataclass(frozen=True)
class _Typed:
    """A part as typed, and the number it is in the sheet's unit (None: no number)."""

    text: str
    form: str
    deserves: str
    number: float | None
    diagnosis: str = ""


def sample_answers(assignment: Assignment, generation: Generation,
                   bank: Mapping[str, Template]) -> list[SampleAnswer]:
    """Every student's answers, in roster and sheet order; the late resubmission comes last."""
    deadline = due_time(assignment.due)
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
        for problem in entry.problems:
            # Streams of the student's own per problem: a part added to one template moves no other
            # problem's answers.
            rng = variant_generator(assignment.seed, f"{_KEY} {problem.key}", entry.student.id)[0]
            physics_rng = variant_generator(assignment.seed, f"{_PHYSICS_KEY} {problem.key}", entry.student.id)[0]
            physics = _Physics(bank[problem.template], problem.params)
            earlier: list[tuple[AnswerPart, float | None]] = []
            for part in problem.answers:
                typed = _typed(part, rng)
                value = part.value if isinstance(part.value, float) else None
                if value is not None and index == vague and part is numeric[-1]:
                    typed = _Typed(f"about {printed_text(value, None, 2)}", "words", "invalid", None)
                elif value is not None and index == late and part is numeric[0]:
                    typed = _wrong(value, part.unit, rng)
                    later = (deadline + timedelta(seconds=int(rng.integers(600, 43200)))).strftime(_WHEN)
                    resubmitted.append(SampleAnswer(entry.student.id, part.label, _three(value), later,
                                                    "late resubmission", "correct"))
                    typed = replace(typed, number=value)  # what is graded is the resubmission
                elif value is not None:
                    typed = physics.typed(part, value, typed, earlier, physics_rng)
                earlier.append((part, typed.number))
                rows.append(SampleAnswer(entry.student.id, part.label, typed.text, when, typed.form, typed.deserves,
                                         typed.diagnosis))
    return rows + resubmitted


def submissions_csv(answers: Sequence[SampleAnswer]) -> str:
    """The long-format file ``grader grade`` reads: ``student_id,label,answer,timestamp``."""
    return csv_text([HEADER, *((a.student_id, a.label, a.text, a.timestamp) for a in answers)])


def student_style(expression: str) -> str:
    """A key's expression as students type it: ``^`` for powers, no ``*`` before a name or a
    parenthesis, no spaces."""
    typed = re.sub(r"(?<=[\w)])\*(?=[A-Za-z(])", "", expression.replace("**", "^"))
    return typed.replace(" ", "")


def sign_error(expression: str) -> str:
    """The expression with its first ``+`` or ``-`` between terms the other way round, as typed."""
    flipped = re.sub(r" ([-+]) ", lambda sign: " + " if sign[1] == "-" else " - ", expression, count=1)
    return student_style(flipped if flipped != expression else f"-({expression})")


def _typed(part: AnswerPart, rng: np.random.Generator) -> _Typed:
    """What the student typed for ``part``."""
    if part.value is None:
        return _Typed("undefined", "undefined", "correct", None)
    if isinstance(part.value, str):
        form = _pick(SYMBOLIC, rng)
        typed = {"implicit products": student_style(part.value), "as in the key": part.value,
                 "sign error": sign_error(part.value), "blank": ""}[form]
        return _Typed(typed, form, {"sign error": "incorrect", "blank": "missing"}.get(form, "correct"), None)
    return _numeric(_pick(NUMERIC, rng), part.value, part.unit, rng)


def _numeric(form: str, value: float, unit: str, rng: np.random.Generator) -> _Typed:
    three = _three(value)
    if form == "unit" and unit:
        return _Typed(f"{three}{_GLUED[unit]}" if unit in _GLUED else f"{three} {unit}", form, "correct", float(three))
    if form == "other unit" and unit in _OTHER_UNITS:
        other, factor = _OTHER_UNITS[unit][int(rng.integers(len(_OTHER_UNITS[unit])))]
        return _Typed(f"{_three(value * factor)} {other}", form, "correct", float(_three(value * factor)) / factor)
    if form == "decimal comma" and "." in three:
        return _Typed(three.replace(".", ","), form, "correct", float(three))
    if form == "×10^":
        mantissa, exponent = scientific(significant(value, 3), 3)
        return _Typed(f"{mantissa}×10^{exponent}", form, "correct", float(f"{mantissa}e{exponent}"))
    if form == "unrounded" and len(f"{value:.9g}") > len(three):  # 0.07 has no more digits to show
        return _Typed(f"{value:.9g}", form, "correct", float(f"{value:.9g}"))
    if form == "wrong":
        return _wrong(value, unit, rng)
    if form == "blank":
        return _Typed("", form, "missing", None)
    return _Typed(three, "3 s.f.", "correct", float(three))


def _wrong(value: float, unit: str, rng: np.random.Generator) -> _Typed:
    """A typical mistake: off by 6 to 30 %, or one the unit invites (the first two the grader diagnoses)."""
    mistakes = ["off by 6-30 %"]
    mistakes += {"%": ["percentage as a fraction"], "deg": ["radians for degrees"]}.get(unit, [])
    mistakes += ["no /s"] if unit.endswith("/s") else []
    mistake = mistakes[int(rng.integers(len(mistakes)))]
    if mistake == "percentage as a fraction":
        return _Typed(_three(value / 100), mistake, "mistake", float(_three(value / 100)),
                      "energy.fraction_for_percent")
    if mistake == "radians for degrees":
        return _Typed(_three(math.radians(value)), mistake, "mistake", float(_three(math.radians(value))),
                      "angle.radians")
    if mistake == "no /s":
        return _Typed(f"{_three(value)} {unit.removesuffix('/s')}", mistake, "incorrect", None)
    off = 1 + float(rng.choice([-1, 1])) * float(rng.uniform(0.06, 0.30))
    return _Typed(_three(value * off), mistake, "incorrect", float(_three(value * off)))


class _Physics:
    """One student's problem as the grader's physics sees it: the mistakes a part's number may match and
    the answers an earlier one carries forward to (:mod:`grader.solve.alternatives`)."""

    def __init__(self, template: Template, params: Mapping[str, float]) -> None:
        self.found = alternatives_for(template)
        self.params = {name: np.array([value]) for name, value in params.items()}

    def mistakes(self, name: str, right: float) -> list[tuple[str, float]]:
        """A part's diagnosed mistakes that can be told from the right value, in the grader's order."""
        found = [(a.id, float(values(self.found, a, self.params)[0]))
                 for a in self.found.for_answer(name) if a.kind == "mistake"]
        return [(id, value) for id, value in found if math.isfinite(value) and not _close(value, right)]

    def carried(self, name: str, sources: Sequence[tuple[AnswerPart, float | None]]) -> list[tuple[str, float]]:
        """What each plausible earlier number carries forward to, nearest part first: ``(label, value)``."""
        found = []
        for source, number in reversed(sources):
            if number is None or not isinstance(source.value, float) or not _plausible(number, source.value):
                continue
            found += [(source.label, float(values(self.found, a, self.params, np.array([number]))[0]))
                      for a in self.found.for_answer(name) if a.kind == "ecf" and a.id == source.name]
        return [(label, value) for label, value in found if math.isfinite(value)]

    def typed(self, part: AnswerPart, right: float, typed: _Typed, earlier: Sequence[tuple[AnswerPart, float | None]],
              rng: np.random.Generator) -> _Typed:
        """``typed`` as the physics grades it: a few right answers become a diagnosed mistake or an error
        carried forward from an earlier wrong number; an answer off by 6 to 30 % is kept clear of both."""
        mistakes = self.mistakes(part.name, right)
        wrong_sources = [(source, number) for source, number in earlier
                         if number is not None and isinstance(source.value, float) and not _close(number, source.value)]
        carried = [(label, value) for label, value in self.carried(part.name, earlier) if not _close(value, right)]
        near = [value for _, value in mistakes + carried]
        mistaken, which, carry = float(rng.random()), float(rng.random()), float(rng.random())
        if typed.form == "off by 6-30 %":
            return _clear_of(typed, right, near)
        if typed.deserves != "correct":
            return typed
        if mistaken < _MISTAKES and mistakes:
            id, value = mistakes[int(which * len(mistakes))]
            # Told apart from the others, and of a size a student would write down (the sign may be wrong).
            if sum(_close(value, other) for other in near) == 1 and _plausible(abs(value), abs(right)):
                return _Typed(_three(value), "diagnosed mistake", "mistake", float(_three(value)), id)
        elif carry < _CARRIED and carried and carried[0][0] in {source.label for source, _ in wrong_sources} \
                and _plausible(carried[0][1], right):  # of a size that looks like an answer
            label, value = carried[0]
            return _Typed(_three(value), "error carried forward", "ecf", float(_three(value)), f"ecf:{label}")
        return typed


def _clear_of(typed: _Typed, right: float, near: Sequence[float]) -> _Typed:
    """An answer off by 6 to 30 %, moved off any value the grader would diagnose (still 6 to 30 % off)."""
    off = (typed.number or right) / right
    for step in (0.0, 0.05, -0.05, 0.1, -0.1, 0.15, -0.15):
        moved = off + step
        number = float(_three(right * moved))
        if 0.06 <= abs(moved - 1) <= 0.30 and not any(_close(number, value) for value in near):
            return replace(typed, text=_three(right * moved), number=number)
    return typed


def _plausible(number: float, right: float) -> bool:
    """The grader's rule for an earlier answer that carries forward (its sign, within a factor of 3)."""
    return bool(carries_forward(number, right))


def _close(value: float, other: float, share: float = 0.03) -> bool:
    return abs(value - other) <= share * abs(other)


def _pick(forms: Sequence[tuple[str, float]], rng: np.random.Generator) -> str:
    draw, total = float(rng.random()), 0.0
    for form, share in forms:
        total += share
        if draw < total:
            return form
    return forms[0][0]


def _three(value: float) -> str:
    return printed_text(value, None, 3)


def due_time(due: str) -> datetime:
    """The time an assignment is due, by which the simulated class submits (a date that is not ISO 8601:
    the sample's)."""
    try:
        return datetime.fromisoformat(due.strip())
    except ValueError:
        return _DEADLINE
