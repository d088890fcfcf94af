"""A student's sheet as it goes back to them: what grading found (:mod:`grader.grade.feedback_rows` makes it)
and what the feedback documents show (:mod:`grader.render.feedback`). ``grade/`` and ``render/`` are peers
that import neither each other, so the record they share lives here, below both, in plain values.

It also rebuilds, from a key file, the variants the documents are made from (:func:`key_variants`):
the feedback shows each student's worked solution as the answer key has it, and grading never
regenerates (the key holds every student's printed numbers, answers and tolerances).

>>> part = MarkedPart("1a", "0.47", "0.47", "correct", 1.0, 2.0, "within ±1 % is accepted", "0.474413", "±1 %", 0.0)
>>> Returned(0, "7", "Ana", "a@x", "L01", (part,), "", 0.0, 2.0, 2.0).submitted
True
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

from grader.assign.assignment import Assignment, Grading, ProblemSpec, Student
from grader.assign.variants import AnswerPart, Generation, ProblemVariant, StudentVariants
from grader.bank.template import Template
from grader.base.errors import GraderError
from grader.model.tolerance import Tolerance


@dataclass(frozen=True, slots=True)
class MarkedPart:
    """One part of a student's sheet, graded: ``typed`` as submitted (None: nothing came), what it was
    ``read_as`` and the ``expected`` value (each with its unit), the verdict and its credit of ``points``,
    the sentence that explains it, the ``tolerance`` in words (with why, where it was widened), and the
    points the late policy took for it."""

    label: str
    typed: str | None
    read_as: str
    verdict: str
    credit: float
    points: float
    feedback: str
    expected: str
    tolerance: str
    deduction: float

    @property
    def score(self) -> float:
        """Points earned, before any late deduction."""
        return self.credit * self.points


@dataclass(frozen=True, slots=True)
class Returned:
    """A student's graded sheet: who (``index``: their place in the key), each part in the key's order,
    how late their latest answer that counts came, in words (empty: on time, not known, or nothing came),
    the points the late policy took, the total after it and what was possible."""

    index: int
    id: str
    name: str
    email: str
    section: str
    parts: tuple[MarkedPart, ...]
    late: str
    deduction: float
    total: float
    possible: float

    @property
    def submitted(self) -> bool:
        """Whether any answer was received."""
        return any(part.typed is not None for part in self.parts)


def key_variants(document: Mapping[str, Any], where: str,
                 templates: Mapping[str, Template]) -> tuple[Assignment, Generation]:
    """The assignment's printed header and every student's variants, as the key ``document`` (the key file
    ``where``, already checked by :func:`grader.grade.key.load_key`) holds them; ``templates``: each
    problem's template, by id (the descriptions of the answers are theirs)."""
    header = document.get("assignment", {})
    grading = header.get("grading", {})
    problems = document.get("problems", [])
    specs = tuple(ProblemSpec(str(p["key"]), str(p.get("template", "")), {}, {}, {}, {}) for p in problems)
    assignment = Assignment(where, str(header.get("title", "")),
                            str(header.get("course", "")), str(header.get("seed", "")), str(header.get("due", "")),
                            str(header.get("instructions", "")), specs,
                            Grading(intermediate_sig_figs=int(grading.get("intermediate_sig_figs", 4)),
                                    max_tolerance=float(grading.get("max_tolerance", 0.05))))
    order = {str(p["key"]): [str(a["name"]) for a in p.get("answers", [])] for p in problems}
    students = tuple(_student(raw, order, templates) for raw in document.get("students", []))
    return assignment, Generation(students, dict(document.get("collisions", {})))


def _student(raw: Mapping[str, Any], order: Mapping[str, Sequence[str]],
             templates: Mapping[str, Template]) -> StudentVariants:
    student = Student(str(raw["id"]), str(raw.get("name", "")), str(raw.get("email", "")), str(raw.get("section", "")))
    return StudentVariants(student, tuple(_variant(p, order[str(p["key"])], templates, student.id)
                                          for p in raw.get("problems", [])))


def _variant(raw: Mapping[str, Any], names: Sequence[str], templates: Mapping[str, Template],
             student_id: str) -> ProblemVariant:
    if "printed" not in raw or "params" not in raw:
        raise GraderError(f"key.json: student {student_id}, problem {raw.get('key')}: no printed numbers (a key "
                          "written before grader kept them); generate the assignment again to hand back feedback")
    template = templates[str(raw["template"])]
    answers = raw["answers"]
    parts = tuple(AnswerPart(name, str(answers[name]["label"]), answers[name]["value"], str(answers[name]["unit"]),
                             float(answers[name]["points"]), _tolerance(answers[name]["tolerance"]),
                             template.answers[name].description, answers[name].get("undefined"))
                  for name in names)
    return ProblemVariant(str(raw["key"]), template.id, str(raw.get("variant_seed", "")),
                          {str(n): float(v) for n, v in raw["params"].items()},
                          {str(n): str(v) for n, v in raw["printed"].items()}, parts)


def _tolerance(raw: Mapping[str, Any]) -> Tolerance:
    """The tolerance of a key's answer; one object for equal entries (a class shares a few)."""
    return _tolerance_of(tuple(sorted(raw.items())))


@lru_cache(maxsize=256)
def _tolerance_of(entry: tuple[tuple[str, Any], ...]) -> Tolerance:
    return Tolerance.from_json(dict(entry))
