"""Units: parse a unit string, convert to SI exactly, compare dimensions.

Factors are exact (a ``Fraction`` times a power of pi), so unit conversions folded into the
solver's expressions cancel exactly.

>>> parse_unit("ft/s").factor, parse_unit("ft/s").dimension
(Fraction(381, 1250), (1, 0, -1, 0))
>>> parse_unit("deg").pi_power
1
>>> parse_unit("m/s^2").same_dimension(parse_unit("ft*s**-2"))
True
>>> parse_unit("furlong")  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
grader.base.errors.GraderError: unknown unit 'furlong' in 'furlong' (known: %, cm, deg, ft, g, ...)
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass
from fractions import Fraction

from grader.base.errors import GraderError
from grader.model.expr import Node, Num, Op, Sym

Dimension = tuple[Fraction, Fraction, Fraction, Fraction]
"""Exponents of (length, mass, time, angle)."""

# dimension exponents: (length, mass, time, angle)
_BASE: dict[str, tuple[Fraction, int, tuple[int, int, int, int]]] = {
    "m": (Fraction(1), 0, (1, 0, 0, 0)),
    "mm": (Fraction(1, 1000), 0, (1, 0, 0, 0)),
    "cm": (Fraction(1, 100), 0, (1, 0, 0, 0)),
    "km": (Fraction(1000), 0, (1, 0, 0, 0)),
    "ft": (Fraction("0.3048"), 0, (1, 0, 0, 0)),
    "in": (Fraction("0.0254"), 0, (1, 0, 0, 0)),
    "mi": (Fraction("1609.344"), 0, (1, 0, 0, 0)),
    "kg": (Fraction(1), 0, (0, 1, 0, 0)),
    "g": (Fraction(1, 1000), 0, (0, 1, 0, 0)),
    "Mg": (Fraction(1000), 0, (0, 1, 0, 0)),
    "t": (Fraction(1000), 0, (0, 1, 0, 0)),
    "lbm": (Fraction("0.45359237"), 0, (0, 1, 0, 0)),
    "slug": (Fraction("0.45359237") * Fraction("9.80665") / Fraction("0.3048"), 0, (0, 1, 0, 0)),
    "s": (Fraction(1), 0, (0, 0, 1, 0)),
    "ms": (Fraction(1, 1000), 0, (0, 0, 1, 0)),
    "min": (Fraction(60), 0, (0, 0, 1, 0)),
    "h": (Fraction(3600), 0, (0, 0, 1, 0)),
    "N": (Fraction(1), 0, (1, 1, -2, 0)),
    "kN": (Fraction(1000), 0, (1, 1, -2, 0)),
    "lbf": (Fraction("0.45359237") * Fraction("9.80665"), 0, (1, 1, -2, 0)),
    "lb": (Fraction("0.45359237") * Fraction("9.80665"), 0, (1, 1, -2, 0)),
    "J": (Fraction(1), 0, (2, 1, -2, 0)),
    "kJ": (Fraction(1000), 0, (2, 1, -2, 0)),
    "rad": (Fraction(1), 0, (0, 0, 0, 1)),
    "deg": (Fraction(1, 180), 1, (0, 0, 0, 1)),
    "%": (Fraction(1, 100), 0, (0, 0, 0, 0)),
    "1": (Fraction(1), 0, (0, 0, 0, 0)),
}
_ALIASES = {"°": "deg", "mph": "mi/h", "km/hr": "km/h", "sec": "s", "ft-lb": "ft*lbf", "ft*lb": "ft*lbf"}
_TOKEN = re.compile(r"\s*([*/])?\s*([A-Za-z%°]+|1)\s*(?:(?:\^|\*\*)\s*(-?\d+))?\s*")
NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")  # a number as a value is written
MAX_POWER = 9  # no unit of mechanics needs more; bounds the exact factor's size
MAX_TEXT = 100  # characters of a number with its unit


@dataclass(frozen=True)
class Unit:
    """A unit: ``value_SI = value * factor * pi**pi_power``; ``text`` as the template wrote it."""

    text: str
    factor: Fraction
    pi_power: int
    dimension: tuple[int, int, int, int]

    @property
    def to_si(self) -> float:
        """The conversion factor to SI as a float (deg -> rad included)."""
        return float(self.factor) * math.pi ** self.pi_power

    def same_dimension(self, other: Unit) -> bool:
        """Whether values in the two units can be converted into each other."""
        return self.dimension == other.dimension


def parse_unit(text: str) -> Unit:
    """Parse ``m``, ``m/s``, ``m/s^2``, ``kg*m/s``, ``deg``, ``%``; empty means dimensionless."""
    if len(text) > MAX_TEXT:
        raise GraderError(f"a unit of {len(text):,} characters; expected at most {MAX_TEXT}")
    cleaned = _ALIASES.get(text.strip(), text.strip())
    if cleaned in ("", "-"):
        cleaned = "1"
    factor, pi_power, dimension = Fraction(1), 0, [0, 0, 0, 0]
    position = 0
    while position < len(cleaned):
        match = _TOKEN.match(cleaned, position)
        if not match or match.end() == position or (position == 0 and match.group(1)):
            raise GraderError(f"cannot read unit '{text}' (write units like m, m/s, m/s^2, kg, deg, %)")
        operator, name, power_text = match.groups()
        name = _ALIASES.get(name, name)
        if name not in _BASE:
            known = ", ".join(sorted(set(_BASE) - {"1"}, key=str.lower))
            raise GraderError(f"unknown unit '{name}' in '{text}' (known: {known}, and products, quotients and "
                              "powers of them)")
        base_factor, base_pi, base_dimension = _BASE[name]
        power = int(power_text or 1) * (-1 if operator == "/" else 1)
        if abs(power) > MAX_POWER:
            raise GraderError(f"the power {power} in '{text}' is beyond what a unit of mechanics needs; "
                              f"expected powers from -{MAX_POWER} to {MAX_POWER}")
        factor *= base_factor ** power
        pi_power += base_pi * power
        dimension = [d + b * power for d, b in zip(dimension, base_dimension, strict=True)]
        position = match.end()
    return Unit(text.strip(), factor, pi_power, (dimension[0], dimension[1], dimension[2], dimension[3]))


DIMENSIONLESS = parse_unit("")


def split_quantity(text: str) -> tuple[float, str] | None:
    """A number and the unit text after it (``"2.1 m"`` -> ``(2.1, "m")``), or None when the text
    does not start with a finite float64 number or is longer than ``MAX_TEXT``. Linear in the text.

    >>> split_quantity(" 2.1e3 mm "), split_quantity("1e309"), split_quantity("abc")
    ((2100.0, 'mm'), None, None)
    """
    text = text.strip()
    match = NUMBER.match(text) if len(text) <= MAX_TEXT else None
    if match is None:
        return None
    value = float(match.group())
    return (value, text[match.end():].strip()) if math.isfinite(value) else None


def dimension_from(length: int = 0, mass: int = 0, time: int = 0, angle: int = 0) -> Dimension:
    """A dimension from its exponents."""
    return Fraction(length), Fraction(mass), Fraction(time), Fraction(angle)


LENGTH, MASS, SPEED = dimension_from(1), dimension_from(mass=1), dimension_from(1, time=-1)
ANGLE, PURE = dimension_from(angle=1), dimension_from()
_NAMES = {LENGTH: "a length", MASS: "a mass", SPEED: "a speed", ANGLE: "an angle", PURE: "a pure number",
          dimension_from(time=1): "a time", dimension_from(1, time=-2): "an acceleration",
          dimension_from(1, 1, -1): "an impulse (a momentum)", dimension_from(2, 1, -2): "an energy"}


def dimension_name(dim: Dimension) -> str:
    """``a length``, ``a speed``, …, or the exponents for anything else."""
    if dim in _NAMES:
        return _NAMES[dim]
    parts = [f"{base}^{power}" if power != 1 else base
             for base, power in zip(("m", "kg", "s", "rad"), dim, strict=True) if power]
    return "*".join(parts)


def dimension_of(node: Node, known: Mapping[str, Dimension]) -> Dimension | None:
    """The dimension of an expression, or None where it depends on a name of unknown dimension;
    a sum of unlike dimensions raises :class:`GraderError`.

    >>> from grader.model.expr import parse
    >>> dimension_name(dimension_of(parse("sqrt(2*g*h)"), {"g": dimension_from(1, time=-2), "h": LENGTH}))
    'a speed'
    >>> dimension_of(parse("h + m"), {"h": LENGTH, "m": MASS})
    Traceback (most recent call last):
    ...
    grader.base.errors.GraderError: adds a length to a mass
    >>> dimension_of(parse("h**h"), {"h": LENGTH})
    Traceback (most recent call last):
    ...
    grader.base.errors.GraderError: raises to a power that is a length
    """
    if isinstance(node, Num):
        return PURE
    if isinstance(node, Sym):
        return PURE if node.name == "pi" else known.get(node.name)
    assert isinstance(node, Op)
    args = [dimension_of(arg, known) for arg in node.args]
    if node.op in ("add", "sub", "hypot", "Max", "Min", "abs", "neg"):
        found = [a for a in args if a is not None]
        if any(a != found[0] for a in found):
            other = next(a for a in found if a != found[0])
            raise GraderError(f"adds {dimension_name(found[0])} to {dimension_name(other)}")
        return found[0] if len(found) == len(args) else None
    found_all = [a for a in args if a is not None]
    if len(found_all) != len(args):
        return None
    first = found_all[0]
    if node.op in ("mul", "div"):
        sign = 1 if node.op == "mul" else -1
        return _scaled(first, 1, found_all[1], sign)
    if node.op == "pow":
        exponent = node.args[1]
        if isinstance(exponent, Num):
            return _scaled(first, Fraction(exponent.value))
        if found_all[1] != PURE:
            raise GraderError(f"raises to a power that is {dimension_name(found_all[1])}")
        if first != PURE:
            raise GraderError(f"raises {dimension_name(first)} to a power that is not a fixed number")
        return PURE
    if node.op == "sqrt":
        return _scaled(first, Fraction(1, 2))
    if node.op == "atan2":
        return ANGLE
    if first not in (PURE, ANGLE) or (first == ANGLE and node.op in ("exp", "log")):
        raise GraderError(f"takes {node.op} of {dimension_name(first)}")
    return PURE  # sin, cos, exp, log, …: a pure number


def _scaled(first: Dimension, power: Fraction | int, second: Dimension = PURE, sign: int = 1) -> Dimension:
    a, b, c, d = (p * power + sign * q for p, q in zip(first, second, strict=True))
    return a, b, c, d
