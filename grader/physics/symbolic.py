"""The sympy side of the solver: custom functions, conversion to and from expression trees,
and the :class:`Context` through which effects see a scene's symbols.

Imported only when a template is compiled (the cache spares later runs the sympy import).

>>> import sympy as sp
>>> x = sp.Symbol("x", positive=True)
>>> to_node(hypot(-3 * x, 4))
Op(op='hypot', args=(Op(op='mul', args=(Num(value=Fraction(3, 1)), Sym(name='x'))), Num(value=Fraction(4, 1))))
>>> from_node(parse("sind(90) + cosd(theta)"), {})
cosd(theta) + 1
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from fractions import Fraction
from typing import Any

import sympy as sp

from grader.base.errors import TemplateError
from grader.model.expr import FUNCTIONS, Node, Num, Op, Sym, parse  # noqa: F401  (parse: doctest)
from grader.model.quantities import Unit
from grader.model.scene import Scene, Stage

INNER = "(compiled expression)"  # the ``where`` of an error raised without the template's file


class hypot(sp.Function):  # type: ignore[misc]  # noqa: N801  (named like the numpy function it becomes)
    """``sqrt(x**2 + y**2)`` without overflow; the sign of either argument does not matter."""

    nargs = 2

    @classmethod
    def eval(cls, x: Any, y: Any) -> Any:
        if x.is_zero:
            return sp.Abs(y)
        if y.is_zero:
            return sp.Abs(x)
        if x.could_extract_minus_sign():
            return cls(-x, y)
        if y.could_extract_minus_sign():
            return cls(x, -y)
        if x.is_Number and y.is_Number:
            return sp.sqrt(x**2 + y**2)
        common = common_positive_factor(x, y)
        if common != 1:
            return common * cls(x / common, y / common)
        return None

    def _eval_is_nonnegative(self) -> bool:
        return True


def common_positive_factor(x: Any, y: Any) -> Any:
    """The positive factor two expressions share, e.g. ``3*v`` of ``6*v*a`` and ``3*v``."""
    cx, rx = x.as_coeff_Mul()
    cy, ry = y.as_coeff_Mul()
    common = sp.Integer(1)
    if cx.is_Rational and cy.is_Rational and cx != 0 and cy != 0:
        common = sp.gcd(abs(cx), abs(cy))
    shared = [f for f in sp.Mul.make_args(rx) if f in sp.Mul.make_args(ry) and f.is_positive]
    return common * sp.Mul(*shared)


class sind(sp.Function):  # type: ignore[misc]  # noqa: N801
    """Sine of an angle in degrees, exact at multiples of 90 (reduced in degrees first)."""

    nargs = 1

    @classmethod
    def eval(cls, x: Any) -> Any:
        if x.is_Number:
            return sp.sin(x * sp.pi / 180)
        if x.could_extract_minus_sign():
            return -cls(-x)
        return None


class cosd(sp.Function):  # type: ignore[misc]  # noqa: N801
    """Cosine of an angle in degrees, exact at multiples of 90."""

    nargs = 1

    @classmethod
    def eval(cls, x: Any) -> Any:
        if x.is_Number:
            return sp.cos(x * sp.pi / 180)
        if x.could_extract_minus_sign():
            return cls(-x)
        return None


_SYMPY_FUNCTIONS: dict[str, Any] = {
    "sqrt": sp.sqrt, "sin": sp.sin, "cos": sp.cos, "tan": sp.tan, "exp": sp.exp, "log": sp.log,
    "abs": sp.Abs, "atan2": sp.atan2, "hypot": hypot, "sind": sind, "cosd": cosd, "Max": sp.Max, "Min": sp.Min,
    "sign": sp.sign,
}
_BINARY = {"add": lambda a, b: a + b, "sub": lambda a, b: a - b, "mul": lambda a, b: a * b,
           "div": lambda a, b: a / b, "pow": lambda a, b: a**b,
           "lt": sp.Lt, "le": sp.Le, "gt": sp.Gt, "ge": sp.Ge}


def from_node(node: Node, symbols: dict[str, sp.Symbol]) -> Any:
    """Build a sympy expression from a tree, with our own code (never ``sympify`` on text)."""
    if isinstance(node, Num):
        return sp.Rational(node.value.numerator, node.value.denominator) if isinstance(node.value, Fraction) \
            else sp.Float(node.value)
    if isinstance(node, Sym):
        if node.name == "pi":
            return sp.pi
        return symbols.get(node.name) or sp.Symbol(node.name, real=True)
    args = [from_node(a, symbols) for a in node.args]
    if node.op == "neg":
        return -args[0]
    if node.op in _BINARY:
        return _BINARY[node.op](*args)
    if node.op == "and":
        return sp.And(*args)
    if node.op == "or":
        return sp.Or(*args)
    return _SYMPY_FUNCTIONS[node.op](*args)


def to_node(expr: Any) -> Node:
    """Convert a sympy expression to a tree, writing quotients and square roots as such.

    >>> a, b = sp.symbols("a b", positive=True)
    >>> from grader.model.expr import to_text
    >>> to_text(to_node((a - b) / (2 * sp.sqrt(a))))
    '(a - b)/(2*sqrt(a))'
    """
    if isinstance(expr, sp.Symbol):
        return Sym(expr.name)
    if expr is sp.pi:
        return Sym("pi")
    if isinstance(expr, sp.Rational):
        return Num(Fraction(int(expr.p), int(expr.q)))
    if isinstance(expr, sp.Number) and not expr.is_finite:  # sympy's oo or nan: a 0/0 or 1/0 in the scene
        raise TemplateError(INNER, "stages or answers", "only real, finite expressions of functions the kernels know",
                            "a value that is infinite or undefined (a 0/0 or a division by zero: e.g. a body left at "
                            "rest that must move)")
    if isinstance(expr, sp.Number):
        return Num(float(expr))
    if isinstance(expr, sp.NumberSymbol):
        return Num(float(expr))
    if isinstance(expr, sp.Add):
        return _add(expr)
    if isinstance(expr, sp.Mul):
        return _mul(expr)
    if isinstance(expr, sp.Pow):
        return _pow(expr)
    if isinstance(expr, sp.Rel):
        name = {sp.StrictLessThan: "lt", sp.LessThan: "le", sp.StrictGreaterThan: "gt",
                sp.GreaterThan: "ge"}[type(expr)]
        return Op(name, (to_node(expr.lhs), to_node(expr.rhs)))
    if isinstance(expr, (sp.And, sp.Or)):
        return Op("and" if isinstance(expr, sp.And) else "or", tuple(to_node(a) for a in expr.args))
    if isinstance(expr, sp.atan):  # sympy's own rewriting of atan2(y, x) where x > 0: the same as atan2(y/x, 1)
        return Op("atan2", (to_node(expr.args[0]), Num(Fraction(1))))
    name = {sp.Abs: "abs", sp.atan2: "atan2"}.get(type(expr), type(expr).__name__)
    if name not in FUNCTIONS:
        words = _IN_WORDS.get(name, "a function no expression may call")
        made = (f"a value that is {words}" if not expr.args else f"a step the solver could only write with {words}, "
                "having solved for a quantity inside a function: give that quantity as a parameter, or name the "
                "function's result instead")
        raise TemplateError(INNER, "stages or answers", "only real, finite expressions of functions the kernels know",
                            made)
    args = tuple(to_node(a) for a in expr.args)
    if name in ("Max", "Min") and len(args) > 2:  # sympy's Max takes any number of arguments
        return Op(name, (args[0], to_node(type(expr)(*expr.args[1:]))))
    return Op(name, args)


_IN_WORDS = {"asin": "an inverse sine", "acos": "an inverse cosine", "acot": "an inverse cotangent",
             "asinh": "an inverse hyperbolic sine", "acosh": "an inverse hyperbolic cosine",
             "Piecewise": "cases", "re": "a real part", "im": "an imaginary part", "arg": "a complex argument",
             "LambertW": "Lambert's W", "floor": "a rounding down", "ceiling": "a rounding up",
             "ImaginaryUnit": "imaginary (the square root of a negative quantity)",
             "ComplexInfinity": "infinite (a division by zero)"}
"""What the solver may write that the kernels cannot compute, in words (the author wrote none of it)."""


def _add(expr: sp.Add) -> Node:
    terms = sorted(expr.as_ordered_terms(), key=lambda term: bool(term.could_extract_minus_sign()))
    result = to_node(terms[0])
    for term in terms[1:]:
        if term.could_extract_minus_sign():
            result = Op("sub", (result, to_node(-term)))
        else:
            result = Op("add", (result, to_node(term)))
    return result


def _mul(expr: sp.Mul) -> Node:
    numerator, denominator = sp.fraction(expr, exact=True)
    if denominator != 1:
        return Op("div", (to_node(numerator), to_node(denominator)))
    coefficient, rest = expr.as_coeff_Mul()
    if coefficient == -1:
        return Op("neg", (to_node(rest),))
    # c*x**2 as (c*x)*x: the square alone may under- or overflow where the product does not.
    factors = []
    for factor in sorted(sp.Mul.make_args(expr), key=lambda f: isinstance(f, sp.Pow) and f.exp == 2):
        base_twice = isinstance(factor, sp.Pow) and factor.exp == 2 and len(sp.Mul.make_args(expr)) > 1
        factors += [to_node(factor.base)] * 2 if base_twice else [to_node(factor)]
    result = factors[0]
    for factor in factors[1:]:
        result = Op("mul", (result, factor))
    return result


def _pow(expr: sp.Pow) -> Node:
    base, exponent = expr.args
    if exponent == sp.Rational(1, 2):
        return Op("sqrt", (to_node(base),))
    if exponent.is_negative:
        return Op("div", (Num(Fraction(1)), to_node(base**-exponent)))
    return Op("pow", (to_node(base), to_node(exponent)))


@dataclass
class Context:
    """What an effect sees while its relations are built: the scene's symbols and bodies."""

    scene: Scene
    symbols: dict[str, sp.Symbol] = field(default_factory=dict)
    defaults: dict[str, int] = field(default_factory=dict)  # default name -> the stage that owns it
    units: dict[str, Unit] = field(default_factory=dict)  # a parameter's unit, by name (a height in mm)

    def sym(self, node: Node) -> Any:
        """A stage field as a sympy expression over the scene's symbols."""
        return from_node(node, self.symbols)

    def symbol(self, name: str) -> sp.Symbol:
        """The symbol of a named quantity, created (real) on first use."""
        if name not in self.symbols:
            self.symbols[name] = sp.Symbol(name, real=True)
        return self.symbols[name]

    def gravity_symbol(self, stage: Stage) -> sp.Symbol:
        """``g``; a scene with flight must declare its value."""
        if self.scene.gravity is None:
            raise TemplateError(self.scene.where, f"stages[{stage.index}]",
                                "a top-level 'gravity' (like '9.81 m/s^2') for this effect")
        return self.symbols.setdefault("g", sp.Symbol("g", positive=True))

    def inverse_mass(self, body: str) -> Any:
        """``1/m`` of a body, 0 for a fixed one."""
        mass = self.scene.bodies[body].mass
        return sp.Integer(0) if mass is None else 1 / self.sym(mass)

    def mass(self, stage: Stage, body: str, key: str) -> Any:
        """A body's mass where the stage's field ``key`` needs one that moves; a fixed body is refused."""
        mass = self.scene.bodies[body].mass
        if mass is None:
            raise TemplateError(self.scene.where, f"stages[{stage.index}].{key}", "a body with a mass (one that "
                                "moves)", f"{body}, which is fixed")
        return self.sym(mass)

    def radius(self, body: str) -> Any:
        """A sphere's radius (the parser makes sure a stage that needs one has it)."""
        radius = self.scene.bodies[body].radius
        if radius is None:
            raise TemplateError(self.scene.where, f"bodies.{body}", "a radius (radius: EXPR)", "a point body")
        return self.sym(radius)

    def quantity(self, stage: Stage, key: str, defaults: Mapping[str, str]) -> sp.Symbol:
        """The symbol a stage names under ``key``, or its default name (``J``, ``T``, ...: the effect's
        field defaults)."""
        name = stage.fields.get(key)
        return self.symbol(name if isinstance(name, str) else self.unused_name(defaults[key], stage))

    def unused_name(self, base: str, stage: Stage) -> str:
        """``base``, unless the template or another stage uses it: then ``base_<stage index>``."""
        taken_by_template = base in self.scene.names() or (base in self.symbols and base not in self.defaults)
        if taken_by_template or self.defaults.get(base, stage.index) != stage.index:
            return f"{base}_{stage.index}"
        self.defaults[base] = stage.index
        return base

    def velocity(self, stage: Stage, body: str, when: str, axis: str) -> Any:
        """A velocity component of a body in an impact: 0 for a body at rest; a fixed body (infinite
        mass) keeps the velocity it is given before the impact (a plate moving at constant speed)."""
        if axis == "t" and not stage.is_oblique:
            return sp.Integer(0)
        if self.scene.bodies[body].mass is None:
            when = "before"
        given = stage.fields.get(when, {}).get(body)
        if given is not None and getattr(given, axis) is not None:
            return self.sym(getattr(given, axis))
        if when == "before":
            return sp.Integer(0)
        return self.symbol(self.unused_name(f"v_{body}_{axis}_after", stage))
