"""Safe expressions: the allow-list holds, limits hold, printing round-trips; units convert exactly."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
import sympy as sp

from grader.base.errors import ExpressionError, GraderError
from grader.model.expr import MAX_DEPTH, MAX_LENGTH, format_number, parse, to_text
from grader.model.kernel import cosd, evaluate, sind
from grader.model.quantities import parse_unit
from grader.physics.symbolic import from_node

REFUSED = [
    ("__import__('os').system('ls')", "is not an allowed function"),
    ("().__class__", "is not allowed in an expression"),
    ("open('x')", "'open' is not an allowed function"),
    ("x.real", "is not allowed"),
    ("lambda: 1", "is not allowed"),
    ("[1, 2]", "is not allowed"),
    ("'text'", "is not a number"),
    ("True", "is not a number"),
    ("2**1000", "exponent 1000 is larger than 64"),
    ("x**" + "9" * 400, "exponent " + "9" * 20 + "… is larger than 64"),  # float() of it overflowed: a traceback
    ("x if y else z", "is not allowed"),
    ("x < 1", "is not allowed"),
    ("sqrt(1, 2)", "sqrt() takes 1 argument"),
    ("sin(x=1)", "sin() takes 1 argument"),
    ("1 +", "is not a valid expression"),
    ("", "expression is empty"),
    ("x" * (MAX_LENGTH + 1), f"at most {MAX_LENGTH} are allowed"),
    ("sqrt(" * (MAX_DEPTH + 5) + "x" + ")" * (MAX_DEPTH + 5), "nested more than"),
    ("(" * 240 + "x" + ")" * 240, "is not a valid expression"),
    ("-" * 490 + "x", "nested more than"),
    ("-" * (MAX_DEPTH + 5) + "x", "nested more than"),
]


@pytest.mark.parametrize(("text", "reason"), REFUSED, ids=[r for _, r in REFUSED])
def test_disallowed_text_is_refused_with_the_reason(text: str, reason: str) -> None:
    """Anything outside numbers, names, arithmetic and the listed functions is refused."""
    with pytest.raises(ExpressionError, match=None) as error:
        parse(text)
    assert reason in str(error.value)


ROUND_TRIP = ["v*(1 - e*p)/(p + 1)", "a - (b - c)", "a/(b*c)", "-x**2", "(-x)**2", "2**3**2", "(2**3)**2",
              "hypot(a, -b)/sqrt(2*g*h)", "1.1*v/(p + 1)", "-(a + b)", "a*-b", "atan2(y, x)*180/pi"]


@pytest.mark.parametrize("text", ROUND_TRIP)
def test_printed_text_parses_back_to_the_same_value(text: str) -> None:
    """to_text(parse(s)) means what s means, for sympy as for our kernels."""
    names = {n: sp.Symbol(n, positive=True) for n in "abcehgpvxy"}
    printed = to_text(parse(text))
    assert sp.simplify(from_node(parse(printed), names) - from_node(parse(text), names)) == 0
    env = {n: np.float64(0.37 + i / 7) for i, n in enumerate("abcehgpvxy")}
    assert evaluate(parse(printed), env) == pytest.approx(evaluate(parse(text), env), rel=1e-15)


def test_caret_is_power_with_power_precedence() -> None:
    """Students write v^2 + 1: that is (v**2) + 1, not v xor 3."""
    assert to_text(parse("v^2 + 1")) == "v**2 + 1"


@pytest.mark.parametrize(("value", "text"), [
    (Fraction(1, 10), "0.1"), (Fraction(-11, 10), "-1.1"), (Fraction(1, 3), "1/3"), (Fraction(7), "7"),
    (0.1 + 0.2, "0.30000000000000004"), (Fraction(3, 8), "0.375"),
])
def test_numbers_print_exactly(value: Fraction | float, text: str) -> None:
    """Exact decimals print as decimals, other fractions as a ratio, floats in full."""
    assert format_number(value) == text


@pytest.mark.parametrize("degrees", [0.0, 30.0, 45.0, 90.0, 180.0, 270.0, -90.0, 360.0, 720.0, 89.9999999, 1e-9])
def test_degree_trig_is_exact_at_right_angles_and_accurate_near_them(degrees: float) -> None:
    """sind/cosd agree with mpmath-free exact values at multiples of 90 and with sympy elsewhere."""
    exact_sin = sp.sin(sp.Rational(degrees) * sp.pi / 180)
    exact_cos = sp.cos(sp.Rational(degrees) * sp.pi / 180)
    assert float(sind(np.float64(degrees))) == pytest.approx(float(exact_sin.evalf(30)), rel=1e-15, abs=1e-300)
    assert float(cosd(np.float64(degrees))) == pytest.approx(float(exact_cos.evalf(30)), rel=1e-15, abs=1e-300)


@pytest.mark.parametrize(("unit", "factor", "dimension"), [
    ("mm", Fraction(1, 1000), (1, 0, 0, 0)), ("ft/s", Fraction("0.3048"), (1, 0, -1, 0)),
    ("km/h", Fraction(1000, 3600), (1, 0, -1, 0)), ("m/s^2", Fraction(1), (1, 0, -2, 0)),
    ("kg*m/s", Fraction(1), (1, 1, -1, 0)), ("%", Fraction(1, 100), (0, 0, 0, 0)), ("", Fraction(1), (0, 0, 0, 0)),
    ("mph", Fraction("1609.344") / 3600, (1, 0, -1, 0)), ("ft*lbf", Fraction("0.3048") * Fraction("4.4482216152605"),
                                                          (2, 1, -2, 0)),
])
def test_units_convert_to_si_exactly(unit: str, factor: Fraction, dimension: tuple[int, ...]) -> None:
    """Conversion factors are exact fractions of the SI unit."""
    parsed = parse_unit(unit)
    assert (parsed.factor, parsed.dimension) == (factor, dimension)


@pytest.mark.parametrize("unit", ["furlong", "m//s", "/s", "m^x"])
def test_unknown_or_malformed_units_are_refused(unit: str) -> None:
    """A unit we cannot read is an error that quotes it."""
    with pytest.raises(GraderError, match=unit.replace("^", r"\^").replace("/", "/")):
        parse_unit(unit)


@pytest.mark.parametrize("data", [
    ["__import__", "x"], ["div", "x"], ["neg", "x", "y"], ["and", "x"], [], [1, "x"], {"q": [1, 0]}, {"q": [True, 1]},
    {"q": [1.5, 2]}, {"q": [1]}, {"f": "1e5"}, {"f": float("nan")}, {"f": 1}, {"q": [1, 2], "f": 0.5}, {}, 1, None,
    True, ("add", "x", "y"),
], ids=repr)
def test_a_tree_read_from_json_is_one_to_json_writes_or_refused(data: object) -> None:
    """A compiled template's trees come from the cache: an unknown operation or a wrong number of arguments failed
    only when the kernel was built (KeyError), a zero denominator was a ZeroDivisionError, a NaN an ExpressionError
    (exit 2, naming no file); a number written as text was read as one."""
    from grader.model.expr import from_json

    with pytest.raises(ValueError, match="not an expression tree"):
        from_json(data)


@pytest.mark.parametrize("text", ["hypot(a, -2.5*b)", "h_r <= h and h > 0 or x < 1 and y > 2 and z >= 0",
                                  "sind(x)**2 + Max(1/3, Min(x, 2))", "atan2(y, x) - pi"])
def test_every_tree_reads_back_from_json(text: str) -> None:
    import json

    from grader.model.expr import from_json, to_json

    tree = parse(text, allow_compare=True)
    assert from_json(json.loads(json.dumps(to_json(tree)))) == tree
