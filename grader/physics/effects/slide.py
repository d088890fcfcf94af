"""Sliding to rest on a level surface against kinetic friction: ``v = sqrt(2 mu_k g d)``.

Work-energy from the start of the slide to rest: the friction force ``mu_k m g`` does the work
``mu_k m g d``, which takes the kinetic energy ``1/2 m v**2`` away; the mass cancels. The forms are
products and quotients of the given quantities (``v**2/(2 mu_k g)`` for the distance), with no
difference to cancel: a skid of ``mu_k d = 1e-9`` m keeps full accuracy.

Force law (simulation): Coulomb kinetic friction, ``a = -mu_k g`` against the motion, acting only
while the body slides. The slide ends at the located event ``v = 0``; on a level surface nothing
drives the body again, so static friction then holds it, and the force never switches sign from
step to step (no chatter about ``v = 0``). Gravity is not simulated: it enters only as the normal
force that friction is proportional to.

Mistakes: ``v = sqrt(mu_k g d)`` (the 2 of ``1/2 m v**2`` lost); ``v = sqrt(2 g d)`` (the friction
coefficient left out: the deceleration taken as g); ``v = 2 mu_k g d`` (no root).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from grader.model.quantities import LENGTH, PURE, SPEED
from grader.physics.effects.base import Condition, Effect, Field, Mistake, Relation

if TYPE_CHECKING:
    from grader.model.scene import Stage
    from grader.physics.record import Run
    from grader.physics.symbolic import Context

_LAWS = ("sqrt(2 mu g d)", "sqrt(mu g d)", "sqrt(2 g d)", "2 mu g d")


def _sliders(stage: Stage) -> str:
    """Who slides: ``A``, or ``A (with B locked to it)``."""
    together = stage.fields.get("with")
    return f"{stage.fields['body']} (with {together} locked to it)" if together else str(stage.fields["body"])


def _work_energy(stage: Stage, ctx: Context, law: str = _LAWS[0]) -> list[Relation]:
    """The stage's relation, or as a student who makes a mistake writes it (``law``, one of ``_LAWS``)."""
    import sympy as sp

    speed, distance = ctx.sym(stage.fields["speed"]), ctx.sym(stage.fields["distance"])
    mu, g = ctx.sym(stage.fields["friction"]), ctx.gravity_symbol(stage)
    deceleration = g if law == "sqrt(2 g d)" else mu * g
    twice = 1 if law == "sqrt(mu g d)" else 2
    start_speed = twice * deceleration * distance if law == "2 mu g d" else \
        sp.Pow(twice * deceleration * distance, sp.Rational(1, 2), evaluate=False)
    solutions: dict[Any, Any] = {}
    if isinstance(speed, sp.Symbol):
        solutions[speed] = start_speed
    squared = speed if law == "2 mu g d" else speed**2
    if isinstance(distance, sp.Symbol):
        solutions[distance] = squared / (twice * deceleration)
    if isinstance(mu, sp.Symbol) and law != "sqrt(2 g d)":
        solutions[mu] = squared / (twice * g * distance)
    who, d, mu_text = _sliders(stage), stage.text("distance"), stage.text("friction")
    return [Relation(
        label=f"work-energy: {who} slides to rest through {d} against kinetic friction {mu_text}; the friction "
              "force's work takes its kinetic energy",
        lhs=speed, rhs=start_speed, solutions=solutions,
        requires=(
            Condition(sp.Ge(distance, 0), f"the sliding distance {d} must not be negative"),
            Condition(sp.Gt(mu, 0), f"the coefficient of kinetic friction {mu_text} must be positive (without "
                      "friction nothing stops the slide)"),
            Condition(sp.Ge(speed, 0), f"{who} must move forward ({stage.text('speed')} >= 0) to slide through a "
                      "distance"),
        ),
    )]


def _slide(stage: Stage, ctx: Context) -> list[Relation]:
    return _work_energy(stage, ctx)


def _mistakes(stage: Stage, ctx: Context) -> list[Mistake]:
    return [
        Mistake("slide.sqrt_mu_g_d", "v = √(μk g d) instead of v = √(2 μk g d)",
                tuple(_work_energy(stage, ctx, "sqrt(mu g d)"))),
        Mistake("slide.without_friction_coefficient", "v = √(2 g d), the friction coefficient left out",
                tuple(_work_energy(stage, ctx, "sqrt(2 g d)"))),
        Mistake("slide.two_mu_g_d", "v = 2 μk g d instead of v = √(2 μk g d)",
                tuple(_work_energy(stage, ctx, "2 mu g d"))),
    ]


def kinetic_friction(mu: float, g: float) -> Any:
    """Coulomb kinetic friction per unit mass on a state ``[distance, velocity]`` of a body sliding
    forward (``velocity > 0``): the constant deceleration ``mu g`` (the slide's mode ends at ``v = 0``)."""
    def rhs(_: float, y: Any) -> Any:
        return np.array([y[1], -mu * g])
    return rhs


def _simulate_slide(stage: Stage, run: Run) -> None:
    from grader.physics.integrate import Mode  # the simulator's part: loading a template needs none of it

    speed, mu, g = run.value(stage.fields["speed"]), run.value(stage.fields["friction"]), run.gravity()
    who = _sliders(stage)
    if speed <= 0 or mu <= 0:
        if speed < 0:
            run.problems.append(f"{who} moves backward ({speed:g} m/s) at the start of the slide")
        elif mu <= 0 < speed:
            run.problems.append(f"without kinetic friction (mu_k = {mu:g}) {who} never stops")
        run.output(stage.fields["distance"], 0.0)  # a body at rest does not slide
        return
    run.uses("kinetic friction (Coulomb)")
    stopping_time = speed / (mu * g)
    skid = Mode("slide", kinetic_friction(mu, g), lambda y: y[1], -1, scale=stopping_time,
                sizes=lambda y: np.array([speed * stopping_time, speed]))
    path = run.integrate([skid], np.array([0.0, speed]))
    run.record(f"{who} slides to rest", ("distance", "velocity"), path)
    run.output(stage.fields["distance"], float(path.y[-1][0]))


SLIDE = Effect(
    "slide",
    "a body sliding on a level surface comes to rest against kinetic friction: v = sqrt(2 mu_k g d)",
    (
        Field("body", "body", doc="the body that slides"),
        Field("with", "body", required=False, doc="a body locked to it that slides along (two cars after a "
              "perfectly plastic impact)", default="the body slides alone"),
        Field("speed", "expr", doc="speed at the start of the slide, >= 0", dimension=SPEED),
        Field("distance", "expr", doc="distance slid to rest", dimension=LENGTH),
        Field("friction", "expr", doc="coefficient of kinetic friction mu_k, > 0", dimension=PURE),
    ),
    _slide,
    _simulate_slide,
    _mistakes,
    force_law="Coulomb kinetic friction, a = -mu_k g against the motion while the body slides, until the located "
              "event v = 0 (static friction then holds it); gravity enters only as the normal force",
)
