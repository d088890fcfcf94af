"""The effects reference: each effect of the catalogue with its faces side by side (fields, relations,
stable forms, force law, mistakes, other routes, figure), for ``grader effects`` and ``docs/effects.md``.

Relations, stable forms, mistakes and routes are not written here: they are what the effect's own code
gives for a few representative stages (:data:`EXAMPLES`), whose fields are conventional symbols. Each
example is read by the scene parser a template goes through, so it is a stage a template could hold.
Sympy is imported by :func:`sheet` only (listing the catalogue needs none).

>>> EXAMPLES.keys() == CATALOGUE.keys()
True
>>> print(stage_yaml(EXAMPLES["swing"][0]))
effect: swing
body: A
speed: v
length: L
angle: theta
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from fractions import Fraction
from typing import Any

from grader.physics.effects import CATALOGUE, Effect

GENERATED_BY = "grader effects --markdown > docs/effects.md"
"""The command that writes ``docs/effects.md`` (its first line says so)."""


@dataclass(frozen=True)
class Example:
    """A representative stage of an effect: what it ``shows``, its bodies and fields as a template's YAML
    writes them, the scene's gravity, and parameters' units where a mistake depends on one (a height in mm)."""

    shows: str
    bodies: Mapping[str, Mapping[str, Any]]
    stage: Mapping[str, Any]
    gravity: str = "9.81 m/s^2"
    units: Mapping[str, str] = field(default_factory=dict)


_ONE: Mapping[str, Mapping[str, Any]] = {"A": {"mass": "m"}}
_TWO: Mapping[str, Mapping[str, Any]] = {"A": {"mass": "m_A"}, "B": {"mass": "m_B"}}
_ON_A_FLOOR: Mapping[str, Mapping[str, Any]] = {"A": {"mass": "m"}, "floor": {"fixed": True}}

EXAMPLES: Mapping[str, tuple[Example, ...]] = {
    "free_fall": (
        Example("a body falls from rest through h", _ONE, {"body": "A", "height": "h", "speed": "v"}),
        Example("a problem in feet, the height printed in mm", _ONE, {"body": "A", "height": "h", "speed": "v"},
                gravity="32.2 ft/s^2", units={"h": "mm"}),
    ),
    "rise": (
        Example("a body moving up at v rises through h", _ONE, {"body": "A", "height": "h", "speed": "v"}),
        Example("a problem in feet, the height printed in mm", _ONE, {"body": "A", "height": "h", "speed": "v"},
                gravity="32.2 ft/s^2", units={"h": "mm"}),
    ),
    "impact": (
        Example("a direct impact of two bodies", _TWO,
                {"bodies": ["A", "B"], "restitution": "e", "before": {"A": "u_A", "B": "u_B"},
                 "after": {"A": "v_A", "B": "v_B"}}),
        Example("an oblique impact of a body on a fixed surface", _ON_A_FLOOR,
                {"bodies": ["A", "floor"], "restitution": "e", "before": {"A": {"n": "u_n", "t": "u_t"}},
                 "after": {"A": {"n": "v_n", "t": "v_t"}}}),
        Example("a perfectly plastic impact: the bodies move on together", _TWO,
                {"bodies": ["A", "B"], "restitution": "0", "before": {"A": "u_A", "B": "u_B"},
                 "after": {"A": "v", "B": "v"}}),
    ),
    "velocity": (
        Example("a velocity by speed and angle, and by components", _ONE,
                {"speed": "v", "angle": "theta", "n": "v_n", "t": "v_t"}),
    ),
    "angle_between": (
        Example("the angle between two velocities", _ONE,
                {"first": {"n": "a_n", "t": "a_t"}, "second": {"n": "b_n", "t": "b_t"}, "angle": "phi"}),
    ),
    "impact_geometry": (
        Example("two spheres, the second's centre b off the first's path",
                {"A": {"mass": "m_A", "radius": "r_A"}, "B": {"mass": "m_B", "radius": "r_B"}},
                {"bodies": ["A", "B"], "offset": "b", "angle": "theta"}),
    ),
    "bounces": (
        Example("a body dropped from h_0 onto a floor, bouncing until it rests", _ON_A_FLOOR,
                {"bodies": ["A", "floor"], "height": "h_0", "restitution": "e", "count": "n", "rebound": "h_n",
                 "distance": "d", "time": "t_rest"}),
    ),
    "swing": (
        Example("a body on a cord swings up from the lowest point", _ONE,
                {"body": "A", "speed": "v", "length": "L", "angle": "theta"}),
    ),
    "slide": (
        Example("a body slides to rest", _ONE, {"body": "A", "speed": "v", "distance": "d", "friction": "mu_k"}),
    ),
    "slope": (
        Example("a body slides down a rough slope to rest", _ONE,
                {"body": "A", "speed": "v", "distance": "d", "angle": "beta", "friction": "mu_k", "static": "mu_s"}),
        Example("a body descends a smooth ramp of height h", _ONE,
                {"body": "A", "speed": "v_0", "end_speed": "v", "height": "h"}),
        Example("a body slides up a rough slope from v_0 to v", _ONE,
                {"body": "A", "speed": "v_0", "end_speed": "v", "distance": "d", "angle": "beta",
                 "direction": "up", "friction": "mu_k"}),
    ),
    "spring": (
        Example("a body stuck to another compresses a horizontal spring", _TWO,
                {"body": "A", "with": "B", "stiffness": "k", "speed": "v", "compression": "x", "energy": "E"}),
        Example("a body dropped on a platform the vertical spring supports", {**_TWO, "P": {"mass": "m_P"}},
                {"body": "P", "with": "A", "stiffness": "k", "speed": "v", "compression": "x", "vertical": True,
                 "supports": "P", "static_deflection": "delta"}),
    ),
    "impulse": (
        Example("a body's impulse and the average force over a contact time", _ONE,
                {"body": "A", "velocity": {"n": "u_n", "t": "u_t"}, "velocity_after": {"n": "v_n", "t": "v_t"},
                 "components": {"n": "J_n", "t": "J_t"}, "impulse": "J", "angle": "phi", "time": "dt",
                 "force": "F"}),
        Example("a falling body stopped by a cushion, the weight included", _ONE,
                {"body": "A", "velocity": {"n": "-v", "t": "0"}, "velocity_after": {"n": "0", "t": "0"}, "impulse": "J",
                 "distance": "d", "force": "F", "weight": True}),
    ),
    "separation": (
        Example("a body at rest splits in two, the energy released given", _TWO,
                {"bodies": ["A", "B"], "after": {"A": "v_A", "B": "v_B"}, "energy": "E"}),
        Example("a recoil: B leaves A at a relative velocity, from a whole moving at V", _TWO,
                {"bodies": ["A", "B"], "whole": {"n": "V", "t": "0"}, "after": {"A": "v_A", "B": "v_B"},
                 "relative": "u"}),
    ),
    "stick": (
        Example("two bodies moving at right angles lock together", _TWO,
                {"bodies": ["A", "B"], "before": {"A": {"n": "0", "t": "u_A"}, "B": {"n": "u_B", "t": "0"}},
                 "common": {"n": "v_n", "t": "v_t"}, "speed": "v", "angle": "theta", "energy_lost": "E_lost",
                 "loss_fraction": "f_loss"}),
    ),
    "flight": (
        Example("a flight to a wall", _ONE,
                {"body": "A", "until": "wall", "horizontal": "v_x", "vertical": "v_y", "height": "y_0",
                 "distance": "D", "end_height": "y_1", "end_vertical": "v_y1"}),
        Example("a flight to the ground", _ONE,
                {"body": "A", "until": "ground", "horizontal": "v_x", "vertical": "v_y", "height": "y_0",
                 "distance": "D", "end_height": "0", "end_vertical": "v_y1"}),
    ),
}
"""Per effect, its representative stages: the first shows the relations as most templates use them; the
others add what only some stages have (a fixed surface, the oblique case, a unit a mistake depends on)."""


@dataclass(frozen=True)
class FieldRow:
    """One field of an effect as the reference shows it."""

    name: str
    meaning: str
    kind: str
    dimension: str | None
    required: bool
    default: str | None


@dataclass(frozen=True)
class Equation:
    """A relation of an example stage: its label and the equation, ``lhs = rhs``."""

    label: str
    equation: str


@dataclass(frozen=True)
class StableForm:
    """A form the kernels prefer for ``unknown``; ``given``: used only when these are parameters."""

    unknown: str
    form: str
    given: tuple[str, ...]


@dataclass(frozen=True)
class ExampleSheet:
    """An example stage with what the effect's code gives for it."""

    shows: str
    stage: str  # the stage as YAML
    relations: tuple[Equation, ...]
    stable: tuple[StableForm, ...]


@dataclass(frozen=True)
class Diagnosis:
    """A mistake the grader diagnoses (or another correct route): its id, its sentence, and the examples
    it applies to when not all of them."""

    id: str
    says: str
    only: tuple[str, ...]


@dataclass(frozen=True)
class Sheet:
    """Everything the reference shows about one effect."""

    name: str
    summary: str
    fields: tuple[FieldRow, ...]
    examples: tuple[ExampleSheet, ...]
    force_law: str
    simulated: bool
    mistakes: tuple[Diagnosis, ...]
    routes: tuple[Diagnosis, ...]
    figure: str

    def to_json(self) -> dict[str, Any]:
        """The sheet as JSON-ready data (strings, booleans, None, lists and objects only)."""
        from dataclasses import asdict

        return asdict(self)


def field_rows(effect: Effect) -> tuple[FieldRow, ...]:
    """An effect's fields as the reference shows them (no sympy).

    >>> [(row.name, row.dimension) for row in field_rows(CATALOGUE["swing"])]
    [('body', None), ('speed', 'a speed'), ('length', 'a length'), ('angle', 'an angle')]
    """
    from grader.model.quantities import words

    return tuple(FieldRow(spec.name, spec.doc, spec.kind_in_words,
                          None if spec.dimension is None else words(spec.dimension), spec.required,
                          spec.default) for spec in effect.fields)


def sheet(name: str) -> Sheet:
    """The reference of the effect ``name`` (a key of the catalogue)."""
    from grader.render.figures import STAGE_FIGURES

    effect = CATALOGUE[name]
    examples = EXAMPLES[name]
    worked = [_worked(effect, example) for example in examples]
    return Sheet(
        name, effect.summary, field_rows(effect), tuple(w.sheet for w in worked), effect.force_law,
        effect.simulate is not None,
        _listed([(example.shows, w.mistakes) for example, w in zip(examples, worked, strict=True)]),
        _listed([(example.shows, w.routes) for example, w in zip(examples, worked, strict=True)]),
        STAGE_FIGURES[name])


def stage_yaml(example: Example, effect: str = "") -> str:
    """An example's stage as a template's YAML writes it (flow style for lists and mappings)."""
    name = effect or next(key for key, examples in EXAMPLES.items() if example in examples)
    return "\n".join(f"{key}: {_flow(value)}" for key, value in {"effect": name, **example.stage}.items())


def _flow(value: Any) -> str:
    if isinstance(value, Mapping):
        return "{" + ", ".join(f"{key}: {_flow(item)}" for key, item in value.items()) + "}"
    if isinstance(value, list):
        return "[" + ", ".join(_flow(item) for item in value) + "]"
    return str(value)


@dataclass(frozen=True)
class _Worked:
    sheet: ExampleSheet
    mistakes: list[tuple[str, str]]
    routes: list[tuple[str, str]]


def _worked(effect: Effect, example: Example) -> _Worked:
    """What the effect's code gives for an example stage, read by the scene parser as a template's is."""
    import sympy as sp

    from grader.bank.scene_parser import parse_scene
    from grader.model.quantities import parse_unit, split_quantity
    from grader.model.scene import Gravity
    from grader.physics.symbolic import Context

    value, unit = split_quantity(example.gravity) or (0.0, "")
    gravity = Gravity(Fraction(str(value)) * parse_unit(unit).factor, example.gravity)
    raw = {"bodies": example.bodies, "stages": [{"effect": effect.name, **example.stage}]}
    scene = parse_scene(raw, f"the effects reference ({effect.name})", gravity)
    stage = scene.stages[0]
    ctx = Context(scene, units={name: parse_unit(unit) for name, unit in example.units.items()})
    names = _names(effect, scene, example.stage)
    # Lengths, masses and pure numbers are never negative here, as a template's parameter domains say
    # (h_0 e^(2n), not h_0 |e|^(2n)).
    ctx.symbols.update({name: sp.Symbol(name, real=True, nonnegative=True) for name, dimension
                        in names.dimensions.items() if tuple(dimension) in _NOT_NEGATIVE})
    relations = effect.relations(stage, ctx)
    # A relation this stage makes an identity (e = separation/approach with e = 0 and the bodies moving on
    # together) holds no unknown: the solver never uses it, and neither does the reference.
    equations = tuple(Equation(r.label, f"{_text(r.lhs, names)} = {_text(r.rhs, names)}") for r in relations
                      if sp.simplify(sp.sympify(r.lhs) - sp.sympify(r.rhs)) != 0)
    stable = tuple(dict.fromkeys(
        StableForm(str(unknown), _text(form.expr, names, reader=False),
                   tuple(sorted(str(s) for given in form.given for s in sp.sympify(given).free_symbols)))
        for r in relations for unknown, forms in r.stable.items() for form in forms))
    mistakes = [(m.id, m.says) for m in (effect.mistakes(stage, ctx) if effect.mistakes else [])]
    routes = [(r.id, r.says) for r in (effect.routes(stage, ctx) if effect.routes else [])]
    return _Worked(ExampleSheet(example.shows, stage_yaml(example, effect.name), equations, stable), mistakes, routes)


_NOT_NEGATIVE = {(1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 0, 0)}  # a length, a mass, a pure number


def _names(effect: Effect, scene: Any, stage: Mapping[str, Any]) -> Any:
    """What :func:`grader.render.readable.readable` knows of an example's names: each field's dimension,
    the masses', the radii's and g's, in the order the stage writes them."""
    from grader.model.expr import Sym, names, parse
    from grader.model.quantities import ACCELERATION, LENGTH, MASS
    from grader.render.readable import Names

    dimensions: dict[str, Any] = {"g": ACCELERATION}
    for body in scene.bodies.values():
        if isinstance(body.mass, Sym):
            dimensions[body.mass.name] = MASS
        if isinstance(body.radius, Sym):
            dimensions[body.radius.name] = LENGTH
    order: list[str] = []
    for spec in effect.fields:
        if spec.name not in stage or spec.kind not in ("expr", "name", "velocities", "vector"):
            continue
        for text in _texts(stage[spec.name]):
            node = parse(text)
            order += sorted(names(node))
            if spec.dimension is not None and isinstance(node, Sym):
                dimensions[node.name] = spec.dimension
    return Names(dimensions, order)


def _texts(value: Any) -> list[str]:
    """The expressions a field's YAML value holds, in order: ``{A: u_A, B: {n: u_n, t: u_t}}`` holds three."""
    if isinstance(value, Mapping):
        return [text for item in value.values() for text in _texts(item)]
    return [str(value)]


def _text(expr: Any, names: Any, reader: bool = True) -> str:
    """A sympy expression as the worked solution writes it (:mod:`grader.render.readable`); ``reader``
    False keeps its composition (a stable form in inverse masses stays one)."""
    from grader.model.expr import to_text
    from grader.physics.symbolic import to_node
    from grader.render.readable import readable
    from grader.solve.solver import for_reader

    return to_text(readable(to_node(for_reader(expr) if reader else expr), names))


def _listed(found: Sequence[tuple[str, Sequence[tuple[str, str]]]]) -> tuple[Diagnosis, ...]:
    """Mistakes (or routes) of all the examples, each once, with the examples it applies to when not all."""
    first: dict[str, str] = {}
    where: dict[str, list[str]] = {}
    for shows, items in found:
        for id_, says in items:
            first.setdefault(id_, says)
            where.setdefault(id_, []).append(shows)
    everywhere = len(found)
    return tuple(Diagnosis(id_, says, () if len(where[id_]) == everywhere else tuple(where[id_]))
                 for id_, says in first.items())
