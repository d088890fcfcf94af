"""Issue 27's templates (problem bank III: springs, slopes, cars that lock together, explosions, recoil,
impulses, the separation in place of e, the head-on impact read backwards) against references written here.

Each reference writes what a student would, from first principles, in 60-digit mpmath with the float inputs
taken as exact, and never calls the solver. Every template is checked on its own example (worked by hand to
four figures), on 20 variants drawn the way its sampling draws them, and on hard cases (mass ratios far from
one, tiny and huge sizes, the limits of e and of the angles).
"""

from __future__ import annotations

from typing import Any

import mpmath as mp
import numpy as np
import pytest
import yaml

from grader.base.resources import bank_dir
from grader.solve.alternatives import values
from grader.solve.cache import alternatives_for
from grader.solve.evaluate import solve_one
from tests import references

G = mp.mpf(9.81)  # the bank's g, as the float the kernels use
KMH = mp.mpf(1000) / 3600  # m/s per km/h


def deg(angle: Any) -> Any:
    return mp.mpf(angle) * mp.pi / 180


# ---- references -------------------------------------------------------------------------------
def ref_bullet_block_spring(m_b, m_blk, v_b, k):
    """Momentum through the plastic impact; then 1/2 (m_b + m_blk) V^2 = 1/2 k x^2."""
    m_b, m_blk, v_b, k = mp.mpf(m_b) / 1000, mp.mpf(m_blk), mp.mpf(v_b), mp.mpf(k) * 1000  # g, kN/m
    common = m_b * v_b / (m_b + m_blk)
    kinetic = (m_b + m_blk) * common**2 / 2
    x = mp.sqrt(2 * kinetic / k)
    return {"V": common, "E_lost": m_b * v_b**2 / 2 - kinetic, "x_max": 1000 * x, "E_max": kinetic}


def ref_package_on_platform(m, m_p, h, k):
    """Free fall, momentum, then energy from the static deflection delta = m_p g / k down to the greatest
    compression x: 1/2 M V^2 + M g (x - delta) = 1/2 k (x^2 - delta^2), the quadratic's larger root."""
    m, m_p, h, k = mp.mpf(m), mp.mpf(m_p), mp.mpf(h), mp.mpf(k) * 1000
    mass = m + m_p
    common = m * mp.sqrt(2 * G * h) / mass
    delta = m_p * G / k
    # k x^2 / 2 - M g x - (M V^2/2 - M g delta + k delta^2/2) = 0
    c = mass * common**2 / 2 - mass * G * delta + k * delta**2 / 2
    x = (mass * G + mp.sqrt((mass * G) ** 2 + 2 * k * c)) / k
    return {"delta": 1000 * delta, "x_max": 1000 * x, "extra": 1000 * (x - delta)}


def ref_ramp_slide(h, v0, mu_k):
    """Energy down the smooth ramp; then mu_k m g d = 1/2 m v_B^2 on the floor."""
    h, v0, mu_k = mp.mpf(h), mp.mpf(v0), mp.mpf(mu_k)
    v_b = mp.sqrt(v0**2 + 2 * G * h)
    return {"v_B": v_b, "d": v_b**2 / (2 * mu_k * G)}


def ref_incline_slide(v0, beta, mu_k):
    """Up: deceleration g (sin beta + mu cos beta); down from rest: acceleration g (sin beta - mu cos beta)."""
    v0, b, mu_k = mp.mpf(v0), deg(beta), mp.mpf(mu_k)
    d = v0**2 / (2 * G * (mp.sin(b) + mu_k * mp.cos(b)))
    return {"d": d, "v_back": mp.sqrt(2 * G * d * (mp.sin(b) - mu_k * mp.cos(b)))}


def ref_intersection_crash(m_A, m_B, v_A, v_B):  # noqa: N803 (the template's names)
    """Momentum east (B's) and north (A's) of the wreck; its direction north of east; the energy."""
    m_a, m_b, v_a, v_b = mp.mpf(m_A), mp.mpf(m_B), mp.mpf(v_A) * KMH, mp.mpf(v_B) * KMH
    east, north = m_b * v_b, m_a * v_a
    v = mp.sqrt(east**2 + north**2) / (m_a + m_b)
    before = (m_a * v_a**2 + m_b * v_b**2) / 2
    return {"v": v / KMH, "theta": mp.atan2(north, east) * 180 / mp.pi,
            "loss_pct": 100 * (before - (m_a + m_b) * v**2 / 2) / before}


def ref_crash_reconstruction(m_A, m_B, v_B, theta):  # noqa: N803
    """tan theta = m_A v_A / (m_B v_B); the wreck's east component m_B v_B / M = v cos theta."""
    m_a, m_b, v_b, t = mp.mpf(m_A), mp.mpf(m_B), mp.mpf(v_B), deg(theta)
    return {"v_A": m_b * v_b * mp.tan(t) / m_a, "v": m_b * v_b / ((m_a + m_b) * mp.cos(t))}


def ref_shell_explosion(m1, m2, V, E):  # noqa: N803
    """Momentum M V = m1 v1 + m2 v2 and energy 1/2 m1 v1^2 + 1/2 m2 v2^2 = 1/2 M V^2 + E: in the centre of
    mass frame the parts move apart at w with 1/2 (m1 m2 / M) w^2 = E, the front one forward."""
    m1, m2, V, E = mp.mpf(m1), mp.mpf(m2), mp.mpf(V), mp.mpf(E) * 1000  # noqa: N806
    mass = m1 + m2
    w = mp.sqrt(2 * E * mass / (m1 * m2))
    return {"v1": V - m2 * w / mass, "v2": V + m1 * w / mass}


def ref_gun_recoil(m_gun, m_b, u):
    """0 = m_gun v_gun + m_b v_b and v_b - v_gun = u."""
    m_gun, m_b, u = mp.mpf(m_gun), mp.mpf(m_b) / 1000, mp.mpf(u)
    v_gun = -m_b * u / (m_gun + m_b)
    v_b = v_gun + u
    return {"v_recoil": -v_gun, "v_b": v_b, "E": (m_gun * v_gun**2 + m_b * v_b**2) / 2 / 1000}


def ref_wall_impulse(m, v, e, dt):
    """The ball comes back at e v: J = m (v + e v), F = J / dt."""
    m, v, e, dt = mp.mpf(m) / 1000, mp.mpf(v), mp.mpf(e), mp.mpf(dt) / 1000
    impulse = m * (v + e * v)
    return {"J": impulse, "F": impulse / dt}


def ref_cushion_stop(m, h, d):
    """v = sqrt(2 g h); J = m v; work-energy over d with the weight: (F - m g) d = 1/2 m v^2."""
    m, h, d = mp.mpf(m), mp.mpf(h), mp.mpf(d) / 1000
    v = mp.sqrt(2 * G * h)
    return {"J": m * v, "F": (m * G + m * v**2 / (2 * d)) / 1000}


def ref_oblique_moving_spheres(m_A, m_B, v_A, alpha, v_B, beta, s):  # noqa: N803
    """n from A to B along the line of centres: A's n-component v_A cos alpha, B's -v_B cos beta (toward A);
    the t-components are kept (smooth spheres); momentum along n and vB_n - vA_n = s; e = s / approach."""
    m_a, m_b, v_a, v_b, s = (mp.mpf(x) for x in (m_A, m_B, v_A, v_B, s))
    ua_n, ua_t = v_a * mp.cos(deg(alpha)), v_a * mp.sin(deg(alpha))
    ub_n, ub_t = -v_b * mp.cos(deg(beta)), v_b * mp.sin(deg(beta))
    mass, momentum = m_a + m_b, m_a * ua_n + m_b * ub_n
    va_n, vb_n = (momentum - m_b * s) / mass, (momentum + m_a * s) / mass
    before = (m_a * v_a**2 + m_b * v_b**2) / 2
    after = (m_a * (va_n**2 + ua_t**2) + m_b * (vb_n**2 + ub_t**2)) / 2
    return {"e": s / (ua_n - ub_n), "vB_n": vb_n, "vA_out": mp.sqrt(va_n**2 + ua_t**2),
            "loss_pct": 100 * (before - after) / before}


def ref_head_on_approach(m1, m2, v2, e, v1_out):
    """m1 v1 + m2 v2 = m1 v1' + m2 v2' and v2' - v1' = e (v1 - v2), solved for v1 and v2' by hand:
    v1 (m1 - e m2) = (m1 + m2) v1' - (1 + e) m2 v2."""
    m1, m2, v2, e, v1o = (mp.mpf(x) for x in (m1, m2, v2, e, v1_out))
    v1 = ((m1 + m2) * v1o - (1 + e) * m2 * v2) / (m1 - e * m2)
    return {"v1": v1, "v2_out": v1o + e * (v1 - v2)}


def ref_spring_carts(m_A, m_B, E):  # noqa: N803
    """0 = m_A v_A' + m_B v_B' (n to the right) and 1/2 m_A v_A'^2 + 1/2 m_B v_B'^2 = E: the speeds m_B u / M
    and m_A u / M with 1/2 (m_A m_B / M) u^2 = E."""
    m_a, m_b, E = mp.mpf(m_A), mp.mpf(m_B), mp.mpf(E)  # noqa: N806
    mass = m_a + m_b
    u = mp.sqrt(2 * E * mass / (m_a * m_b))
    return {"v_A": m_b * u / mass, "v_B": m_a * u / mass}


def ref_ramp_strike(m_A, m_B, h, e, mu_k):  # noqa: N803
    """Energy down the ramp, v_A = sqrt(2 g h); momentum and e with B at rest: v_B' = m_A (1 + e) v_A / M;
    then mu_k m_B g d = 1/2 m_B v_B'^2."""
    m_a, m_b, h, e, mu_k = (mp.mpf(x) for x in (m_A, m_B, h, e, mu_k))
    v_a = mp.sqrt(2 * G * h)
    v_b = m_a * (1 + e) * v_a / (m_a + m_b)
    return {"v_A": v_a, "vB_out": v_b, "d": v_b**2 / (2 * mu_k * G)}


def ref_ramp_strike_inverse(m_A, m_B, h, mu_k, d):  # noqa: N803
    """v_A = sqrt(2 g h), v_B' = sqrt(2 mu_k g d) from the slide, and v_B' = m_A (1 + e) v_A / M for e."""
    m_a, m_b, h, mu_k, d = (mp.mpf(x) for x in (m_A, m_B, h, mu_k, d))
    v_a, v_b = mp.sqrt(2 * G * h), mp.sqrt(2 * mu_k * G * d)
    return {"v_A": v_a, "vB_out": v_b, "e": v_b * (m_a + m_b) / (m_a * v_a) - 1}


def ref_package_bounce(m, m_p, h, e, k):
    """Free fall; momentum and e (n down); then the platform alone oscillates about where it rested, which is
    its static equilibrium: the greatest deflection below it is the amplitude V sqrt(m_p / k)."""
    m, m_p, h, e, k = mp.mpf(m), mp.mpf(m_p), mp.mpf(h), mp.mpf(e), mp.mpf(k) * 1000
    v0 = mp.sqrt(2 * G * h)
    mass = m + m_p
    platform = m * (1 + e) * v0 / mass
    return {"v_up": v0 * (e * m_p - m) / mass, "V": platform, "extra": 1000 * platform * mp.sqrt(m_p / k)}


def ref_pile_driver(m_ram, m_pile, h_drop, h_rebound):
    """The ram falls h_drop and comes back up at sqrt(2 g h_rebound); momentum gives the pile's velocity; the energy
    lost is T - T'. (The energy in kJ and the impulse are not asked of pile-driver: see CHANGELOG, issue 27.)"""
    m_ram, m_pile, h_drop, h_rebound = (mp.mpf(x) for x in (m_ram, m_pile, h_drop, h_rebound))
    v_ram, v_back = mp.sqrt(2 * G * h_drop), mp.sqrt(2 * G * h_rebound)
    v_pile = m_ram * (v_ram + v_back) / m_pile
    before, after = m_ram * v_ram**2 / 2, (m_ram * v_back**2 + m_pile * v_pile**2) / 2
    return {"v_pile": v_pile, "e": (v_pile + v_back) / v_ram, "loss_pct": 100 * (before - after) / before}


def ref_two_pendulums(m_A, m_B, L, theta_A, e):  # noqa: N803
    """Energy down A's swing, 1/2 v_A^2 = g L (1 - cos theta_A); momentum and e with B at rest,
    v_B' = m_A (1 + e) v_A / (m_A + m_B); energy up B's swing, cos theta_B = 1 - v_B'^2 / (2 g L)."""
    m_a, m_b, length, e = (mp.mpf(x) for x in (m_A, m_B, L, e))
    v_a = mp.sqrt(2 * G * length * (1 - mp.cos(deg(theta_A))))
    v_b = m_a * (1 + e) * v_a / (m_a + m_b)
    return {"v_A": v_a, "vB_out": v_b, "theta_B": mp.acos(1 - v_b**2 / (2 * G * length)) * 180 / mp.pi}


def ref_two_pendulums_inverse(m_A, m_B, L, theta_A, theta_B):  # noqa: N803
    """v_A and v_B' from the two swings' energy; A's velocity after from momentum, e = (v_B' - v_A') / v_A."""
    m_a, m_b, length = (mp.mpf(x) for x in (m_A, m_B, L))
    v_a = mp.sqrt(2 * G * length * (1 - mp.cos(deg(theta_A))))
    v_b = mp.sqrt(2 * G * length * (1 - mp.cos(deg(theta_B))))
    v_a_after = (m_a * v_a - m_b * v_b) / m_a
    return {"v_A": v_a, "vB_out": v_b, "e": (v_b - v_a_after) / v_a}


def ref_billiards_inverse(v, r, b, alpha):
    """sin theta = b / 2r between the cue ball's velocity and the line of centres n. Equal masses, the object ball
    at rest: the cue ball keeps v sin theta along t and has v cos theta (1 - e)/2 along n after, so its direction
    from n is theta + alpha: tan(theta + alpha) = 2 tan theta / (1 - e); the object ball takes v cos theta (1 + e)/2.
    (The cue ball's speed after is not asked: given it instead, b is a block of nine unknowns that the solver does
    not reduce, "nothing fixes b", which the inverse walk refuses.)"""
    v, r, b = mp.mpf(v), mp.mpf(r), mp.mpf(b)
    theta = mp.asin(b / (2 * r))
    e = 1 - 2 * mp.tan(theta) / mp.tan(theta + deg(alpha))
    along_n = v * mp.cos(theta)
    return {"e": e, "v_obj": along_n * (1 + e) / 2}


def ref_two_walls(h0, v0, D, W, e):  # noqa: N803
    """Smooth walls leave the vertical motion alone: the height after a time t is h0 - g t^2 / 2 throughout. The
    ball reaches wall A after D / v0, wall B after W / (e v0) more, and then moves away from B at e^2 v0 until it
    lands at sqrt(2 h0 / g) from the throw."""
    h0, v0, D, W, e = (mp.mpf(x) for x in (h0, v0, D, W, e))  # noqa: N806
    t_a, t_b = D / v0, D / v0 + W / (e * v0)
    return {"y_A": h0 - G * t_a**2 / 2, "y_B": h0 - G * t_b**2 / 2,
            "x_land": e**2 * v0 * (mp.sqrt(2 * h0 / G) - t_b)}


def ref_shell_landing(m_A, m_B, v0, alpha):  # noqa: N803
    """At the top the shell moves at v0 cos alpha, H = (v0 sin alpha)^2 / 2 g up, after t = v0 sin alpha / g and
    v0 cos alpha t along; A is left at rest, so momentum gives B (m_A + m_B) v0 cos alpha / m_B; B falls H in
    the same time t, landing (v0 cos alpha + v_B) t from the gun; the energy added is T' - T."""
    m_a, m_b, v0 = mp.mpf(m_A), mp.mpf(m_B), mp.mpf(v0)
    v_x, v_y = v0 * mp.cos(deg(alpha)), v0 * mp.sin(deg(alpha))
    t = v_y / G
    v_b = (m_a + m_b) * v_x / m_b
    return {"H": v_y**2 / (2 * G), "v_B": v_b, "x_land": (v_x + v_b) * t,
            "E": (m_b * v_b**2 - (m_a + m_b) * v_x**2) / 2 / 1000}


REFERENCES = {
    "bullet-block-spring": ref_bullet_block_spring, "package-on-platform": ref_package_on_platform,
    "ramp-slide": ref_ramp_slide, "incline-slide": ref_incline_slide,
    "intersection-crash": ref_intersection_crash, "crash-reconstruction": ref_crash_reconstruction,
    "shell-explosion": ref_shell_explosion, "gun-recoil": ref_gun_recoil, "wall-impulse": ref_wall_impulse,
    "cushion-stop": ref_cushion_stop, "oblique-moving-spheres": ref_oblique_moving_spheres,
    "head-on-approach": ref_head_on_approach, "spring-carts": ref_spring_carts, "ramp-strike": ref_ramp_strike,
    "ramp-strike-inverse": ref_ramp_strike_inverse, "package-bounce": ref_package_bounce,
    "pile-driver": ref_pile_driver, "two-pendulums": ref_two_pendulums,
    "two-pendulums-inverse": ref_two_pendulums_inverse, "billiards-inverse": ref_billiards_inverse,
    "two-walls": ref_two_walls, "shell-landing": ref_shell_landing,
}


def check(bank, compiled, template_id, params):
    references.check(bank, compiled, template_id, params, REFERENCES[template_id])


def test_every_new_template_is_shipped_with_a_reference(bank):
    assert set(REFERENCES) <= set(bank)


# ---- the examples, worked by hand to four figures ---------------------------------------------
KNOWN = [
    # V = 0.010(500)/2.010 = 2.488 m/s; lost 1250 - 6.219 = 1244 J; x = sqrt(2(6.219)/5000) = 49.88 mm
    ("bullet-block-spring", {"m_b": 10, "m_blk": 2, "v_b": 500, "k": 5},
     {"V": 2.488, "E_lost": 1244.0, "x_max": 49.88, "E_max": 6.219}),
    # v0 = sqrt(2(9.81)(0.5)) = 3.132, V = 1.044 m/s; delta = 20(9.81)/10000 = 19.62 mm;
    # 5000 x^2 - 294.3 x - (16.35 - 5.774 + 1.925) = 0:
    # x = (294.3 + sqrt(294.3^2 + 2(10^4)(12.50)))/10^4 = 87.45 mm
    ("package-on-platform", {"m": 10, "m_p": 20, "h": 0.5, "k": 10},
     {"delta": 19.62, "x_max": 87.45, "extra": 67.83}),
    # v_B = sqrt(1 + 2(9.81)(1.2)) = 4.954 m/s; d = 24.54/(2(0.3)(9.81)) = 4.170 m
    ("ramp-slide", {"h": 1.2, "v0": 1, "mu_k": 0.3}, {"v_B": 4.954, "d": 4.17}),
    # d = 25/(2(9.81)(0.5 + 0.1732)) = 1.893 m; v = sqrt(2(9.81)(1.893)(0.5 - 0.1732)) = 3.484 m/s
    ("incline-slide", {"v0": 5, "beta": 30, "mu_k": 0.2}, {"d": 1.893, "v_back": 3.484}),
    # east 1200(60) = 72000, north 1500(50) = 75000 kg km/h; v = 103968/2700 = 38.51 km/h at 46.17 deg;
    # T before 1500(2500) + 1200(3600) = 8.07e6, after 2700(38.51^2) = 4.003e6 (x 1/2 (km/h)^2): 50.39 % lost
    ("intersection-crash", {"m_A": 1500, "m_B": 1200, "v_A": 50, "v_B": 60},
     {"v": 38.51, "theta": 46.17, "loss_pct": 50.39}),
    # v_A = 1200(60) tan 40 / 1500 = 40.28 km/h; v = 72000/(2700 cos 40) = 34.81 km/h
    ("crash-reconstruction", {"m_A": 1500, "m_B": 1200, "v_B": 60, "theta": 40}, {"v_A": 40.28, "v": 34.81}),
    # w = sqrt(2(24000)(10)/24) = 141.4 m/s; v1 = 200 - 0.6 w = 115.1, v2 = 200 + 0.4 w = 256.6 m/s
    ("shell-explosion", {"m1": 4, "m2": 6, "V": 200, "E": 24}, {"v1": 115.1, "v2": 256.6}),
    # v_gun = -0.02(600)/4.02 = -2.985 m/s; v_b = 597.0 m/s; E = 1/2 (4)(0.02)(600^2)/4.02 = 3.582 kJ
    ("gun-recoil", {"m_gun": 4, "m_b": 20, "u": 600}, {"v_recoil": 2.985, "v_b": 597.0, "E": 3.582}),
    # J = 0.2(12)(1.6) = 3.84 N s; F = 3.84/0.008 = 480 N
    ("wall-impulse", {"m": 200, "v": 12, "e": 0.6, "dt": 8}, {"J": 3.84, "F": 480.0}),
    # v = sqrt(2(9.81)(1.5)) = 5.425; J = 54.25 N s; F = 98.1 (1 + 1.5/0.08) = 1937 N
    ("cushion-stop", {"m": 10, "h": 1.5, "d": 80}, {"J": 54.25, "F": 1.937}),
    # A: (5.196, 3); B: (-1.414, 1.414); p = 8.271; vA_n = (8.271 - 3.6)/3.5 = 1.335, vB_n = 3.735;
    # e = 2.4/6.610 = 0.3631; vA' = sqrt(1.335^2 + 9) = 3.283; T = 36 + 3 = 39, T' = 10.78 + 11.96 = 22.75: 41.69 % lost
    ("oblique-moving-spheres", {"m_A": 2, "m_B": 1.5, "v_A": 6, "alpha": 30, "v_B": 2, "beta": 45, "s": 2.4},
     {"e": 0.3631, "vB_n": 3.735, "vA_out": 3.283, "loss_pct": 41.69}),
    # v1 (4 - 0.9) = 5.5(-0.3) - 1.6(1.5)(-5) = 10.35, v1 = 3.339 m/s; v2' = -0.3 + 0.6(8.339) = 4.703 m/s
    ("head-on-approach", {"m1": 4, "m2": 1.5, "v2": -5, "e": 0.6, "v1_out": -0.3}, {"v1": 3.339, "v2_out": 4.703}),
    # u = sqrt(2(15)(5)/6) = 5 m/s; A at 3(5)/5 = 3 m/s, B at 2(5)/5 = 2 m/s
    ("spring-carts", {"m_A": 2, "m_B": 3, "E": 15}, {"v_A": 3.0, "v_B": 2.0}),
    # v0 = sqrt(2(9.81)(0.8)) = 3.962 m/s; up 3.962(15 - 5)/35 = 1.132 m/s; V = 5(1.5)(3.962)/35 = 0.8490 m/s;
    # amplitude 0.8490 sqrt(30/10^4) = 46.50 mm
    ("package-bounce", {"m": 5, "m_p": 30, "h": 0.8, "e": 0.5, "k": 10}, {"v_up": 1.132, "V": 0.849, "extra": 46.5}),
    # v_A = sqrt(2(9.81)(1.2)) = 4.852 m/s; v_B' = 2(1.6)(4.852)/5 = 3.105 m/s; d = 9.643/(2(0.3)(9.81)) = 1.638 m
    ("ramp-strike", {"m_A": 2, "m_B": 3, "h": 1.2, "e": 0.6, "mu_k": 0.3}, {"v_A": 4.852, "vB_out": 3.105, "d": 1.638}),
    # v_A = sqrt(2(9.81)(1.1)) = 4.646 m/s; v_B' = sqrt(2(0.28)(9.81)(2)) = 3.315 m/s; e = 3.315(4.4)/(2.2(4.646)) - 1
    ("ramp-strike-inverse", {"m_A": 2.2, "m_B": 2.2, "h": 1.1, "mu_k": 0.28, "d": 2},
     {"v_A": 4.646, "vB_out": 3.315, "e": 0.427}),
    # Sample Problem 3/28: v = sqrt(2(9.81)(2)) = 6.264 down, 1.401 back up; v_pile = 800(7.665)/2400 = 2.555 m/s;
    # T = 15 696 J, T' = 784.8 + 7834 = 8619 J: 7077 J, 45.09 % lost
    ("pile-driver", {"m_ram": 800, "m_pile": 2400, "h_drop": 2, "h_rebound": 0.1},
     {"v_pile": 2.555, "e": 0.6315, "loss_pct": 45.09}),
    # v_A = sqrt(2(9.81)(1.2)(1 - cos 30)) = 1.776 m/s; v_B' = 0.6(1.8)(1.776)/1.0 = 1.918 m/s;
    # cos theta_B = 1 - 1.918^2/(2(9.81)(1.2)) = 0.8437: 32.46 deg
    ("two-pendulums", {"m_A": 0.6, "m_B": 0.4, "L": 1.2, "theta_A": 30, "e": 0.8},
     {"v_A": 1.776, "vB_out": 1.918, "theta_B": 32.46}),
    # v_B' = sqrt(2(9.81)(1.2)(1 - cos 28)) = 1.660 m/s; v_A' = (0.55(1.776) - 0.45(1.660))/0.55 = 0.4178 m/s;
    # e = (1.660 - 0.4178)/1.776 = 0.6995
    ("two-pendulums-inverse", {"m_A": 0.55, "m_B": 0.45, "L": 1.2, "theta_A": 30, "theta_B": 28},
     {"v_A": 1.776, "vB_out": 1.66, "e": 0.6995}),
    # sin theta = 30/57: theta = 31.76 deg; e = 1 - 2 tan 31.76/tan 79.76 = 1 - 1.238/5.535 = 0.7763;
    # along n 2 cos 31.76 = 1.701: v_obj = 1.701(1.776)/2 = 1.510 m/s
    ("billiards-inverse", {"v": 2, "r": 28.5, "b": 30, "alpha": 48}, {"e": 0.7763, "v_obj": 1.51}),
    # t_A = 2/10.5 = 0.1905 s, y_A = 5.5 - 4.905(0.1905)^2 = 5.322 m; t_B = 0.1905 + 4.5/7.875 = 0.7619 s,
    # y_B = 5.5 - 4.905(0.7619)^2 = 2.653 m; lands at sqrt(11/9.81) = 1.0589 s: x = 0.5625(10.5)(0.2970) = 1.754 m
    ("two-walls", {"h0": 5.5, "v0": 10.5, "D": 2, "W": 4.5, "e": 0.75}, {"y_A": 5.322, "y_B": 2.653, "x_land": 1.754}),
    # v_x = v_y = 80 cos 45 = 56.57 m/s; H = 56.57^2/19.62 = 163.1 m; v_B = 10(56.57)/6 = 94.28 m/s;
    # t = 56.57/9.81 = 5.766 s: x = (56.57 + 94.28)(5.766) = 869.9 m; E = 3(94.28^2) - 5(56.57^2) = 10.67 kJ
    ("shell-landing", {"m_A": 4, "m_B": 6, "v0": 80, "alpha": 45},
     {"H": 163.1, "v_B": 94.28, "x_land": 869.9, "E": 10.67}),
]


@pytest.mark.parametrize(("template_id", "params", "answers"), KNOWN, ids=[k[0] for k in KNOWN])
def test_known_answers(bank, compiled, template_id, params, answers):
    """The hand-worked values to four figures, the reference to 1e-9, and the template's own example."""
    assert bank[template_id].example == params
    references.check_known(bank, compiled, template_id, params, answers, REFERENCES[template_id])


# ---- 20 variants each, drawn as the template's sampling draws them -----------------------------
def drawn(template_id: str, count: int = 20) -> list[dict[str, float]]:
    """``count`` draws from the template's sampling ranges, rounded to its printed decimals."""
    raw = yaml.safe_load((bank_dir() / f"{template_id}.yaml").read_text(encoding="utf-8"))["parameters"]
    rng = np.random.default_rng(27)
    return [{name: printed(float(rng.uniform(*spec["sample"]["uniform"])), spec) for name, spec in raw.items()}
            for _ in range(count)]


def printed(value: float, spec: dict[str, Any]) -> float:
    """``value`` rounded as the sheet prints it: to ``decimals``, or to ``sig_figs`` significant figures."""
    if "decimals" in spec:
        return round(value, spec["decimals"])
    return float(f"{value:.{spec['sig_figs']}g}")


# Where the sampling box holds draws the physics refuses (the check-bank keeps them under 10 %): what the reference
# says makes a draw impossible; the solver must refuse those, and 20 possible ones are checked.
IMPOSSIBLE = {"two-pendulums-inverse": lambda params: not 0 <= ref_two_pendulums_inverse(**params)["e"] <= 1}


@pytest.mark.parametrize("template_id", REFERENCES)
def test_twenty_sampled_variants(bank, compiled, template_id):
    impossible = IMPOSSIBLE.get(template_id, lambda params: False)
    draws = drawn(template_id, 40)
    possible = [params for params in draws if not impossible(params)][:20]
    assert len(possible) == 20
    for params in possible:
        check(bank, compiled, template_id, params)
    for params in draws:
        if impossible(params):
            assert "coefficient of restitution" in str(solve_one(bank[template_id], compiled[template_id],
                                                                 params).error)


# ---- hard cases -------------------------------------------------------------------------------
HARD = [
    ("bullet-block-spring", {"m_b": 1e-6, "m_blk": 1e6, "v_b": 700, "k": 1e-3}),
    ("bullet-block-spring", {"m_b": 1e9, "m_blk": 1e-3, "v_b": 1e-100, "k": 1e100}),
    ("package-on-platform", {"m": 1e-6, "m_p": 40, "h": 1.5, "k": 30}),  # a hair below its rest
    ("package-on-platform", {"m": 10, "m_p": 20, "h": 1e-9, "k": 10}),  # barely dropped
    ("package-on-platform", {"m": 1e6, "m_p": 1e-3, "h": 1e-12, "k": 1e9}),
    ("ramp-slide", {"h": 1e-9, "v0": 0, "mu_k": 1e-6}),
    ("ramp-slide", {"h": 1e100, "v0": 1e50, "mu_k": 5}),
    ("incline-slide", {"v0": 5, "beta": 89.9, "mu_k": 0.2}),
    ("incline-slide", {"v0": 1e-6, "beta": 30, "mu_k": 0}),
    ("incline-slide", {"v0": 5, "beta": 20, "mu_k": 0.36}),  # tan beta a hair above mu_k: it creeps back
    ("intersection-crash", {"m_A": 1e-6, "m_B": 1e6, "v_A": 50, "v_B": 60}),
    ("intersection-crash", {"m_A": 1500, "m_B": 1200, "v_A": 1e-9, "v_B": 60}),
    ("intersection-crash", {"m_A": 1500, "m_B": 1200, "v_A": 1e9, "v_B": 60}),
    ("crash-reconstruction", {"m_A": 1e6, "m_B": 1, "v_B": 60, "theta": 0.001}),
    ("crash-reconstruction", {"m_A": 1, "m_B": 1e6, "v_B": 60, "theta": 89.999}),
    ("shell-explosion", {"m1": 1e-6, "m2": 1e6, "V": 200, "E": 24}),
    ("shell-explosion", {"m1": 4, "m2": 6, "V": -200, "E": 1e-12}),
    ("shell-explosion", {"m1": 4, "m2": 6, "V": 0, "E": 24}),  # the parts pushed apart from rest
    ("gun-recoil", {"m_gun": 1e6, "m_b": 1e-3, "u": 600}),
    ("gun-recoil", {"m_gun": 1e-3, "m_b": 1e6, "u": 1e-100}),
    ("wall-impulse", {"m": 1e-9, "v": 1e150, "e": 1, "dt": 1e-9}),
    ("wall-impulse", {"m": 50, "v": 1e-150, "e": 0, "dt": 20}),
    ("cushion-stop", {"m": 1e6, "h": 1e-12, "d": 1e9}),  # the weight all but alone
    ("cushion-stop", {"m": 1e-6, "h": 1e3, "d": 1e-6}),
    ("oblique-moving-spheres", {"m_A": 1e-6, "m_B": 1e6, "v_A": 6, "alpha": 0, "v_B": 2, "beta": 0, "s": 7.9}),
    ("oblique-moving-spheres", {"m_A": 2, "m_B": 1.5, "v_A": 6, "alpha": 30, "v_B": 2, "beta": 45, "s": 0}),
    ("oblique-moving-spheres", {"m_A": 1e6, "m_B": 1e-6, "v_A": 6, "alpha": 80, "v_B": 2, "beta": 80, "s": 1.3}),
    ("head-on-approach", {"m1": 1e6, "m2": 1e-6, "v2": -5, "e": 1, "v1_out": -0.3}),
    ("head-on-approach", {"m1": 4, "m2": 1.5, "v2": -5, "e": 0, "v1_out": -0.3}),
    ("head-on-approach", {"m1": 1e-3, "m2": 1e-6, "v2": -1e-100, "e": 0.5, "v1_out": -1e-101}),
    ("spring-carts", {"m_A": 1e-6, "m_B": 1e6, "E": 15}),
    ("package-bounce", {"m": 1e-6, "m_p": 1e6, "h": 1.5, "e": 1, "k": 1e-3}),
    ("package-bounce", {"m": 2, "m_p": 40, "h": 1e-12, "e": 0.06, "k": 1e9}),
    ("spring-carts", {"m_A": 1e100, "m_B": 1e100, "E": 1e-100}),
    ("ramp-strike", {"m_A": 1e-6, "m_B": 1e6, "h": 1.2, "e": 1, "mu_k": 0.3}),
    ("ramp-strike", {"m_A": 1e6, "m_B": 1e-6, "h": 1e-9, "e": 0, "mu_k": 1e-6}),
    ("ramp-strike-inverse", {"m_A": 2, "m_B": 2, "h": 1, "mu_k": 0.25, "d": 3.9}),  # e a hair below 1
    ("ramp-strike-inverse", {"m_A": 1e6, "m_B": 1e-6, "h": 1e-9, "mu_k": 1e-3, "d": 1.5e-6}),
    ("pile-driver", {"m_ram": 1e-6, "m_pile": 1e6, "h_drop": 2, "h_rebound": 1.999999}),  # all but elastic
    ("pile-driver", {"m_ram": 800, "m_pile": 2400, "h_drop": 2, "h_rebound": 0}),  # the ram stops dead
    ("two-pendulums", {"m_A": 1, "m_B": 1, "L": 1.2, "theta_A": 30, "e": 1}),  # B swings exactly as high as A fell
    ("two-pendulums", {"m_A": 1e-6, "m_B": 1e6, "L": 1, "theta_A": 90, "e": 0}),  # B barely moves
    ("two-pendulums", {"m_A": 1, "m_B": 2, "L": 1e3, "theta_A": 1e-4, "e": 0.5}),  # 1 - cos cancels in float64
    ("two-pendulums", {"m_A": 1e6, "m_B": 1e-6, "L": 0.5, "theta_A": 40, "e": 1}),  # B leaves at twice A's speed
    ("two-pendulums-inverse", {"m_A": 1, "m_B": 1, "L": 1, "theta_A": 30, "theta_B": 30}),  # e = 1
    ("two-pendulums-inverse", {"m_A": 1, "m_B": 1, "L": 1, "theta_A": 30, "theta_B": 14.872}),  # e = 7e-5
    ("two-pendulums-inverse", {"m_A": 1, "m_B": 3, "L": 1e-3, "theta_A": 1e-3, "theta_B": 0.4e-3}),
    ("billiards-inverse", {"v": 2, "r": 28.5, "b": 0.01, "alpha": 0.03}),  # all but head-on: barely turned
    ("billiards-inverse", {"v": 2, "r": 28.5, "b": 56.9, "alpha": 2.5}),  # all but grazing
    ("billiards-inverse", {"v": 1e-100, "r": 28.5, "b": 30, "alpha": 58.2}),  # e a hair below 1
    ("billiards-inverse", {"v": 1e100, "r": 1e-6, "b": 1e-6, "alpha": 40}),
    ("two-walls", {"h0": 5.5, "v0": 10.5, "D": 1e-9, "W": 4.5, "e": 0.75}),  # thrown from the foot of wall A
    ("two-walls", {"h0": 5.5, "v0": 10.5, "D": 2, "W": 5, "e": 1}),
    ("two-walls", {"h0": 5e3, "v0": 1e3, "D": 2e3, "W": 3e3, "e": 0.3}),
    ("shell-landing", {"m_A": 1e-6, "m_B": 1e6, "v0": 80, "alpha": 45}),  # A a crumb: B flies on as the shell would
    ("shell-landing", {"m_A": 1e6, "m_B": 1e-6, "v0": 80, "alpha": 45}),
    ("shell-landing", {"m_A": 4, "m_B": 6, "v0": 80, "alpha": 89.999}),  # fired all but straight up
    ("shell-landing", {"m_A": 4, "m_B": 6, "v0": 1e-3, "alpha": 1e-6}),  # all but level
]


@pytest.mark.parametrize(("template_id", "params"), HARD, ids=[f"{t}-{i}" for i, (t, _) in enumerate(HARD)])
def test_hard_cases(bank, compiled, template_id, params):
    check(bank, compiled, template_id, params)


# ---- the worked solution and the mistakes ------------------------------------------------------
def test_ball_a_is_released_at_its_angle_and_swings_down(bank, compiled):
    """A's swing comes first in two-pendulums: the page says A swings down to the lowest point; B's swing, after
    the impact, goes up (as the ballistic pendulum's block does)."""
    from grader.render.worked import page_wording

    said = [page_wording(step, bank["two-pendulums"]) for step in compiled["two-pendulums"].steps]
    assert any(line.startswith("A, released at rest with the cord") and "swings down" in line for line in said)
    assert any(line.startswith("B swings up from vB_out") for line in said)


def test_a_ball_on_a_cord_has_the_swings_mistakes(bank):
    """The height risen taken as L cos theta: v_A = sqrt(2 g L cos theta_A), worked by hand on the example."""
    found = [a for a in alternatives_for(bank["two-pendulums"]).for_answer("v_A") if a.id == "swing.height_cos"]
    assert len(found) == 1
    got = values(alternatives_for(bank["two-pendulums"]), found[0],
                 {k: np.array([float(v)]) for k, v in bank["two-pendulums"].example.items()})
    assert float(got[0]) == pytest.approx(float(mp.sqrt(2 * G * mp.mpf(1.2) * mp.cos(deg(30)))), rel=1e-9)


def test_the_angle_b_swings_to_has_the_swings_mistakes(bank):
    """The height risen taken as L sin theta in both swings: v_A^2 = 2 g L sin 30, v_B' = 1.08 v_A (the example's
    m_A (1 + e)/(m_A + m_B)) and sin theta_B = v_B'^2/(2 g L) = 1.08^2 sin 30 = 0.5832: 35.68 degrees. As
    L cos theta, cos theta_B = 1.08^2 cos 30 > 1: no angle, so that mistake matches no answer."""
    template = bank["two-pendulums"]
    found = {a.id: a for a in alternatives_for(template).for_answer("theta_B") if a.kind == "mistake"}
    params = {k: np.array([float(v)]) for k, v in template.example.items()}
    by_hand = mp.asin(mp.mpf("1.08") ** 2 * mp.sin(deg(30))) * 180 / mp.pi
    assert float(values(alternatives_for(template), found["swing.height_sin"], params)[0]) == pytest.approx(
        float(by_hand), rel=1e-9)
    assert np.isnan(values(alternatives_for(template), found["swing.height_cos"], params)[0])
