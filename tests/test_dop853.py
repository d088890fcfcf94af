"""The adaptive method's own stepper takes solve_ivp's DOP853 steps to the last bit: the same steps, the same
states, the same located event (grader/physics/dop853.py)."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from grader.physics import dop853


def pulse(t: float, y: Any) -> Any:
    return np.array([y[2], y[3], 6 * t * (1 - t), 0.3])


def contact(t: float, y: Any) -> Any:  # a spring and dashpot, e about 0.6
    return np.array([y[1], -(2 * 0.16 * 3 * y[1] + 9 * y[0])])


def swing(t: float, y: Any) -> Any:  # a pendulum: nonlinear
    return np.array([y[1], -9.81 / 1.6 * math.sin(y[0])])


CASES: list[tuple[str, Callable[[float, Any], Any], Any, float, Callable[[float, Any], float] | None, int]] = [
    ("pulse, to the end", pulse, np.array([0.0, 0.0, 1.0, 0.0]), 1.0, None, 0),
    ("contact, until the overlap is gone", contact, np.array([0.0, 1.0]), 10.0, lambda t, y: y[0], -1),
    ("approach, until contact", lambda t, y: np.array([y[1], 0.0]), np.array([-0.25, 1.0]), 10.0,
     lambda t, y: y[0], 1),
    ("fall, to the ground", lambda t, y: np.array([y[1], -9.81]), np.array([2.0, 0.0]), 10.0, lambda t, y: y[0], -1),
    ("swing, to the top", swing, np.array([0.0, 2.0]), 10.0, lambda t, y: y[1], -1),
]


@pytest.mark.parametrize("rtol", [1e-3, 1e-9, 1e-13])
@pytest.mark.parametrize(("name", "fun", "y0", "t_bound", "event", "direction"), CASES, ids=[c[0] for c in CASES])
def test_the_steps_are_solve_ivps_to_the_last_bit(name: str, fun: Callable[[float, Any], Any], y0: Any,
                                                  t_bound: float, event: Callable[[float, Any], float] | None,
                                                  direction: int, rtol: float) -> None:
    if event is not None:
        event.terminal = True  # type: ignore[attr-defined]
        event.direction = direction  # type: ignore[attr-defined]
    want = solve_ivp(fun, (0.0, t_bound), y0, method="DOP853", rtol=rtol, atol=rtol, events=event)
    got = dop853.integrate(fun, 0.0, t_bound, y0, rtol, rtol, event, direction)
    assert got.status == want.status == (0 if event is None else 1)
    assert got.t == list(want.t)
    assert all((a == b).all() for a, b in zip(got.y, want.y.T, strict=True))


def test_a_step_too_small_fails_as_solve_ivp_does() -> None:
    def undefined_beyond_half(t: float, y: Any) -> Any:  # every step across t = 1/2 is rejected
        return np.array([1.0 if t <= 0.5 else math.nan])

    got = dop853.integrate(undefined_beyond_half, 0.0, 2.0, np.array([1.0]), 1e-10, 1e-10)
    want = solve_ivp(undefined_beyond_half, (0.0, 2.0), np.array([1.0]), method="DOP853", rtol=1e-10, atol=1e-10)
    assert got.t == list(want.t)
    assert (got.status, got.message) == (want.status, want.message) == (-1, dop853.TOO_SMALL)
