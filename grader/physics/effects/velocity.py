"""A velocity as speed and angle, or as components along the n (impact) and t (tangent) axes; and
the angle between two velocities.

The angle is measured from the axis named in ``from`` toward the other one. Speeds come from
``hypot`` and angles from ``atan2``; the angle of a zero velocity is undefined, not zero. The angle
between two velocities is ``atan2(|a x b|, a . b)``, 0 to 180 degrees.

Mistakes: an angle reported from the other axis (``90° - θ``), or in radians where degrees were asked.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

from grader.model.expr import to_text
from grader.model.quantities import ANGLE, SPEED
from grader.physics.effects.base import Condition, Effect, Field, Mistake, Relation

if TYPE_CHECKING:
    from grader.model.expr import Node
    from grader.model.scene import Stage
    from grader.physics.record import Run
    from grader.physics.symbolic import Context

_FROM = "t"  # the axis an angle is measured from when a stage does not say


def _components(stage: Stage, ctx: Context, other_axis: bool = False) -> list[Relation]:
    """The stage's relations; ``other_axis``: its angle reported from the other axis (``90° - θ``)."""
    import sympy as sp

    from grader.physics.symbolic import hypot

    speed, angle = ctx.sym(stage.fields["speed"]), ctx.sym(stage.fields["angle"])
    n, t = ctx.sym(stage.fields["n"]), ctx.sym(stage.fields["t"])
    along, across = (t, n) if stage.fields.get("from", _FROM) == "t" else (n, t)
    along_name, across_name = ("t", "n") if stage.fields.get("from", _FROM) == "t" else ("n", "t")
    what = stage.text("speed")
    relations = [
        Relation(f"{what}: component along {along_name}", along, speed * sp.cos(angle),
                 requires=(Condition(sp.Ge(speed, 0), f"the speed {what} must not be negative"),)),
        Relation(f"{what}: component along {across_name}", across, speed * sp.sin(angle)),
    ]
    if isinstance(speed, sp.Symbol):
        # A component from the speed and the other component is known only up to its sign.
        branches = {component.free_symbols.pop(): sp.sqrt(speed**2 - other**2)
                    for component, other in ((n, t), (t, n)) if _signed_symbol(component)}
        relations.append(Relation(
            f"{what}: magnitude from its components", speed, hypot(n, t),
            solutions={speed: hypot(n, t)}, general=False, branches=branches))
    if isinstance(angle, sp.Symbol):
        direction = sp.atan2(across, along)
        relations.append(Relation(
            f"{what}: direction, measured from the {across_name if other_axis else along_name}-axis",
            angle if other_axis else sp.tan(angle), sp.pi / 2 - direction if other_axis else across / along,
            solutions={angle: sp.pi / 2 - direction if other_axis else direction}, general=False,
            undefined={angle: (sp.Le(hypot(n, t), 0), f"{what} is zero, so it has no direction")}))
    return relations


def output_polar(run: Run, vector: tuple[float, float], size: Node | None, angle: Node | None, still: str,
                 speed: float) -> None:
    """Give a simulated vector's magnitude (``hypot``) and direction (``atan2``, from its first component toward
    its second) to the fields that name them (None: not asked). A vector whose ``speed`` (the speed it stands
    for) the run does not tell apart from zero has no direction: ``still`` says why.

    >>> from grader.model.expr import Sym
    >>> from grader.model.scene import Scene
    >>> from grader.physics.record import Options, Run
    >>> run = Run(Scene("x", {}, (), None), Options(), {}, speed_scale=5.0)
    >>> output_polar(run, (3.0, 4.0), Sym("J"), Sym("theta"), "no impulse", 5.0)
    >>> run.values["J"], round(math.degrees(run.values["theta"]), 2)
    (5.0, 53.13)
    """
    magnitude = math.hypot(*vector)
    if size is not None:
        run.output(size, magnitude)
    if angle is None:
        return
    if magnitude > 0 and run.resolves(speed):
        run.output(angle, math.atan2(vector[1], vector[0]))
    else:
        run.undefined[to_text(angle)] = still
        run.output(angle, math.nan)


def _signed_symbol(expr: Any) -> bool:
    """Whether ``expr`` is a quantity, or one with its sign turned (``-v_n_after``)."""
    import sympy as sp

    return isinstance(expr, sp.Symbol) or isinstance(-expr, sp.Symbol)


def _mistakes(stage: Stage, ctx: Context) -> list[Mistake]:
    import sympy as sp

    if not isinstance(ctx.sym(stage.fields["angle"]), sp.Symbol):
        return []
    return [Mistake("angle.other_axis", "the angle measured from the other axis (90° − θ)",
                    tuple(_components(stage, ctx, other_axis=True))),
            Mistake("angle.radians", "the angle in radians where degrees were asked", unit="deg",
                    scale=sp.pi / 180)]


def _simulate_components(stage: Stage, run: Run) -> None:
    """Kinematics, not a force: split a known velocity into components, or combine them."""
    fields = stage.fields
    along_key, across_key = ("t", "n") if fields.get("from", _FROM) == "t" else ("n", "t")
    if run.known(fields["speed"]) and run.known(fields["angle"]):
        # In degrees, reduced exactly (as the closed form does): cos 90 deg is 0, not 6e-17, so a
        # head-on impact has no tangential motion to give a stopped ball a direction.
        from grader.model.kernel import cosd, sind  # numpy's: loading a template needs only the catalogue

        speed, degrees = run.value(fields["speed"]), math.degrees(run.value(fields["angle"]))
        run.output(fields[along_key], speed * float(cosd(degrees)))
        run.output(fields[across_key], speed * float(sind(degrees)))
        return
    along, across = run.value(fields[along_key]), run.value(fields[across_key])
    speed = math.hypot(along, across)
    run.output(fields["speed"], speed)
    if speed > 0 and run.resolves(speed):
        run.output(fields["angle"], math.atan2(across, along))
    else:
        reason = "is zero" if speed == 0 else "is zero within what the simulation resolves"
        run.undefined[to_text(fields["angle"])] = f"{stage.text('speed')} {reason}, so it has no direction"
        run.output(fields["angle"], math.nan)


VELOCITY = Effect(
    "velocity",
    "a velocity given by speed and angle, related to its n and t components",
    (
        Field("speed", "expr", doc="magnitude", dimension=SPEED),
        Field("angle", "expr", doc="direction, measured from the `from` axis toward the other", dimension=ANGLE),
        Field("from", "choice:t|n", required=False, doc="axis the angle is measured from", default=_FROM),
        Field("n", "expr", doc="component along the line of impact", dimension=SPEED),
        Field("t", "expr", doc="component along the tangent", dimension=SPEED),
    ),
    _components,
    _simulate_components,
    _mistakes,
    force_law="none: kinematics; a known velocity is split into components (cosine and sine in degrees, exact at "
              "multiples of 90), or components combined with hypot and atan2",
)


def _shown(stage: Stage) -> list[str]:
    return [f"({to_text(v.n)}, {to_text(v.t)})" for v in (stage.fields["first"], stage.fields["second"])]


def _no_angle(stage: Stage) -> str:
    first, second = _shown(stage)
    return f"the velocity {first} or {second} is zero, so there is no angle between them"


def _between(stage: Stage, ctx: Context) -> list[Relation]:
    import sympy as sp

    from grader.physics.symbolic import hypot

    first, second = stage.fields["first"], stage.fields["second"]
    an, at, bn, bt = (ctx.sym(part) for part in (first.n, first.t, second.n, second.t))
    angle = ctx.sym(stage.fields["angle"])
    if not isinstance(angle, sp.Symbol):
        return []
    shown = _shown(stage)
    # atan2 of the cross and dot products: accurate at 0 and 180 degrees, where acos of the cosine is not.
    return [Relation(
        f"angle between the velocities {shown[0]} and {shown[1]} (n and t components), 0 to 180 degrees",
        sp.cos(angle), (an * bn + at * bt) / (hypot(an, at) * hypot(bn, bt)),
        solutions={angle: sp.atan2(sp.Abs(an * bt - at * bn), an * bn + at * bt)}, general=False,
        undefined={angle: (sp.Le(sp.Min(hypot(an, at), hypot(bn, bt)), 0),
                           _no_angle(stage))})]


def _simulate_between(stage: Stage, run: Run) -> None:
    a, b = ((run.value(v.n), run.value(v.t)) for v in (stage.fields["first"], stage.fields["second"]))
    sizes = math.hypot(*a), math.hypot(*b)
    if all(size > 0 and run.resolves(size) for size in sizes):
        # Directions first: the products of two speeds of 1e170 m/s would overflow.
        (an, at), (bn, bt) = ((v[0] / s, v[1] / s) for v, s in zip((a, b), sizes, strict=True))
        run.output(stage.fields["angle"], math.atan2(abs(an * bt - at * bn), an * bn + at * bt))
        return
    run.undefined[to_text(stage.fields["angle"])] = _no_angle(stage)
    run.output(stage.fields["angle"], math.nan)


ANGLE_BETWEEN = Effect(
    "angle_between",
    "the angle between two velocities given by their n and t components, 0 to 180 degrees",
    (
        Field("first", "vector", doc="{n: .., t: ..}: the velocity the angle is measured from", dimension=SPEED),
        Field("second", "vector", doc="{n: .., t: ..}: the other velocity", dimension=SPEED),
        Field("angle", "expr", doc="the angle between them, 0 to 180 degrees", dimension=ANGLE),
    ),
    _between,
    _simulate_between,
    force_law="none: kinematics; the angle is atan2(|a x b|, a . b) of the two velocities' directions",
)
