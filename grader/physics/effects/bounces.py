"""Successive bounces on a floor: a body dropped from rest bounces again and again with restitution e.

Each impact sends the body up at ``e`` times the speed it arrived with, so each rebound height is
``e**2`` times the one before: after the n-th bounce ``h_n = h0 e**(2 n)``. Summed to rest (the
series converge for ``e < 1``; at ``e = 1`` the body bounces for ever and they do not):

- distance travelled: the drop, then each rebound height up and down,
  ``h0 + 2 h0 (e**2 + e**4 + ...) = h0 (1 + e**2)/(1 - e**2)``;
- time: the fall ``t0 = sqrt(2 h0/g)``, then each rebound up and down, ``2 t0 (e + e**2 + ...)``,
  so ``t0 (1 + e)/(1 - e)``.

``e = 0`` is valid: the body rests at the first impact (``h_n = 0``, the distance is ``h0``, the time
``t0``). The kernels divide by ``(1 - e)(1 + e)``, never by ``1 - e**2``: ``1 - e`` is exact in
float64 for ``e`` in [0.5, 1], so near ``e = 1``, where the sums grow without bound, they keep full
accuracy (``1 - e*e`` carries the rounding of ``e*e``: 3e-9 of the sum at ``e = 1 - 6e-9``).

Force law (simulation): gravity in flight and the impact's Kelvin-Voigt contact with the floor,
calibrated to ``e``; the weight is off during the contact, as the closed form assumes. The first
``k = max(n, 5)`` bounces run in time (each fall, contact and rise to the apex ends at a located
event); their partial sums of distance and time are compared with the series' own partial sums,
and the tail beyond bounce ``k`` is added analytically from the last simulated rebound:
``2 h_k e**2/(1 - e**2)`` and ``2 t_k e/(1 - e)`` (``t_k`` its rise time), with its share of the total
reported as the bound on what the simulation did not integrate.

Mistakes: heights scaled by ``e`` instead of ``e**2``; the n-th rebound counted from the drop
(``e**(2(n - 1))``); each rebound height travelled one way only (in the distance), or each rise
timed without its fall.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from grader.base.errors import TemplateError
from grader.model.quantities import LENGTH, PURE, TIME
from grader.physics.effects.base import Condition, Effect, Field, Mistake, Relation, Stable

if TYPE_CHECKING:
    from grader.model.scene import Stage
    from grader.physics.record import Run
    from grader.physics.symbolic import Context

SIMULATED_BOUNCES = 5  # bounces simulated in time at least (more when the n-th is asked)

_FIELDS = (
    Field("bodies", "bodies", doc="[body, floor]: the body that bounces and the fixed floor"),
    Field("height", "expr", doc="height the body is dropped from, at rest", dimension=LENGTH),
    Field("restitution", "expr", doc="coefficient of restitution e between body and floor, 0 <= e < 1",
          dimension=PURE),
    Field("count", "expr", required=False, doc="the bounce n whose rebound height is asked (a whole number >= 1)",
          dimension=PURE, default="none; rebound needs it"),
    Field("rebound", "expr", required=False, doc="height the body rises to after bounce n", dimension=LENGTH,
          default="the scene has no rebound height"),
    Field("distance", "expr", required=False, doc="total distance travelled until the body rests",
          dimension=LENGTH, default="the scene has no total distance"),
    Field("time", "expr", required=False, doc="total time until the body rests", dimension=TIME,
          default="the scene has no total time"),
)


def _series(stage: Stage, ctx: Context, heights: str = "e**2", first: int = 1, both_ways: bool = True,
            timed_both_ways: bool = True) -> list[Relation]:
    """The stage's relations; the keywords write them as a student who makes a mistake does:
    ``heights`` "e" (each rebound e times as high), ``first`` 0 (the drop counted as a bounce),
    ``both_ways`` False (each rebound height travelled once), ``timed_both_ways`` False (each rise
    timed without its fall)."""
    import sympy as sp

    body, floor = stage.fields["bodies"]
    if ctx.scene.bodies[floor].mass is not None:
        raise TemplateError(ctx.scene.where, f"stages[{stage.index}].bodies",
                            "a fixed floor second (fixed: true): the body bounces on it", floor)
    h0, e = ctx.sym(stage.fields["height"]), ctx.sym(stage.fields["restitution"])
    h_text, e_text = stage.text("height"), stage.text("restitution")
    valid = (Condition(sp.Ge(h0, 0), f"the drop height {h_text} must not be negative"),
             Condition(sp.Ge(e, 0), "the coefficient of restitution is {value}; it cannot be negative (the body "
                       "would pass through the floor)", subject=e))
    converges = (*valid, Condition(sp.Lt(e, 1), "the coefficient of restitution is {value}: at e = 1 the "
                                   f"{body} bounces back to {h_text} for ever, so the series does not converge (it "
                                   "never comes to rest)", subject=e))
    relations = []
    if "rebound" in stage.fields:
        if "count" not in stage.fields:
            raise TemplateError(ctx.scene.where, f"stages[{stage.index}].count",
                                "the bounce n whose rebound height is asked", "nothing")
        n, rebound = ctx.sym(stage.fields["count"]), ctx.sym(stage.fields["rebound"])
        ratio = e**2 if heights == "e**2" else e
        factor = ratio ** (n - 1 + first)
        relations.append(Relation(
            f"each rebound of {body} rises e² times as high as the one before (v' = e v, h = v²/2g), so after "
            f"bounce {stage.text('count')}", rebound, h0 * factor,
            solutions=_solved(rebound, h0 * factor, {h0: rebound / factor}), general=False,
            requires=(*valid, Condition(sp.Ge(n, 1), f"the bounce {stage.text('count')} is counted from 1, the first "
                                        "impact"),
                      Condition(sp.Le(e, 1), "the coefficient of restitution is {value}; above 1 each bounce would "
                                "create energy", subject=e))))
    if "distance" in stage.fields:
        distance = ctx.sym(stage.fields["distance"])
        up_and_down = 2 if both_ways else 1
        total = h0 * (1 + (up_and_down - 1) * e**2) / (1 - e**2)
        stable = h0 * (1 + (up_and_down - 1) * e**2) / ((1 - e) * (1 + e))
        relations.append(Relation(
            f"total distance: the drop {h_text}, then each rebound height up and down, a geometric series of ratio "
            f"{e_text}²", distance, total, solutions=_solved(distance, total, {h0: distance / total * h0}),
            stable={distance: (Stable(stable, given=(e,)),)}, general=False, requires=converges))
    if "time" in stage.fields:
        time = ctx.sym(stage.fields["time"])
        g = ctx.gravity_symbol(stage)
        fall = sp.Pow(2 * h0 / g, sp.Rational(1, 2), evaluate=False)
        total = fall * ((1 + e) / (1 - e) if timed_both_ways else 1 / (1 - e))
        relations.append(Relation(
            f"total time: the fall from {h_text}, then each rebound up and down, a geometric series of ratio "
            f"{e_text}", time, total, solutions=_solved(time, total, {}), general=False, requires=converges))
    return relations


def _solved(unknown: Any, value: Any, others: dict[Any, Any]) -> dict[Any, Any]:
    """Solutions for the symbols among ``unknown`` and ``others``' keys."""
    import sympy as sp

    return {symbol: form for symbol, form in [(unknown, value), *others.items()] if isinstance(symbol, sp.Symbol)}


def _bounces(stage: Stage, ctx: Context) -> list[Relation]:
    return _series(stage, ctx)


def _mistakes(stage: Stage, ctx: Context) -> list[Mistake]:
    mistakes = []
    if "rebound" in stage.fields:
        mistakes += [Mistake("bounces.e_not_squared", "each rebound e times as high as the one before, not e² times",
                             tuple(_series(stage, ctx, heights="e"))),
                     Mistake("bounces.drop_counted", "the drop counted as the first bounce (e^(2(n − 1)))",
                             tuple(_series(stage, ctx, first=0)))]
    if "distance" in stage.fields:
        mistakes.append(Mistake("bounces.one_way", "each rebound height travelled once instead of up and down",
                                tuple(_series(stage, ctx, both_ways=False))))
    if "time" in stage.fields:
        mistakes.append(Mistake("bounces.rise_time_only", "each rebound timed for its rise only, without its fall",
                                tuple(_series(stage, ctx, timed_both_ways=False))))
    return mistakes


def _simulate_bounces(stage: Stage, run: Run) -> None:
    """The first bounces in time (fall, contact, rise to the apex, each a located event), their
    partial sums, and the tail beyond the last one from the series."""
    from grader.physics.effects.flight import gravity
    from grader.physics.integrate import Mode

    h0, e, g = run.value(stage.fields["height"]), run.value(stage.fields["restitution"]), run.gravity()
    count = run.value(stage.fields["count"]) if "count" in stage.fields else 1.0
    body, floor = stage.fields["bodies"]
    if not (0 <= e < 1 and h0 > 0 and count >= 1 and float(count).is_integer()):
        run.problems.append(f"the series of bounces does not converge (e = {e:g})" if e >= 1 else
                            f"cannot simulate bounces from {h0:g} m with e = {e:g} and n = {count:g}")
        _outputs(stage, run, math.nan, math.nan, math.nan)
        return
    run.uses("gravity")
    wanted = max(int(count), SIMULATED_BOUNCES)
    height, distance, elapsed = h0, h0, 0.0
    landing = Mode("free fall", gravity(g), lambda y: y[0], -1, scale=math.sqrt(2 * h0 / g))
    path = run.integrate([landing], np.array([h0, 0.0]))
    run.record(f"{body} falls", ("height", "velocity"), path)
    elapsed += path.t[-1] - path.t[0]
    speed, rise_time = -float(path.y[-1][1]), 0.0
    heights: list[float] = []
    for bounce in range(1, wanted + 1):
        speed = _bounce(stage, run, (body, floor), e, speed, bounce)
        if speed <= 0:  # e = 0: it rests on the floor
            heights += [0.0] * (wanted - len(heights))
            rise_time = 0.0
            break
        apex = Mode("rise", gravity(g), lambda y: y[1], -1, scale=speed / g)
        rise = run.integrate([apex], np.array([0.0, speed]))
        run.record(f"{body} rises after bounce {bounce}", ("height", "velocity"), rise)
        height, rise_time = float(rise.y[-1][0]), rise.t[-1] - rise.t[0]
        fall = Mode("free fall", gravity(g), lambda y: y[0], -1, scale=rise_time)
        down = run.integrate([fall], np.array([height, 0.0]))
        run.record(f"{body} falls after bounce {bounce}", ("height", "velocity"), down)
        heights.append(height)
        distance += 2 * height
        elapsed += rise_time + (down.t[-1] - down.t[0])
        speed = -float(down.y[-1][1])
    # The tail beyond the last simulated bounce, from the series of ratio e**2 (heights) and e (times).
    last = heights[-1] if heights else 0.0
    tail_distance = 2 * last * e * e / ((1 - e) * (1 + e))
    tail_time = 2 * rise_time * e / (1 - e)
    run.notes.append(_partial_sums(body, floor, (h0, e, g), heights, (distance, elapsed),
                                   (tail_distance, tail_time)))
    _outputs(stage, run, heights[int(count) - 1], distance + tail_distance, elapsed + tail_time)


def _partial_sums(body: str, floor: str, given: tuple[float, float, float], heights: list[float],
                  simulated: tuple[float, float], tail: tuple[float, float]) -> str:
    """What the simulation of the first bounces says beside the series' own partial sums."""
    h0, e, g = given
    bounces = len(heights)
    if not any(heights):
        return f"bounces of {body} on {floor}: it rests at the first impact (e = 0); simulated distance " \
               f"{simulated[0]:.10g} m and time {simulated[1]:.10g} s, nothing left of the series"
    series_distance = h0 * (1 + 2 * sum(e ** (2 * k) for k in range(1, bounces + 1)))
    series_time = math.sqrt(2 * h0 / g) * (1 + 2 * sum(e**k for k in range(1, bounces + 1)))
    total = simulated[0] + tail[0]
    return (f"bounces of {body} on {floor}: the first {bounces} simulated in time; partial sums distance "
            f"{simulated[0]:.10g} m (series {series_distance:.10g} m), time {simulated[1]:.10g} s (series "
            f"{series_time:.10g} s); tail beyond bounce {bounces} from the series: {tail[0]:.4g} m "
            f"({tail[0] / total:.2g} of the distance), {tail[1]:.4g} s")


def _bounce(stage: Stage, run: Run, bodies: tuple[str, str], e: float, speed: float, bounce: int) -> float:
    """One impact on the floor through the impact's contact law; the speed the body leaves it with."""
    from grader.physics.effects.impact import simulate_contact

    after = simulate_contact(stage, run, bodies, (1.0, 0.0), e, [speed, 0.0, 0.0, 0.0],
                             label=f"bounce {bounce} of {bodies[0]} on {bodies[1]}")
    return -after[0]


def _outputs(stage: Stage, run: Run, rebound: float, distance: float, time: float) -> None:
    for key, value in (("rebound", rebound), ("distance", distance), ("time", time)):
        if key in stage.fields:
            run.output(stage.fields[key], value)


BOUNCES = Effect(
    "bounces",
    "a body dropped onto a fixed floor bounces again and again: h_n = h0 e^(2n), and the series to rest",
    _FIELDS,
    _bounces,
    _simulate_bounces,
    _mistakes,
    force_law="gravity in flight and the impact's Kelvin-Voigt contact with the floor, calibrated to e (no weight "
              "during the contact); the first max(n, 5) bounces run in time, the tail beyond them added from the "
              "series and reported as the bound on what was not integrated",
)
