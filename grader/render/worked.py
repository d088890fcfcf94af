"""Worked solutions: the solver's step chain with one variant's numbers substituted, as Typst.

Every step of ``compiled_for(template).steps`` is shown as a student would write it: the
relation, its equation, the solved form, then the same with the variant's numbers (in SI) and
the value with its SI unit, which is inferred from the parameters' units. A step that depends on
a symbol without a value (a mass that cancels) is shown as a multiple of it, never with a
made-up number.

Typst source is built here too: :class:`Typ` marks trusted source, :func:`text` turns any text
into a string literal so that it is shown, never interpreted.

>>> from grader.model.expr import parse
>>> math(parse("sqrt(2*g*h_drop)"))
'sqrt(2 g h_"drop")'
>>> math(parse("v_n - J/m"), {"v_n": "3.5", "J": "2.1 m"})
'3.5 - (2.1 m)/m'
>>> unit_of(dimension(parse("m*v*v/2"), {"m": (0, 1, 0, 0), "v": (1, 0, -1, 0)}))
'J'
>>> str(text("$x$ #1"))
'#"$x$ #1";'
"""

from __future__ import annotations

import math as _m
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from fractions import Fraction
from functools import lru_cache
from typing import Any

import numpy as np

from grader.assign.variants import ProblemVariant
from grader.bank.template import Template
from grader.model.expr import FUNCTIONS, Node, Num, Op, Sym, format_number, names, parse
from grader.model.kernel import evaluate
from grader.render.readable import Names, counted, readable
from grader.solve.cache import compiled_for
from grader.solve.compiled import Compiled


class Typ(str):
    """Typst source we generated (or the instructor wrote): inserted into a document as is."""


def string(value: object) -> Typ:
    """A Typst string literal (for code and math): ``"..."`` with quotes and backslashes escaped."""
    body = str(value).replace("\\", "\\\\").replace('"', '\\"')
    body = body.replace("\n", "\\n").replace("\r", "\\r").replace("\t", "\\t")
    return Typ(f'"{body}"')


def text(value: object) -> Typ:
    """Text shown literally in markup: an embedded string literal, ended by ``;`` so that nothing
    after it (a dot, a bracket) can continue the expression."""
    return Typ(f"#{string(value)};")


# --- names and numbers in Typst math ------------------------------------------------------------

GREEK = {"alpha", "beta", "gamma", "delta", "epsilon", "zeta", "eta", "theta", "iota", "kappa", "lambda",
         "mu", "nu", "xi", "pi", "rho", "sigma", "tau", "upsilon", "phi", "chi", "psi", "omega",
         "Gamma", "Delta", "Theta", "Lambda", "Xi", "Pi", "Sigma", "Phi", "Psi", "Omega"}


def _atom(word: str) -> str:
    if word in GREEK or re.fullmatch(r"[A-Za-z]|\d+", word):
        return word
    return str(string(word))


@lru_cache(maxsize=4096)  # a class's worked solutions name the same few quantities thousands of times
def name(quantity: str) -> str:
    """A quantity's name in Typst math: ``h_drop`` -> ``h_"drop"``, ``v1_n_after`` -> ``v'_(1, n)``.

    ``after`` becomes a prime, as in the textbook; a trailing digit or capital of the first part is
    a subscript (``vA`` -> ``v_A``, ``theta1`` -> ``theta_1``).

    >>> name("theta"), name("vA_after"), name("E_lost")
    ('theta', "v'_A", 'E_"lost"')
    """
    parts = quantity.split("_")
    primes = parts.count("after")
    rest = [p for p in parts[1:] if p and p != "after"]
    base = parts[0]
    split = re.fullmatch(r"([a-z]+)([A-Z]+)", base) or re.fullmatch(r"([A-Za-z]+?)(\d+)", base)
    if split and (split.group(1) in GREEK or len(split.group(1)) == 1):
        base, rest = split.group(1), [split.group(2), *rest]
    result = _atom(base) + "'" * primes
    if rest:
        subs = [_atom(p) for p in rest]
        result += f"_{subs[0]}" if len(subs) == 1 else f"_({', '.join(subs)})"
    return result


def number(value: float, figures: int = 4) -> str:
    """A number in Typst math to ``figures`` significant figures (trailing zeros kept).

    >>> number(6.0459), number(0.000012346), number(-2.5), number(17683.2)
    ('6.046', '1.235 times 10^(-5)', '-2.500', '17680')
    """
    if value == 0 or not _m.isfinite(value):
        return "0" if value == 0 else str(string("undefined"))
    rounded = float(f"{value:.{figures - 1}e}")
    exponent = _m.floor(_m.log10(abs(rounded)))
    if -3 <= exponent < 5:
        return f"{rounded:.{max(0, figures - 1 - exponent)}f}"
    mantissa = f"{rounded / 10 ** exponent:.{figures - 1}f}"
    return f"{mantissa} times 10^({exponent})"


def _significant(printed: str) -> int:
    digits = printed.lstrip("+-").replace(".", "").lstrip("0")
    return max(1, len(digits))


# --- expression trees in Typst math --------------------------------------------------------------

_LEVEL = {"add": 4, "sub": 4, "mul": 5, "div": 5, "neg": 6, "pow": 7}
_CALLS = {"sqrt": "sqrt", "sin": "sin", "cos": "cos", "tan": "tan", "sind": "sin", "cosd": "cos",
          "log": "ln", "abs": "abs", "Max": "max", "Min": "min", "atan2": 'op("atan2")'}
_TRIG = {"sin", "cos", "tan", "sind", "cosd"}


@dataclass(frozen=True)
class _Math:
    """Converts trees; ``values`` replace names (substitution), ``degrees`` inside trig calls."""

    values: Mapping[str, str]
    degrees: Mapping[str, str]

    def convert(self, node: Node, trig: bool = False) -> tuple[str, int, bool]:
        """Typst math, precedence level and whether it shows a number."""
        if isinstance(node, Num):
            shown = self._num(node)
            return (f"({shown})", 9, True) if shown.startswith("-") or "/" in shown else (shown, 9, True)
        if isinstance(node, Sym):
            value = (self.degrees.get(node.name) if trig else None) or self.values.get(node.name)
            if value is None:
                return name(node.name), 9, False
            bare = re.fullmatch(r"[0-9.]+|[0-9.]+ degree", value)
            return (value if bare else f"({value})"), 9, True
        if node.op in FUNCTIONS:
            return self._call(node), 9, False
        if node.op == "mul":
            return self._product(node), 5, False
        return self._operator(node)

    def _num(self, node: Num) -> str:
        if isinstance(node.value, float):
            return number(node.value)
        return format_number(node.value)

    def _call(self, node: Op) -> str:
        trig = node.op in _TRIG
        args = [self.convert(a, trig)[0] for a in node.args]
        if node.op == "hypot":
            squares = [self._power(a, "2") for a in node.args]
            return f"sqrt({' + '.join(squares)})"
        if node.op == "exp":
            return f"e^({args[0]})"
        return f"{_CALLS[node.op]}({', '.join(args)})"

    def _power(self, base: Node, exponent: str) -> str:
        shown, level, _ = self.convert(base)
        return f"{shown if level >= 9 else f'({shown})'}^{exponent}"

    def _factors(self, node: Node) -> list[Node]:
        if isinstance(node, Op) and node.op == "mul":
            return self._factors(node.args[0]) + self._factors(node.args[1])
        return [node]

    def _product(self, node: Op) -> str:
        pieces: list[tuple[str, bool]] = []
        for factor, count in counted(self._factors(node)):
            if count > 1:
                pieces.append((self._power(factor, str(count)), self.convert(factor)[2]))
                continue
            shown, level, numeric = self.convert(factor)
            if not pieces and _is_fraction(factor):  # 1/2 m v^2: Typst's fraction takes the 2 alone
                pieces.append((shown, False))
                continue
            # A fraction among factors stays bare: Typst's slash takes the group just before it, so
            # sqrt(x) (1 + e)/(1 - e) is the root times the fraction.
            if (level <= 5 and not _is_quotient(factor)) or (pieces and shown.startswith("-")):
                shown = f"({shown})"
            pieces.append((shown, numeric or shown[:1].isdigit()))
        result = pieces[0][0]
        for shown, numeric in pieces[1:]:
            result += (" dot " if numeric else " ") + shown
        return result

    def _operator(self, node: Op) -> tuple[str, int, bool]:
        level = _LEVEL[node.op]
        if node.op == "neg":
            shown, inner, _ = self.convert(node.args[0])
            return ("-" + (shown if inner >= 5 else f"({shown})")), 6, False
        if node.op == "pow":
            exponent = node.args[1]
            if isinstance(exponent, Num) and exponent.value == Fraction(1, 2):
                return f"sqrt({self.convert(node.args[0])[0]})", 9, False
            power = self.convert(exponent)[0]
            return self._power(node.args[0], power if re.fullmatch(r"\d+", power) else f"({power})"), 7, False
        left, left_level, _ = self.convert(node.args[0])
        right, right_level, _ = self.convert(node.args[1])
        if node.op == "div":
            numerator = left if left_level >= 9 else f"({left})"
            denominator = right if right_level >= 9 else f"({right})"
            return f"{numerator}/{denominator}", 5, False
        if (node.op == "sub" and right_level <= 4) or right.startswith("-"):
            right = f"({right})"
        sign = " + " if node.op == "add" else " - "
        return left + sign + right, level, False


def _is_quotient(node: Node) -> bool:
    return isinstance(node, Op) and node.op == "div"


def _is_fraction(node: Node) -> bool:
    """A quotient of two whole numbers: a product's leading coefficient, as :mod:`readable` writes it."""
    return isinstance(node, Op) and node.op == "div" and all(
        isinstance(arg, Num) and isinstance(arg.value, Fraction) and arg.value.denominator == 1 for arg in node.args)


def math(node: Node, values: Mapping[str, str] | None = None, degrees: Mapping[str, str] | None = None) -> str:
    """Typst math of a tree; ``values`` are shown instead of names (numbers substituted)."""
    return _Math(values or {}, degrees or {}).convert(node)[0]


# --- dimensions ----------------------------------------------------------------------------------

Dimension = tuple[Fraction, Fraction, Fraction, Fraction]
"""Exponents of length, mass, time and angle."""

ZERO: Dimension = (Fraction(0), Fraction(0), Fraction(0), Fraction(0))
ANGLE: Dimension = (Fraction(0), Fraction(0), Fraction(0), Fraction(1))
_NAMED = {(1, 0, 0, 0): "m", (1, 0, -1, 0): "m/s", (1, 0, -2, 0): "m/s²", (0, 1, 0, 0): "kg",
          (1, 1, -1, 0): "N·s", (1, 1, -2, 0): "N", (2, 1, -2, 0): "J", (0, 0, 0, 1): "rad",
          (0, 0, 1, 0): "s", (2, 0, -2, 0): "m²/s²", (0, 0, -1, 0): "1/s", (0, -1, 0, 0): "1/kg"}
_SUPERSCRIPT = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")


def _dim(values: Sequence[int | Fraction]) -> Dimension:
    return (Fraction(values[0]), Fraction(values[1]), Fraction(values[2]), Fraction(values[3]))


def dimension(node: Node, known: Mapping[str, Sequence[int | Fraction]]) -> Dimension | None:
    """The dimension of an expression from its names' dimensions; ``None`` when it cannot be told
    (an unknown name, a sum of unlike terms, a power of a dimensioned quantity by a non-number)."""
    if isinstance(node, Num):
        return ZERO
    if isinstance(node, Sym):
        return ZERO if node.name == "pi" else (_dim(known[node.name]) if node.name in known else None)
    if node.op in ("sin", "cos", "tan", "sind", "cosd", "exp", "log", "lt", "le", "gt", "ge", "and", "or"):
        return ZERO
    if node.op == "atan2":
        return ANGLE
    parts = [dimension(a, known) for a in node.args]
    if node.op in ("add", "sub", "hypot", "Max", "Min"):
        # Terms must agree; a bare number (0 in Max(0, x)) or a term of unknown dimension takes
        # the dimension of the others.
        shaped = {d for d, a in zip(parts, node.args, strict=True) if d is not None and not isinstance(a, Num)}
        return next(iter(shaped)) if len(shaped) == 1 else (ZERO if not shaped and None not in parts else None)
    if any(p is None for p in parts):
        return None
    dims = [p for p in parts if p is not None]
    if node.op in ("neg", "abs"):
        return dims[0]
    if node.op == "sqrt":
        return _scaled(dims[0], Fraction(1, 2))
    if node.op == "mul":
        return _dim([a + b for a, b in zip(dims[0], dims[1], strict=True)])
    if node.op == "div":
        return _dim([a - b for a, b in zip(dims[0], dims[1], strict=True)])
    if node.op == "pow":
        exponent = node.args[1]
        if isinstance(exponent, Num):
            return _scaled(dims[0], Fraction(exponent.value))
        return ZERO if dims[0] == ZERO else None
    return None


def _scaled(dim: Dimension, factor: Fraction) -> Dimension:
    return _dim([d * factor for d in dim])


def unit_of(dim: Dimension | None) -> str:
    """The SI unit of a dimension as text: ``m/s``, ``N·s``, ``J``; products otherwise; ``""`` for a
    pure number (or an unknown dimension).

    >>> unit_of((1, 2, -1, 0))
    'kg²·m/s'
    """
    if dim is None or all(d == 0 for d in dim):
        return ""
    key = tuple(int(d) if d.denominator == 1 else d for d in _dim(dim))
    if key in _NAMED:
        return _NAMED[key]
    up: list[str] = []
    down: list[str] = []
    for symbol, power in zip(("kg", "m", "s", "rad"), (key[1], key[0], key[2], key[3]), strict=True):
        if power == 0:
            continue
        size = abs(Fraction(power))
        shown = symbol if size == 1 else symbol + (str(size).translate(_SUPERSCRIPT) if size.denominator == 1
                                                   else f"^({size})")
        (up if power > 0 else down).append(shown)
    numerator = "·".join(up) or "1"
    return numerator + ("/" + "·".join(down) if down else "")


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


def _si_unit(dimension_: Sequence[int]) -> str:
    return unit_of(_dim(dimension_))


def given_lines(template: Template, variant: ProblemVariant, compiled: Compiled) -> list[str]:
    """``h_drop = 2100 mm = 2.100 m`` for each parameter (math), then the constants."""
    lines = []
    for parameter_name, parameter in template.parameters.items():
        printed, unit = variant.printed[parameter_name], parameter.unit
        shown = f"{name(parameter_name)} = {printed}"
        if unit.text == "deg":
            shown += f" degree = {number(float(printed) * unit.to_si)}{_unit_math('rad')}"
        elif unit.to_si != 1.0 or unit.text not in ("", _si_unit(unit.dimension)):
            shown += f"{_unit_math(unit.text)} = {_shown_parameter(printed, unit.to_si)}" \
                     f"{_unit_math(_si_unit(unit.dimension))}"
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
        if word in quantities:
            pieces += [str(text(plain)) if plain else "", f"${name(word)}$"]
            plain = ""
        else:
            plain += word
    return Typ("".join(pieces) + (str(text(plain)) if plain else ""))


@dataclass(frozen=True)
class StepForm:
    """What one step shows whatever the numbers: its relation (markup), its equation when it is not
    already the solved form (math), the solved form written for a reader and as math."""

    unknown: str
    relation: Typ
    equation: str | None
    solved: Node
    solved_math: str


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


def worked_form(template: Template, compiled: Compiled | None = None) -> WorkedForm:
    """The parts of ``template``'s worked solutions that do not depend on a variant's numbers."""
    compiled = compiled or compiled_for(template)
    dimensions = quantity_dimensions(template, compiled)
    reader = reader_names(template, compiled, dimensions)
    quantities = set(dimensions) | {s.unknown for s in compiled.steps}
    steps = []
    for step in compiled.steps:
        lhs, rhs, solved = (readable(side, reader) for side in (*step.equation, step.solved))
        equation = None if (lhs == Sym(step.unknown) and rhs == solved) else f"{math(lhs)} = {math(rhs)}"
        steps.append(StepForm(step.unknown, relation_markup(step.relation, quantities), equation, solved,
                              math(solved)))
    symbols = tuple(sorted(template.symbols))
    # A symbol no step uses (a mass the scene needs only for its simulation) gets no note.
    used = set().union(*(names(step.solved) for step in compiled.steps))
    return WorkedForm(tuple(steps), dimensions, symbols,
                      {n: _si_unit(s.unit.dimension) or "1" for n, s in template.symbols.items()},
                      tuple(_symbol_note(s, template.symbols[s].description) for s in symbols if s in used))


@dataclass(frozen=True)
class _Context:
    """What every step of one variant is shown with."""

    shown: dict[str, str]
    degrees: Mapping[str, str]
    symbol_units: Mapping[str, str]
    undefined: Mapping[str, str]


def worked(template: Template, variant: ProblemVariant, compiled: Compiled | None = None,
           form: WorkedForm | None = None) -> Worked:
    """The worked solution of one variant (``compiled`` and ``form``: the template's, if the caller
    has them)."""
    compiled = compiled or compiled_for(template)
    form = form or worked_form(template, compiled)
    si = si_parameters(template, variant)
    scaled = scalings(compiled, si, form.symbols)
    shown = {n: _shown_parameter(variant.printed[n], p.unit.to_si) for n, p in template.parameters.items()}
    shown.update({c: number(v, 3) for c, v in compiled.constants.items()})
    context = _Context(
        shown, {n: f"{variant.printed[n]} degree" for n, p in template.parameters.items() if p.unit.text == "deg"},
        form.symbol_units, _undefined(template, variant))
    steps = []
    for step in form.steps:
        scaling = scaled.get(step.unknown)
        steps.append(_step(step, scaling, form.dimensions.get(step.unknown), context))
        if scaling is not None:
            shown[step.unknown] = scaling.math()
    values = chain_values(compiled, {**si, **{s: 1.0 for s in form.symbols}})
    return Worked(tuple(given_lines(template, variant, compiled)), form.notes, tuple(steps), values)


def quantity_dimensions(template: Template, compiled: Compiled) -> dict[str, Dimension]:
    """The dimension of every parameter, symbol, constant and step quantity whose dimension can be
    told (a step's from its solved form; a bare number, a velocity that stays 0, says nothing)."""
    known: dict[str, Dimension] = {n: _dim(p.unit.dimension) for n, p in template.parameters.items()}
    known.update({n: _dim(s.unit.dimension) for n, s in template.symbols.items()})
    known.update({c: _dim((1, 0, -2, 0)) for c in compiled.constants if c == "g"})
    for step in compiled.steps:
        found = None if isinstance(step.solved, Num) else dimension(step.solved, known)
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
    chain = [name(step.unknown), step.solved_math]
    substituted = math(step.solved, context.shown, context.degrees)
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
    unit = unit_of(dim)
    multiple = [s for s, p in scaling.powers.items() if p]
    if multiple:
        symbols = ", ".join(f"${name(s)}$ {text('in ' + context.symbol_units[s])}" for s in multiple)
        note = Typ(f"{text(f'(in {unit}, with ' if unit else '(with ')}{symbols}{text(')')}")
        return WorkedStep(relation, equation, tuple(chain), note)
    chain[-1] += _unit_math(unit)
    if dim == ANGLE:
        chain.append(f"{number(_m.degrees(scaling.coefficient))} degree")
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
