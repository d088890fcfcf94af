"""The adaptive method's stepper: the embedded 8(5,3) Dormand-Prince pair of ``scipy.integrate.solve_ivp``
(``method="DOP853"``), step for step, with its terminal event located on the same 7th-order interpolant.

``solve_ivp`` spends most of a short integration (a contact of a few steps) on its own generality: wrappers
around every call of the right-hand side, event bookkeeping for many events, a solution object. A mode has one
state vector, one terminal event and needs only the states at its steps, so this module takes the same steps
with the same coefficients, the same step-size control and the same event location, and leaves the rest out:
the states agree with ``solve_ivp``'s to the last bit (``tests/test_simulate.py`` checks it).

>>> import numpy as np
>>> def fall(t, y):
...     return np.array([y[1], -9.81])
>>> def ground(t, y):
...     return y[0]
>>> run = integrate(fall, 0.0, 10.0, np.array([2.0, 0.0]), 1e-10, 1e-10, ground, -1)
>>> run.status, round(run.t[-1], 6), round(float(-run.y[-1][1]), 6)  # lands after sqrt(2 h/g), at sqrt(2 g h)
(1, 0.638551, 6.264184)
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.integrate._ivp import dop853_coefficients as tableau  # the coefficients solve_ivp's DOP853 uses

STAGES = tableau.N_STAGES
A, B, C = tableau.A[:STAGES, :STAGES], tableau.B, tableau.C[:STAGES]
ROWS = [(s, A[s, :s], float(C[s])) for s in range(1, STAGES)]  # each stage's weights of the ones before, its time
E3, E5, D = tableau.E3, tableau.E5, tableau.D
A_EXTRA, C_EXTRA = tableau.A[STAGES + 1:], tableau.C[STAGES + 1:]
SAFETY, MIN_FACTOR, MAX_FACTOR = 0.9, 0.2, 10.0  # scipy's step-size control
EXPONENT = -1 / 8  # -1/(error estimator order + 1)
EPS = float(np.finfo(float).eps)
TOO_SMALL = "Required step size is less than spacing between numbers."

Rhs = Callable[[float, Any], Any]


@dataclass
class Integration:
    """The accepted steps' times and states (the first the start), how it ended (0: at ``t_bound``, 1: at the
    event, -1: failed, with ``message``)."""

    t: list[float] = field(default_factory=list)
    y: list[Any] = field(default_factory=list)
    status: int = 0
    message: str = ""


def _norm(x: Any) -> float:
    """The RMS norm (scipy's ``norm``: ``np.linalg.norm(x)/sqrt(size)``, a real vector's being ``sqrt(x . x)``)."""
    return math.sqrt(float(x.dot(x))) / float(x.size ** 0.5)


def _first_step(fun: Rhs, t0: float, y0: Any, t_bound: float, f0: Any, rtol: float, atol: float) -> float:
    """scipy's ``select_initial_step`` (Hairer, Norsett and Wanner, II.4) for order 7, forward in time."""
    interval = abs(t_bound - t0)
    if interval == 0.0:
        return 0.0
    scale = atol + np.abs(y0) * rtol
    d0, d1 = _norm(y0 / scale), _norm(f0 / scale)
    h0 = 1e-6 if d0 < 1e-5 or d1 < 1e-5 else 0.01 * d0 / d1
    h0 = min(h0, interval)
    f1 = fun(t0 + h0, y0 + h0 * f0)
    d2 = _norm((f1 - f0) / scale) / h0
    h1 = max(1e-6, h0 * 1e-3) if d1 <= 1e-15 and d2 <= 1e-15 else (0.01 / max(d1, d2)) ** (1 / 8)
    return min(100 * h0, h1, interval)


def _error_norm(stages: Any, h: float, scale: Any) -> float:
    err5 = np.dot(stages.T, E5) / scale
    err3 = np.dot(stages.T, E3) / scale
    err5_2, err3_2 = math.sqrt(float(err5.dot(err5))) ** 2, math.sqrt(float(err3.dot(err3))) ** 2  # as scipy's
    if err5_2 == 0 and err3_2 == 0:
        return 0.0
    return abs(h) * err5_2 / math.sqrt((err5_2 + 0.01 * err3_2) * len(scale))


def _interpolant(fun: Rhs, stages: Any, t_old: float, h: float, y_old: Any, y: Any, f: Any) -> Callable[[float], Any]:
    """The step's 7th-order dense output (three more evaluations), as scipy's ``Dop853DenseOutput``."""
    for s, (a, c) in enumerate(zip(A_EXTRA, C_EXTRA, strict=True), start=STAGES + 1):
        stages[s] = fun(t_old + c * h, y_old + np.dot(stages[:s].T, a[:s]) * h)
    delta = y - y_old
    rows = np.empty((tableau.INTERPOLATOR_POWER, len(y)))
    rows[0], rows[1], rows[2] = delta, h * stages[0] - delta, 2 * delta - h * (f + stages[0])
    rows[3:] = h * np.dot(D, stages)
    rows = rows[::-1]

    def at(t: float) -> Any:
        x = (t - t_old) / h
        value = np.zeros_like(y_old)
        for i, row in enumerate(rows):
            value += row
            value *= x if i % 2 == 0 else 1 - x
        return value + y_old

    return at


def _crossed(before: float, after: float, direction: int) -> bool:
    """scipy's ``find_active_events`` for one event."""
    up, down = before <= 0 <= after, before >= 0 >= after
    return (up and direction > 0) or (down and direction < 0) or ((up or down) and direction == 0)


def integrate(fun: Rhs, t0: float, t_bound: float, y0: Any, rtol: float, atol: float,
              event: Callable[[float, Any], float] | None = None, direction: int = 0,
              stepped: Callable[[], None] | None = None) -> Integration:
    """From ``t0`` to ``t_bound`` (forward), or to the first zero of a terminal ``event`` crossed in
    ``direction``: what ``solve_ivp(fun, (t0, t_bound), y0, method="DOP853", rtol=rtol, atol=atol,
    events=event)`` returns in ``t``, ``y`` and ``status``. ``stepped`` is called after every step taken
    (a budget's clock)."""
    from scipy.optimize import brentq

    t, y = t0, np.asarray(y0, dtype=float)
    run = Integration([t], [y])
    f = fun(t, y)
    h_abs = _first_step(fun, t, y, t_bound, f, rtol, atol)
    k = np.empty((tableau.N_STAGES_EXTENDED, len(y)))  # the stages' slopes, as scipy's K
    g = event(t, y) if event is not None else 0.0
    while t != t_bound:
        min_step = 10 * abs(np.nextafter(t, np.inf) - t)
        h_abs = max(h_abs, min_step)
        rejected = False
        while True:
            if h_abs < min_step:
                run.status, run.message = -1, TOO_SMALL
                return run
            t_new = min(t + h_abs, t_bound)
            h = t_new - t
            h_abs = abs(h)
            k[0] = f
            for s, weights, c in ROWS:
                k[s] = fun(t + c * h, y + np.dot(k[:s].T, weights) * h)
            y_new = y + h * np.dot(k[:STAGES].T, B)
            f_new = fun(t + h, y_new)
            k[STAGES] = f_new
            error = _error_norm(k[:STAGES + 1], h, atol + np.maximum(np.abs(y), np.abs(y_new)) * rtol)
            if error < 1:
                factor = MAX_FACTOR if error == 0 else min(MAX_FACTOR, SAFETY * error ** EXPONENT)
                h_abs *= min(1.0, factor) if rejected else factor
                break
            h_abs *= max(MIN_FACTOR, SAFETY * error ** EXPONENT)
            rejected = True
        if stepped is not None:
            stepped()
        t_old, y_old, t, y, f = t, y, t_new, y_new, f_new
        if event is not None:
            g_new = event(t, y)
            if _crossed(g, g_new, direction):
                at = _interpolant(fun, k, t_old, h, y_old, y, f)
                root = brentq(lambda s, at=at: event(s, at(s)), t_old, t, xtol=4 * EPS, rtol=4 * EPS)
                run.t.append(float(root))
                run.y.append(at(root))
                run.status = 1
                return run
            g = g_new
        run.t.append(t)
        run.y.append(y)
    return run
