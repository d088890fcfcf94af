"""Projectile motion of a body under gravity alone, from a start until a located event: reaching a
wall a given horizontal distance away (``until: wall``), or coming down to the ground (``until: ground``).

Axes: x horizontal, positive the way the body moves; y up, heights measured from the ground. The
horizontal velocity is constant, ``x = v_x t``; the height is ``y = y0 + v_y t - g t**2/2`` and the
vertical velocity ``v_y - g t``. To the wall the time is linear, ``t = D/v_x``. To the ground it is a
root of a quadratic, ``(v_y +- sqrt(v_y**2 + 2 g (y0 - y1)))/g``: the physical root is the one with
``+``, since the other is not positive (at or before the start: where the parabola, run backwards,
meets the ground). The kernels evaluate it without cancellation for either sign of ``v_y``: with
``a = max(v_y, 0)``, ``b = min(v_y, 0)`` and ``s`` the root,
``t = (a + (2 g (y0 - y1) + a**2)/(s - b))/g``, a sum of terms that are never negative (a body
thrown down, ``v_y < 0``, would otherwise lose its time in ``v_y + s``).

Force law (simulation): gravity only, ``a = (0, -g)``; the flight ends at the located event ``x = D``
(the wall) or ``y = y1`` while descending (the ground).

Mistakes: the other root of the quadratic, taken as a positive time (``(s - v_y)/g``); the fall
under gravity left out (``y = y0 + v_y t``); ``g t**2`` for ``g t**2/2``.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from grader.model.expr import Sym
from grader.model.quantities import LENGTH, SPEED, TIME
from grader.physics.effects.base import Condition, Effect, Field, Mistake, Relation, Stable

if TYPE_CHECKING:
    from grader.model.scene import Stage
    from grader.physics.record import Run
    from grader.physics.symbolic import Context

_FIELDS = (
    Field("body", "body", doc="the body in flight"),
    Field("until", "choice:wall|ground", doc="the event that ends the flight: reaching a wall at `distance`, or "
          "coming down to the ground (`end_height`, usually 0)"),
    Field("horizontal", "expr", doc="horizontal velocity, constant, positive the way the body moves", dimension=SPEED),
    Field("vertical", "expr", doc="vertical velocity at the start, up positive", dimension=SPEED),
    Field("height", "expr", doc="height above the ground at the start", dimension=LENGTH),
    Field("distance", "expr", doc="horizontal distance from the start to the end", dimension=LENGTH),
    Field("end_height", "expr", doc="height above the ground at the end (0 at the ground)", dimension=LENGTH),
    Field("end_vertical", "expr", doc="vertical velocity at the end, up positive", dimension=SPEED),
    Field("time", "name", required=False, doc="name for the time of flight", dimension=TIME,
          default="t_flight"),
)
_DEFAULT_TIME = next(str(spec.default) for spec in _FIELDS if spec.name == "time")


def _time(stage: Stage, ctx: Context) -> Any:
    name = stage.fields.get("time")
    return ctx.symbol(name if isinstance(name, str) else ctx.unused_name(_DEFAULT_TIME, stage))


def _flight(stage: Stage, ctx: Context, law: str = "y0 + vy t - g t^2/2", root: str = "+") -> list[Relation]:
    """The stage's relations, or as a student who makes a mistake writes them: ``law`` of the height
    (``y0 + vy t`` without the fall, ``y0 + vy t - g t^2`` without the half) or the other ``root``."""
    import sympy as sp

    body, wall = stage.fields["body"], stage.fields["until"] == "wall"
    vx, vy = ctx.sym(stage.fields["horizontal"]), ctx.sym(stage.fields["vertical"])
    y0, x1, y1 = (ctx.sym(stage.fields[key]) for key in ("height", "distance", "end_height"))
    vy1, g, t = ctx.sym(stage.fields["end_vertical"]), ctx.gravity_symbol(stage), _time(stage, ctx)
    half = {"y0 + vy t - g t^2/2": sp.Rational(1, 2), "y0 + vy t": 0, "y0 + vy t - g t^2": 1}[law]
    text = {key: stage.text(key) for key in ("horizontal", "vertical", "height", "distance", "end_height")}

    horizontal = Relation(
        f"horizontal motion of {body}: no horizontal force, so it covers {text['distance']} at the constant "
        f"{text['horizontal']} in the time {t}", x1, vx * t,
        solutions={x1: vx * t, t: x1 / vx, vx: x1 / t},
        requires=(Condition(sp.Gt(vx, 0) if wall else sp.Ge(vx, 0),
                            f"{body} must move toward the wall ({text['horizontal']} > 0) to reach it" if wall else
                            f"the horizontal velocity {text['horizontal']} must not be negative (x is measured the "
                            f"way {body} moves)"),))
    height_at = y0 + vy * t - half * g * t**2
    drop = y0 - y1
    solutions: dict[Any, Any] = {y1: height_at}
    stable: dict[Any, tuple[Stable, ...]] = {}
    # To a wall, the height there says nothing of whether the body rises or falls as it reaches it: the time
    # comes from the distance, and from the height only as a block's root that the scene's values select.
    if half and not wall:
        root_of = sp.sqrt(vy**2 + 2 * g * drop / (2 * half))
        solutions[t] = (vy + root_of) / (2 * half * g) if root == "+" else (root_of - vy) / (2 * half * g)
        if root == "+":
            up, down = sp.Max(vy, 0), sp.Min(vy, 0)
            stable[t] = (Stable((up + (2 * g * drop / (2 * half) + up**2) / (root_of - down)) / (2 * half * g)),)
    requires: tuple[Condition, ...]
    if wall:
        label = (f"vertical motion of {body}: gravity alone, so its height when it reaches the wall, after the "
                 f"time {t}, is")
        requires = (Condition(sp.Ge(y1, 0), f"{body} reaches the ground before it gets to the wall (its height at "
                              f"the wall, {text['end_height']}, would be {{value}})", subject=y1),
                    Condition(sp.Ge(t, 0), f"{body} reaches the wall after it is thrown ({t} >= 0)"))
    else:
        ground = text["end_height"] == "0"
        fallen = text["height"] if ground else f"({text['height']} − {text['end_height']})"
        where = "on the ground" if ground else f"at {text['end_height']}"
        label = (f"vertical motion of {body} until it lands {where}: a quadratic in {t}, whose roots are "
                 f"({text['vertical']} ± √({text['vertical']}² + 2 g {fallen}))/g;"
                 f" the landing is the root with +, since the root with − is not positive (at or before the start: "
                 f"where the path, run backwards, meets {'the ground' if ground else 'that height'})")
        if vy == 0:  # no vertical velocity at the start: the fall alone, ½ g t² = h, with no quadratic to solve
            label = (f"vertical motion of {body} until it lands {where}: it starts with no vertical velocity, so it "
                     f"falls {fallen} in the time {t} under gravity alone")
        requires = (Condition(sp.Ge(drop, 0), f"{body} starts below the height it is to land at "
                              f"({text['height']} < {text['end_height']})"),)
    return [
        horizontal,
        Relation(label, y1, height_at, solutions=solutions, stable=stable, general=False, requires=requires),
        Relation(f"vertical velocity of {body}: gravity alone changes it, by g {t}", vy1, vy - g * t,
                 solutions={vy1: vy - g * t, vy: vy1 + g * t, t: (vy - vy1) / g}),
    ]


def _projectile(stage: Stage, ctx: Context) -> list[Relation]:
    return _flight(stage, ctx)


def _mistakes(stage: Stage, ctx: Context) -> list[Mistake]:
    mistakes = [
        Mistake("projectile.no_fall", "y = y0 + v_y t, the fall under gravity (−½ g t²) left out",
                tuple(_flight(stage, ctx, law="y0 + vy t"))),
        Mistake("projectile.g_t_squared", "y = y0 + v_y t − g t² instead of − ½ g t²",
                tuple(_flight(stage, ctx, law="y0 + vy t - g t^2"))),
    ]
    if stage.fields["until"] == "ground":
        mistakes.insert(0, Mistake("projectile.other_root", "the other root of the quadratic in t, taken as positive",
                                   tuple(_flight(stage, ctx, root="-"))))
    return mistakes


def gravity_2d(g: float) -> Any:
    """The force law of a projectile, per unit mass, on a state ``[x, y, v_x, v_y]`` (y up)."""
    def rhs(_: float, state: Any) -> Any:
        return np.array([state[2], state[3], 0.0, -g])
    return rhs


def _simulate_flight(stage: Stage, run: Run) -> None:
    fields, body = stage.fields, stage.fields["body"]
    vx, vy, y0 = (run.value(fields[key]) for key in ("horizontal", "vertical", "height"))
    g = run.gravity()
    if fields["until"] == "wall":
        end = _to_wall(stage, run, vx, vy, y0, g)
        if end is not None and end[1][1] < 0:
            run.problems.append(f"{body} reaches the ground before it gets to the wall (it would strike the wall "
                                f"{-end[1][1]:.3g} m below the ground)")
    else:
        end = _to_ground(stage, run, vx, vy, y0, g)
    if end is None:
        return
    time, (x, y, _, vy_end) = end
    if fields["until"] == "wall":
        run.output(fields["end_height"], y)
    else:
        run.output(fields["distance"], x)
    run.output(fields["end_vertical"], vy_end)
    if isinstance(fields.get("time"), str):
        run.output(Sym(fields["time"]), time)


def _to_wall(stage: Stage, run: Run, vx: float, vy: float, y0: float, g: float) -> tuple[float, Any] | None:
    from grader.physics.integrate import Mode  # the simulator's part: loading a template needs none of it

    distance = run.value(stage.fields["distance"])
    if vx <= 0 or distance < 0:
        run.problems.append(f"{stage.fields['body']} does not move toward the wall (horizontal velocity {vx:g} m/s)"
                            if vx <= 0 else f"the distance to the wall {distance:g} m is negative")
        return None
    if distance == 0:  # thrown from the foot of the wall: it strikes it at once
        return 0.0, np.array([0.0, y0, vx, vy])
    run.uses("gravity")
    duration = distance / vx
    speed = max(vx, abs(vy), g * duration)
    sizes = np.array([distance, max(y0, speed * duration), speed, speed])
    flight = Mode("flight to the wall", gravity_2d(g), lambda y: y[0] - distance, +1, scale=duration,
                  sizes=lambda y: sizes)
    path = run.integrate([flight], np.array([0.0, y0, vx, vy]))
    run.record(f"{stage.fields['body']} flies to the wall", ("x", "y", "v_x", "v_y"), path)
    return path.t[-1], path.y[-1]


def _to_ground(stage: Stage, run: Run, vx: float, vy: float, y0: float, g: float) -> tuple[float, Any] | None:
    from grader.physics.integrate import Mode  # the simulator's part: loading a template needs none of it

    y1 = run.value(stage.fields["end_height"])
    drop = y0 - y1
    if drop < 0 or vx < 0:
        run.problems.append(f"{stage.fields['body']} starts below the height it is to land at" if drop < 0 else
                            f"the horizontal velocity {vx:g} m/s is negative (x is measured the way the body moves)")
        return None
    if drop == 0 and vy <= 0:  # it is there already, moving down or level: it lands at once
        return 0.0, np.array([0.0, y0, vx, vy])
    run.uses("gravity")
    # The time scale only sets fixed step sizes and the tolerances' sizes; the motion itself is integrated.
    duration = (abs(vy) + math.sqrt(vy * vy + 2 * g * drop)) / g
    speed = max(abs(vx), abs(vy), g * duration)
    sizes = np.array([max(abs(vx) * duration, speed * duration), max(y0, speed * duration), speed, speed])
    # Descending through the landing height: a body thrown up from it passes it going up first.
    flight = Mode("flight to the ground", gravity_2d(g), lambda y: y[1] - y1, -1, scale=duration,
                  sizes=lambda y: sizes)
    path = run.integrate([flight], np.array([0.0, y0, vx, vy]))
    run.record(f"{stage.fields['body']} flies to the ground", ("x", "y", "v_x", "v_y"), path)
    return path.t[-1], path.y[-1]


FLIGHT = Effect(
    "flight",
    "projectile motion under gravity alone, until a wall at a given distance or the ground",
    _FIELDS,
    _projectile,
    _simulate_flight,
    _mistakes,
    force_law="gravity alone, a = (0, -g), until the located event x = D (the wall) or y = y1 while descending "
              "(the ground)",
)
