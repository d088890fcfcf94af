"""Direct and oblique central impact of two bodies, or of a body against a fixed surface.

A fixed surface has infinite mass: it is at rest, or moves at the constant velocity given for it
under ``before`` (a plate driven up and down), which the impact does not change.

Axes: n along the line of impact, pointing from the first body into the second; t along the
common tangent. Surfaces are smooth: no impulse along t. Numbers follow docs/design.md: impulse form
with inverse masses ``w = 1/m`` (``w = 0`` for a fixed surface); after-impact velocities in the
mass-centre form ``v1' = v_c - e w1 (v1 - v2)/(w1 + w2)``, which equals ``v1 - J w1`` but keeps its
accuracy when ``e`` is small or the masses are very unequal; energy lost as
``1/2 mu (1 - e)(1 + e) v_rel^2``, or ``1/2 mu (v_rel - v_sep)(v_rel + v_sep)`` when ``e`` itself is derived.
When the bodies move on together (a perfectly plastic impact) the worked solution takes the common speed after,
or a speed before, from conservation of momentum, ``m1 v1 + m2 v2 = (m1 + m2) v'``, as the textbook does,
whichever body is listed first; its kernel is the impulse form's (the mass-centre form for the speed after).

Force law (simulation): a Kelvin-Voigt contact calibrated to ``e`` (:class:`ContactLaw`), plus the
weight during contact only where asked for.

Mistakes: the first body's velocity after with its sign turned; ``e**2`` or ``1/e`` for ``e``; the full
speed for the normal component (oblique); the masses swapped, or a fixed surface taken as a body of
the other's mass; and with the energy: the energy kept reported as lost, a fraction for a
percentage, the loss as ``T' - T``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from grader.model.expr import Sym
from grader.model.quantities import ENERGY, IMPULSE, PURE, SPEED
from grader.physics.effects.base import Condition, Effect, Field, Mistake, Relation, Route, Stable

if TYPE_CHECKING:
    from grader.model.scene import Stage
    from grader.physics.record import Run
    from grader.physics.symbolic import Context



_FIELDS = (
    Field("bodies", "bodies", doc="[first, second]: n points from the first into the second"),
    Field("restitution", "expr", doc="coefficient of restitution e, 0..1", dimension=PURE),
    Field("before", "velocities", doc="per body: n-velocity, or {n: .., t: ..}; omitted = at rest; a fixed body "
          "keeps it", dimension=SPEED),
    Field("after", "velocities", required=False, doc="per body: names for the velocities after", dimension=SPEED,
          default="v_<body>_n_after (and v_<body>_t_after when oblique)"),
    Field("impulse", "name", required=False, doc="name for the normal impulse J", dimension=IMPULSE,
          default="J"),
    Field("energy_before", "name", required=False, doc="name for the kinetic energy before", dimension=ENERGY,
          default="T"),
    Field("energy_after", "name", required=False, doc="name for the kinetic energy after", dimension=ENERGY,
          default="T_after"),
    Field("energy_lost", "name", required=False, doc="name for the energy lost", dimension=ENERGY, default="E_lost"),
    Field("loss_fraction", "name", required=False, doc="name for the fraction of energy lost", dimension=PURE,
          default="f_loss"),
    Field("separation", "expr", required=False, doc="relative velocity of separation along n, v2' - v1', given in "
          "place of e (then name e as a quantity to find)", dimension=SPEED, default="v2' - v1' from e"),
    Field("weight_during_contact", "flag", required=False,
          doc="simulate the weight during contact (the closed form neglects it)", default="false"),
)
_DEFAULT_NAMES = {spec.name: spec.default for spec in _FIELDS if spec.kind == "name" and spec.default is not None}


@dataclass(frozen=True)
class _Impact:
    """One impact's quantities as its relations use them. A mistake is the same impact with a field
    changed: ``e`` used as ``e**2``, the masses swapped, a velocity with its sign turned."""

    stage: Stage
    bodies: tuple[str, str]
    inverse: tuple[Any, Any]  # w = 1/m of each body (0: fixed)
    e: Any  # the restitution as the template gives it (a parameter, a derived quantity or a number)
    before: tuple[tuple[Any, Any], tuple[Any, Any]]  # (n, t) of each body
    after: tuple[tuple[Any, Any], tuple[Any, Any]]
    tangents: tuple[int, ...]  # the bodies whose t-velocity the impact leaves unchanged (movable, oblique)
    law: str = "e"  # how the equations use e: "e", "e**2" or "1/e"
    loss: str = "lost"  # the loss as "lost", the energy "kept", T' - T ("negated"), or T - T' ("difference")

    @classmethod
    def of(cls, stage: Stage, ctx: Context) -> _Impact:
        """The impact a stage describes."""
        first, second = stage.fields["bodies"]

        def velocities(when: str) -> tuple[tuple[Any, Any], tuple[Any, Any]]:
            return ((ctx.velocity(stage, first, when, "n"), ctx.velocity(stage, first, when, "t")),
                    (ctx.velocity(stage, second, when, "n"), ctx.velocity(stage, second, when, "t")))

        inverse = (ctx.inverse_mass(first), ctx.inverse_mass(second))
        return cls(stage, (first, second), inverse, ctx.sym(stage.fields["restitution"]), velocities("before"),
                   velocities("after"), tuple(i for i, w in enumerate(inverse) if w != 0 and stage.is_oblique))

    def relations(self, ctx: Context) -> list[Relation]:
        """The impact's equations, as a student would write them."""
        import sympy as sp

        (first, second), (w1, w2), e = self.bodies, self.inverse, self.e
        used = {"e": e, "e**2": e**2, "1/e": 1 / e}[self.law]
        impulse = ctx.quantity(self.stage, "impulse", _DEFAULT_NAMES)
        (u1, u2), (a1, a2) = (self.before[0][0], self.before[1][0]), (self.after[0][0], self.after[1][0])
        approach, separation = u1 - u2, a2 - a1
        # A measured separation (given in place of e) makes e its ratio to the approach: one unknown.
        measured = self.stage.fields.get("separation")
        ratio = (separation if measured is None else ctx.sym(measured)) / approach
        centre = (w2 * u1 + w1 * u2) / (w1 + w2)
        e_text = self.stage.text("restitution")

        given_impulse = {impulse: (1 + used) * approach / (w1 + w2)}
        if isinstance(u1, sp.Symbol) and not self.e.free_symbols:
            # A speed before found from the impulse (a bullet's, from the block it strikes and embeds in).
            given_impulse[u1] = u2 + impulse * sp.together(w1 + w2) / (1 + used)
        relations = [
            Relation(f"impulse along n in the impact of {first} and {second}, with restitution {e_text}",
                     impulse, (1 + used) * approach / (w1 + w2), solutions=given_impulse, general=False),
        ]
        if w1 != 0 and w2 != 0 and sp.simplify(a1 - a2) == 0:
            # Before either body's impulse-momentum: the common velocity is the textbook's momentum balance,
            # whichever body is listed first (the bullet's own, v - J/m_b, cancels).
            relations.append(self._momentum(used))
        relations.append(
            Relation(f"impulse-momentum for {first} along n", a1, u1 - impulse * w1,
                     solutions={a1: u1 - impulse * w1, impulse: (u1 - a1) / w1},
                     stable={a1: (Stable(centre - used * w1 * approach / (w1 + w2)),)}))
        if w2 != 0:
            relations.append(Relation(
                f"impulse-momentum for {second} along n", a2, u2 + impulse * w2,
                solutions={a2: u2 + impulse * w2, impulse: (a2 - u2) / w2},
                stable={a2: (Stable(centre + used * w2 * approach / (w1 + w2)),)}))
        restitution = Relation(
            "coefficient of restitution: separation over approach along n", used, ratio,
            solutions={e: {"e": ratio, "e**2": sp.sqrt(ratio), "1/e": 1 / ratio}[self.law],
                       a1: a2 - used * approach, a2: a1 + used * approach},
            requires=(
                Condition(sp.Gt(approach, 0), f"{first} and {second} are not approaching along the line of "
                          "impact (relative normal velocity <= 0), so they do not collide"),
                Condition(sp.Ge(e, 0), "the coefficient of restitution is {value}; it cannot be negative "
                          "(the bodies would pass through each other)", subject=e),
                # Slack of 1e-12: a derived e one rounding above 1 (an exactly elastic rebound, its
                # height rounded) is 1, not a refusal; a real excess is far larger.
                Condition(sp.Le(e, 1 + sp.Rational(1, 10**12)), "the coefficient of restitution is {value}; above 1 "
                          "the impact would create energy", subject=e),
            ))
        # Against a fixed body (a floor, a wall, a plate moving on regardless) a textbook writes the rebound
        # from e first (v' = -e v): the impulse is then a step only where it is asked for.
        relations.insert(0 if w2 == 0 else len(relations), restitution)
        for index in self.tangents:
            (_, before), (_, after) = self.before[index], self.after[index]
            relations.append(Relation(f"smooth surfaces: no impulse along t, so {self.bodies[index]}'s t-velocity is "
                                      "unchanged", after, before, solutions={after: before}))
        return relations + self._energy(ctx, used, approach, separation)

    def _momentum(self, used: Any) -> Relation:
        """Conservation of momentum along n when the bodies move on together (a perfectly plastic
        impact): ``m1 v1 + m2 v2 = (m1 + m2) v'``, the textbook's route to a speed before from the
        common speed after (a bullet's, from the block it embeds in; a car's, from the skid).

        The kernels keep the impulse form's composition (``v1 = v2 + J (w1 + w2)/(1 + e)`` with
        ``J = (v' - v2)/w2``): the relation changes what the reader sees, not what computes."""
        import sympy as sp

        (first, second), (w1, w2) = self.bodies, self.inverse
        (u1, u2), common = (self.before[0][0], self.before[1][0]), self.after[0][0]
        m1, m2 = 1 / w1, 1 / w2
        together = sp.together(w1 + w2) / (1 + used)
        return Relation(
            f"conservation of momentum along n: {first} and {second} move on together", m1 * u1 + m2 * u2,
            (m1 + m2) * common,
            solutions={u1: ((m1 + m2) * common - m2 * u2) / m1, u2: ((m1 + m2) * common - m1 * u1) / m2,
                       common: (m1 * u1 + m2 * u2) / (m1 + m2)},
            stable={u1: (Stable(u2 + (common - u2) / w2 * together),),
                    u2: (Stable(u1 - (u1 - common) / w1 * together),),
                    common: (Stable((w2 * u1 + w1 * u2) / (w1 + w2)),)},
            general=False)

    def _kinetic(self, when: str) -> Any:
        """Sum of ``(v_n^2 + v_t^2) / (2 w)`` over the movable bodies."""
        import sympy as sp

        from grader.physics.symbolic import hypot

        velocities = self.before if when == "before" else self.after
        total = sp.Integer(0)
        for w, (n, t) in zip(self.inverse, velocities, strict=True):
            if w != 0:
                total += hypot(n, t) ** 2 / (2 * w)  # no square of a component under- or overflows
        return total

    def _energy(self, ctx: Context, used: Any, approach: Any, separation: Any) -> list[Relation]:
        import sympy as sp

        stage, (w1, w2) = self.stage, self.inverse
        before, after = (ctx.quantity(stage, key, _DEFAULT_NAMES) for key in ("energy_before", "energy_after"))
        lost, fraction = (ctx.quantity(stage, key, _DEFAULT_NAMES) for key in ("energy_lost", "loss_fraction"))
        totals = {when: self._kinetic(when) for when in ("before", "after")}
        lost_form = (1 - used) * (1 + used) * approach**2 / (2 * (w1 + w2))
        # With e derived, (v_rel - v_sep) is a difference of measured quantities; once e <= 1 is
        # checked the true loss is >= 0, so a negative result is rounding of an exact 0.
        derived_form = sp.Max(0, (approach - separation) * (approach + separation) / (2 * (w1 + w2)))
        sign = -1 if self.loss == "negated" else 1
        if self.loss == "kept":
            loss = Relation("energy lost in the impact", lost, totals["after"], solutions={lost: totals["after"]},
                            general=False)
        elif self.loss == "difference":  # the textbook's route (Sample Problem 3/30): T and T' written down first
            loss = Relation("energy lost in the impact", lost, before - after, solutions={lost: before - after},
                            general=False)
        else:
            loss = Relation("energy lost in the impact", lost, sign * lost_form, solutions={lost: sign * lost_form},
                            general=False, stable={lost: (Stable(sign * lost_form, given=(self.e,)),
                                                          Stable(sign * derived_form))})
        return [
            Relation("kinetic energy just before the impact", before, totals["before"],
                     solutions={before: totals["before"]}, general=False),
            Relation("kinetic energy just after the impact", after, totals["after"],
                     solutions={after: totals["after"]}, general=False),
            loss,
            Relation("fraction of the kinetic energy lost", fraction, lost / before,
                     solutions={fraction: lost / before}, general=False),
        ]


def _impact(stage: Stage, ctx: Context) -> list[Relation]:
    return _Impact.of(stage, ctx).relations(ctx)


def _mistakes(stage: Stage, ctx: Context) -> list[Mistake]:
    """The mistakes of an impact, then of its energy; each only where the scene lets it differ."""
    import sympy as sp

    from grader.physics.symbolic import hypot

    real = _Impact.of(stage, ctx)
    (n1, t1), (n2, t2) = real.after
    changed: list[tuple[str, str, _Impact | None]] = [
        ("impact.rebound_sign", f"{real.bodies[0]}'s velocity after the impact with its sign turned",
         replace(real, after=((-n1, t1), (n2, t2)))),
    ]
    if not (real.e.is_number and real.e in (0, 1)):  # e**2 and 1/e are e itself, or 1/0
        changed += [("impact.e_squared", "using e² instead of e", replace(real, law="e**2")),
                    ("impact.e_inverse", "using 1/e instead of e (approach over separation)", replace(real, law="1/e"))]
    (u1, s1), second = real.before
    if 0 in real.tangents:
        changed.append(("impact.full_speed", f"{real.bodies[0]}'s full speed used instead of its normal component",
                        replace(real, before=((hypot(u1, s1), s1), second))))
    w1, w2 = real.inverse
    if w2 != 0:
        changed.append(("impact.masses_swapped", "the two masses swapped", replace(real, inverse=(w2, w1))))
    else:
        surface = ctx.symbol(ctx.unused_name(f"v_{real.bodies[1]}_n_after", stage))
        changed.append(("impact.fixed_as_equal_mass", f"the fixed {real.bodies[1]} treated as a body of "
                        f"{real.bodies[0]}'s mass", replace(real, inverse=(w1, w1), after=((n1, t1), (surface, t2)))))
    changed += [
        ("energy.kept_as_lost", "the energy kept (T') reported as the energy lost", replace(real, loss="kept")),
        ("energy.fraction_for_percent", "a fraction where a percentage was asked (0.476 for 47.6 %)", None),
        ("energy.wrong_sign", "the energy lost as T' − T, with the wrong sign", replace(real, loss="negated")),
    ]
    return [Mistake(id, says, tuple(impact.relations(ctx))) if impact is not None else
            Mistake(id, says, unit="%", scale=sp.Rational(1, 100)) for id, says, impact in changed]


def _routes(stage: Stage, ctx: Context) -> list[Route]:
    """The textbook's energy route: the kinetic energies before and after written down, then their
    difference (which cancels when little is lost: what rounding them costs is what this route is for)."""
    real = _Impact.of(stage, ctx)
    return [Route("energy", "the energy route (T − T′)",
                  tuple(replace(real, loss="difference").relations(ctx)))]


@dataclass(frozen=True)
class ContactLaw:
    """Kelvin-Voigt contact (linear spring and dashpot, tension allowed until the overlap is 0
    again), calibrated so that it reproduces ``e`` exactly:
    ``zeta = -ln e / sqrt(pi^2 + ln^2 e)``, natural frequency from the contact duration
    ``omega_n = pi / (duration sqrt(1 - zeta^2))``. Stiffness and damping per unit reduced mass
    (``k = mu omega_n^2``, ``c = 2 zeta mu omega_n``), so extreme mass ratios change nothing.
    ``e = 0`` never separates on its own: the contact ends at maximum compression (``sticks``).

    >>> law = ContactLaw.calibrated(0.5, 1e-3)
    >>> round(law.zeta, 6), round(math.exp(-law.zeta * math.pi / math.sqrt(1 - law.zeta**2)), 12)
    (0.215454, 0.5)
    """

    zeta: float
    omega: float
    sticks: bool

    @classmethod
    def calibrated(cls, e: float, duration: float) -> ContactLaw:
        """The law for restitution ``e`` and a contact lasting ``duration`` seconds."""
        if e <= 0:
            return cls(1.0, math.pi / duration, True)
        log_e = math.log1p(e - 1) if e > 0.5 else math.log(e)  # e - 1 is exact for e in [0.5, 1]
        zeta = -log_e / math.hypot(math.pi, log_e)
        return cls(zeta, math.pi / (duration * math.sqrt((1 - zeta) * (1 + zeta))), False)

    def specific_force(self, overlap: float, rate: float) -> float:
        """Contact force per unit reduced mass, pushing the bodies apart."""
        return self.omega * (self.omega * overlap + 2 * self.zeta * rate)


def _simulate_impact(stage: Stage, run: Run) -> None:
    first, second = stage.fields["bodies"]
    w1, w2 = _inverse_mass(run, first), _inverse_mass(run, second)
    e = run.value(stage.fields["restitution"])
    before = [_component(run, stage, body, "before", axis) for body in (first, second) for axis in ("n", "t")]
    approach = before[0] - before[2]
    run.speed_scale = max(run.speed_scale, *map(abs, before))
    if approach <= 0 or not 0 <= e <= 1:
        run.problems.append(f"{first} and {second} do not collide (relative normal velocity {approach:g}) "
                            if approach <= 0 else f"the coefficient of restitution {e:g} is outside [0, 1]")
        after = before
    else:
        after = simulate_contact(stage, run, (first, second), (w1, w2), e, before)
    for index, body in enumerate((first, second)):
        given = stage.fields.get("after", {}).get(body)
        if given is not None:
            run.output(given.n, after[2 * index])
            if given.t is not None:
                run.output(given.t, after[2 * index + 1])
    _output_energies(stage, run, (w1, w2), before, after)
    if "separation" in stage.fields:  # given: an observation a search for e matches
        run.output(stage.fields["separation"], after[2] - after[0])


def simulate_contact(stage: Stage, run: Run, bodies: tuple[str, str], inverse: tuple[float, float], e: float,
                     before: list[float], label: str | None = None) -> list[float]:
    """One contact of two bodies (inverse masses ``inverse``) arriving with ``before`` (n and t of each)
    under the law calibrated to ``e``; their velocities after, in the same order. Recorded under
    ``label`` (default: the impact of the two bodies)."""
    from grader.physics.integrate import Mode  # the simulator's part: loading a template needs none of it
    from grader.physics.record import ContactRecord

    w1, w2 = inverse
    share1, share2 = w1 / (w1 + w2), w2 / (w1 + w2)
    law = ContactLaw.calibrated(e, run.options.contact_duration)
    run.uses("contact (Kelvin-Voigt)")
    weight_n, weight_t = _weight(stage, run, before)

    def free(_: float, y: Any) -> Any:
        return np.concatenate([y[4:], np.zeros(4)])

    def pressed(_: float, y: Any) -> Any:
        f = law.specific_force(y[0] - y[2], y[4] - y[6])
        second = (weight_n, weight_t) if w2 else (0.0, 0.0)
        return np.concatenate([y[4:], [weight_n - share1 * f, weight_t, second[0] + share2 * f, second[1]]])

    approach = before[0] - before[2]
    duration = run.options.contact_duration
    gap = approach * duration / 4
    y0 = np.array([-gap, 0.0, 0.0, 0.0, *before])
    # Errors along n are measured against the overlap and the approach speed, along t against the
    # tangential motion: a grazing impact's tiny normal motion is not drowned by its t-motion.
    normal_speed = max(approach, abs(before[0]), abs(before[2]))
    tangent_speed = max(abs(before[1]), abs(before[3])) or normal_speed
    sizes = np.array([approach * duration, tangent_speed * duration] * 2 + [normal_speed, tangent_speed] * 2)
    entry = Mode("approach", free, lambda y: y[0] - y[2], +1, scale=gap / approach, sizes=lambda y: sizes)
    # e = 0: the spring would hold the bodies together for ever; they part at maximum compression.
    exit_event = (lambda y: y[4] - y[6]) if law.sticks else (lambda y: y[0] - y[2])
    contact = Mode("contact", pressed, exit_event, -1, scale=duration, omega=law.omega,
                   force=lambda y: law.specific_force(y[0] - y[2], y[4] - y[6]) / (w1 + w2), sizes=lambda y: sizes)
    path = run.integrate([entry, contact], y0)
    label = label or f"impact of {bodies[0]} and {bodies[1]}"
    run.record(label, ("x1n", "x1t", "x2n", "x2t", "v1n", "v1t", "v2n", "v2t"), path)
    after = [float(v) for v in path.y[-1][4:]]
    if law.sticks:
        # The contact ended where the relative normal velocity is zero (its event): the bodies move
        # on together, at the velocity the simulated momentum gives; what remains of the relative
        # velocity is the event's location error, and would give a zero velocity a direction.
        common = share2 * after[0] + share1 * after[2]
        after[0] = after[2] = common
    run.contacts.append(ContactRecord(stage.index, label, e, (after[2] - after[0]) / approach, law.zeta, duration))
    return after


def _weight(stage: Stage, run: Run, before: list[float]) -> tuple[float, float]:
    """Gravity along n and t during contact: only if asked for, and only where the first body fell
    onto the second. It fell from rest, so gravity points the way it moves at the impact: straight
    along n onto a floor or a pile, at an angle to n onto an incline."""
    if not (run.options.weight_during_contact or stage.fields.get("weight_during_contact", False)):
        return 0.0, 0.0
    fell = any(s.effect == "free_fall" and s.fields["body"] == stage.fields["bodies"][0]
               for s in run.scene.stages[:stage.index])
    if not fell:
        return 0.0, 0.0
    run.uses("weight during contact")
    speed = math.hypot(before[0], before[1])
    if speed == 0:  # it fell through no height: n is downward, as the scene's axes say
        return run.gravity(), 0.0
    return run.gravity() * before[0] / speed, run.gravity() * before[1] / speed


def _inverse_mass(run: Run, body: str) -> float:
    mass = run.scene.bodies[body].mass
    return 0.0 if mass is None else 1.0 / run.value(mass)


def _component(run: Run, stage: Stage, body: str, when: str, axis: str) -> float:
    given = stage.fields.get(when, {}).get(body)
    part = None if given is None else getattr(given, axis)
    return 0.0 if part is None else run.value(part)


def _output_energies(stage: Stage, run: Run, inverse: tuple[float, float], before: list[float],
                     after: list[float]) -> None:
    # Energies in units of the largest speed squared: 1e170 m/s overflows only the energy itself,
    # never the fraction lost.
    unit = max(abs(v) for v in before + after) or 1.0

    def kinetic(v: list[float]) -> float:
        return sum((math.hypot(v[2 * i], v[2 * i + 1]) / unit) ** 2 / (2 * w) for i, w in enumerate(inverse) if w)

    # The loss in the stable form 1/2 mu (v_rel - v_sep)(v_rel + v_sep) of the simulated normal
    # velocities (smooth surfaces: the t-velocities do not change), never T - T', which cancels.
    # The contact is passive (a spring and a dashpot with c >= 0), so a negative value can only be
    # the integration error of a separation one rounding above the approach: it is 0.
    approach, separation = (before[0] - before[2]) / unit, (after[2] - after[0]) / unit
    scaled_before, scaled_after = kinetic(before), kinetic(after)
    scaled_lost = max(0.0, (approach - separation) * (approach + separation) / (2 * (inverse[0] + inverse[1])))
    measured = {"energy_before": scaled_before * unit * unit, "energy_after": scaled_after * unit * unit,
                "energy_lost": scaled_lost * unit * unit,
                "loss_fraction": scaled_lost / scaled_before if scaled_before else math.nan,  # nothing moved
                "impulse": (before[0] - after[0]) / inverse[0]}
    for key, value in measured.items():
        if key in stage.fields:
            run.output(Sym(stage.fields[key]), value)


IMPACT = Effect(
    "impact",
    "direct or oblique central impact with restitution e; smooth surfaces; a body may be fixed",
    _FIELDS,
    _impact,
    _simulate_impact,
    _mistakes,
    _routes,
    force_law="a Kelvin-Voigt contact along n (a linear spring and dashpot per unit reduced mass) calibrated so "
              "that it reproduces e exactly; no force along t (smooth surfaces); the weight acts during the contact "
              "only where asked for (weight_during_contact, or grader simulate --weight-during-contact)",
)
