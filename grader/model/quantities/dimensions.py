"""Dimensions: exponents of length, mass, time and angle, the dimension of an expression, and the one
table that says a dimension in words (``a speed``) and as its SI unit (``m/s``).

Angle is a dimension of its own, so that ``30 deg`` is never taken for a pure number.

>>> from grader.model.expr import parse
>>> words(dimension_of(parse("sqrt(2*g*h)"), {"g": ACCELERATION, "h": LENGTH}))
'a speed'
>>> si_unit(dimension_of(parse("m*v*v/2"), {"m": MASS, "v": SPEED})), si_unit(dimension(1, 2, -1))
('J', 'kg²·m/s')
>>> dimension_of(parse("h + m"), {"h": LENGTH, "m": MASS})
Traceback (most recent call last):
...
grader.base.errors.GraderError: adds a length to a mass
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from fractions import Fraction

from grader.base.errors import GraderError
from grader.model.expr import Node, Num, Op, Sym

Dimension = tuple[Fraction, Fraction, Fraction, Fraction]
"""Exponents of (length, mass, time, angle)."""


def dimension(length: int | Fraction = 0, mass: int | Fraction = 0, time: int | Fraction = 0,
              angle: int | Fraction = 0) -> Dimension:
    """A dimension from its exponents."""
    return Fraction(length), Fraction(mass), Fraction(time), Fraction(angle)


def as_dimension(exponents: Sequence[int | Fraction]) -> Dimension:
    """A dimension from four exponents in the order of :data:`Dimension`."""
    return dimension(*exponents)


PURE, LENGTH, MASS, TIME, ANGLE = dimension(), dimension(1), dimension(mass=1), dimension(time=1), dimension(angle=1)
SPEED, ACCELERATION = dimension(1, time=-1), dimension(1, time=-2)
FORCE, IMPULSE, ENERGY = dimension(1, 1, -2), dimension(1, 1, -1), dimension(2, 1, -2)
STIFFNESS, POWER = dimension(mass=1, time=-2), dimension(2, 1, -3)

_TABLE: dict[Dimension, tuple[str, str]] = {
    PURE: ("a pure number", ""), LENGTH: ("a length", "m"), MASS: ("a mass", "kg"), TIME: ("a time", "s"),
    ANGLE: ("an angle", "rad"), SPEED: ("a speed", "m/s"), ACCELERATION: ("an acceleration", "m/s²"),
    FORCE: ("a force", "N"), IMPULSE: ("an impulse", "N·s"), ENERGY: ("an energy", "J"),
    STIFFNESS: ("a stiffness", "N/m"), POWER: ("a power", "W"),
    dimension(time=-1, angle=1): ("an angular speed", "rad/s"), dimension(time=-1): ("a rate (per time)", "1/s"),
}
"""Each dimension grader names: in words (errors, feedback, the effects reference) and its SI unit
(worked solutions). Any other dimension is said by its SI unit, built from the base units."""

_SUPERSCRIPT = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")


def words(dim: Dimension) -> str:
    """``a length``, ``a speed``, …; ``a quantity in kg·m²`` for a dimension without a name."""
    named = _TABLE.get(dim)
    return named[0] if named else f"a quantity in {si_unit(dim)}"


def si_unit(dim: Dimension | None) -> str:
    """The SI unit of a dimension as text: ``m/s``, ``N·s``, ``J``; products of ``kg``, ``m``, ``s`` and
    ``rad`` otherwise; ``""`` for a pure number or an unknown dimension (None)."""
    if dim is None:
        return ""
    dim = as_dimension(dim)
    if dim in _TABLE:
        return _TABLE[dim][1]
    up: list[str] = []
    down: list[str] = []
    for symbol, power in zip(("kg", "m", "s", "rad"), (dim[1], dim[0], dim[2], dim[3]), strict=True):
        if power == 0:
            continue
        size = abs(power)
        shown = symbol if size == 1 else symbol + (str(size).translate(_SUPERSCRIPT) if size.denominator == 1
                                                   else f"^({size})")
        (up if power > 0 else down).append(shown)
    return "·".join(up or ["1"]) + ("/" + "·".join(down) if down else "")


_ALIKE = frozenset({"add", "sub", "hypot", "Max", "Min", "abs", "neg"})
"""Operations whose arguments must share one dimension, which is the result's."""
_OF_PURE = frozenset({"sin", "cos", "tan", "sind", "cosd", "exp", "log", "lt", "le", "gt", "ge", "and", "or"})
"""Operations whose result is a pure number."""


def dimension_of(node: Node, known: Mapping[str, Sequence[int | Fraction]], *, strict: bool = True) -> Dimension | None:
    """The dimension of an expression from its names' dimensions, or None where it depends on a name of
    unknown dimension.

    Strict (a template's expressions, checked when the bank is read): a sum of unlike dimensions, a power
    whose exponent has a dimension or a function of a dimensioned quantity raises :class:`GraderError`.
    Lenient (the solver's step chain, shown in worked solutions): what cannot be told is None, and a bare
    number in a sum takes the other terms' dimension (``Max(0, h - h')`` is a length).

    >>> from grader.model.expr import parse
    >>> dimension_of(parse("Max(0, h)"), {"h": LENGTH}, strict=False) == LENGTH
    True
    >>> dimension_of(parse("h**h"), {"h": LENGTH})
    Traceback (most recent call last):
    ...
    grader.base.errors.GraderError: raises to a power that is a length
    """
    if isinstance(node, Num):
        return PURE
    if isinstance(node, Sym):
        found = PURE if node.name == "pi" else known.get(node.name)
        return None if found is None else as_dimension(found)
    assert isinstance(node, Op)
    args = [dimension_of(arg, known, strict=strict) for arg in node.args]
    if node.op in _ALIKE:
        return _alike(args, node.args, strict)
    if not strict and node.op in _OF_PURE:
        return PURE
    if node.op == "atan2" and not strict:
        return ANGLE
    if None in args:
        return None
    dims = [a for a in args if a is not None]
    if node.op in ("mul", "div"):
        sign = 1 if node.op == "mul" else -1
        return as_dimension([a + sign * b for a, b in zip(dims[0], dims[1], strict=True)])
    if node.op == "sqrt":
        return _scaled(dims[0], Fraction(1, 2))
    if node.op == "pow":
        exponent = node.args[1]
        if isinstance(exponent, Num):
            return _scaled(dims[0], Fraction(exponent.value))
        if not strict:
            return PURE if dims[0] == PURE else None
        if dims[1] != PURE:
            raise GraderError(f"raises to a power that is {words(dims[1])}")
        if dims[0] != PURE:
            raise GraderError(f"raises {words(dims[0])} to a power that is not a fixed number")
        return PURE
    if not strict:
        return None
    if node.op == "atan2":
        return ANGLE
    if dims[0] not in (PURE, ANGLE) or (dims[0] == ANGLE and node.op in ("exp", "log")):
        raise GraderError(f"takes {node.op} of {words(dims[0])}")
    return PURE  # sin, cos, exp, log, …: a pure number


def _alike(args: list[Dimension | None], nodes: Sequence[Node], strict: bool) -> Dimension | None:
    if strict:
        found = [a for a in args if a is not None]
        other = next((a for a in found if a != found[0]), None)
        if other is not None:
            raise GraderError(f"adds {words(found[0])} to {words(other)}")
        return found[0] if len(found) == len(args) else None
    shaped = {a for a, node in zip(args, nodes, strict=True) if a is not None and not isinstance(node, Num)}
    if len(shaped) == 1:
        return next(iter(shaped))
    return PURE if not shaped and None not in args else None


def _scaled(dim: Dimension, power: Fraction) -> Dimension:
    return as_dimension([d * power for d in dim])
