"""Issue 14's impact-with-a-skid and impact-with-a-flight templates against references written here.

skid: momentum through a perfectly plastic impact, then work-energy over the skid mark;
wall-throw: projectile motion to a smooth wall, the rebound (normal component times e, tangential
kept), projectile motion to the ground. The references write what a student would, in 60-digit mpmath
with the float inputs taken as exact, and never call the solver. Hard cases (e = 0 and 1, alpha = 0,
a throw that grazes the ground at the wall, mass ratios 1e-6..1e6, a tiny mu_k d) agree to 1e-9.
"""

from __future__ import annotations

import mpmath as mp
import numpy as np
import pytest

from grader.physics.effects import CATALOGUE
from grader.physics.run import Options
from grader.simulate.walker import simulate
from grader.solve.evaluate import solve_one
from tests import references

G = mp.mpf(9.81)  # the bank's g, as the float the kernels use
KMH = mp.mpf(3.6)  # (km/h) per (m/s)
ISSUE = {  # ids, parameters and answers exactly as issue 14's table names them
    "skid": (["m_A", "m_B", "d", "mu_k"], ["v_A", "loss_pct"]),
}


# ---- references -------------------------------------------------------------------------------
def ref_skid(m_A, m_B, d, mu_k):  # noqa: N803 (the template's names)
    m_A, m_B, d, mu_k = (mp.mpf(x) for x in (m_A, m_B, d, mu_k))
    v_c = mp.sqrt(2 * mu_k * G * d)  # 1/2 (m_A + m_B) v_c^2 = mu_k (m_A + m_B) g d
    v_A = (m_A + m_B) * v_c / m_A  # m_A v_A = (m_A + m_B) v_c
    before, after = m_A * v_A**2 / 2, (m_A + m_B) * v_c**2 / 2
    return {"v_A": v_A * KMH, "loss_pct": 100 * (before - after) / before}


REFERENCES = {"skid": ref_skid}


def check(bank, compiled, template_id, params):
    references.check(bank, compiled, template_id, params, REFERENCES[template_id])


def test_ids_parameters_and_answers_are_the_issues(bank):
    assert {t: (list(bank[t].parameters), list(bank[t].answers)) for t in ISSUE} == ISSUE


# ---- known answers, worked by hand to four figures ----------------------------------------------
@pytest.mark.parametrize("template_id, params, answers", [
    # v_c = sqrt(2(0.6)(9.81)(8.5)) = 10.003 m/s; v_A = 10.003(2700/1500) = 18.006 m/s = 64.82 km/h;
    # the plastic impact keeps m_A/(m_A + m_B) of the energy: 1200/2700 of it is lost
    ("skid", {"m_A": 1500, "m_B": 1200, "d": 8.5, "mu_k": 0.6}, {"v_A": 64.82, "loss_pct": 44.44}),
])
def test_known_answers(bank, compiled, template_id, params, answers):
    """The hand-worked values to four figures, and the reference to 1e-9."""
    references.check_known(bank, compiled, template_id, params, answers, REFERENCES[template_id])


# ---- hard cases -----------------------------------------------------------------------------
@pytest.mark.parametrize("m_A, m_B", [(1e-6, 1.0), (1500.0, 1200.0), (1e6, 1.0), (1.0, 1e6)],
                         ids=["A-1e-6", "cars", "A-1e6", "B-1e6"])
@pytest.mark.parametrize("d, mu_k", [(8.5, 0.6), (1e-9, 1e-6), (1e-150, 0.7), (1e150, 0.7)],
                         ids=["skid", "tiny-mu-d", "tiny-d", "large-d"])
def test_skid(bank, compiled, m_A, m_B, d, mu_k):  # noqa: N803
    check(bank, compiled, "skid", {"m_A": m_A, "m_B": m_B, "d": d, "mu_k": mu_k})


# ---- the slide's force law ------------------------------------------------------------------
def test_skid_simulation_integrates_friction_and_the_contact_only(bank):
    """No gravity in the skid's simulation (its weight only presses the tyres on the road): friction
    where the cars slide, the contact in the impact; car A's speed is found from the skid mark."""
    params = {"m_A": 1500, "m_B": 1200, "d": 8.5, "mu_k": 0.6}
    result = simulate(bank["skid"], params)
    assert result.effects == ("contact (Kelvin-Voigt)", "kinetic friction (Coulomb)")
    with mp.workdps(30):
        expected = ref_skid(**params)
    assert result.answers["v_A"] == pytest.approx(float(expected["v_A"]), rel=1e-9)
    assert result.answers["loss_pct"] == pytest.approx(float(expected["loss_pct"]), rel=1e-9)


def test_slide_stops_at_the_located_event_without_chatter(bank):
    """The slide's path ends where the velocity reaches 0, exactly at v**2/(2 mu g), and never turns back."""
    result = simulate(bank["skid"], {"m_A": 1000, "m_B": 1000, "d": 2.0, "mu_k": 0.5}, Options())
    slide = next(phase for phase in result.phases if "slides" in phase.label)
    states = np.array(slide.path.y)
    assert states[-1][1] == pytest.approx(0.0, abs=1e-12)
    assert states[-1][0] == pytest.approx(2.0, rel=1e-12)
    assert np.all(np.diff(states[:, 0]) >= 0) and np.all(states[:, 1] >= -1e-12)
    assert slide.path.steps < 20  # a constant deceleration is one smooth mode: no steps spent at v = 0


def test_slide_declares_its_mistakes(bank):
    stage = bank["skid"].scene.stages[1]
    from grader.physics.symbolic import Context

    ids = [m.id for m in CATALOGUE["slide"].mistakes(stage, Context(bank["skid"].scene))]
    assert ids == ["slide.sqrt_mu_g_d", "slide.without_friction_coefficient", "slide.two_mu_g_d"]


# ---- refusals name the reason -----------------------------------------------------------------
@pytest.mark.parametrize("template_id, params, reason", [
    ("skid", {"m_A": 1500, "m_B": 1200, "d": 8.5, "mu_k": 0}, "mu_k = 0 is outside its domain (0, inf)"),
    ("skid", {"m_A": 1500, "m_B": 1200, "d": 0, "mu_k": 0.6}, "d = 0 m is outside its domain (0, inf)"),
])
def test_unphysical_input_is_refused_with_the_reason(bank, compiled, template_id, params, reason):
    solution = solve_one(bank[template_id], compiled[template_id], params)
    assert solution.answers is None and reason in solution.error, solution.error
