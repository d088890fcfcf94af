"""successive-bounces and ballistic-pendulum (issue 14, part a) against references written here from first
principles, never by the solver: the bounces as the sums a student writes (the drop, then each rebound up and
down; mpmath's nsum of the terms where the series converges fast, its geometric sum otherwise), the pendulum
from momentum through the impact and energy in the swing with ``1 - cos`` at 60 digits, and the energy lost as
``T - T'`` at 60 digits. Hard cases: e = 0 and e within 1e-12 of 1, swings of 1e-4 degrees and 90 degrees, mass
ratios 1e-15..1e15, tiny and huge heights; each within 1e-9 relative where the answer is well-conditioned."""

from __future__ import annotations

import re
from typing import Any

import mpmath as mp
import pytest

from grader.cli import main
from grader.simulate.walker import simulate
from grader.solve.cache import alternatives_for
from grader.solve.evaluate import solve_one
from grader.solve.solver import compile_template
from tests import references
from tests.test_diagnosis import graded_alone, mistake_value

G = mp.mpf(9.81)
ISSUE = {  # ids, parameters and answers exactly as issue 14's table names them
    "successive-bounces": (["h0", "e", "n"], ["h_n", "distance", "t_total"]),
    "ballistic-pendulum": (["m_b", "m_blk", "L", "theta_max"], ["v_bullet", "loss_pct"]),
}


def ref_bounces(h0: float, e: float, n: float) -> dict[str, Any]:
    """Heights h0 e^(2k); distance: the drop, then each rebound height twice; time: the fall, then each
    rebound's rise and fall (each sqrt(2 h/g)). Summed term by term where e is well below 1, as the
    geometric series' sum (a/(1 - r)) where nsum would need too many terms."""
    h0, e = mp.mpf(h0), mp.mpf(e)
    fall = mp.sqrt(2 * h0 / G)
    if e <= mp.mpf("0.9"):  # each term in units of the first: nsum's tolerance is absolute
        distance = h0 * (1 + mp.nsum(lambda k: 2 * e ** (2 * k), [1, mp.inf]))
        time = fall * (1 + mp.nsum(lambda k: 2 * mp.sqrt(e ** (2 * k)), [1, mp.inf]))
    else:
        distance = h0 + 2 * h0 * e**2 / (1 - e**2)
        time = fall + 2 * fall * e / (1 - e)
    height = h0 * e ** (2 * int(n))
    # Below float64's smallest normal number (e = 1e-9, n = 200: 1e-1800 m) the height is 0 in float64.
    return {"h_n": height if height >= mp.mpf("2.2250738585072014e-308") else mp.mpf(0), "distance": distance,
            "time": time}


def _bounces(h0: float, e: float, n: float) -> dict[str, Any]:
    reference = ref_bounces(h0, e, n)
    return {"h_n": reference["h_n"], "distance": reference["distance"], "t_total": reference["time"]}


def ref_pendulum(m_b: float, m_blk: float, L: float, theta_max: float) -> dict[str, Any]:  # noqa: N803
    """Energy in the swing, V**2 = 2 g L (1 - cos theta); momentum through the impact, m_b v = (m_b + M) V;
    the energy lost as T - T' (60 digits: no cancellation that matters)."""
    bullet, block = mp.mpf(m_b) / 1000, mp.mpf(m_blk)
    V = mp.sqrt(2 * G * mp.mpf(L) * (1 - mp.cos(mp.radians(mp.mpf(theta_max)))))  # noqa: N806
    v = (bullet + block) * V / bullet
    before, after = bullet * v**2 / 2, (bullet + block) * V**2 / 2
    return {"v_bullet": v, "loss_pct": 100 * (before - after) / before}


def test_ids_parameters_and_answers_are_the_issues(bank: dict[str, Any]) -> None:
    for template_id, (parameters, answers) in ISSUE.items():
        template = bank[template_id]
        assert (list(template.parameters), list(template.answers)) == (parameters, answers)
    assert bank["successive-bounces"].parameters["n"].integer
    assert bank["ballistic-pendulum"].topic == "impact and a swing"
    assert bank["successive-bounces"].topic == "drops and rebounds"


@pytest.mark.parametrize(("template_id", "params", "answers", "reference"), [
    # by hand: h_3 = 1.8 (0.75)^6; D = 1.8 (1 + 0.5625)/(1 - 0.5625); t = sqrt(3.6/9.81)(1.75/0.25)
    ("successive-bounces", {"h0": 1.8, "e": 0.75, "n": 3}, {"h_n": 0.3204, "distance": 6.429, "t_total": 4.240},
     _bounces),
    # by hand: V = sqrt(2 (9.81)(1.6)(1 - cos 20)) = 1.3765; v = (0.012 + 4)(1.3765)/0.012; loss = 4/4.012
    ("ballistic-pendulum", {"m_b": 12, "m_blk": 4, "L": 1.6, "theta_max": 20},
     {"v_bullet": 460.0, "loss_pct": 99.70}, ref_pendulum),
])
def test_known_answers(bank: dict[str, Any], compiled: dict[str, Any], template_id: str, params: dict[str, float],
                       answers: dict[str, float], reference: Any) -> None:
    references.check_known(bank, compiled, template_id, params, answers, reference)


NEAR_1 = 0.9999999940006266  # where 1 - e*e is worst: e*e's rounding is 3e-9 of 1 - e**2

@pytest.mark.parametrize("e", [0.0, 1e-9, 0.3, 0.75, 0.9, 0.999999, NEAR_1, 1 - 1e-12])
@pytest.mark.parametrize("n", [1, 4, 200])
@pytest.mark.parametrize("h0", [1e-150, 1.8, 1e150])
def test_successive_bounces(bank: dict[str, Any], compiled: dict[str, Any], h0: float, e: float, n: int) -> None:
    """e = 0 rests at the first impact (h_n = 0 exactly); near e = 1 the sums grow as 1/(1 - e) and keep
    full accuracy."""
    references.check(bank, compiled, "successive-bounces", {"h0": h0, "e": e, "n": n}, _bounces)


def test_the_sums_near_e_1_are_accurate_where_1_minus_e_squared_is_not(bank: dict[str, Any],
                                                                        compiled: dict[str, Any]) -> None:
    e = NEAR_1
    solution = solve_one(bank["successive-bounces"], compiled["successive-bounces"], {"h0": 1.0, "e": e, "n": 1})
    assert solution.answers is not None
    with mp.workdps(60):
        exact = ref_bounces(1.0, e, 1)["distance"]
        naive = (1 + e * e) / (1 - e * e)  # what the kernel must not do
        assert abs(solution.answers["distance"].value / exact - 1) < 1e-14
        assert abs(naive / exact - 1) > 1e-9


@pytest.mark.parametrize("theta", [1e-4, 1e-9, 0.5, 20.0, 45.0, 89.999, 90.0])
@pytest.mark.parametrize(("m_b", "m_blk"), [(12.0, 4.0), (1e-6, 1e6), (1e9, 1e-6), (1000.0, 1.0)],
                         ids=["bullet", "1e-15", "1e15", "equal"])
def test_ballistic_pendulum(bank: dict[str, Any], compiled: dict[str, Any], theta: float, m_b: float,
                            m_blk: float) -> None:
    """A swing of 1e-4 degrees keeps full accuracy (1 - cos theta would keep four digits); 90 degrees is valid."""
    references.check(bank, compiled, "ballistic-pendulum", {"m_b": m_b, "m_blk": m_blk, "L": 1.6, "theta_max": theta},
                     ref_pendulum)


@pytest.mark.parametrize(("template_id", "params", "reason"), [
    ("successive-bounces", {"h0": 2, "e": 1, "n": 3}, "the coefficient of restitution is 1: at e = 1 the ball bounces "
     "back to h0 for ever, so the series does not converge (it never comes to rest)"),
    ("successive-bounces", {"h0": 2, "e": 1.2, "n": 3}, "e = 1.2 is outside its domain [0, 1]"),
    ("successive-bounces", {"h0": 0, "e": 0.5, "n": 3}, "h0 = 0 m is outside its domain (0, inf)"),
    ("successive-bounces", {"h0": 2, "e": 0.5, "n": 0}, "n = 0 is outside its domain [1, inf)"),
    ("successive-bounces", {"h0": 2, "e": 0.5, "n": 1.5}, "n = 1.5 is not a whole number"),
    ("ballistic-pendulum", {"m_b": 12, "m_blk": 4, "L": 1.6, "theta_max": 90.1}, "the swing angle is 90.1 degrees: "
     "above 90 degrees the cord would go slack before block got there (a cord pulls, it cannot push)"),
    ("ballistic-pendulum", {"m_b": 12, "m_blk": 4, "L": 1.6, "theta_max": 0}, "theta_max = 0 deg is outside its "
     "domain (0, 180]"),
    ("ballistic-pendulum", {"m_b": 12, "m_blk": 4, "L": 0, "theta_max": 30}, "L = 0 m is outside its domain"),
])
def test_unphysical_input_is_refused_with_the_reason(bank: dict[str, Any], compiled: dict[str, Any], template_id: str,
                                                     params: dict[str, float], reason: str) -> None:
    solution = solve_one(bank[template_id], compiled[template_id], params)
    assert solution.answers is None and solution.error is not None
    assert reason in solution.error


@pytest.mark.parametrize("params", [
    {"h0": 2.0, "e": 0.0, "n": 3}, {"h0": 2.0, "e": 0.3, "n": 1}, {"h0": 0.9, "e": 0.9, "n": 7},
    {"h0": 2.0, "e": 0.999, "n": 2},
])
def test_bounces_simulated_in_time_give_the_series(bank: dict[str, Any], compiled: dict[str, Any],
                                                   params: dict[str, float]) -> None:
    """The first max(n, 5) bounces integrated (gravity in flight, the contact at each impact); their partial
    sums agree with the series' partial sums; the tail beyond is the series', its share as worked here."""
    closed = solve_one(bank["successive-bounces"], compiled["successive-bounces"], params)
    result = simulate(bank["successive-bounces"], params)
    assert closed.answers is not None and result.effects == ("gravity", "contact (Kelvin-Voigt)")
    for name, value in result.answers.items():
        assert value == pytest.approx(closed.answers[name].value, rel=1e-7, abs=1e-12), name
    [note] = result.notes
    e, bounces = params["e"], max(int(params["n"]), 5)
    if e == 0:
        assert "it rests at the first impact" in note and len(result.contacts) == 1
        return
    numbers = re.search(r"partial sums distance (\S+) m \(series (\S+) m\), time (\S+) s \(series (\S+) s\); tail "
                        r"beyond bounce (\d+) from the series: \S+ m \((\S+) of the distance\)", note)
    assert numbers is not None, note
    distance, series_distance, time, series_time, last, share = numbers.groups()
    with mp.workdps(30):
        h0 = mp.mpf(params["h0"])
        by_hand = h0 + sum(2 * h0 * mp.mpf(e) ** (2 * k) for k in range(1, bounces + 1))
        tail = 2 * mp.mpf(e) ** (2 * bounces + 2) / (1 + mp.mpf(e) ** 2)  # share of the whole distance
    assert int(last) == bounces == len(result.contacts)
    assert float(distance) == pytest.approx(float(by_hand), rel=1e-8)
    assert float(series_distance) == pytest.approx(float(by_hand), rel=1e-9)
    assert float(time) == pytest.approx(float(series_time), rel=1e-8)
    assert float(share) == pytest.approx(float(tail), rel=0.05)  # printed to 2 figures


@pytest.mark.parametrize(("theta", "m_b", "m_blk"), [(20.0, 12.0, 4.0), (1e-4, 12.0, 4.0), (90.0, 12.0, 4.0),
                                                     (30.0, 1e-3, 4000.0)])
def test_the_pendulum_simulated_finds_the_bullets_speed(bank: dict[str, Any], compiled: dict[str, Any], theta: float,
                                                        m_b: float, m_blk: float) -> None:
    """The bullet's speed found so that the simulated impact and swing reach the given angle: the cord's
    tension and gravity in the swing only, the contact in the impact only."""
    params = {"m_b": m_b, "m_blk": m_blk, "L": 1.6, "theta_max": theta}
    closed = solve_one(bank["ballistic-pendulum"], compiled["ballistic-pendulum"], params)
    result = simulate(bank["ballistic-pendulum"], params)
    assert closed.answers is not None and "v_bullet" in result.fitted
    assert set(result.effects) == {"contact (Kelvin-Voigt)", "gravity", "cord tension (pendulum)"}
    for name, value in result.answers.items():
        assert value == pytest.approx(closed.answers[name].value, rel=1e-7), name


def _bob(template_id: str, given: dict[str, tuple[str, str]], asked: tuple[str, str]) -> Any:
    """A bob on a cord of length L: one of its speed v at the lowest point and the angle theta it stops at
    given (unit, domain), the other asked."""
    from grader.bank.template import parse_template

    parameters = {name: {"unit": unit, "domain": domain, "sample": {"uniform": [1, 2]}, "decimals": 2}
                  for name, (unit, domain) in {**given, "L": ("m", "(0, inf)")}.items()}
    raw = {"id": template_id, "title": "t", "version": 1, "gravity": "9.81 m/s^2", "bodies": {"bob": {"mass": "m"}},
           "symbols": {"m": {"unit": "kg"}}, "parameters": parameters,
           "stages": [{"effect": "swing", "body": "bob", "speed": "v", "length": "L", "angle": "theta"}],
           "answers": {asked[0]: {"value": asked[0], "unit": asked[1]}},
           "statement": " ".join(f"{name} = {{{{ {name} }}}}" for name in parameters)}
    return parse_template(raw, f"test:{template_id}", template_id)


def test_a_swing_given_its_speed_stops_where_energy_says(bank: dict[str, Any]) -> None:
    """The swing up, forward: the pendulum released at the lowest point at v stops at the angle of the closed
    form; above 90 degrees its cord goes slack, and the simulation says so."""
    template = _bob("swing-up", {"v": ("m/s", "[0, inf)")}, ("theta", "deg"))
    compiled = compile_template(template)
    for v in (1e-6, 2.0, 5.0):
        closed = solve_one(template, compiled, {"v": v, "L": 1.6})
        with mp.workdps(60):
            exact = mp.degrees(2 * mp.asin(mp.mpf(v) / (2 * mp.sqrt(G * mp.mpf(1.6)))))
        assert closed.answers is not None and closed.answers["theta"].value == pytest.approx(float(exact), rel=1e-12)
        assert simulate(template, {"v": v, "L": 1.6}).answers["theta"] == pytest.approx(float(exact), rel=1e-8)
    too_fast = solve_one(template, compiled, {"v": 6.0, "L": 1.6})
    assert too_fast.error is not None and "above 90 degrees the cord would go slack" in too_fast.error
    from grader.physics.integrate import SimulationError

    with pytest.raises(SimulationError, match=r"the cord goes slack at 1[0-9][0-9].* degrees from the vertical"):
        simulate(template, {"v": 6.0, "L": 1.6})


MISTAKES = [
    ("successive-bounces", {"h0": 1.8, "e": 0.75, "n": 3}, "h_n", "bounces.e_not_squared", 1.8 * 0.75**3),
    ("successive-bounces", {"h0": 1.8, "e": 0.75, "n": 3}, "h_n", "bounces.drop_counted", 1.8 * 0.75**4),
    ("successive-bounces", {"h0": 1.8, "e": 0.75, "n": 3}, "distance", "bounces.one_way", 1.8 / (1 - 0.75**2)),
    ("successive-bounces", {"h0": 1.8, "e": 0.75, "n": 3}, "t_total", "bounces.rise_time_only",
     (3.6 / 9.81) ** 0.5 / 0.25),
    ("ballistic-pendulum", {"m_b": 12, "m_blk": 4, "L": 1.6, "theta_max": 20}, "v_bullet", "swing.height_cos",
     4.012 / 0.012 * (2 * 9.81 * 1.6 * float(mp.cos(mp.radians(20)))) ** 0.5),
    ("ballistic-pendulum", {"m_b": 12, "m_blk": 4, "L": 1.6, "theta_max": 20}, "v_bullet", "swing.height_sin",
     4.012 / 0.012 * (2 * 9.81 * 1.6 * float(mp.sin(mp.radians(20)))) ** 0.5),
]


@pytest.mark.parametrize(("template_id", "params", "answer", "mistake", "by_hand"), MISTAKES,
                         ids=[m[3] for m in MISTAKES])
def test_a_typical_mistake_is_diagnosed(bank: dict[str, Any], template_id: str, params: dict[str, float],
                                        answer: str, mistake: str, by_hand: float) -> None:
    template = bank[template_id]
    assert mistake_value(alternatives_for(template), params, answer, mistake) == pytest.approx(by_hand, rel=1e-9)
    verdict = graded_alone(template, params, answer, f"{by_hand:.3g}")
    assert (verdict.verdict, verdict.diagnosis) == ("mistake", mistake), verdict


def test_simulate_cli_prints_the_partial_sums(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["simulate", "successive-bounces", "--set", "h0=2", "--set", "e=0.8", "--set", "n=3", "--json"]) == 0
    record = __import__("json").loads(capsys.readouterr().out)
    assert record["notes"][0].startswith("bounces of ball on floor: the first 5 simulated in time")
    assert max(row["rel_diff"] for row in record["answers"].values()) < 1e-7


def test_a_swing_given_its_angle_is_simulated_swinging_down(bank: dict[str, Any]) -> None:
    """Released at rest at the angle, the pendulum reaches the lowest point at the closed form's speed,
    2 sqrt(g L) sin(theta/2), from a swing of 1e-4 degrees to one of 90."""
    template = _bob("swing-down", {"theta": ("deg", "(0, 90]")}, ("v", "m/s"))
    compiled = compile_template(template)
    for theta in (1e-4, 30.0, 90.0):
        with mp.workdps(60):
            exact = mp.sqrt(2 * G * mp.mpf(1.6) * (1 - mp.cos(mp.radians(mp.mpf(theta)))))
        closed = solve_one(template, compiled, {"theta": theta, "L": 1.6})
        assert closed.answers is not None and closed.answers["v"].value == pytest.approx(float(exact), rel=1e-13)
        result = simulate(template, {"theta": theta, "L": 1.6})
        assert result.answers["v"] == pytest.approx(float(exact), rel=1e-8) and not result.fitted
