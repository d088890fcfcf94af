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
    "billiards": (["v", "r", "b", "e"], ["v_cue", "v_obj", "angle_cue", "loss_pct"]),
    "offset-spheres": (["m1", "m2", "r1", "r2", "v1", "b", "e"], ["v1_out", "v2_out", "theta1_out", "theta2_out",
                                                                  "loss_pct"]),
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


def spheres(m1, m2, r1, r2, v1, b, e):
    """Sphere 1 at v1 along x; sphere 2 at rest, its centre b off that line: velocities after, energies."""
    m1, m2, r1, r2, v1, b, e = (mp.mpf(x) for x in (m1, m2, r1, r2, v1, b, e))
    reach = r1 + r2
    n = (mp.sqrt(reach**2 - b**2) / reach, b / reach)  # the line of centres at contact: sin theta = b/(r1 + r2)
    u = (v1, mp.mpf(0))
    impulse = (1 + e) * dot(u, n) / (1 / m1 + 1 / m2)  # from momentum along n and separation = e approach
    w1 = (u[0] - impulse / m1 * n[0], u[1] - impulse / m1 * n[1])
    w2 = (impulse / m2 * n[0], impulse / m2 * n[1])
    before = m1 * dot(u, u) / 2
    after = m1 * dot(w1, w1) / 2 + m2 * dot(w2, w2) / 2
    return u, w1, w2, mp.chop(100 * (before - after) / before, 1e-40)  # e = 1: 0, not 60-digit rounding


def ref_billiards(v, r, b, e):
    u, cue, obj, loss = spheres(1, 1, r, r, v, b, e)
    return {"v_cue": speed(cue), "v_obj": speed(obj), "angle_cue": angle_between(u, cue), "loss_pct": loss}


def ref_offset_spheres(m1, m2, r1, r2, v1, b, e):
    u, w1, w2, loss = spheres(m1, m2, r1, r2, v1, b, e)
    return {"v1_out": speed(w1), "v2_out": speed(w2), "theta1_out": angle_between(u, w1),
            "theta2_out": angle_between(u, w2), "loss_pct": loss}


REFERENCES = {"incline-bounce": ref_incline_bounce, "billiards": ref_billiards, "offset-spheres": ref_offset_spheres}


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
    # sin theta = 30/57: v_n = 1.701, v_t = 1.053; equal masses: cue keeps v_n (1 - e)/2 = 0.08503 and v_t,
    # the object ball gets v_n (1 + e)/2 = 1.616; turned by atan2(1.053, 0.08503) - 31.76 deg; lost (1 - e^2) cos^2/2
    ("billiards", {"v": 2, "r": 28.5, "b": 30, "e": 0.9},
     {"v_cue": 1.056, "v_obj": 1.616, "angle_cue": 53.62, "loss_pct": 6.868}),
    # sin theta = 35/70, theta = 30 deg: v_n = 4.330, v_t = 2.5; J = 1.6 (2/3)(4.330) = 4.619; v1n' = 2.021,
    # v2n' = 4.619; sphere 1 at atan2(2.5, 2.021) = 51.05 deg from n, 21.05 from its path; sphere 2 along n;
    # lost 1/2 (2/3)(1 - 0.36)(4.330^2) = 4 J of 25 J
    ("offset-spheres", {"m1": 2, "m2": 1, "r1": 40, "r2": 30, "v1": 5, "b": 35, "e": 0.6},
     {"v1_out": 3.215, "v2_out": 4.619, "theta1_out": 21.05, "theta2_out": 30, "loss_pct": 16}),
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


@pytest.mark.parametrize("e", [0.0, 1.0, 0.9])
@pytest.mark.parametrize("offset", [0.0, 1e-9, 0.5, 1 - 1e-9, 1 - 1e-12], ids=["head-on", "b=1e-9", "half",
                                                                              "near-grazing", "grazing-1e-12"])
@pytest.mark.parametrize("v, r", [(2.0, 28.5), (1e-150, 28.5), (1e170, 28.5), (2.0, 1e-150), (2.0, 1e170)],
                         ids=["table", "tiny-v", "large-v", "tiny-r", "large-r"])
def test_billiards(bank, compiled, v, r, offset, e):
    """b as a share of 2r; head-on with e = 1 the cue ball stops, and the angle it turns is undefined.
    Closer to grazing than 1e-12 the answers are ill-conditioned: one ulp of b moves them by more than 1e-9."""
    check(bank, compiled, "billiards", {"v": v, "r": r, "b": offset * 2 * r, "e": e})


@pytest.mark.parametrize("e", [0.0, 1.0, 0.6])
@pytest.mark.parametrize("m1, m2", [(1e-12, 1.0), (1e-6, 1.0), (2.0, 1.0), (1e6, 1.0), (1e12, 1.0)],
                         ids=["m1=1e-12", "m1=1e-6", "m1=2", "m1=1e6", "m1=1e12"])
@pytest.mark.parametrize("b", [0.0, 35.0, 70 * (1 - 1e-9)], ids=["head-on", "30deg", "near-grazing"])
def test_offset_spheres(bank, compiled, m1, m2, b, e):
    """A sphere 10^12 times heavier than the one it strikes turns by 10^-12 of the line of centres' angle,
    and keeps it to 1e-9; one 10^12 times lighter bounces back (theta1_out near 180)."""
    check(bank, compiled, "offset-spheres", {"m1": m1, "m2": m2, "r1": 40.0, "r2": 30.0, "v1": 5.0, "b": b, "e": e})


@pytest.mark.parametrize("r1, r2, v1", [(1e-150, 3e-150, 5.0), (1e170, 3e170, 5.0), (40.0, 30.0, 1e-150),
                                        (40.0, 30.0, 1e170), (1e-3, 1e3, 5.0)],
                         ids=["tiny-radii", "large-radii", "tiny-v", "large-v", "radii-1e6-apart"])
def test_offset_spheres_tiny_and_large_values(bank, compiled, r1, r2, v1):
    """Lengths enter only as b/(r1 + r2), speeds only as a scale: nothing over- or underflows."""
    check(bank, compiled, "offset-spheres",
          {"m1": 2.0, "m2": 3.0, "r1": r1, "r2": r2, "v1": v1, "b": 0.4 * (r1 + r2), "e": 0.7})


# ---- refusals name the reason -----------------------------------------------------------------
@pytest.mark.parametrize("template_id, params, reason", [
    ("incline-bounce", {"h": 1.2, "beta": 90, "e": 0.5}, "beta = 90 deg is outside its domain (0, 90)"),
    ("incline-bounce", {"h": 1.2, "beta": 0, "e": 0.5}, "beta = 0 deg is outside its domain (0, 90)"),
    ("billiards", {"v": 2, "r": 28.5, "b": 57, "e": 0.9},
     "b/(r + r) is 1: the offset b must be below the sum of the radii, or cue passes object without striking it "
     "(at b = r + r it only grazes it)"),
    ("billiards", {"v": 2, "r": 28.5, "b": 60, "e": 0.9}, "b/(r + r) is 1.05263"),
    ("billiards", {"v": 2, "r": 28.5, "b": -1, "e": 0.9}, "b = -1 mm is outside its domain [0, inf)"),
    ("offset-spheres", {"m1": 2, "m2": 1, "r1": 40, "r2": 30, "v1": 5, "b": 70, "e": 0.6},
     "b/(r1 + r2) is 1: the offset b must be below the sum of the radii, or sphere1 passes sphere2"),
    ("offset-spheres", {"m1": 2, "m2": 1, "r1": 40, "r2": 30, "v1": 5, "b": 35, "e": 1.2},
     "e = 1.2 is outside its domain [0, 1]"),
])
def test_unphysical_input_is_refused_with_the_reason(bank, compiled, template_id, params, reason):
    solution = solve_one(bank[template_id], compiled[template_id], params)
    assert solution.answers is None and reason in solution.error, solution.error
