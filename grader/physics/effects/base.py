"""What every effect provides: field schema, relations with solved and stable forms, conditions,
and the mistakes students make with it.

An effect turns one stage of a scene into :class:`Relation` objects. A relation is one
equation as a student would write it (for the worked solution), the forms solved for each
unknown it can give, and, per unknown, numerically stable forms the compiled kernel prefers.
A :class:`Mistake` is the same stage as a student who makes that mistake writes it, so the
solver re-derives what such a student answers. Sympy is imported lazily: loading and validating
a template never needs it.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from grader.model.quantities import Dimension

if TYPE_CHECKING:
    import sympy as sp

    from grader.model.scene import Stage
    from grader.physics.record import Run
    from grader.physics.symbolic import Context


KINDS = {"body": "a body's name", "bodies": "two bodies' names", "spheres": "two names of bodies with a radius",
         "expr": "an expression", "name": "a new quantity's name", "velocities": "per body: an expression, or {n:, t:}",
         "vector": "one {n:, t:}", "choice": "one of the listed words", "flag": "true or false"}
"""What the YAML value of a field of each kind is, in words (the scene parser reads them)."""


@dataclass(frozen=True)
class Field:
    """One key of a stage: its kind says how the YAML value is read.

    kinds: see :data:`KINDS` (``choice:a|b``: one of the listed words).

    ``default`` says what an optional key means when it is left out, as the reference shows it: the
    value taken (``t``, ``false``), the name the solver gives the quantity (``J``), or what the stage
    then lacks.
    """

    name: str
    kind: str
    required: bool = True
    doc: str = ""
    dimension: Dimension | None = None  # what an expression or velocity here must measure
    default: str | None = None

    @property
    def kind_in_words(self) -> str:
        """What the YAML value is, in words.

        >>> Field("from", "choice:t|n").kind_in_words, Field("height", "expr").kind_in_words
        ('one of t, n', 'an expression')
        """
        kind, _, options = self.kind.partition(":")
        return f"one of {', '.join(options.split('|'))}" if options else KINDS[kind]


@dataclass(frozen=True)
class Condition:
    """A condition that must hold for the relation to describe the physics.

    ``message`` is shown when it fails; ``{value}`` in it is replaced by ``subject``'s value.
    """

    holds: Any  # sympy relational
    message: str
    subject: Any = None  # sympy expression, dimensionless


@dataclass(frozen=True)
class Stable:
    """A numerically preferred form of a solution; ``given`` symbols must be parameters,
    not derived, for it to be used (it would otherwise inherit their rounding)."""

    expr: Any
    given: tuple[Any, ...] = ()


@dataclass(frozen=True)
class Relation:
    """One equation of a stage, with what the solver may do with it."""

    label: str
    lhs: Any
    rhs: Any
    solutions: Mapping[Any, Any] = field(default_factory=dict)
    stable: Mapping[Any, tuple[Stable, ...]] = field(default_factory=dict)
    general: bool = True
    requires: tuple[Condition, ...] = ()
    undefined: Mapping[Any, tuple[Any, str]] = field(default_factory=dict)
    branches: Mapping[Any, Any] = field(default_factory=dict)
    """Solutions known only up to sign (a component from a speed and the other component): per
    unknown, its magnitude. Only chains that carry a student's answer forward use them, with the
    sign the quantity has in the scene's own solution."""

    def symbols(self) -> set[sp.Symbol]:
        """Every quantity the equation involves."""
        import sympy as sp

        return {s for s in (sp.sympify(self.lhs) - sp.sympify(self.rhs)).free_symbols}


@dataclass(frozen=True)
class Mistake:
    """A typical mistake with an effect, as the solver re-derives it.

    Either the stage's relations as a student who makes it writes them (``relations``: all of the
    stage's relations, one or more of them changed), or, for an answer printed in ``unit``, the right
    value read in another unit: the student gives ``scale`` times it (radians for degrees: pi/180).
    ``says`` completes "your answer matches ...".
    """

    id: str
    says: str
    relations: tuple[Relation, ...] = ()
    unit: str | None = None
    scale: Any = None


@dataclass(frozen=True)
class Route:
    """Another correct way through a stage, as the textbook also solves it: the stage's relations as
    a student who takes it writes them (all of them, one or more changed). Every value such a student
    writes down is rounded as the sheet asks, so the rounding allowance covers this route too.
    ``says`` completes "along ...": ``the energy route (T − T′)``."""

    id: str
    says: str
    relations: tuple[Relation, ...]


@dataclass(frozen=True)
class Effect:
    """An entry of the catalogue: its name, what it means, its fields, its relations (the
    closed form), how to simulate it (its force law in the time domain; None: it has none),
    the mistakes students make with it, first the most telling (None: none declared), and the
    other correct routes through it (None: none). ``force_law`` says in words what ``simulate``
    integrates (for ``grader effects`` and docs/effects.md); every effect states it."""

    name: str
    summary: str
    fields: tuple[Field, ...]
    relations: Callable[[Stage, Context], list[Relation]]
    simulate: Callable[[Stage, Run], None] | None = None
    mistakes: Callable[[Stage, Context], list[Mistake]] | None = None
    routes: Callable[[Stage, Context], list[Route]] | None = None
    force_law: str = field(kw_only=True)

    def __post_init__(self) -> None:
        if not self.force_law.strip():
            raise ValueError(f"effect {self.name}: force_law must say what its simulation integrates")
        for spec in self.fields:
            if spec.required and spec.default is not None:
                raise ValueError(f"effect {self.name}: field {spec.name} is required, so it has no default")


@dataclass(frozen=True)
class TwoBodyStage:
    """A stage of two bodies with a mass each (a separation's parts, two bodies that stick), as its effect's
    relations read it: the stage, the two bodies' names and their inverse masses ``1/m`` (sympy). An effect's
    own stage class adds its quantities; a mistake is the same stage with one of them changed."""

    stage: Stage
    bodies: tuple[str, str]
    inverse: tuple[Any, Any]

    @staticmethod
    def pair(stage: Stage, ctx: Context) -> tuple[tuple[str, str], tuple[Any, Any]]:
        """The stage's ``bodies`` and their inverse masses; a body without a mass (a fixed surface) is refused."""
        first, second = stage.fields["bodies"]
        for body in (first, second):
            ctx.mass(stage, body, "bodies")
        return (first, second), (ctx.inverse_mass(first), ctx.inverse_mass(second))
