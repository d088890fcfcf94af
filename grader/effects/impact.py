"""Direct and oblique central impact of two bodies, or of a body against a fixed surface.

Axes: n along the line of impact, pointing from the first body into the second; t along the
common tangent. Surfaces are smooth: no impulse along t. Numbers follow DESIGN.md: impulse form
with inverse masses ``w = 1/m`` (``w = 0`` for a fixed surface); after-impact velocities in the
mass-centre form ``v1' = v_c - e w1 (v1 - v2)/(w1 + w2)``, which equals ``v1 - J w1`` but keeps its
accuracy when ``e`` is small or the masses are very unequal; energy lost as
``1/2 mu (1 - e)(1 + e) v_rel^2``, or ``1/2 mu (v_rel^2 - v_sep^2)`` when ``e`` itself is derived.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from grader.effects.base import Condition, Effect, Field, Relation, Stable

if TYPE_CHECKING:
    from grader.scene import Stage
    from grader.symbolic import Context


def _impact(stage: Stage, ctx: Context) -> list[Relation]:
    import sympy as sp

    first, second = stage.fields["bodies"]
    w1, w2 = ctx.inverse_mass(first), ctx.inverse_mass(second)
    e = ctx.sym(stage.fields["restitution"])
    impulse = ctx.quantity(stage, "impulse")
    u1, u2 = ctx.velocity(stage, first, "before", "n"), ctx.velocity(stage, second, "before", "n")
    a1, a2 = ctx.velocity(stage, first, "after", "n"), ctx.velocity(stage, second, "after", "n")
    approach, separation = u1 - u2, a2 - a1
    centre = (w2 * u1 + w1 * u2) / (w1 + w2)
    e_text = stage.text("restitution")

    relations = [
        Relation(f"impulse along n in the impact of {first} and {second}, with restitution {e_text}",
                 impulse, (1 + e) * approach / (w1 + w2), solutions={impulse: (1 + e) * approach / (w1 + w2)},
                 general=False),
        Relation(f"impulse-momentum for {first} along n", a1, u1 - impulse * w1,
                 solutions={a1: u1 - impulse * w1, impulse: (u1 - a1) / w1},
                 stable={a1: (Stable(centre - e * w1 * approach / (w1 + w2)),)}),
    ]
    if w2 != 0:
        relations.append(Relation(
            f"impulse-momentum for {second} along n", a2, u2 + impulse * w2,
            solutions={a2: u2 + impulse * w2, impulse: (a2 - u2) / w2},
            stable={a2: (Stable(centre + e * w2 * approach / (w1 + w2)),)}))
    relations.append(Relation(
        "coefficient of restitution: separation over approach along n", e, separation / approach,
        solutions={e: separation / approach, a1: a2 - e * approach, a2: a1 + e * approach},
        requires=(
            Condition(sp.Gt(approach, 0), f"{first} and {second} are not approaching along the line of "
                      "impact (relative normal velocity <= 0), so they do not collide"),
            Condition(sp.Ge(e, 0), "the coefficient of restitution is {value}; it cannot be negative "
                      "(the bodies would pass through each other)", subject=e),
            # Slack of 1e-12: a derived e one rounding above 1 (an exactly elastic rebound, its
            # height rounded) is 1, not a refusal; a real excess is far larger.
            Condition(sp.Le(e, 1 + sp.Rational(1, 10**12)), "the coefficient of restitution is {value}; above 1 "
                      "the impact would create energy", subject=e),
        )))
    for body in (first, second):
        if ctx.inverse_mass(body) != 0 and stage.is_oblique:
            before, after = ctx.velocity(stage, body, "before", "t"), ctx.velocity(stage, body, "after", "t")
            relations.append(Relation(f"smooth surfaces: no impulse along t, so {body}'s t-velocity is "
                                      "unchanged", after, before, solutions={after: before}))
    return relations + _energy(stage, ctx, e, approach, separation, w1, w2)


def _energy(stage: Stage, ctx: Context, e: Any, approach: Any, separation: Any, w1: Any, w2: Any) -> list[Relation]:
    import sympy as sp

    before, after = ctx.quantity(stage, "energy_before"), ctx.quantity(stage, "energy_after")
    lost, fraction = ctx.quantity(stage, "energy_lost"), ctx.quantity(stage, "loss_fraction")
    totals = {when: ctx.kinetic_energy(stage, when) for when in ("before", "after")}
    lost_form = (1 - e) * (1 + e) * approach**2 / (2 * (w1 + w2))
    # With e derived, (v_rel - v_sep) is a difference of measured quantities; once e <= 1 is
    # checked the true loss is >= 0, so a negative result is rounding of an exact 0.
    derived_form = sp.Max(0, (approach - separation) * (approach + separation) / (2 * (w1 + w2)))
    return [
        Relation("kinetic energy just before the impact", before, totals["before"],
                 solutions={before: totals["before"]}, general=False),
        Relation("kinetic energy just after the impact", after, totals["after"],
                 solutions={after: totals["after"]}, general=False),
        Relation("energy lost in the impact", lost, lost_form, solutions={lost: lost_form}, general=False,
                 stable={lost: (Stable(lost_form, given=(e,)),
                                Stable(derived_form))}),
        Relation("fraction of the kinetic energy lost", fraction, lost / before,
                 solutions={fraction: lost / before}, general=False),
    ]


IMPACT = Effect(
    "impact",
    "direct or oblique central impact with restitution e; smooth surfaces; a body may be fixed",
    (
        Field("bodies", "bodies", doc="[first, second]: n points from the first into the second"),
        Field("restitution", "expr", doc="coefficient of restitution e, 0..1"),
        Field("before", "velocities", doc="per body: n-velocity, or {n: .., t: ..}; omitted = at rest"),
        Field("after", "velocities", required=False, doc="per body: names for the velocities after"),
        Field("impulse", "name", required=False, doc="name for the normal impulse J"),
        Field("energy_before", "name", required=False, doc="name for the kinetic energy before"),
        Field("energy_after", "name", required=False, doc="name for the kinetic energy after"),
        Field("energy_lost", "name", required=False, doc="name for the energy lost"),
        Field("loss_fraction", "name", required=False, doc="name for the fraction of energy lost"),
    ),
    _impact,
)
