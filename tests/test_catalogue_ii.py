"""Physics catalogue II (issue 25): the spring, the slope, two bodies that stick together in a plane, the
impulse and the separation, each through a trial template of tests/data: listed by ``grader effects``,
answered to 1e-12 of a 50-digit mpmath reference written here from first principles (never through the
solver), re-derived by the simulation to 1e-6, and its typical mistakes diagnosed when a student makes them."""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import mpmath as mp
import pytest
import yaml

from grader.bank.template import Template, parse_template
from grader.cli import main
from grader.physics.integrate import Settings, SimulationError
from grader.physics.record import Options
from grader.simulate.walker import simulate
from grader.solve.cache import alternatives_for, compiled_for
from grader.solve.evaluate import solve_one
from tests.test_diagnosis import graded_alone, mistake_value

DATA = Path(__file__).parent / "data"
DIGITS = 50
G = mp.mpf(9.81)  # the templates' g, as the float the kernels use
RTOL = 1e-12
ADAPTIVE = Options(Settings("adaptive", rtol=1e-10))


def trial(name: str) -> Template:
    """A trial template of tests/data."""
    raw = yaml.safe_load((DATA / f"{name}.yaml").read_text(encoding="utf-8"))
    return parse_template(raw, f"tests/data/{name}.yaml", name)


def answers(template: Template, params: Mapping[str, float]) -> dict[str, float]:
    """The kernels' answers, in the template's units."""
    solution = solve_one(template, compiled_for(template), {k: float(v) for k, v in params.items()})
    assert solution.answers is not None, solution.error
    return {name: found.value for name, found in solution.answers.items()}  # type: ignore[misc]


def assert_matches_reference(template: Template, params: Mapping[str, float],
                             reference: Callable[..., Mapping[str, Any]]) -> None:
    with mp.workdps(DIGITS):
        want = reference(**{k: mp.mpf(v) for k, v in params.items()})
        got = answers(template, params)
        for name, value in want.items():
            assert abs(mp.mpf(got[name]) - value) <= RTOL * abs(value), (name, got[name], mp.nstr(value, 20))


def assert_simulated(template: Template, params: Mapping[str, float]) -> None:
    """The simulation of the scene re-derives every numeric answer to 1e-6."""
    closed = answers(template, params)
    simulated = simulate(template, params, ADAPTIVE)
    for name, value in simulated.answers.items():
        assert value is not None
        assert value == pytest.approx(closed[name], rel=1e-6, abs=1e-12), name


def listed(capsys: pytest.CaptureFixture[str], effect: str, fields: set[str]) -> None:
    assert main(["effects"]) == 0
    assert any(line.split()[:1] == [effect] for line in capsys.readouterr().out.splitlines())
    assert main(["effects", effect]) == 0
    out = capsys.readouterr().out
    assert all(f"  {field} " in out for field in fields), out


# --- spring ------------------------------------------------------------------------------------------

BULLET = trial("bullet-spring")
PACKAGE = trial("package-platform")


def ref_bullet_spring(m_b: Any, m_blk: Any, v_b: Any, k: Any) -> dict[str, Any]:
    """Momentum, then the kinetic energy of bullet and block stored in the spring: 1/2 M V^2 = 1/2 k x^2."""
    m_b, k = m_b / 1000, k * 1000  # g, kN/m
    common = m_b * v_b / (m_b + m_blk)
    x = mp.sqrt((m_b + m_blk) * common**2 / k)
    return {"V": common, "x_max": 1000 * x, "E_max": k * x**2 / 2}


def ref_package_platform(m: Any, m_p: Any, h: Any, k: Any) -> dict[str, Any]:
    """Free fall, momentum, then energy from the static deflection to the greatest compression (the
    quadratic's positive root): 1/2 M V^2 + M g (x - delta) = 1/2 k (x^2 - delta^2)."""
    k = k * 1000
    common = m * mp.sqrt(2 * G * h) / (m + m_p)
    mass, delta = m + m_p, m_p * G / k
    constant = mass * common**2 / 2 - mass * G * delta + k * delta**2 / 2
    x = (mass * G + mp.sqrt((mass * G) ** 2 + 2 * k * constant)) / k
    return {"delta": 1000 * delta, "x_max": 1000 * x, "extra": 1000 * (x - delta)}


SPRING_CASES = [
    (BULLET, {"m_b": 10, "m_blk": 2, "v_b": 500, "k": 5}, ref_bullet_spring),
    (BULLET, {"m_b": 1e-9, "m_blk": 1e6, "v_b": 700, "k": 1e-3}, ref_bullet_spring),
    (BULLET, {"m_b": 1e12, "m_blk": 1e-3, "v_b": 1e-150, "k": 1e170}, ref_bullet_spring),
    (PACKAGE, {"m": 10, "m_p": 20, "h": 0.5, "k": 10}, ref_package_platform),
    (PACKAGE, {"m": 1e-9, "m_p": 40, "h": 1.5, "k": 30}, ref_package_platform),  # a hair below its rest
    (PACKAGE, {"m": 10, "m_p": 20, "h": 1e-9, "k": 10}, ref_package_platform),  # barely dropped
    (PACKAGE, {"m": 1e6, "m_p": 1e-3, "h": 1e-12, "k": 1e9}, ref_package_platform),
]


@pytest.mark.parametrize(("template", "params", "reference"), SPRING_CASES,
                         ids=[f"{t.id}-{i}" for i, (t, _, _) in enumerate(SPRING_CASES)])
def test_spring_answers_match_a_50_digit_reference(template: Template, params: dict[str, float],
                                                   reference: Callable[..., Mapping[str, Any]]) -> None:
    assert_matches_reference(template, params, reference)


@pytest.mark.parametrize(("template", "params"), [(BULLET, {"m_b": 10, "m_blk": 2, "v_b": 500, "k": 5}),
                                                  (PACKAGE, {"m": 10, "m_p": 20, "h": 0.5, "k": 10}),
                                                  (PACKAGE, {"m": 2, "m_p": 35, "h": 1.2, "k": 6})])
def test_spring_scenes_are_re_derived_by_hookes_law(template: Template, params: dict[str, float]) -> None:
    assert_simulated(template, params)
    assert "spring (Hooke's law)" in simulate(template, params, ADAPTIVE).effects


def test_a_spring_asked_backwards_is_released_from_its_greatest_compression() -> None:
    """The bullet's speed from the compression: the simulation releases the spring at rest there."""
    raw = yaml.safe_load((DATA / "bullet-spring.yaml").read_text(encoding="utf-8"))
    raw["parameters"]["x_max"] = {"unit": "mm", "domain": "(0, inf)", "sample": {"uniform": [20, 80]}, "decimals": 1}
    del raw["parameters"]["v_b"], raw["answers"]["x_max"], raw["example"]
    raw["answers"]["v_b"] = {"value": "v_b", "unit": "m/s", "description": "speed of the bullet"}
    raw["statement"] = "Given {{ m_b }}, {{ m_blk }}, {{ x_max }} and {{ k }}."
    template = parse_template(raw, "test:bullet-spring-backwards", "bullet-spring-backwards")
    params = {"m_b": 10, "m_blk": 2, "x_max": 49.875, "k": 5}
    by_hand = 49.875e-3 * math.sqrt(5000 / 2.01) * 2.01 / 0.01
    assert answers(template, params)["v_b"] == pytest.approx(by_hand, rel=1e-12)
    assert_simulated(template, params)


SPRING_MISTAKES = [
    # 1/2 M V^2 = 1/2 k x: x = M V^2/k
    (BULLET, {"m_b": 10, "m_blk": 2, "v_b": 500, "k": 5}, "x_max", "spring.half_k_x",
     1000 * 2.01 * (0.01 * 500 / 2.01) ** 2 / 5000),
    # the block's mass alone: x = V sqrt(m_blk/k)
    (BULLET, {"m_b": 30, "m_blk": 1, "v_b": 500, "k": 5}, "x_max", "spring.mass_before_stuck",
     1000 * (0.03 * 500 / 1.03) * math.sqrt(1 / 5000)),
    # from the natural length: 1/2 M V^2 + M g x = 1/2 k x^2
    (PACKAGE, {"m": 10, "m_p": 20, "h": 0.5, "k": 10}, "x_max", "spring.static_deflection_forgotten",
     1000 * (30 * 9.81 + math.sqrt((30 * 9.81) ** 2 + 10000 * 30 * (10 * math.sqrt(2 * 9.81 * 0.5) / 30) ** 2))
     / 10000),
]


def test_spring_energy_in_another_unit_is_correct() -> None:
    """E_max = 6.2189 J typed in kJ, and the compression in m where the sheet asks mm."""
    params = {"m_b": 10, "m_blk": 2, "v_b": 500, "k": 5}
    assert graded_alone(BULLET, params, "E_max", "0.00622 kJ").verdict == "correct"
    assert graded_alone(BULLET, params, "E_max", "4.587 ft·lb").verdict == "correct"
    assert graded_alone(BULLET, params, "x_max", "0.0499 m").verdict == "correct"


def test_the_spring_is_listed_with_its_fields(capsys: pytest.CaptureFixture[str]) -> None:
    listed(capsys, "spring", {"body", "with", "stiffness", "speed", "compression", "initial", "vertical",
                              "supports", "static_deflection", "energy", "travel"})


def test_a_support_needs_a_vertical_spring() -> None:
    raw = yaml.safe_load((DATA / "package-platform.yaml").read_text(encoding="utf-8"))
    del raw["stages"][2]["vertical"]
    template = parse_template(raw, "test:package-platform", "package-platform-flat")
    with pytest.raises(Exception, match="vertical: true"):
        compiled_for(template)


TRIALS = ("bullet-spring", "package-platform", "ramp-and-floor", "incline-up-and-back", "intersection",
          "intersection-reconstruction", "ball-wall-impulse", "cushion", "floor-push", "recoil", "explosion",
          "explosion-before", "oblique-both-moving")
"""Issue 25's trial templates in tests/data, until the bank carries templates of these effects."""


@pytest.mark.slow  # 4 s; the shipped bank III templates of these effects pass check-bank in the default run
def test_check_bank_passes_every_trial_template(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Sampled, solved, simulated (to 1e-6 on 4 draws) and typeset, sheet and key: an effect without a figure
    panel of its own falls back to the figure its other stages choose, or its bodies in a row."""
    for name in TRIALS:
        (tmp_path / f"{name}.yaml").write_text((DATA / f"{name}.yaml").read_text(encoding="utf-8"), encoding="utf-8")
    code = main(["check-bank", "--bank", str(tmp_path), "--no-shipped-bank"])
    out = capsys.readouterr().out
    assert code == 0, out
    assert out.count(" ok ") == len(TRIALS), out


# --- slope -------------------------------------------------------------------------------------------

RAMP = trial("ramp-and-floor")
INCLINE = trial("incline-up-and-back")


def ref_ramp_and_floor(h: Any, v0: Any, mu_k: Any) -> dict[str, Any]:
    """Energy down the smooth ramp, then the friction force mu_k m g's work takes the kinetic energy."""
    v_foot = mp.sqrt(v0**2 + 2 * G * h)
    return {"v_B": v_foot, "d": v_foot**2 / (2 * mu_k * G)}


def ref_incline(v0: Any, beta: Any, mu_k: Any) -> dict[str, Any]:
    """Up: gravity's component and friction decelerate it; down from rest: gravity's component less friction."""
    beta = beta * mp.pi / 180
    up = G * (mp.sin(beta) + mu_k * mp.cos(beta))
    down = G * (mp.sin(beta) - mu_k * mp.cos(beta))
    d = v0**2 / (2 * up)
    return {"d": d, "v_back": mp.sqrt(2 * down * d)}


SLOPE_CASES = [
    (RAMP, {"h": 1.2, "v0": 1, "mu_k": 0.3}, ref_ramp_and_floor),
    (RAMP, {"h": 1e-12, "v0": 0, "mu_k": 1e-9}, ref_ramp_and_floor),
    (RAMP, {"h": 1e-9, "v0": 1e3, "mu_k": 0.5}, ref_ramp_and_floor),  # the ramp adds a hair to a fast block
    (INCLINE, {"v0": 5, "beta": 30, "mu_k": 0.2}, ref_incline),
    (INCLINE, {"v0": 1e-150, "beta": 89.9, "mu_k": 0}, ref_incline),
    (INCLINE, {"v0": 7, "beta": 1e-6, "mu_k": 1e-12}, ref_incline),
]


@pytest.mark.parametrize(("template", "params", "reference"), SLOPE_CASES,
                         ids=[f"{t.id}-{i}" for i, (t, _, _) in enumerate(SLOPE_CASES)])
def test_slope_answers_match_a_50_digit_reference(template: Template, params: dict[str, float],
                                                  reference: Callable[..., Mapping[str, Any]]) -> None:
    assert_matches_reference(template, params, reference)


@pytest.mark.parametrize(("template", "params"), [(RAMP, {"h": 1.2, "v0": 1, "mu_k": 0.3}),
                                                  (RAMP, {"h": 2.5, "v0": 0, "mu_k": 0.55}),
                                                  (INCLINE, {"v0": 5, "beta": 30, "mu_k": 0.2})])
def test_slope_scenes_are_re_derived_by_gravity_and_friction(template: Template, params: dict[str, float]) -> None:
    assert_simulated(template, params)


def test_the_ramp_is_a_descent_not_a_fall() -> None:
    """The key says the block descends the ramp, and no step of it says it falls."""
    steps = [step.relation for step in compiled_for(RAMP).steps]
    assert any("descends a smooth ramp" in label for label in steps), steps
    assert not any("falls" in label for label in steps), steps


def test_friction_asked_from_the_slide_is_found_by_the_simulation_too() -> None:
    """mu_k from the distance slid along the floor: the closed form, and the simulation's search."""
    raw = yaml.safe_load((DATA / "ramp-and-floor.yaml").read_text(encoding="utf-8"))
    raw["parameters"]["d"] = {"unit": "m", "domain": "(0, inf)", "sample": {"uniform": [2, 8]}, "decimals": 2}
    del raw["parameters"]["mu_k"], raw["answers"]["d"], raw["example"]
    raw["answers"]["mu_k"] = {"value": "mu_k", "unit": "", "description": "coefficient of kinetic friction"}
    raw["statement"] = "Given {{ h }}, {{ v0 }} and {{ d }}."
    template = parse_template(raw, "test:ramp-and-floor-friction", "ramp-and-floor-friction")
    params = {"h": 1.2, "v0": 1, "d": 4.17}
    assert answers(template, params)["mu_k"] == pytest.approx((1 + 2 * 9.81 * 1.2) / (2 * 9.81 * 4.17), rel=1e-12)
    assert_simulated(template, params)


def test_a_body_that_does_not_stay_at_rest_is_refused() -> None:
    """With mu_s given, a block come to rest on a slope steeper than atan(mu_s) is refused, with the reason."""
    raw = yaml.safe_load((DATA / "incline-up-and-back.yaml").read_text(encoding="utf-8"))
    raw["stages"] = raw["stages"][:1]
    raw["stages"][0]["static"] = "mu_s"
    raw["parameters"]["mu_s"] = {"unit": "", "domain": "[0, inf)", "sample": {"uniform": [0.9, 1.2]}, "decimals": 2}
    raw["answers"] = {"d": raw["answers"]["d"]}
    raw["statement"] = "Given {{ v0 }}, {{ beta }}, {{ mu_k }} and {{ mu_s }}."
    raw["example"] = {"v0": 5, "beta": 30, "mu_k": 0.2, "mu_s": 0.9}
    template = parse_template(raw, "test:incline-stays", "incline-stays")
    assert answers(template, {"v0": 5, "beta": 30, "mu_k": 0.2, "mu_s": 0.9})["d"] == pytest.approx(1.8928, rel=1e-4)
    refused = solve_one(template, compiled_for(template), {"v0": 5, "beta": 45, "mu_k": 0.2, "mu_s": 0.9})
    assert refused.answers is None and "slides off again" in str(refused.error)


def incline_up() -> Template:
    """The incline's first stage alone: how far up the block slides."""
    raw = yaml.safe_load((DATA / "incline-up-and-back.yaml").read_text(encoding="utf-8"))
    raw["stages"], raw["answers"] = raw["stages"][:1], {"d": raw["answers"]["d"]}
    raw["statement"] = "Given {{ v0 }}, {{ beta }} and {{ mu_k }}."
    return parse_template(raw, "test:incline-up", "incline-up")


SLOPE_MISTAKES = [
    # mu_k m g for mu_k m g cos(beta): d = v0^2 / (2 g (sin beta + mu_k))
    (INCLINE, {"v0": 5, "beta": 30, "mu_k": 0.2}, "d", "slope.friction_without_cos",
     25 / (2 * 9.81 * (0.5 + 0.2))),
    # gravity's component helping the block up: d = v0^2 / (2 g (mu_k cos beta - sin beta))
    (incline_up(), {"v0": 5, "beta": 20, "mu_k": 0.8}, "d", "slope.gravity_sign",
     25 / (2 * 9.81 * (0.8 * math.cos(math.radians(20)) - math.sin(math.radians(20))))),
    # no friction: d = v0^2 / (2 g sin beta)
    (INCLINE, {"v0": 5, "beta": 30, "mu_k": 0.2}, "d", "slope.friction_left_out", 25 / (2 * 9.81 * 0.5)),
]


def test_the_slope_is_listed_with_its_fields(capsys: pytest.CaptureFixture[str]) -> None:
    listed(capsys, "slope", {"body", "with", "speed", "end_speed", "distance", "angle", "direction", "height",
                             "friction", "static"})


# --- stick -------------------------------------------------------------------------------------------

CARS = trial("intersection")
RECONSTRUCTION = trial("intersection-reconstruction")
KMH = mp.mpf(1000) / 3600


def ref_intersection(m_A: Any, m_B: Any, v_A: Any, v_B: Any) -> dict[str, Any]:  # noqa: N803 (its names)
    """Momentum east and north; the kinetic energies before and after as sums of 1/2 m v^2."""
    east, north = m_B * v_B / (m_A + m_B), m_A * v_A / (m_A + m_B)
    before = (m_A * v_A**2 + m_B * v_B**2) / 2
    after = (m_A + m_B) * (east**2 + north**2) / 2
    return {"v": mp.hypot(east, north), "theta": mp.degrees(mp.atan2(north, east)),
            "loss_pct": 100 * (before - after) / before}


def ref_reconstruction(m_A: Any, m_B: Any, v_B: Any, theta: Any) -> dict[str, Any]:  # noqa: N803 (its names)
    """East from B's momentum, north from the wreck's direction, car A's speed from the momentum north."""
    east = m_B * v_B / (m_A + m_B)
    north = east * mp.tan(mp.radians(theta))
    return {"v_A": (m_A + m_B) * north / m_A, "v": mp.hypot(east, north)}


STICK_CASES = [
    (CARS, {"m_A": 1500, "m_B": 1200, "v_A": 50, "v_B": 60}, ref_intersection),
    (CARS, {"m_A": 1e-9, "m_B": 1e3, "v_A": 1e170, "v_B": 1e-150}, ref_intersection),
    (CARS, {"m_A": 1e12, "m_B": 1, "v_A": 30, "v_B": 80}, ref_intersection),
    (RECONSTRUCTION, {"m_A": 1500, "m_B": 1200, "v_B": 60, "theta": 40}, ref_reconstruction),
    (RECONSTRUCTION, {"m_A": 1e-6, "m_B": 2000, "v_B": 60, "theta": 1e-9}, ref_reconstruction),
    (RECONSTRUCTION, {"m_A": 1500, "m_B": 1200, "v_B": 60, "theta": 89.9}, ref_reconstruction),  # tan near its pole
]


@pytest.mark.parametrize(("template", "params", "reference"), STICK_CASES,
                         ids=[f"{t.id}-{i}" for i, (t, _, _) in enumerate(STICK_CASES)])
def test_stick_answers_match_a_50_digit_reference(template: Template, params: dict[str, float],
                                                  reference: Callable[..., Mapping[str, Any]]) -> None:
    assert_matches_reference(template, params, reference)


@pytest.mark.parametrize(("template", "params"), [(CARS, {"m_A": 1500, "m_B": 1200, "v_A": 50, "v_B": 60}),
                                                  (CARS, {"m_A": 900, "m_B": 2000, "v_A": 80, "v_B": 30}),
                                                  (RECONSTRUCTION, {"m_A": 1500, "m_B": 1200, "v_B": 60,
                                                                    "theta": 40})])
def test_stick_scenes_are_re_derived_by_a_plastic_contact(template: Template, params: dict[str, float]) -> None:
    """Forward, and asked backward (the simulation searches for car A's speed that sends the wreck off at
    the given direction)."""
    assert_simulated(template, params)


def test_a_wreck_that_does_not_move_has_no_direction() -> None:
    """Equal and opposite momenta: the direction is undefined, with the reason, not an angle of 0."""
    raw = yaml.safe_load((DATA / "intersection.yaml").read_text(encoding="utf-8"))
    raw["stages"][0]["before"] = {"A": {"n": "-v_A", "t": 0}, "B": {"n": "v_B", "t": 0}}
    template = parse_template(raw, "test:head-on-lock", "head-on-lock")
    solution = solve_one(template, compiled_for(template), {"m_A": 1500, "m_B": 1000, "v_A": 40, "v_B": 60})
    assert solution.answers is not None and solution.answers["v"].value == 0
    assert solution.answers["theta"].value is None and "no direction" in str(solution.answers["theta"].undefined)


STICK_MISTAKES = [
    # (m_A |u_A| + m_B |u_B|)/(m_A + m_B) = (1500 * 50 + 1200 * 60)/2700 km/h
    (CARS, {"m_A": 1500, "m_B": 1200, "v_A": 50, "v_B": 60}, "v", "stick.speeds_added", (1500 * 50 + 1200 * 60) / 2700),
    # from north instead of east: atan(east/north)
    (CARS, {"m_A": 1500, "m_B": 1200, "v_A": 50, "v_B": 60}, "theta", "stick.angle_other_axis",
     math.degrees(math.atan2(1200 * 60, 1500 * 50))),
    # the direction from the other axis turns the reconstruction: north = east / tan(theta)
    (RECONSTRUCTION, {"m_A": 1500, "m_B": 1200, "v_B": 60, "theta": 40}, "v_A", "stick.angle_other_axis",
     1200 * 60 / math.tan(math.radians(40)) / 1500),
]


def test_stick_is_listed_with_its_fields(capsys: pytest.CaptureFixture[str]) -> None:
    listed(capsys, "stick", {"bodies", "before", "common", "speed", "angle", "from", "energy_lost", "loss_fraction"})


# --- impulse -----------------------------------------------------------------------------------------

WALL = trial("ball-wall-impulse")
CUSHION = trial("cushion")


def ref_ball_wall(m: Any, v: Any, e: Any, dt: Any) -> dict[str, Any]:
    """The rebound at e v the other way: the impulse m (v + e v), over the contact time."""
    impulse = m / 1000 * (v + e * v)
    return {"J": impulse, "F": impulse / (dt / 1000)}


def ref_cushion(m: Any, h: Any, d: Any) -> dict[str, Any]:
    """Fall: v = sqrt(2 g h); the cushion takes m v; work-energy over d with the weight: (F - m g) d = 1/2 m v^2."""
    v = mp.sqrt(2 * G * h)
    return {"J": m * v, "F": (m * v**2 / 2 / (d / 1000) + m * G) / 1000}


IMPULSE_CASES = [
    (WALL, {"m": 200, "v": 12, "e": 0.6, "dt": 8}, ref_ball_wall),
    (WALL, {"m": 1e-9, "v": 1e170, "e": 1 - 1e-12, "dt": 1e-9}, ref_ball_wall),
    (WALL, {"m": 50, "v": 1e-150, "e": 0, "dt": 20}, ref_ball_wall),
    (CUSHION, {"m": 10, "h": 1.5, "d": 80}, ref_cushion),
    (CUSHION, {"m": 1e6, "h": 1e-12, "d": 1e9}, ref_cushion),  # the weight all but alone
]


@pytest.mark.parametrize(("template", "params", "reference"), IMPULSE_CASES,
                         ids=[f"{t.id}-{i}" for i, (t, _, _) in enumerate(IMPULSE_CASES)])
def test_impulse_answers_match_a_50_digit_reference(template: Template, params: dict[str, float],
                                                    reference: Callable[..., Mapping[str, Any]]) -> None:
    assert_matches_reference(template, params, reference)


@pytest.mark.parametrize(("template", "params"), [(WALL, {"m": 200, "v": 12, "e": 0.6, "dt": 8}),
                                                  (WALL, {"m": 50, "v": 1e-150, "e": 0, "dt": 20}),
                                                  (CUSHION, {"m": 10, "h": 1.5, "d": 80}),
                                                  (CUSHION, {"m": 1e6, "h": 1e-12, "d": 1e9})])
def test_impulse_scenes_are_re_derived_by_the_simulation(template: Template, params: dict[str, float]) -> None:
    assert_simulated(template, params)


FLOOR = trial("floor-push")


def ref_floor_push(m: Any, v: Any, dt: Any, F: Any) -> dict[str, Any]:  # noqa: N803 (its names)
    """Impulse-momentum along n (up) with the weight: m v_up - m (-v) = (F - m g) dt."""
    dt = dt / 1000
    v_up = -v + (F - m * G) * dt / m
    return {"v_up": v_up, "J": m * (v_up + v)}


def test_the_impulse_is_simulated_by_integrating_a_force_pulse() -> None:
    """The wall's force on the ball is a parabolic pulse over the contact time, integrated step by step: not the
    impulse taken from the velocities the impact gives."""
    simulated = simulate(WALL, {"m": 200, "v": 12, "e": 0.6, "dt": 8}, ADAPTIVE)
    assert "force pulse over the contact time (parabolic)" in simulated.effects
    phase = next(p for p in simulated.phases if p.label == "the force on ball")
    assert phase.path.steps > 1 and phase.path.t[-1] == pytest.approx(0.008, rel=1e-12)
    # against the ball's motion (-n), 6 s (1 - s) times its mean F = 480 N at s = t/dt: 3/2 of it at its peak
    for t, force in zip(phase.path.t, phase.path.force, strict=True):
        assert force == pytest.approx(-6 * 480 * (t / 0.008) * (1 - t / 0.008), rel=1e-9, abs=1e-9)


@pytest.mark.parametrize("params", [{"m": 0.5, "v": 6, "dt": 8, "F": 700},
                                    {"m": 2, "v": 0.5, "dt": 20, "F": 30},  # the weight all but cancels it
                                    {"m": 1e-6, "v": 1e3, "dt": 1e-6, "F": 3e-3}])
def test_a_given_force_drives_the_body_to_its_velocity_after(params: dict[str, float]) -> None:
    """The force the scene gives is the input: the velocity after is what its integration gives, to 1e-6 of the
    50-digit reference and of the closed form."""
    assert_matches_reference(FLOOR, params, ref_floor_push)
    assert_simulated(FLOOR, params)
    with mp.workdps(DIGITS):
        want = ref_floor_push(**{k: mp.mpf(v) for k, v in params.items()})
    got = simulate(FLOOR, params, ADAPTIVE).answers["v_up"]
    assert got == pytest.approx(float(want["v_up"]), rel=1e-8)


def cushion_through() -> Template:
    """The cushion's force given and the speed after the distance asked (the solver refuses it: v' from v'**2 has two
    signs; the simulation is run alone)."""
    raw = yaml.safe_load((DATA / "cushion.yaml").read_text(encoding="utf-8"))
    raw["stages"] = raw["stages"][1:]
    raw["stages"][0]["velocity"] = {"n": "-v", "t": 0}
    raw["stages"][0]["velocity_after"] = {"n": "-v2", "t": 0}
    del raw["parameters"]["h"]
    raw["parameters"]["v"] = {"unit": "m/s", "domain": "(0, inf)", "sample": {"uniform": [4, 8]}, "decimals": 1}
    raw["parameters"]["F"] = {"unit": "N", "domain": "(0, inf)", "sample": {"uniform": [500, 1000]}, "decimals": 0}
    raw["answers"] = {"v2": {"value": "v2", "unit": "m/s", "description": "speed after"}}
    raw["statement"], raw["example"] = "Given {{ m }}, {{ v }}, {{ d }} and {{ F }}.", {"m": 10, "v": 6, "d": 80,
                                                                                      "F": 1000}
    return parse_template(raw, "test:cushion-through", "cushion-through")


def test_a_given_force_over_a_distance_is_integrated_until_the_body_has_travelled_it() -> None:
    """Work-energy with the weight, (F - m g) d = 1/2 m (v**2 - v'**2), by a 50-digit reference; a force that stops
    the body short of the distance is refused, saying where it stops."""
    template = cushion_through()
    with mp.workdps(DIGITS):
        m, v, d, force = mp.mpf(10), mp.mpf(6), mp.mpf("0.08"), mp.mpf(1000)
        want = mp.sqrt(v**2 - 2 * (force / m - G) * d)
    got = simulate(template, {"m": 10, "v": 6, "d": 80, "F": 1000}, ADAPTIVE)
    assert got.answers["v2"] == pytest.approx(float(want), rel=1e-9)
    assert "constant force over a distance" in got.effects
    with pytest.raises(SimulationError, match=r"stops package within 0\.1996 m, before it has moved the distance d"):
        simulate(template, {"m": 10, "v": 6, "d": 800, "F": 1000}, ADAPTIVE)


def cushion_height() -> Template:
    """The cushion's average force given and the drop height asked: the simulation searches for the height whose
    fall the force, found from the stop, reproduces."""
    raw = yaml.safe_load((DATA / "cushion.yaml").read_text(encoding="utf-8"))
    del raw["parameters"]["h"]
    raw["parameters"]["F"] = {"unit": "kN", "domain": "(0, inf)", "sample": {"uniform": [1, 3]}, "decimals": 2}
    raw["answers"] = {"h": {"value": "h", "unit": "m", "description": "height of the drop"},
                      "J": {"value": "J", "unit": "N·s", "description": "impulse of the cushion"}}
    raw["statement"], raw["example"] = "Given {{ m }}, {{ F }} and {{ d }}.", {"m": 10, "F": 2, "d": 80}
    return parse_template(raw, "test:cushion-height", "cushion-height")


def test_the_drop_height_is_found_from_the_cushions_force() -> None:
    """(F - m g) d = m g h (the fall's energy, taken by the cushion with the weight's work), by a 50-digit
    reference; the simulation's search finds h."""
    params = {"m": 10, "F": 2, "d": 80}
    with mp.workdps(DIGITS):
        m, force, d = mp.mpf(10), mp.mpf(2000), mp.mpf("0.08")
        h = (force - m * G) * d / (m * G)
        assert_matches_reference(cushion_height(), params, lambda **_: {"h": h, "J": m * mp.sqrt(2 * G * h)})
    assert_simulated(cushion_height(), params)


def rebound_given() -> Template:
    """The ball's rebound speed given instead of e: the impulse stage alone (with e, the impact's own
    "rebound's sign turned" mistake gives the same number first)."""
    raw = yaml.safe_load((DATA / "ball-wall-impulse.yaml").read_text(encoding="utf-8"))
    raw["stages"] = raw["stages"][1:]
    raw["stages"][0]["velocity_after"] = {"n": "-v2", "t": 0}
    raw["parameters"]["v2"] = {**raw["parameters"].pop("e"), "unit": "m/s", "domain": "[0, inf)",
                               "sample": {"uniform": [2, 5]}}
    raw["statement"], raw["example"] = "Given {{ m }}, {{ v }}, {{ v2 }} and {{ dt }}.", {"m": 200, "v": 12, "v2": 7.2,
                                                                                        "dt": 8}
    return parse_template(raw, "test:rebound-given", "rebound-given")


IMPULSE_MISTAKES = [
    # m (|v'| - |v|) = 0.2 (7.2 - 12): the magnitude 0.96 N s
    (rebound_given(), {"m": 200, "v": 12, "v2": 7.2, "dt": 8}, "J", "impulse.speeds_for_velocities",
     0.2 * (12 - 7.2)),
    # the weight left out, which the scene declares: m v^2 / (2 d) in kN
    (CUSHION, {"m": 10, "h": 1.5, "d": 80}, "F", "impulse.weight", 10 * 2 * 9.81 * 1.5 / (2 * 0.08) / 1000),
]


@pytest.mark.parametrize(("template", "params", "answer", "typed"), [
    (WALL, {"m": 200, "v": 12, "e": 0.6, "dt": 8}, "J", "3.84 N*s"),
    (WALL, {"m": 200, "v": 12, "e": 0.6, "dt": 8}, "J", "0.863 lb·s"),
    (WALL, {"m": 200, "v": 12, "e": 0.6, "dt": 8}, "F", "0.48 kN"),
    (CUSHION, {"m": 10, "h": 1.5, "d": 80}, "F", "1937.5 N"),
])
def test_impulse_and_force_in_other_units_are_correct(template: Template, params: dict[str, float], answer: str,
                                                      typed: str) -> None:
    assert graded_alone(template, params, answer, typed).verdict == "correct"


def test_the_impulse_is_listed_with_its_fields(capsys: pytest.CaptureFixture[str]) -> None:
    listed(capsys, "impulse", {"body", "velocity", "velocity_after", "components", "impulse", "angle", "time",
                               "distance", "force", "weight"})


# --- separation --------------------------------------------------------------------------------------

RECOIL = trial("recoil")
EXPLOSION = trial("explosion")


def ref_recoil(m_gun: Any, m_b: Any, u: Any) -> dict[str, Any]:
    """Momentum from rest, m_gun v_gun + m_b v_b = 0, with v_b - v_gun = u; energy as the sum of 1/2 m v^2."""
    m_b = m_b / 1000
    v_b = m_gun * u / (m_gun + m_b)
    v_gun = v_b - u
    return {"v_recoil": -v_gun, "v_b": v_b, "E": (m_gun * v_gun**2 + m_b * v_b**2) / 2 / 1000}


def ref_explosion(m1: Any, m2: Any, V: Any, E: Any) -> dict[str, Any]:  # noqa: N803 (its names)
    """Momentum (m1 + m2) V = m1 v1 + m2 v2 and energy 1/2 m1 v1^2 + 1/2 m2 v2^2 = 1/2 (m1 + m2) V^2 + E, solved
    as a quadratic for v2 (the front fragment faster)."""
    released, total = E * 1000, m1 + m2
    # v1 = (total V - m2 v2)/m1 into the energy: a v2^2 + b v2 + c = 0
    a = m2 + m2**2 / m1
    b = -2 * total * V * m2 / m1
    c = total**2 * V**2 / m1 - total * V**2 - 2 * released
    v2 = (-b + mp.sqrt(b**2 - 4 * a * c)) / (2 * a)
    return {"v1": (total * V - m2 * v2) / m1, "v2": v2}


SEPARATION_CASES = [
    (RECOIL, {"m_gun": 4, "m_b": 20, "u": 600}, ref_recoil),
    (RECOIL, {"m_gun": 1e9, "m_b": 1e-6, "u": 1e3}, ref_recoil),
    (EXPLOSION, {"m1": 4, "m2": 6, "V": 200, "E": 24}, ref_explosion),
    (EXPLOSION, {"m1": 4, "m2": 6, "V": 200, "E": 1e-20}, ref_explosion),  # a puff: the fragments barely part
]


@pytest.mark.parametrize(("template", "params", "reference"), SEPARATION_CASES,
                         ids=[f"{t.id}-{i}" for i, (t, _, _) in enumerate(SEPARATION_CASES)])
def test_separation_answers_match_a_50_digit_reference(template: Template, params: dict[str, float],
                                                       reference: Callable[..., Mapping[str, Any]]) -> None:
    assert_matches_reference(template, params, reference)


@pytest.mark.parametrize(("template", "params"), [(RECOIL, {"m_gun": 4, "m_b": 20, "u": 600}),
                                                  (EXPLOSION, {"m1": 4, "m2": 6, "V": 200, "E": 24}),
                                                  (EXPLOSION, {"m1": 9, "m2": 2.5, "V": -150, "E": 40})])
def test_separation_scenes_are_re_derived_by_a_spring_between_the_parts(template: Template,
                                                                        params: dict[str, float]) -> None:
    assert_simulated(template, params)


EXPLOSION_BEFORE = trial("explosion-before")


def ref_explosion_before(m1: Any, m2: Any, v1: Any, E: Any) -> dict[str, Any]:  # noqa: N803 (its names)
    """Momentum M V = m1 v1 + m2 v2 and energy 1/2 m1 v1^2 + 1/2 m2 v2^2 = 1/2 M V^2 + E with V put in, a quadratic
    for v2 whose larger root is the front fragment's (it moves off ahead of the rear one)."""
    released, total = E * 1000, m1 + m2
    a = m2 - m2**2 / total
    b = -2 * m1 * m2 * v1 / total
    c = m1 * v1**2 - (m1 * v1) ** 2 / total - 2 * released
    v2 = (-b + mp.sqrt(b**2 - 4 * a * c)) / (2 * a)
    return {"V": (m1 * v1 + m2 * v2) / total, "v2": v2}


@pytest.mark.parametrize("params", [{"m1": 4, "m2": 6, "v1": 40, "E": 24},
                                    {"m1": 4, "m2": 6, "v1": -400, "E": 24},  # the shell was flying backwards
                                    {"m1": 9, "m2": 2.5, "v1": 0, "E": 40},
                                    {"m1": 1e-3, "m2": 1e3, "v1": 250, "E": 1e-3}])
def test_the_whole_velocity_before_a_separation_is_found_by_the_simulation(params: dict[str, float]) -> None:
    """The shell's velocity before it explodes asked (the rear fragment's after given): the simulation searches
    for it both ways from 0, so that the spring between the parts leaves the rear fragment at the given velocity."""
    assert_matches_reference(EXPLOSION_BEFORE, params, ref_explosion_before)
    assert_simulated(EXPLOSION_BEFORE, params)
    assert set(simulate(EXPLOSION_BEFORE, params, ADAPTIVE).fitted) == {"V"}


SEPARATION_MISTAKES = [
    # each fragment's speed relative to the shell sqrt(2 E/(m1 + m2)): v2 = 200 + sqrt(48000/10)
    (EXPLOSION, {"m1": 4, "m2": 6, "V": 200, "E": 24}, "v2", "separation.mass_ratio", 200 + math.sqrt(48000 / 10)),
    # a heavy shot leaves at u itself (a bullet of 20 g would be within the tolerance of it)
    (RECOIL, {"m_gun": 4, "m_b": 2000, "u": 600}, "v_b", "separation.relative_as_absolute", 600.0),
]


def test_the_separation_is_listed_with_its_fields(capsys: pytest.CaptureFixture[str]) -> None:
    listed(capsys, "separation", {"bodies", "whole", "after", "energy", "relative"})


# --- oblique impact of two moving bodies, the separation given in place of e -------------------------

OBLIQUE = trial("oblique-both-moving")


def ref_oblique_both_moving(m_A: Any, m_B: Any, v_A: Any, alpha: Any, v_B: Any, beta: Any,  # noqa: N803
                            s: Any) -> dict[str, Any]:
    """Components along the line of centres n and the tangent t; e = separation/approach; along n momentum and
    the separation give the velocities after; along t nothing changes (smooth); energies as 1/2 m v^2."""
    a_n, a_t = v_A * mp.cos(mp.radians(alpha)), v_A * mp.sin(mp.radians(alpha))
    b_n, b_t = -v_B * mp.cos(mp.radians(beta)), v_B * mp.sin(mp.radians(beta))
    e = s / (a_n - b_n)
    # m_A a_n + m_B b_n = m_A x + m_B (x + s)
    after_a = (m_A * a_n + m_B * b_n - m_B * s) / (m_A + m_B)
    after_b = after_a + s
    before = (m_A * (a_n**2 + a_t**2) + m_B * (b_n**2 + b_t**2)) / 2
    after = (m_A * (after_a**2 + a_t**2) + m_B * (after_b**2 + b_t**2)) / 2
    return {"e": e, "vB_n": after_b, "vA_out": mp.hypot(after_a, a_t), "loss_pct": 100 * (before - after) / before}


@pytest.mark.parametrize("params", [
    {"m_A": 2, "m_B": 1.5, "v_A": 6, "alpha": 30, "v_B": 2, "beta": 45, "s": 2.4},
    {"m_A": 1e-6, "m_B": 1e6, "v_A": 6, "alpha": 89, "v_B": 2, "beta": 0, "s": 1e-9},
    {"m_A": 2, "m_B": 3, "v_A": 5, "alpha": 0, "v_B": 5, "beta": 0, "s": 10},  # head-on, elastic
])
def test_two_moving_spheres_match_a_50_digit_reference(params: dict[str, float]) -> None:
    assert_matches_reference(OBLIQUE, params, ref_oblique_both_moving)


def test_two_moving_spheres_are_re_derived_by_the_simulation_searching_for_e() -> None:
    """e is not given: the simulation finds the e whose contact separates the spheres at the given speed."""
    params = {"m_A": 2, "m_B": 1.5, "v_A": 6, "alpha": 30, "v_B": 2, "beta": 45, "s": 2.4}
    assert_simulated(OBLIQUE, params)
    assert "e" in simulate(OBLIQUE, params, ADAPTIVE).fitted


@pytest.mark.slow  # 4 s: grades every mistake of a scene; the default run keeps the per-effect mistake tests
def test_the_separation_in_place_of_e_keeps_the_impacts_mistakes() -> None:
    """1/e for e (approach over separation): e = (approach)/s."""
    params = {"m_A": 2, "m_B": 1.5, "v_A": 6, "alpha": 30, "v_B": 2, "beta": 45, "s": 2.4}
    approach = 6 * math.cos(math.radians(30)) + 2 * math.cos(math.radians(45))
    assert mistake_value(alternatives_for(OBLIQUE), params, "e", "impact.e_inverse") == pytest.approx(approach / 2.4)


# --- every effect's diagnosed mistakes -----------------------------------------------------------------

MISTAKES = SPRING_MISTAKES + SLOPE_MISTAKES + STICK_MISTAKES + IMPULSE_MISTAKES + SEPARATION_MISTAKES


@pytest.mark.parametrize(("template", "params", "answer", "mistake", "by_hand"), MISTAKES,
                         ids=[f"{m[0].id}-{m[3]}" for m in MISTAKES])
def test_a_new_effects_mistake_is_diagnosed(template: Template, params: dict[str, float], answer: str,
                                            mistake: str, by_hand: float) -> None:
    """The solver's chain under the mistake, against the variant worked by hand with it; and that answer typed
    to 4 significant figures is graded ``mistake`` with the mistake's id."""
    assert mistake_value(alternatives_for(template), params, answer, mistake) == pytest.approx(by_hand, rel=1e-9)
    verdict = graded_alone(template, params, answer, f"{by_hand:.4g}")
    assert (verdict.verdict, verdict.diagnosis) == ("mistake", mistake), verdict


# --- the units that come with them ---------------------------------------------------------------------

LBF, INCH, FOOT = 4.4482216152605, 0.0254, 0.3048  # N, m, m: the international pound-force, inch and foot


@pytest.mark.parametrize(("typed", "key", "factor"), [
    ("kN", "N", 1000), ("N/m", "kN/m", 1e-3), ("kN/m", "N/m", 1000), ("lb/in", "N/m", LBF / INCH),
    ("N·s", "N*s", 1), ("N s", "N·s", 1), ("lb·s", "N·s", LBF), ("kJ", "J", 1000), ("ft·lb", "J", FOOT * LBF),
    ("ft-lb", "J", FOOT * LBF), ("lbf", "N", LBF),
])
def test_the_new_effects_units_read_in_templates_and_in_students_cells(typed: str, key: str, factor: float) -> None:
    """Each unit a template may print (parse_unit) and a student may type (unit_factor), against the definitions."""
    from grader.model.quantities import parse_unit, unit_factor

    assert float(parse_unit(typed).factor) / float(parse_unit(key).factor) == pytest.approx(factor, rel=1e-12)
    assert unit_factor(typed, key) == pytest.approx(factor, rel=1e-12)
