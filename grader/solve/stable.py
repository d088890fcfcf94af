"""Rewrites that keep a composed expression accurate in float64 (docs/design.md, Numerics).

Each rewrite is an identity; together they make sure differences of nearly equal inputs are
formed first and that no intermediate product overflows where the answer does not. Most work on
sympy expressions (:func:`stabilize`); two on the numeric tree, whose evaluation order sympy
would not keep (:func:`numeric_order`).

>>> import sympy as sp
>>> a, b, g = sp.symbols("a b g", positive=True)
>>> root_differences(sp.sqrt(2*g*a) - sp.sqrt(2*g*b))
sqrt(2)*sqrt(g)*(a - b)/(sqrt(a) + sqrt(b))
>>> m, M, x = sp.symbols("m M x", positive=True)
>>> positive_factors_out_of_max(sp.Max(0, m * (x - a)))
m*Max(0, -a + x)
>>> absorb_reciprocals(a * m * (1/m + 1/M))
a*(1 + m/M)
"""

from __future__ import annotations

import itertools
from collections.abc import Iterable
from fractions import Fraction
from typing import Any

import sympy as sp

from grader.model.expr import Node, Num, Op, Sym, names
from grader.physics.symbolic import common_positive_factor, cosd, sind


def stabilize(expr: Any, degree_angles: Iterable[Any] = ()) -> Any:
    """All rewrites, repeated until none changes anything (each can expose work for another)."""
    result = expr
    for _ in range(4):
        previous = result
        result = absorb_reciprocals(positive_factors_out_of_max(root_differences(cancel_fraction_sums(result))))
        result = drop_common_factors(sp.factor_terms(result))
        if result == previous:
            break
    for angle in degree_angles:
        result = result.subs(sind(angle) ** 2 + cosd(angle) ** 2, 1)
    return result


def _root_ratio(ratio: Any) -> tuple[Any, Any] | None:
    """``(x, y)`` if ``ratio`` is ``-sqrt(x)/sqrt(y)``, else None."""
    if not ratio.could_extract_minus_sign():
        return None
    numerator, denominator = sp.fraction(-ratio)
    if (isinstance(numerator, sp.Pow) and numerator.exp == sp.Rational(1, 2)
            and isinstance(denominator, sp.Pow) and denominator.exp == sp.Rational(1, 2)):
        return numerator.base, denominator.base
    return None


def _pair_roots(add: sp.Add) -> Any:
    terms = list(add.args)
    for i, first in enumerate(terms):
        for j in range(i + 1, len(terms)):
            second = terms[j]
            found = _root_ratio(first / second)
            if found is None:
                continue
            x, y = found
            # first + second = second*(1 - sqrt(x)/sqrt(y)) = -second*(x - y)/(sqrt(y)*(sqrt(x) + sqrt(y)))
            combined = -second * (x - y) / (sp.sqrt(y) * (sp.sqrt(x) + sp.sqrt(y)))
            rest = [t for k, t in enumerate(terms) if k not in (i, j)]
            return sp.Add(combined, *rest)
    return add


def root_differences(expr: Any) -> Any:
    """``k sqrt(x) - k sqrt(y)`` becomes ``k (x - y)/(sqrt(x) + sqrt(y))``: the radicands'
    difference is formed first (exact when they are close), so no rounded roots cancel."""
    return expr.replace(lambda e: isinstance(e, sp.Add), _pair_roots)


def _cancelled(add: sp.Add) -> Any:
    if not any(isinstance(sp.fraction(term)[1], sp.Add) for term in add.args) or not add.is_rational_function():
        return add
    combined = sp.factor(sp.together(add))
    return combined if not isinstance(sp.fraction(combined)[0], sp.Add) else add


def cancel_fraction_sums(expr: Any) -> Any:
    """A sum of fractions that cancels to a product, ``1 - 1/(1 + x) + e/(1/x + 1)``, is written as that
    product, ``x*(e + 1)/(x + 1)``: the sum cancels in float64 where ``x`` is tiny (a sphere 10**12 times
    heavier than the one it strikes turns by ``x`` times its angle), the product keeps full accuracy.
    A sum whose numerator stays a sum (a true difference, ``e*x - 1``) is left as it is.

    >>> x, e = sp.symbols("x e", positive=True)
    >>> cancel_fraction_sums(1 - 1/(1 + x) + e/(1/x + 1))
    x*(e + 1)/(x + 1)
    """
    return expr.replace(lambda e: isinstance(e, sp.Add), _cancelled)


def _pull_out(node: Any) -> Any:
    if len(node.args) != 2 or 0 not in node.args:
        return node
    inner = sp.factor_terms(node.args[1] if node.args[0] == 0 else node.args[0])
    outside = [f for f in sp.Mul.make_args(inner) if f.is_positive]
    return sp.Mul(*outside) * type(node)(0, sp.Mul(*[f for f in sp.Mul.make_args(inner) if not f.is_positive]))


def positive_factors_out_of_max(expr: Any) -> Any:
    """``Max(0, m*x)`` becomes ``m*Max(0, x)`` for ``m > 0``, so ``m`` can cancel outside."""
    return expr.replace(lambda e: isinstance(e, (sp.Max, sp.Min)), _pull_out)


def _absorb(mul: sp.Mul) -> Any:
    # sympy keeps a/(m*(1/m + 1/M)) as a * m**-1 * (1/m + 1/M)**-1: pair equal powers of both.
    factors = list(mul.args)
    for i, factor in enumerate(factors):
        total, power = factor.as_base_exp()
        if not (isinstance(total, sp.Add) and power in (1, -1)):
            continue
        for j, other in enumerate(factors):
            symbol, symbol_power = other.as_base_exp()
            if (isinstance(symbol, sp.Symbol) and symbol.is_positive and symbol_power == power
                    and any(sp.Pow(symbol, -1) in sp.Mul.make_args(t) for t in total.args)):
                spread = sp.Add(*[symbol * t for t in total.args])
                others = [f for k, f in enumerate(factors) if k not in (i, j)]
                return sp.Mul(sp.Pow(spread, power), *others)
    return mul


def absorb_reciprocals(expr: Any) -> Any:
    """``m*(1/m + 1/M)`` becomes ``1 + m/M``: the product ``m*...`` of large values could
    overflow where the answer does not."""
    return expr.replace(lambda e: isinstance(e, sp.Mul), _absorb)


def drop_common_factors(expr: Any) -> Any:
    """``atan2(k*y, k*x)`` is ``atan2(y, x)`` for ``k > 0``: write it so."""
    def simpler(node: Any) -> Any:
        common = common_positive_factor(*node.args)
        return sp.atan2(node.args[0] / common, node.args[1] / common) if common != 1 else node
    return expr.replace(lambda e: isinstance(e, sp.atan2), simpler)


# --- the numeric tree ---------------------------------------------------------------------------

def numeric_order(node: Node) -> Node:
    """A compiled tree with the rewrites below applied, innermost first.

    >>> from grader.model.expr import parse
    >>> numeric_order(parse("h1**2/h2")) == parse("(h1/h2)*h1")
    True
    >>> numeric_order(parse("v1 + w - 2*v2 - x")) == parse("((v1 - v2) + (w - v2)) - x")
    True
    """
    if not isinstance(node, Op):
        return node
    node = Op(node.op, tuple(numeric_order(arg) for arg in node.args))
    if node.op == "div":
        return constants_over(balance_quotient(node))
    if node.op in ("add", "sub"):
        return differences_first(node)
    if node.op == "mul":
        return constants_first(node)
    return node


CONSTANT_NAMES = frozenset({"g", "pi"})
"""Names a compiled tree may hold that are no parameter: their values are known when it is compiled."""


def constants_first(node: Op) -> Node:
    """A product whose constant factors (numbers, ``g``, ``pi``) are not all in front, with them in front
    and in their order, then the others in theirs: the kernel multiplies the constants once, when it is
    built, instead of one numpy call per constant on every evaluation (sympy's order puts ``sqrt(g)``
    among the parameters' roots).

    >>> from grader.model.expr import parse, to_text
    >>> to_text(constants_first(parse("18*sqrt(2)*sqrt(d)*sqrt(g)*sqrt(mu)*(a + b)")))
    '18*sqrt(2)*sqrt(g)*sqrt(d)*sqrt(mu)*(a + b)'
    >>> constants_first(parse("2*sqrt(g)*h")) == parse("2*sqrt(g)*h")
    True
    """
    factors = _factors(node, powers=False)
    fixed = [factor for factor in factors if names(factor) <= CONSTANT_NAMES]
    if not fixed or len(fixed) == len(factors) or factors[:len(fixed)] == fixed:
        return node
    return _product(fixed + [factor for factor in factors if not names(factor) <= CONSTANT_NAMES])


def constants_over(node: Node) -> Node:
    """A quotient whose numerator starts with constants and whose denominator holds some too, with the
    denominator's constants divided into the numerator's: one constant the kernel makes when it is
    built, instead of a numpy call for ``5*m_A`` on every evaluation.

    >>> from grader.model.expr import parse, to_text
    >>> to_text(constants_over(parse("18*sqrt(g)*d*(a + b)/(5*a)")))
    '18*sqrt(g)/5*d*(a + b)/a'
    """
    if not (isinstance(node, Op) and node.op == "div"):
        return node
    over, under = (_factors(side, powers=False) for side in node.args)
    fixed_over = len(list(itertools.takewhile(lambda factor: names(factor) <= CONSTANT_NAMES, over)))
    fixed_under = [factor for factor in under if names(factor) <= CONSTANT_NAMES]
    if not fixed_over or fixed_over == len(over) or not fixed_under or len(fixed_under) == len(under):
        return node
    constant = Op("div", (_product(over[:fixed_over]), _product(fixed_under)))
    rest = [factor for factor in under if not names(factor) <= CONSTANT_NAMES]
    return Op("div", (_product([constant, *over[fixed_over:]]), _product(rest)))


def _product(factors: list[Node]) -> Node:
    """The factors multiplied left to right."""
    product = factors[0]
    for factor in factors[1:]:
        product = Op("mul", (product, factor))
    return product


def _factors(node: Node, powers: bool = True) -> list[Node]:
    """The factors of a product tree; with ``powers``, a power of a name written out (``h**2*x``:
    ``[h, h, x]``)."""
    if isinstance(node, Op) and node.op == "mul":
        return _factors(node.args[0], powers) + _factors(node.args[1], powers)
    if powers and isinstance(node, Op) and node.op == "pow" and isinstance(node.args[0], Sym) \
            and isinstance(node.args[1], Num) and node.args[1].value in (2, 3, 4):
        return [node.args[0]] * int(node.args[1].value)
    return [node]


def balance_quotient(node: Op) -> Node:
    """A quotient that holds a power of a name (``h1**2/h2``) as a product of ratios (``(h1/h2)*h1``),
    so that no partial product over- or underflows where the quotient does not (``h1 = 1e170``:
    ``h1**2`` overflows, the quotient ``1.7e170`` does not).

    >>> from grader.model.expr import parse, to_text
    >>> to_text(balance_quotient(parse("100*x*h2/h1**2")))
    '100*(x/h1)*(h2/h1)'
    """
    if all(len(_factors(side)) == len(_factors(side, powers=False)) for side in node.args):
        return node
    above, below = _factors(node.args[0]), _factors(node.args[1])
    numbers = [f for f in above if isinstance(f, Num)]
    above = [f for f in above if not isinstance(f, Num)]
    factors: list[Node] = [*numbers, *(Op("div", (a, b)) for a, b in zip(above, below, strict=False))]
    factors += above[len(below):] + [Op("div", (Num(Fraction(1)), b)) for b in below[len(above):]]
    result = factors[0]
    for factor in factors[1:]:
        result = Op("mul", (result, factor))
    return result


def _terms(node: Node, sign: int = 1) -> list[tuple[int, Node]]:
    """The signed terms of a sum tree."""
    if isinstance(node, Op) and node.op in ("add", "sub"):
        return _terms(node.args[0], sign) + _terms(node.args[1], sign if node.op == "add" else -sign)
    if isinstance(node, Op) and node.op == "neg":
        return _terms(node.args[0], -sign)
    return [(sign, node)]


def _multiple(sign: int, term: Node) -> tuple[Fraction, str] | None:
    """``(c, x)`` for a term ``c*x`` of a name ``x`` and an exact number ``c``."""
    if isinstance(term, Sym):
        return Fraction(sign), term.name
    if isinstance(term, Op) and term.op == "mul" and isinstance(term.args[0], Num) \
            and isinstance(term.args[0].value, Fraction) and isinstance(term.args[1], Sym):
        return sign * term.args[0].value, term.args[1].name
    return None


def differences_first(node: Node) -> Node:
    """A sum whose multiples of names have coefficients adding up to zero (``v1 + w - 2*v2``, which
    sympy writes for ``(v1 - v2) + (w - v2)``; ``x*y + v1 - w``) as differences against one name, added
    first: each is exact when the inputs are close (two cars at nearly equal speeds), and the sum
    then keeps full accuracy.

    >>> from grader.model.expr import parse
    >>> differences_first(parse("a + b - c")) == parse("a + b - c")  # 1 + 1 - 1 is not 0
    True
    >>> differences_first(parse("x*y + v1 - w")) == parse("(v1 - w) + x*y")
    True
    """
    terms = _terms(node)
    multiples = [(index, found) for index, (sign, term) in enumerate(terms)
                 if (found := _multiple(sign, term)) is not None]
    if len(multiples) < 2 or len(multiples) == len(terms) == 2 or sum(c for _, (c, _) in multiples) != 0:
        return node
    reference = min(multiples, key=lambda item: item[1][0])[1][1]  # the most negative: v1 + w - 2*v2 -> v2
    parts: list[tuple[int, Node]] = []
    for _, (coefficient, name) in multiples:
        if name == reference:
            continue
        difference: Node = Op("sub", (Sym(name), Sym(reference)))
        if abs(coefficient) != 1:
            difference = Op("mul", (Num(abs(coefficient)), difference))
        parts.append((1 if coefficient > 0 else -1, difference))
    used = {index for index, _ in multiples}
    parts += [term for index, term in enumerate(terms) if index not in used]
    result = parts[0][1] if parts[0][0] > 0 else Op("neg", (parts[0][1],))
    for sign, term in parts[1:]:
        result = Op("add" if sign > 0 else "sub", (result, term))
    return result
