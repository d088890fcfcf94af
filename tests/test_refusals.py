"""Physically invalid input is refused with the reason; nothing NaN or infinite is answered."""

from __future__ import annotations

import pytest
import yaml

from grader.bank.template import Template, parse_template
from grader.solve.compiled import Compiled
from grader.solve.evaluate import solve_one
from grader.solve.solver import compile_template
from tests.scenes import TWO_BODIES

REFUSALS = [
    ("ball-plate", {"v": 50, "theta": 30, "e": 1.2}, "e = 1.2 is outside its domain [0, 1]"),
    ("ball-plate", {"v": 50, "theta": 30, "e": -0.1}, "e = -0.1 is outside its domain [0, 1]"),
    ("car-collision", {"p": 0.5, "e": 1.01}, "e = 1.01 is outside its domain [0, 1]"),
    ("drop-rebound", {"h_drop": 1000, "h_rebound": 1001},
     "constraint h_rebound <= h_drop fails: the ball cannot bounce higher than it was dropped from"),
    ("pile-driver", {"m_ram": 800, "m_pile": 2400, "h_drop": 1, "h_rebound": 1.5},
     "constraint h_rebound < h_drop fails: the ram cannot bounce back higher than it fell"),
    # s = sqrt(0.5/2) = 0.5; e = (m_ram/m_pile)(1 + s) + s = 2*1.5 + 0.5 = 3.5
    ("pile-driver", {"m_ram": 2000, "m_pile": 1000, "h_drop": 2, "h_rebound": 0.5},
     "the coefficient of restitution is 3.5; above 1 the impact would create energy"),
    ("oblique-spheres", {"v1": 6, "theta": 30, "e": 0.6, "m1": 0, "m2": 1}, "m1 = 0 kg is outside its domain (0, inf)"),
    ("oblique-spheres", {"v1": 6, "theta": 30, "e": 0.6, "m1": 1, "m2": -2}, "m2 = -2 kg is outside its domain"),
    ("pile-driver", {"m_ram": -800, "m_pile": 2400, "h_drop": 2, "h_rebound": 0.1}, "m_ram = -800 kg is outside"),
    ("ball-plate", {"v": 50, "theta": 0, "e": 0.5}, "theta = 0 deg is outside its domain (0, 90]"),
    ("ball-plate", {"v": 50, "theta": 95, "e": 0.5}, "theta = 95 deg is outside its domain (0, 90]"),
    ("oblique-spheres", {"v1": 6, "theta": 90, "e": 0.6, "m1": 1, "m2": 1},
     "theta = 90 deg is outside its domain [0, 90)"),
    ("ball-plate", {"v": float("nan"), "theta": 30, "e": 0.5}, "v is not a finite number"),
    ("ball-plate", {"v": float("inf"), "theta": 30, "e": 0.5}, "v is not a finite number"),
]


@pytest.mark.parametrize(("template_id", "params", "reason"), REFUSALS, ids=[f"{t}:{r[:30]}" for t, _, r in REFUSALS])
def test_invalid_parameters_are_refused_with_the_reason(template_id: str, params: dict[str, float], reason: str,
                                                        bank: dict[str, Template],
                                                        compiled: dict[str, Compiled]) -> None:
    """The refusal says which value breaks which rule; no answers are given."""
    solution = solve_one(bank[template_id], compiled[template_id], params)
    assert solution.answers is None
    assert solution.error is not None and solution.error.startswith(reason)




@pytest.fixture(scope="module")
def two_bodies() -> tuple[Template, Compiled]:
    raw = yaml.safe_load(TWO_BODIES)
    raw["answers"]["square"] = {"value": "u1*u1*a2", "unit": "m^3/s^3"}  # overflows where a1, a2 do not
    template = parse_template(raw, "test:two-bodies", "two-bodies")
    return template, compile_template(template)


def test_separating_bodies_are_refused(two_bodies: tuple[Template, Compiled]) -> None:
    """A first body slower than the second along n never reaches it."""
    template, compiled = two_bodies
    solution = solve_one(template, compiled, {"m1": 1, "m2": 1, "u1": 1, "u2": 2, "e": 0.5})
    assert solution.error == ("a and b are not approaching along the line of impact "
                              "(relative normal velocity <= 0), so they do not collide")


def test_overflowing_answer_is_refused_not_printed_as_inf(two_bodies: tuple[Template, Compiled]) -> None:
    """An answer beyond float64 is a refusal with the answer's name, never inf or NaN."""
    template, compiled = two_bodies
    solution = solve_one(template, compiled, {"m1": 1, "m2": 1, "u1": 1e200, "u2": -1e200, "e": 0.5})
    assert solution.answers is None
    assert solution.error is not None
    assert solution.error.startswith("answer square: a step of the solution is not a finite number")


def test_refused_rows_do_not_stop_the_others(two_bodies: tuple[Template, Compiled]) -> None:
    """Between two refused rows, a good row is still answered."""
    import numpy as np

    from grader.solve.evaluate import solve_batch

    template, compiled = two_bodies
    table = {"m1": np.array([1.0, 1.0, 0.0]), "m2": np.ones(3), "u1": np.array([1.0, 3.0, 3.0]),
             "u2": np.array([2.0, -1.0, -1.0]), "e": np.full(3, 0.5)}
    solutions = solve_batch(template, compiled, table)
    assert [s.error is None for s in solutions] == [False, True, False]
    # equal masses, e = 0.5: a1 = (u1 + u2)/2 - e (u1 - u2)/2 = 1 - 1 = 0
    assert solutions[1].answers is not None and solutions[1].answers["a1"].value == 0.0
