"""Time integration of a phase as a sequence of modes, each ended by a located event.

A mode is a right-hand side (free flight, contact, ...) and an event function; the mode ends
where the event crosses zero, or, for a mode of known length (a force pulse over a contact time),
at its end, where the integration stops with nothing to locate. Events are located, never
detected by a sign test inside the step: the fixed-step methods find the crossing on their own
partial step, the adaptive method uses ``scipy.integrate.solve_ivp``'s event location. Methods:

- ``euler``: semi-implicit (symplectic) Euler, fixed steps;
- ``rk4``: classical Runge-Kutta, fixed steps;
- ``adaptive``: an embedded 8(5,3) Dormand-Prince pair (``DOP853``) with a relative tolerance.

States are ``[positions..., velocities...]``. An explicit fixed step at or above the stability
limit ``2/omega`` of a mode is refused, never silently blown up.

>>> import numpy as np
>>> fall = Mode("flight", lambda t, y: np.array([y[1], -9.81]), lambda y: y[0], -1, scale=0.64)
>>> path = integrate([fall], np.array([2.0, 0.0]), Settings("rk4", steps=50))
>>> round(float(-path.y[-1][1]), 6)  # speed after falling 2 m: sqrt(2*9.81*2)
6.264184
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from grader.base.errors import GraderError

if TYPE_CHECKING:
    from grader.physics.dop853 import Integration

METHODS = ("euler", "rk4", "adaptive")
# rk4 reaches rounding (1e-16) at about 10,000 steps per contact, and Euler's first-order error
# is 2e-6 there: more steps buy nothing a user can see, and only cost time (tens of us a step).
MAX_STEPS_PER_CONTACT = 10_000
MAX_STEPS = 500_000  # steps in one simulation, all phases and all passes of a search together
TIME_LIMIT = 60.0  # s of wall time for one simulation
# Magnitudes (SI) a mode may involve: a margin of 1e8 below float64's overflow, so sums and products
# of a few of them stay finite, and of 1e3 above its subnormal range, where precision is lost.
LARGEST, SMALLEST = 1e300, 1e-305


class SimulationError(GraderError):
    """A simulation that cannot be run as asked (bad step, unknown method, no force law)."""


@dataclass(frozen=True)
class Mode:
    """One regime of motion: ``rhs(t, y)``, ended where ``event(y)`` crosses zero in ``direction``,
    or ``lasts`` seconds after it starts (then ``event`` is None).

    ``scale`` is the mode's time scale (a fixed step is ``scale/steps``); ``omega`` its highest
    natural angular frequency (0 for free motion); ``force(y)`` what a plot shows; ``sizes(y)``
    the size each state component is measured against (absolute tolerance = rtol * size).
    """

    name: str
    rhs: Callable[[float, Any], Any]
    event: Callable[[Any], float] | None
    direction: int
    scale: float
    omega: float = 0.0
    force: Callable[[Any], float] | None = None
    sizes: Callable[[Any], Any] | None = None
    lasts: float = 0.0


@dataclass(frozen=True)
class Settings:
    """How to integrate: a method, fixed steps per mode time scale, or a relative tolerance."""

    method: str = "adaptive"
    steps: int = 100
    rtol: float = 1e-10
    dense: bool = False  # adaptive: record 50 points per step interval's span for plots

    def __post_init__(self) -> None:
        if self.method not in METHODS:
            raise SimulationError(f"unknown method '{self.method}' (use one of {', '.join(METHODS)})")
        if not isinstance(self.steps, int) or self.steps < 1:
            raise SimulationError(f"steps per contact must be a whole number >= 1, got {self.steps!r}")
        if self.steps > MAX_STEPS_PER_CONTACT:
            raise SimulationError(f"steps per contact must be at most {MAX_STEPS_PER_CONTACT} (more buys no visible "
                                  "accuracy: rk4 reaches rounding error there, and the adaptive method is better "
                                  f"still), got {self.steps}")
        # Below 100 machine epsilons scipy raises rtol itself (with a warning): refuse it here instead.
        if not (isinstance(self.rtol, float | int) and 1e-13 <= self.rtol < 1):
            raise SimulationError(f"rtol must be between 1e-13 and 1, got {self.rtol + 0.0!r}")


class Budget:
    """The work one simulation may do, shared by all its phases: a number of steps and a wall-clock
    deadline. Spending past either raises :class:`SimulationError` naming the limit.

    >>> budget = Budget(steps=10, seconds=60.0)
    >>> budget.spend(4); budget.left
    6
    >>> budget.spend(7)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    grader.physics.integrate.SimulationError: the simulation needs more than 10 steps, the limit; ...
    """

    def __init__(self, steps: int = MAX_STEPS, seconds: float = TIME_LIMIT) -> None:
        self.steps, self.seconds = steps, seconds
        self.left = steps
        self.deadline = time.perf_counter() + seconds

    def spend(self, steps: int) -> None:
        """Count ``steps`` (0 only checks the clock)."""
        self.left -= steps
        if self.left < 0:
            raise SimulationError(f"the simulation needs more than {self.steps} steps, the limit; use fewer steps "
                                  "per contact or a larger rtol")
        if time.perf_counter() > self.deadline:
            raise SimulationError(f"the simulation took more than {self.seconds:g} s, the limit; use fewer steps "
                                  "per contact or a larger rtol")


@dataclass
class Path:
    """What an integration produced: times, states, the force acting, and the step count."""

    t: list[float] = field(default_factory=list)
    y: list[Any] = field(default_factory=list)
    force: list[float] = field(default_factory=list)
    steps: int = 0

    def add(self, t: float, y: Any, mode: Mode) -> None:
        self.t.append(t)
        self.y.append(y)
        self.force.append(mode.force(y) if mode.force is not None else 0.0)


def integrate(modes: Sequence[Mode], y0: Any, settings: Settings, t0: float = 0.0,
              budget: Budget | None = None) -> Path:
    """Run the modes one after another, each until its event; return the whole path."""
    path = Path()
    budget = budget or Budget()
    t, y = t0, np.asarray(y0, dtype=float)
    for mode in modes:
        _check_magnitudes(mode, t, y)
        path.add(t, y, mode)
        if settings.method == "adaptive":
            t, y = _adaptive(mode, t, y, settings.rtol, path, settings.dense, budget)
        else:
            t, y = _fixed(mode, t, y, settings, path, budget)
    return path


def _check_magnitudes(mode: Mode, t: float, y: Any) -> None:
    """Refuse a mode whose scales float64 cannot carry: its state, its time scale, the change of
    its state over that time scale and its frequency must lie within [SMALLEST, LARGEST] (zeros
    aside), so nothing overflows and nothing is lost in subnormal rounding."""
    with np.errstate(all="ignore"):
        # Sizes, not the state itself: a position that is 0 up to a rounding (an overlap at onset)
        # is not a scale.
        scales = {"time scale (s)": np.array([mode.scale, mode.omega * mode.scale]),
                  "size (m, m/s)": _sizes(mode, t, y),
                  "change over the time scale (m, m/s)": np.abs(np.asarray(mode.rhs(t, y), dtype=float)) * mode.scale}
        if mode.omega > 0:
            sizes, half = _sizes(mode, t, y), len(y) // 2
            scales["force per unit mass (m/s^2)"] = np.concatenate([np.float64(mode.omega) ** 2 * sizes[:half],
                                                                    mode.omega * sizes[half:]])
    for what, values in scales.items():
        values = np.asarray(values, dtype=float)
        bad = values[~np.isfinite(values) | (values > LARGEST) | ((values != 0) & (values < SMALLEST))]
        if bad.size:
            raise SimulationError(f"the {mode.name} mode cannot be simulated in float64: its {what} reaches "
                                  f"{float(bad[0]):.3g}, outside [{SMALLEST:g}, {LARGEST:g}]; use less extreme "
                                  "values (or another contact duration)")


def _step(method: str, rhs: Callable[[float, Any], Any], t: float, y: Any, dt: float) -> Any:
    if method == "euler":
        half = len(y) // 2
        velocity = y[half:] + dt * rhs(t, y)[half:]
        return np.concatenate([y[:half] + dt * velocity, velocity])
    k1 = rhs(t, y)
    k2 = rhs(t + dt / 2, y + dt / 2 * k1)
    k3 = rhs(t + dt / 2, y + dt / 2 * k2)
    k4 = rhs(t + dt, y + dt * k3)
    return y + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)


def _crossed(mode: Mode, before: float, after: float) -> bool:
    if mode.direction < 0:
        return before > 0 >= after
    return before < 0 <= after


def _fixed(mode: Mode, t: float, y: Any, settings: Settings, path: Path, budget: Budget) -> tuple[float, Any]:
    dt = mode.scale / settings.steps
    if mode.omega > 0 and dt * mode.omega >= 2:
        raise SimulationError(
            f"{settings.method}: a step of {dt:.3g} s is at or above the stability limit 2/omega = "
            f"{2 / mode.omega:.3g} s of the {mode.name} mode; use at least "
            f"{math.floor(mode.scale * mode.omega / 2) + 1} steps per contact")
    if mode.lasts:
        return _fixed_span(mode, t, y, settings, dt, path, budget)
    assert mode.event is not None  # a mode without an event lasts a given time (Mode's contract)
    for count in range(MAX_STEPS + 1):
        budget.spend(1)
        following = _step(settings.method, mode.rhs, t, y, dt)
        path.steps += 1
        if count == 0 and mode.omega > 0 and mode.event(following) * mode.direction >= 0:
            # A contact starts at zero overlap, on its own end; ending it within the first step
            # means the step cannot resolve it (and whether a crossing is seen would hang on rounding).
            raise SimulationError(
                f"{settings.method}: {settings.steps} steps per contact do not resolve the {mode.name} mode "
                "(it reverses within the first step); use more steps per contact")
        if _crossed(mode, mode.event(y), mode.event(following)):
            # The crossing, located on the method's own partial step (same order as a full step).
            fraction = _locate(mode, settings.method, t, y, dt)
            y = _step(settings.method, mode.rhs, t, y, fraction * dt)
            t += fraction * dt
            path.add(t, y, mode)
            return t, y
        t, y = t + dt, following
        path.add(t, y, mode)
    raise SimulationError(f"the {mode.name} mode did not end within {MAX_STEPS} steps{_never_ends(mode)}")


def _fixed_span(mode: Mode, t: float, y: Any, settings: Settings, dt: float, path: Path,
                budget: Budget) -> tuple[float, Any]:
    """A mode of known length in whole steps, the last one shortened to end on it."""
    end = t + mode.lasts
    steps = max(1, math.ceil(mode.lasts / dt * (1 - 1e-12)))
    if steps > MAX_STEPS:
        raise SimulationError(f"the {mode.name} mode did not end within {MAX_STEPS} steps")
    for count in range(steps):
        budget.spend(1)
        step = dt if count < steps - 1 else end - t
        y = _step(settings.method, mode.rhs, t, y, step)
        t = t + step if count < steps - 1 else end
        path.steps += 1
        path.add(t, y, mode)
    return t, y


def _sizes(mode: Mode, t: float, y: Any) -> Any:
    """What each component's error is measured against: the mode's own sizes, or else the largest
    position and the largest velocity (per component, one that starts at 0 would get none)."""
    if mode.sizes is not None:
        return np.asarray(mode.sizes(y), dtype=float)
    half, slope = len(y) // 2, np.abs(mode.rhs(t, y))
    positions = max(np.abs(y[:half]).max(), slope[:half].max() * mode.scale)
    velocities = max(np.abs(y[half:]).max(), slope[half:].max() * mode.scale)
    return np.repeat([positions, velocities], half)


def _locate(mode: Mode, method: str, t: float, y: Any, dt: float) -> float:
    """The fraction of the step at which the event crosses zero, on the method's own partial step."""
    from scipy.optimize import brentq  # here, not at the top: every command imports the effects

    event = mode.event
    assert event is not None  # only a mode that ends at its event is located
    return float(brentq(lambda f: event(_step(method, mode.rhs, t, y, f * dt)), 0.0, 1.0,
                        xtol=1e-15, rtol=8.9e-16))


def _adaptive(mode: Mode, t: float, y: Any, rtol: float, path: Path, dense: bool,
              budget: Budget) -> tuple[float, Any]:
    # Time in units of the mode's own scale and each state component in units of its own size:
    # the event is located to a tolerance relative to the contact's duration (a 1 ns contact
    # survives), and the error of a 1e-300 m/s motion is measured against itself, with no
    # absolute floor that would swallow it.
    start, unit = t, mode.scale
    sizes = _sizes(mode, t, y)
    sizes = np.where(sizes > 0, sizes, 1.0)
    ended = mode.event

    def event(_: float, state: Any) -> float:
        return ended(state * sizes)  # type: ignore[misc]  # passed on only where the mode has an event

    def scaled(s: float, state: Any) -> Any:
        return unit * mode.rhs(start + s * unit, state * sizes) / sizes

    horizon, y = 0.0, y / sizes
    span = mode.lasts / unit if mode.lasts else 10.0  # a mode of known length is integrated to its end at once
    for _ in range(60):
        origin, horizon = horizon, horizon + span
        run, interior = _stretch(scaled, origin, horizon, y, rtol, None if mode.lasts else event, mode.direction,
                                 dense, budget)
        path.steps += len(run.t) - 1
        budget.spend(len(run.t) - 1)
        if run.status < 0:
            raise SimulationError(f"the {mode.name} mode could not be integrated: {run.message}")
        for s, state in interior:
            path.add(start + float(s) * unit, state * sizes, mode)
        end, y = float(run.t[-1]), run.y[-1]
        t = start + mode.lasts if mode.lasts else start + end * unit
        path.add(t, y * sizes, mode)
        if run.status == 1 or mode.lasts:
            return t, y * sizes
        horizon = end
    raise SimulationError(f"the {mode.name} mode did not end within {600 * mode.scale:.3g} s{_never_ends(mode)}")


def _stretch(fun: Callable[[float, Any], Any], origin: float, horizon: float, y: Any, rtol: float,
             event: Callable[[float, Any], float] | None, direction: int, dense: bool,
             budget: Budget) -> tuple[Integration, list[tuple[float, Any]]]:
    """One stretch of the adaptive method: its steps (the last at the event, if it is crossed), and the points
    between its ends that a plot shows: the steps, or for a dense plot 48 points of ``solve_ivp``'s interpolant.
    The budget's clock is checked at every step."""
    from grader.physics import dop853  # scipy's tableau: here, not at the top, as solve_ivp below

    if not dense:
        run = dop853.integrate(fun, origin, horizon, y, rtol, rtol, event, direction, lambda: budget.spend(0))
        return run, list(zip(run.t[1:-1], run.y[1:-1], strict=True))
    from scipy.integrate import solve_ivp  # here, not at the top: every command imports the effects

    if event is not None:
        event.terminal = True  # type: ignore[attr-defined]
        event.direction = direction  # type: ignore[attr-defined]
    def timed(s: float, state: Any) -> Any:
        budget.spend(0)
        return fun(s, state)

    solution = solve_ivp(timed, (origin, horizon), y, method="DOP853", rtol=rtol, atol=rtol, events=event,
                         dense_output=True)
    run = dop853.Integration(list(solution.t), list(solution.y.T), solution.status, solution.message)
    return run, [(s, solution.sol(s)) for s in np.linspace(origin, solution.t[-1], 50)[1:-1]]


def _never_ends(mode: Mode) -> str:
    if mode.omega > 0:
        return (": the bodies stay in contact (with the weight acting on a soft contact they come to rest "
                "pressed together); try a shorter contact duration")
    return ""
