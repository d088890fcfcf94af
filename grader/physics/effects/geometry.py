"""Impact geometry: where two spheres touch, from their radii and an offset.

Sphere 1 moves along a straight line; sphere 2's centre lies at a distance ``b`` (the offset) from
that line. At contact the centres are ``r1 + r2`` apart, so the line of centres n makes the angle
``theta`` with sphere 1's velocity, ``sin theta = b/(r1 + r2)``: head-on at ``b = 0``, grazing at
``b = r1 + r2`` (a miss, refused). The kernels evaluate the angle as
``2 atan2(b, R + sqrt((R - b)(R + b)))`` with ``R = r1 + r2``: near grazing the difference ``R - b`` is
formed first, so the line of centres keeps its accuracy where ``R**2 - b**2`` would cancel.

Simulation: no force. Sphere 1 moves uniformly along its line toward sphere 2, at rest, until the
located event where the centres are ``r1 + r2`` apart; the line of centres is measured from the
positions there.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from grader.model.expr import to_text
from grader.model.quantities import ANGLE, LENGTH
from grader.physics.effects.base import Condition, Effect, Field, Relation, Stable

if TYPE_CHECKING:
    from grader.model.scene import Stage
    from grader.physics.record import Run
    from grader.physics.symbolic import Context


def _line_of_centres(stage: Stage, ctx: Context) -> list[Relation]:
    import sympy as sp

    first, second = stage.fields["bodies"]
    reach = ctx.radius(first) + ctx.radius(second)
    offset, angle = ctx.sym(stage.fields["offset"]), ctx.sym(stage.fields["angle"])
    b = stage.text("offset")
    reach_text = " + ".join(to_text(ctx.scene.bodies[body].radius) for body in (first, second))  # type: ignore[arg-type]
    solutions, stable = {}, {}
    if isinstance(angle, sp.Symbol):
        solutions[angle] = sp.atan2(offset, sp.sqrt(reach**2 - offset**2))
        # The half-angle form 2 atan2(b, R + sqrt((R - b)(R + b))): a sum of positive terms, R - b formed
        # first, no square of a length (1e170 m would overflow); its sine and cosine stay functions of
        # the angle (sympy writes cos(atan2(y, x)) as x/sqrt(x**2 + y**2), a quotient of squared lengths).
        stable[angle] = (Stable(2 * sp.atan2(offset, reach + sp.sqrt((reach - offset) * (reach + offset)))),)
    if isinstance(offset, sp.Symbol):
        solutions[offset] = reach * sp.sin(angle)
    return [Relation(
        f"impact geometry: at contact the centres of {first} and {second} are {reach_text} apart, and {second}'s "
        f"centre is {b} off {first}'s line of travel", sp.sin(angle), offset / reach,
        solutions=solutions, stable=stable, general=False,
        requires=(
            Condition(sp.Ge(offset, 0), f"the offset {b} is a distance from {first}'s line of travel; it cannot "
                      "be negative"),
            Condition(sp.Lt(offset, reach), f"{b}/({reach_text}) is {{value}}: the offset {b} must be below the sum "
                      f"of the radii, or {first} passes {second} without striking it (at {b} = {reach_text} it only "
                      "grazes it)", subject=offset / reach),
        ))]


def _simulate_line_of_centres(stage: Stage, run: Run) -> None:
    """Sphere 1 moves at ``r1 + r2`` per second toward sphere 2 until the centres are ``r1 + r2`` apart."""
    first, second = stage.fields["bodies"]
    radii = [run.scene.bodies[body].radius for body in (first, second)]  # the parser made sure both have one
    reach = sum(run.value(radius) for radius in radii if radius is not None)
    offset = run.value(stage.fields["offset"])
    if not 0 <= offset < reach:
        run.problems.append(f"{first} passes {second} without striking it (offset {offset:g} m, sum of the radii "
                            f"{reach:g} m)" if offset >= reach else f"the offset {offset:g} m is negative")
        run.output(stage.fields["angle"], math.pi / 2)
        return
    run.uses("uniform motion to contact")
    from grader.physics.integrate import Mode  # the simulator's: loading a template needs only the catalogue

    # The state is sphere 2's centre seen from sphere 1's: [along the line of travel, across it, and
    # their rates]. The event is the squared distance less reach**2, written so that near grazing
    # (offset close to reach) nothing cancels, and with the sign of the distance along: it keeps falling
    # through the contact (uniform motion is one step long, and the squared distance would rise again
    # within it, with no change of sign to locate).
    def moving(_: float, y: np.ndarray) -> np.ndarray:
        return np.array([y[2], y[3], 0.0, 0.0])

    def apart(y: np.ndarray) -> float:
        return float(y[0] * abs(y[0]) - (reach - y[1]) * (reach + y[1]))

    contact = Mode("approach to contact", moving, apart, -1, scale=1.0, sizes=lambda y: np.full(4, reach))
    path = run.integrate([contact], np.array([2 * reach, offset, -reach, 0.0]))
    run.record(f"{first} moves toward {second}", ("along the path", "across the path", "rate along the path",
                                                  "rate across the path"), path)
    along, across = path.y[-1][:2]
    run.output(stage.fields["angle"], math.atan2(float(across), float(along)))


IMPACT_GEOMETRY = Effect(
    "impact_geometry",
    "where two spheres touch: the line of centres makes the angle asin(b/(r1 + r2)) with the first's velocity",
    (
        Field("bodies", "spheres", doc="[first, second]: spheres (bodies with a radius); the first moves, the "
              "second is at rest"),
        Field("offset", "expr", doc="distance b of the second's centre from the first's line of travel, "
              "0 <= b < r1 + r2", dimension=LENGTH),
        Field("angle", "expr", doc="angle between the first's velocity and the line of centres n at contact",
              dimension=ANGLE),
    ),
    _line_of_centres,
    _simulate_line_of_centres,
    force_law="none: the first sphere moves uniformly toward the second, at rest, until the located event where "
              "the centres are r1 + r2 apart; the line of centres is measured from the positions there",
)
