"""The tolerance each variant's answer gets: what is configured, or what honest rounding needs.

A student who follows a solution route (:mod:`grader.solve.routes`), keeps
``grading.intermediate_sig_figs`` significant figures in every value written down and gives the
answer to three, must be marked right. Their answer can be off the key by the route's rounding bound
``S`` plus half a unit in the answer's third figure ``h``; the variant needs a band of at least
``2 S + h`` (the factor 2 covers first order's error and the key's own rounding-free value; ``h`` is
exact). Where the configured band is narrower, the ``rtol`` is widened to it (rounded up to two
figures) and the tolerance carries the reason; an answer with only an ``atol`` (``rtol`` 0) gets a
wider ``atol``. A variant whose widened tolerance would pass ``grading.max_tolerance`` (relative to
its answer) is redrawn like a degenerate one. Tolerances in ``sigfigs`` and ``decimals`` modes are
the instructor's statement of what is accepted and are kept as set, neither widened nor capped.

>>> widened(0.01234), widened(0.027), widened(0.0100000001)
(0.013, 0.027, 0.011)
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from grader.model.quantities import half_unit
from grader.model.tolerance import ANSWER_SIG_FIGS, Tolerance, with_unit
from grader.solve.routes import Moves, Routes, rounding_bounds

SAFETY = 2.0
"""How many times the first-order rounding bound a tolerance allows."""


def widened(rtol: float) -> float:
    """A needed tolerance rounded up to two significant figures (a figure the key can print)."""
    if rtol <= 0:
        return 0.0
    step = 10.0 ** (math.floor(math.log10(rtol)) - 1)
    return round(math.ceil(rtol / step * (1 - 1e-12)) * step, 12)


@dataclass(frozen=True)
class Capped:
    """Why a variant's widened tolerance passes the cap: the ``answer``, the route whose rounding moves it most
    (``route``, as a reason says it: ``the worked solution``), the values written down that move it most
    (``moved_by``), and the relative tolerance it would need (``needed``, a fraction)."""

    answer: str
    route: str
    moved_by: str
    needed: float


@dataclass(frozen=True)
class Fair:
    """Per answer and parameter set: the tolerance (``tolerances[name][row]``), and per row why the
    variant must be redrawn (``flaws[row]``, None if it need not) and, when it is the cap, which answer and
    route pass it (``capped[row]``)."""

    tolerances: Mapping[str, list[Tolerance]]
    flaws: list[str | None]
    capped: list[Capped | None]


def fair_tolerances(routes: Routes, configured: Mapping[str, Tolerance], units: Mapping[str, str],
                    params: Mapping[str, Any], values: Mapping[str, Any], answered: Any, figures: int,
                    cap: float) -> Fair:
    """The tolerance of every answer of every parameter set (``values``: the key's answers; ``answered``:
    whether each row has a value for each answer, ``answered[name][row]``)."""
    size = len(next(iter(params.values()))) if params else 0

    def short(name: str, bound: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """What honest rounding needs of the answer, and where the configured band is narrower (or it is NaN)."""
        tolerance, value = configured[name], np.asarray(values[name], dtype=float)
        needed: np.ndarray = SAFETY * bound + half_unit(value, ANSWER_SIG_FIGS)
        with np.errstate(invalid="ignore"):
            return needed, ~(needed <= tolerance.atol + tolerance.rtol * np.abs(value))

    def doubtful(name: str, bound: np.ndarray) -> Any:
        if name not in values or configured[name].mode != "rtol":
            return np.zeros(size, dtype=bool)
        return short(name, bound)[1]

    moves = rounding_bounds(routes, params, figures, doubtful)
    flaws: list[str | None] = [None] * size
    capped: list[Capped | None] = [None] * size
    tolerances: dict[str, list[Tolerance]] = {}
    for name, tolerance in configured.items():
        tolerances[name] = [tolerance] * size
        if name not in moves or tolerance.mode != "rtol":
            continue
        needed, wider = short(name, moves[name].bound)
        value = np.asarray(values[name], dtype=float)
        for row in np.flatnonzero(wider & np.asarray(answered[name], dtype=bool)):
            tolerances[name][row], flaw, passed = _widen(name, tolerance, float(value[row]), float(needed[row]),
                                                         moves[name], routes, int(row), units[name], figures, cap)
            if flaws[row] is None:
                flaws[row], capped[row] = flaw, passed
    return Fair(tolerances, flaws, capped)


def _widen(name: str, tolerance: Tolerance, value: float, needed: float, moves: Moves, routes: Routes, row: int,
           unit: str, figures: int, cap: float) -> tuple[Tolerance, str | None, Capped | None]:
    """The widened tolerance of one answer, why the variant must be redrawn (or None), and, when that is the
    cap, what passes it."""
    if not math.isfinite(needed):
        return tolerance, (f"answer {name}: how far rounding along a solution route moves it cannot be bounded here "
                           "(a step of the route is not finite)"), None
    absolute = tolerance.rtol == 0 and tolerance.atol > 0
    if value == 0:  # no relative band fits; an atol that rounding overruns at 0 cannot be capped relatively
        return tolerance, f"answer {name} is 0 and rounding along a solution route moves it more than its tolerance", \
            None
    moved_by, route = _moved_by(moves, routes, row)
    bound = float(moves.bound[row])
    # Relative, as the tolerance it explains; a band in the answer's unit (an atol) is explained in that unit.
    moved = with_unit(f"{bound:.2g}", unit) if absolute else f"{bound / abs(value) * 100:.2g} %"
    reason = f"rounding {moved_by} to {figures} figures along {route} moves {name} by up to {moved}"
    if absolute:
        wide = Tolerance(rtol=0.0, atol=widened(needed), reason=reason)
    else:
        wide = Tolerance(rtol=widened((needed - tolerance.atol) / abs(value)), atol=tolerance.atol, reason=reason)
    if wide.atol + wide.rtol * abs(value) > cap * abs(value):
        return tolerance, (f"answer {name} = {value:.4g} would need {wide.describe(unit)} to allow for rounding "
                           f"({reason}), more than grading.max_tolerance (±{cap * 100:g} %)"), \
            Capped(name, route, moved_by, wide.rtol + wide.atol / abs(value))
    return wide, None, None


def _moved_by(moves: Moves, routes: Routes, row: int) -> tuple[str, str]:
    """The values written down that move an answer most along the route that moves it most (``T and T′``), and
    that route as a reason says it (``the energy route``)."""
    index = int(moves.route[row])
    route = routes.items[index]
    shares = moves.shares[index][:, row]
    total = float(np.nansum(shares))
    named = [display_name(n) for n, share in zip(route.names, shares, strict=True)
             if total > 0 and share >= 0.2 * total][:4] or [display_name(n) for n in route.names[-1:]]
    return named[0] if len(named) == 1 else ", ".join(named[:-1]) + f" and {named[-1]}", route.says


def display_name(name: str) -> str:
    """A value's name as the reason prints it: ``T_after`` is ``T′``.

    >>> display_name("T_after"), display_name("v1_n_after"), display_name("J")
    ('T′', 'v1_n′', 'J')
    """
    return name[: -len("_after")] + "′" if name.endswith("_after") else name
