"""Worked solutions: the solver's step chain with one variant's numbers substituted, as Typst.

Every step of ``compiled_for(template).steps`` is shown as a student would write it: the
relation, its equation, the solved form, then the same with the variant's numbers (in SI) and
the value with its SI unit, which is inferred from the parameters' units. A step that depends on
a symbol without a value (a mass that cancels) is shown as a multiple of it, never with a
made-up number.

Dimensions and their SI units come from :mod:`grader.model.quantities`.
"""

from __future__ import annotations

import math as _m
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from fractions import Fraction
from typing import Any

import numpy as np

from grader.assign.variants import ProblemVariant
from grader.bank.template import Template
from grader.model.expr import Node, Num, Sym, format_number, names, parse
from grader.model.kernel import evaluate
from grader.model.quantities import ACCELERATION, ANGLE, Dimension, dimension_of, si_unit
from grader.model.roots import TOLERANCE_TEXT
from grader.render.readable import Names, readable
from grader.render.typst_math import math, name, number
from grader.render.typst_text import Typ, body_name, string, text
from grader.solve.cache import compiled_for
from grader.solve.compiled import Compiled, Step
from grader.solve.page_forms import page_value, tidy_signs
from grader.solve.textbook_steps import textbook_route


def _significant(printed: str) -> int:
    digits = printed.lstrip("+-").replace(".", "").lstrip("0")
    return max(1, len(digits))


# --- evaluating the chain ------------------------------------------------------------------------

def chain_values(compiled: Compiled, given: Mapping[str, float]) -> dict[str, float]:
    """Every step's value (SI) from the parameters in SI, the constants and ``given`` symbols;
    a step that cannot be evaluated (a symbol without value) is left out."""
    env: dict[str, Any] = {**compiled.constants, **given}
    with np.errstate(all="ignore"):
        for step in compiled.steps:
            try:
                env[step.unknown] = float(evaluate(step.solved, env))
            except KeyError:
                continue
    return {k: float(v) for k, v in env.items()}


def si_parameters(template: Template, variant: ProblemVariant) -> dict[str, float]:
    """The variant's parameters as printed, converted to SI (deg to rad)."""
    return {n: float(variant.printed[n]) * p.unit.to_si for n, p in template.parameters.items()}


@dataclass(frozen=True)
class Scaling:
    """A value that is a multiple of the symbols without value: ``coefficient * prod(s**power)``."""

    coefficient: float
    powers: Mapping[str, Fraction]

    def math(self) -> str:
        """``20.61 m`` or ``0.6912 m v`` in Typst math."""
        shown = [number(self.coefficient)]
        for symbol, power in self.powers.items():
            if power:
                shown.append(name(symbol) + ("" if power == 1 else f"^({format_number(power)})"))
        return " ".join(shown)


def scalings(compiled: Compiled, si: Mapping[str, float], symbols: Sequence[str]) -> dict[str, Scaling | None]:
    """Each step's quantity as a multiple of the valueless ``symbols`` (``None``: not a simple one).

    The chain is evaluated with every symbol at 1, with each symbol at 2 in turn (the ratio gives
    its power), and with all of them at different primes, to confirm that the powers combine as a
    product.
    """
    ones = {s: 1.0 for s in symbols}
    base = chain_values(compiled, {**si, **ones})
    doubled = {s: chain_values(compiled, {**si, **ones, s: 2.0}) for s in symbols}
    primes = dict(zip(symbols, (3.0, 5.0, 7.0, 11.0, 13.0, 17.0, 19.0, 23.0), strict=False))
    joint = chain_values(compiled, {**si, **primes})
    result: dict[str, Scaling | None] = {}
    for step in compiled.steps:
        quantity = step.unknown
        value = base.get(quantity, _m.nan)
        powers = {s: _power_of(value, doubled[s].get(quantity, _m.nan)) for s in symbols}
        if not _m.isfinite(value) or any(p is None for p in powers.values()):
            result[quantity] = None
            continue
        found = {s: p for s, p in powers.items() if p is not None}
        expected = value * _m.prod(primes[s] ** float(p) for s, p in found.items())
        close = _m.isclose(joint.get(quantity, _m.nan), expected, rel_tol=1e-9, abs_tol=1e-300)
        result[quantity] = Scaling(value, found) if close else None
    return result


def _power_of(value: float, doubled: float) -> Fraction | None:
    """The power ``k`` (a multiple of 1/2) with ``doubled == value * 2**k``, if there is one."""
    if value == 0:
        return Fraction(0) if doubled == 0 else None
    ratio = doubled / value
    if not (_m.isfinite(ratio) and ratio > 0):
        return None
    power = Fraction(round(2 * _m.log2(ratio)), 2)
    return power if _m.isclose(2.0 ** float(power), ratio, rel_tol=1e-9) else None


# --- the worked solution -------------------------------------------------------------------------

@dataclass(frozen=True)
class WorkedStep:
    """One step: the relation (markup), its equation when it is not already the solved form (math),
    the chain ``unknown = solved = with numbers = value unit`` as its parts (math) and a note (markup)."""

    relation: Typ
    equation: str | None
    chain: tuple[str, ...]
    note: Typ


@dataclass(frozen=True)
class Worked:
    """A problem's worked solution: given values (math), notes on symbols without value, the
    steps, and every quantity's value in SI (symbols at 1) for the figures."""

    given: tuple[str, ...]
    notes: tuple[Typ, ...]
    steps: tuple[WorkedStep, ...]
    values: Mapping[str, float]


def _unit_math(unit: str) -> str:
    return f" thin {string(unit)}" if unit else ""


def given_lines(template: Template, variant: ProblemVariant, compiled: Compiled) -> list[str]:
    """``h_drop = 2100 mm = 2.100 m`` for each parameter (math), then the constants."""
    lines = []
    for parameter_name, parameter in template.parameters.items():
        printed, unit = variant.printed[parameter_name], parameter.unit
        shown = f"{name(parameter_name)} = {printed}"
        if unit.text == "deg":
            shown += f" degree = {number(float(printed) * unit.to_si)}{_unit_math('rad')}"
        elif unit.to_si != 1.0:
            shown += f"{_unit_math(unit.text)} = {_shown_parameter(printed, unit.to_si)}" \
                     f"{_unit_math(si_unit(unit.dimension))}"
        else:
            shown += _unit_math(unit.text)
        lines.append(shown)
    for constant, value in compiled.constants.items():
        lines.append(f"{name(constant)} = {number(value, 3)}{_unit_math('m/s²' if constant == 'g' else '')}")
    return lines


def _shown_parameter(printed: str, to_si: float) -> str:
    return printed if to_si == 1.0 else number(float(printed) * to_si, max(4, _significant(printed)))


def relation_markup(label: str, quantities: set[str]) -> Typ:
    """A relation's label as markup: text shown literally, quantity names as math.

    >>> str(relation_markup("falls through h_drop", {"h_drop"}))
    '#"falls through ";$h_"drop"$'
    """
    pieces, plain = [], ""
    for word in re.split(r"([A-Za-z_][A-Za-z0-9_]*)", label):
        if word in quantities and not plain.endswith("'"):  # "A's": a possessive, not the quantity s
            pieces += [str(text(plain)) if plain else "", f"${name(word)}$"]
            plain = ""
        else:
            plain += word
    return Typ("".join(pieces) + (str(text(plain)) if plain else ""))


_SWING = re.compile(r"conservation of energy in the swing of (\w+) on its cord of length (\w+) \(the cord does no "
                    r"work\): it rises L\(1 − cos θ\) to stop at (\w+) from the vertical")


_FLIGHT_AXES = ((re.compile(r"component along n\b"), "horizontal component"),
                (re.compile(r"component along t\b"), "vertical component"),
                (re.compile(r"separation over approach along n\b"), "separation over approach, horizontally"),
                (re.compile(r"no impulse along t, so (.+?)'s t-velocity"),
                 r"no vertical impulse, so \1's vertical velocity"))


def _released_at_the_angle(template: Template, speed: str) -> bool:
    """Whether the swing whose lowest-point speed is ``speed`` comes first, before any stage that speaks of that
    speed: then the body is released at its angle and swings down (two pendulums' ball A), not up."""
    for stage in template.scene.stages:
        if stage.effect == "swing" and stage.fields["speed"] == Sym(speed):
            return True
        if speed in stage.quantities:
            return False
    return False


def page_wording(step: Step, template: Template) -> str:
    """A step's relation as the page says it: bodies by their printed names (``cart 1``); no axis n in a
    problem on one line, where n is never drawn or defined; a swing names the speed it starts from (a
    quantity the impact after it in the chain defines) and its angle in the height it rises.

    >>> from grader.bank.template import load_bank
    >>> template = load_bank()["head-on"]
    >>> [page_wording(s, template) for s in compiled_for(template).steps][1]
    'impulse-momentum for cart 1'
    """
    label = step.relation
    for body in template.scene.bodies:
        if body_name(body) != body:
            label = re.sub(rf"\b{re.escape(body)}\b", body_name(body), label)
    label = re.sub(r"(?<![\w)])-(?=[A-Za-z_(])", "\u2212", label)  # a minus sign, not a hyphen: "-v_x_after"
    label = re.sub(r"\b([A-Za-z]\w*) \+ \1\b", r"2\1", label)  # two equal radii: "2r apart", not "r + r"
    stages = template.scene.stages
    if not any(stage.is_oblique or stage.effect == "velocity" for stage in stages):
        label = re.sub(r"\s+along n\b", "", label)
    if any(stage.effect == "flight" for stage in stages):  # a throw is drawn in x and y: n is across, t up
        for axis, words in _FLIGHT_AXES:
            label = axis.sub(words, label)
    swing = _SWING.fullmatch(label)
    if swing and isinstance(step.equation[0], Sym):
        body, length, angle = swing.groups()
        speed = step.equation[0].name
        if _released_at_the_angle(template, speed):
            label = (f"{body}, released at rest with the cord (of length {length}) at {angle} to the vertical, swings "
                     f"down {length}(1 − cos {angle}) to the lowest point, where its speed is {speed}: conservation "
                     "of energy (the cord does no work)")
        else:
            label = (f"{body} swings up from {speed}, its speed at the lowest point, until the cord (of length "
                     f"{length}) is at {angle} to the vertical, rising {length}(1 − cos {angle}): conservation of "
                     "energy (the cord does no work)")
    return label


@dataclass(frozen=True)
class StepForm:
    """What one step shows whatever the numbers: its relation (markup), its equation when it is not
    already the solved form (math), the solved form written for a reader and as math."""

    unknown: str
    relation: Typ
    equation: str | None
    solved: Node
    solved_math: str
    block: tuple[str, ...] = ()  # the unknowns of the block of equations solved together (empty: one equation)
    numeric: bool = False  # the unknown of a block solved numerically: shown by its value alone
    positive: Node | None = None  # a quantity that must be positive for ``solved`` to hold (tan⁻¹(y/x): x)
    kernel: Node | None = None  # the kernel's form, shown where ``positive`` is not


@dataclass(frozen=True)
class WorkedForm:
    """What every worked solution of one template shares (:func:`worked_form`): the steps' forms,
    the quantities' dimensions, and the symbols without value with their SI units and notes. Made
    once per template, so a class's worked solutions only substitute their numbers."""

    steps: tuple[StepForm, ...]
    dimensions: Mapping[str, Dimension]
    symbols: tuple[str, ...]
    symbol_units: Mapping[str, str]
    notes: tuple[Typ, ...]
    extra: tuple[Step, ...] = ()  # quantities only the page's route names, evaluated after the chain


def worked_form(template: Template, compiled: Compiled | None = None) -> WorkedForm:
    """The parts of ``template``'s worked solutions that do not depend on a variant's numbers."""
    compiled = compiled or compiled_for(template)
    route = textbook_route(template, compiled)
    evaluated = replace(compiled, steps=(*compiled.steps, *route.extra))
    dimensions = quantity_dimensions(template, evaluated)
    reader = reader_names(template, evaluated, dimensions)
    quantities = set(dimensions) | {s.unknown for s in route.steps}
    titles = [page_wording(step, template) for step in route.steps]
    kernel_forms = {step.unknown: step.solved for step in compiled.steps}
    steps = []
    for step, title in zip(route.steps, titles, strict=True):
        if step.numeric:  # its root(...) tree is what the kernel finds, not a form a reader follows
            lhs, rhs = (readable(side, reader) for side in step.equation)
            steps.append(StepForm(step.unknown, relation_markup(title, quantities),
                                  f"{math(lhs)} = {math(rhs)}", Sym(step.unknown), "", step.block, numeric=True))
            continue
        lhs, rhs, solved = (readable(side, reader) for side in (*step.equation, step.solved))
        # A block's equations are each shown, labelled, before the block's solution.
        shown = step.block or not (lhs == Sym(step.unknown) and rhs == solved)
        equation = f"{math(lhs)} = {math(rhs)}" if shown else None
        if titles.count(title) > 1 and not step.block:  # two steps, one relation: say what each finds
            title += f", which gives {step.unknown}"
        positive = route.positive.get(step.unknown)
        kernel = readable(kernel_forms[step.unknown], reader) if positive is not None else None
        steps.append(StepForm(step.unknown, relation_markup(title, quantities), equation, solved,
                              math(solved), step.block, positive=positive, kernel=kernel))
    symbols = tuple(sorted(template.symbols))
    # A symbol no step uses (a mass the scene needs only for its simulation) gets no note.
    used = set().union(*(names(step.solved) for step in compiled.steps))
    return WorkedForm(tuple(steps), dimensions, symbols,
                      {n: si_unit(s.unit.dimension) or "1" for n, s in template.symbols.items()},
                      tuple(_symbol_note(s, template.symbols[s].description) for s in symbols if s in used),
                      route.extra)


@dataclass(frozen=True)
class _Context:
    """What every step of one variant is shown with."""

    shown: dict[str, str]
    degrees: Mapping[str, str]
    symbol_units: Mapping[str, str]
    undefined: Mapping[str, str]
    conversions: Mapping[str, tuple[str, float]]  # an answer's quantity: the unit it is asked in, its SI factor
    symbolic: Mapping[str, str]  # an answer's quantity asked as an expression: the key's expression (math)


def worked(template: Template, variant: ProblemVariant, compiled: Compiled | None = None,
           form: WorkedForm | None = None) -> Worked:
    """The worked solution of one variant (``compiled`` and ``form``: the template's, if the caller
    has them)."""
    compiled = compiled or compiled_for(template)
    form = form or worked_form(template, compiled)
    evaluated = replace(compiled, steps=(*compiled.steps, *form.extra))
    si = si_parameters(template, variant)
    scaled = scalings(evaluated, si, form.symbols)
    shown = {n: _shown_parameter(variant.printed[n], p.unit.to_si) for n, p in template.parameters.items()}
    shown.update({c: number(v, 3) for c, v in compiled.constants.items()})
    answers = [spec for spec in template.answers.values() if isinstance(spec.value, Sym)]
    context = _Context(
        shown, {n: f"{variant.printed[n]} degree" for n, p in template.parameters.items() if p.unit.text == "deg"},
        form.symbol_units, _undefined(template, variant),
        {spec.value.name: (spec.unit.text, spec.unit.to_si) for spec in answers  # type: ignore[union-attr]
         if spec.unit.text not in ("", "deg") and spec.unit.to_si != 1.0},
        {template.answers[part.name].value.name: answer_math(part.value, "")  # type: ignore[union-attr]
         for part in variant.answers if isinstance(part.value, str) and template.answers[part.name].symbolic
         and isinstance(template.answers[part.name].value, Sym)})
    values = chain_values(evaluated, {**si, **{s: 1.0 for s in form.symbols}})
    steps = []
    for index, step in enumerate(form.steps):
        if step.block:
            if step.unknown == step.block[0]:
                steps += _block_equations(form.steps[index:index + len(step.block)])
            step = replace(step, relation=(numerically if step.numeric else simultaneous)(len(step.block)),
                           equation=None)
        if step.positive is not None and step.kernel is not None and not page_value(step.positive, values) > 0:
            step = replace(step, solved=step.kernel, solved_math=math(step.kernel))  # tan⁻¹(y/x) is not the angle
        scaling = scaled.get(step.unknown)
        steps.append(_step(step, scaling, form.dimensions.get(step.unknown), context))
        if scaling is not None:
            shown[step.unknown] = scaling.math()
    steps += _answer_steps(template, evaluated, si, form, context, values)
    return Worked(tuple(given_lines(template, variant, compiled)), form.notes, tuple(steps), values)


def _answer_steps(template: Template, compiled: Compiled, si: Mapping[str, float], form: WorkedForm,
                  context: _Context, ones: Mapping[str, float]) -> list[WorkedStep]:
    """An answer asked as an expression of the chain's quantities (a ratio, a sum of two losses) as a step of
    its own, so the answer's cell shows a value the page computes (``ones``: the chain's values, the symbols
    without value at 1; a value that changes with them is not shown)."""
    asked = [spec for spec in template.answers.values() if not (isinstance(spec.value, Sym) or spec.symbolic)]
    if not asked:
        return []
    reader = reader_names(template, compiled, form.dimensions)
    twos = chain_values(compiled, {**si, **{s: 2.0 for s in form.symbols}}) if form.symbols else ones
    steps = []
    for spec in asked:
        try:
            value, check = (float(page_value(spec.value, env)) for env in (ones, twos))
        except KeyError:
            continue
        if not (_m.isfinite(value) and _m.isclose(value, check, rel_tol=1e-9, abs_tol=1e-300)):
            continue
        shown = readable(spec.value, reader)
        chain = [math(shown), tidy_signs(math(shown, context.shown, context.degrees))]
        if chain[-1] == number(value):
            chain.pop()
        chain.append(number(value))
        if spec.unit.text not in ("", "deg"):
            chain[-1] += _unit_math(si_unit(spec.unit.dimension))
            if spec.unit.to_si != 1.0:
                chain.append(number(value / spec.unit.to_si) + _unit_math(spec.unit.text))
        steps.append(WorkedStep(text(spec.description), None, tuple(chain), Typ("")))
    return steps


def _letter(index: int) -> str:
    return f"({chr(ord('a') + index)})"


def _block_equations(members: Sequence[StepForm]) -> list[WorkedStep]:
    """A block's equations as a textbook writes them before solving them together: each labelled (a),
    (b), ... with its relation, and no value yet."""
    return [WorkedStep(Typ(f"{text(_letter(index) + ' ')}{member.relation}"), member.equation, (), Typ(""))
            for index, member in enumerate(members)]


def simultaneous(count: int) -> Typ:
    """``simultaneous solution of (a) and (b) gives``, for a block of ``count`` equations.

    >>> str(simultaneous(3))
    '#"simultaneous solution of (a), (b) and (c) gives";'
    """
    letters = [_letter(index) for index in range(count)]
    return text(f"simultaneous solution of {', '.join(letters[:-1])} and {letters[-1]} gives")


def numerically(count: int) -> Typ:
    """What a block solved numerically says before its unknown's value, with the tolerance the root is found to.

    >>> str(numerically(2))
    '#"(a) and (b) solved together numerically (to 1e−15, relative) give";'
    """
    letters = [_letter(index) for index in range(count)]
    return text(f"{', '.join(letters[:-1])} and {letters[-1]} solved together numerically (to {TOLERANCE_TEXT}, "
                "relative) give")


def quantity_dimensions(template: Template, compiled: Compiled) -> dict[str, Dimension]:
    """The dimension of every parameter, symbol, constant and step quantity whose dimension can be
    told (a step's from its solved form; a bare number, a velocity that stays 0, says nothing)."""
    known: dict[str, Dimension] = {n: p.unit.dimension for n, p in template.parameters.items()}
    known.update({n: s.unit.dimension for n, s in template.symbols.items()})
    known.update({c: ACCELERATION for c in compiled.constants if c == "g"})
    asked = {spec.value.name: spec.unit.dimension for spec in template.answers.values() if isinstance(spec.value, Sym)}
    for step in compiled.steps:
        if step.numeric:  # a root has the dimension of the answer that asks for it, if one does
            found = asked.get(step.unknown)
        else:
            found = None if isinstance(step.solved, Num) else dimension_of(step.solved, known, strict=False)
        if found is not None:
            known[step.unknown] = found
    return known


def reader_names(template: Template, compiled: Compiled, dimensions: Mapping[str, Dimension] | None = None) -> Names:
    """The names of a template for :func:`~grader.render.readable.readable`: their dimensions, and the
    order the problem introduces them in (parameters, symbols, constants, then the steps')."""
    order = [*template.parameters, *template.symbols, *compiled.constants, *(s.unknown for s in compiled.steps)]
    return Names(quantity_dimensions(template, compiled) if dimensions is None else dimensions, order)


def _undefined(template: Template, variant: ProblemVariant) -> dict[str, str]:
    """Quantities that an undefined answer names directly, with the reason (an angle of a zero vector)."""
    result = {}
    for part in variant.answers:
        value = template.answers[part.name].value
        if part.undefined is not None and isinstance(value, Sym):
            result[value.name] = part.undefined
    return result


def _symbol_note(symbol: str, description: str) -> Typ:
    explained = f": {description}. It has no value, so the steps that depend on it are shown as multiples of it."
    return Typ(f"${name(symbol)}$" + text(explained))


def _step(step: StepForm, scaling: Scaling | None, dim: Dimension | None, context: _Context) -> WorkedStep:
    relation, equation = step.relation, step.equation
    chain = [name(step.unknown)] if step.numeric else [name(step.unknown), step.solved_math]
    printed = context.symbolic.get(step.unknown)
    if printed and printed != chain[-1]:  # asked as an expression: the form, the variant's numbers in, is the key's
        chain.append(printed)
    substituted = chain[-1] if step.numeric else tidy_signs(math(step.solved, context.shown, context.degrees))
    if substituted != chain[-1]:
        chain.append(substituted)
    if step.unknown in context.undefined:
        return WorkedStep(relation, equation, tuple(chain), text(f"(undefined: {context.undefined[step.unknown]})"))
    if scaling is None:
        why = "it depends on symbols without a value" if context.symbol_units else "it has no finite value here"
        return WorkedStep(relation, equation, tuple(chain), text(f"({why}, so it is not evaluated)"))
    value = scaling.math()
    if value != chain[-1]:
        chain.append(value)
    unit = si_unit(dim)
    multiple = [s for s, p in scaling.powers.items() if p]
    if multiple:
        symbols = ", ".join(f"${name(s)}$ {text('in ' + context.symbol_units[s])}" for s in multiple)
        note = Typ(f"{text(f'(in {unit}, with ' if unit else '(with ')}{symbols}{text(')')}")
        return WorkedStep(relation, equation, tuple(chain), note)
    chain[-1] += _unit_math(unit)
    if dim == ANGLE:
        chain.append(f"{number(_m.degrees(scaling.coefficient))} degree")
    if step.unknown in context.conversions:  # the unit the answer is asked in, as a step of its own
        asked, to_si = context.conversions[step.unknown]
        chain.append(number(scaling.coefficient / to_si) + _unit_math(asked))
    return WorkedStep(relation, equation, tuple(chain), Typ(""))


def answer_math(value: float | str | None, unit: str) -> str:
    """An answer as Typst math: a number to 4 significant figures with its (template) unit, or a
    symbolic answer as an expression, written for a reader; ``""`` when it is undefined.

    >>> answer_math("v*(1 - 0.1*p)/(p + 1)", "m/s")
    '(v (1 - 0.1 p))/(1 + p)'
    """
    if value is None:
        return ""
    if isinstance(value, str):
        return math(readable(parse(value), Names({})))
    if unit == "deg":
        return f"{number(value)} degree"
    return number(value) + _unit_math(unit)
