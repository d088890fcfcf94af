"""The bank's answers as a textbook writes them, from first principles, for the benchmarks' baselines.

Each function takes a math namespace ``xp`` (``sqrt``, ``sin``, ``cos``, ``asin``, ``atan2``, ``hypot``,
``radians``, ``degrees``, and ``where(condition, a, b)``, a choice made per row) and the template's
parameters in its units, and returns the numeric answers in its units. With numpy (:data:`NUMPY`) on
columns it is the closed form a competent user writes in a minimal script (``minimal_solve.py``); with
mpmath at 50 digits it is the exact reference the accuracy benchmark measures against (``accuracy.py``
builds that namespace: importing mpmath here would slow the minimal script down). Nothing here comes
from grader: energies are ``T - T'``, velocities the momentum and restitution equations solved by hand,
the plain forms grader's stable forms improve on.

Adding a template: write its function here and list it in :data:`FORMS`. ``swing_angle`` and ``skid_length``
are two inverse templates asked forward (the speed they find given), for the accuracy benchmark's sweep.
"""

from __future__ import annotations

from collections.abc import Callable
from types import SimpleNamespace
from typing import Any

import numpy as np

G = 9.81  # the bank's g, m/s^2

NUMPY = SimpleNamespace(sqrt=np.sqrt, sin=np.sin, cos=np.cos, asin=np.arcsin, atan2=np.arctan2, hypot=np.hypot,
                        radians=np.radians, degrees=np.degrees, where=np.where)


def _angle_between(xp: Any, n1: Any, t1: Any, n2: Any, t2: Any) -> Any:
    """The angle between two velocities (n, t), 0 to 180 degrees."""
    return xp.degrees(xp.atan2(abs(n1 * t2 - t1 * n2), n1 * n2 + t1 * t2))


def _loss_pct(before: Any, after: Any) -> Any:
    return 100 * (before - after) / before


def _line(v: Any, m1: Any, m2: Any, e: Any, u2: Any = 0) -> tuple[Any, Any]:
    """Velocities after a direct central impact of m1 at v on m2 at u2: momentum and restitution."""
    momentum = m1 * v + m2 * u2
    return (momentum - m2 * e * (v - u2)) / (m1 + m2), (momentum + m1 * e * (v - u2)) / (m1 + m2)


def drop_rebound(xp: Any, h_drop: Any, h_rebound: Any) -> dict[str, Any]:
    return {"e": xp.sqrt(h_rebound / h_drop), "loss_pct": _loss_pct(h_drop, h_rebound)}


def pile_driver(xp: Any, m_ram: Any, m_pile: Any, h_drop: Any, h_rebound: Any) -> dict[str, Any]:
    v_ram = xp.sqrt(2 * G * h_drop)  # just before the impact, down
    v_back = xp.sqrt(2 * G * h_rebound)  # just after, up
    v_pile = m_ram * (v_ram + v_back) / m_pile  # momentum
    return {"v_pile": v_pile, "e": (v_pile + v_back) / v_ram,
            "loss_pct": _loss_pct(m_ram * v_ram**2, m_ram * v_back**2 + m_pile * v_pile**2)}


def car_collision(xp: Any, p: Any, e: Any) -> dict[str, Any]:
    """The numeric answers: vA'/v = (1 - e p)/(1 + p), vB'/v = (1 + e)/(1 + p) (p = mB/mA)."""
    return {"vA_ratio": (1 - e * p) / (1 + p), "vB_ratio": (1 + e) / (1 + p)}


def ball_plate(xp: Any, v: Any, theta: Any, e: Any) -> dict[str, Any]:
    normal, tangent = e * v * xp.sin(xp.radians(theta)), v * xp.cos(xp.radians(theta))
    return {"v_out": xp.hypot(normal, tangent), "theta_out": xp.degrees(xp.atan2(normal, tangent))}


def oblique_spheres(xp: Any, v1: Any, theta: Any, e: Any, m1: Any, m2: Any) -> dict[str, Any]:
    normal, tangent = v1 * xp.cos(xp.radians(theta)), v1 * xp.sin(xp.radians(theta))
    n1, n2 = _line(normal, m1, m2, e)
    v1_out = xp.hypot(n1, tangent)
    return {"v1_out": v1_out, "v2_out": abs(n2), "theta1_out": xp.degrees(xp.atan2(n1, tangent)),
            "loss_pct": _loss_pct(m1 * v1**2, m1 * v1_out**2 + m2 * n2**2)}


def head_on(xp: Any, m1: Any, m2: Any, v1: Any, v2: Any, e: Any) -> dict[str, Any]:
    v1_out, v2_out = _line(v1, m1, m2, e, v2)
    before, after = (m1 * v1**2 + m2 * v2**2) / 2, (m1 * v1_out**2 + m2 * v2_out**2) / 2
    return {"v1_out": v1_out, "v2_out": v2_out, "loss_pct": _loss_pct(before, after), "energy_lost": before - after,
            "impulse": abs(m1 * (v1 - v1_out))}  # N·s: cart 1's change of momentum


def head_on_inverse(xp: Any, m1: Any, m2: Any, v1: Any, v2: Any, v1_out: Any) -> dict[str, Any]:
    v2_out = v2 + m1 * (v1 - v1_out) / m2  # momentum
    return {"v2_out": v2_out, "e": (v2_out - v1_out) / (v1 - v2),
            "loss_pct": _loss_pct(m1 * v1**2 + m2 * v2**2, m1 * v1_out**2 + m2 * v2_out**2)}


def coupling(xp: Any, m_A: Any, m_B: Any, v_A: Any, v_B: Any) -> dict[str, Any]:  # noqa: N803 (its names)
    """Masses in Mg, speeds in km/h; energy in kJ: (1/2) (1000 m) (v/3.6)^2 / 1000."""
    v_common = (m_A * v_A + m_B * v_B) / (m_A + m_B)
    before = (m_A * (v_A / 3.6) ** 2 + m_B * (v_B / 3.6) ** 2) / 2
    after = (m_A + m_B) * (v_common / 3.6) ** 2 / 2
    return {"v_common": v_common, "energy_lost": before - after, "loss_pct": _loss_pct(before, after),
            "impulse": abs(m_A * (v_A - v_common) / 3.6)}  # kN·s: (1000 m_A) (Δv/3.6) N·s, over 1000


def moving_plate(xp: Any, h: Any, u: Any, e: Any) -> dict[str, Any]:
    """The ball arrives at sqrt(2 g h) down, the plate moves up at u: v_out - u = e (v + u)."""
    v_out = u + e * (xp.sqrt(2 * G * h) + u)
    return {"v_out": v_out, "h_out": v_out**2 / (2 * G)}


def incline_bounce(xp: Any, h: Any, beta: Any, e: Any) -> dict[str, Any]:
    v = xp.sqrt(2 * G * h)
    normal, tangent = e * v * xp.cos(xp.radians(beta)), v * xp.sin(xp.radians(beta))
    return {"v_out": xp.hypot(normal, tangent), "theta_out": xp.degrees(xp.atan2(normal, tangent))}


def billiards(xp: Any, v: Any, r: Any, b: Any, e: Any) -> dict[str, Any]:
    """Equal masses: the line of centres makes asin(b / 2r) with the cue ball's velocity."""
    v_cue, v_obj, angle_cue, _, loss = _offset(xp, 1, 1, v, xp.asin(b / (2 * r)), e)
    return {"v_cue": v_cue, "v_obj": v_obj, "angle_cue": angle_cue, "loss_pct": loss}


def offset_spheres(xp: Any, m1: Any, m2: Any, r1: Any, r2: Any, v1: Any, b: Any, e: Any) -> dict[str, Any]:
    answers = _offset(xp, m1, m2, v1, xp.asin(b / (r1 + r2)), e)
    return dict(zip(("v1_out", "v2_out", "theta1_out", "theta2_out", "loss_pct"), answers, strict=True))


def _offset(xp: Any, m1: Any, m2: Any, v: Any, theta: Any, e: Any) -> tuple[Any, ...]:
    """Sphere 2 at rest, struck at ``theta`` from the line of centres n (t across it: unchanged for
    sphere 1, zero for sphere 2): both speeds after, both angles from sphere 1's direction, loss in %."""
    normal, tangent = v * xp.cos(theta), v * xp.sin(theta)
    n1, n2 = _line(normal, m1, m2, e)
    v1_out, v2_out = xp.hypot(n1, tangent), abs(n2)
    return (v1_out, v2_out, _angle_between(xp, normal, tangent, n1, tangent),
            _angle_between(xp, normal, tangent, n2, 0 * n2), _loss_pct(m1 * v**2, m1 * v1_out**2 + m2 * v2_out**2))


def three_balls(xp: Any, m1: Any, m2: Any, m3: Any, v: Any, e: Any) -> dict[str, Any]:
    v1_out, v2_between = _line(v, m1, m2, e)
    v2_out, v3_out = _line(v2_between, m2, m3, e)
    return {"v1_out": v1_out, "v2_out": v2_out, "v3_out": v3_out}


def two_rebounds(xp: Any, h1: Any, h2: Any) -> dict[str, Any]:
    """Each bounce keeps e^2 of the height: e^2 = h2/h1, h0 = h1/e^2; the energy left is m g h2."""
    h0 = h1 * h1 / h2
    return {"e": xp.sqrt(h2 / h1), "h0": h0, "loss_pct": _loss_pct(h0, h2)}


def successive_bounces(xp: Any, h0: Any, e: Any, n: Any) -> dict[str, Any]:
    """Each rebound leaves at e times the speed it arrived with, so it rises e^2 times as high: h_n = h0 e^(2n).
    To rest: the drop, then each rebound height up and down (geometric, ratio e^2); the fall time
    sqrt(2 h0/g), then each rebound's rise and fall (geometric, ratio e)."""
    fall = xp.sqrt(2 * h0 / G)
    return {"h_n": h0 * e ** (2 * n), "distance": h0 * (1 + e**2) / (1 - e**2), "t_total": fall * (1 + e) / (1 - e)}


def ballistic_pendulum(xp: Any, m_b: Any, m_blk: Any, L: Any, theta_max: Any) -> dict[str, Any]:  # noqa: N803
    """Bullet in g, block in kg. The swing: V^2 = 2 g L (1 - cos theta) = (2 sqrt(g L) sin(theta/2))^2; the
    impact (plastic): momentum m v = (m + M) V; the loss as T - T' over T."""
    bullet = m_b / 1000
    swing = 2 * xp.sqrt(G * L) * xp.sin(xp.radians(theta_max) / 2)
    v_bullet = (bullet + m_blk) / bullet * swing
    return {"v_bullet": v_bullet, "loss_pct": _loss_pct(bullet * v_bullet**2, (bullet + m_blk) * swing**2)}


def swing_angle(xp: Any, m_b: Any, m_blk: Any, L: Any, v_bullet: Any) -> dict[str, Any]:  # noqa: N803
    """ballistic-pendulum asked forward (the bullet's speed given): V = m v / (m + M), then
    sin(theta/2) = V / (2 sqrt(g L)); the loss as T - T' over T."""
    bullet = m_b / 1000
    swing = bullet * v_bullet / (bullet + m_blk)
    return {"theta_max": xp.degrees(2 * xp.asin(swing / (2 * xp.sqrt(G * L)))),
            "loss_pct": _loss_pct(bullet * v_bullet**2, (bullet + m_blk) * swing**2)}

def skid(xp: Any, m_A: Any, m_B: Any, d: Any, mu_k: Any) -> dict[str, Any]:  # noqa: N803 (its names)
    """The skid: (m_A + m_B) v^2 / 2 = mu_k (m_A + m_B) g d; the impact (plastic): m_A v_A = (m_A + m_B) v;
    v_A in km/h (3.6 km/h per m/s); the loss as T - T' over T."""
    after = xp.sqrt(2 * mu_k * G * d)
    before = (m_A + m_B) / m_A * after
    return {"v_A": 3.6 * before, "loss_pct": _loss_pct(m_A * before**2, (m_A + m_B) * after**2)}


def skid_length(xp: Any, m_A: Any, m_B: Any, mu_k: Any, v_A: Any) -> dict[str, Any]:  # noqa: N803 (its names)
    """skid asked forward (car A's speed given, in km/h): V = m_A v_A / (m_A + m_B), then d = V^2 / (2 mu_k g)."""
    before = v_A / 3.6
    after = m_A * before / (m_A + m_B)
    return {"d": after**2 / (2 * mu_k * G), "loss_pct": _loss_pct(m_A * before**2, (m_A + m_B) * after**2)}

def wall_throw(xp: Any, h0: Any, D: Any, v0: Any, alpha: Any, e: Any) -> dict[str, Any]:  # noqa: N803
    """To the wall in t1 = D / (v0 cos alpha); the smooth wall reverses e times the horizontal velocity and
    keeps the vertical; then y_hit + v_y t - g t^2/2 = 0 for the landing. Its positive root
    (v_y + s)/g, s = sqrt(v_y^2 + 2 g y_hit), is the same as 2 y_hit / (s - v_y); each is a sum of
    positive terms on one side of v_y = 0, so the landing takes (s + |v_y|)/g rising and 2 y_hit/(s + |v_y|)
    falling: no difference of nearly equal numbers."""
    v_x, v_y = v0 * xp.cos(xp.radians(alpha)), v0 * xp.sin(xp.radians(alpha))
    t1 = D / v_x
    y_hit, v_y_hit = h0 + v_y * t1 - G * t1**2 / 2, v_y - G * t1
    both = xp.sqrt(v_y_hit**2 + 2 * G * y_hit) + abs(v_y_hit)
    t2 = xp.where(v_y_hit >= 0, both / G, 2 * y_hit / both)
    return {"y_hit": y_hit, "v_hit": xp.hypot(v_x, v_y_hit), "v_out": xp.hypot(e * v_x, v_y_hit),
            "x_land": e * v_x * t2}


def bullet_spring(xp: Any, m_b: Any, m_blk: Any, v_b: Any, k: Any) -> dict[str, Any]:
    """Momentum, then 1/2 (m_b + m_blk) V^2 = 1/2 k x^2 (issue 25's trial template, tests/data)."""
    m_b, k = m_b / 1000, k * 1000  # g, kN/m
    common = m_b * v_b / (m_b + m_blk)
    x = xp.sqrt((m_b + m_blk) * common**2 / k)
    return {"V": common, "x_max": 1000 * x, "E_max": k * x**2 / 2}


def package_platform(xp: Any, m: Any, m_p: Any, h: Any, k: Any) -> dict[str, Any]:
    """Fall, momentum, then 1/2 M V^2 + M g (x - delta) = 1/2 k (x^2 - delta^2), the quadratic's root."""
    k = k * 1000
    common = m * xp.sqrt(2 * G * h) / (m + m_p)
    mass, delta = m + m_p, m_p * G / k
    constant = mass * common**2 / 2 - mass * G * delta + k * delta**2 / 2
    x = (mass * G + xp.sqrt((mass * G) ** 2 + 2 * k * constant)) / k
    return {"delta": 1000 * delta, "x_max": 1000 * x, "extra": 1000 * (x - delta)}


def ramp_and_floor(xp: Any, h: Any, v0: Any, mu_k: Any) -> dict[str, Any]:
    """Energy down a smooth ramp, then friction's work mu_k m g d takes the kinetic energy."""
    v_foot = xp.sqrt(v0**2 + 2 * G * h)
    return {"v_B": v_foot, "d": v_foot**2 / (2 * mu_k * G)}


def incline_up_and_back(xp: Any, v0: Any, beta: Any, mu_k: Any) -> dict[str, Any]:
    """Up to rest against gravity's component and friction, then down from rest through the same distance."""
    sine, cosine = xp.sin(xp.radians(beta)), xp.cos(xp.radians(beta))
    d = v0**2 / (2 * G * (sine + mu_k * cosine))
    return {"d": d, "v_back": xp.sqrt(2 * G * (sine - mu_k * cosine) * d)}


def intersection(xp: Any, m_A: Any, m_B: Any, v_A: Any, v_B: Any) -> dict[str, Any]:  # noqa: N803 (its names)
    """Momentum east and north; the loss as T - T'."""
    east, north = m_B * v_B / (m_A + m_B), m_A * v_A / (m_A + m_B)
    before = (m_A * v_A**2 + m_B * v_B**2) / 2
    return {"v": xp.hypot(east, north), "theta": xp.degrees(xp.atan2(north, east)),
            "loss_pct": _loss_pct(before, (m_A + m_B) * (east**2 + north**2) / 2)}


def ball_wall_impulse(xp: Any, m: Any, v: Any, e: Any, dt: Any) -> dict[str, Any]:
    """The rebound at e v the other way: impulse m (v + e v) (m in g), average force over dt (in ms)."""
    impulse = m / 1000 * (v + e * v)
    return {"J": impulse, "F": impulse / (dt / 1000)}


def cushion(xp: Any, m: Any, h: Any, d: Any) -> dict[str, Any]:
    """Fall, then (F - m g) d = 1/2 m v^2 over the cushion's d (in mm); F in kN."""
    v = xp.sqrt(2 * G * h)
    return {"J": m * v, "F": (m * v**2 / 2 / (d / 1000) + m * G) / 1000}


def recoil(xp: Any, m_gun: Any, m_b: Any, u: Any) -> dict[str, Any]:
    """From rest: m_gun v_gun + m_b v_b = 0 with v_b - v_gun = u (m_b in g); the energy as a sum of 1/2 m v^2."""
    m_b = m_b / 1000
    v_b = m_gun * u / (m_gun + m_b)
    v_gun = v_b - u
    return {"v_recoil": -v_gun, "v_b": v_b, "E": (m_gun * v_gun**2 + m_b * v_b**2) / 2 / 1000}


def explosion(xp: Any, m1: Any, m2: Any, V: Any, E: Any) -> dict[str, Any]:  # noqa: N803 (its names)
    """Momentum and energy, 1/2 m1 v1^2 + 1/2 m2 v2^2 = 1/2 (m1 + m2) V^2 + E (E in kJ), the quadratic in v2."""
    released, total = E * 1000, m1 + m2
    a, b = m2 + m2**2 / m1, -2 * total * V * m2 / m1
    c = total**2 * V**2 / m1 - total * V**2 - 2 * released
    v2 = (-b + xp.sqrt(b**2 - 4 * a * c)) / (2 * a)
    return {"v1": (total * V - m2 * v2) / m1, "v2": v2}


FORMS: dict[str, Callable[..., dict[str, Any]]] = {
    "drop-rebound": drop_rebound, "pile-driver": pile_driver, "car-collision": car_collision,
    "ball-plate": ball_plate, "oblique-spheres": oblique_spheres, "head-on": head_on,
    "head-on-inverse": head_on_inverse, "coupling": coupling, "moving-plate": moving_plate,
    "incline-bounce": incline_bounce, "billiards": billiards, "offset-spheres": offset_spheres,
    "three-balls": three_balls, "two-rebounds": two_rebounds, "successive-bounces": successive_bounces,
    "ballistic-pendulum": ballistic_pendulum, "skid": skid, "wall-throw": wall_throw,
    "bullet-spring": bullet_spring, "package-platform": package_platform, "ramp-and-floor": ramp_and_floor,
    "incline-up-and-back": incline_up_and_back, "intersection": intersection, "ball-wall-impulse": ball_wall_impulse,
    "cushion": cushion, "recoil": recoil, "explosion": explosion,
}
"""Template id -> its textbook answers."""
