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
   scan along every variable, refined by zoomed-in grids and coordinate ascent; the expressions are compared
   there and just either side.
3. An expression that agrees everywhere there but uses a function the key does not, or has a sub-term that
   comes within a rounding of zero inside the domain, is checked exactly: sympy, on a tree built from ours
   (never from the student's text), within :data:`grader.grade.identity.EXACT_SECONDS`. Not shown identical,
   it is not equivalent.

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
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any, NamedTuple

import numpy as np

from grader.base.errors import shown
from grader.grade.identity import identical
from grader.model.expr import CONSTANTS, Node, Num, Op, Sym, parse, to_text
from grader.model.kernel import (
    OPERATIONS,
    _float,  # evaluate's own reading of a constant: one place
    evaluate,
)

REFUSED = {"Max": "piecewise", "Min": "piecewise", "sign": "a step", "abs": "piecewise",
           "atan2": "a step across its branch cut"}
"""Functions refused in a student's expression unless the key's uses them, and why."""
_REFUSED_CALLS = tuple(f"{name}(" for name in REFUSED)  # as to_text prints a call

_TRANSCENDENTAL = {"sqrt", "sin", "cos", "tan", "sind", "cosd", "exp", "log", "hypot", "atan2", "abs", "sign",
                   "Max", "Min"}
_SMALLEST = {"sqrt", "log", "abs", "sign", "hypot", "atan2"}  # whose arguments matter where they are near 0
_GRID = 65  # points of a line scan
_BASES = 4  # lines scanned along each variable
_ZOOM = 33  # points of a zoomed-in grid
_LEVELS = 7  # zoomed-in grids: a bracket of 2/64 of the domain narrowed to about 1e-10 of it
_NEAR_ZERO = 1e-7  # a sub-term this small relative to its largest size is "at zero"


def refused(student: Node, key: Node | str, text: str | None = None) -> str | None:
    """Why ``student`` is refused (a function of :data:`REFUSED` the key does not use), or None. ``key``: the key's
    expression, a tree or its text (read once per distinct text); ``text``: ``to_text(student)`` where the caller
    has it (a function whose call it does not print, the tree does not use: no walk)."""
    if text is not None and not any(call in text for call in _REFUSED_CALLS):
        return None
    allowed = _survey_of_key(_key_form(key)).functions
    for name in sorted(_functions(student) - allowed):
        if name in REFUSED:
            return f"{name}() is not accepted in this answer (it is {REFUSED[name]}: a physical answer here does " \
                   "not need it)"
    return None


def _names(tree: Node) -> frozenset[str]:
    """:func:`grader.model.expr.names` of a tree without ``root`` (one loop, no set a node)."""
    found, stack = set(), [tree]
    while stack:
        node = stack.pop()
        if isinstance(node, Op):
            stack.extend(node.args)
        elif isinstance(node, Sym) and node.name not in CONSTANTS:
            found.add(node.name)
    return frozenset(found)


def _functions(tree: Node) -> set[str]:
    found, stack = set(), [tree]
    while stack:
        node = stack.pop()
        if isinstance(node, Op):
            if node.op in _TRANSCENDENTAL:
                found.add(node.op)
            stack.extend(node.args)
    return found


@dataclass(frozen=True)
class _Form:
    """An expression keyed by its normalised text (the tree rides along, outside the key)."""

    text: str
    tree: Node = field(compare=False, hash=False)


Domains = tuple[tuple[str, tuple[float, float]], ...]


def equivalent(student: Node, expected: Node | str, domains: Mapping[str, tuple[float, float]], *, seed: str,
               rtol: float = 1e-6, points: int = 64) -> bool | str:
    """Whether two expressions are equal on ``domains`` (see the module's steps), to ``rtol``.

    ``points`` random points are drawn, uniformly in each name's domain. Points where the key is undefined
    are skipped; a student expression undefined at a random point where the key is defined is not
    equivalent. Returns a reason instead of a verdict when no comparison is possible: the caller marks the
    cell invalid. ``expected``: the key's expression, a tree or its text (read once per distinct text, which is
    faster to look up than a tree is to hash). Nothing is cached per student expression (grading keeps one
    verdict per distinct text); the points depend on the key and the seed only, and are worked out once per key.

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
    return _equivalent(student, _key_form(expected), key, seed, rtol, points)


@lru_cache(maxsize=1024)
def _key_form(expected: Node | str) -> _Form:
    tree = parse(expected) if isinstance(expected, str) else expected
    return _Form(to_text(tree), tree)


def _equivalent(student: Node, expected: _Form, domains: Domains, seed: str, rtol: float,
                points: int) -> bool | str:
    keyed = _keyed(expected, domains, seed, points)
    fixed, key_survey = keyed.fixed, keyed.survey
    # One walk of the student's tree finds what _survey finds and its values at the fixed points and the lines
    # (see _Fixed); a tree it cannot evaluate there is surveyed alone, and is NaN everywhere as _values makes it.
    walked = _walk(student, fixed.everywhere) if fixed is not None and domains else None
    if walked is None:
        survey = _survey(student)
        missing = sorted((survey.names | key_survey.names) - keyed.known)
        if missing:
            return f"the expression uses {', '.join(missing)}, which this answer does not know"
    assert fixed is not None  # the key's names are known
    b, largest = fixed.values, fixed.largest
    if b.size == 0:
        return "the key's expression cannot be evaluated at any test point; please ask your instructor to check it"
    lines: list[np.ndarray | None]
    if walked is None:
        functions, watched, lines = survey.functions, survey.watched, [None] * len(survey.watched)
        a = _values(student, fixed.points)
    else:
        functions, watched, lines = walked.functions, walked.watched, _lines(walked, keyed.lines)
        a = walked.values[:b.size]
    # A sub-term found twice is probed twice (the same points): cheaper than hashing every one to drop repeats.
    found = [*(_structure(one, domains) if line is None or not _tame_values(one.kind, line) else _TAME
               for one, line in zip(watched, lines, strict=True)),
             *keyed.structure]
    probes = _stack([probe for probe, _ in found])
    finite = np.isfinite(a)
    if not np.logical_and.reduce(finite):  # finite.all(), without its Python wrapper
        return False if finite.any() else "the expression cannot be evaluated at any test point (division by zero?)"
    floor = 1e-3 * rtol * largest
    if not _agree(a, b, rtol, floor):
        return False
    if probes is not None:
        a, b = _values(student, probes), _values(expected.tree, probes)
        both = np.isfinite(a) & np.isfinite(b)  # a probe may sit on a pole: compare beside it
        if not _agree(a[both], b[both], rtol, floor):
            return False
    touches_zero = any(near for _, near in found)
    if touches_zero or not functions <= key_survey.functions:
        return identical(student, expected.tree, domains)
    return True


_TAME: tuple[Points | None, bool] = (None, False)


class _Keyed(NamedTuple):
    """What every answer to a key is compared with: the key's survey, the names the domains know, the points (None:
    the key uses a name they do not), the key's probes, where each name's line starts among the points."""

    survey: _Survey
    known: frozenset[str]
    fixed: _Fixed | None
    structure: tuple[tuple[Points | None, bool], ...]
    lines: Mapping[str, int]


@lru_cache(maxsize=256)
def _keyed(expected: _Form, domains: Domains, seed: str, points: int) -> _Keyed:
    """Worked out once per key (one look-up an answer, not one a part)."""
    survey, known = _survey_of_key(expected), frozenset(name for name, _ in domains)
    if not survey.names <= known:
        return _Keyed(survey, known, None, (), {})
    fixed = _fixed(expected, domains, seed, points)
    lines = {name: fixed.values.size + index * _GRID for index, (name, _) in enumerate(domains)}
    return _Keyed(survey, known, fixed, _key_structure(expected, domains), lines)


def _lines(walked: _Walked, starts: Mapping[str, int]) -> list[np.ndarray | None]:
    """For each watched sub-term, its values along its name's line (the :func:`_tame` grid), where the walk
    evaluated it (``starts``: where each name's line starts); None for a sub-term of several names, or where not
    evaluated."""
    return [None if len(watched.names) != 1 or values is None else
            values[(start := starts[next(iter(watched.names))]):start + _GRID]
            for watched, values in zip(walked.watched, walked.watched_values, strict=True)]


def _agree(a: np.ndarray, b: np.ndarray, rtol: float, floor: float) -> bool:
    """``|a - b| <= rtol max(|a|, |b|) + floor`` everywhere (in place: a few numpy calls on short arrays)."""
    # The floor lets a value that cancels to near zero at one point agree to the size of the others.
    error = np.subtract(a, b)
    np.abs(error, out=error)
    bound = np.abs(a)
    np.maximum(bound, np.abs(b), out=bound)
    bound *= rtol
    bound += floor
    return bool(np.logical_and.reduce(np.less_equal(error, bound)))


Points = dict[str, np.ndarray]
Score = Callable[[Points], np.ndarray]
"""A sub-term's score at points (higher: nearer what is looked for)."""


class _Fixed(NamedTuple):
    """The points every answer to a key is compared at, the key's values there and the largest of their sizes;
    ``everywhere``: those points, then for each name in turn a line along it (the :func:`_tame` grid, the other
    names at their centre), where a student's expression is evaluated in the same walk."""

    points: Points
    values: np.ndarray
    largest: float
    everywhere: Points


@lru_cache(maxsize=256)
def _fixed(expected: _Form, domains: Domains, seed: str, points: int) -> _Fixed:
    """The points every answer to a key is compared at, where the key is defined: ``points`` seeded random
    ones, the domain's corners and the line scans; and the key's values there. Worked out once per key."""
    digest = hashlib.sha256("\n".join((seed, expected.text)).encode()).digest()
    generator = np.random.default_rng(np.random.SeedSequence(int.from_bytes(digest, "big")))
    random = {name: generator.uniform(low, high, 4 * points) for name, (low, high) in domains}
    chosen = np.flatnonzero(np.isfinite(_values(expected.tree, random)))[:points]
    everywhere = _joined([{name: column[chosen] for name, column in random.items()}, _corners(domains),
                          _scans(domains, generator)])
    values = _values(expected.tree, everywhere)
    defined = np.isfinite(values)
    values = values[defined]
    largest = float(np.max(np.abs(values))) if values.size else 0.0
    compared = {name: column[defined] for name, column in everywhere.items()}
    centre = {name: (low + high) / 2 for name, (low, high) in domains}
    lines = _joined([_line(centre, name, _grid(low, high)) for name, (low, high) in domains])
    return _Fixed(compared, values, largest, _joined([compared, lines]))


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


def _stack(probes: list[Points | None]) -> Points | None:
    found = [probe for probe in probes if probe is not None]
    return _joined(found) if found else None


def _values(tree: Node, env: Points) -> np.ndarray:
    """The tree at every point; NaN wherever it is undefined, and everywhere if it cannot be evaluated."""
    size = len(next(iter(env.values()))) if env else 1
    try:
        with np.errstate(all="ignore"):
            values = np.asarray(evaluate(tree, env), dtype=float)
        return values.copy() if values.shape == (size,) else np.broadcast_to(values, (size,)).copy()
    except (ArithmeticError, ValueError, TypeError, KeyError):
        return np.full(size, np.nan)


# ---- where the structure changes ----------------------------------------------------------------

class _Watched(NamedTuple):
    """A sub-term that can change fast, what to look for in it (``"small"``: where it is nearest 0; ``"large"``:
    where it is largest), and the names it uses."""

    kind: str
    node: Node
    names: frozenset[str]


class _Survey(NamedTuple):
    """What one walk of a tree finds: the names it uses, its functions of :data:`_TRANSCENDENTAL`, the sub-terms
    it has that can change fast."""

    names: frozenset[str]
    functions: frozenset[str]
    watched: tuple[_Watched, ...]  # in the order found; not made a set, which would hash every sub-term


_NONE: frozenset[str] = frozenset()


def _survey(tree: Node) -> _Survey:
    """The tree's names, functions and watched sub-terms, in one walk. Sub-terms without names are constants,
    never watched.

    >>> from grader.model.expr import parse
    >>> found = _survey(parse("v/(p + 1) + exp(-p)"))
    >>> sorted(found.names), sorted(found.functions), sorted((w.kind, to_text(w.node)) for w in found.watched)
    (['p', 'v'], ['exp'], [('large', '-p'), ('small', 'p + 1')])
    """
    functions: set[str] = set()
    found: list[_Watched] = []

    def visit(node: Node) -> frozenset[str]:  # the names the node uses; depth is bounded by the parser
        if isinstance(node, Sym):
            return _NONE if node.name in CONSTANTS else _named(node.name)
        if isinstance(node, Num):
            return _NONE
        args = node.args
        if len(args) == 2:  # most operations: no list, no loop
            left, right = visit(args[0]), visit(args[1])
            uses: tuple[frozenset[str], ...] = (left, right)
            used = left if right <= left else right if left <= right else left | right
        else:
            uses = tuple(visit(arg) for arg in args)
            used = uses[0] if len(uses) == 1 else _union(uses)
        op = node.op
        if op in _TRANSCENDENTAL:
            functions.add(op)
        if used and op in _WATCHING:
            found.extend(_Watched(kind, watched, used if index is None else uses[index])
                         for kind, index, watched in _watches(node, [bool(its) for its in uses]))
        return used

    used = visit(tree)
    return _Survey(used, frozenset(functions), tuple(found))


_WATCHING = frozenset(("div", "pow", "exp", "Max", "Min", *_SMALLEST))


def _watches(node: Op, named: list[bool]) -> list[tuple[str, int | None, Node]]:
    """The sub-terms of an operation that uses a name to watch: (kind, which argument (None: the difference of
    ``Max`` or ``Min``'s two), sub-term); ``named``: whether each argument uses a name."""
    op, args = node.op, node.args
    if op == "div":
        return [("small", 1, args[1])] if named[1] else []
    if op in _SMALLEST:
        return [("small", index, arg) for index, arg in enumerate(args) if named[index]]
    if op in ("Max", "Min"):
        return [("small", None, Op("sub", args))]
    if op == "exp":
        return [("large", 0, args[0])]
    exponent = args[1]  # pow
    if named[0] and not (isinstance(exponent, Num) and exponent.value >= 0 and float(exponent.value).is_integer()):
        return [("small", 0, args[0])]  # a root or a negative power: a kink or a pole at 0
    return []


class _Walked(NamedTuple):
    """What :func:`_walk` finds: a tree's functions of :data:`_TRANSCENDENTAL`, its watched sub-terms with the
    values of each at the points (None for ``Max`` or ``Min``'s difference), its values at the points."""

    functions: frozenset[str]
    watched: tuple[_Watched, ...]
    watched_values: list[np.ndarray | None]
    values: np.ndarray


_EVALUATED = {op: function for op, function in OPERATIONS.items() if op not in ("and", "or")}  # as evaluate does
_PLAIN = frozenset(("add", "sub", "mul"))  # neither transcendental nor watched


def _walk(tree: Node, env: Points) -> _Walked | None:
    """What :func:`_survey` finds of a tree but its names, and its values at ``env``'s points as :func:`_values`
    finds them, in one walk; None where evaluating it would raise (a name ``env`` does not have, an operation
    evaluate treats apart), which :func:`_values` turns into NaN everywhere. A sub-term uses a name where its value
    is an array (every name's is; a constant's is a number)."""
    functions: set[str] = set()
    found: list[_Watched] = []
    seen: list[np.ndarray | None] = []

    def visit(node: Node) -> Any:  # the node's value; depth is bounded by the parser
        if isinstance(node, Op):
            args, op = node.args, node.op
            if len(args) == 2:
                left, right = visit(args[0]), visit(args[1])
                value = _EVALUATED[op](left, right)
                if op in _PLAIN:
                    return value
                values: tuple[Any, ...] = (left, right)
            else:
                values = tuple(visit(arg) for arg in args)
                value = _EVALUATED[op](*values)
                if op == "neg":
                    return value
            if op in _TRANSCENDENTAL:
                functions.add(op)
            if op in _WATCHING and type(value) is np.ndarray:
                for kind, index, watched in _watches(node, [type(at) is np.ndarray for at in values]):
                    found.append(_Watched(kind, watched, _names(watched)))
                    seen.append(None if index is None else values[index])
            return value
        if isinstance(node, Sym):
            return np.pi if node.name in CONSTANTS else env[node.name]
        return _float(node.value)

    try:
        with np.errstate(all="ignore"):
            value = visit(tree)
    except (ArithmeticError, ValueError, TypeError, KeyError):
        return None
    size = len(next(iter(env.values())))
    at = np.asarray(value, dtype=float)
    at = at.copy() if at.shape == (size,) else np.broadcast_to(at, (size,)).copy()
    return _Walked(frozenset(functions), tuple(found), seen, at)


@lru_cache(maxsize=1024)
def _named(name: str) -> frozenset[str]:
    return frozenset((name,))


def _union(uses: tuple[frozenset[str], ...]) -> frozenset[str]:
    first, *rest = uses
    for other in rest:
        if not other <= first:  # mostly a sub-term's names are its sibling's: no new set then
            first = first | other
    return first


@lru_cache(maxsize=1024)
def _survey_of_key(expected: _Form) -> _Survey:
    return _survey(expected.tree)


@lru_cache(maxsize=256)
def _key_structure(expected: _Form, domains: Domains) -> tuple[tuple[Points | None, bool], ...]:
    """The key's probes (see :func:`_structure`), worked out once per key."""
    return tuple(_structure(watched, domains) for watched in _survey_of_key(expected).watched)


@lru_cache(maxsize=4096)
def _structure(watched: _Watched, domains: Domains) -> tuple[Points | None, bool]:
    """Probe points where a watched sub-term is most extreme (and just either side), and whether it comes
    within a rounding of zero inside the domain. Cached: the same denominators recur across a class."""
    kind, node, used = watched
    if _tame(kind, node, used, domains):
        return None, False
    sign = -1.0 if kind == "small" else 1.0

    def score(env: Points) -> np.ndarray:
        values = _values(node, env)
        scored = sign * (np.abs(values) if kind == "small" else values)
        return np.where(np.isnan(scored), -np.inf if kind == "large" else 0.0, scored)

    best = _ascend(score, domains, used)
    if best is None:
        return None, False
    side = {name: np.array([value]) for name, value in best.items()}
    near = False
    if kind == "small":
        size = float(np.max(np.abs(np.nan_to_num(_values(node, _corners(domains)), posinf=0, neginf=0))))
        at = abs(float(_values(node, side)[0]))
        inside = any(low < best[name] < high for name, (low, high) in domains if name in used)
        near = inside and (not (at > _NEAR_ZERO * size) if size > 0 else True)
    probes = [side]
    for name, (low, high) in domains:
        for offset in (1e-9, 1e-6, 1e-3):
            for direction in (-1.0, 1.0):
                moved = dict(side)
                moved[name] = np.clip(side[name] + direction * offset * (high - low), low, high)
                probes.append(moved)
    return _joined(probes), near


def _tame(kind: str, node: Node, used: frozenset[str], domains: Domains) -> bool:
    """Whether a sub-term of one name is seen well enough by the line scans: a denominator or a root's argument
    of one sign that stays above 1e-3 of its largest size (a pole or a peak is then wider than the scans'
    spacing), an exponent that changes by at most 20 over the domain."""
    if len(used) != 1:
        return False  # in two names or more the scans may pass beside the place: search it
    name = next(iter(used))
    low, high = next(bounds for other, bounds in domains if other == name)
    return _tame_values(kind, _values(node, {name: _grid(low, high)}))


def _tame_values(kind: str, values: np.ndarray) -> bool:
    """:func:`_tame` on a sub-term's values along the grid of its one name."""
    least, most = float(np.minimum.reduce(values)), float(np.maximum.reduce(values))  # NaN if any value is
    if not (math.isfinite(least) and math.isfinite(most)):
        return False
    if kind == "large":
        return most - least <= 20
    # Of one sign, its size never below 1e-3 of its largest: |values| run from least to most, or -most to -least.
    return (least > 0 and least > 1e-3 * most) or (most < 0 and -most > 1e-3 * -least)


@lru_cache(maxsize=256)
def _grid(low: float, high: float) -> np.ndarray:
    """:data:`_GRID` points from ``low`` to ``high`` (read only: shared between calls)."""
    along = np.linspace(low, high, _GRID)
    along.flags.writeable = False
    return along


def _ascend(score: Score, domains: Domains, used: frozenset[str]) -> dict[str, float] | None:
    """Coordinate ascent of ``score`` over the box, along the names it ``used``: a grid along each name, zoomed
    in around the grid's best, two sweeps."""
    point = {name: (low + high) / 2 for name, (low, high) in domains}
    if not used:
        return None
    for _ in range(2 if len(used) > 1 else 1):
        for name, (low, high) in domains:
            if name not in used or high <= low:
                continue
            along = np.linspace(low, high, _GRID)
            scores = score(_line(point, name, along))
            index = int(np.argmax(scores))
            point[name] = float(along[index])
            # Zoomed in even at an end of the grid: the place may lie within its last spacing (a sub-term
            # that only tame ones, skipped before, never need).
            left, right = along[max(index - 1, 0)], along[min(index + 1, _GRID - 1)]
            point[name] = _zoom(score, point, name, float(left), float(right), float(scores[index]))
    return point


def _line(point: Mapping[str, float], name: str, along: np.ndarray) -> Points:
    return {other: np.full(along.size, value) for other, value in point.items()} | {name: along}


def _zoom(score: Score, point: dict[str, float], name: str,
          left: float, right: float, best_score: float) -> float:
    """The best place for ``score`` in [left, right]: grids of :data:`_ZOOM` points, each around the last's
    best, :data:`_LEVELS` times (the bracket narrows 16 times a level)."""
    best = point[name]
    for _ in range(_LEVELS):
        along = np.linspace(left, right, _ZOOM)
        scores = score(_line(point, name, along))
        index = int(np.argmax(scores))
        if scores[index] >= best_score:
            best, best_score = float(along[index]), float(scores[index])
        left, right = float(along[max(index - 1, 0)]), float(along[min(index + 1, _ZOOM - 1)])
    return best
