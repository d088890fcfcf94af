"""Is a student's expression the key's? Evaluation at many points, placed where the expressions' structure
changes, and an exact check where evaluation alone cannot be trusted.

WeBWorK's method (agreement at a few seeded random points) passes any wrong answer whose error vanishes at
those points: ``... + 100*Max(0, p - 2.99)``, a bump ``50*exp(-1e6*(p - 1.7)^2)``, a step. So:

1. Functions a physical answer never needs, piecewise or discontinuous ones (:data:`REFUSED`), are refused
   unless the key's own expression uses them (:func:`refused`).
2. The expressions are compared at seeded random points, at the corners of the domain, along line scans
   through it, and at *probes*: for each sub-term that can change fast, where it does. A denominator or the
   argument of ``sqrt``, ``log``, ``abs``, ``hypot``, ``atan2`` changes fast where it is smallest in size
   (a pole, a kink, a step); the argument of ``exp`` where it is largest (a narrow bump). Each is found by a
   scan along every variable, refined by golden sections and coordinate ascent; the expressions are compared
   there and just either side.
3. An expression that agrees everywhere there but uses a function the key does not, or has a sub-term that
   comes within a rounding of zero inside the domain, is checked exactly: sympy, on a tree built from ours
   (never from the student's text), within :data:`EXACT_SECONDS`. Not shown identical, it is not equivalent.

>>> from grader.model.expr import parse
>>> domains = {"v": (1.0, 10.0), "p": (0.3, 3.0)}
>>> key = parse("v*(1 - 0.1*p)/(p + 1)")
>>> equivalent(parse("(v - 0.1*p*v)/(1 + p)"), key, domains, seed="s1")
True
>>> equivalent(parse("v*(1 - 0.1*p)/(p + 1) + 50*exp(-1000000*(p - 1.7)**2)"), key, domains, seed="s1")
False
>>> refused(parse("v*(1 - 0.1*p)/(p + 1) + Max(0, p - 2.99)"), key)
'Max() is not accepted in this answer (it is piecewise: a physical answer here does not need it)'
"""

from __future__ import annotations

import hashlib
import math
import signal
import threading
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any

import numpy as np

from grader.errors import shown
from grader.model.expr import Node, Num, Op, Sym, names, to_text
from grader.model.kernel import evaluate

REFUSED = {"Max": "piecewise", "Min": "piecewise", "sign": "a step", "abs": "piecewise",
           "atan2": "a step across its branch cut"}
"""Functions refused in a student's expression unless the key's uses them, and why."""

EXACT_SECONDS = 2.0
"""The time the exact check may take (in the main thread; elsewhere only its quick steps run)."""

_TRANSCENDENTAL = {"sqrt", "sin", "cos", "tan", "sind", "cosd", "exp", "log", "hypot", "atan2", "abs", "sign",
                   "Max", "Min"}
_SMALLEST = {"sqrt", "log", "abs", "sign", "hypot", "atan2"}  # whose arguments matter where they are near 0
_GRID = 65  # points of a line scan
_BASES = 4  # lines scanned along each variable
_GOLDEN = 34  # golden-section steps: a bracket of 2/64 of the domain narrowed to about 1e-9 of it
_NEAR_ZERO = 1e-7  # a sub-term this small relative to its largest size is "at zero"


def refused(student: Node, key: Node) -> str | None:
    """Why ``student`` is refused (a function of :data:`REFUSED` the key does not use), or None."""
    allowed = _functions(key)
    for name in sorted(_functions(student) - allowed):
        if name in REFUSED:
            return f"{name}() is not accepted in this answer (it is {REFUSED[name]}: a physical answer here does " \
                   "not need it)"
    return None


def _functions(tree: Node) -> set[str]:
    return {node.op for node in _nodes(tree) if isinstance(node, Op) and node.op in _TRANSCENDENTAL}


def _nodes(tree: Node) -> Iterator[Node]:
    stack = [tree]
    while stack:
        node = stack.pop()
        yield node
        if isinstance(node, Op):
            stack.extend(node.args)


@dataclass(frozen=True)
class _Form:
    """An expression keyed by its normalised text (the tree rides along, outside the key)."""

    text: str
    tree: Node = field(compare=False, hash=False)


Domains = tuple[tuple[str, tuple[float, float]], ...]


def equivalent(student: Node, expected: Node, domains: Mapping[str, tuple[float, float]], *, seed: str,
               rtol: float = 1e-6, points: int = 64) -> bool | str:
    """Whether two expressions are equal on ``domains`` (see the module's steps), to ``rtol``.

    ``points`` random points are drawn, uniformly in each name's domain. Points where the key is undefined
    are skipped; a student expression undefined at a random point where the key is defined is not
    equivalent. Returns a reason instead of a verdict when no comparison is possible: the caller marks the
    cell invalid. Results are cached per (texts, domains, seed, rtol, points).

    >>> from grader.model.expr import parse
    >>> equivalent(parse("v/(p - p)"), parse("v*(1 - 0.1*p)/(p + 1)"), {"v": (1, 10), "p": (0.1, 5)}, seed="s1")
    'the expression cannot be evaluated at any test point (division by zero?)'
    """
    if not 0 < rtol < 1 or isinstance(points, bool) or not isinstance(points, int) or not 1 <= points <= 1000:
        raise ValueError(f"equivalent: expected 0 < rtol < 1 and 1 <= points <= 1000, got {rtol!r}, {points!r}")
    for name, (low, high) in domains.items():
        if not (math.isfinite(low) and math.isfinite(high) and low <= high):
            raise ValueError(f"equivalent: domain of {name}: expected finite low <= high, got {shown((low, high))}")
    key = tuple(sorted((name, (float(low), float(high))) for name, (low, high) in domains.items()))
    return _equivalent(_Form(to_text(student), student), _Form(to_text(expected), expected), key, seed, rtol, points)


@lru_cache(maxsize=4096)
def _equivalent(student: _Form, expected: _Form, domains: Domains, seed: str, rtol: float,
                points: int) -> bool | str:
    known = dict(domains)
    missing = sorted((names(student.tree) | names(expected.tree)) - set(known))
    if missing:
        return f"the expression uses {', '.join(missing)}, which this answer does not know"
    digest = hashlib.sha256("\n".join((seed, student.text, expected.text)).encode()).digest()
    generator = np.random.default_rng(np.random.SeedSequence(int.from_bytes(digest, "big")))
    sampled = _sampled(domains, generator, 4 * points)
    key_values, student_values = _values(expected.tree, sampled), _values(student.tree, sampled)
    usable = np.flatnonzero(np.isfinite(key_values))
    if usable.size == 0:
        return "the key's expression cannot be evaluated at any test point; please ask your instructor to check it"
    usable = np.concatenate([usable[:points], usable[usable >= 4 * points]])  # the random ones, then scans
    b, a = key_values[usable], student_values[usable]
    if not np.isfinite(a).any():
        return "the expression cannot be evaluated at any test point (division by zero?)"
    if not np.isfinite(a).all():
        return False
    floor = 1e-3 * rtol * float(np.max(np.abs(b)))
    if not _agree(a, b, rtol, floor):
        return False
    found = [_structure(node, domains) for node in _watched(student.tree) | _watched(expected.tree)]
    probes = _stack([probe for probe, _ in found], domains)
    if probes is not None:
        b, a = _values(expected.tree, probes), _values(student.tree, probes)
        both = np.isfinite(a) & np.isfinite(b)  # a probe may sit on a pole: compare beside it
        if not _agree(a[both], b[both], rtol, floor):
            return False
    touches_zero = any(near for _, near in found)
    if touches_zero or not _functions(student.tree) <= _functions(expected.tree):
        return _identical(student.tree, expected.tree, domains)
    return True


def _agree(a: np.ndarray, b: np.ndarray, rtol: float, floor: float) -> bool:
    # The floor lets a value that cancels to near zero at one point agree to the size of the others.
    return bool(np.all(np.abs(a - b) <= rtol * np.maximum(np.abs(a), np.abs(b)) + floor))


Points = dict[str, np.ndarray]


def _sampled(domains: Domains, generator: np.random.Generator, drawn: int) -> Points:
    """``drawn`` random points, then the domain's corners and the line scans' points."""
    random = {name: generator.uniform(low, high, drawn) for name, (low, high) in domains}
    return _joined([random, _corners(domains), _scans(domains, generator)])


def _corners(domains: Domains) -> Points:
    count = min(len(domains), 6)  # 64 corners at most: the first six names vary, the rest sit at their centre
    grid = np.array(np.meshgrid(*[[0.0, 1.0]] * count, indexing="ij")).reshape(count, -1) if count else \
        np.zeros((0, 1))
    out = {}
    for index, (name, (low, high)) in enumerate(domains):
        share = grid[index] if index < count else np.full(grid.shape[1], 0.5)
        out[name] = low + share * (high - low)
    return out


def _scans(domains: Domains, generator: np.random.Generator) -> Points:
    """For each name, lines along it through the centre and through random points."""
    lines = []
    for name, (low, high) in domains:
        bases = {other: np.concatenate([[(lo + hi) / 2], generator.uniform(lo, hi, _BASES - 1)])
                 for other, (lo, hi) in domains}
        along = np.linspace(low, high, _GRID)
        lines.append({other: np.repeat(values, _GRID) for other, values in bases.items()}
                     | {name: np.tile(along, _BASES)})
    return _joined(lines)


def _joined(parts: list[Points]) -> Points:
    parts = [part for part in parts if part]
    if not parts:
        return {}
    return {name: np.concatenate([part[name] for part in parts]) for name in parts[0]}


def _stack(probes: list[Points | None], domains: Domains) -> Points | None:
    found = [probe for probe in probes if probe is not None]
    return _joined(found) if found else None


def _values(tree: Node, env: Points) -> np.ndarray:
    """The tree at every point; NaN wherever it is undefined, and everywhere if it cannot be evaluated."""
    size = len(next(iter(env.values()))) if env else 1
    try:
        with np.errstate(all="ignore"):
            values = np.asarray(evaluate(tree, env), dtype=float)
        return np.broadcast_to(values, (size,)).copy()
    except (ArithmeticError, ValueError, TypeError, KeyError):
        return np.full(size, np.nan)


# ---- where the structure changes ----------------------------------------------------------------

def _watched(tree: Node) -> set[tuple[str, Node]]:
    """The sub-terms that can change fast, each with what to look for: ``"small"`` (where it is nearest 0)
    or ``"large"`` (where it is largest)."""
    found: set[tuple[str, Node]] = set()
    for node in _nodes(tree):
        if not isinstance(node, Op) or not names(node):
            continue
        if node.op == "div":
            found.add(("small", node.args[1]))
        elif node.op in _SMALLEST:
            found.update(("small", arg) for arg in node.args)
        elif node.op in ("Max", "Min"):
            found.add(("small", Op("sub", node.args)))
        elif node.op == "exp":
            found.add(("large", node.args[0]))
        elif node.op == "pow" and not (isinstance(node.args[1], Num) and float(node.args[1].value).is_integer()
                                         and float(node.args[1].value) >= 0):
            found.add(("small", node.args[0]))  # a root or a negative power: a kink or a pole at 0
    return {(kind, node) for kind, node in found if names(node)}


@lru_cache(maxsize=4096)
def _structure(watched: tuple[str, Node], domains: Domains) -> tuple[Points | None, bool]:
    """Probe points where a watched sub-term is most extreme (and just either side), and whether it comes
    within a rounding of zero inside the domain. Cached: the same denominators recur across a class."""
    kind, node = watched
    sign = -1.0 if kind == "small" else 1.0

    def score(env: Points) -> np.ndarray:
        values = _values(node, env)
        scored = sign * (np.abs(values) if kind == "small" else values)
        return np.where(np.isnan(scored), -np.inf if kind == "large" else 0.0, scored)

    best = _ascend(score, domains)
    if best is None:
        return None, False
    side = {name: np.array([value]) for name, value in best.items()}
    near = False
    if kind == "small":
        size = float(np.max(np.abs(np.nan_to_num(_values(node, _corners(domains)), posinf=0, neginf=0))))
        at = abs(float(_values(node, side)[0]))
        inside = any(low < best[name] < high for name, (low, high) in domains if name in names(node))
        near = inside and (not (at > _NEAR_ZERO * size) if size > 0 else True)
    probes = [side]
    for name, (low, high) in domains:
        for offset in (1e-9, 1e-6, 1e-3):
            for direction in (-1.0, 1.0):
                moved = dict(side)
                moved[name] = np.clip(side[name] + direction * offset * (high - low), low, high)
                probes.append(moved)
    return _joined(probes), near


def _ascend(score: Callable[[Points], np.ndarray], domains: Domains) -> dict[str, float] | None:
    """Coordinate ascent of ``score`` over the box: a grid along each name, a golden section around the grid's
    best, two sweeps."""
    spans = dict(domains)
    point = {name: (low + high) / 2 for name, (low, high) in domains}
    if not spans:
        return None
    for _ in range(2):
        for name, (low, high) in domains:
            if high <= low:
                continue
            along = np.linspace(low, high, _GRID)
            env = {other: np.full(_GRID, value) for other, value in point.items()} | {name: along}
            scores = score(env)
            index = int(np.argmax(scores))
            left, right = along[max(index - 1, 0)], along[min(index + 1, _GRID - 1)]
            point[name] = _golden(score, point, name, left, right, float(along[index]), float(scores[index]))
    return point


def _golden(score: Callable[[Points], np.ndarray], point: dict[str, float], name: str, left: float,
            right: float, best: float, best_score: float) -> float:
    """The best of ``best`` and a golden-section search for the maximum of ``score`` in [left, right]."""
    ratio = (math.sqrt(5) - 1) / 2
    for _ in range(_GOLDEN):
        inner = np.array([right - ratio * (right - left), left + ratio * (right - left)])
        env = {other: np.full(2, value) for other, value in point.items()} | {name: inner}
        low_score, high_score = score(env)
        if low_score >= high_score:
            right = float(inner[1])
        else:
            left = float(inner[0])
        for value, at in ((low_score, inner[0]), (high_score, inner[1])):
            if value > best_score:
                best, best_score = float(at), float(value)
    return best


# ---- the exact check ----------------------------------------------------------------------------

def _identical(student: Node, expected: Node, domains: Domains) -> bool:
    """Whether sympy shows ``student - expected`` to be 0, within :data:`EXACT_SECONDS`."""
    import sympy

    symbols = {name: sympy.Symbol(name, positive=True) if low > 0 else sympy.Symbol(name, real=True)
               for name, (low, high) in domains}
    difference = _sympy(student, symbols) - _sympy(expected, symbols)
    try:
        with _deadline(EXACT_SECONDS) as bounded:
            if sympy.cancel(difference) == 0:
                return True
            return bounded and bool(sympy.simplify(difference) == 0)
    except (_OutOfTimeError, RecursionError, ValueError, TypeError, ZeroDivisionError):
        return False


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
