"""Rewrites that keep a composed expression accurate in float64 (DESIGN.md, Numerics).

Each rewrite is an identity; together they make sure differences of nearly equal inputs are
formed first and that no intermediate product overflows where the answer does not.

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

from collections.abc import Iterable
from typing import Any

import sympy as sp

from grader.physics.symbolic import common_positive_factor, cosd, sind


def stabilize(expr: Any, degree_angles: Iterable[Any] = ()) -> Any:
    """All rewrites, repeated until none changes anything (each can expose work for another)."""
    result = expr
    for _ in range(4):
        previous = result
        result = absorb_reciprocals(positive_factors_out_of_max(root_differences(result)))
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
