"""Numpy evaluation of expression trees: the compiled kernels.

Every operation is vectorised, so one call answers any number of parameter sets. Degree-argument
sine and cosine reduce the angle in degrees first, so ``cosd(90) == 0`` and ``cosd(89.9999999)``
keeps full relative accuracy.

>>> import numpy as np
>>> from grader.model.expr import parse
>>> evaluate(parse("hypot(3*x, 4)"), {"x": np.array([1.0, 0.0])}).tolist()
[5.0, 4.0]
>>> float(cosd(np.float64(90.0))), float(sind(np.float64(-180.0)))
(0.0, 0.0)
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from fractions import Fraction
from typing import Any

import numpy as np

from grader.model.expr import Node, Num, Op, Sym


def _quadrant(degrees: Any) -> tuple[Any, Any, Any]:
    x = np.asarray(degrees, dtype=float)
    finite = np.isfinite(x)
    reduced = np.fmod(np.where(finite, x, 0.0), 360.0)  # exact
    quarter = np.round(reduced / 90.0)
    rest = reduced - 90.0 * quarter  # exact: |rest| <= 45 and the operands are close
    radians = rest * (np.pi / 180.0)
    # A non-finite angle has no sine: NaN, which the caller refuses (never an index error).
    return np.mod(quarter, 4).astype(int), np.where(finite, np.sin(radians), np.nan), np.where(
        finite, np.cos(radians), np.nan)


def sind(degrees: Any) -> Any:
    """Sine of an angle in degrees."""
    q, s, c = _quadrant(degrees)
    return np.choose(q, [s, c, -s, -c]) + 0.0  # + 0.0 turns -0.0 into 0.0 (atan2 tells them apart)


def cosd(degrees: Any) -> Any:
    """Cosine of an angle in degrees."""
    q, s, c = _quadrant(degrees)
    return np.choose(q, [c, -s, -c, s]) + 0.0


def _power(base: Any, exponent: Any) -> Any:
    if np.ndim(exponent) == 0 and float(exponent) == 2.0:
        return base * base
    return np.power(base, exponent)


OPERATIONS: dict[str, Callable[..., Any]] = {
    "add": np.add, "sub": np.subtract, "mul": np.multiply, "div": np.divide, "neg": np.negative,
    "pow": _power, "sqrt": np.sqrt, "sin": np.sin, "cos": np.cos, "tan": np.tan, "exp": np.exp,
    "log": np.log, "abs": np.abs, "sign": np.sign, "atan2": np.arctan2, "hypot": np.hypot, "sind": sind, "cosd": cosd,
    "Max": np.maximum, "Min": np.minimum, "lt": np.less, "le": np.less_equal, "gt": np.greater, "ge": np.greater_equal,
    "and": np.logical_and, "or": np.logical_or,
}


def _float(value: Fraction | float) -> float:
    """An exact constant as float64: beyond its range, an infinity the caller refuses like any overflow.

    >>> _float(Fraction(10**400, 3)), _float(Fraction(1, 4))
    (inf, 0.25)
    """
    try:
        return float(value)
    except OverflowError:
        return math.inf if value > 0 else -math.inf


def evaluate(node: Node, env: Mapping[str, Any]) -> Any:
    """Evaluate a tree with numpy; names are looked up in ``env`` (``pi`` is built in)."""
    if isinstance(node, Num):
        return _float(node.value)
    if isinstance(node, Sym):
        if node.name == "pi":
            return np.pi
        return env[node.name]
    assert isinstance(node, Op)
    return OPERATIONS[node.op](*(evaluate(arg, env) for arg in node.args))
