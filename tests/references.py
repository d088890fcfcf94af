"""What the bank's template tests share: answers checked against a reference the test computes itself
(exact fractions, or mpmath at 60 digits, the float inputs taken as exact), never by the solver."""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from fractions import Fraction
from typing import Any

import mpmath as mp

from grader.solve.evaluate import solve_one

RTOL = 1e-9


def check(bank: Mapping[str, Any], compiled: Mapping[str, Any], template_id: str, params: Mapping[str, float],
          reference: Callable[..., Mapping[str, Any]]) -> None:
    """Every answer within RTOL of ``reference(**params)``: a Fraction or an mpf, an exact zero exactly
    (or below 1e-300), and None for an answer that is undefined (the solver must say why)."""
    solution = solve_one(bank[template_id], compiled[template_id], params)
    assert solution.answers is not None, solution.error
    with mp.workdps(60):
        failures = []
        for name, expected in reference(**params).items():
            answer = solution.answers[name]
            if expected is None:
                ok = answer.value is None and bool(answer.undefined)
            else:
                got = answer.value
                assert isinstance(got, float) and math.isfinite(got), (name, answer)
                error = abs(Fraction(got) - expected) if isinstance(expected, Fraction) else abs(mp.mpf(got) - expected)
                ok = abs(got) <= 1e-300 if expected == 0 else error / abs(expected) <= RTOL
            if not ok:
                failures.append(f"{name}: got {answer.value!r}, reference {expected and float(expected)!r}")
    assert not failures, f"{template_id} {params}: " + "; ".join(failures)


def check_known(bank: Mapping[str, Any], compiled: Mapping[str, Any], template_id: str, params: Mapping[str, float],
                answers: Mapping[str, float], reference: Callable[..., Mapping[str, Any]]) -> None:
    """The answers worked by hand to four figures, and every answer within RTOL of the reference."""
    solution = solve_one(bank[template_id], compiled[template_id], params)
    assert solution.answers is not None, solution.error
    assert {n: float(f"{solution.answers[n].value:.4g}") for n in answers} == answers
    check(bank, compiled, template_id, params, reference)
