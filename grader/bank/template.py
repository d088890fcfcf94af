"""The problem bank: YAML templates parsed into frozen, validated :class:`Template` objects.

>>> bank = load_bank()
>>> sorted(bank)[:3]
['ball-plate', 'ballistic-pendulum', 'billiards']
>>> bank["drop-rebound"].parameters["h_drop"].unit.text
'mm'
"""

from __future__ import annotations

import hashlib
import math
import re
from collections.abc import Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from grader.bank.figure_field import SCENE_FIGURE, FigureSpec, parse_figure
from grader.bank.folders import NAME, TEMPLATE_ID, TOPICS, bank_folders, one_line, template_files, template_paths
from grader.bank.scene_parser import parse_scene
from grader.base.errors import ExpressionError, GraderError, TemplateError, UsageError, close_matches, shown
from grader.base.inputs import YAML_BYTES, parse_yaml, read_bytes
from grader.base.resources import bank_dir
from grader.model.expr import Node, Num, Op, Sym, names, parse, to_text
from grader.model.quantities import (
    ACCELERATION,
    LENGTH,
    MASS,
    NUMBER,
    Dimension,
    Unit,
    dimension_of,
    parse_unit,
    words,
)
from grader.model.scene import Gravity, Scene
from grader.model.tolerance import Tolerance, ToleranceError
from grader.physics.effects import CATALOGUE

RESERVED = {"g", "pi"}
_BOUND = r"(-?inf|[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)"
_INTERVAL = re.compile(rf"^\s*([\[(])\s*{_BOUND}\s*,\s*{_BOUND}\s*([\])])\s*$")
_TOP_KEYS = {"id", "title", "topic", "version", "gravity", "bodies", "stages", "symbols", "parameters",
             "constraints", "answers", "tolerance", "statement", "example", "figure"}

@dataclass(frozen=True)
class Interval:
    """A parameter's valid domain, e.g. ``[0, 1]`` or ``(0, inf)``.

    >>> Interval.parse("[0, 90)", "x", "k").contains(90.0)
    False
    """

    low: float
    high: float
    low_open: bool
    high_open: bool

    @classmethod
    def parse(cls, text: Any, where: str, key: str) -> Interval:
        """Read ``[a, b]``, ``(a, b)``, ``[a, inf)`` and mixed forms."""
        match = _INTERVAL.match(str(text))
        if not match:
            raise TemplateError(where, key, "an interval like '[0, 1]' or '(0, inf)'", shown(text))
        low, high = float(match.group(2)), float(match.group(3))
        if not all(math.isfinite(float(bound)) or "inf" in bound for bound in match.group(2, 3)):
            raise TemplateError(where, key, "bounds within float64 (about ±1.8e308) or inf", shown(text))
        if not low < high:
            raise TemplateError(where, key, "an interval with low < high", shown(text))
        return cls(low, high, match.group(1) == "(", match.group(4) == ")")

    def contains(self, value: Any) -> Any:
        """Whether ``value`` (a number or numpy array) lies in the interval."""
        above = value > self.low if self.low_open else value >= self.low
        below = value < self.high if self.high_open else value <= self.high
        return above & below

    def __str__(self) -> str:
        def show(x: float) -> str:
            return "inf" if x == float("inf") else "-inf" if x == float("-inf") else f"{x:g}"
        return f"{'(' if self.low_open else '['}{show(self.low)}, {show(self.high)}{')' if self.high_open else ']'}"


@dataclass(frozen=True)
class Sampling:
    """How a variant draws a parameter: ``uniform``, ``log_uniform`` over a range, ``integers`` (each
    whole number of a range, ends included, equally likely) or ``choice``."""

    kind: str
    values: tuple[float, ...]


@dataclass(frozen=True)
class Parameter:
    """A given quantity: unit, domain, sampling, the precision it is printed with."""

    name: str
    unit: Unit
    domain: Interval
    sample: Sampling
    decimals: int | None
    sig_figs: int | None
    description: str
    integer: bool = False  # a count (of bounces, ...): sampled, printed and accepted as a whole number only

    def admits(self, value: Any) -> Any:
        """Whether ``value`` (a number or numpy array) may be this parameter's: in its domain, and a
        whole number for an integer parameter.

        >>> n = load_bank()["successive-bounces"].parameters["n"]
        >>> bool(n.admits(3.0)), bool(n.admits(2.5)), bool(n.admits(0.0))
        (True, False, False)
        """
        inside = self.domain.contains(value)
        return inside & (value % 1 == 0) if self.integer else inside

    def not_whole(self, shown: str) -> str:
        """Why a value printed as ``shown`` is refused for an integer parameter."""
        return f"{self.name} = {shown} is not a whole number; {self.name} is an integer parameter ({self.description})"

    def refusal(self, value: float) -> str | None:
        """Why ``value`` cannot be this parameter's (what was expected), or None when it can.

        >>> load_bank()["successive-bounces"].parameters["n"].refusal(2.5)
        'a whole number (n is an integer parameter: number of bounces counted)'
        """
        if not self.domain.contains(value):
            whole = "a whole number " if self.integer else "a value "
            return f"{whole}in the parameter's domain {self.domain}"
        if self.integer and value % 1 != 0:
            return f"a whole number ({self.name} is an integer parameter: {self.description})"
        return None


@dataclass(frozen=True)
class SymbolSpec:
    """A name that stays symbolic: it has no value (a mass that cancels, the speed ``v``)."""

    name: str
    unit: Unit
    description: str


@dataclass(frozen=True)
class AnswerSpec:
    """An asked quantity: an expression of scene quantities, its unit, and whether it is symbolic."""

    name: str
    value: Node
    unit: Unit
    description: str
    tolerance: Tolerance
    symbolic: tuple[str, ...]


@dataclass(frozen=True)
class Constraint:
    """A condition on the parameters, with the reason it must hold."""

    holds: Node
    text: str
    message: str


@dataclass(frozen=True)
class Template:
    """A loaded, validated problem template."""

    id: str
    title: str
    topic: str
    version: int
    where: str
    source_hash: str
    scene: Scene
    parameters: Mapping[str, Parameter]
    symbols: Mapping[str, SymbolSpec]
    constraints: tuple[Constraint, ...]
    answers: Mapping[str, AnswerSpec]
    statement: str
    example: Mapping[str, float]
    figure: FigureSpec = SCENE_FIGURE  # what the sheets draw: the scene's panels unless the template says


def load_bank(directory: Path | None = None) -> dict[str, Template]:
    """Load every ``*.yaml`` template of a folder (the shipped bank by default), keyed by id."""
    templates: dict[str, Template] = {}
    for path in template_files(directory or bank_dir()):
        template = load_template(path)
        if template.id in templates:
            raise TemplateError(str(path), "id", "an id no other template uses", shown(template.id))
        templates[template.id] = template
    return templates


def load_banks(folders: Sequence[Path] = (), shipped: bool = True) -> dict[str, Template]:
    """The shipped bank (unless ``shipped`` is false) and the templates of each folder, keyed by id.

    A folder given twice (or the shipped bank named again) counts once. Two templates with one id
    are refused, naming both files: an instructor's own templates sit beside the shipped ones, and a
    template must not replace another silently.

    >>> load_banks([bank_dir()]).keys() == load_bank().keys()
    True
    """
    templates: dict[str, Template] = {}
    for folder in bank_folders(folders, shipped):
        for template_id, template in load_bank(folder).items():
            if template_id in templates:
                raise GraderError(same_id(templates[template_id], template))
            templates[template_id] = template
    return templates


def same_id(first: Template, second: Template) -> str:
    """Why two templates cannot be in one bank."""
    return (f"two templates have the id '{first.id}': {first.where} and {second.where}; rename one (its id and "
            "its file name), or leave out its folder (--no-shipped-bank leaves out the shipped bank)")


def load_one(template_id: str, directory: Path | None = None) -> Template | None:
    """The template ``template_id`` of a bank folder, read from its own file alone (a template's id
    is its file's name), or None when the folder has no such file: then :func:`load_bank` tells why.

    >>> load_one("drop-rebound").title, load_one("../drop-rebound"), load_one("nothing-like-it")
    ('Ball dropped onto a rigid floor', None, None)
    """
    path = (directory or bank_dir()) / f"{template_id}.yaml"
    if not TEMPLATE_ID.match(template_id) or not path.is_file():
        return None
    return load_template(path)


def load_named(template_id: str, folders: Sequence[Path] = (), shipped: bool = True) -> Template | None:
    """The template ``template_id`` of the banks :func:`load_banks` reads, from its own file alone, or
    None when no folder has it (then :func:`load_banks` tells why); in two folders, refused as there."""
    found = [template for folder in bank_folders(folders, shipped)
             if (template := load_one(template_id, folder)) is not None]
    if len(found) > 1:
        raise GraderError(same_id(found[0], found[1]))
    return found[0] if found else None


def find_template(template_id: str, folders: Sequence[Path] = (), shipped: bool = True) -> Template:
    """The template ``template_id`` of the banks, read from its own file (:func:`load_named`); else the banks
    are read whole, so that an unusable folder is refused as such, and a template they lack is refused with the
    ids it may be a misspelling of (or, when none is close, every id)."""
    template = load_named(template_id, folders, shipped)
    if template is not None:
        return template
    bank = load_banks(folders, shipped)
    if template_id not in bank:
        close = close_matches(template_id, bank)
        hint = f"; did you mean {' or '.join(close)}?" if close else f"; the bank has {', '.join(sorted(bank))}"
        raise UsageError(f"unknown template '{template_id}'{hint}")
    return bank[template_id]


class Banks(Mapping[str, "Template"]):
    """The banks :func:`load_banks` reads, as a mapping that reads a template from its own file when it is
    asked for (:func:`load_named`): grading needs the few templates a key names, not the whole bank."""

    def __init__(self, folders: Sequence[Path] = (), shipped: bool = True) -> None:
        self.folders, self.shipped = list(folders), shipped

    def __getitem__(self, template_id: str) -> Template:
        template = load_named(template_id, self.folders, self.shipped)
        if template is None:
            raise KeyError(template_id)
        return template

    def __iter__(self) -> Iterator[str]:
        return iter(sorted({path.stem for path in template_paths(self.folders, self.shipped)}))

    def __len__(self) -> int:
        return sum(1 for _ in self)


def load_template(path: Path) -> Template:
    """Read, parse and validate one template file."""
    where = str(path)
    data = read_bytes(path, YAML_BYTES)
    raw = parse_yaml(data, path)
    if not isinstance(raw, Mapping):
        raise TemplateError(where, "(file)", "a mapping of template keys", type(raw).__name__)
    return parse_template(raw, where, hashlib.sha256(data).hexdigest(), path.stem)


def parse_template(raw: Mapping[str, Any], where: str, source_hash: str, stem: str | None = None) -> Template:
    """Validate a template's YAML mapping and freeze it."""
    unknown = set(raw) - _TOP_KEYS
    if unknown:
        raise TemplateError(where, ", ".join(sorted(map(str, unknown))),
                            f"only the keys {', '.join(sorted(_TOP_KEYS))}", "unknown key(s)")
    template_id = _text(raw, "id", where)
    if not TEMPLATE_ID.match(template_id):
        raise TemplateError(where, "id", "lower-case letters, digits and -", shown(template_id))
    if stem is not None and stem != template_id:
        raise TemplateError(where, "id", f"the file name's stem '{stem}'", shown(template_id))
    version = raw.get("version")
    if not isinstance(version, int) or isinstance(version, bool) or version < 1:
        raise TemplateError(where, "version", "a whole number >= 1", shown(version))
    gravity = _gravity(raw.get("gravity"), where)
    parameters = {name: _parameter(name, spec, where) for name, spec in _mapping(raw, "parameters", where).items()}
    symbols_raw = raw.get("symbols") or {}
    if not isinstance(symbols_raw, Mapping):
        raise TemplateError(where, "symbols", "a mapping of names to {unit: ..., description: ...}", shown(symbols_raw))
    symbols = {name: _symbol(name, spec, where) for name, spec in symbols_raw.items()}
    for name in list(parameters) + list(symbols):
        if not NAME.match(name) or name in RESERVED:
            raise TemplateError(where, name, "a name of letters, digits and _, not g or pi", shown(name))
    both = set(parameters) & set(symbols)
    if both:
        raise TemplateError(where, "symbols", "names not also parameters", ", ".join(sorted(both)))
    scene = parse_scene(raw, where, gravity)
    default = tolerance_in(raw.get("tolerance", {}), where, "tolerance")
    answers_raw = _mapping(raw, "answers", where)
    for name in answers_raw:
        if not NAME.match(name):
            raise TemplateError(where, "answers", "names of letters, digits and _", shown(name))
    answers = {name: _answer(name, spec, where, default) for name, spec in answers_raw.items()}
    template = Template(
        id=template_id, title=_title(raw, where), topic=_topic(raw.get("topic"), scene, where),
        version=version, where=where,
        source_hash=source_hash, scene=scene, parameters=parameters, symbols=symbols,
        constraints=tuple(_constraint(i, c, where) for i, c in enumerate(_list(raw, "constraints", where))),
        answers=answers, statement=_text(raw, "statement", where),
        example=_example(raw.get("example") or {}, parameters, where),
        figure=parse_figure(raw.get("figure"), where, len(scene.stages), parameters),
    )
    _check_names(template)
    return template


def _check_names(template: Template) -> None:
    where = template.where
    given = set(template.parameters) | set(template.symbols)
    quantities = template.scene.names() | given
    for body in template.scene.bodies.values():
        for key, part in (("mass", body.mass), ("radius", body.radius)):
            missing = names(part) - given if part is not None else set()
            if missing:
                raise TemplateError(where, f"bodies.{body.name}.{key}", "parameters or symbols only",
                                    unknown_names(missing, given))
    for answer in template.answers.values():
        missing = names(answer.value) - quantities
        if missing:
            raise TemplateError(where, f"answers.{answer.name}.value", "names of the scene's quantities",
                                unknown_names(missing, quantities))
        missing = set(answer.symbolic) - given
        if missing:
            raise TemplateError(where, f"answers.{answer.name}.symbolic", "parameters or symbols",
                                unknown_names(missing, given))
    _check_misspelt_quantities(template, given)
    for index, constraint in enumerate(template.constraints):
        missing = names(constraint.holds) - set(template.parameters)
        if missing:
            raise TemplateError(where, f"constraints[{index}].require", "an expression in the parameters",
                                unknown_names(missing, template.parameters))
    _check_statement(template, given)
    _check_dimensions(template)


def unknown_names(missing: Iterable[str], known: Iterable[str]) -> str:
    """``unknown name e_ (did you mean e?)``: names a template uses and does not define, each with the defined names it
    may be a misspelling of.

    >>> unknown_names(["e_", "zz"], ["e", "h_drop"])
    'unknown names e_ (did you mean e?), zz'
    """
    shown_names = []
    for name in sorted(missing):
        close = misspelt_as(name, known)
        shown_names.append(f"{name} (did you mean {' or '.join(close)}?)" if close else name)
    return f"unknown name{'s' if len(shown_names) > 1 else ''} " + ", ".join(shown_names)


def misspelt_as(name: str, known: Iterable[str]) -> list[str]:
    """The names of ``known`` that ``name`` may be a misspelling of: one letter added, dropped, changed or two
    swapped (two edits in a name of 8 letters or more, and fewer edits than letters), or another letter case;
    closest first, at most three.
    Tighter than :func:`close_matches`: ``E_lost`` is not ``f_loss``.

    >>> misspelt_as("e_", ["e", "h"]), misspelt_as("E_lost", ["f_loss", "E_loss"]), misspelt_as("V", ["v", "m"])
    (['e'], ['E_loss'], ['v'])
    """
    most = 2 if len(name) >= 8 else 1
    found = sorted((distance, other) for other in known  # a letter for a letter is no misspelling: E is not m
                   if (distance := _edits(name.lower(), other.lower(), most)) <= most
                   and distance < max(len(name), len(other)))
    return [other for _, other in found[:3]]


def _edits(first: str, second: str, most: int) -> int:
    """The edits (a letter added, dropped, changed; two neighbours swapped) from one name to another, or
    ``most + 1`` when there are more than ``most``."""
    if abs(len(first) - len(second)) > most:
        return most + 1
    before, row = None, list(range(len(second) + 1))
    for i, a in enumerate(first, 1):
        current = [i] + [0] * len(second)
        for j, b in enumerate(second, 1):
            current[j] = min(row[j] + 1, current[j - 1] + 1, row[j - 1] + (a != b))
            if before is not None and i > 1 and j > 1 and a == second[j - 2] and first[i - 2] == b:
                current[j] = min(current[j], before[j - 2] + 1)
        before, row = row, current
    return min(row[-1], most + 1)


def _check_misspelt_quantities(template: Template, given: set[str]) -> None:
    """A name a stage uses that is not given is a quantity the solver finds; one that only that stage uses (no
    other stage, no answer) and that looks like a parameter or symbol no stage uses is that name misspelt
    (``restitution: e_`` for the parameter ``e``), said so here rather than as an answer nothing fixes."""
    asked = {n for answer in template.answers.values() for n in names(answer.value)}
    unused = sorted(given - template.scene.names())
    for stage in template.scene.stages:
        elsewhere = asked.union(*(other.quantities for other in template.scene.stages if other is not stage))
        for name in sorted(stage.quantities - given - RESERVED - elsewhere):
            close = misspelt_as(name, unused)
            if close:
                field = next((key for key, text in stage.source.items() if re.search(rf"\b{name}\b", text)), "")
                kinds = [f"the {'parameter' if other in template.parameters else 'symbol'} {other}" for other in close]
                raise TemplateError(template.where, f"stages[{stage.index}].{field}".rstrip("."),
                                    "names of parameters, symbols or quantities the solver finds",
                                    f"{unknown_names([name], close)}: {' and '.join(kinds)}, which no stage uses")


def _check_dimensions(template: Template) -> None:
    """Each stage field measures what its effect says (a height is a length, a mass a mass), and
    each answer what its unit says; a name a stage introduces takes its field's dimension."""
    known: dict[str, Dimension] = {n: p.unit.dimension for n, p in template.parameters.items()}
    known |= {n: s.unit.dimension for n, s in template.symbols.items()}
    if template.scene.gravity is not None:
        known["g"] = ACCELERATION
    for body in template.scene.bodies.values():
        if body.mass is not None:
            _expect(body.mass, MASS, known, template.where, f"bodies.{body.name}.mass")
        if body.radius is not None:
            _expect(body.radius, LENGTH, known, template.where, f"bodies.{body.name}.radius")
    for stage in template.scene.stages:
        for spec in CATALOGUE[stage.effect].fields:
            value = stage.fields.get(spec.name)
            if spec.dimension is None or value is None:
                continue
            key = f"stages[{stage.index}].{spec.name}"
            if spec.kind in ("velocities", "vector"):
                vectors = {f"{key}.{b}": v for b, v in value.items()} if spec.kind == "velocities" else {key: value}
                for place, velocity in vectors.items():
                    for part in (velocity.n, velocity.t):
                        if part is not None:
                            _expect(part, spec.dimension, known, template.where, place)
            else:
                _expect(Sym(value) if spec.kind == "name" else value, spec.dimension, known, template.where, key)
    for name, answer in template.answers.items():
        _expect(answer.value, answer.unit.dimension, known, template.where, f"answers.{name}.value")


def _expect(node: Node, expected: Dimension, known: dict[str, Dimension], where: str, key: str) -> None:
    if isinstance(node, Num) and node.value == 0:  # zero is zero in any unit: a landing height of 0
        return
    try:
        found = dimension_of(node, known)
    except GraderError as error:
        raise TemplateError(where, key, "an expression whose terms have one dimension",
                            f"'{to_text(node)}', which {error}") from None
    if found is None and isinstance(node, Sym):
        known[node.name] = expected
    elif found is not None and found != expected:
        raise TemplateError(where, key, f"{words(expected)} (check the parameters' units)",
                            f"'{to_text(node)}', which is {words(found)}")


def _check_statement(template: Template, given: set[str]) -> None:
    from grader.bank.markup import plain_fill, typst_refusal

    # A trial fill (parameters and g as "1", symbols as their names, as a sheet shows them) refuses
    # what would be too costly for every student alike, and Typst code assembled from pieces.
    values = {**dict.fromkeys([*template.parameters, "g"], "1"), **{n: n for n in template.symbols}}
    filled = plain_fill(template.statement, values)  # text and {{ name }}: no Jinja2 needed
    if filled is None:
        filled = _jinja_fill(template, given, values)
    refusal = typst_refusal(template.statement) or typst_refusal(filled)
    if refusal is not None:
        raise TemplateError(template.where, "statement", "text and math only", refusal)


def filled_statement(template: Template, printed: Mapping[str, str]) -> str:
    """The statement with a variant's printed values (symbols stay their names, ``g`` as the scene
    gives it): text and ``{{ name }}`` filled in without Jinja2, anything else by the bounded sandbox
    of :mod:`grader.bank.statement`. Typst code in the result is refused."""
    from grader.bank.markup import plain_fill, typst_refusal

    values = {n: n for n in template.symbols}
    if template.scene.gravity is not None:
        values["g"] = template.scene.gravity.text.split()[0]
    values.update(printed)
    filled = plain_fill(template.statement, values)
    if filled is None:
        from grader.bank.statement import StatementRefused, fill_statement

        try:
            filled = fill_statement(template.statement, values)
        except StatementRefused as error:
            raise GraderError(f"{template.where}: statement: expected values filled in, not code, got {error}") \
                from None
    refusal = typst_refusal(filled)
    if refusal is not None:
        raise GraderError(f"{template.where}: statement: expected text and math only, got {refusal}")
    return filled


def _jinja_fill(template: Template, given: set[str], values: dict[str, str]) -> str:
    """A statement that is more than text and ``{{ name }}``, read by Jinja2: refused unless it only
    fills in values (with filters) of the template's names."""
    import jinja2
    import jinja2.meta

    from grader.bank.statement import StatementRefused, check_jinja, fill_statement

    try:
        syntax = check_jinja(template.statement)
    except jinja2.TemplateSyntaxError as error:
        raise TemplateError(template.where, "statement", "a valid Jinja2 snippet", error.message) from None
    except StatementRefused as error:
        raise TemplateError(template.where, "statement", "values filled in, not code", str(error)) from None
    unknown = jinja2.meta.find_undeclared_variables(syntax) - given - {"g"}
    if unknown:
        asked = sorted(unknown & set(template.answers))
        raise TemplateError(template.where, "statement", "only parameters, symbols and g",
                            f"the answer {', '.join(asked)}, which the student finds" if asked
                            else unknown_names(unknown, given | {"g"}))
    try:
        return fill_statement(template.statement, values)
    except StatementRefused as error:
        raise TemplateError(template.where, "statement", "values filled in, not code", str(error)) from None


def _text(raw: Mapping[str, Any], key: str, where: str) -> str:
    value = raw.get(key)
    if not isinstance(value, str) or not value.strip():
        raise TemplateError(where, key, "non-empty text", shown(value))
    return value.strip()


def _title(raw: Mapping[str, Any], where: str) -> str:
    title = _text(raw, "title", where)
    if not one_line(title):  # grader list and show print it to a terminal
        raise TemplateError(where, "title", "one line of text without control characters", shown(title))
    return title


def _list(raw: Mapping[str, Any], key: str, where: str) -> list[Any]:
    value = raw.get(key) or []
    if not isinstance(value, list):
        raise TemplateError(where, key, "a list", shown(value))
    return value


def _mapping(raw: Mapping[str, Any], key: str, where: str) -> Mapping[str, Any]:
    value = raw.get(key)
    if not isinstance(value, Mapping) or not value:
        raise TemplateError(where, key, "a non-empty mapping", shown(value))
    return value


def _unit(text: Any, where: str, key: str) -> Unit:
    try:
        return parse_unit("" if text is None else str(text))
    except GraderError as error:
        raise TemplateError(where, key, "a unit like m, m/s, kg, deg, %", str(error)) from None


def _topic(declared: Any, scene: Scene, where: str) -> str:
    if declared is None:
        return infer_topic(scene)
    if declared not in TOPICS:
        raise TemplateError(where, "topic", f"one of {', '.join(TOPICS)} (or no topic: the scene decides)",
                            shown(declared))
    return str(declared)


def infer_topic(scene: Scene) -> str:
    """The topic of a scene that does not name one (see :data:`TOPICS`).

    >>> infer_topic(load_bank()["pile-driver"].scene), infer_topic(load_bank()["ball-plate"].scene)
    ('drops and rebounds', 'oblique impact')
    """
    effects = {stage.effect for stage in scene.stages}
    if "slide" in effects:
        return "impact and sliding"
    if "flight" in effects:
        return "impact with flight"
    if "velocity" in effects or any(stage.is_oblique for stage in scene.stages):
        return "oblique impact"
    if "swing" in effects:
        return "impact and a swing"
    if effects & {"free_fall", "rise", "bounces"}:
        return "drops and rebounds"
    return "direct impact"


def _gravity(text: Any, where: str) -> Gravity | None:
    if text is None:
        return None
    match = re.match(rf"^\s*({NUMBER.pattern})\s+(\S+)\s*$", str(text))
    unit = _unit(match.group(2), where, "gravity") if match else None
    if not match or unit is None or unit.dimension != ACCELERATION or not 0 < float(match.group(1)) < 1e300:
        raise TemplateError(where, "gravity", "a positive acceleration below 1e300, like '9.81 m/s^2' or "
                            "'32.2 ft/s^2'",
                            shown(text))
    from fractions import Fraction
    return Gravity(Fraction(match.group(1)) * unit.factor, str(text).strip())


def _parameter(name: str, spec: Any, where: str) -> Parameter:
    key = f"parameters.{name}"
    if not isinstance(spec, Mapping):
        raise TemplateError(where, key, "a mapping with unit, domain, sample and decimals or sig_figs", shown(spec))
    allowed = {"unit", "domain", "sample", "decimals", "sig_figs", "description", "integer"}
    if set(spec) - allowed:
        raise TemplateError(where, key, f"only {', '.join(sorted(allowed))}",
                            f"unknown key(s) {', '.join(sorted(set(spec) - allowed))}")
    integer = spec.get("integer", False)
    if not isinstance(integer, bool):
        raise TemplateError(where, f"{key}.integer", "true or false", shown(integer))
    domain = Interval.parse(spec.get("domain"), where, f"{key}.domain")
    sample = _sampling(spec.get("sample"), where, f"{key}.sample", domain, integer)
    decimals, sig_figs = spec.get("decimals"), spec.get("sig_figs")
    if integer:
        # A count prints as a whole number: decimals 0, said or not.
        if sig_figs is not None or decimals not in (None, 0) or isinstance(decimals, bool):
            raise TemplateError(where, key, "no printed precision, or decimals: 0 (an integer parameter prints as a "
                                "whole number)", f"decimals={shown(decimals)}, sig_figs={shown(sig_figs)}")
        decimals = 0
    if (decimals is None) == (sig_figs is None):
        raise TemplateError(where, key, "exactly one of decimals or sig_figs (the printed precision)",
                            f"decimals={shown(decimals)}, sig_figs={shown(sig_figs)}")
    for label, value, least in (("decimals", decimals, 0), ("sig_figs", sig_figs, 1)):
        if value is not None and (not isinstance(value, int) or isinstance(value, bool) or not least <= value <= 15):
            raise TemplateError(where, f"{key}.{label}", f"a whole number from {least} to 15", shown(value))
    return Parameter(name, _unit(spec.get("unit"), where, f"{key}.unit"), domain, sample, decimals, sig_figs,
                     str(spec.get("description", name)), integer)


def _sampling(spec: Any, where: str, key: str, domain: Interval, integer: bool = False) -> Sampling:
    kinds = ("integers", "choice") if integer else ("uniform", "log_uniform", "choice")
    if not isinstance(spec, Mapping) or len(spec) != 1 or next(iter(spec)) not in kinds:
        expected = ("{integers: [a, b]} (each whole number from a to b) or {choice: [n, ...]} for an integer "
                    "parameter" if integer else
                    "one of {uniform: [a, b]}, {log_uniform: [a, b]}, {choice: [x, ...]}, and {integers: [a, b]} "
                    "only with integer: true")
        raise TemplateError(where, key, expected, shown(spec))
    kind, values = next(iter(spec.items()))
    if not isinstance(values, list) or not values or not all(
            isinstance(v, (int, float)) and not isinstance(v, bool) for v in values):
        raise TemplateError(where, f"{key}.{kind}", "a list of numbers", shown(values))
    if integer and not all(float(v).is_integer() for v in values):
        raise TemplateError(where, f"{key}.{kind}", "whole numbers (the parameter is an integer)", shown(values))
    if kind != "choice" and (len(values) != 2 or not values[0] < values[1]):
        raise TemplateError(where, f"{key}.{kind}", "[low, high] with low < high", shown(values))
    if kind == "log_uniform" and values[0] <= 0:
        raise TemplateError(where, f"{key}.{kind}", "a positive range for log_uniform", shown(values))
    outside = [v for v in values if not domain.contains(float(v))]
    if outside:
        raise TemplateError(where, f"{key}.{kind}", f"values inside the domain {domain}",
                            ", ".join(map(str, outside)))
    return Sampling(kind, tuple(float(v) for v in values))


def _symbol(name: str, spec: Any, where: str) -> SymbolSpec:
    if not isinstance(spec, Mapping) or set(spec) - {"unit", "description"}:
        raise TemplateError(where, f"symbols.{name}", "{unit: ..., description: ...}", shown(spec))
    return SymbolSpec(name, _unit(spec.get("unit"), where, f"symbols.{name}.unit"),
                      str(spec.get("description", name)))


def tolerance_in(spec: Any, where: str, key: str, base: Tolerance | None = None) -> Tolerance:
    """A tolerance written in a template or an assignment (fields left out come from ``base``)."""
    try:
        return Tolerance.from_json(spec, base=base)
    except ToleranceError as error:
        raise TemplateError(where, f"{key}.{error.field}" if error.field else key, error.expected,
                            error.got) from None


def _answer(name: str, spec: Any, where: str, default: Tolerance) -> AnswerSpec:
    key = f"answers.{name}"
    allowed = {"value", "unit", "description", "tolerance", "symbolic"}
    if not isinstance(spec, Mapping) or "value" not in spec or set(spec) - allowed:
        raise TemplateError(where, key, f"a mapping with value and only {', '.join(sorted(allowed))}", shown(spec))
    symbolic = spec.get("symbolic") or []
    if not isinstance(symbolic, list) or not all(isinstance(s, str) for s in symbolic):
        raise TemplateError(where, f"{key}.symbolic", "a list of names", shown(symbolic))
    return AnswerSpec(name, _parse(spec["value"], where, f"{key}.value"),
                      _unit(spec.get("unit"), where, f"{key}.unit"), str(spec.get("description", name)),
                      tolerance_in(spec.get("tolerance", {}), where, f"{key}.tolerance", default), tuple(symbolic))


def _constraint(index: int, spec: Any, where: str) -> Constraint:
    key = f"constraints[{index}]"
    if not isinstance(spec, Mapping) or set(spec) != {"require", "message"}:
        raise TemplateError(where, key, "{require: EXPR, message: TEXT}", shown(spec))
    holds = _parse(spec["require"], where, f"{key}.require", compare=True)
    if not _is_condition(holds):
        raise TemplateError(where, f"{key}.require", "a comparison like 'h_rebound <= h_drop', or comparisons "
                            "joined by and/or (a comparison is not a number to compute with)", shown(spec["require"]))
    return Constraint(holds, str(spec["require"]), str(spec["message"]))


def _is_condition(node: Node) -> bool:
    """A comparison of two numeric expressions, or conditions joined by and/or.

    >>> _is_condition(parse("h < 1 and (h > 0 or h < -1)", allow_compare=True))
    True
    >>> _is_condition(parse("-(h > 1) >= -0.5", allow_compare=True)), _is_condition(parse("h", allow_compare=True))
    (False, False)
    """
    if not isinstance(node, Op):
        return False
    if node.op in ("and", "or"):
        return all(_is_condition(arg) for arg in node.args)
    return node.op in ("lt", "le", "gt", "ge") and not any(_holds_condition(arg) for arg in node.args)


def _holds_condition(node: Node) -> bool:
    return isinstance(node, Op) and (node.op in ("lt", "le", "gt", "ge", "and", "or") or
                                     any(_holds_condition(arg) for arg in node.args))


def _parse(text: Any, where: str, key: str, compare: bool = False) -> Node:
    try:
        return parse(str(text), allow_compare=compare)
    except ExpressionError as error:
        raise TemplateError(where, key, "a valid expression", f"{shown(text)} ({error})") from None


def _example(raw: Any, parameters: Mapping[str, Parameter], where: str) -> dict[str, float]:
    if not isinstance(raw, Mapping) or set(raw) - set(parameters):
        raise TemplateError(where, "example", "a mapping of parameter names to values", shown(raw))
    for name, value in raw.items():
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise TemplateError(where, f"example.{name}", "a number", shown(value))
        refusal = parameters[name].refusal(float(value))
        if refusal is not None:
            raise TemplateError(where, f"example.{name}", refusal, shown(value))
    return {k: float(v) for k, v in raw.items()}
