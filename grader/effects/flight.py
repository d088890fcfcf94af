"""Free fall from rest and rise to a height: ``v = sqrt(2 g h)`` under gravity alone."""

from __future__ import annotations

from typing import TYPE_CHECKING

from grader.effects.base import Condition, Effect, Field, Relation

if TYPE_CHECKING:
    from grader.scene import Stage
    from grader.symbolic import Context

_FIELDS = (
    Field("body", "body", doc="the body that moves"),
    Field("height", "expr", doc="height fallen or risen (m)"),
    Field("speed", "expr", doc="speed at the bottom of the path, >= 0"),
)


def _energy(stage: Stage, ctx: Context, verb: str) -> list[Relation]:
    import sympy as sp

    height, speed = ctx.sym(stage.fields["height"]), ctx.sym(stage.fields["speed"])
    g = ctx.gravity_symbol(stage)
    body = stage.fields["body"]
    solutions = {}
    if isinstance(height, sp.Symbol):
        solutions[height] = speed**2 / (2 * g)
    if isinstance(speed, sp.Symbol):
        solutions[speed] = sp.Pow(2 * g * height, sp.Rational(1, 2), evaluate=False)
    return [Relation(
        label=f"conservation of energy, {body} {verb} through {stage.text('height')}",
        lhs=speed, rhs=sp.Pow(2 * g * height, sp.Rational(1, 2), evaluate=False),
        solutions=solutions,
        requires=(
            Condition(sp.Ge(height, 0), f"the {verb} height {stage.text('height')} must not be negative"),
            Condition(sp.Ge(speed, 0), f"{body} must move {'down' if verb == 'falls' else 'up'} "
                      f"({stage.text('speed')} >= 0) to {verb.rstrip('s')} through a height"),
        ),
    )]


def _free_fall(stage: Stage, ctx: Context) -> list[Relation]:
    return _energy(stage, ctx, "falls")


def _rise(stage: Stage, ctx: Context) -> list[Relation]:
    return _energy(stage, ctx, "rises")


FREE_FALL = Effect("free_fall", "a body falls from rest through a height: v = sqrt(2 g h)", _FIELDS, _free_fall)
RISE = Effect("rise", "a body moving up at a speed rises to a height where it stops: h = v^2/(2 g)", _FIELDS, _rise)
