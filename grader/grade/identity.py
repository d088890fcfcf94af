"""Whether two expressions are identical, shown by sympy within a time bound: the exact check behind
:func:`grader.grade.equivalence.equivalent`. The sympy expressions are built from our trees node by node; no
text, least of all a student's, is parsed.

>>> from grader.model.expr import parse
>>> identical(parse("v*exp(log(1.1))/(p + 1)"), parse("1.1*v/(p + 1)"), (("p", (0.3, 3.0)), ("v", (1.0, 10.0))))
True
>>> identical(parse("sqrt((p - 2)^2)"), parse("p - 2"), (("p", (0.3, 3.0)),))
False
>>> identical(parse("sqrt((p - 4)^2)"), parse("4 - p"), (("p", (0.3, 3.0)),))  # p < 4 on its domain
True
"""

from __future__ import annotations

import signal
import threading
from collections.abc import Callable, Mapping
from typing import Any

from grader.base.errors import SYMPY_FAILURES, unworkable
from grader.model.expr import Node, Num, Sym

EXACT_SECONDS = 2.0
"""The time the exact check may take (in the main thread; elsewhere only its quick steps run)."""

def identical(student: Node, expected: Node, domains: tuple[tuple[str, tuple[float, float]], ...]) -> bool:
    """Whether sympy shows ``student - expected`` to be 0, within :data:`EXACT_SECONDS`."""
    import sympy

    try:
        with _deadline(EXACT_SECONDS) as bounded:
            symbols = {name: _inside(low, high) for name, (low, high) in domains}
            difference = _sympy(student, symbols) - _sympy(expected, symbols)
            if sympy.cancel(difference) == 0:
                return True
            return bounded and bool(sympy.simplify(difference) == 0)
    except (_OutOfTimeError, sympy.PolynomialError, *SYMPY_FAILURES) as error:
        if isinstance(error, _OutOfTimeError | sympy.PolynomialError) or unworkable(error):
            return False  # not shown identical: sympy could not, in time, on the student's expression
        raise  # a bug of grader's keeps its traceback


def _inside(low: float, high: float) -> Any:
    """A name that ranges over (low, high) exactly as sympy can reason about it: ``(low + high*s)/(1 + s)``
    with ``s`` positive (a name only assumed positive or real would let ``sqrt(x^2)`` differ from ``x``
    where the domain says it cannot).

    >>> _inside(0.3, 3.0)
    (3*_s + 3/10)/(_s + 1)
    """
    import sympy

    s = sympy.Dummy("s", positive=True)
    if low == high:
        return sympy.Rational(repr(float(low)))
    return (sympy.Rational(repr(float(low))) + sympy.Rational(repr(float(high))) * s) / (1 + s)


class _OutOfTimeError(Exception):
    pass


class _deadline:  # noqa: N801 - used as a context manager, like contextlib's
    """Raise :class:`_OutOfTimeError` after ``seconds`` (an interval timer: only in the main thread; elsewhere the
    context's value is False and only bounded steps should run)."""

    def __init__(self, seconds: float) -> None:
        self.seconds = seconds
        self.armed = threading.current_thread() is threading.main_thread() and hasattr(signal, "setitimer")

    def __enter__(self) -> bool:
        if self.armed:
            self.previous = signal.signal(signal.SIGALRM, self._expire)
            signal.setitimer(signal.ITIMER_REAL, self.seconds)
        return self.armed

    def __exit__(self, *exc: object) -> None:
        if self.armed:
            signal.setitimer(signal.ITIMER_REAL, 0)
            signal.signal(signal.SIGALRM, self.previous)

    @staticmethod
    def _expire(signum: int, frame: Any) -> None:
        raise _OutOfTimeError


def _sympy(node: Node, symbols: Mapping[str, Any]) -> Any:
    """A sympy expression built from our tree, node by node (no text is parsed)."""
    import sympy

    if isinstance(node, Num):
        value = node.value
        return sympy.Float(value) if isinstance(value, float) else sympy.Rational(value.numerator, value.denominator)
    if isinstance(node, Sym):
        return sympy.pi if node.name == "pi" else symbols[node.name]
    args = [_sympy(arg, symbols) for arg in node.args]
    builders: dict[str, Callable[..., Any]] = {
        "add": lambda a, b: a + b, "sub": lambda a, b: a - b, "mul": lambda a, b: a * b,
        "div": lambda a, b: a / b, "pow": lambda a, b: a ** b, "neg": lambda a: -a,
        "sqrt": sympy.sqrt, "sin": sympy.sin, "cos": sympy.cos, "tan": sympy.tan, "exp": sympy.exp,
        "log": sympy.log, "abs": sympy.Abs, "sign": sympy.sign, "Max": sympy.Max, "Min": sympy.Min,
        "atan2": sympy.atan2, "hypot": lambda a, b: sympy.sqrt(a**2 + b**2),
        "sind": lambda a: sympy.sin(sympy.pi * a / 180), "cosd": lambda a: sympy.cos(sympy.pi * a / 180)}
    return builders[node.op](*args)
