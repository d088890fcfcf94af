"""What each student gets back from a grading run, in plain values (:class:`~grader.assign.returned.Returned`):
per part what they typed, what it was read as, the verdict with its credit, the sentence that explains it,
the expected value and the tolerance; the late deduction and the total, as ``grades.csv`` has them.

Only the student's own verdicts go in: not where their answer came from (the file and line), not the run's
notes for the instructor, not another student's anything.

>>> from grader.grade.key import Key, KeyPart, KeyProblem, KeyStudent
>>> from grader.grade.grading import Graded, Row
>>> part = KeyPart("1", "e", "1a", 0.5, "", 2.0, {"mode": "rtol", "rtol": 0.01, "atol": 0.0}, None, {})
>>> key = Key("key.json", 2, "HW", True, (KeyProblem("1", "Drop", ("1a",)),),
...           (KeyStudent("s1", "Ana", "a@x", "1", {"1a": part}),))
>>> row = Row("0.51", "incorrect", 0.0, 2.0, "0.5", "0.51", "", 0.01, 0.02, "±1 %", "0.51 is 2 % above 0.5", "", "a:2")
>>> [back] = returned(Graded(key, {"1a": [row]}, (), (), ()))
>>> back.parts[0].typed, back.parts[0].read_as, back.total, back.possible
('0.51', '0.51', 0.0, 2.0)
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from grader.assign.assignment import Assignment
from grader.assign.returned import MarkedPart, Returned, key_variants
from grader.assign.variants import Generation
from grader.bank.template import Template
from grader.base.errors import GraderError, visible
from grader.grade.class_grades import ClassGrades, final_scores, lateness
from grader.grade.class_report import _lateness
from grader.grade.diagnosis import template_of
from grader.grade.grading import Graded
from grader.grade.key import Key
from grader.model.tolerance import with_unit


def returned(graded: Graded) -> list[Returned]:
    """Every student of the key, in its order, with their graded parts."""
    key, late, whole = graded.key, graded.late, ClassGrades.of(graded)
    final, minutes = final_scores(whole), lateness(whole)
    back = []
    for index, student in enumerate(key.students):
        parts = []
        for label in key.labels:
            row = graded.columns[label][index]
            shares = late.shares[label][index] if late else 0.0
            parts.append(MarkedPart(label, None if row.submitted is None else visible(row.submitted),
                                    _with_unit(visible(row.parsed), row.unit), row.verdict, row.credit, row.points,
                                    visible(row.feedback), _with_unit(row.expected, row.unit), row.tolerance,
                                    shares or 0.0))
        late_by = minutes[index]
        back.append(Returned(index, student.id, student.name, student.email, student.section, tuple(parts),
                             _lateness(late_by) if late_by else "", graded.deductions.get(student.id, 0.0),
                             final[student.id], student.possible))
    return back


def _with_unit(text: str, unit: str) -> str:
    """A value's text with its unit; an expression (or nothing) as it is."""
    try:
        float(text)
    except ValueError:
        return text
    return with_unit(text, unit)


def key_templates(key: Key, bank: Path | Mapping[str, Template] | None = None) -> dict[str, Template]:
    """Each problem's template, by id, as the key was made from it; refused, with the reason and what to
    give, when one cannot be found (a student's worked solution needs it)."""
    templates = {}
    for problem in key.problems:
        found = template_of(key, problem, bank)
        if isinstance(found, str):
            raise GraderError(f"{key.where}: problem {problem.key}: {found}; feedback shows each student's worked "
                              "solution from the template the key was made from (give --bank DIR where it is)")
        templates[found.id] = found
    return templates


def key_generation(key: Key, templates: Mapping[str, Template]) -> tuple[Assignment, Generation]:
    """The assignment's header and every student's variants, read again from the key's file."""
    document: Any = json.loads(Path(key.where).read_text(encoding="utf-8"))
    return key_variants(document, key.where, templates)
