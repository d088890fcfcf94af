"""Answers for parameter sets: domain and physics checks, then the compiled kernels.

Every set is answered or refused with a reason; one bad set never stops the others, and no NaN
or infinity reaches an answer.

>>> from grader.bank.template import load_bank
>>> from grader.solve.cache import compiled_for
>>> template = load_bank()["drop-rebound"]
>>> solution = solve_one(template, compiled_for(template), {"h_drop": 2100, "h_rebound": 1100})
>>> round(solution.answers["e"].value, 3), round(solution.answers["loss_pct"].value, 1)
(0.724, 47.6)
>>> solve_one(template, compiled_for(template), {"h_drop": 1000, "h_rebound": 1100}).error
'constraint h_rebound <= h_drop fails: the ball cannot bounce higher than it was dropped from'
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

import numpy as np

from grader.bank.template import Template
from grader.model.expr import Node, Num, fold, substitute, to_text
from grader.model.kernel import evaluate
from grader.solve.compiled import Compiled

OVERFLOW = ("a step of the solution is not a finite number for these values (it overflows float64, divides by "
            "zero or leaves the real numbers); expected values for which every step is defined")


@dataclass(frozen=True)
class AnswerValue:
    """One answer: a number, an expression (text) for a symbolic answer, or undefined."""

    name: str
    unit: str
    value: float | str | None
    undefined: str | None = None

    def to_json(self) -> dict[str, Any]:
        """``{"value", "unit"}``, plus ``"undefined": reason`` where there is no value."""
        data: dict[str, Any] = {"value": self.value, "unit": self.unit}
        if self.undefined is not None:
            data["undefined"] = self.undefined
        return data


@dataclass(frozen=True)
class Solution:
    """The answers for one parameter set, or the reason it was refused."""

    template: str
    params: Mapping[str, float]
    answers: Mapping[str, AnswerValue] | None
    error: str | None = None


def solve_one(template: Template, compiled: Compiled, params: Mapping[str, float]) -> Solution:
    """Answers for one parameter set."""
    table = {name: np.array([float(value)]) for name, value in params.items()}
    return solve_batch(template, compiled, table)[0]


@dataclass(frozen=True)
class Columns:
    """Answers for many parameter sets as arrays: ``values[name][row]`` (numeric answers only),
    ``undefined[name][row]`` a reason or None, ``refusals[row]`` a reason or None. Values of
    refused or undefined rows are meaningless and must be read through ``refusals``/``undefined``."""

    params: Mapping[str, Any]
    values: Mapping[str, Any]
    undefined: Mapping[str, list[str | None]]
    refusals: list[str | None]


def solve_columns(template: Template, compiled: Compiled, table: Mapping[str, Any]) -> Columns:
    """Answers for many parameter sets at once, as arrays: ``table`` maps parameters to float arrays."""
    columns = {name: np.asarray(table[name], dtype=float) for name in template.parameters}
    count = len(next(iter(columns.values()))) if columns else 0
    refusals: list[str | None] = [None] * count
    with np.errstate(all="ignore"):
        _check_domains(template, columns, refusals)
        _check_constraints(template, columns, refusals)
        trees = _overflows_again_in_extended_range(compiled, columns, compiled.kernel(columns), count)
        _check_physics(compiled, trees, refusals)
        values, undefined = _numeric_answers(compiled, trees, refusals, count)
    return Columns(columns, values, undefined, refusals)


def _overflows_again_in_extended_range(compiled: Compiled, columns: Mapping[str, Any], trees: Mapping[Any, Any],
                                       count: int) -> Mapping[Any, Any]:
    """``trees``, with the rows where a step is not finite worked out again in numpy's ``longdouble``, whose
    exponent reaches 10**4932 on x86: a subnormal ``p = 1e-309`` is a float64 whose ``1/p`` is not, although
    the answer (``(1/p - e)/(1 + 1/p)``, 1) is ordinary. Where ``longdouble`` is float64 nothing changes; a row
    still not finite in float64 is refused as before.
    """
    if np.finfo(np.longdouble).maxexp <= np.finfo(np.float64).maxexp or not count:
        return trees
    columnar = {key: value for key, value in trees.items() if np.shape(value) == (count,)}
    failing = np.zeros(count, dtype=bool)
    for value in columnar.values():
        if np.asarray(value).dtype.kind == "f":
            failing |= ~np.isfinite(value)
    if not failing.any():
        return trees
    rows = np.flatnonzero(failing)
    again = compiled.kernel({name: np.asarray(column, dtype=np.longdouble)[rows] for name, column in columns.items()})
    redone = dict(trees)
    for key, value in columnar.items():
        if np.shape(again[key]) == rows.shape:
            redone[key] = np.array(value)  # a copy: the kernel's arrays may be its own
            redone[key][rows] = again[key]
    return redone


def solve_batch(template: Template, compiled: Compiled, table: Mapping[str, Any]) -> list[Solution]:
    """Answers for many parameter sets, one :class:`Solution` per set, in order."""
    result = solve_columns(template, compiled, table)
    return [_solution(template, compiled, result, row) for row in range(len(result.refusals))]


def _refuse(refusals: list[str | None], failing: Any, message: Any) -> None:
    for row in np.flatnonzero(failing):
        if refusals[row] is None:
            refusals[row] = message(row) if callable(message) else message


def _check_domains(template: Template, columns: Mapping[str, Any], refusals: list[str | None]) -> None:
    for name, parameter in template.parameters.items():
        values = columns[name]
        unit = f" {parameter.unit.text}" if parameter.unit.text else ""
        _refuse(refusals, ~np.isfinite(values), f"{name} is not a finite number")
        _refuse(refusals, ~parameter.domain.contains(values),
                lambda row, v=values, n=name, p=parameter, u=unit:
                f"{n} = {_show(v[row])}{u} is outside its domain {p.domain}")
        if parameter.integer:
            _refuse(refusals, ~parameter.admits(values), lambda row, v=values, p=parameter: p.not_whole(_show(v[row])))


def _check_constraints(template: Template, env: Mapping[str, Any], refusals: list[str | None]) -> None:
    for constraint in template.constraints:
        holds = evaluate(constraint.holds, env)
        _refuse(refusals, ~np.asarray(holds, dtype=bool),
                f"constraint {constraint.text} fails: {constraint.message}")


def _check_physics(compiled: Compiled, trees: Mapping[Any, Any], refusals: list[str | None]) -> None:
    for index, check in enumerate(compiled.checks):
        holds = np.asarray(trees["holds", index], dtype=bool)
        if check.subject is not None and "{value}" in check.message:
            subject = np.broadcast_to(trees["subject", index], holds.shape)
            _refuse(refusals, ~np.isfinite(subject), OVERFLOW)
            _refuse(refusals, ~holds, lambda row, s=subject, m=check.message: m.replace("{value}", _show(s[row])))
        else:
            _refuse(refusals, ~holds, check.message)


def _numeric_answers(compiled: Compiled, trees: Mapping[Any, Any], refusals: list[str | None],
                     count: int) -> tuple[dict[str, Any], dict[str, list[str | None]]]:
    values: dict[str, Any] = {}
    undefined: dict[str, list[str | None]] = {}
    for name, answer in compiled.answers.items():
        missing: list[str | None] = [None] * count
        for index, rule in enumerate(answer.undefined):
            for row in np.flatnonzero(np.broadcast_to(trees["undefined", name, index], (count,))):
                missing[row] = missing[row] or rule.reason
        undefined[name] = missing
        if answer.numeric is None:
            continue
        value = np.broadcast_to(np.asarray(trees["answer", name], dtype=float), (count,))
        values[name] = value
        bad = ~np.isfinite(value) & np.array([m is None for m in missing])
        _refuse(refusals, bad, f"answer {name}: {OVERFLOW}")
    return values, undefined


def _solution(template: Template, compiled: Compiled, result: Columns, row: int) -> Solution:
    params = {name: float(column[row]) for name, column in result.params.items()}
    if result.refusals[row] is not None:
        return Solution(template.id, params, None, result.refusals[row])
    answers = {name: AnswerValue(name, answer.unit, *answer_at(template, compiled, result, name, row))
               for name, answer in compiled.answers.items()}
    return Solution(template.id, params, answers)


def answer_at(template: Template, compiled: Compiled, result: Columns, name: str,
              row: int) -> tuple[float | str | None, str | None]:
    """One answer of one row of a result: ``(value, None)``, where the value is a number or, for a
    symbolic answer, its text; or ``(None, reason)`` where it is undefined."""
    reason = result.undefined[name][row]
    if reason is not None:
        return None, reason
    symbolic = compiled.answers[name].symbolic
    if symbolic is None:
        return float(result.values[name][row]) + 0.0, None  # -0 is 0
    params = {parameter: float(column[row]) for parameter, column in result.params.items()}
    return symbolic_text(symbolic, params, template.answers[name].symbolic), None


def symbolic_text(tree: Node, params: Mapping[str, float], keep: Sequence[str]) -> str:
    """A symbolic answer as text: the parameters not kept symbolic substituted as exact decimals.

    >>> from grader.model.expr import parse
    >>> symbolic_text(parse("v*(1 - e*p)/(p + 1)"), {"e": 0.1, "p": 0.5}, ["p", "v"])
    'v*(1 - 0.1*p)/(p + 1)'
    """
    numbers: dict[str, Node] = {p: Num(Fraction(repr(v))) for p, v in params.items() if p not in keep}
    return to_text(fold(substitute(tree, numbers)))


def _show(value: float) -> str:
    """A number for a message: 6 significant figures, but never a rounded whole number (a limit
    like 1 or 90) for a value that is not exactly that: 1.0000000000000002 stays visible."""
    value = float(value)
    short = f"{value:.6g}"
    if float(short) != value and float(short).is_integer():
        short = repr(value)
    return short
