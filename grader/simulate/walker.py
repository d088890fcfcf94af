"""Re-derive a template's answers in the time domain, simulating only the effects its scene declares.

The stages run forward in order, each through its effect's own phase (gravity for flight, a
compliant contact for an impact, kinematics for a velocity). A template that gives a measured
outcome instead of an input (a rebound height instead of ``e``) is solved by root finding on
the simulation itself: ``e`` is adjusted until the simulated rebound matches, so no closed form
is used. Symbols without a value (a mass that cancels, the speed ``v``) are set to 1 in their
unit; only answers that do not depend on them are compared.

>>> from grader.bank.template import load_bank
>>> template = load_bank()["pile-driver"]
>>> result = simulate(template, {"m_ram": 800, "m_pile": 2400, "h_drop": 2, "h_rebound": 0.1})
>>> round(result.answers["e"], 4), result.effects
(0.6315, ('gravity', 'contact (Kelvin-Voigt)'))
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping
from dataclasses import dataclass, field

from scipy.optimize import brentq

from grader.bank.template import Template
from grader.errors import GraderError
from grader.model.expr import Sym, names
from grader.model.scene import Stage
from grader.physics.effects import CATALOGUE
from grader.physics.integrate import MAX_STEPS, Budget, SimulationError
from grader.physics.run import ContactRecord, Options, PhaseRecord, Run, UnknownQuantityError


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
            restitution = template.scene.stages[contact.stage].fields["restitution"]
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
                                            in answers.items() if value is None})


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
        values[name] = value * parameter.unit.to_si
    values.update({name: 1.0 * spec.unit.to_si for name, spec in template.symbols.items()})
    if template.scene.gravity is not None:
        values["g"] = float(template.scene.gravity.si)
    return values


def _walk(template: Template, options: Options, values: dict[str, float], budget: Budget) -> Run:
    run = Run(template.scene, options, dict(values), budget=budget)
    for stage in template.scene.stages:
        simulator = CATALOGUE[stage.effect].simulate
        assert simulator is not None  # checked by _check_force_laws
        simulator(stage, run)
    return run


# Passes a search for e makes: two ends, brentq's iterations (about 10 to 20 on these scenes at
# xtol 1e-15), the final run; the bound is what the fixed-step work is estimated with.
SEARCH_PASSES = 25


def _check_work(template: Template, options: Options, passes: int) -> None:
    """Refuse, before any work, a fixed-step simulation that would exceed the step limit: every
    stage integrates at most two modes of ``steps`` steps each."""
    settings = options.settings
    if settings.method == "adaptive":
        return
    estimate = settings.steps * 2 * len(template.scene.stages) * passes
    if estimate > MAX_STEPS:
        most = MAX_STEPS // (2 * len(template.scene.stages) * passes)
        search = f" x {passes} passes of the search for the unknown restitution" if passes > 1 else ""
        raise SimulationError(f"{settings.method} with {settings.steps} steps per contact would take up to "
                              f"{estimate:,} steps ({len(template.scene.stages)} stages{search}), above the limit of "
                              f"{MAX_STEPS:,}; use at most {most} steps per contact, or the adaptive method")


def _solve_for_unknowns(template: Template, options: Options, base: dict[str, float],
                        budget: Budget) -> tuple[Run, dict[str, float]]:
    """Walk the stages; a restitution nothing gives is found so the simulated observation matches."""
    _check_work(template, options, 1)
    try:
        return _walk(template, options, base, budget), {}
    except UnknownQuantityError as missing:
        name = missing.name
    stage = _restitution_stage(template, name)
    _check_work(template, options, SEARCH_PASSES)

    def mismatch(e: float) -> float:
        run = _walk(template, options, {**base, name: e}, budget)
        observed = list(run.observed.values())
        if len(observed) != 1:
            raise SimulationError(f"cannot simulate: finding {name} needs exactly one measured outcome, the scene "
                                  f"has {len(observed)}")
        simulated, given = observed[0]
        return simulated - given

    low, high = mismatch(0.0), mismatch(1.0)
    if low == 0:
        return _walk(template, options, {**base, name: 0.0}, budget), {name: 0.0}
    if low * high > 0:
        raise SimulationError(f"no coefficient of restitution in [0, 1] reproduces the given outcome of "
                              f"stages[{stage.index}] (with e = {1 if high < 0 else 0} the simulated value is still "
                              f"{'below' if high < 0 else 'above'} it)")
    found = brentq(mismatch, 0.0, 1.0, xtol=1e-15, rtol=8.9e-16, maxiter=200)
    run = _walk(template, options, {**base, name: found}, budget)
    if run.problems and mismatch(found) < 0:
        # brentq returns a point within its tolerance of the root, on either side. Where the
        # outcome is a body that just stops (a rebound of 0), the low side leaves it moving on down
        # by a rounding: the root is then just above, within the tolerance.
        upper = min(1.0, found + 2 * (1e-15 + 8.9e-16 * found))
        if mismatch(upper) >= 0:
            found, run = upper, _walk(template, options, {**base, name: upper}, budget)
    return run, {name: found}


def _restitution_stage(template: Template, name: str) -> Stage:
    for stage in template.scene.stages:
        if stage.effect == "impact" and stage.fields["restitution"] == Sym(name):
            return stage
    raise SimulationError(f"cannot simulate: '{name}' is neither given nor produced by an earlier stage")


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
