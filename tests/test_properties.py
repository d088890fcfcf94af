"""Physical invariants of the impact solver, as Hypothesis properties over the valid domain."""

from __future__ import annotations

import functools
import math
from typing import Any

import pytest
import yaml
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st

from grader.bank.template import Template, load_bank, parse_template
from grader.base.resources import bank_dir
from grader.solve.compiled import Compiled
from grader.solve.evaluate import solve_one
from grader.solve.solver import compile_template

PROPERTY = settings(max_examples=100, deadline=None)

TWO_BODIES = """
id: two-bodies
title: Oblique impact of two moving bodies
version: 1
bodies:
  b1: {mass: m1}
  b2: {mass: m2}
parameters:
  m1: {unit: kg, domain: "(0, inf)", sample: {uniform: [1, 2]}, decimals: 3}
  m2: {unit: kg, domain: "(0, inf)", sample: {uniform: [1, 2]}, decimals: 3}
  u1: {unit: m/s, domain: "(-inf, inf)", sample: {uniform: [1, 2]}, decimals: 3}
  u2: {unit: m/s, domain: "(-inf, inf)", sample: {uniform: [-2, -1]}, decimals: 3}
  s1: {unit: m/s, domain: "(-inf, inf)", sample: {uniform: [1, 2]}, decimals: 3}
  s2: {unit: m/s, domain: "(-inf, inf)", sample: {uniform: [1, 2]}, decimals: 3}
  e: {unit: "", domain: "[0, 1]", sample: {uniform: [0, 1]}, decimals: 3}
stages:
  - effect: impact
    bodies: [b1, b2]
    restitution: e
    before: {b1: {n: u1, t: s1}, b2: {n: u2, t: s2}}
    after: {b1: {n: a1, t: c1}, b2: {n: a2, t: c2}}
    energy_before: T_before
    energy_after: T_after
    energy_lost: T_lost
answers:
  a1: {value: a1, unit: m/s}
  a2: {value: a2, unit: m/s}
  c1: {value: c1, unit: m/s}
  c2: {value: c2, unit: m/s}
  T_before: {value: T_before, unit: J}
  T_after: {value: T_after, unit: J}
  T_lost: {value: T_lost, unit: J}
statement: Two smooth bodies of {{ m1 }} kg and {{ m2 }} kg collide obliquely with e = {{ e }}.
"""

AGAINST_WALL = """
id: against-wall
title: Oblique impact on a fixed surface
version: 1
bodies:
  b1: {mass: m1}
  wall: {fixed: true}
symbols:
  m1: {unit: kg, description: the body's mass (against a fixed wall it does not matter)}
parameters:
  u1: {unit: m/s, domain: "(0, inf)", sample: {uniform: [1, 2]}, decimals: 3}
  s1: {unit: m/s, domain: "(-inf, inf)", sample: {uniform: [1, 2]}, decimals: 3}
  e: {unit: "", domain: "[0, 1]", sample: {uniform: [0, 1]}, decimals: 3}
stages:
  - effect: impact
    bodies: [b1, wall]
    restitution: e
    before: {b1: {n: u1, t: s1}}
    after: {b1: {n: a1, t: c1}}
answers:
  a1: {value: a1, unit: m/s}
  c1: {value: c1, unit: m/s}
statement: A smooth body strikes a fixed wall with e = {{ e }}.
"""

RESTITUTION = {"unit": "", "domain": "[0, 1]", "sample": {"uniform": [0.3, 0.9]}, "decimals": 2}

masses = st.floats(min_value=1e-6, max_value=1e6)
# Magnitudes from docs/design.md's envelope (down to 1e-150): near 1e-308 the kernels' u/m goes subnormal
# (the inverse-mass form divides it by the mass) and loses digits: outside what docs/design.md promises.
speeds = st.one_of(st.just(0.0), st.builds(math.copysign, st.floats(min_value=1e-150, max_value=1e3),
                                           st.sampled_from([1.0, -1.0])))
restitutions = st.floats(min_value=0.0, max_value=1.0)
# Below ~1e-6, e**2 scales h_rebound toward underflow and the inverse cannot recover e to 1e-12.
recoverable_restitutions = st.one_of(st.just(0.0), st.floats(min_value=1e-6, max_value=1.0))


@functools.cache
def _compiled_text(text: str) -> tuple[Template, Compiled]:
    template = parse_template(yaml.safe_load(text), "test:properties", "hash-properties")
    return template, compile_template(template)


@functools.cache
def _shipped(template_id: str) -> tuple[Template, Compiled]:
    template = load_bank()[template_id]
    return template, compile_template(template)


@functools.cache
def _forward(shipped_id: str) -> tuple[Template, Compiled]:
    """A shipped inverse template turned forward: e given, h_rebound asked (same scene)."""
    raw = yaml.safe_load((bank_dir() / f"{shipped_id}.yaml").read_text())
    for key in ("constraints", "example"):
        raw.pop(key)
    unit = raw["parameters"].pop("h_rebound")["unit"]
    raw["parameters"]["e"] = RESTITUTION
    raw["answers"] = {"h_rebound": {"value": "h_rebound", "unit": unit}}
    raw["id"], raw["statement"] = f"{shipped_id}-forward", "Find the rebound height for e = {{ e }}."
    template = parse_template(raw, f"test:{shipped_id}-forward", f"hash-{shipped_id}-forward")
    return template, compile_template(template)


def _solve(pair: tuple[Template, Compiled], params: dict[str, float]) -> dict[str, Any]:
    solution = solve_one(pair[0], pair[1], params)
    assert solution.error is None, f"{params} refused: {solution.error}"
    assert solution.answers is not None
    return {name: answer.value for name, answer in solution.answers.items()}


@st.composite
def two_body_impacts(draw: st.DrawFn) -> dict[str, float]:
    """Masses, oblique velocities that approach along n (u1 > u2), and e."""
    u1, u2 = draw(speeds), draw(speeds)
    assume(u1 != u2)
    u1, u2 = max(u1, u2), min(u1, u2)
    return {"m1": draw(masses), "m2": draw(masses), "u1": u1, "u2": u2, "s1": draw(speeds), "s2": draw(speeds),
            "e": draw(restitutions)}


@PROPERTY
@given(two_body_impacts())
def test_momentum_is_conserved_along_the_line_of_impact(params: dict[str, float]) -> None:
    """m1 u1 + m2 u2 = m1 u1' + m2 u2', to rounding of the momenta involved."""
    out = _solve(_compiled_text(TWO_BODIES), params)
    m1, m2, u1, u2 = params["m1"], params["m2"], params["u1"], params["u2"]
    before, after = m1 * u1 + m2 * u2, m1 * out["a1"] + m2 * out["a2"]
    assert abs(before - after) <= 1e-12 * (abs(m1 * u1) + abs(m2 * u2)), (before, after)


@PROPERTY
@given(two_body_impacts())
def test_tangential_velocities_are_unchanged_by_a_smooth_impact(params: dict[str, float]) -> None:
    """No impulse along t: each body keeps its t-velocity exactly."""
    out = _solve(_compiled_text(TWO_BODIES), params)
    assert (out["c1"], out["c2"]) == (params["s1"], params["s2"])


@PROPERTY
@given(two_body_impacts())
# Mass ratio 1e12 and speed 1e-150, both inside docs/design.md's envelope: u1'**2 ~ 4e-324 underflows.
@example({"m1": 1e6, "m2": 1e-6, "u1": 0.0, "u2": -1e-150, "s1": 0.0, "s2": 0.0, "e": 1.0})
def test_kinetic_energy_never_increases_and_the_loss_is_before_minus_after(params: dict[str, float]) -> None:
    """T' <= T; the energy lost is >= 0 and equals T - T' to rounding of T."""
    out = _solve(_compiled_text(TWO_BODIES), params)
    before, after, lost = out["T_before"], out["T_after"], out["T_lost"]
    assert after <= before * (1 + 1e-12), (before, after)
    assert lost >= 0
    assert abs(lost - (before - after)) <= 1e-12 * before, (lost, before - after)


@PROPERTY
@given(two_body_impacts())
def test_separation_is_e_times_approach_along_n(params: dict[str, float]) -> None:
    """u2' - u1' = e (u1 - u2), to rounding of the velocities involved."""
    out = _solve(_compiled_text(TWO_BODIES), params)
    separation, approach = out["a2"] - out["a1"], params["u1"] - params["u2"]
    scale = abs(params["u1"]) + abs(params["u2"])
    assert math.isclose(separation, params["e"] * approach, rel_tol=1e-12, abs_tol=1e-12 * scale), \
        (separation, params["e"] * approach)


@PROPERTY
@given(st.floats(min_value=1e-6, max_value=1e3), speeds, restitutions)
def test_a_fixed_surface_returns_minus_e_times_the_normal_velocity(u1: float, s1: float, e: float) -> None:
    """Against a fixed surface u1' = -e u1 and the t-velocity is kept (the mass is not needed: a symbol)."""
    out = _solve(_compiled_text(AGAINST_WALL), {"u1": u1, "s1": s1, "e": e})
    assert math.isclose(out["a1"], -e * u1, rel_tol=1e-12, abs_tol=0.0), (out["a1"], -e * u1)
    assert out["c1"] == s1


@PROPERTY
@given(st.floats(min_value=1e-3, max_value=1e6), recoverable_restitutions)
def test_drop_rebound_forward_then_inverse_returns_e(h_drop: float, e: float) -> None:
    """h_drop, e -> h_rebound through the scene, then the shipped template gives e back."""
    h_rebound = _solve(_forward("drop-rebound"), {"h_drop": h_drop, "e": e})["h_rebound"]
    back = _solve(_shipped("drop-rebound"), {"h_drop": h_drop, "h_rebound": h_rebound})["e"]
    assert math.isclose(back, e, rel_tol=1e-12, abs_tol=0.0), (e, h_rebound, back)


@PROPERTY
@given(st.floats(min_value=1e-3, max_value=1e3), st.floats(min_value=1e-3, max_value=1.25),
       st.floats(min_value=1e-3, max_value=1e3), st.floats(min_value=1e-6, max_value=1.0))
# Elastic, Sample Problem 3/28 scale: h_rebound = 0.5 exactly, yet the inverse derives e = 1 + 1 ulp.
@example(m_pile=2400.0, k=1 / 3, h_drop=2.0, e=1.0)
def test_pile_driver_forward_then_inverse_returns_e(m_pile: float, k: float, h_drop: float, e: float) -> None:
    """m_ram = k e m_pile, m_pile, h_drop, e -> h_rebound, then the shipped template gives e back.

    A ram heavier than e*m_pile (k > 1) follows the pile down: that row is refused with a reason.
    """
    forward_params = {"m_ram": k * e * m_pile, "m_pile": m_pile, "h_drop": h_drop, "e": e}
    template, compiled_forward = _forward("pile-driver")
    forward = solve_one(template, compiled_forward, forward_params)
    if forward.error is not None:
        assert forward.error.strip()
        assert k >= 1 - 1e-12, (forward_params, forward.error)
        assume(False)
    assert forward.answers is not None
    h_rebound = forward.answers["h_rebound"].value
    inverse_params = {"m_ram": k * e * m_pile, "m_pile": m_pile, "h_drop": h_drop, "h_rebound": h_rebound}
    back = _solve(_shipped("pile-driver"), inverse_params)["e"]
    assert math.isclose(back, e, rel_tol=1e-12, abs_tol=0.0), (forward_params, h_rebound, back)


def _widened(template: Template, name: str) -> st.SearchStrategy[float]:
    """Any value of the parameter's domain within [-1e3, 1e3], kept 1e-3 off an open zero bound; a
    value of either sign (a signed velocity) is 0 or at least 1e-150 in size, docs/design.md's envelope (a
    speed of 1e-287 squares to 0 in float64, and such a row is refused, not answered)."""
    domain = template.parameters[name].domain
    low, high = max(domain.low, -1e3), min(domain.high, 1e3)
    if domain.low_open and low == 0:
        low = 1e-3
    values = st.floats(min_value=low, max_value=high, exclude_min=domain.low_open and low == domain.low,
                       exclude_max=domain.high_open and high == domain.high)
    return values.filter(lambda x: x == 0 or abs(x) >= 1e-150) if low < 0 else values


@pytest.mark.parametrize("template_id", [
    "ball-plate", "car-collision", "drop-rebound", "oblique-spheres", "pile-driver",
    "head-on",
    "head-on-inverse",
    "coupling",
    "moving-plate",
    "three-balls",
    "two-rebounds",
    "incline-bounce",
    "billiards",
    "offset-spheres",
])
@PROPERTY
@given(data=st.data())
def test_every_answer_is_finite_or_the_row_is_refused_with_a_reason(template_id: str, data: st.DataObject) -> None:
    """Widened draws never produce NaN or infinity, nor an overflow refusal; other refusals give a reason."""
    template, compiled = _shipped(template_id)
    params = {name: data.draw(_widened(template, name), label=name) for name in template.parameters}
    solution = solve_one(template, compiled, params)
    if solution.error is not None:
        assert solution.error.strip()
        assert "not a finite number" not in solution.error, (params, solution.error)
        return
    assert solution.answers is not None
    for name, answer in solution.answers.items():
        if answer.undefined is not None:
            assert answer.value is None and answer.undefined.strip()
        elif not isinstance(answer.value, str):
            assert answer.value is not None and math.isfinite(answer.value), (params, name, answer.value)
