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
from dataclasses import dataclass

from scipy.optimize import brentq

from grader.bank.template import Template
from grader.errors import GraderError
from grader.model.expr import Sym
from grader.model.scene import Stage
from grader.physics.effects import CATALOGUE
from grader.physics.integrate import SimulationError
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


def simulate(template: Template, params: Mapping[str, float], options: Options | None = None) -> Simulation:
    """Simulate one parameter set (values in the template's units)."""
    options = options or Options()
    _check_force_laws(template)
    started = time.perf_counter()
    base = _si_values(template, params)
    try:
        run, fitted = _solve_for_unknowns(template, options, base)
    except SimulationError as error:
        raise SimulationError(f"{template.id}: {error}") from None
    # A found e is reported as the contact produced it (separation over approach), not as the
    # value the contact law was calibrated to: that is the time-domain answer.
    for contact in run.contacts:
        restitution = template.scene.stages[contact.stage].fields["restitution"]
        if isinstance(restitution, Sym) and restitution.name in fitted:
            run.values[restitution.name] = contact.measured_e
    if run.problems:
        raise SimulationError(f"{template.id}: {run.problems[0]}")
    answers = {name: _answer(template, run, name) for name, spec in template.answers.items() if not spec.symbolic}
    return Simulation(template.id, dict(params), answers, tuple(run.effects), run.steps,
                      time.perf_counter() - started, fitted, {n: 1.0 for n in template.symbols}, tuple(run.phases),
                      tuple(run.contacts))


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


def _walk(template: Template, options: Options, values: dict[str, float]) -> Run:
    run = Run(template.scene, options, dict(values))
    for stage in template.scene.stages:
        simulator = CATALOGUE[stage.effect].simulate
        assert simulator is not None  # checked by _check_force_laws
        simulator(stage, run)
    return run


def _solve_for_unknowns(template: Template, options: Options, base: dict[str, float]) -> tuple[Run, dict[str, float]]:
    """Walk the stages; a restitution nothing gives is found so the simulated observation matches."""
    try:
        return _walk(template, options, base), {}
    except UnknownQuantityError as missing:
        name = missing.name
    stage = _restitution_stage(template, name)

    def mismatch(e: float) -> float:
        run = _walk(template, options, {**base, name: e})
        observed = list(run.observed.values())
        if len(observed) != 1:
            raise SimulationError(f"{template.where}: cannot simulate: finding {name} needs exactly one "
                                  f"measured outcome, the scene has {len(observed)}")
        simulated, given = observed[0]
        return simulated - given

    low, high = mismatch(0.0), mismatch(1.0)
    if low == 0:
        return _walk(template, options, {**base, name: 0.0}), {name: 0.0}
    if low * high > 0:
        raise SimulationError(f"{template.id}: no coefficient of restitution in [0, 1] reproduces the given "
                              f"outcome of stages[{stage.index}] (with e = 1 the simulated value is still "
                              f"{'below' if high < 0 else 'above'} it)")
    found = brentq(mismatch, 0.0, 1.0, xtol=1e-15, rtol=8.9e-16, maxiter=200)
    return _walk(template, options, {**base, name: found}), {name: found}


def _restitution_stage(template: Template, name: str) -> Stage:
    for stage in template.scene.stages:
        if stage.effect == "impact" and stage.fields["restitution"] == Sym(name):
            return stage
    raise SimulationError(f"{template.where}: cannot simulate: '{name}' is neither given nor produced by an "
                          "earlier stage")


def _answer(template: Template, run: Run, name: str) -> float | None:
    spec = template.answers[name]
    try:
        value = run.value(spec.value)
    except UnknownQuantityError as missing:
        raise SimulationError(f"{template.where}: answers.{name}: the simulation does not produce "
                              f"'{missing.name}'") from None
    return value / spec.unit.to_si if math.isfinite(value) else None

