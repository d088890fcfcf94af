"""The numbers of a block solved numerically (``torn_block`` in :mod:`grader.solve.solver`): the interval its
unknown's root is looked for in, and the roots at a point of the template's sampling.

>>> import sympy as sp
>>> e = sp.Symbol("e", nonnegative=True)
>>> interval(e, e**2 + e - 1, [e <= 1])
(0.0, 1.0)
>>> theta = sp.Symbol("theta", real=True)
>>> interval(theta, sp.sin(theta) - sp.Rational(1, 2), [])
(-3.141592653589793, 3.141592653589793)
>>> [round(r, 12) for r in roots_at(e**2 + e - 1, e, 0.0, 1.0, {})]
[0.61803398875]
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from typing import Any

import numpy as np
import sympy as sp

from grader.model.expr import ROOT, Node, Num, Op, Sym
from grader.model.kernel import evaluate
from grader.model.roots import LIMIT, every_root, grid
from grader.physics.symbolic import to_node

_TRIGONOMETRIC = (sp.sin, sp.cos, sp.tan)


def interval(unknown: Any, residual: Any, conditions: Iterable[Any]) -> tuple[float, float]:
    """Where ``unknown``'s root is looked for (SI): its sign's assumption, ``(-pi, pi]`` for an angle (it appears
    inside a sine, cosine or angle), and each condition that bounds it by a number alone (``e <= 1``); else
    :data:`~grader.model.roots.LIMIT` either side."""
    low, high = (0.0 if unknown.is_nonnegative else -LIMIT), LIMIT
    if any(f.args[0].is_polynomial(unknown) and sp.degree(f.args[0], unknown) == 1
           for f in residual.atoms(*_TRIGONOMETRIC) if unknown in f.free_symbols):
        low, high = max(low, -math.pi), math.pi
    for condition in conditions:
        condition = sp.sympify(condition)
        if not isinstance(condition, sp.Rel) or condition.free_symbols != {unknown}:
            continue
        difference = sp.expand(condition.lhs - condition.rhs)  # holds: difference (rel) 0
        if not difference.is_polynomial(unknown) or sp.degree(difference, unknown) != 1:
            continue
        slope, bound = difference.coeff(unknown, 1), -difference.coeff(unknown, 0) / difference.coeff(unknown, 1)
        if not (slope.is_number and bound.is_number):
            continue
        above = isinstance(condition, (sp.GreaterThan, sp.StrictGreaterThan)) == bool(slope > 0)
        if above:
            low = max(low, float(bound))
        else:
            high = min(high, float(bound))
    return low, high


def roots_at(residual: Any, unknown: Any, low: float, high: float, at: Mapping[Any, Any]) -> list[float]:
    """The roots in ``[low, high]`` of ``residual`` with the values ``at`` (SI) given: none where a value is
    not a finite number."""
    fixed = sp.sympify(residual).xreplace({s: v for s, v in at.items() if s != unknown})
    if fixed.free_symbols - {unknown} or fixed.has(sp.nan, sp.zoo, sp.oo, -sp.oo, sp.I):
        return []
    tree = to_node(fixed)
    with np.errstate(all="ignore"):  # a residual outside its domain (a square root of a negative) is no root
        return every_root(lambda x: np.broadcast_to(evaluate(tree, {unknown.name: x}), x.shape), low, high)


def root_node(residual: Node, unknown: str, low: float, high: float) -> Op:
    """The tree of a numeric block's unknown: ``root(residual, unknown, low, high)``."""
    return Op(ROOT, (residual, Sym(unknown), Num(low), Num(high)))


def identity(lhs: Any, rhs: Any, unknown: Any, low: float, high: float, at: Mapping[Any, Any]) -> bool:
    """Whether ``lhs = rhs`` holds for every value of ``unknown`` in ``[low, high]`` with the values ``at``
    (to 1e-9 of its sides at 90 % of the grid's points): an equation the block already satisfies, which fixes
    nothing."""
    if sp.expand(sp.sympify(lhs) - sp.sympify(rhs)) == 0:  # J = m c (1 - (c - J/m)/c): exact, where floats cancel
        return True
    sides = []
    for side in (lhs, rhs):
        fixed = sp.sympify(side).xreplace({s: v for s, v in at.items() if s != unknown})
        if fixed.free_symbols - {unknown} or fixed.has(sp.nan, sp.zoo, sp.oo, -sp.oo, sp.I):
            return False
        points = grid(low, high)
        with np.errstate(all="ignore"):
            sides.append(np.broadcast_to(evaluate(to_node(fixed), {unknown.name: points}), points.shape))
    left, right = sides
    finite = np.isfinite(left) & np.isfinite(right)
    left, right = left[finite], right[finite]
    agree = np.abs(left - right) <= 1e-9 * np.maximum(np.abs(left), np.abs(right))
    # Where both sides are near 0 their rounding errors are large beside them: an identity may fail there, at
    # a few points; an equation that fixes x fails nearly everywhere but at its roots.
    return bool(agree.size and agree.mean() >= 0.9)
