"""The time-domain simulation re-derives every template's answers; only declared effects are simulated."""

from __future__ import annotations

import dataclasses
import json
import math
import re
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import yaml

from grader.bank.template import Template, parse_template
from grader.cli import main
from grader.physics.effects import CATALOGUE
from grader.physics.integrate import Settings, SimulationError
from grader.physics.record import Options
from grader.simulate.comparison import relative_difference
from grader.simulate.walker import simulate
from grader.solve.compiled import Compiled
from grader.solve.evaluate import solve_one
from grader.solve.solver import compile_template
from tests.scenes import TWO_BODIES, TWO_BOUNCES

ADAPTIVE = Options(Settings("adaptive", rtol=1e-10))


def _variants(template: Template, compiled: Compiled, count: int, seed: int) -> list[dict[str, float]]:
    """Parameter sets drawn from the template's sampling, rounded as they would be printed; a draw the
    closed form refuses (a measurement implying e > 1) is drawn again, as a variant would be."""
    rng = np.random.default_rng(seed)
    sets: list[dict[str, float]] = []
    while len(sets) < count:
        params = {}
        for name, parameter in template.parameters.items():
            low, high = parameter.sample.values[0], parameter.sample.values[-1]
            value = float(rng.choice(parameter.sample.values)) if parameter.sample.kind == "choice" else float(
                rng.uniform(low, high))
            params[name] = round(value, parameter.decimals) if parameter.decimals is not None else float(
                f"{value:.{parameter.sig_figs}g}")
        if solve_one(template, compiled, params).error is None:
            sets.append(params)
    return sets


def _compare(template: Template, compiled: Compiled, params: dict[str, float], options: Options) -> dict[str, float]:
    closed = solve_one(template, compiled, params)
    assert closed.answers is not None, closed.error
    simulated = simulate(template, params, options)
    differences = {}
    for name, value in simulated.answers.items():
        exact = closed.answers[name].value
        if exact is None or value is None:
            assert exact is None and value is None, (name, exact, value)
            continue
        assert isinstance(exact, float)
        differences[name] = relative_difference(value, exact)
    return differences


def test_every_bank_template_is_cross_checked_by_simulation(bank: dict[str, Template],
                                                            compiled: dict[str, Compiled]) -> None:
    """Each template of problem_bank/, on sampled variants, agrees with its closed form to 1e-6."""
    for template_id, template in bank.items():
        for params in _variants(template, compiled[template_id], 4, seed=len(template_id)):
            differences = _compare(template, compiled[template_id], params, ADAPTIVE)
            assert differences, template_id
            assert max(differences.values()) <= 1e-6, (template_id, params, differences)


@pytest.mark.parametrize(("template_id", "params", "effects"), [
    ("car-collision", {"p": 0.5, "e": 0.1}, ("contact (Kelvin-Voigt)",)),
    ("ball-plate", {"v": 50, "theta": 30, "e": 0.5}, ("contact (Kelvin-Voigt)",)),
    ("drop-rebound", {"h_drop": 2100, "h_rebound": 1100}, ("gravity", "contact (Kelvin-Voigt)")),
    ("incline-bounce", {"h": 1.2, "beta": 30, "e": 0.6}, ("gravity", "contact (Kelvin-Voigt)")),
    ("billiards", {"v": 2, "r": 28.5, "b": 30, "e": 0.9}, ("uniform motion to contact", "contact (Kelvin-Voigt)")),
])
def test_only_the_effects_a_scene_declares_are_simulated(template_id: str, params: dict[str, float],
                                                         effects: tuple[str, ...],
                                                         bank: dict[str, Template]) -> None:
    """A car collision integrates no gravity, even when the weight during contact is asked for."""
    asked = dataclasses.replace(ADAPTIVE, weight_during_contact=True)
    assert simulate(bank[template_id], params).effects == effects
    with_weight = simulate(bank[template_id], params, asked).effects
    assert with_weight == ((*effects, "weight during contact") if "gravity" in effects else effects)


@pytest.fixture(scope="module")
def two_bodies() -> tuple[Template, Compiled]:
    template = parse_template(yaml.safe_load(TWO_BODIES), "test:two-bodies", "two-bodies")
    return template, compile_template(template)


@pytest.mark.parametrize("e", [0.0, 0.01, 0.5, 0.99, 1 - 1e-9, 1.0])
def test_the_contact_reproduces_e(e: float, two_bodies: tuple[Template, Compiled]) -> None:
    """Separation over approach equals e (e = 0: the bodies part at maximum compression)."""
    template, compiled = two_bodies
    params = {"m1": 1.0, "m2": 2.0, "u1": 3.0, "u2": -1.0, "e": e}
    result = simulate(template, params, Options(Settings("adaptive", rtol=1e-12)))
    separation = result.answers["a2"] - result.answers["a1"]  # type: ignore[operator]
    assert separation == pytest.approx(e * 4.0, rel=1e-10, abs=1e-12)
    assert max(_compare(template, compiled, params, Options(Settings("adaptive", rtol=1e-12))).values()) < 1e-10


@pytest.mark.parametrize("ratio", [1e-6, 1e-3, 1.0, 1e3, 1e6])
def test_extreme_mass_ratios_stay_accurate(ratio: float, two_bodies: tuple[Template, Compiled]) -> None:
    """Stiffness follows the reduced mass, so the relative motion is the same at any mass ratio."""
    template, compiled = two_bodies
    params = {"m1": ratio, "m2": 1.0, "u1": 3.0, "u2": -1.0, "e": 0.7}
    assert max(_compare(template, compiled, params, Options(Settings("adaptive", rtol=1e-12))).values()) < 1e-10


@pytest.mark.parametrize("theta", [1e-3, 1.0, 89.999, 90.0])
def test_grazing_and_head_on_impacts_on_a_plate(theta: float, bank: dict[str, Template],
                                                compiled: dict[str, Compiled]) -> None:
    """A grazing impact's small normal motion is integrated on its own scale."""
    params = {"v": 50.0, "theta": theta, "e": 0.5}
    assert max(_compare(bank["ball-plate"], compiled["ball-plate"], params, ADAPTIVE).values()) < 1e-8


@pytest.mark.parametrize("duration", [1e-1, 1e-3, 1e-6, 1e-9])
def test_stiff_contacts_are_integrated_on_their_own_time_scale(duration: float,
                                                               two_bodies: tuple[Template, Compiled]) -> None:
    """The error does not depend on how short (stiff) the contact is."""
    template, compiled = two_bodies
    params = {"m1": 1.0, "m2": 2.0, "u1": 3.0, "u2": -1.0, "e": 0.7}
    options = dataclasses.replace(ADAPTIVE, contact_duration=duration)
    assert max(_compare(template, compiled, params, options).values()) < 1e-8


@pytest.mark.parametrize(("method", "steps", "bound"), [("euler", 100, 2e-3), ("euler", 1000, 2e-4),
                                                        ("rk4", 30, 5e-6), ("rk4", 300, 1e-9)])
def test_fixed_step_methods_converge_within_their_bounds(method: str, steps: int, bound: float,
                                                         two_bodies: tuple[Template, Compiled]) -> None:
    """Semi-implicit Euler is first order, RK4 fourth: errors within what benchmarks/accuracy.py shows."""
    template, compiled = two_bodies
    params = {"m1": 1.0, "m2": 2.0, "u1": 3.0, "u2": -1.0, "e": 0.7}
    error = max(_compare(template, compiled, params, Options(Settings(method, steps=steps))).values())
    assert error < bound
    coarse = max(_compare(template, compiled, params, Options(Settings(method, steps=steps // 2))).values())
    assert coarse / error > (1.6 if method == "euler" else 10)


@pytest.mark.parametrize("magnitude", [1e-150, 1e170])
def test_extreme_magnitudes_neither_blow_up_nor_lose_accuracy(magnitude: float,
                                                              two_bodies: tuple[Template, Compiled]) -> None:
    """Speeds near 1e-150 and 1e170 simulate like ordinary ones."""
    template, compiled = two_bodies
    params = {"m1": 1.0, "m2": 2.0, "u1": 3 * magnitude, "u2": -magnitude, "e": 0.7}
    closed = solve_one(template, compiled, params)
    result = simulate(template, params, ADAPTIVE)
    for name in ("a1", "a2"):
        exact = closed.answers[name].value if closed.answers else None  # type: ignore[union-attr]
        assert isinstance(exact, float) and math.isfinite(exact)
        assert result.answers[name] == pytest.approx(exact, rel=1e-9)


def test_inverse_template_finds_e_by_matching_the_simulated_rebound(bank: dict[str, Template]) -> None:
    """The rebound height is given; e is what makes the simulated rebound reach it."""
    result = simulate(bank["drop-rebound"], {"h_drop": 2100, "h_rebound": 1100}, ADAPTIVE)
    assert result.fitted["e"] == pytest.approx(math.sqrt(1100 / 2100), rel=1e-8)


@pytest.mark.parametrize(("settings", "message"), [
    (lambda: Settings("leapfrog"), "unknown method 'leapfrog' (use one of euler, rk4, adaptive)"),
    (lambda: Settings("rk4", steps=-3), "steps per contact must be a whole number >= 1"),
    (lambda: Settings("adaptive", rtol=0.0), "rtol must be between 1e-13 and 1"),
    (lambda: Options(contact_duration=-1.0), "the contact duration must be a positive number of seconds"),
])
def test_bad_settings_are_refused_with_a_message(settings: object, message: str) -> None:
    """Unknown methods, negative steps, tolerances and durations out of range."""
    with pytest.raises(SimulationError, match=message.replace("(", r"\(").replace(")", r"\)")):
        settings()  # type: ignore[operator]


def test_a_step_above_the_stability_limit_is_refused(two_bodies: tuple[Template, Compiled]) -> None:
    """Euler with one step per contact would blow up: refused with the limit and what to use."""
    template, _ = two_bodies
    with pytest.raises(SimulationError, match=r"stability limit 2/omega .* use at least 2 steps per contact"):
        simulate(template, {"m1": 1.0, "m2": 2.0, "u1": 3.0, "u2": -1.0, "e": 0.7}, Options(Settings("euler", 1)))


def test_a_scene_with_an_effect_without_force_law_is_refused(monkeypatch: pytest.MonkeyPatch,
                                                             bank: dict[str, Template]) -> None:
    """An effect that cannot be simulated is named, with the stage it is in."""
    monkeypatch.setitem(CATALOGUE, "rise", dataclasses.replace(CATALOGUE["rise"], simulate=None))
    with pytest.raises(SimulationError, match=r"stages\[2\]: the effect 'rise' has no force law"):
        simulate(bank["drop-rebound"], {"h_drop": 2100, "h_rebound": 1100})


def test_simulate_cli_json_has_the_documented_shape(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    """One object: template, params, method, effects, steps, seconds, answers with both values; a plot file."""
    plot = tmp_path / "run.png"
    code = main(["simulate", "ball-plate", "--set", "v=50", "--set", "theta=30", "--set", "e=0.5", "--json",
                 "--plot", str(plot)])
    record = json.loads(capsys.readouterr().out)
    assert code == 0
    assert {"template", "params", "method", "effects", "steps", "seconds", "answers"} <= set(record)
    assert record["effects"] == ["contact (Kelvin-Voigt)"]
    assert record["answers"]["v_out"]["rel_diff"] < 1e-8
    assert record["answers"]["v_out"]["closed_form"] == pytest.approx(45.0694, abs=1e-4)
    assert plot.stat().st_size > 10_000


@pytest.mark.parametrize(("argv", "message"), [
    (["--method", "rk4", "--steps-per-contact", "0"], "steps per contact must be a whole number >= 1"),
    (["--method", "euler", "--steps-per-contact", "1"], "stability limit"),
    (["--method", "magic"], "unknown method 'magic'"),
    (["--steps-per-contact", "50"], "--steps-per-contact is for the fixed-step methods"),
    (["--method", "rk4", "--rtol", "1e-6"], "--rtol is for the adaptive method"),
    (["--contact-duration", "0"], "the contact duration must be a positive number"),
])
def test_simulate_cli_bad_input_exits_2(capsys: pytest.CaptureFixture[str], argv: list[str], message: str) -> None:
    """Bad steps, methods and durations: exit 2 with the reason on stderr."""
    code = main(["simulate", "ball-plate", "--set", "v=50", "--set", "theta=30", "--set", "e=0.5", *argv])
    assert code == 2
    assert message in capsys.readouterr().err


@pytest.mark.parametrize("duration", [1e-3, 1.15625e-3])
def test_coarse_euler_is_refused_whatever_the_onset_rounding(duration: float, bank: dict[str, Template]) -> None:
    """Regression: with 4 Euler steps a heavily damped contact reverses within one step; whether that
    counted as an exit hung on a 1e-20 overlap at onset. Now it is refused either way."""
    options = Options(Settings("euler", steps=4), contact_duration=duration)
    with pytest.raises(SimulationError, match="4 steps per contact do not resolve the contact mode"):
        simulate(bank["car-collision"], {"p": 0.5, "e": 0.1}, options)


def test_a_contact_that_never_ends_says_why(bank: dict[str, Template]) -> None:
    """Regression: a soft contact with the weight on leaves the ball resting on the floor."""
    raw = yaml.safe_load((Path(bank["drop-rebound"].where)).read_text(encoding="utf-8"))
    raw["parameters"]["e"] = {"unit": "", "domain": "[0, 1]", "sample": {"uniform": [0.3, 0.9]}, "decimals": 2}
    raw["answers"] = {"h_rebound": {"value": "h_rebound", "unit": "mm"}}
    raw["parameters"].pop("h_rebound")
    for key in ("constraints", "example"):
        raw.pop(key)
    raw["statement"] = "Dropped from {{ h_drop }} mm with e = {{ e }}."
    forward = parse_template(raw, "test:forward", "forward")
    options = Options(contact_duration=0.1, weight_during_contact=True)
    with pytest.raises(SimulationError, match=r"drop-rebound: the contact mode did not end .* the bodies stay in"):
        simulate(forward, {"h_drop": 2000.0, "e": 0.05}, options)


def _simulate_cli(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(["simulate", *argv])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


BALL_PLATE = ("ball-plate", "--set", "v=50", "--set", "theta=30", "--set", "e=0.5")


def test_plot_to_an_unknown_format_is_refused_and_nothing_written(capsys: pytest.CaptureFixture[str],
                                                                  tmp_path: Path) -> None:
    """Regression: --plot x.txt raised matplotlib's ValueError; now exit 2 naming the formats, no file."""
    code, out, err = _simulate_cli(capsys, *BALL_PLATE, "--plot", str(tmp_path / "x.txt"))
    assert (code, out) == (2, "")
    assert "--plot" in err and ".png" in err and ".pdf" in err and "got '.txt'" in err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(("v", "argv", "message"), [
    ("1e307", (), "its size (m, m/s) reaches 1.52e+303, outside [1e-305, 1e+300]"),
    ("1e298", (), "its force per unit mass (m/s^2) reaches 1.58e+301, outside [1e-305, 1e+300]"),
    ("1e-320", (), "outside [1e-305, 1e+300]"),
    ("50", ("--method", "rk4", "--steps-per-contact", "100000"), "steps per contact must be at most 10000"),
])
def test_work_that_would_overflow_or_not_end_is_refused_at_once(capsys: pytest.CaptureFixture[str], v: str,
                                                                argv: tuple[str, ...], message: str) -> None:
    """Regression: v=1e307 and 100000 rk4 steps per contact ran without end; now refused within a
    second, with the limit. (1 ft/s = 0.3048 m/s; 1e298 ft/s at 1 ms: omega v = pi/1e-3 * 0.3048e298.)"""
    started = time.process_time()
    code, _, err = _simulate_cli(capsys, "ball-plate", "--set", f"v={v}", "--set", "theta=30", "--set", "e=0.5",
                                 *argv)
    assert time.process_time() - started < 1.0
    assert code == 2 and message in err and err.count("\n") == 1, err


def test_a_search_that_would_exceed_the_step_limit_is_refused_before_it_starts(bank: dict[str, Template]) -> None:
    """drop-rebound searches e over about 25 passes of 3 stages: 10000 rk4 steps would be 1.5e6 steps."""
    started = time.process_time()
    with pytest.raises(SimulationError, match=r"up to 1,500,000 steps .* limit of 500,000; use at most 3333"):
        simulate(bank["drop-rebound"], {"h_drop": 2100, "h_rebound": 1000}, Options(Settings("rk4", steps=10_000)))
    assert time.process_time() - started < 1.0


def test_a_simulation_over_its_time_limit_stops_with_the_limit(bank: dict[str, Template]) -> None:
    """The wall-clock budget covers every pass of a search."""
    options = Options(Settings("rk4", steps=3000), time_limit=0.05)
    started = time.process_time()
    with pytest.raises(SimulationError, match=r"drop-rebound: the simulation took more than 0.05 s, the limit"):
        simulate(bank["drop-rebound"], {"h_drop": 2100, "h_rebound": 1000}, options)
    assert time.process_time() - started < 1.0


def test_simulate_json_is_strict_and_reports_undefined_with_a_reason(capsys: pytest.CaptureFixture[str]) -> None:
    """Regression: --json wrote NaN/Infinity. Head-on with e = 0 the ball stops: its rebound angle is
    undefined (null, with the closed form's reason), its speed exactly 0 (cos 90 deg is 0)."""
    code, out, _ = _simulate_cli(capsys, "ball-plate", "--set", "v=50", "--set", "theta=90", "--set", "e=0",
                                 "--json")
    record = json.loads(out, parse_constant=lambda constant: pytest.fail(f"not strict JSON: {constant}"))
    assert code == 0
    angle = record["answers"]["theta_out"]
    assert angle["simulated"] is None and angle["closed_form"] is None
    assert angle["undefined"] == {"simulated": "v_out is zero, so it has no direction",
                                  "closed_form": "v_out is zero, so it has no direction"}
    assert record["answers"]["v_out"]["simulated"] == 0.0
    assert record["contacts"][0]["measured_e"] == 0.0


def test_rebound_angle_of_a_stopped_ball_is_undefined_in_the_table(capsys: pytest.CaptureFixture[str]) -> None:
    """Regression: theta=90, e=0 printed theta_out = 78.68 where the closed form says undefined."""
    code, out, _ = _simulate_cli(capsys, "ball-plate", "--set", "v=50", "--set", "theta=90", "--set", "e=0")
    assert code == 0
    assert re.search(r"^theta_out +undefined +undefined +-$", out, re.MULTILINE)
    assert "undefined: v_out is zero, so it has no direction" in out


@pytest.mark.parametrize("method", [Settings(), Settings("rk4", steps=200), Settings("euler", steps=50)])
def test_a_body_stopped_up_to_integration_error_has_no_direction(bank: dict[str, Template],
                                                                 method: Settings) -> None:
    """Regression: equal spheres head-on with e = 1 gave sphere 1 a direction (-90 deg) from a
    leftover speed of 1e-10 v, which is integration error; the closed form says undefined."""
    params = {"v1": 6, "theta": 0, "e": 1, "m1": 1, "m2": 1}
    template = bank["oblique-spheres"]
    closed = solve_one(template, compile_template(template), params)
    assert closed.answers is not None and closed.answers["theta1_out"].value is None  # the reference
    result = simulate(template, params, Options(settings=method))
    assert result.answers["theta1_out"] is None
    assert "within what the simulation resolves" in result.undefined["theta1_out"]
    assert result.answers["v2_out"] == pytest.approx(6.0, rel=1e-2)


@pytest.mark.parametrize(("template_id", "params", "e"), [
    # The ram stops dead: m_ram v = m_pile v_pile, so e = v_pile / v = m_ram / m_pile.
    ("pile-driver", {"m_ram": 800, "m_pile": 2400, "h_drop": 2, "h_rebound": 0}, 1 / 3),
    # The ball does not bounce at all: e = sqrt(h_rebound / h_drop) = 0.
    ("drop-rebound", {"h_drop": 2100, "h_rebound": 0}, 0.0),
])
def test_inverse_scene_with_zero_rebound_finds_e(template_id: str, params: dict[str, float], e: float,
                                                 bank: dict[str, Template]) -> None:
    """Regression: h_rebound = 0 was refused (the rebound height is flat at 0 for every e at which
    the body moves on down); now the search finds the e at which it just stops."""
    result = simulate(bank[template_id], params, ADAPTIVE)
    assert result.answers["e"] == pytest.approx(e, rel=1e-9, abs=1e-12)


def test_refusal_names_the_template_once(capsys: pytest.CaptureFixture[str]) -> None:
    """Regression: 'drop-rebound: drop-rebound: no coefficient ...' repeated the template id."""
    code, _, err = _simulate_cli(capsys, "drop-rebound", "--set", "h_drop=2100", "--set", "h_rebound=2100",
                                 "--weight-during-contact", "--contact-duration", "0.1")
    assert code == 2 and "no coefficient of restitution in [0, 1]" in err
    assert err.count("drop-rebound:") == 1, err


@pytest.mark.parametrize("v", [1e-300, 1e-150, 1e150, 1e290])
def test_tiny_and_huge_speeds_give_the_closed_form_angle(v: float, bank: dict[str, Template]) -> None:
    """Regression: v=1e-300 gave theta_out 7.6 instead of 16.1 (an absolute tolerance floor of 1e-300
    swallowed the motion). tan(theta_out) = e tan(theta): atan(0.5 tan 30 deg) = 16.102113751 deg."""
    result = simulate(bank["ball-plate"], {"v": v, "theta": 30, "e": 0.5}, ADAPTIVE)
    assert result.answers["theta_out"] == pytest.approx(math.degrees(math.atan(0.5 * math.tan(math.pi / 6))),
                                                        rel=1e-8)
    assert result.answers["v_out"] == pytest.approx(v * math.hypot(math.cos(math.pi / 6), 0.5 * 0.5), rel=1e-8)


@pytest.mark.parametrize("e", [0.6, 1.0])
def test_loss_pct_of_a_head_on_impact_is_never_negative(e: float, bank: dict[str, Template]) -> None:
    """Regression: oblique-spheres at theta=0 gave a tiny negative loss_pct (T - T' cancelling).
    Equal masses head-on: loss = 1/2 mu (1 - e^2) v^2 over 1/2 m v^2 = (1 - e^2)/2."""
    params = {"v1": 6, "theta": 0, "e": e, "m1": 1, "m2": 1}
    loss = simulate(bank["oblique-spheres"], params, ADAPTIVE).answers["loss_pct"]
    assert loss is not None and loss >= 0
    assert loss == pytest.approx(100 * (1 - e * e) / 2, rel=1e-8, abs=1e-12)


def test_simulate_never_prints_minus_zero(capsys: pytest.CaptureFixture[str]) -> None:
    """Regression: -0 in the table or the JSON; a ball stopped head-on has v_out = 0, not -0."""
    argv = ("oblique-spheres", "--set", "v1=6", "--set", "theta=0", "--set", "e=0", "--set", "m1=1", "--set", "m2=1")
    code, out, _ = _simulate_cli(capsys, *argv)
    json_code, json_out, _ = _simulate_cli(capsys, *argv, "--json")
    assert code == json_code == 0
    assert not re.search(r"(?<![\w.])-0(?![.\d]*[1-9])", out + json_out), out + json_out


def test_two_unknowns_are_found_one_at_a_time(bank: dict[str, Template], compiled: dict[str, Compiled]) -> None:
    """two-rebounds gives neither e nor the drop height: e is found from the second bounce (the only
    outcome it alone reaches), then h0 from the first; both as the closed form has them."""
    params = {"h1": 1.2, "h2": 0.75}
    result = simulate(bank["two-rebounds"], params, ADAPTIVE)
    assert list(result.fitted) == ["e", "h0"]
    assert result.fitted["h0"] == pytest.approx(1.2**2 / 0.75, rel=1e-9)
    assert max(_compare(bank["two-rebounds"], compiled["two-rebounds"], params, ADAPTIVE).values()) < 1e-8


def test_a_scene_the_solver_finds_coupled_is_simulated_by_one_search() -> None:
    """Given only the drop and the second bounce, e sits in both impacts with h1 between them: the
    step chain refuses it (tests/test_solver.py), yet one search for e reaches the second bounce."""
    raw = yaml.safe_load(TWO_BOUNCES)
    raw["parameters"]["h2"] = raw["parameters"].pop("e") | {"domain": "(0, inf)", "unit": "m"}
    raw["answers"] = {"e": {"value": "e", "unit": ""}}
    raw["statement"] = "Dropped from {{ h_drop }} m, the second bounce reaches {{ h2 }} m."
    template = parse_template(raw, "test:coupled", "coupled")
    result = simulate(template, {"h_drop": 2.0, "h2": 2.0 * 0.8**4, "J": 0.5}, ADAPTIVE)
    assert result.answers["e"] == pytest.approx(0.8, rel=1e-9)


def test_a_plate_moving_at_constant_velocity_keeps_it_through_the_contact(bank: dict[str, Template]) -> None:
    """The plate is a fixed (infinite-mass) body moving up at u: the ball leaves at u + e (v + u)."""
    result = simulate(bank["moving-plate"], {"h": 1.2, "u": 1.5, "e": 0.6}, ADAPTIVE)
    v = math.sqrt(2 * 9.81 * 1.2)
    assert result.answers["v_out"] == pytest.approx(1.5 + 0.6 * (v + 1.5), rel=1e-8)


def test_the_weight_on_an_incline_acts_the_way_the_ball_fell(bank: dict[str, Template],
                                                           compiled: dict[str, Compiled]) -> None:
    """With the weight during contact asked for, gravity acts straight down, at beta to the incline's normal:
    it presses the ball into the plane and speeds it down the slope, so it leaves flatter and faster."""
    params = {"h": 1.2, "beta": 30.0, "e": 0.6}
    closed = solve_one(bank["incline-bounce"], compiled["incline-bounce"], params).answers
    assert closed is not None
    weighted = simulate(bank["incline-bounce"], params, dataclasses.replace(ADAPTIVE, weight_during_contact=True))
    v_out, theta_out = weighted.answers["v_out"], weighted.answers["theta_out"]
    assert v_out is not None and theta_out is not None
    assert 0 < v_out - closed["v_out"].value < 0.01 * closed["v_out"].value  # type: ignore[operator]
    assert 0 < closed["theta_out"].value - theta_out < 0.01 * theta_out  # type: ignore[operator]


@pytest.mark.parametrize("template_id, params", [
    ("billiards", {"v": 2, "r": 28.5, "b": 0, "e": 1}),
    ("billiards", {"v": 2, "r": 28.5, "b": 57 * (1 - 1e-6), "e": 0.9}),
    ("offset-spheres", {"m1": 1e-6, "m2": 1, "r1": 40, "r2": 30, "v1": 5, "b": 35, "e": 0}),
    ("offset-spheres", {"m1": 1e6, "m2": 1, "r1": 1e-3, "r2": 1e3, "v1": 5, "b": 600, "e": 0.6}),
], ids=["head-on-e1", "near-grazing", "light-sphere-1", "heavy-sphere-1"])
def test_the_line_of_centres_is_found_where_the_simulated_spheres_touch(template_id: str, params: dict[str, float],
                                                                      bank: dict[str, Template],
                                                                      compiled: dict[str, Compiled]) -> None:
    """Sphere 1 moves along its line until the centres are r1 + r2 apart (a located event); the line of
    centres measured there, then the contact, give the closed form's answers, head-on to near grazing."""
    assert max(_compare(bank[template_id], compiled[template_id], params, ADAPTIVE).values()) < 1e-8


def test_the_relative_difference_is_measured_against_zero_by_the_difference_itself() -> None:
    """No relative difference is measured against an exact 0: the simulated value itself is how far it is (what
    `grader simulate` printed and `grader check-bank` allowed, each computing it on its own, before one function
    did both); a difference that overflows is the largest float, so that `--json` stays finite."""
    assert relative_difference(1.5, 1.0) == 0.5 and relative_difference(-1.0, 1.0) == 2.0
    assert relative_difference(3e-9, 0.0) == 3e-9 and relative_difference(-3e-9, -0.0) == 3e-9
    assert relative_difference(0.0, 0.0) == 0.0
    assert relative_difference(1e300, 1e-10) == relative_difference(1e308, -1e308) == sys.float_info.max
