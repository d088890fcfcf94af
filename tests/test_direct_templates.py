"""The direct-impact templates of issue 13 against references written here from first principles.

head-on, head-on-inverse, coupling, moving-plate, three-balls, two-rebounds. Each reference writes
what a student would (momentum and restitution per impact, energies as sums of 1/2 m v^2, heights
from v^2 = 2 g h) and never calls the solver: exact fractions where the answer is rational,
60-digit mpmath where a square root enters, the float inputs taken as exact. Hard cases (e = 0 and
1 where allowed, mass ratios 1e-6..1e6, tiny and large heights) agree to 1e-9 relative.
"""

from __future__ import annotations

from fractions import Fraction

import mpmath as mp
import pytest

from grader.solve.evaluate import solve_one
from tests import references

G = mp.mpf(9.81)  # the bank's g, as the float the kernels use
KMH = Fraction(1000, 3600)  # km/h in m/s
ISSUE = {  # ids, parameters and answers exactly as issue 13's table names them (issue 27 adds energies and impulses)
    "head-on": (["m1", "m2", "v1", "v2", "e"], ["v1_out", "v2_out", "loss_pct", "energy_lost", "impulse"]),
    "head-on-inverse": (["m1", "m2", "v1", "v2", "v1_out"], ["v2_out", "e", "loss_pct"]),
    "coupling": (["m_A", "m_B", "v_A", "v_B"], ["v_common", "energy_lost", "loss_pct", "impulse"]),
    "moving-plate": (["h", "u", "e"], ["v_out", "h_out"]),
    "three-balls": (["m1", "m2", "m3", "v", "e"], ["v1_out", "v2_out", "v3_out"]),
    "two-rebounds": (["h1", "h2"], ["e", "h0", "loss_pct"]),
}


# ---- references -------------------------------------------------------------------------------
def after_impact(m1, m2, u1, u2, e):
    """Velocities after a direct central impact from the two equations a student writes,
    m1 v1 + m2 v2 = m1 u1 + m2 u2 and v2 - v1 = e (u1 - u2), solved by Cramer's rule, exactly."""
    m1, m2, u1, u2, e = (Fraction(x) for x in (m1, m2, u1, u2, e))
    momentum, separation = m1 * u1 + m2 * u2, e * (u1 - u2)
    determinant = m1 + m2  # of [[m1, m2], [-1, 1]]
    return (momentum - m2 * separation) / determinant, (momentum + m1 * separation) / determinant


def energy(*pairs):
    """Sum of 1/2 m v^2 over (m, v)."""
    return sum(Fraction(m) * v * v / 2 for m, v in pairs)


def ref_head_on(m1, m2, v1, v2, e):
    """The energy lost as T - T' and the impulse as cart 2's change of momentum, m2 (v2' - v2)."""
    w1, w2 = after_impact(m1, m2, v1, v2, e)
    before, after = energy((m1, Fraction(v1)), (m2, Fraction(v2))), energy((m1, w1), (m2, w2))
    return {"v1_out": w1, "v2_out": w2, "energy_lost": before - after, "loss_pct": 100 * (before - after) / before,
            "impulse": Fraction(m2) * (w2 - Fraction(v2))}


def ref_head_on_inverse(m1, m2, v1, v2, v1_out):
    m1, m2, v1, v2, w1 = (Fraction(x) for x in (m1, m2, v1, v2, v1_out))
    w2 = (m1 * v1 + m2 * v2 - m1 * w1) / m2  # momentum
    before, after = energy((m1, v1), (m2, v2)), energy((m1, w1), (m2, w2))
    return {"v2_out": w2, "e": (w2 - w1) / (v1 - v2), "loss_pct": 100 * (before - after) / before}


def ref_coupling(m_A, m_B, v_A, v_B):  # noqa: N803 (the template's names)
    common, _ = after_impact(m_A, m_B, v_A, v_B, 0)  # they move on together: e = 0
    masses = (Fraction(m_A) * 1000, Fraction(m_B) * 1000)  # Mg -> kg
    before = energy((masses[0], Fraction(v_A) * KMH), (masses[1], Fraction(v_B) * KMH))
    after = energy((masses[0] + masses[1], common * KMH))
    impulse = masses[1] * (common - Fraction(v_B)) * KMH / 1000  # B's change of momentum, in kN s
    return {"v_common": common, "energy_lost": (before - after) / 1000, "loss_pct": 100 * (before - after) / before,
            "impulse": impulse}


def ref_moving_plate(h, u, e):
    v = mp.sqrt(2 * G * mp.mpf(h))  # down, just before the impact
    relative = v + mp.mpf(u)  # the ball approaches the plate at this speed, seen from the plate
    v_out = mp.mpf(u) + mp.mpf(e) * relative  # and leaves it at e times that, upward
    return {"v_out": v_out, "h_out": v_out**2 / (2 * G)}


def ref_three_balls(m1, m2, m3, v, e):
    w1, between = after_impact(m1, m2, v, 0, e)
    w2, w3 = after_impact(m2, m3, between, 0, e)
    return {"v1_out": w1, "v2_out": w2, "v3_out": w3}


def ref_two_rebounds(h1, h2):
    h1, h2 = mp.mpf(h1), mp.mpf(h2)
    e = mp.sqrt(2 * G * h2) / mp.sqrt(2 * G * h1)  # second bounce: up at sqrt(2 g h2) after falling h1
    v0 = mp.sqrt(2 * G * h1) / e  # first bounce: it left at sqrt(2 g h1) = e times its impact speed
    h0 = v0**2 / (2 * G)
    start, end = v0**2 / 2, 2 * G * h2 / 2  # per unit mass: before the first impact, after the second
    return {"e": e, "h0": h0, "loss_pct": 100 * (start - end) / start}


REFERENCES = {
    "head-on": ref_head_on,
    "head-on-inverse": ref_head_on_inverse,
    "coupling": ref_coupling,
    "moving-plate": ref_moving_plate,
    "three-balls": ref_three_balls,
    "two-rebounds": ref_two_rebounds,
}


def check(bank, compiled, template_id, params):
    references.check(bank, compiled, template_id, params, REFERENCES[template_id])


# ---- the bank holds them as the issue names them ------------------------------------------------
def test_ids_parameters_and_answers_are_the_issues(bank):
    assert {t: (list(bank[t].parameters), list(bank[t].answers)) for t in ISSUE} == ISSUE


# ---- known answers, worked by hand to four figures ----------------------------------------------
@pytest.mark.parametrize("template_id, params, answers", [
    # p = 2(4) + 3(-2) = 2, v_c = 0.4; v1' = 0.4 - 0.6(3/5)(6), v2' = 0.4 + 0.6(2/5)(6); T = 22, lost 13.824 J;
    # the impulse on cart 2: 3(1.84 + 2) = 11.52 N s
    ("head-on", {"m1": 2, "m2": 3, "v1": 4, "v2": -2, "e": 0.6},
     {"v1_out": -1.76, "v2_out": 1.84, "energy_lost": 13.82, "loss_pct": 62.84, "impulse": 11.52}),
    # the same impact read backwards: J = 2(4 + 1.76) = 11.52, v2' = -2 + 11.52/3
    ("head-on-inverse", {"m1": 2, "m2": 3, "v1": 4, "v2": -2, "v1_out": -1.76},
     {"v2_out": 1.84, "e": 0.6, "loss_pct": 62.84}),
    # (60(8) + 40(-2))/100 = 4 km/h; lost 1/2 (24 000 kg)(10/3.6 m/s)^2 = 92.59 kJ of 154.3 kJ;
    # the impulse on B: 40 000 kg (4 + 2)/3.6 m/s = 66.67 kN s
    ("coupling", {"m_A": 60, "m_B": 40, "v_A": 8, "v_B": -2},
     {"v_common": 4, "energy_lost": 92.59, "loss_pct": 60, "impulse": 66.67}),
    # v = sqrt(2(9.81)(1.2)) = 4.852; v' = 1.5 + 0.6(4.852 + 1.5) = 5.311; h' = 5.311^2/19.62
    ("moving-plate", {"h": 1.2, "u": 1.5, "e": 0.6}, {"v_out": 5.311, "h_out": 1.438}),
    # 1 -> 2: v1' = 4(0.5 - 1.6)/2.5 = -1.76, v_b = 4(1.8)(0.5)/2.5 = 1.44; 2 -> 3: (2 - 0.64)/2.8, 1.8(2)/2.8
    ("three-balls", {"m1": 0.5, "m2": 2, "m3": 0.8, "v": 4, "e": 0.8},
     {"v1_out": -1.76, "v2_out": 0.6994, "v3_out": 1.851}),
    # e = sqrt(0.75/1.2) = 0.7906, h0 = 1.2^2/0.75 = 1.92, lost 1 - 0.75/1.92 of it
    ("two-rebounds", {"h1": 1.2, "h2": 0.75}, {"e": 0.7906, "h0": 1.92, "loss_pct": 60.94}),
])
def test_known_answers(bank, compiled, template_id, params, answers):
    """The hand-worked values to four figures, and the reference to 1e-9."""
    references.check_known(bank, compiled, template_id, params, answers, REFERENCES[template_id])


# ---- hard cases -----------------------------------------------------------------------------
@pytest.mark.parametrize("e", [0.0, 1.0, 0.5])
@pytest.mark.parametrize("m1, m2", [(1e-6, 1.0), (1.0, 1.0), (1e6, 1.0), (1.0, 1e6)],
                         ids=["m1=1e-6", "equal", "m1=1e6", "m2=1e6"])
@pytest.mark.parametrize("v1, v2", [(3.0, -1.0), (5.0, 2.0)], ids=["toward", "chasing"])
def test_head_on(bank, compiled, m1, m2, v1, v2, e):
    check(bank, compiled, "head-on", {"m1": m1, "m2": m2, "v1": v1, "v2": v2, "e": e})


def test_head_on_loss_of_nearly_equal_speeds_keeps_full_accuracy(bank, compiled):
    """A relative speed of 1e-6 in 10 m/s: T - T' would lose 12 digits; the stable form none."""
    check(bank, compiled, "head-on", {"m1": 2.0, "m2": 3.0, "v1": 10.000001, "v2": 10.0, "e": 0.5})


@pytest.mark.parametrize("params", [
    pytest.param({"m1": 1.0, "m2": 3.0, "v1": 4.0, "v2": 0.0, "v1_out": 1.0}, id="e0-they-move-together"),
    pytest.param({"m1": 1.0, "m2": 3.0, "v1": 4.0, "v2": 0.0, "v1_out": -2.0}, id="e1"),
    pytest.param({"m1": 1e6, "m2": 1.0, "v1": 4.0, "v2": 0.0, "v1_out": 3.999994}, id="ratio1e6"),
    pytest.param({"m1": 1e-6, "m2": 1.0, "v1": 4.0, "v2": 0.0, "v1_out": -2.0}, id="ratio1e-6"),
    pytest.param({"m1": 2.0, "m2": 3.0, "v1": 5.0, "v2": 1.0, "v1_out": 1.96}, id="chasing"),
    pytest.param({"m1": 2.0, "m2": 3.0, "v1": 10.000001, "v2": 10.0, "v1_out": 10.0000001}, id="nearly-equal"),
])
def test_head_on_inverse(bank, compiled, params):
    check(bank, compiled, "head-on-inverse", params)


@pytest.mark.parametrize("masses", [(1e-6, 1.0), (60.0, 40.0), (1e6, 1.0)], ids=["1e-6", "1.5", "1e6"])
@pytest.mark.parametrize("speeds", [(8.0, -2.0), (8.0, 3.0), (10.000001, 10.0)],
                         ids=["toward", "chasing", "nearly-equal"])
def test_coupling(bank, compiled, masses, speeds):
    """Two cars at nearly equal speeds keep full accuracy in the energy lost and its percentage."""
    check(bank, compiled, "coupling", {"m_A": masses[0], "m_B": masses[1], "v_A": speeds[0], "v_B": speeds[1]})


@pytest.mark.parametrize("h, u, e", [
    pytest.param(1.2, 0.0, 1.0, id="e1-plate-at-rest"),
    pytest.param(1.2, 1.5, 1.0, id="e1-plate-up"),
    pytest.param(1.2, 0.0, 1e-12, id="tiny-e"),
    pytest.param(2.0, -1.0, 0.9, id="plate-down"),
    pytest.param(1e-6, 10.0, 0.5, id="fast-plate"),
    pytest.param(1e-150, 1e-76, 0.5, id="tiny-height"),
    pytest.param(1e150, 1e74, 0.5, id="large-height"),
])
def test_moving_plate(bank, compiled, h, u, e):
    check(bank, compiled, "moving-plate", {"h": h, "u": u, "e": e})


@pytest.mark.parametrize("m1, m2, m3", [(1.0, 1.0, 1.0), (1e-6, 1.0, 1e-6), (1e6, 1.0, 1e6), (1.0, 1e6, 1.0),
                                        (0.5, 2.0, 0.8)], ids=["equal", "1e-6", "1e6", "heavy-middle", "example"])
@pytest.mark.parametrize("e", [1.0, 0.5, 1e-12])
@pytest.mark.parametrize("v", [4.0, 1e-150, 1e170])
def test_three_balls(bank, compiled, m1, m2, m3, v, e):
    """Equal masses with e = 1 pass the velocity on (1 and 2 stop exactly)."""
    check(bank, compiled, "three-balls", {"m1": m1, "m2": m2, "m3": m3, "v": v, "e": e})


@pytest.mark.parametrize("h1, h2", [
    pytest.param(1.2, 1.2, id="e1"),
    pytest.param(3.7, 3.7 * (1 - 1e-12), id="e1-1e-12"),
    pytest.param(1.0, 1e-12, id="e1e-6"),
    pytest.param(1e-150, 3e-151, id="tiny"),
    pytest.param(1e170, 6e169, id="large"),
    pytest.param(1e170, 1e170 * (1 - 1e-12), id="large-e1-1e-12"),
])
def test_two_rebounds(bank, compiled, h1, h2):
    check(bank, compiled, "two-rebounds", {"h1": h1, "h2": h2})


# ---- refusals name the reason -----------------------------------------------------------------
@pytest.mark.parametrize("template_id, params, reason", [
    ("head-on", {"m1": 2, "m2": 3, "v1": 1, "v2": 2, "e": 0.5}, "the carts never meet"),
    ("head-on-inverse", {"m1": 2, "m2": 3, "v1": 4, "v2": -2, "v1_out": 2},
     "restitution is -0.444444; it cannot be negative (the bodies would pass through each other)"),
    ("head-on-inverse", {"m1": 2, "m2": 3, "v1": 4, "v2": -2, "v1_out": -4},
     "restitution is 1.22222; above 1 the impact would create energy"),
    ("coupling", {"m_A": 60, "m_B": 40, "v_A": 3, "v_B": 3}, "the cars never meet"),
    ("moving-plate", {"h": 1.2, "u": -5, "e": 0.6}, "ball and plate are not approaching"),
    ("moving-plate", {"h": 1.2, "u": -2, "e": 0.3}, "ball must move up (v_out >= 0)"),
    ("three-balls", {"m1": 1, "m2": 1, "m3": 1, "v": 4, "e": 0}, "with e = 0 balls 1 and 2 move on together"),
    ("two-rebounds", {"h1": 1.2, "h2": 1.3}, "cannot rise higher after the second impact"),
    ("two-rebounds", {"h1": 1.2, "h2": 0}, "h2 = 0 m is outside its domain (0, inf)"),
])
def test_unphysical_input_is_refused_with_the_reason(bank, compiled, template_id, params, reason):
    solution = solve_one(bank[template_id], compiled[template_id], params)
    assert solution.answers is None and reason in solution.error, solution.error
