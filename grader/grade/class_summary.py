"""What the class report shows, worked out from a grading run with numpy: the class's scores, each
part's verdicts, tolerances and diagnosed mistakes, each problem's score against its printed
parameters, and the students with answers that could not be read.

Everything here is an aggregate of the class, or a list cut to a few entries, so that a class of
100,000 costs a few passes over its verdict rows and a few arrays of floats. Verdict kinds are read
generically: every kind of :data:`~grader.grade.grading.VERDICTS` is counted, in the order of
:data:`SHOWN_ORDER` (kinds grading does not have yet are left out), and a row's diagnosis is read by
:func:`diagnosis`, by field name.

>>> from grader.grade.key import Key, KeyPart, KeyProblem, KeyStudent
>>> tol = {"mode": "rtol", "rtol": 0.01, "atol": 0.0}
>>> def student(id, e):
...     part = KeyPart("1", "e", "1a", 0.5, "", 2.0, tol, None, {})
...     return KeyStudent(id, f"Student {id}", "", "1", {"1a": part}, (("1", "h"),), (e,))
>>> key = Key("key.json", 2, "HW", True, (KeyProblem("1", "Drop", ("1a",)),), (student("a", 1.0), student("b", 2.0)))
>>> from grader.grade.grading import Row
>>> row = lambda kind, credit: Row("0.5", kind, credit, 2.0, "0.5", "0.5", "", None, None, "±1 %", "", "", "a.csv:2")
>>> graded = Graded(key, {"1a": [row("correct", 1.0), row("invalid", 0.0)]}, (), (), ())
>>> summary = summarize(graded)
>>> summary.percent.tolist(), summary.parts[0].counts["invalid"], summary.parts[0].tolerances
([100.0, 0.0], 1, (('±1 %', 2),))
>>> [(p.name, p.values.tolist()) for p in summary.problems[0].parameters]
[('h', [1.0, 2.0])]
>>> [(s.id, [(c.label, c.submitted) for c in cells]) for s, cells in summary.invalid]
[('b', [('1a', '0.5')])]
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from itertools import repeat
from operator import is_

import numpy as np
import numpy.typing as npt

from grader.grade.class_grades import ClassGrades, Outcomes, classwide
from grader.grade.grading import VERDICTS, Graded
from grader.grade.key import Key, KeyStudent
from grader.grade.row_problems import RowProblem
from grader.model.tolerance import Tolerance, Widening, widening

Floats = npt.NDArray[np.float64]

SHOWN_ORDER = ("correct", "ecf", "mistake", "incorrect", "invalid", "missing")
"""The order the report shows verdict kinds in; a kind grading has that is not here comes after them."""

HARD_DROP = 0.10  # a parameter's bin is hard when its mean is this far below the problem's (and clearly so)
HARD_STUDENTS = 5  # ... and it holds at least this many students
MAX_BINS = 12  # a parameter with at most this many values gets a bin per value
DRAWN_UP_TO = 1e300  # a parameter reaching beyond ±this is not drawn: a figure's axis overflows near float64's limit
TOP_MISTAKES = 5  # diagnosed mistakes listed per part
INVALID_STUDENTS = 50  # students listed with the answers that could not be read; the rest are counted
NOT_GRADED_SHOWN = 5  # submitted rows not graded named in the report's header; problems.csv lists them all

def shown_kinds(kinds: Sequence[str] = VERDICTS) -> tuple[str, ...]:
    """The verdict kinds the report shows, in its order.

    >>> shown_kinds(("missing", "correct", "late", "incorrect"))
    ('correct', 'incorrect', 'missing', 'late')
    """
    return (*(kind for kind in SHOWN_ORDER if kind in kinds), *(kind for kind in kinds if kind not in SHOWN_ORDER))


@dataclass(frozen=True)
class PartSummary:
    """One part over the class: how many verdicts of each kind, the mean score, and how it was graded."""

    label: str
    problem: str  # the problem's key
    name: str  # the answer's name in the template (``v_out``)
    unit: str
    points: tuple[float, ...]  # the distinct points it is worth (one, unless the key was edited)
    counts: dict[str, int]  # by verdict kind, every kind shown (0 too)
    mean_credit: float  # 0..1 over every student of the key
    tolerances: tuple[tuple[str, int], ...]  # each tolerance as configured, in words, with how many verdicts it decided
    widened: Widening | None  # the verdicts decided by a tolerance widened for rounding, and the widest
    mistakes: tuple[tuple[str, int], ...]  # the most frequent diagnoses, with their counts
    diagnosed: int  # verdicts with a diagnosis in all
    says: dict[str, str] = field(default_factory=dict)  # each of those mistakes in words, where grading knew them

    @property
    def students(self) -> int:
        """How many students the part was graded for."""
        return sum(self.counts.values())


@dataclass(frozen=True)
class ParameterBin:
    """The students whose parameter lies in ``[low, high]`` (the least and greatest of their values), and
    how they did."""

    low: float
    high: float
    students: int
    mean: float  # their mean share of the problem's points, 0..1
    error: float  # its standard error (0 for fewer than 2 students)


@dataclass(frozen=True)
class Parameter:
    """A printed parameter of a problem, against the problem's score."""

    name: str
    values: Floats  # per student of the key (NaN: none in the key)
    bins: tuple[ParameterBin, ...]  # over the students who attempted the problem
    unit: str = ""  # as printed on the sheets ("": none, or a key that does not record it)

    @property
    def axis(self) -> str:
        """The parameter as a figure's axis names it: its name and unit.

        >>> Parameter("h_drop", np.array([1.0]), (), "mm").axis, Parameter("e", np.array([1.0]), ()).axis
        ('h_drop (mm)', 'e')
        """
        return f"{self.name} ({self.unit})" if self.unit else self.name

    @property
    def drawable(self) -> bool:
        """Whether a figure can scale to its values: every bin within ±:data:`DRAWN_UP_TO`.

        >>> Parameter("h", np.array([2.0, 1.6e308]), binned(np.array([2.0, 1.6e308]), np.ones(2))).drawable
        False
        """
        return all(part.low >= -DRAWN_UP_TO and part.high <= DRAWN_UP_TO for part in self.bins)


@dataclass(frozen=True)
class ProblemSummary:
    """One problem: each student's share of its points (0..1), who tried it, and the printed parameters."""

    key: str
    title: str
    labels: tuple[str, ...]
    score: Floats  # per student of the key
    attempted: npt.NDArray[np.bool_]  # not every part missing
    parameters: tuple[Parameter, ...]

    @property
    def mean(self) -> float:
        """The mean share of the points of the students who attempted the problem (0 when nobody did)."""
        return float(self.score[self.attempted].mean()) if self.attempted.any() else 0.0

    @property
    def drawn(self) -> tuple[Parameter, ...]:
        """The parameters its figure shows: those that vary and that a figure can scale to."""
        return tuple(p for p in self.parameters if len(p.bins) > 1 and p.drawable)

    def hard_corners(self) -> list[tuple[Parameter, ParameterBin]]:
        """Where a parameter's bin scored clearly below the problem (:func:`is_hard`), lowest first."""
        mean = self.mean
        found = [(parameter, part) for parameter in self.parameters for part in parameter.bins if is_hard(part, mean)]
        return sorted(found, key=lambda item: (item[1].mean, item[0].name, item[1].low))


@dataclass(frozen=True)
class InvalidCell:
    """An answer that could not be read."""

    label: str
    submitted: str
    reason: str


@dataclass(frozen=True)
class ClassSummary:
    """The whole class: see the module's docstring."""

    key: Key
    kinds: tuple[str, ...]
    percent: Floats  # each student's score, as a percentage of what they could earn
    submitted: int  # students with at least one answer
    parts: tuple[PartSummary, ...]
    problems: tuple[ProblemSummary, ...]
    invalid: tuple[tuple[KeyStudent, tuple[InvalidCell, ...]], ...]  # the first INVALID_STUDENTS
    invalid_students: int  # in all
    rows_not_graded: int
    not_graded: tuple[RowProblem, ...]  # the first NOT_GRADED_SHOWN of those rows, each with its reason
    notes: tuple[str, ...]


def summarize(graded: Graded | ClassGrades) -> ClassSummary:
    """The report's aggregates of a grading run."""
    graded = classwide(graded)
    key = graded.key
    count = len(key.students)
    kinds = shown_kinds(tuple(dict.fromkeys((*VERDICTS, *_kinds_found(graded)))))
    scores: dict[str, Floats] = {}
    points: dict[str, Floats] = {}
    missing: dict[str, npt.NDArray[np.bool_]] = {}
    parts = []
    invalid: set[int] = set()  # students with an answer that could not be read
    answered = np.zeros(count, dtype=bool)
    for problem in key.problems:
        for label in problem.labels:
            column = graded.columns[label]
            worth = column.worth()
            scores[label] = column.scores()
            points[label] = worth
            missing[label] = column.verdict.are("missing")
            answered |= column.submitted.given
            parts.append(_part(graded, problem.key, label, column, scores[label], worth, kinds,
                               key.part_entries(label, "tolerance")))
            if parts[-1].counts.get("invalid"):
                invalid.update(np.flatnonzero(column.verdict.are("invalid")).tolist())
    possible = sum(points.values(), np.zeros(count))
    earned = sum(scores.values(), np.zeros(count))
    percent = np.divide(100.0 * earned, possible, out=np.zeros(count), where=possible > 0)
    not_graded = [problem for problem in graded.problems if problem.not_graded]
    return ClassSummary(key, kinds, percent, int(answered.sum()), tuple(parts),
                        _problems(key, scores, points, missing), _invalid(graded, sorted(invalid)[:INVALID_STUDENTS]),
                        len(invalid), sum(problem.rows for problem in not_graded),
                        tuple(problem for problem in not_graded if problem.rows == 1)[:NOT_GRADED_SHOWN], graded.notes)


def _kinds_found(graded: ClassGrades) -> set[str]:
    """Kinds in the verdicts that :data:`VERDICTS` does not name (none, unless grading and VERDICTS disagree)."""
    return {kind for column in graded.columns.values() for kind in column.verdict.counted()} - set(VERDICTS)


def _part(graded: ClassGrades, problem: str, label: str, column: Outcomes, scores: Floats, worth: Floats,
          kinds: tuple[str, ...], rules: Sequence[Mapping[str, object]]) -> PartSummary:
    key = graded.key
    found = column.verdict.counted()
    mistakes = Counter(column.diagnosis.values(column.verdict.are("mistake")))  # ecf rows name their part
    first = key.students[0].parts[label] if key.students else None
    credit = float(scores.sum() / worth.sum()) if worth.sum() > 0 else 0.0
    top = _by_count(mistakes)[:TOP_MISTAKES]
    says = {mistake: graded.mistakes[label, mistake] for mistake, _ in top if (label, mistake) in graded.mistakes}
    return PartSummary(label, problem, first.name if first else "", first.unit if first else "",
                       tuple(sorted(set(worth.tolist()))), {kind: found.get(kind, 0) for kind in kinds}, credit,
                       *_tolerances(rules, column), top, sum(mistakes.values()), says)


def _tolerances(rules: Sequence[Mapping[str, object]],
                column: Outcomes) -> tuple[tuple[tuple[str, int], ...], Widening | None]:
    """The tolerances in words of the part's verdicts that were not widened, with their counts; and the
    :class:`~grader.model.tolerance.Widening` of those that were, from each student's tolerance as the key has
    it, ``rules`` (the key's parts share one mapping for equal tolerances, so each distinct one is read once)."""
    if rules and all(map(is_, rules, repeat(rules[0]))):  # one mapping for the class (most parts): no counting
        counted = [(Tolerance.from_json(rules[0]), len(rules))]
    else:
        distinct = dict(zip(map(id, rules), rules, strict=True))
        counted = [(Tolerance.from_json(distinct[found]), count) for found, count in Counter(map(id, rules)).items()]
    widened = {rule.explained() for rule, _ in counted if rule.reason}  # the words grading gave them
    words = column.tolerance.counted()
    return _by_count(Counter({text: count for text, count in words.items() if text not in widened})), \
        widening(counted)


def _by_count(found: Counter[str]) -> tuple[tuple[str, int], ...]:
    """Most frequent first; equal counts in the order of the text, so that reruns agree."""
    return tuple(sorted(found.items(), key=lambda item: (-item[1], item[0])))


def _invalid(graded: ClassGrades,
             students: list[int]) -> tuple[tuple[KeyStudent, tuple[InvalidCell, ...]], ...]:
    """The students (their indices in the key) with the answers of theirs that could not be read."""
    found: dict[int, list[InvalidCell]] = {index: [] for index in students}
    for label in graded.key.labels:
        column = graded.columns[label]
        invalid = column.verdict.are("invalid")
        mine = [index for index in students if invalid[index]]
        for index, typed, said in zip(mine, column.submitted.take(mine), column.feedback.take(mine), strict=True):
            found[index].append(InvalidCell(label, "" if typed is None else typed,
                                            str(said).removeprefix("could not read this answer: ")))
    return tuple((graded.key.students[index], tuple(cells)) for index, cells in found.items())


def _problems(key: Key, scores: dict[str, Floats], points: dict[str, Floats],
              missing: dict[str, npt.NDArray[np.bool_]]) -> tuple[ProblemSummary, ...]:
    count = len(key.students)
    parameters = key.parameter_columns.items()
    found = []
    for problem in key.problems:
        earned = sum((scores[label] for label in problem.labels), np.zeros(count))
        possible = sum((points[label] for label in problem.labels), np.zeros(count))
        share = np.divide(earned, possible, out=np.zeros(count), where=possible > 0)
        attempted = np.zeros(count, dtype=bool)
        for label in problem.labels:
            attempted |= ~missing[label]
        mine = tuple(Parameter(name, values, binned(values[attempted], share[attempted]), problem.units.get(name, ""))
                     for (owner, name), values in parameters if owner == problem.key)
        found.append(ProblemSummary(problem.key, problem.title, problem.labels, share, attempted, mine))
    return tuple(found)


def binned(values: Floats, score: Floats) -> tuple[ParameterBin, ...]:
    """The scores grouped by parameter value: a bin per value where there are few, else equal widths
    (3 to 12 of them, more for a bigger class); empty bins and students without the parameter left out.

    >>> [(b.low, b.high, b.students, b.mean) for b in binned(np.array([1.0, 1, 2, 2]), np.array([1.0, 0, 1, 1]))]
    [(1.0, 1.0, 2, 0.5), (2.0, 2.0, 2, 1.0)]
    >>> [(b.low, b.high, b.students) for b in binned(np.arange(20.0), np.ones(20))]
    [(0.0, 6.0, 7), (7.0, 12.0, 6), (13.0, 19.0, 7)]
    """
    known = np.isfinite(values)
    values, score = values[known], score[known]
    distinct = np.unique(values)
    if len(distinct) <= MAX_BINS:
        count = len(distinct)
        which = np.searchsorted(distinct, values)
    else:
        count = int(np.clip(np.sqrt(len(values)) / 2, 3, MAX_BINS))
        cuts = _cuts(float(distinct[0]), float(distinct[-1]), count)
        which = np.clip(np.searchsorted(cuts, values, side="right") - 1, 0, count - 1)
    students = np.bincount(which, minlength=count)
    sums = np.bincount(which, weights=score, minlength=count)
    squares = np.bincount(which, weights=score * score, minlength=count)
    lows, highs = np.full(count, np.inf), np.full(count, -np.inf)
    np.minimum.at(lows, which, values)
    np.maximum.at(highs, which, values)
    found = []
    for low, high, size, total, square in zip(lows.tolist(), highs.tolist(), students.tolist(), sums.tolist(),
                                              squares.tolist(), strict=True):
        if size:
            mean = total / size
            variance = max(square - size * mean * mean, 0.0) / (size - 1) if size > 1 else 0.0
            found.append(ParameterBin(low, high, size, mean, (variance / size) ** 0.5))
    return tuple(found)


def _cuts(low: float, high: float, count: int) -> Floats:
    """``count`` equal widths from ``low`` to ``high``, whose span may be beyond float64 (-1e308 to 1e308).

    >>> _cuts(-1.5e308, 1.5e308, 2).tolist()
    [-1.5e+308, 0.0, 1.5e+308]
    """
    if np.isfinite(high - low):
        return np.linspace(low, high, count + 1)
    return np.linspace(low / 2, high / 2, count + 1) * 2


def is_hard(part: ParameterBin, mean: float) -> bool:
    """Whether a bin scored clearly below the problem's ``mean``: by :data:`HARD_DROP` at least and by
    more than twice its standard error, with :data:`HARD_STUDENTS` students at least.

    >>> is_hard(ParameterBin(1, 2, 10, 0.5, 0.05), 0.8), is_hard(ParameterBin(1, 2, 10, 0.5, 0.2), 0.8)
    (True, False)
    """
    return part.students >= HARD_STUDENTS and mean - part.mean >= max(HARD_DROP, 2 * part.error)
