"""Re-derive a template's answers in the time domain, simulating only the effects its scene declares.

The stages run in the order their quantities flow (as written, unless a stage waits for one a later
stage gives), each through its effect's own phase (gravity for flight, a compliant contact for an
impact, kinematics for a velocity). A template that gives a measured outcome instead of an input
(a rebound height instead of ``e``) is solved by root finding on the simulation itself: ``e`` is
adjusted until the simulated rebound matches, so no closed form is used. Several such unknowns are
found one at a time (two rebound heights: ``e`` from the second bounce, then the drop height).
Symbols without a value (a mass that cancels, the speed ``v``) are set to 1 in their unit; only
answers that do not depend on them are compared.

>>> from grader.bank.template import load_bank
>>> template = load_bank()["pile-driver"]
>>> result = simulate(template, {"m_ram": 800, "m_pile": 2400, "h_drop": 2, "h_rebound": 0.1})
>>> round(result.answers["e"], 4), result.effects
(0.6315, ('gravity', 'contact (Kelvin-Voigt)'))
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

from scipy.optimize import brentq

from grader.bank.template import Template
from grader.base.errors import GraderError
from grader.model.expr import Num, Op, Sym, names, parse
from grader.model.scene import Stage, Velocity
from grader.physics.effects import CATALOGUE
from grader.physics.integrate import MAX_STEPS, Budget, SimulationError
from grader.physics.record import ContactRecord, Options, PhaseRecord, Run, UnknownQuantityError


@dataclass(frozen=True)
class Simulation:
    """Simulated answers (template units) with what produced them."""

    template: str
    params: Mapping[str, float]
    answers: Mapping[str, float | None]
    effects: tuple[str, ...]
    steps: int
    seconds: float
    fitted: Mapping[str, float]
    nominal: Mapping[str, float]
    phases: tuple[PhaseRecord, ...]
    contacts: tuple[ContactRecord, ...] = ()
    undefined: Mapping[str, str] = field(default_factory=dict)  # answer -> why it has no value
    notes: tuple[str, ...] = ()  # what the force laws tell the reader (a series' tail beyond the simulated part)


def simulate(template: Template, params: Mapping[str, float], options: Options | None = None) -> Simulation:
    """Simulate one parameter set (values in the template's units)."""
    options = options or Options()
    _check_force_laws(template)
    started = time.perf_counter()
    base = _si_values(template, params)
    budget = Budget(MAX_STEPS, options.time_limit)
    try:
        run, fitted = _solve_for_unknowns(template, options, base, budget)
        # A found e is reported as the contact produced it (separation over approach), not as the
        # value the contact law was calibrated to: that is the time-domain answer.
        for contact in run.contacts:
            restitution = template.scene.stages[contact.stage].fields.get("restitution")  # none: bodies that stick
            if isinstance(restitution, Sym) and restitution.name in fitted:
                run.values[restitution.name] = contact.measured_e
        if run.problems:
            raise SimulationError(run.problems[0])
        answers = {name: _answer(template, run, name) for name, spec in template.answers.items()
                   if not spec.symbolic}
    except SimulationError as error:
        # The one place a simulation's messages are told which template they are about.
        raise SimulationError(f"{template.id}: {error}") from None
    return Simulation(template.id, dict(params), answers, tuple(run.effects), run.steps,
                      time.perf_counter() - started, fitted, {n: 1.0 for n in template.symbols}, tuple(run.phases),
                      tuple(run.contacts), {name: _why_undefined(template, run, name) or "" for name, value
                                            in answers.items() if value is None}, tuple(run.notes))


def _check_force_laws(template: Template) -> None:
    for stage in template.scene.stages:
        if CATALOGUE[stage.effect].simulate is None:
            raise SimulationError(f"{template.where}: stages[{stage.index}]: the effect '{stage.effect}' has no "
                                  "force law, so this scene cannot be simulated")


def _si_values(template: Template, params: Mapping[str, float]) -> dict[str, float]:
    values: dict[str, float] = {}
    for name, parameter in template.parameters.items():
        value = float(params[name])
        if not (math.isfinite(value) and parameter.domain.contains(value)):
            raise GraderError(f"{name} = {value:g} is outside its domain {parameter.domain}")
        if not parameter.admits(value):
            raise GraderError(parameter.not_whole(f"{value:g}"))
        values[name] = value * parameter.unit.to_si
    values.update({name: 1.0 * spec.unit.to_si for name, spec in template.symbols.items()})
    if template.scene.gravity is not None:
        values["g"] = float(template.scene.gravity.si)
    return values


def _walk(template: Template, options: Options, values: dict[str, float], budget: Budget) -> Run:
    """Simulate every stage whose inputs are known, in the order the quantities flow: a stage that
    needs a quantity a later stage produces (or a search must find) waits for it. The run's
    ``waiting`` names, per stage left over, the first quantity it still needs. An effect's force law
    reads its inputs before it simulates anything, so a stage that cannot start leaves no trace."""
    run = Run(template.scene, options, dict(values), budget=budget)
    waiting = list(template.scene.stages)
    while waiting:
        for stage in waiting:
            simulator = CATALOGUE[stage.effect].simulate
            assert simulator is not None  # checked by _check_force_laws
            try:
                simulator(stage, run)
            except UnknownQuantityError as missing:
                run.waiting[stage.index] = missing.name
                continue
            run.waiting.pop(stage.index, None)
            waiting.remove(stage)
            break
        else:
            break
    return run


# Passes a search for one unknown makes: two ends, brentq's iterations (about 10 to 20 on these scenes
# at xtol 1e-15), the final run; the bound is what the fixed-step work is estimated with.
SEARCH_PASSES = 25
# What a search may find, by the stage field that needs it: a restitution in [0, 1]; a fall height, the
# speed of an approach along n before an impact (a car's, from the skid after it) or at the start of a
# slide in [0, inf), bracketed by growing an upper end from the size of the outcome it must match; the
# velocity of a whole before it separates in (-inf, inf), bracketed by growing both ends from 0.
_SEARCHABLE = {("impact", "restitution"): ("coefficient of restitution", 0.0, 1.0),
               ("free_fall", "height"): ("fall height", 0.0, math.inf),
               ("impact", "before"): ("velocity before the impact", 0.0, math.inf),
               ("slide", "speed"): ("speed at the start of the slide", 0.0, math.inf),
               ("spring", "stiffness"): ("spring constant", 0.0, math.inf),
               ("slope", "speed"): ("speed at the start of the path", 0.0, math.inf),
               ("slope", "friction"): ("coefficient of kinetic friction", 0.0, math.inf),
               ("stick", "before"): ("speed before the collision", 0.0, math.inf),
               ("separation", "relative"): ("relative velocity of separation", 0.0, math.inf),
               ("separation", "energy"): ("energy released", 0.0, math.inf),
               ("separation", "whole"): ("velocity of the whole before it separates", -math.inf, math.inf)}
_PROBE = 0.5  # a value of the unknown that shows which outcome it leads to
_GROWTH, _MAX_GROWTH = 4.0, 120  # an open upper end grows 4x at a time, at most 120 times (4**120 ~ 1e72)


def _check_work(template: Template, options: Options, passes: int) -> None:
    """Refuse, before any work, a fixed-step simulation that would exceed the step limit: every
    stage integrates at most two modes of ``steps`` steps each."""
    settings = options.settings
    if settings.method == "adaptive":
        return
    estimate = settings.steps * 2 * len(template.scene.stages) * passes
    if estimate > MAX_STEPS:
        most = MAX_STEPS // (2 * len(template.scene.stages) * passes)
        search = f" x {passes} passes of the search for what is not given" if passes > 1 else ""
        raise SimulationError(f"{settings.method} with {settings.steps} steps per contact would take up to "
                              f"{estimate:,} steps ({len(template.scene.stages)} stages{search}), above the limit of "
                              f"{MAX_STEPS:,}; use at most {most} steps per contact, or the adaptive method")


@dataclass(frozen=True)
class _Unknown:
    """A quantity no parameter gives and no stage produces: the stage that needs it, what it is and
    the range searched, and the one measured outcome (an observation's key) it must reproduce."""

    name: str
    stage: Stage
    what: str
    low: float
    high: float
    outcome: str


def _solve_for_unknowns(template: Template, options: Options, base: dict[str, float],
                        budget: Budget) -> tuple[Run, dict[str, float]]:
    """Walk the stages; each quantity nothing gives (a restitution, a fall height) is found, one at a
    time, so that the one measured outcome it leads to is reproduced: the simulation's own "one
    equation, one unknown". Two rebound heights give e from the second bounce, then the drop height."""
    _check_work(template, options, 1)
    fitted: dict[str, float] = {}
    while True:
        run = _walk(template, options, {**base, **fitted}, budget)
        if not run.waiting:
            return run, fitted
        _check_work(template, options, SEARCH_PASSES * (len(fitted) + 1))
        unknown = _next_unknown(template, options, {**base, **fitted}, budget, run)
        fitted[unknown.name] = _search(template, options, {**base, **fitted}, budget, unknown)


def _next_unknown(template: Template, options: Options, values: dict[str, float], budget: Budget,
                  stalled: Run) -> _Unknown:
    """Of the quantities the waiting stages need, the first that can be searched for now: with a trial
    value, the stages it unblocks reach exactly one new measured outcome."""
    tried: list[tuple[str, int]] = []  # searchable quantities that reached no single outcome, and how many
    for index, name in sorted(stalled.waiting.items()):
        stage = template.scene.stages[index]
        kind = next((_SEARCHABLE[(stage.effect, key)] for key, value in stage.fields.items()
                     if (stage.effect, key) in _SEARCHABLE and _names(value, name)), None)
        if kind is None or name in (u for u, _ in tried):
            continue
        probe = _walk(template, options, {**values, name: _PROBE}, budget)
        # A measured outcome is one the statement gives (a skid's length); a quantity the run produced
        # twice (the common velocity of two cars that couple) only checks the run against itself.
        outcomes = sorted(key for key in set(probe.observed) - set(stalled.observed)
                          if names(parse(key)) <= set(values))
        if len(outcomes) == 1:
            return _Unknown(name, stage, *kind, outcomes[0])
        tried.append((name, len(outcomes)))
    if not tried:
        name = stalled.waiting[min(stalled.waiting)]
        raise SimulationError(f"cannot simulate: '{name}' is neither given nor produced by an earlier stage")
    name, count = tried[0]
    raise SimulationError(f"cannot simulate: finding {name} needs exactly one measured outcome that it alone "
                          f"leads to, the scene has {count}")


def _names(field: object, name: str) -> bool:
    """Whether a stage field is the quantity ``name`` itself: the field, or a velocity (a body's, or the whole's
    before it separates) along one axis alone, or its negative, the other component a given number (a bullet's or
    a car's speed before it strikes, found from what happens after: a car driving north, ``{n: 0, t: v_A}``)."""
    if isinstance(field, Mapping):  # per body
        return any(_names(v, name) for v in field.values())
    if isinstance(field, Velocity):  # the velocity, or its negative (a bullet coming in along -n)
        alone = (Sym(name), Op("neg", (Sym(name),)))
        return (field.n in alone and (field.t is None or isinstance(field.t, Num))) or \
            (field.t in alone and isinstance(field.n, Num))
    return field == Sym(name)


def _search(template: Template, options: Options, values: dict[str, float], budget: Budget,
            unknown: _Unknown) -> float:
    """The value of the unknown at which the simulated outcome equals the given one (brentq)."""
    name = unknown.name

    def outcome(x: float) -> tuple[float, float]:
        return _walk(template, options, {**values, name: x}, budget).observed[unknown.outcome]

    low, high = unknown.low, unknown.high
    simulated, given = outcome(0.0 if math.isinf(low) else low)
    at_low = simulated - given
    if at_low == 0:
        return 0.0 if math.isinf(low) else low

    def mismatch(x: float) -> float:
        return outcome(x)[0] - given

    if math.isinf(low):  # a signed quantity: ends grown both ways from 0 until one brackets the root
        low, high, at_low, at_high = _bracket_both_ways(mismatch, at_low, abs(given) or 1.0)
        span = "(-inf, inf)"
    elif math.isinf(high):  # an upper end grown from the size of the outcome until it brackets the root
        high = abs(given) or 1.0
        for _ in range(_MAX_GROWTH):
            at_high = mismatch(high)
            if at_high * at_low <= 0:
                break
            high *= _GROWTH
        span = f"[{low:g}, inf)"
    else:
        at_high = mismatch(high)
        span = f"[{low:g}, {high:g}]"
    if at_low * at_high > 0:
        raise SimulationError(f"no {unknown.what} in {span} reproduces the given {unknown.outcome} (with {name} = "
                              f"{high if at_high < 0 else low:g} the simulated {unknown.outcome} is still "
                              f"{'below' if at_high < 0 else 'above'} it)")
    xtol, rtol = 1e-15 * max(abs(low), abs(high)), 8.9e-16
    found = brentq(mismatch, low, high, xtol=xtol, rtol=rtol, maxiter=200)
    if _walk(template, options, {**values, name: found}, budget).problems and mismatch(found) * at_low > 0:
        # brentq returns a point within its tolerance of the root, on either side. Where the
        # outcome is a body that just stops (a rebound of 0), the low side leaves it moving on down
        # by a rounding: the root is then just above, within the tolerance.
        upper = min(high, found + 2 * (xtol + rtol * abs(found)))
        if mismatch(upper) * at_low <= 0:
            found = upper
    return float(found)


def _bracket_both_ways(mismatch: Callable[[float], float], at_zero: float,
                       size: float) -> tuple[float, float, float, float]:
    """Ends ``0`` and ``+size`` or ``-size``, ``size`` grown 4x at a time, between which ``mismatch`` changes
    sign: ``(low, high, mismatch(low), mismatch(high))``, or the last pair tried, unbracketed."""
    for _ in range(_MAX_GROWTH):
        at_plus = mismatch(size)
        if at_plus * at_zero <= 0:
            return 0.0, size, at_zero, at_plus
        at_minus = mismatch(-size)
        if at_minus * at_zero <= 0:
            return -size, 0.0, at_minus, at_zero
        size *= _GROWTH
    return -size, size, at_minus, at_plus


def _why_undefined(template: Template, run: Run, name: str) -> str | None:
    """Why an answer has no value: the reason of the first undefined quantity it uses, if any."""
    return next((run.undefined[q] for q in sorted(names(template.answers[name].value)) if q in run.undefined), None)


def _answer(template: Template, run: Run, name: str) -> float | None:
    """An answer in its unit; None where the quantity is undefined (the run says why)."""
    spec = template.answers[name]
    try:
        value = run.value(spec.value)
    except UnknownQuantityError as missing:
        raise SimulationError(f"answers.{name}: the simulation does not produce '{missing.name}'") from None
    if math.isnan(value) and _why_undefined(template, run, name) is not None:
        return None
    shown = value / spec.unit.to_si
    if not math.isfinite(shown):
        raise SimulationError(f"answers.{name}: the simulated value ({value}) is not a finite float64 number; "
                              "use less extreme parameters")
    return shown + 0.0  # never -0
