"""Partial credit from the physics: a wrong number that is right for the student's own earlier answer
(error carried forward, verdict ``ecf``) or that matches a mistake the solver re-derives (``mistake``).

For each problem of the key, its template's alternatives (:mod:`grader.solve.alternatives`) are
evaluated at once for every student whose answer to a part is a wrong number. The template is read
from the bank by the id the key names, else from the bank folder the key records it came from (an
instructor's own, given to ``grader generate``; relative to the key's folder), and used only when it is
the file the key was made from (the SHA-256 the key records); a problem without it is graded as before,
and a note says why and which ``--bank`` to give.

Rules, in order, for one wrong number:

- ``ecf`` when it matches (the part's tolerance) a chain from an earlier answer of the problem, the
  nearest part first; only a plausible earlier answer carries forward: a number of the right sign
  within a factor of 3 of the right value. Credit ``ecf_credit`` (0 turns this off).
- ``mistake`` when it matches a diagnosed mistake whose value can be told from the right answer for
  this student's numbers, the first in the effects' lists. Credit ``mistake_credit``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from grader.bank.template import Template, load_template
from grader.base.errors import SYMPY_FAILURES, GraderError, unworkable
from grader.base.resources import bank_dir
from grader.grade.compare import is_correct, number_text
from grader.grade.key import Key, KeyProblem
from grader.model.tolerance import Tolerance, with_unit
from grader.solve.alternatives import Alternative, Alternatives, carries_forward, values
from grader.solve.cache import alternatives_for


@dataclass(frozen=True)
class ProblemPhysics:
    """A problem's alternatives, and each student's parameters (one column per parameter, in the key's
    order of students; NaN where the key has no number)."""

    alternatives: Alternatives
    params: Mapping[str, np.ndarray]


@dataclass(frozen=True)
class Physics:
    """The problems of a key that can carry errors forward and diagnose mistakes, by problem key; and why
    the others cannot."""

    problems: Mapping[str, ProblemPhysics]
    notes: tuple[str, ...] = ()

    def piece(self, start: int, stop: int) -> Physics:
        """The physics of the key's students ``start`` to ``stop`` alone (:meth:`grader.grade.key.Key.piece`)."""
        return Physics({key: ProblemPhysics(found.alternatives, {name: column[start:stop]
                                                                  for name, column in found.params.items()})
                        for key, found in self.problems.items()}, self.notes)


@dataclass(frozen=True)
class Earlier:
    """An earlier part of the same problem, for every student of the key: the number each gave in the
    part's unit and the right value (NaN where there is none)."""

    label: str
    name: str
    unit: str
    given: np.ndarray
    right: np.ndarray


@dataclass(frozen=True)
class Finding:
    """A wrong number reconsidered: its verdict, credit, sentence and diagnosis."""

    kind: str
    credit: float
    feedback: str
    diagnosis: str


def physics_for(key: Key, bank: Path | Mapping[str, Template] | None = None) -> Physics:
    """Each problem's template from ``bank`` (a folder, or templates loaded from one; the shipped bank by
    default), when it is the one the key was made from, with its alternatives; a note for each problem
    that goes without."""
    bank = bank_dir() if bank is None else bank
    problems, notes = {}, []
    for problem in key.problems:
        found = _problem_physics(key, problem, bank)
        if isinstance(found, str):
            notes.append(f"problem {problem.key}: {found}; its parts are graded without error carried forward "
                         "or diagnosed mistakes")
        else:
            problems[problem.key] = found
    return Physics(problems, tuple(notes))


def template_of(key: Key, problem: KeyProblem, bank: Path | Mapping[str, Template] | None = None) -> Template | str:
    """The template a problem of the key was made from, found in ``bank`` (by default the shipped bank) or
    the bank folder the key records, when it is the very file the key records; else why not."""
    if not problem.template:
        return "the key does not name its template"
    recorded = key.templates.get(problem.template)
    if not recorded:
        return f"the key does not record which file of template {problem.template} it was made from"
    return _template(key, problem.template, recorded, bank_dir() if bank is None else bank)


def _problem_physics(key: Key, problem: KeyProblem, bank: Path | Mapping[str, Template]) -> ProblemPhysics | str:
    """The problem's physics, or why there is none."""
    found = template_of(key, problem, bank)
    if isinstance(found, str):
        return found
    template = found
    absent = np.full(len(key.students), math.nan)
    params = {name: key.parameter_columns.get((problem.key, name), absent) for name in template.parameters}
    if key.students and any(np.isnan(column).all() for column in params.values()):
        return f"the key holds no values of {problem.template}'s parameters"
    try:
        return ProblemPhysics(alternatives_for(template), params)
    except (GraderError, *SYMPY_FAILURES) as error:  # a colleague's template sympy cannot work with: grading goes on
        if not unworkable(error):
            raise  # a bug of grader's keeps its traceback
        return f"template {problem.template} could not be compiled ({type(error).__name__}: {error})"


def _template(key: Key, template_id: str, recorded: str, bank: Path | Mapping[str, Template]) -> Template | str:
    """The template the key was made from (its SHA-256 ``recorded``): from ``bank``, else from the bank
    folder the key records; or why neither has it, and the ``--bank`` that would."""
    where = "the problem bank" if isinstance(bank, Mapping) else str(bank)
    found = _read(template_id, recorded, bank)
    if isinstance(found, Template):
        return found
    said = _said(template_id, where, found)
    folder = key.banks.get(template_id)
    if folder is None:  # the shipped bank's, or a key written before the folders were recorded
        return said
    place = Path(key.where).parent / folder
    again = _read(template_id, recorded, place)
    if isinstance(again, Template):
        return again
    there = {_ABSENT: "it is not there", _CHANGED: "it has changed since"}.get(again, f"it could not be read ({again})")
    return (f"{said}; the key records that it came from {place}, and {there}: give grader grade --bank DIR, where "
            f"DIR holds {template_id}.yaml as it was when the key was written (SHA-256 {recorded[:12]}…)")


_ABSENT, _CHANGED = "absent", "changed"


def _read(template_id: str, recorded: str, bank: Path | Mapping[str, Template]) -> Template | str:
    """The template from ``bank`` if it is the one the key recorded; else why not: :data:`_ABSENT`,
    :data:`_CHANGED`, or the error that reading it gave."""
    try:
        if isinstance(bank, Mapping):
            template = bank.get(template_id)
        else:
            path = bank / f"{template_id}.yaml"
            template = load_template(path) if path.exists() else None
    except (GraderError, OSError) as error:
        return str(error)
    if template is None:
        return _ABSENT
    return template if template.source_hash == recorded else _CHANGED


def _said(template_id: str, where: str, why: str) -> str:
    """Why a template was not used from ``where`` (a :func:`_read` reason), in a sentence."""
    if why == _ABSENT:
        return f"template {template_id} is not in {where}"
    if why == _CHANGED:
        return f"template {template_id} in {where} has changed since the key was written"
    return f"template {template_id} could not be read from {where} ({why})"


def reconsider(problem: ProblemPhysics, key: Key, name: str, label: str, unit: str,
               groups: Sequence[tuple[Tolerance, np.ndarray]], students: np.ndarray, submitted: np.ndarray,
               right: np.ndarray, said: Sequence[str], earlier: Sequence[Earlier]) -> dict[int, Finding]:
    """The wrong numbers ``submitted`` to part ``label`` (answer ``name``) by ``students`` (their indices in
    the key; ``right``: the key's values, ``said``: the sentences comparing them) that earn ``ecf`` or are
    a ``mistake``, by position in ``students``; ``groups``: the positions each tolerance decides.

    A part's wrong numbers fall into a few tolerance groups: each alternative is evaluated once for all
    of them (its value for a student does not depend on the others'), then told apart by each group's rule.
    """
    alternatives = problem.alternatives.for_answer(name)
    angle = unit if unit in ("deg", "rad") else None
    found: dict[int, Finding] = {}
    open_ = np.ones(len(students), dtype=bool)
    group_of = np.zeros(len(students), dtype=np.intp)
    for number, (_, positions) in enumerate(groups):
        group_of[positions] = number

    def correct(given: np.ndarray, expected: np.ndarray, rows: np.ndarray) -> np.ndarray:
        verdicts = np.zeros(rows.size, dtype=bool)
        among = group_of[rows]
        for number, (tolerance, _) in enumerate(groups):
            mine = among == number
            if mine.any():
                verdicts[mine] = is_correct(given[mine], expected[mine], tolerance, angle_unit=angle)
        return verdicts

    def matches(alternative: Alternative, rows: np.ndarray,
                given: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        params = {parameter: column[students[rows]] for parameter, column in problem.params.items()}
        value = values(problem.alternatives, alternative, params, given)
        return value, correct(submitted[rows], value, rows)

    for source in reversed(earlier) if key.ecf_credit > 0 else ():
        chains = [a for a in alternatives if a.kind == "ecf" and a.id == source.name]
        given, was = source.given[students], source.right[students]
        plausible = carries_forward(given, was)
        for chain in chains:
            rows = np.flatnonzero(open_ & plausible)
            if not rows.size:
                break
            _, hit = matches(chain, rows, given[rows])
            for row in rows[hit]:
                found[int(row)] = Finding("ecf", key.ecf_credit, _carried(source, given[row], was[row], label,
                                                                           right[row], unit), f"ecf:{source.label}")
            open_[rows[hit]] = False
    for mistake in (a for a in alternatives if a.kind == "mistake"):
        rows = np.flatnonzero(open_)
        if not rows.size:
            break
        value, hit = matches(mistake, rows)
        hit &= ~correct(value, right[rows], rows)  # not to be told from the right answer
        for row in rows[hit]:
            found[int(row)] = Finding("mistake", key.mistake_credit, f"your answer matches {mistake.says}: {said[row]}",
                                      mistake.id)
        open_[rows[hit]] = False
    return found


def _carried(source: Earlier, given: float, was: float, label: str, right: float, unit: str) -> str:
    """``right for your 3a = 2.71 m/s (error carried forward); with 3a = 2.55 m/s, 3b is 0.631``."""
    def quantity(value: float, unit: str) -> str:
        return with_unit(number_text(value), unit)

    return (f"right for your {source.label} = {quantity(given, source.unit)} (error carried forward); "
            f"with {source.label} = {quantity(was, source.unit)}, {label} is {quantity(right, unit)}")
