"""Numpy evaluation of expression trees: the compiled kernels.

Every operation is vectorised, so one call answers any number of parameter sets. Degree-argument
sine and cosine reduce the angle in degrees first, so ``cosd(90) == 0`` and ``cosd(89.9999999)``
keeps full relative accuracy.

:func:`evaluate` walks one tree (a constraint, a student's expression). :class:`Kernel` compiles
named trees once into one function of numpy calls for the solver's hot path: a subtree that occurs
more than once is computed once, constants are folded when it is built, the sine and cosine of
one angle share their reduction, and on long float64 columns each call writes into an array no
later step reads, or a scratch array the kernel keeps (``out=``), instead of allocating. None of this
changes a number: every step is the same numpy operation on the same operands as in :func:`evaluate`.

>>> import numpy as np
>>> from grader.model.expr import parse
>>> evaluate(parse("hypot(3*x, 4)"), {"x": np.array([1.0, 0.0])}).tolist()
[5.0, 4.0]
>>> float(cosd(np.float64(90.0))), float(sind(np.float64(-180.0)))
(0.0, 0.0)
>>> kernel = Kernel({"a": parse("sqrt(x) + sqrt(x)*g"), "b": parse("2*sqrt(x)")}, {"g": 9.0})
>>> len(kernel), {name: value.tolist() for name, value in kernel({"x": np.array([4.0])}).items()}
(4, {'a': [20.0], 'b': [4.0]})
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from fractions import Fraction
from functools import reduce
from typing import Any, NamedTuple

import numpy as np

from grader.model.expr import ROOT, Node, Num, Op, Sym, names
from grader.model.roots import find_root

_NUMERIC: dict[str, Any] = {
    "add": np.add, "sub": np.subtract, "mul": np.multiply, "div": np.divide, "neg": np.negative,
    "sqrt": np.sqrt, "sin": np.sin, "cos": np.cos, "tan": np.tan, "exp": np.exp, "log": np.log,
    "abs": np.absolute, "sign": np.sign, "atan2": np.arctan2, "hypot": np.hypot, "Max": np.maximum, "Min": np.minimum,
}
"""Operations that are numpy ufuncs from float64 to float64: they can write into a given array."""


_TRUTH: dict[str, Any] = {
    "lt": np.less, "le": np.less_equal, "gt": np.greater, "ge": np.greater_equal,
    "and": np.logical_and, "or": np.logical_or,
}


class _Quadrant(NamedTuple):
    """An angle as ``360 j + 90 k + r`` degrees with ``|r| <= 45``, as arrays of at least one dimension."""

    k: Any  # k mod 4, as int8; None when it is 0 for every angle (all within ±45°)
    sine: Any  # sin r
    cosine: Any  # cos r
    shape: tuple[int, ...]  # the angle's own shape: () for a number


def _quadrant(degrees: Any, with_sine: bool = True, with_cosine: bool = True) -> _Quadrant:
    """Reduce an angle in degrees exactly: ``fmod`` is exact, and ``r`` is the difference of two
    close numbers. Arrays are written in place where they are this function's own. Where every angle is
    within ±45°, ``with_sine`` or ``with_cosine`` false leaves that one out (None): it is not asked for."""
    x = np.asarray(degrees, dtype=float)
    shape = x.shape
    x = x.reshape(-1)  # a view: never written
    finite = np.isfinite(x)
    every = bool(finite.all())
    if not every:  # a non-finite angle has no sine: NaN, which the caller refuses (never an index error)
        x = np.where(finite, x, 0.0)
    low, high = (float(x.min()), float(x.max())) if every and x.size else (0.0, 0.0)
    if every and low >= -45.0 and high <= 45.0:
        # r is the angle itself (k = 0): the steps below would give these values to the bit (an
        # incline's or a swing's half angle), in 2 numpy calls instead of 9.
        radians = np.multiply(x, np.pi / 180.0)
        return _Quadrant(None, np.sin(radians, out=None if with_cosine else radians) if with_sine else None,
                         np.cos(radians, out=radians) if with_cosine else None, shape)
    # fmod(x, 360) is x itself when |x| < 360, as textbook angles are: skip its cost on long arrays.
    inside = every and x.size >= _SHORT and low > -360.0 and high < 360.0
    reduced = x if inside else np.fmod(x, 360.0)
    quarter = np.divide(reduced, 90.0)
    np.round(quarter, out=quarter)
    radians = np.multiply(quarter, 90.0)
    np.subtract(reduced, radians, out=radians)
    radians *= np.pi / 180.0
    k = quarter.astype(np.int8)  # |quarter| <= 4; int8 keeps this array small
    k &= 3  # mod 4, negative quarters included
    sine = np.sin(radians, out=quarter)
    cosine = np.cos(radians, out=radians)
    if not every:
        sine[~finite] = np.nan
        cosine[~finite] = np.nan
    return _Quadrant(k, sine, cosine, shape)


def _sine_of(quadrant: _Quadrant, turn: int = 0, out: Any = None) -> Any:
    """The sine of ``90 turn + 90 k + r`` degrees, ``sin r * a + cos r * b`` with weights for ``k`` of
    ``(1, 0)``, ``(0, 1)``, ``(-1, 0)``, ``(0, -1)``: one is ±1 and the other 0, so the sum is ±sin r or
    ±cos r exactly (written into ``out``, a float64 array of the angle's shape, if given). Arithmetic,
    not numpy.where, whose branches on mixed quadrants cost 5x more."""
    if quadrant.k is None:  # k = 0: sin r, or cos r for the cosine, as the weighted sum gives it
        value = np.add(quadrant.cosine if turn else quadrant.sine, 0.0, out=None if out is None else out.reshape(-1))
        if out is not None:
            return out
        return value.reshape(quadrant.shape) if quadrant.shape else value[0]
    of_sine, of_cosine = _weights(quadrant.k, turn)
    value = np.multiply(quadrant.sine, of_sine, out=None if out is None else out.reshape(-1))
    value += quadrant.cosine * of_cosine
    value += 0.0  # turns -0.0 into 0.0 (atan2 tells them apart)
    if out is not None:
        return out
    return value.reshape(quadrant.shape) if quadrant.shape else value[0]


# Weights of (sin r, cos r) for k = 0..3 (the sine of 90 k + r degrees), and for k + 1 (its cosine).
_WEIGHTS = ((np.array([1, 0, -1, 0], dtype=np.int8), np.array([0, 1, 0, -1], dtype=np.int8)),
            (np.array([0, -1, 0, 1], dtype=np.int8), np.array([1, 0, -1, 0], dtype=np.int8)))


def _weights(k: Any, turn: int) -> tuple[Any, Any]:
    """The weights of ``sin r`` and ``cos r`` for ``k + turn`` quarter turns (int8): looked up in a
    table for a few angles, computed for many (numpy's indexing costs more than five int8 operations)."""
    if k.size < _SHORT:
        return _WEIGHTS[turn][0][k], _WEIGHTS[turn][1][k]
    if turn:
        k = (k + turn) & 3
    odd, sign = k & 1, 1 - (k & 2)
    return (1 - odd) * sign, odd * sign


def _cosine_of(quadrant: _Quadrant, out: Any = None) -> Any:
    return _sine_of(quadrant, 1, out)  # cos x = sin(x + 90)


def _for_sine(degrees: Any) -> _Quadrant:
    """The quadrant of an angle only the sine of is taken."""
    return _quadrant(degrees, with_cosine=False)


def _for_cosine(degrees: Any) -> _Quadrant:
    """The quadrant of an angle only the cosine of is taken."""
    return _quadrant(degrees, with_sine=False)


def sind(degrees: Any) -> Any:
    """Sine of an angle in degrees."""
    return _sine_of(_quadrant(degrees))


def cosd(degrees: Any) -> Any:
    """Cosine of an angle in degrees."""
    return _cosine_of(_quadrant(degrees))


def _at_least(limit: Any, x: Any, out: Any = None) -> Any:
    """``numpy.maximum(limit, x)`` for a number ``limit`` (not NaN) and a float64 array ``x``, three
    times faster on long arrays (numpy's loop for a number first is slow): ``limit`` where it is
    larger, else ``x``, which is what numpy.maximum gives where they are equal (its second argument:
    -0.0 stays) or ``x`` is NaN."""
    if x.size < _SHORT:
        return np.maximum(limit, x, out=out)
    return _limited(np.greater(limit, x), limit, x, out)


def _at_most(limit: Any, x: Any, out: Any = None) -> Any:
    """``numpy.minimum(limit, x)`` for a number ``limit`` (not NaN) and a float64 array ``x``."""
    if x.size < _SHORT:
        return np.minimum(limit, x, out=out)
    return _limited(np.less(limit, x), limit, x, out)


_SHORT = 4096  # elements below which allocating is cheap, and numpy's own loops beat planning around them
_BLOCK = 32768  # rows per block on long columns at most: 256 KiB arrays; 8,192 made four times the numpy calls
_ALIGN = 1024  # a block's length is a multiple of this: every element meets the numpy loop it meets on the column
_NUMBER, _WRITTEN, _COPIED = -1, -2, -3  # how a root is assembled from blocks (>= 0: it is that input)


def _limited(wins: Any, limit: Any, x: Any, out: Any) -> Any:
    if out is None:
        out = np.array(x, dtype=float)
    elif out is not x:
        np.copyto(out, x)
    np.copyto(out, limit, where=wins)
    return out


def _power(base: Any, exponent: Any, out: Any = None) -> Any:
    if np.ndim(exponent) == 0 and float(exponent) == 2.0:
        return np.multiply(base, base, out=out)
    return np.power(base, exponent, out=out)


_LIMITS = {np.maximum: _at_least, np.minimum: _at_most}
_WRITERS = {*_NUMERIC.values(), np.power, _power, *_LIMITS.values(), _sine_of, _cosine_of}  # functions taking out=

OPERATIONS: dict[str, Callable[..., Any]] = {**_NUMERIC, **_TRUTH, "pow": _power, "sind": sind, "cosd": cosd}
"""Every operation of a tree by name (``and`` and ``or`` take two arguments here; a tree's may take more)."""


def _float(value: Fraction | float) -> float:
    """An exact constant as float64: beyond its range, an infinity the caller refuses like any overflow.

    >>> _float(Fraction(10**400, 3)), _float(Fraction(1, 4))
    (inf, 0.25)
    """
    try:
        # A fraction's float is its numerator over its denominator (numbers.Rational.__float__, without its calls).
        return value.numerator / value.denominator if type(value) is Fraction else float(value)
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
    if node.op == ROOT:
        residual, bound, low, high = node.args
        inputs = sorted(names(node))
        root = _Root(lambda values: evaluate(residual, values), tuple(inputs), _bound(bound))
        return root(evaluate(low, env), evaluate(high, env), *(env[name] for name in inputs))
    return _apply(node.op, [evaluate(arg, env) for arg in node.args])


def _bound(node: Node) -> str:
    assert isinstance(node, Sym)  # from_json refuses anything else
    return node.name


class _Root:
    """``root(r, x, low, high)`` as a step: ``residual`` evaluates ``r`` from its inputs (``inputs``' values and
    ``bound``'s), for the rows :func:`~grader.model.roots.find_root` asks, on every row of the inputs at once."""

    def __init__(self, residual: Callable[[Mapping[str, Any]], Any], inputs: tuple[str, ...], bound: str) -> None:
        self.residual, self.inputs, self.bound = residual, inputs, bound

    def __call__(self, low: Any, high: Any, *values: Any) -> Any:
        shape = np.broadcast_shapes(*(np.shape(value) for value in values))
        columns = [np.broadcast_to(np.asarray(value, dtype=float), shape).reshape(-1) for value in values]

        def at(x: np.ndarray, rows: np.ndarray) -> np.ndarray:
            found = self.residual({**{name: column[rows] for name, column in zip(self.inputs, columns, strict=True)},
                                   self.bound: x})
            return np.broadcast_to(np.asarray(found, dtype=float), x.shape)

        with np.errstate(all="ignore"):
            root = find_root(at, float(low), float(high), int(np.prod(shape)))
        return root.reshape(shape) if shape else root[0]


def _apply(op: str, args: list[Any]) -> Any:
    if op in ("and", "or"):  # a constraint may join more than two conditions
        return reduce(_TRUTH[op], args)
    return OPERATIONS[op](*args)


class _Step(NamedTuple):
    target: int  # the slot the result goes to
    function: Callable[..., Any]
    args: tuple[int, ...]
    out: int  # a slot whose array nothing reads any more, to write the result into; -1: allocate
    scratch: int = -1  # else the kernel's scratch array to write it into (>= 0), when no such slot is free


class Kernel:
    """Named trees compiled into numpy calls made in a row; ``kernel(inputs)`` evaluates them all.

    Building it walks the trees once: equal subtrees become one step, operations on constants
    (``constants`` and numbers) are done here, ``sind`` and ``cosd`` of one angle share its
    reduction. The steps then become the text of one Python function, compiled once, so that a call
    does no work per tree node beyond the numpy calls themselves (as ``sympy.lambdify`` does): it reads
    the inputs from the mapping and builds the mapping of results itself, and a float constant reaches
    numpy as a read-only 0-d array, which numpy takes faster than a Python float. That text is made
    here from slot numbers alone (``v7 = f2(x0, a3, out=v5)``): no name, number or text of a tree or
    template enters it, and it runs with no builtins, so it can only call this kernel's own functions
    on its own values. When every input is a float64 array of one shape, and a long one
    (``solve_columns`` gives such columns), a step whose function takes ``out=`` writes into the
    array of a step that nothing reads any more, or else into a scratch array of the kernel's, planned
    here (:meth:`_by_blocks`); otherwise each step allocates its result.
    For float64 inputs (arrays, or Python or numpy numbers) results are those of :func:`evaluate` bit
    for bit, and numbers stay numbers. A result may be an input array itself, or a
    number when it depends on no input.
    """

    def __init__(self, trees: Mapping[str, Node], constants: Mapping[str, float] | None = None) -> None:
        self._known: dict[str, Any] = {"pi": np.pi, **(constants or {})}
        self._slots: dict[Any, int] = {}  # a node (or a derived key) -> its slot
        self._values: list[Any] = []  # a slot's value when it is known now, else None
        self._floats: list[bool] = []  # whether a slot holds float64 when the inputs do
        self._steps: list[_Step] = []
        self.inputs: list[str] = []
        self.roots = {name: self._slot(tree) for name, tree in trees.items()}
        self._one_sided()
        in_place = self._plan_buffers()
        self._kinds = self._root_kinds(in_place)
        self._no_outs = (None,) * len(self._kinds)
        self._spares: list[list[Any]] = []  # scratch arrays of _BLOCK elements for long columns, kept between calls
        self._run, self._block = self._functions(self._steps, in_place)

    def _root_kinds(self, in_place: list[_Step]) -> list[int]:
        """How :meth:`_by_blocks` assembles each root: an input's position when it is that input,
        ``_NUMBER`` when it depends on no input, ``_WRITTEN`` when its step writes a float64 result into
        a given array (the first root of that step), else ``_COPIED``."""
        places = {self._slots[("input", name)]: index for index, name in enumerate(self.inputs)}
        writers = {step.target for step in in_place if step.function in _WRITERS and self._floats[step.target]}
        kinds, written = [], set()
        for slot in self.roots.values():
            if slot in places:
                kinds.append(places[slot])
            elif self._values[slot] is not None:
                kinds.append(_NUMBER)
            elif slot in writers and slot not in written:
                kinds.append(_WRITTEN)
                written.add(slot)
            else:
                kinds.append(_COPIED)
        return kinds

    def __len__(self) -> int:
        """How many numpy calls one evaluation makes (one per distinct subtree that needs the inputs)."""
        return len(self._steps)

    def __call__(self, inputs: Mapping[str, Any]) -> dict[Any, Any]:
        """Every tree's value, by name; ``inputs`` holds the names the trees use."""
        return self._run(inputs)

    def _by_blocks(self, arrays: tuple[Any, ...]) -> dict[Any, Any]:
        """The in-place steps on long columns, a block of ``_BLOCK`` rows at a time (numexpr's way): the
        block's arrays stay in the processor's cache, and a step that finds no array it may write over
        writes into a scratch array this kernel keeps between calls. New arrays of that size
        (256 KiB) come from the operating system, a page fault per 4 KiB on every call: at 100,000 rows
        that was three times the arithmetic. A float result is written by its step straight into its
        block of the result; any other is copied there. Every element meets the same numpy loop as on
        the whole column, since blocks start at multiples of ``_ALIGN`` elements (vector loops take a few
        at a time), so the numbers are the same to the bit. Calls at once (threads) each take a set of
        scratch arrays of their own."""
        size, shape = arrays[0].size, arrays[0].shape
        if size > _BLOCK and (len(shape) != 1 or not all(a.flags.c_contiguous for a in arrays)):
            scratch = [np.empty(shape) for _ in range(self._scratch)]  # one block, with scratch arrays of its own
            return dict(zip(self.roots, self._block(*arrays, *self._no_outs, *scratch), strict=True))
        try:
            spare = self._spares.pop()  # atomic: two threads never take one set
        except IndexError:
            spare = [np.empty(_BLOCK) for _ in range(self._scratch)]
        try:
            if size <= _BLOCK:
                scratch = [array[:size].reshape(shape) for array in spare]
                return dict(zip(self.roots, self._block(*arrays, *self._no_outs, *scratch), strict=True))
            return self._blocks(arrays, spare)
        finally:
            self._spares.append(spare)

    def _blocks(self, arrays: tuple[Any, ...], spare: list[Any]) -> dict[Any, Any]:
        size = arrays[0].size
        # Per root: an array the block's step writes into, one to copy into (its dtype is known after
        # the first block), the input itself, or the number it is.
        results: list[Any] = [np.empty(size) if kind == _WRITTEN else None for kind in self._kinds]
        blocks = -(-size // _BLOCK)
        length = -(-size // blocks // _ALIGN) * _ALIGN  # blocks of one length (the last shorter), none tiny
        full = [array[:length] for array in spare]
        for start in range(0, size, length):
            stop = start + length
            outs = [None if result is None or kind != _WRITTEN else result[start:stop]
                    for kind, result in zip(self._kinds, results, strict=True)]
            scratch = full if stop <= size else [array[:size - start] for array in spare]
            values = self._block(*(a[start:stop] for a in arrays), *outs, *scratch)
            for index, (kind, value) in enumerate(zip(self._kinds, values, strict=True)):
                if kind == _COPIED:
                    if results[index] is None:
                        results[index] = np.empty(size, dtype=value.dtype)
                    results[index][start:stop] = value
                elif kind == _NUMBER or (kind >= 0 and start == 0):
                    results[index] = value if kind == _NUMBER else arrays[kind]
        return dict(zip(self.roots, results, strict=True))

    def _functions(self, plain: list[_Step], in_place: list[_Step]) -> tuple[Callable[[Mapping[str, Any]], dict[
            Any, Any]], Callable[..., tuple[Any, ...]]]:
        """Two Python functions. The first reads the inputs from the mapping and returns the roots' values
        by name: when every input is a long float64 array of one shape it hands them to
        :meth:`_by_blocks`, else it makes ``plain``'s calls in order (no per-call work beyond the numpy
        calls and a few attribute reads, as lambdify's function). The second makes ``in_place``'s calls
        on positional inputs and returns the roots' values in order. Names and keys reach them as
        values in their namespace, never as text."""
        inputs = {self._slots[("input", name)]: f"x{index}" for index, name in enumerate(self.inputs)}
        namespace: dict[str, Any] = {"__builtins__": {}, "ndarray": np.ndarray, "short": _SHORT, "uniform": _uniform,
                                     "blocks": self._by_blocks}
        functions: dict[Callable[..., Any], str] = {}

        def value(slot: int, argument: bool = True) -> str:
            if slot in inputs:
                return inputs[slot]
            known = self._values[slot]
            if known is None:
                return f"v{slot}"
            if argument and _is_float(known):
                # A float64 number as a read-only 0-d array: numpy takes it as is, where a Python float
                # goes through its scalar conversion on every call (x/c: 1.7 us against 0.8 us on 2,000).
                namespace[f"a{slot}"] = _frozen(known)
                return f"a{slot}"
            namespace[f"c{slot}"] = known
            return f"c{slot}"

        def calls(steps: list[_Step], outs: Mapping[int, str]) -> list[str]:
            lines = []
            for step in steps:
                called = functions.setdefault(step.function, f"f{len(functions)}")
                namespace[called] = step.function
                out = outs.get(step.target) or (value(step.out) if step.out >= 0 else
                                                f"s{step.scratch}" if step.scratch >= 0 else None)
                args = [value(arg) for arg in step.args] + ([f"out={out}"] if out else [])
                lines.append(f"    v{step.target} = {called}({', '.join(args)})")
            return lines

        every = "".join(f"{name}, " for name in inputs.values())
        roots = list(enumerate(self.roots.values()))
        namespace.update({f"n{index}": name for index, name in enumerate(self.inputs)})
        namespace.update({f"r{index}": name for index, name in enumerate(self.roots)})
        lines = ["def kernel(inputs):"] + [f"    x{index} = inputs[n{index}]" for index in range(len(self.inputs))]
        if self.inputs:  # short-circuits on the first input's type and size: a short column pays two reads
            lines.append(f"    if x0.__class__ is ndarray and x0.size >= short and uniform(({every})):")
            lines.append(f"        return blocks(({every}))")
        lines += calls(plain, {})
        lines.append(f"    return {{{', '.join(f'r{index}: {value(slot, False)}' for index, slot in roots)}}}")
        outs = {slot: f"o{index}" for (index, slot), kind in zip(roots, self._kinds, strict=True) if kind == _WRITTEN}
        scratch = "".join(f"s{index}, " for index in range(self._scratch))
        lines.append(f"def block({every}{''.join(f'o{index}, ' for index, _ in roots)}{scratch}):")
        lines += calls(in_place, outs)
        lines.append(f"    return ({''.join(value(slot, False) + ', ' for _, slot in roots)})")
        exec(compile("\n".join(lines), "<grader kernel>", "exec"), namespace)  # noqa: S102  (text of slot numbers)
        return namespace["kernel"], namespace["block"]

    def _new(self, key: Any, value: Any = None, floats: bool = True) -> int:
        self._slots[key] = len(self._values)
        self._values.append(value)
        self._floats.append(floats)
        return self._slots[key]

    def _slot(self, node: Node) -> int:
        if node in self._slots:
            return self._slots[node]
        if isinstance(node, Num):
            return self._new(node, _float(node.value))
        if isinstance(node, Sym):
            if node.name in self._known:
                return self._new(node, self._known[node.name])
            if ("input", node.name) not in self._slots:
                self.inputs.append(node.name)
                self._new(("input", node.name))
            self._slots[node] = self._slots[("input", node.name)]
            return self._slots[node]
        if node.op == ROOT:
            slot = self._root(node)
            self._slots[node] = slot
            return slot
        args = tuple(self._slot(arg) for arg in node.args)
        if node.op in ("and", "or"):  # two at a time, as evaluate does
            return reduce(lambda left, right: self._call(_TRUTH[node.op], (left, right), floats=False), args)
        if node.op in ("sind", "cosd"):
            quadrant = self._call(_quadrant, args, floats=False)
            slot = self._call(_sine_of if node.op == "sind" else _cosine_of, (quadrant,), floats=True)
        elif node.op == "pow":
            slot = self._power(args)
        else:
            slot = self._call(OPERATIONS[node.op], args, floats=None if node.op in _NUMERIC else False)
        self._slots[node] = slot
        return slot

    def _root(self, node: Op) -> int:
        """A numeric block's root: its residual compiled as a kernel of its own, called by one step."""
        residual, bound, low, high = node.args
        inner = Kernel({"r": residual}, {name: value for name, value in self._known.items() if name != "pi"})
        inputs = tuple(name for name in inner.inputs if name != _bound(bound))
        step = _Root(lambda values: inner(values)["r"], inputs, _bound(bound))
        return self._call(step, (self._slot(low), self._slot(high), *(self._slot(Sym(name)) for name in inputs)),
                          floats=True)

    def _power(self, args: tuple[int, ...]) -> int:
        base, exponent = args
        if self._values[exponent] is None:  # an exponent that depends on the inputs
            return self._call(_power, args)
        if np.ndim(self._values[exponent]) == 0 and float(self._values[exponent]) == 2.0:
            return self._call(np.multiply, (base, base))  # what _power does
        return self._call(np.power, args)

    def _call(self, function: Callable[..., Any], args: tuple[int, ...], floats: bool | None = None) -> int:
        """The slot of ``function(*args)``: a known value when every argument is known, else a step.
        ``floats``: whether the result is float64 when the inputs are; None: when its arguments are."""
        key = (function, args)
        if key in self._slots:
            return self._slots[key]
        known = [self._values[a] for a in args]
        if all(value is not None for value in known):
            with np.errstate(all="ignore"):  # as evaluate does it under the caller's errstate
                return self._new(key, function(*known))
        if floats is None:
            floats = all(self._floats[a] if self._values[a] is None else _is_float(self._values[a]) for a in args)
        slot = self._new(key, floats=floats)
        self._steps.append(_Step(slot, function, args, -1))
        return slot

    def _one_sided(self) -> None:
        """An angle only the sine or only the cosine of is taken has its quadrant without the other: for
        angles within ±45° (a half angle, a small incline) one numpy call fewer, the sine's own."""
        taken: dict[int, set[Callable[..., Any]]] = {}
        for step in self._steps:
            if step.function in (_sine_of, _cosine_of):
                taken.setdefault(step.args[0], set()).add(step.function)
        for index, step in enumerate(self._steps):
            if step.function is _quadrant and len(taken[step.target]) == 1:
                one = _for_sine if _sine_of in taken[step.target] else _for_cosine
                self._steps[index] = step._replace(function=one)

    def _plan_buffers(self) -> list[_Step]:
        """The steps again, each ufunc writing into the array of a step no later step reads, else into a
        scratch array of the kernel's (a root's step writes into its block of the result instead)."""
        last_use: dict[int, int] = {}
        for index, step in enumerate(self._steps):
            for arg in step.args:
                last_use[arg] = index
        roots = set(self.roots.values())
        for slot in roots:
            last_use[slot] = len(self._steps)  # results are returned: never written over
        computed = {step.target for step in self._steps}
        free: list[int] = []
        planned = []
        self._scratch = 0
        for index, step in enumerate(self._steps):
            for arg in dict.fromkeys(step.args):  # an argument read for the last time may be the output
                if arg in computed and self._floats[arg] and last_use[arg] == index:
                    free.append(arg)
            step = self._faster(step)
            if step.function not in _WRITERS or not self._floats[step.target] or step.target in roots:
                planned.append(step)
            elif free:
                planned.append(step._replace(out=free.pop()))
            else:
                planned.append(step._replace(scratch=self._scratch))
                self._scratch += 1
        return planned

    def _faster(self, step: _Step) -> _Step:
        """``Max(0, x)`` (an energy lost is never negative) without numpy's slow loop for a number first."""
        limit = self._values[step.args[0]]
        if step.function in _LIMITS and _is_float(limit) and limit == limit and self._floats[step.args[1]]:
            return step._replace(function=_LIMITS[step.function])
        return step


def _is_float(value: Any) -> bool:
    return isinstance(value, float) or (isinstance(value, np.generic) and value.dtype == np.float64)


_FLOAT64 = np.dtype(np.float64)


def _frozen(number: Any) -> Any:
    """A float64 number as a 0-d array nothing can write into. With float64 operands (the inputs the
    kernel takes: float64 arrays and Python or numpy numbers) numpy's result is the same as with the
    number itself, to the bit and in type (a ufunc returns a 0-d result as a number)."""
    array = np.array(number, dtype=np.float64)
    array.setflags(write=False)
    return array


def _uniform(arrays: Sequence[Any]) -> bool:
    """Whether every input is a float64 array of one shape (and not a short one), so every step's result
    has that shape too."""
    if not arrays or type(arrays[0]) is not np.ndarray or arrays[0].size < _SHORT:  # short: allocating is cheap
        return False
    shape = arrays[0].shape
    return all(type(a) is np.ndarray and a.dtype is _FLOAT64 and a.shape == shape for a in arrays)
