"""A linear spring of stiffness k between a body (or two bodies stuck together) and a fixed support:
the greatest compression from the speed on contact, or the speed a released spring gives.

Work-energy from the start (compression ``x0``, speed ``v``, moving so as to compress the spring) to
the greatest compression ``x`` (at rest there): ``1/2 M v**2 + M g (x - x0) = 1/2 k (x**2 - x0**2)``, the
gravity term only where the spring is ``vertical`` and the bodies move down onto it. ``M`` is the
mass of everything the spring stops: the body and the one stuck to it (a bullet embedded in the block).
The relation is the same read backwards: released at rest from ``x``, the spring gives the bodies ``v``
where its compression is ``x0`` again.

A spring that ``supports`` a body before the stage (a platform a package is dropped on) starts at its
static deflection ``delta = m_s g/k``. Compressions are measured from the spring's natural length.

The kernels use, with ``a = M g/k`` the static deflection of everything it stops (0 for a
horizontal spring), ``x = a + hypot(x0 - a, v sqrt(M/k))``: a sum of terms never negative, where the
quadratic formula's ``-b + sqrt(b**2 - 4ac)`` would cancel for a slow body on a stiff spring; and
``v = sqrt(k/M) sqrt((x - x0)(x + x0 - 2a))``, the difference of compressions formed first.

Force law (simulation): Hooke's law ``-k x`` on the bodies (and their weight where the spring is
vertical), from the start until the located event where they stop (``x' = 0``); with the speed
unknown, released at rest at the greatest compression until the compression is ``x0`` again.

Mistakes: ``1/2 k x`` for ``1/2 k x**2``; the mass of the body alone, before the other stuck to it;
the static deflection forgotten (the spring taken to start at its natural length).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from grader.base.errors import TemplateError
from grader.model.expr import Sym
from grader.model.quantities import ENERGY, LENGTH, SPEED, STIFFNESS
from grader.physics.effects.base import Condition, Effect, Field, Mistake, Relation, Stable

if TYPE_CHECKING:
    from grader.model.scene import Stage
    from grader.physics.record import Run
    from grader.physics.symbolic import Context

_FIELDS = (
    Field("body", "body", doc="the body the spring stops (or launches)"),
    Field("with", "body", required=False, doc="a body stuck to it that moves along (a bullet embedded in the block)",
          default="the body moves alone"),
    Field("stiffness", "expr", doc="spring constant k, > 0", dimension=STIFFNESS),
    Field("speed", "expr", doc="speed where the compression is `initial` (on contact), moving so as to compress "
          "the spring, >= 0", dimension=SPEED),
    Field("compression", "expr", doc="greatest compression, from the spring's natural length", dimension=LENGTH),
    Field("initial", "expr", required=False, doc="compression at the start, from the natural length",
          dimension=LENGTH, default="0 (or the static deflection, with `supports`)"),
    Field("vertical", "flag", required=False, doc="the spring is vertical and the bodies move down onto it: their "
          "weight does work as it compresses", default="false"),
    Field("supports", "body", required=False, doc="a body the spring holds at rest before the stage (a platform): "
          "the spring starts at its static deflection m g/k; needs `vertical`", default="none"),
    Field("static_deflection", "name", required=False, doc="name for the static deflection m g/k of `supports`",
          dimension=LENGTH, default="delta_st"),
    Field("energy", "name", required=False, doc="name for the energy stored at the greatest compression, "
          "1/2 k x^2", dimension=ENERGY, default="not named: no step for it"),
    Field("travel", "name", required=False, doc="name for the further compression from the start, x - x0 (how "
          "far a platform moves below where it rested)", dimension=LENGTH, default="not named: no step for it"),
)
_DEFAULT_NAMES = {spec.name: spec.default for spec in _FIELDS if spec.kind == "name" and spec.default is not None}


def check_fields(stage: Stage, where: str) -> None:
    """What the field schema cannot say: a support only under a vertical spring, and not with an
    initial compression of its own."""
    fields = stage.fields
    if "supports" in fields and not fields.get("vertical", False):
        raise TemplateError(where, f"stages[{stage.index}].supports", "vertical: true as well (a spring that holds "
                            "a body at its static deflection is vertical)", f"supports: {fields['supports']}")
    if "supports" in fields and "initial" in fields:
        raise TemplateError(where, f"stages[{stage.index}].initial", "no initial compression with `supports` (the "
                            "spring then starts at the static deflection)", f"initial: {stage.text('initial')}")
    if "static_deflection" in fields and "supports" not in fields:
        raise TemplateError(where, f"stages[{stage.index}].static_deflection", "`supports: BODY` (the body whose "
                            "weight deflects the spring)", "no supports")


@dataclass(frozen=True)
class _Spring:
    """One spring stage's quantities; a mistake is the same stage with one changed."""

    stage: Stage
    mass: Any  # everything the spring stops: the body and the one stuck to it
    k: Any
    v: Any
    x: Any
    x0: Any  # the compression at the start: 0, `initial`, or the static deflection's symbol
    g: Any  # g where the spring is vertical, else 0
    x0_value: Any  # x0 in the scene's parameters (the static deflection m_s g/k written out)
    law: str = "x**2"  # the spring's energy as 1/2 k x**2, or as a student who writes 1/2 k x
    forgets_static: bool = False

    @classmethod
    def of(cls, stage: Stage, ctx: Context) -> _Spring:
        """The spring a stage describes."""
        check_fields(stage, ctx.scene.where)
        fields = stage.fields
        mass = ctx.mass(stage, fields["body"], "body")
        if "with" in fields:
            mass += ctx.mass(stage, fields["with"], "with")
        g = ctx.gravity_symbol(stage) if fields.get("vertical", False) else 0
        k = ctx.sym(fields["stiffness"])
        if "supports" in fields:
            x0 = ctx.quantity(stage, "static_deflection", _DEFAULT_NAMES)
            x0_value = ctx.mass(stage, fields["supports"], "supports") * g / k
        else:
            x0 = x0_value = ctx.sym(fields["initial"]) if "initial" in fields else 0
        return cls(stage, mass, k, ctx.sym(fields["speed"]), ctx.sym(fields["compression"]), x0, g, x0_value)

    def relations(self, ctx: Context) -> list[Relation]:
        """The stage's relations as a student writes them."""
        relations = [self._static(ctx)] if "supports" in self.stage.fields else []
        relations.append(self._energy(ctx))
        import sympy as sp

        if "travel" in self.stage.fields:
            relations.append(self._travel(ctx))
        if "energy" in self.stage.fields:
            stored = ctx.quantity(self.stage, "energy", _DEFAULT_NAMES)
            form = self.k * self.x**2 / 2 if self.law == "x**2" else self.k * self.x / 2
            relations.append(Relation(f"energy stored in the spring at its greatest compression "
                                      f"{self.stage.text('compression')}", stored, form,
                                      solutions={stored: form}, general=False,
                                      requires=(Condition(sp.Gt(self.k, 0), "the spring constant must be positive"),)))
        return relations

    def _travel(self, ctx: Context) -> Relation:
        """``x - x0``; in the kernels ``2 max(d, 0) + q**2/(hypot(d, q) + |d|)`` with ``d = a - x0`` and
        ``q = v sqrt(M/k)``: the difference of the two compressions never formed (a light package on a
        heavy platform moves it a hair's breadth below its static deflection)."""
        import sympy as sp

        travel = ctx.quantity(self.stage, "travel", _DEFAULT_NAMES)
        x0 = 0 if self.forgets_static else self.x0
        stable: dict[Any, Any] = {}
        if self.law == "x**2" and not self.forgets_static:
            static = self.mass * self.g / self.k
            d = sp.factor(static - self.x0_value)
            q = self.v * sp.sqrt(self.mass / self.k)
            stable[travel] = (Stable(q if d == 0 else 2 * sp.Max(d, 0) + q**2 / (_hypot(d, q) + sp.Abs(d))),)
        return Relation(f"further compression from the start to the greatest, {self.stage.text('compression')} − "
                        f"x0", travel, self.x - x0, solutions={travel: self.x - x0}, stable=stable, general=False)

    def _static(self, ctx: Context) -> Relation:
        """The platform at rest on the spring: ``k delta = m_s g``."""
        import sympy as sp

        supported = self.stage.fields["supports"]
        weight = ctx.mass(self.stage, supported, "supports") * ctx.gravity_symbol(self.stage)
        delta = ctx.quantity(self.stage, "static_deflection", _DEFAULT_NAMES)
        solutions = {delta: weight / self.k, self.k: weight / delta} if isinstance(self.k, sp.Symbol) else \
            {delta: weight / self.k}
        if self.forgets_static:
            return Relation(f"static deflection of the spring under {supported} (forgotten: the spring taken to start "
                            "at its natural length)", delta, sp.Integer(0), solutions={delta: sp.Integer(0)},
                            general=False)
        return Relation(f"equilibrium of {supported} at rest on the spring: its static deflection", self.k * delta,
                        weight, solutions=solutions, general=False)

    def _energy(self, ctx: Context) -> Relation:
        import sympy as sp

        stage, mass, k, v, x, x0, g = self.stage, self.mass, self.k, self.v, self.x, self.x0, self.g
        if self.forgets_static:
            x0 = 0
        who = _who(stage)
        spring = k * (x**2 - x0**2) / 2 if self.law == "x**2" else k * (x - x0) / 2
        kinetic = mass * v**2 / 2 + mass * g * (x - x0)
        solutions: dict[Any, Any] = {}
        stable: dict[Any, Any] = {}
        static = mass * g / k  # the static deflection of everything the spring stops (0: horizontal)
        if isinstance(x, sp.Symbol):
            if self.law == "x**2":
                solutions[x] = v * sp.sqrt(mass / k) if x0 == 0 and static == 0 else \
                    static + sp.sqrt((x0 - static) ** 2 + mass * v**2 / k)
                # x0 - static with the static deflection written out: (m_s - M) g/k is the weight of what
                # the platform did not carry (the package's), with no difference of two deflections.
                start = 0 if self.forgets_static else self.x0_value
                offset = sp.factor(start - static) if "supports" in stage.fields else x0 - static
                stable[x] = (Stable(v * sp.sqrt(mass / k)) if offset == 0 and static == 0 else
                             Stable(static + _hypot(offset, v * sp.sqrt(mass / k))),)
            else:
                solutions[x] = x0 + mass * v**2 / (k - 2 * mass * g)
        if isinstance(v, sp.Symbol):
            rest = (x - x0) * (x + x0 - 2 * static) if self.law == "x**2" else (x - x0) * (1 - 2 * static)
            solutions[v] = sp.sqrt(k * rest / mass)
        if isinstance(k, sp.Symbol):
            stretch = (x - x0) * (x + x0) if self.law == "x**2" else x - x0
            solutions[k] = mass * (v**2 + 2 * g * (x - x0)) / stretch
        gravity_words = " and its weight's work" if g != 0 else ""
        spring_words = "½k(x² − x0²)" if self.law == "x**2" else "½k(x − x0)"
        return Relation(
            f"work-energy from contact to the greatest compression {stage.text('compression')}: {who}'s kinetic "
            f"energy{gravity_words} stored in the spring, {spring_words}", kinetic, spring,
            solutions=solutions, stable=stable, general=False,
            requires=(
                Condition(sp.Gt(k, 0), f"the spring constant {stage.text('stiffness')} must be positive"),
                Condition(sp.Ge(v, 0), f"{who} must move toward the spring ({stage.text('speed')} >= 0) to compress "
                          "it"),
                Condition(sp.Ge(x - x0, 0), f"the greatest compression {stage.text('compression')} cannot be below "
                          "the compression at the start"),
            ))


def _hypot(a: Any, b: Any) -> Any:
    from grader.physics.symbolic import hypot

    return hypot(a, b)


def _who(stage: Stage) -> str:
    together = stage.fields.get("with")
    return f"{stage.fields['body']} (with {together} stuck to it)" if together else str(stage.fields["body"])


def _spring(stage: Stage, ctx: Context) -> list[Relation]:
    return _Spring.of(stage, ctx).relations(ctx)


def _mistakes(stage: Stage, ctx: Context) -> list[Mistake]:
    real = _Spring.of(stage, ctx)
    mistakes = [Mistake("spring.half_k_x", "½kx instead of ½kx² for the energy stored in the spring",
                        tuple(replace(real, law="x").relations(ctx)))]
    if "with" in stage.fields:
        alone = ctx.mass(stage, stage.fields["body"], "body")
        mistakes.append(Mistake("spring.mass_before_stuck", f"the mass of {stage.fields['body']} alone, as before "
                                f"{stage.fields['with']} stuck to it", tuple(replace(real, mass=alone).relations(ctx))))
    if "supports" in stage.fields:
        mistakes.append(Mistake("spring.static_deflection_forgotten", "the static deflection forgotten: the spring "
                                "taken to start at its natural length",
                                tuple(replace(real, forgets_static=True).relations(ctx))))
    return mistakes


def hooke(k_per_m: float, g: float) -> Any:
    """The force law per unit mass on a state ``[compression, rate]``: the spring pushes back, the weight
    (``g``, 0 for a horizontal spring) pushes on."""
    def rhs(_: float, y: Any) -> Any:
        return np.array([y[1], g - k_per_m * y[0]])
    return rhs


@dataclass(frozen=True)
class _Numbers:
    """A spring stage's values in SI for the simulation."""

    mass: float
    k: float
    g: float
    x0: float


def _numbers(stage: Stage, run: Run) -> _Numbers:
    fields = stage.fields
    mass = sum(_body_mass(run, fields[key]) for key in ("body", "with") if key in fields)
    k = run.value(fields["stiffness"])
    g = run.gravity() if fields.get("vertical", False) else 0.0
    x0 = run.value(fields["initial"]) if "initial" in fields else 0.0
    if "supports" in fields:
        x0 = _body_mass(run, fields["supports"]) * run.gravity() / k
        if "static_deflection" in fields:
            run.output(Sym(fields["static_deflection"]), x0)
    return _Numbers(mass, k, g, x0)


def _body_mass(run: Run, body: str) -> float:
    mass = run.scene.bodies[body].mass
    if mass is None:  # the relations refuse a fixed body on a spring before any simulation
        raise TemplateError(run.scene.where, "stages", "a movable body on the spring", f"{body}, which is fixed")
    return run.value(mass)


def _simulate_spring(stage: Stage, run: Run) -> None:
    from grader.physics.integrate import Mode  # the simulator's part: loading a template needs none of it

    fields = stage.fields
    if not run.known(fields["speed"]) and run.known(fields["compression"]):
        _release(stage, run)
        return
    speed = run.value(fields["speed"])
    numbers = _numbers(stage, run)
    run.uses("spring (Hooke's law)")
    if numbers.g:
        run.uses("gravity")
    omega = math.sqrt(numbers.k / numbers.mass)
    static = numbers.g / omega**2
    if speed < 0 or numbers.k <= 0:
        run.problems.append(f"{_who(stage)} moves away from the spring ({speed:g} m/s)" if speed < 0 else
                            f"the spring constant {numbers.k:g} N/m is not positive")
        run.output(fields["compression"], numbers.x0)
        return
    if speed == 0 and numbers.x0 >= static:  # at rest where the spring holds it, or pushed back at once
        run.output(fields["compression"], numbers.x0)
        _output_energy(stage, run, numbers, numbers.x0)
        return
    reach = static + math.hypot(numbers.x0 - static, speed / omega)  # only sizes the tolerances and steps
    sizes = np.array([reach, reach * omega])
    stops = Mode("spring", hooke(omega**2, numbers.g), lambda y: y[1], -1, scale=1 / omega, omega=omega,
                 force=lambda y: numbers.k * y[0], sizes=lambda y: sizes)
    path = run.integrate([stops], np.array([numbers.x0, speed]))
    run.record(f"{_who(stage)} compresses the spring", ("compression", "rate"), path)
    greatest = float(path.y[-1][0])
    run.output(fields["compression"], greatest)
    _output_energy(stage, run, numbers, greatest)


def _release(stage: Stage, run: Run) -> None:
    """Released at rest at the greatest compression, the spring pushes the bodies back to ``x0``: their
    speed there."""
    from grader.physics.integrate import Mode

    fields = stage.fields
    numbers = _numbers(stage, run)
    greatest = run.value(fields["compression"])
    run.uses("spring (Hooke's law)")
    if numbers.g:
        run.uses("gravity")
    omega = math.sqrt(numbers.k / numbers.mass)
    if greatest <= numbers.x0:
        if greatest < numbers.x0:
            run.problems.append(f"the greatest compression {greatest:g} m is below the compression at the start "
                                f"{numbers.x0:g} m")
        run.output(fields["speed"], 0.0)
        _output_energy(stage, run, numbers, greatest)
        return
    if greatest + numbers.x0 < 2 * numbers.g / omega**2:
        # Its weight carries it down again before the spring has pushed it back to x0 (the oscillation
        # about the static deflection g/omega**2 turns short of x0).
        run.problems.append(f"released at {greatest:g} m, the spring does not push {_who(stage)} back to "
                            f"{numbers.x0:g} m: its weight carries it down again first")
        run.output(fields["speed"], 0.0)
        return
    sizes = np.array([greatest, greatest * omega])
    back = Mode("spring released", hooke(omega**2, numbers.g), lambda y: y[0] - numbers.x0, -1, scale=1 / omega,
                omega=omega, force=lambda y: numbers.k * y[0], sizes=lambda y: sizes)
    path = run.integrate([back], np.array([greatest, 0.0]))
    run.record(f"the spring pushes {_who(stage)} back", ("compression", "rate"), path)
    run.output(fields["speed"], -float(path.y[-1][1]))
    _output_energy(stage, run, numbers, greatest)


def _output_energy(stage: Stage, run: Run, numbers: _Numbers, greatest: float) -> None:
    k = numbers.k
    if "travel" in stage.fields:
        run.output(Sym(stage.fields["travel"]), greatest - numbers.x0)
    if "energy" in stage.fields:
        run.output(Sym(stage.fields["energy"]), k * greatest * greatest / 2)


SPRING = Effect(
    "spring",
    "a linear spring stops a body (or two stuck together): 1/2 M v^2 (+ M g (x - x0)) = 1/2 k (x^2 - x0^2)",
    _FIELDS,
    _spring,
    _simulate_spring,
    _mistakes,
    force_law="Hooke's law, -k x on the bodies (and their weight where the spring is vertical), from the start until "
              "the located event where they stop (x' = 0); with the speed unknown, released at rest at the greatest "
              "compression until the compression is x0 again",
)
