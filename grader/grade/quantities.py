"""Units students type after a number: read by our own grammar, resolved and converted by pint.

pint never sees a student's text whole. :func:`unit_factors` reads the unit with a strict grammar
(words of letters, ``*``, ``/``, ``per``, powers after ``^`` or ``**``); pint is then asked about one
word at a time (``"foot"``, ``"second"``), never to evaluate a string. The registry is built on the
first conversion, so importing this module does not import pint.

>>> unit_factors("m/s^2"), unit_factors("meters per second"), unit_factors("kg m")
((('m', 1), ('s', -2)), (('meters', 1), ('second', -1)), (('kg', 1), ('m', 1)))
>>> unit_factors("x10^3") is None, unit_factors("m s 2") is None
(True, True)
>>> round(unit_factor("ft/sec", "m/s"), 6), unit_factor("%", ""), round(unit_factor("rad", "deg"), 4)
(0.3048, 0.01, 57.2958)

A pound is a force, as the templates' ``lb`` is, unless only a mass fits the answer:

>>> round(unit_factor("lb", "N"), 4), round(unit_factor("ft*lb", "J"), 4), round(unit_factor("lbs", "kg"), 5)
(4.4482, 1.3558, 0.45359)
>>> unit_factor("kg", "m/s")
Traceback (most recent call last):
...
grader.grade.quantities.UnitMismatchError: expected a speed (m/s), got a mass (kg)
"""

from __future__ import annotations

import functools
import re
from typing import Any

from grader.base.errors import GraderError
from grader.model.expr import CONSTANTS, FUNCTIONS

MAX_UNIT_TEXT = 40
MAX_POWER = 9  # no unit of mechanics needs more

Factors = tuple[tuple[str, int], ...]
"""A unit as (word, power) pairs: ``m/s^2`` is ``(("m", 1), ("s", -2))``."""

_TOKEN = re.compile(r"\s*(?:(?P<power>(?:\^|\*\*)\s*[-+]?\s*\d{1,2})|(?P<op>[*/·]|(?<=[A-Za-zµμ])-(?=[A-Za-zµμ]))"
                    r"|(?P<name>[A-Za-zµμ]+|°|%)(?P<bare>[1-9](?!\d))?)")
# Words pint knows that are constants or letters of a number (2e3, 6x10^3, 2 pi), never a student's unit.
_NOT_UNITS = frozenset({"e", "E", "x", "X", "c", "k", "G", "R", "a", "per", *CONSTANTS, *FUNCTIONS})
_ALIASES: dict[str, Factors] = {
    "°": (("degree", 1),), "%": (("percent", 1),), "deg": (("degree", 1),), "degs": (("degree", 1),),
    "fps": (("foot", 1), ("second", -1)), "mph": (("mile", 1), ("hour", -1)),
    "kph": (("kilometer", 1), ("hour", -1)), "kmh": (("kilometer", 1), ("hour", -1)),
    "secs": (("second", 1),), "hrs": (("hour", 1),), "lbm": (("pound", 1),),
    # In mechanics a pound is a force, as in the templates' units (grader.model.units); pint's is a mass.
    "lb": (("pound_force", 1),), "lbs": (("pound_force", 1),), "pound": (("pound_force", 1),),
    "pounds": (("pound_force", 1),),
}
_POUNDS = frozenset({"lb", "lbs", "pound", "pounds"})
"""Words read as pound-force, or as pound-mass where only that reading has the expected dimension."""
_L, _M, _T = "[length]", "[mass]", "[time]"
_DESCRIPTIONS = {
    ((), 0): "a pure number", ((), 1): "an angle", (((_L, 1),), 0): "a length", (((_M, 1),), 0): "a mass",
    (((_T, 1),), 0): "a time", (((_L, 1), (_T, -1)), 0): "a speed", (((_L, 1), (_T, -2)), 0): "an acceleration",
    (((_L, 1), (_M, 1), (_T, -2)), 0): "a force", (((_L, 2), (_M, 1), (_T, -2)), 0): "an energy",
    (((_L, 1), (_M, 1), (_T, -1)), 0): "an impulse", (((_L, 2), (_M, 1), (_T, -3)), 0): "a power",
    (((_T, -1),), 1): "an angular speed", (((_T, -1),), 0): "a rate (per time)",
}


class UnitMismatchError(ValueError):
    """A unit of another dimension than the expected one; the message is for the student."""


class UnknownUnitError(ValueError):
    """A unit word that no unit registry knows; the message is for the student."""


def unit_factors(text: str) -> Factors | None:
    """The (word, power) pairs of a unit as students write it, or None when ``text`` is not one.

    Words are letters (``°``, ``%`` and ``µ`` included), joined by ``*``, ``·``, ``/``, ``per``, a
    space or a hyphen between two letters (``ft-lb``, ``N-s``, as textbooks print them); a power follows
    ``^`` or ``**`` (``m/s^2``), or is one digit glued to the word (``m/s2``).
    A ``/`` or ``per`` divides by the next word only.
    """
    text = text.strip()
    if not text or len(text) > MAX_UNIT_TEXT:
        return None
    factors: list[list[Any]] = []
    sign, position, expect_word, powered = 1, 0, True, False
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
            factors[-1][1] *= power
            powered = True
    if expect_word:
        return None
    return tuple((word, power) for word, power in factors)


def unit_factor(given: str, expected: str) -> float:
    """The factor that turns a value in the unit ``given`` (student text) into ``expected`` (a key's unit).

    Raises :class:`UnitMismatchError` for another dimension (angles are a dimension of their own here,
    unlike in pint), :class:`UnknownUnitError` for a word no registry knows, and :class:`GraderError`
    when ``expected`` is not a unit (a bug in the key, not the student's doing).
    """
    given_factors = unit_factors(given)
    if given_factors is None:
        raise UnknownUnitError(f"cannot read the unit '{given}'")
    expected_factors = _expected(expected)
    if _canonical(given_factors) == _canonical(expected_factors):
        return 1.0  # the common case, without pint
    given_unit, expected_unit = _resolve(given_factors), _resolve(expected_factors)
    if _dimension(given_unit) != _dimension(expected_unit) and _POUNDS.intersection(w for w, _ in given_factors):
        as_mass = tuple(("lbm" if word in _POUNDS else word, power) for word, power in given_factors)
        if _dimension(_resolve(as_mass)) == _dimension(expected_unit):  # "12 lb" where a mass is asked
            given_factors, given_unit = as_mass, _resolve(as_mass)
    if _dimension(given_unit) != _dimension(expected_unit):
        wanted = describe(_dimension(expected_unit)) + (f" ({expected.strip()})" if expected.strip() else "")
        raise UnitMismatchError(f"expected {wanted}, got {describe(_dimension(given_unit))} ({given.strip()})")
    return _conversion(given_factors, expected_factors)


def describe(dimension: tuple[tuple[tuple[str, int], ...], int]) -> str:
    """``a speed``, ``an angle``, …; the dimension's base quantities for anything rarer."""
    if dimension in _DESCRIPTIONS:
        return _DESCRIPTIONS[dimension]
    parts = [f"{base.strip('[]')}^{power}" if power != 1 else base.strip("[]") for base, power in dimension[0]]
    if dimension[1]:
        parts.append(f"angle^{dimension[1]}" if dimension[1] != 1 else "angle")
    return "a quantity of " + " * ".join(parts)


@functools.lru_cache(maxsize=64)
def _expected(text: str) -> Factors:
    if not text.strip():
        return ()
    factors = unit_factors(text)
    if factors is None:
        raise GraderError(f"the answer key's unit '{text}' is not a unit (expected units like m/s, deg, kJ)")
    return factors


def _canonical(factors: Factors) -> Factors:
    return tuple(sorted((name, power * times) for word, power in factors
                        for name, times in _ALIASES.get(word, ((word, 1),))))


@functools.cache
def registry() -> Any:
    """pint's unit registry, built once, on first use."""
    import pint  # lazy: importing the grader must not cost pint's start-up

    return pint.UnitRegistry()


@functools.lru_cache(maxsize=1024)
def _word(word: str) -> Any:
    """The pint unit of one word; pint is asked about letters only."""
    reg = registry()
    for candidate in (word, word.lower()) if len(word) > 2 else (word,):
        try:
            if candidate in reg:
                return reg.Unit(candidate)
        except Exception:  # noqa: S112 (any failure inside pint means: not a unit)
            continue
    raise UnknownUnitError(f"unknown unit '{word}' (write units like m/s, ft/s, km/h, deg, rad, kg, J, %)")


@functools.lru_cache(maxsize=1024)
def _resolve(factors: Factors) -> Any:
    unit = registry().Unit("dimensionless")
    for name, power in _canonical(factors):
        unit = unit * _word(name) ** power
    return unit


def _dimension(unit: Any) -> tuple[tuple[tuple[str, int], ...], int]:
    """pint's dimensionality plus the power of angle (pint counts radians as dimensionless)."""
    _, root = registry().get_root_units(unit)
    dims = tuple(sorted((str(base), int(power)) for base, power in dict(unit.dimensionality).items()))
    return dims, int(dict(root._units).get("radian", 0))


@functools.lru_cache(maxsize=1024)
def _conversion(given: Factors, expected: Factors) -> float:
    reg = registry()
    try:
        return float(reg.Quantity(1.0, _resolve(given)).to(_resolve(expected)).magnitude)
    except Exception as error:  # an offset unit (degC) or anything else pint cannot scale
        into = _describe_factors(expected)
        raise UnknownUnitError(f"cannot convert {_describe_factors(given)} into {into}") from error


def _describe_factors(factors: Factors) -> str:
    return "*".join(word if power == 1 else f"{word}^{power}" for word, power in factors) or "a pure number"
