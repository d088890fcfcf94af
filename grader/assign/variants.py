"""One seeded variant per student and problem, with answers from the numbers as printed.

A variant's generator is keyed on ``(assignment seed, problem key, student id)`` through SHA-256
into ``numpy.random.SeedSequence``: adding or removing a student changes nobody else's numbers.
Parameters are rounded to their printed precision before anything is computed. A draw that the
solver refuses, or whose answer sits near a degenerate point (an answer near zero, where a
relative tolerance breaks; a derived ``e`` at 0 or 1), or whose tolerance, widened for honest
rounding along a solution route (:mod:`grader.assign.fair`), would pass ``grading.max_tolerance``,
is redrawn from the same generator, at most ``MAX_DRAWS`` times. Whether a draw is degenerate or
too loose never depends on the rest of the class, nor on an answer the problem does not ask (an
assignment's ``parts``): a part added to the template changes no numbers of an assignment that lists its
parts.

Parameters print by :func:`grader.model.quantities.printed_text`.
"""

from __future__ import annotations

import hashlib
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np

from grader.assign.assignment import Assignment, ProblemSpec, Student
from grader.assign.fair import Fair, fair_tolerances
from grader.bank.template import Parameter, Template
from grader.base.errors import GraderError
from grader.model.expr import Sym
from grader.model.quantities import printed_text
from grader.model.tolerance import Tolerance
from grader.solve.cache import compiled_for, routes_for
from grader.solve.compiled import Compiled
from grader.solve.evaluate import Columns, answer_at, solve_columns
from grader.solve.routes import Routes

MAX_DRAWS = 25
NEAR_ZERO = 0.02  # an answer below 2% of its typical size is too close to zero to grade relatively
PILOT = 256  # draws that set an answer's typical size, from a generator of their own
PRINTED_CHARS = 24  # a printed value longer than this is no number a student can read or type


@dataclass(frozen=True, slots=True)
class AnswerPart:
    """One answer of a variant, as the key stores it."""

    name: str
    label: str
    value: float | str | None
    unit: str
    points: float
    tolerance: Tolerance
    description: str
    undefined: str | None = None


@dataclass(frozen=True, slots=True)
class ProblemVariant:
    """One student's numbers for one problem: parameters as printed, and the answers they give."""

    key: str
    template: str
    variant_seed: str
    params: Mapping[str, float]
    printed: Mapping[str, str]
    answers: tuple[AnswerPart, ...]


@dataclass(frozen=True, slots=True)
class StudentVariants:
    """Everything one student gets."""

    student: Student
    problems: tuple[ProblemVariant, ...]


@dataclass(frozen=True)
class Generation:
    """All students' variants, and how many students share their numbers with another, per problem."""

    students: tuple[StudentVariants, ...]
    collisions: Mapping[str, int]


def variant_generator(seed: str, problem_key: str, student_id: str) -> tuple[np.random.Generator, str]:
    """The generator of one variant, and its seed as hex (stored in the key).

    >>> first, seed = variant_generator("s", "1", "42")
    >>> again, same = variant_generator("s", "1", "42")
    >>> seed == same and first.random() == again.random()
    True
    """
    digest = hashlib.sha256("\x1f".join((seed, problem_key, student_id)).encode("utf-8")).digest()
    return np.random.Generator(np.random.PCG64(np.random.SeedSequence(int.from_bytes(digest[:16], "big")))), \
        digest[:8].hex()


def _draw(parameter: Parameter, problem: ProblemSpec, rng: np.random.Generator) -> str:
    name = parameter.name
    if name in problem.fixed:
        value = problem.fixed[name]
    elif name in problem.narrowed:
        low, high = problem.narrowed[name]
        value = float(rng.integers(int(low), int(high), endpoint=True) if parameter.integer else rng.uniform(low, high))
    elif parameter.sample.kind == "integers":
        low, high = parameter.sample.values
        value = float(rng.integers(int(low), int(high), endpoint=True))
    elif parameter.sample.kind == "choice":
        value = float(rng.choice(parameter.sample.values))
    elif parameter.sample.kind == "log_uniform":
        low, high = np.log(parameter.sample.values)
        value = float(np.exp(rng.uniform(low, high)))
    else:
        low, high = parameter.sample.values
        value = float(rng.uniform(low, high))
    text = printed_text(value, parameter.decimals, parameter.sig_figs)
    if len(text) > PRINTED_CHARS:
        precision = f"{parameter.decimals} decimals" if parameter.decimals is not None else \
            f"{parameter.sig_figs} significant figures"
        raise GraderError(f"{name} = {value:g} prints as {len(text)} characters with "
                          f"{precision}; expected values that print in at most {PRINTED_CHARS} (choose a value "
                          "of ordinary size, or another unit in the template)")
    return text


def _restitution_answers(template: Template) -> set[str]:
    """Answers that are a derived coefficient of restitution (kept off 0 and 1)."""
    derived = {stage.fields["restitution"].name for stage in template.scene.stages
               if stage.effect == "impact" and isinstance(stage.fields["restitution"], Sym)} - set(template.parameters)
    return {name for name, spec in template.answers.items()
            if isinstance(spec.value, Sym) and spec.value.name in derived}


class ProblemDraws:
    """Draws and checks the variants of one problem (``grader check-bank`` samples through it too)."""

    def __init__(self, assignment: Assignment, problem: ProblemSpec, template: Template) -> None:
        self.assignment, self.problem, self.template = assignment, problem, template
        self.where = f"{assignment.where}: problem {problem.key} ({template.id})"
        self.compiled: Compiled = compiled_for(template)
        self.restitution = _restitution_answers(template)
        self.asked = problem.asked(template)
        self.typical = self._typical_sizes()
        self.configured = {name: tolerance(problem, template, name) for name in self.asked}
        self.tolerances: dict[str, dict[str, Tolerance]] = {}  # per student drawn: each answer's tolerance

    @cached_property
    def routes(self) -> Routes:
        """The template's solution routes (compiled on first use: ``check-bank`` needs none)."""
        return routes_for(self.template)

    def fair(self, result: Columns) -> Fair:
        """Each answer's tolerance per row of a result, widened for honest rounding, and the rows whose
        widened tolerance would pass the cap."""
        answered = {name: [refused is None and missing is None for refused, missing in
                           zip(result.refusals, result.undefined[name], strict=True)] for name in self._numeric(result)}
        grading = self.assignment.grading
        return fair_tolerances(self.routes, self.configured,
                               {name: spec.unit.text for name, spec in self.template.answers.items()},
                               result.params, {name: result.values[name] for name in answered}, answered,
                               grading.intermediate_sig_figs,
                               grading.max_tolerance)

    def _numeric(self, result: Columns) -> list[str]:
        """The answers asked that have a number per row (a symbolic answer has none)."""
        return [name for name in self.asked if name in result.values]

    def _typical_sizes(self) -> dict[str, float]:
        rng, _ = variant_generator(self.assignment.seed, self.problem.key, "\x00pilot")
        rows = [self.draw_row(rng) for _ in range(PILOT)]
        result = solve_columns(self.template, self.compiled, self.table(rows))
        ok = np.array([reason is None for reason in result.refusals])
        typical = {}
        for name in self._numeric(result):
            values = result.values[name]
            defined = ok & np.array([reason is None for reason in result.undefined[name]])
            typical[name] = float(np.median(np.abs(values[defined]))) if defined.any() else 0.0
            if ok.any() and typical[name] == 0 and _relative(tolerance(self.problem, self.template, name)):
                what = "undefined" if not defined.any() else "0"
                raise GraderError(f"{self.where}: answer {name} is {what} for every variant the fixed and narrowed "
                                  "parameters allow, so it cannot be graded with a relative tolerance; expected "
                                  "parameters that give it a nonzero value (change fixed/narrow, or give the answer "
                                  "an atol)")
        return typical

    def draw_row(self, rng: np.random.Generator) -> dict[str, str]:
        """One draw: each parameter as printed."""
        try:
            return {name: _draw(p, self.problem, rng) for name, p in self.template.parameters.items()}
        except GraderError as error:
            raise GraderError(f"{self.where}: {error}") from None

    def table(self, rows: Sequence[Mapping[str, str]]) -> dict[str, Any]:
        """Printed rows as the columns :func:`solve_columns` takes."""
        return {name: np.array([float(row[name]) for row in rows]) for name in self.template.parameters}

    def degeneracies(self, result: Columns) -> list[str | None]:
        """Per row of a result, why a draw the solver answered sits at a degenerate point (an answer asked that
        is too close to zero to grade relatively, a derived ``e`` at 0 or 1), or None."""
        flaws: list[str | None] = [None] * len(result.refusals)
        for name in self._numeric(result):
            values = result.values[name]
            for row, value in enumerate(values):
                answered = result.refusals[row] is None and result.undefined[name][row] is None
                if flaws[row] is not None or not answered:
                    continue
                if abs(value) < NEAR_ZERO * self.typical.get(name, 0.0):
                    flaws[row] = f"answer {name} = {value:.3g} is too close to zero to grade with a relative tolerance"
                elif name in self.restitution and not 0.01 <= value <= 0.99:
                    flaws[row] = (f"the derived coefficient of restitution {name} = {value:.4g} is within 0.01 "
                                  "of 0 or 1 (a variant at a limit of e is a special case, not the problem asked)")
        return flaws

    def _flaws(self, rows: Sequence[Mapping[str, str]]) -> tuple[list[str | None], Fair]:
        result = solve_columns(self.template, self.compiled, self.table(rows))
        fair = self.fair(result)
        return [refused or degenerate or loose for refused, degenerate, loose in
                zip(result.refusals, self.degeneracies(result), fair.flaws, strict=True)], fair

    def draw(self, students: Sequence[Student]) -> tuple[list[dict[str, str]], list[str]]:
        """Each student's parameters as printed, and each variant's seed."""
        keyed = {s.id: variant_generator(self.assignment.seed, self.problem.key, s.id) for s in students}
        generators = {student_id: pair[0] for student_id, pair in keyed.items()}
        rows = {s.id: self.draw_row(generators[s.id]) for s in students}
        pending = [s.id for s in students]
        for _ in range(MAX_DRAWS):
            flaws, fair = self._flaws([rows[i] for i in pending])
            for index, (student_id, flaw) in enumerate(zip(pending, flaws, strict=True)):
                if flaw is None:
                    self.tolerances[student_id] = {name: fair.tolerances[name][index] for name in fair.tolerances}
            pending = [i for i, flaw in zip(pending, flaws, strict=True) if flaw is not None]
            if not pending:
                return [rows[s.id] for s in students], [keyed[s.id][1] for s in students]
            last = dict(zip(pending, [f for f in flaws if f is not None], strict=True))
            for student_id in pending:
                rows[student_id] = self.draw_row(generators[student_id])
        first = pending[0]
        advice = ("narrow the parameters toward variants that rounding moves less, or raise grading.max_tolerance"
                  if "max_tolerance" in last[first] else
                  "check fixed/narrowed parameters against the template's constraints")
        raise GraderError(f"{self.where}: no valid variant for student {first} in {MAX_DRAWS} draws; the last was "
                          f"refused because {last[first]} ({advice})")


CHUNK = 10_000
"""Students drawn together when a class is drawn in pieces (:class:`ClassDraws`): big enough that the vectorised
solving pays, small enough that a piece's variants (about 8 KiB a student) are a few tens of MiB."""


class ClassDraws:
    """A class's variants drawn a piece of the roster at a time (each problem's pilot and compiled form made
    once), so that a key can be written as it is drawn and a million students never sit in memory at once.
    A student's variants do not depend on the piece they are drawn in, so the pieces joined are the class
    drawn whole; after the last piece, :meth:`collisions` counts the students sharing their numbers.
    """

    def __init__(self, assignment: Assignment, roster: Sequence[Student], bank: Mapping[str, Template]) -> None:
        self.assignment, self.roster = assignment, roster
        self.makers = [ProblemDraws(assignment, problem, bank[problem.template]) for problem in assignment.problems]
        self._printed: list[list[np.ndarray]] = [[] for _ in self.makers]  # per problem: each piece's rows

    def chunks(self, size: int = CHUNK) -> Iterator[tuple[StudentVariants, ...]]:
        """The class's variants, ``size`` students at a time, in roster order."""
        for start in range(0, len(self.roster), size):
            students = self.roster[start:start + size]
            per_problem = [self._variants(index, maker, students) for index, maker in enumerate(self.makers)]
            yield tuple(StudentVariants(s, tuple(p[i] for p in per_problem)) for i, s in enumerate(students))

    def _variants(self, index: int, maker: ProblemDraws, students: Sequence[Student]) -> list[ProblemVariant]:
        problem, template = maker.problem, maker.template
        rows, seeds = maker.draw(students)
        answers = _Answers(_blank_parts(problem, template, maker.asked), template, maker.compiled,
                           solve_columns(template, maker.compiled, maker.table(rows)))
        variants = [ProblemVariant(problem.key, template.id, seed, {n: float(v) for n, v in row.items()}, row,
                                   answers.parts(row_index, row, maker.tolerances[student.id]))
                    for row_index, (row, seed, student) in enumerate(zip(rows, seeds, students, strict=True))]
        maker.tolerances.clear()
        # Each row's printed values as one byte string (no printed value holds the separator): the rows of a
        # million students take tens of MiB, where a counter of tuples takes hundreds.
        self._printed[index].append(np.array(["\x1f".join(row.values()).encode("utf-8") for row in rows],
                                             dtype=bytes))
        return variants

    def collisions(self) -> dict[str, int]:
        """Per problem, how many students of the pieces drawn so far share their printed numbers with another."""
        return {maker.problem.key: _shared(np.concatenate(pieces) if pieces else np.array([], dtype=bytes))
                for maker, pieces in zip(self.makers, self._printed, strict=True)}


def _shared(rows: np.ndarray) -> int:
    """How many of ``rows`` equal another of them.

    >>> _shared(np.array([b"2.10", b"3.00", b"2.10", b"1.5"]))
    2
    """
    _, inverse, counts = np.unique(rows, return_inverse=True, return_counts=True)
    return int((counts[inverse] > 1).sum())


def generate(assignment: Assignment, roster: Sequence[Student], bank: Mapping[str, Template]) -> Generation:
    """Every student's variants for every problem, answers computed from the printed values."""
    draws = ClassDraws(assignment, roster, bank)
    students = tuple(variant for chunk in draws.chunks(max(len(roster), 1)) for variant in chunk)
    return Generation(students, draws.collisions())


def _blank_parts(problem: ProblemSpec, template: Template, asked: Sequence[str]) -> list[AnswerPart]:
    """What every student's answer parts share: label, unit, points, tolerance (overrides applied). The
    parts asked are lettered a, b, c, ... as the sheet prints them, whichever of the template's they are."""
    parts = []
    for index, name in enumerate(asked):
        spec = template.answers[name]
        parts.append(AnswerPart(name, f"{problem.key}{chr(ord('a') + index)}", None, spec.unit.text,
                                problem.points.get(name, problem.points.get("*", 1.0)),
                                tolerance(problem, template, name), spec.description))
    return parts


def _relative(tolerance: Tolerance) -> bool:
    """Whether the band shrinks to nothing at a key of 0 (only ``rtol`` mode without ``atol``)."""
    return tolerance.mode == "rtol" and tolerance.atol == 0


def tolerance(problem: ProblemSpec, template: Template, name: str) -> Tolerance:
    """An answer's tolerance: the template's, with the assignment's override (checked when it was read)."""
    spec, override = template.answers[name].tolerance, problem.tolerances.get(name)
    return spec if override is None else Tolerance.from_json(override, base=spec)


class _Answers:
    """The answer parts of one problem's variants, from the solved columns.

    A symbolic answer's text depends only on the parameters it does not keep as symbols, and
    many students share those (``e`` printed to two decimals): each distinct text is made once.
    """

    def __init__(self, blanks: Sequence[AnswerPart], template: Template, compiled: Compiled,
                 result: Columns) -> None:
        self.blanks, self.template, self.compiled, self.result = blanks, template, compiled, result
        self.substituted = {b.name: [p for p in template.parameters if p not in template.answers[b.name].symbolic]
                            for b in blanks if compiled.answers[b.name].symbolic is not None}
        self.texts: dict[tuple[str, ...], tuple[float | str | None, str | None]] = {}

    def parts(self, row: int, printed: Mapping[str, str],
              tolerances: Mapping[str, Tolerance]) -> tuple[AnswerPart, ...]:
        """The answer parts of the variant in ``row`` of the result, printed as ``printed``, with each
        answer's tolerance for this variant."""
        parts = []
        for blank in self.blanks:
            value, undefined = self._value(blank.name, row, printed)
            parts.append(AnswerPart(blank.name, blank.label, value, blank.unit, blank.points, tolerances[blank.name],
                                    blank.description, undefined))
        return tuple(parts)

    def _value(self, name: str, row: int, printed: Mapping[str, str]) -> tuple[float | str | None, str | None]:
        substituted = self.substituted.get(name)
        if substituted is None or self.result.undefined[name][row] is not None:
            return answer_at(self.template, self.compiled, self.result, name, row)
        key = (name, *(printed[p] for p in substituted))
        if key not in self.texts:
            self.texts[key] = answer_at(self.template, self.compiled, self.result, name, row)
        return self.texts[key]
