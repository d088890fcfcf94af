"""pile-driver against a reference written here from first principles (issue 27 adds the energy lost in
kilojoules and the impulse on the pile).

The reference writes what a student would, in 60-digit mpmath with the float inputs taken as exact, and
never calls the solver: the ram's speed at the pile from ``v² = 2 g h``, its speed back up from the
rebound height, the pile's from conservation of momentum, ``e`` as separation over approach, the energy
lost as ``T − T'`` (each a sum of ``½ m v²``), and the impulse on the pile as its change of momentum.
"""

from __future__ import annotations

import mpmath as mp
import numpy as np
import pytest
import yaml

from grader.base.resources import bank_dir
from grader.solve.evaluate import solve_one
from tests import references

G = mp.mpf(9.81)  # the bank's g, as the float the kernels use


def ref_pile_driver(m_ram, m_pile, h_drop, h_rebound):
    m, big_m = mp.mpf(m_ram), mp.mpf(m_pile)
    v = mp.sqrt(2 * G * mp.mpf(h_drop))  # down, just before the impact
    back = mp.sqrt(2 * G * mp.mpf(h_rebound))  # up, just after: the ram rises h_rebound
    v_pile = m * (v + back) / big_m  # momentum, down positive: m v = m (-back) + M v_pile
    before = m * v**2 / 2
    after = m * back**2 / 2 + big_m * v_pile**2 / 2
    return {"v_pile": v_pile, "e": (v_pile + back) / v, "loss_pct": 100 * (before - after) / before,
            "energy_lost": (before - after) / 1000, "impulse": big_m * v_pile}


def check(bank, compiled, params):
    references.check(bank, compiled, "pile-driver", params, ref_pile_driver)


def test_answers_are_the_issues(bank):
    assert list(bank["pile-driver"].answers) == ["v_pile", "e", "loss_pct", "energy_lost", "impulse"]


def test_sample_problem_3_28(bank, compiled):
    """The template's example is Sample Problem 3/28: v = √(2(9.81)(2)) = 6.264 m/s down, 1.401 m/s back up;
    v_pile = 800(6.264 + 1.401)/2400 = 2.555 m/s; T = 15.70 kJ, T' = ½(800)(1.401)² + ½(2400)(2.555)² = 8.620 kJ,
    so 7.078 kJ (45.09 %) is lost; the impulse on the pile is 2400(2.555) = 6132 N·s."""
    params = {"m_ram": 800, "m_pile": 2400, "h_drop": 2, "h_rebound": 0.1}
    assert bank["pile-driver"].example == params
    references.check_known(bank, compiled, "pile-driver", params,
                           {"v_pile": 2.555, "e": 0.6315, "loss_pct": 45.09, "energy_lost": 7.078, "impulse": 6132},
                           ref_pile_driver)


def drawn(count: int) -> list[dict[str, float]]:
    """``count`` draws from the template's sampling ranges, rounded as the sheet prints them."""
    raw = yaml.safe_load((bank_dir() / "pile-driver.yaml").read_text(encoding="utf-8"))["parameters"]
    rng = np.random.default_rng(27)
    rounded = {name: (lambda x, s=spec: round(x, s["decimals"]) if "decimals" in s else float(f"{x:.{s['sig_figs']}g}"))
               for name, spec in raw.items()}
    return [{name: rounded[name](float(rng.uniform(*spec["sample"]["uniform"]))) for name, spec in raw.items()}
            for _ in range(count)]


def test_twenty_five_sampled_variants(bank, compiled):
    for params in drawn(25):
        check(bank, compiled, params)


@pytest.mark.parametrize("params", [
    pytest.param({"m_ram": 800, "m_pile": 2400, "h_drop": 2, "h_rebound": 0}, id="no-rebound"),
    pytest.param({"m_ram": 1e-6, "m_pile": 1.0, "h_drop": 2, "h_rebound": 0.5}, id="ratio1e-6"),
    pytest.param({"m_ram": 1.0, "m_pile": 1e6, "h_drop": 1e-3, "h_rebound": 1e-4}, id="tiny-heights"),
    pytest.param({"m_ram": 800, "m_pile": 2400, "h_drop": 200, "h_rebound": 20}, id="tall-drop"),
    pytest.param({"m_ram": 1.0, "m_pile": 3.0, "h_drop": 2, "h_rebound": 0.5}, id="elastic"),
])
def test_hard_cases(bank, compiled, params):
    """No rebound; a ram a millionth of the pile's mass; tiny and tall drops; a perfectly elastic impact
    (h' = h/4 with M = 3 m gives e = 1 and no energy lost)."""
    if params["m_pile"] == 3.0 * params["m_ram"] and params["h_rebound"] * 4 == params["h_drop"]:
        solution = solve_one(bank["pile-driver"], compiled["pile-driver"], params)
        assert solution.answers is not None, solution.error
        assert solution.answers["e"].value == pytest.approx(1.0, rel=1e-12)
        assert abs(solution.answers["energy_lost"].value) <= 1e-12
        return
    check(bank, compiled, params)
