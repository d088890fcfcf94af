"""Units: one grammar, one table of exact units, and the words students may type layered on top.

A unit is read by :func:`unit_factors` (words joined by ``*``, ``·``, ``/``, ``per``, a space, or a hyphen
between two letters as in ``ft-lb``; a power after ``^`` or ``**``, or one digit glued to its word as in
``m/s2``), then each word is looked up. Templates, ``--set``, batch files and answer keys
(:func:`parse_unit`) may use the table's symbols and a few aliases; a student's cell
(:func:`unit_factor`) may also use names and plurals (``meters``, ``feet``), another letter case
(``KM/H``), SI prefixes (``µs``, ``MJ``), and a pound where only a mass fits the answer. Factors are
exact (a ``Fraction`` times a power of pi), so conversions folded into the solver's expressions cancel
exactly, and a pound is a force on both sides because the table says so.

>>> parse_unit("ft/s").factor, words(parse_unit("ft/s").dimension)
(Fraction(381, 1250), 'a speed')
>>> parse_unit("N·s").same_dimension(parse_unit("kg*m/s")), parse_unit("deg").pi_power
(True, 1)
>>> unit_factors("m/s^2"), unit_factors("meters per second"), unit_factors("x10^3")
((('m', 1), ('s', -2)), (('meters', 1), ('second', -1)), None)
>>> unit_factor("kN/m", "N/m"), round(unit_factor("ft-lb", "J"), 4), round(unit_factor("lbs", "kg"), 5)
(1000.0, 1.3558, 0.45359)
>>> unit_factor("kg", "m/s")
Traceback (most recent call last):
...
grader.model.quantities.units.UnitMismatchError: expected a speed (m/s), got a mass (kg)
"""

from __future__ import annotations

import functools
import math
import re
from dataclasses import dataclass
from fractions import Fraction

from grader.base.errors import GraderError
from grader.model.expr import CONSTANTS, FUNCTIONS
from grader.model.quantities.dimensions import (
    ANGLE,
    ENERGY,
    FORCE,
    LENGTH,
    MASS,
    PURE,
    TIME,
    Dimension,
    dimension,
    words,
)

MAX_POWER = 9
"""No unit of mechanics needs a higher power; bounds the exact factor's size."""
MAX_UNIT_TEXT = 40
"""Characters of a unit."""

Factors = tuple[tuple[str, int], ...]
"""A unit as (word, power) pairs: ``m/s^2`` is ``(("m", 1), ("s", -2))``."""

_POUND, _SLUG = Fraction("0.45359237"), Fraction("0.45359237") * Fraction("9.80665") / Fraction("0.3048")
_TABLE: dict[str, tuple[Fraction, int, Dimension]] = {
    "m": (Fraction(1), 0, LENGTH), "mm": (Fraction(1, 1000), 0, LENGTH), "cm": (Fraction(1, 100), 0, LENGTH),
    "km": (Fraction(1000), 0, LENGTH), "ft": (Fraction("0.3048"), 0, LENGTH), "in": (Fraction("0.0254"), 0, LENGTH),
    "mi": (Fraction("1609.344"), 0, LENGTH),
    "kg": (Fraction(1), 0, MASS), "g": (Fraction(1, 1000), 0, MASS), "Mg": (Fraction(1000), 0, MASS),
    "t": (Fraction(1000), 0, MASS), "lbm": (_POUND, 0, MASS), "slug": (_SLUG, 0, MASS),
    "s": (Fraction(1), 0, TIME), "ms": (Fraction(1, 1000), 0, TIME), "min": (Fraction(60), 0, TIME),
    "h": (Fraction(3600), 0, TIME),
    "N": (Fraction(1), 0, FORCE), "kN": (Fraction(1000), 0, FORCE), "lbf": (_POUND * Fraction("9.80665"), 0, FORCE),
    "lb": (_POUND * Fraction("9.80665"), 0, FORCE),  # in mechanics a pound is a force
    "J": (Fraction(1), 0, ENERGY), "kJ": (Fraction(1000), 0, ENERGY),
    "W": (Fraction(1), 0, dimension(2, 1, -3)),
    "rad": (Fraction(1), 0, ANGLE), "deg": (Fraction(1, 180), 1, ANGLE),
    "%": (Fraction(1, 100), 0, PURE), "1": (Fraction(1), 0, PURE),
}
"""The units grader knows, each exactly: ``value_SI = value * factor * pi**pi_power``. Products of them
(``N·m``, ``ft·lb``, ``N·s``) and quotients (``N/m``, ``lb/in``, ``kN/m``) need no entry."""
_ALIASES: dict[str, Factors] = {
    "°": (("deg", 1),), "mph": (("mi", 1), ("h", -1)), "hr": (("h", 1),), "sec": (("s", 1),),
}
"""Other names for the table's units, accepted everywhere."""
_STUDENT_WORDS: dict[str, Factors] = {
    **{word: ((symbol, 1),) for symbol, spelled in {
        "m": "meter meters metre metres", "mm": "millimeter millimeters millimetre millimetres",
        "cm": "centimeter centimeters centimetre centimetres", "km": "kilometer kilometers kilometre kilometres",
        "ft": "foot feet", "in": "inch inches", "mi": "mile miles",
        "kg": "kilogram kilograms kilo kilos", "g": "gram grams gramme grammes", "t": "tonne tonnes",
        "slug": "slugs", "s": "second seconds secs", "ms": "millisecond milliseconds msec",
        "min": "minute minutes mins", "h": "hour hours hrs",
        "N": "newton newtons", "kN": "kilonewton kilonewtons", "J": "joule joules",
        "kJ": "kilojoule kilojoules", "W": "watt watts",
        "deg": "degree degrees degs", "rad": "radian radians rads", "%": "percent",
        "lb": "lbs pound pounds",
    }.items() for word in spelled.split()},
    "fps": (("ft", 1), ("s", -1)), "kph": (("km", 1), ("h", -1)), "kmh": (("km", 1), ("h", -1)),
}
"""What students type besides the table's symbols and aliases: names, plurals, abbreviations."""
_PREFIXES = {"µ": Fraction(1, 10**6), "μ": Fraction(1, 10**6), "m": Fraction(1, 1000), "c": Fraction(1, 100),
             "k": Fraction(1000), "M": Fraction(10**6), "G": Fraction(10**9)}
_PREFIXED = frozenset({"m", "g", "s", "N", "J", "W"})
"""SI prefixes a student may put before a unit of the table (``µs``, ``MJ``, ``mN``)."""
_POUNDS = frozenset({"lb", "lbs", "pound", "pounds"})
"""Words read as pound-force, or as pound-mass where only that reading has the expected dimension."""
_NOT_UNITS = frozenset({"e", "E", "x", "X", "c", "k", "G", "R", "a", "per", *CONSTANTS, *FUNCTIONS})
"""Words that are constants or letters of a number (``2e3``, ``6x10^3``, ``2 pi``), never a unit."""

_TOKEN = re.compile(r"\s*(?:(?P<power>(?:\^|\*\*)\s*[-+]?\s*\d{1,2})|(?P<op>[*/·]|(?<=[A-Za-zµμ])-(?=[A-Za-zµμ]))"
                    r"|(?P<name>[A-Za-zµμ]+|°|%)(?P<bare>[1-9](?!\d))?)")

_POWER = re.compile(r"(?:\^|\*\*)\s*([-+]?\d+)")


class UnitMismatchError(ValueError):
    """A student's unit of another dimension than the expected one; the message is for the student."""


class UnknownUnitError(ValueError):
    """A student's unit that cannot be read or has a word no table knows; the message is for the student."""


@dataclass(frozen=True)
class Unit:
    """A unit: ``value_SI = value * factor * pi**pi_power``; ``text`` as it was written."""

    text: str
    factor: Fraction
    pi_power: int
    dimension: Dimension

    @property
    def to_si(self) -> float:
        """The conversion factor to SI as a float (deg -> rad included)."""
        return float(self.factor) * math.pi ** self.pi_power

    def same_dimension(self, other: Unit) -> bool:
        """Whether values in the two units can be converted into each other."""
        return self.dimension == other.dimension


def unit_factors(text: str) -> Factors | None:
    """The (word, power) pairs of a unit, or None when ``text`` is not one (or is empty).

    A ``/`` or ``per`` divides by the next word only; a unit may start with ``1/`` (``1/s``).
    """
    text = text.strip()
    if not text or len(text) > MAX_UNIT_TEXT:
        return None
    factors: list[list[str | int]] = []
    sign, position, expect_word, powered = 1, 0, True, False
    if re.match(r"1\s*/", text):
        factors.append(["1", 1])
        position, expect_word = 1, False
    while position < len(text):
        match = _TOKEN.match(text, position)
        if match is None or match.end() == position:
            return None
        position = match.end()
        if match["name"] is not None:
            word = match["name"]
            if word == "per" and not expect_word:
                sign, expect_word = -1, True
                continue
            if word in _NOT_UNITS:
                return None
            factors.append([word, sign * int(match["bare"] or 1)])
            sign, expect_word, powered = 1, False, match["bare"] is not None
        elif match["op"] is not None:
            if expect_word:
                return None
            sign, expect_word = (-1 if match["op"] == "/" else 1), True
        else:
            power = int(re.sub(r"[\s^*]", "", match["power"]))
            if expect_word or powered or power == 0 or abs(power) > MAX_POWER:
                return None
            factors[-1][1] = int(factors[-1][1]) * power
            powered = True
    if expect_word:
        return None
    return tuple((str(word), int(power)) for word, power in factors)


@functools.lru_cache(maxsize=256)
def parse_unit(text: str) -> Unit:
    """A unit of a template, ``--set``, a batch file or a key: the table's symbols and aliases
    (``m/s``, ``m/s^2``, ``kg*m/s``, ``N·s``, ``deg``, ``%``); empty (or ``-``) means a pure number.
    Raises :class:`GraderError` saying what is wrong."""
    if len(text) > MAX_UNIT_TEXT:
        raise GraderError(f"a unit of {len(text):,} characters; expected at most {MAX_UNIT_TEXT}")
    if text.strip() in ("", "-"):
        return Unit(text.strip(), Fraction(1), 0, PURE)
    factors = unit_factors(text)
    if factors is None:
        beyond = [power for power in map(int, _POWER.findall(text)) if abs(power) > MAX_POWER]
        if beyond:
            raise GraderError(f"the power {beyond[0]} in '{text}' is beyond what a unit of mechanics needs; "
                              f"expected powers from -{MAX_POWER} to {MAX_POWER}")
        raise GraderError(f"cannot read unit '{text}' (write units like m, m/s, m/s^2, kg, deg, %)")
    for word, _ in factors:
        if _expanded(word, lenient=False) is None:
            known = ", ".join(sorted(set(_TABLE) - {"1"}, key=str.lower))
            raise GraderError(f"unknown unit '{word}' in '{text}' (known: {known}, and products, quotients and "
                              "powers of them)")
    return _unit(text.strip(), factors, lenient=False)


@functools.lru_cache(maxsize=1024)
def unit_factor(given: str, expected: str) -> float:
    """The factor that turns a value in the unit ``given`` (a student's text) into ``expected`` (a key's unit).

    Raises :class:`UnitMismatchError` for another dimension, :class:`UnknownUnitError` for a unit that
    cannot be read or has an unknown word, and :class:`GraderError` when ``expected`` is not a unit (a bug
    in the key, not the student's doing).
    """
    factors = unit_factors(given)
    if factors is None:
        raise UnknownUnitError(f"cannot read the unit '{given}'")
    for word, _ in factors:
        if _expanded(word, lenient=True) is None:
            raise UnknownUnitError(f"unknown unit '{word}' (write units like m/s, ft/s, km/h, deg, rad, kg, J, %)")
    wanted, unit = parse_unit(expected), _unit(given.strip(), factors, lenient=True)
    if unit.dimension != wanted.dimension and _POUNDS.intersection(word for word, _ in factors):
        as_mass = _unit(unit.text, tuple(("lbm" if w in _POUNDS else w, p) for w, p in factors), lenient=True)
        if as_mass.dimension == wanted.dimension:  # "12 lb" where a mass is asked
            unit = as_mass
    if unit.dimension != wanted.dimension:
        said = words(wanted.dimension) + (f" ({wanted.text})" if wanted.text else "")
        raise UnitMismatchError(f"expected {said}, got {words(unit.dimension)} ({unit.text})")
    ratio, pi_power = unit.factor / wanted.factor, unit.pi_power - wanted.pi_power
    return ratio.numerator * math.pi ** max(pi_power, 0) / (ratio.denominator * math.pi ** max(-pi_power, 0))


def _expanded(word: str, *, lenient: bool) -> Factors | None:
    """The table's symbols a word stands for, or None for a word not known (on this side)."""
    if word in _TABLE:
        return ((word, 1),)
    if word in _ALIASES:
        return _ALIASES[word]
    if not lenient:
        return None
    for candidate in (word, word.lower()) if len(word) > 2 else (word,):
        if candidate in _TABLE:
            return ((candidate, 1),)
        if candidate in _ALIASES or candidate in _STUDENT_WORDS:
            return _ALIASES.get(candidate) or _STUDENT_WORDS[candidate]
    if len(word) > 1 and word[0] in _PREFIXES and word[1:] in _PREFIXED:
        return ((word, 1),)
    return None


def _unit(text: str, factors: Factors, *, lenient: bool) -> Unit:
    factor, pi_power, exponents = Fraction(1), 0, [Fraction(0)] * 4
    for word, power in factors:
        for symbol, times in _expanded(word, lenient=lenient) or ():
            if symbol in _TABLE:
                base_factor, base_pi, base_dimension = _TABLE[symbol]
            else:  # an SI prefix
                base_factor, base_pi, base_dimension = _TABLE[symbol[1:]]
                base_factor *= _PREFIXES[symbol[0]]
            factor *= base_factor ** (power * times)
            pi_power += base_pi * power * times
            exponents = [e + b * power * times for e, b in zip(exponents, base_dimension, strict=True)]
    return Unit(text, factor, pi_power, dimension(*exponents))
