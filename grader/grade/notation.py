"""Arithmetic as students write it: implicit products written out, then parsed by the allow-list parser
of :mod:`grader.model.expr`, bounded in size, and (without names) evaluated step by step.

>>> to_text(tree_of("2v(1 + p)", ("p", "v")))
'2*v*(1 + p)'
>>> value_of(tree_of("sqrt(2*9.81*2)", ()))
6.26418390534633
>>> value_of(tree_of("9^9^9", ()))
Traceback (most recent call last):
...
grader.grade.notation.ReadError: the power 3.8742e+08 is larger than 64
"""

from __future__ import annotations

import math
import operator
import re
from collections.abc import Callable, Sequence
from functools import lru_cache

import numpy as np

from grader.base.errors import ExpressionError
from grader.grade.infix import read_tokens
from grader.model.expr import CONSTANTS, FUNCTIONS, MAX_EXPONENT, Node, Num, Op, Sym, names, parse, to_text
from grader.model.kernel import OPERATIONS

MAX_NODES = 200
MAX_NAME = 50


class ReadError(ValueError):
    """Text that cannot be read; the message is the student's reason."""


# A token after its spaces, or (where none starts) the character where reading stops. Read with findall, whose
# groups are (spaces, number, name, operator, other): a third of the time a loop over match objects takes.
_TOKEN = re.compile(r"(\s*)(?:((?>\d+(?:\.\d*)?|\.\d+)(?>[eE][-+]?\d+)?)|([A-Za-z_][A-Za-z_0-9]*)"
                    r"|(\*\*|[-+*/^×·(),]))|(\S)")
_TOKEN_NO_E = re.compile(_TOKEN.pattern.replace(r"(?>[eE][-+]?\d+)?", ""))
_CALLED = re.compile(r"\s*\(")  # after a name: it is called


def tree_of(text: str, symbols: tuple[str, ...]) -> Node:
    """Parse with the allow-list parser after writing out implicit products; bounded in size."""
    parts = _written(text, symbols)
    tree = read = read_tokens(parts)
    if tree is None:  # not a common shape: parse reads it, and says what is wrong
        written = "".join(parts)
        try:
            tree = parse(written)
        except ExpressionError as error:
            raise ReadError(str(error).replace(written, cut(text, 60))) from None
    # Each node read from the tokens has a token of its own: a short list needs no count.
    if (len(parts) > MAX_NODES or tree is not read) and _count(tree) > MAX_NODES:
        raise ReadError(f"more than {MAX_NODES} numbers, names and operations; simplify the answer")
    return tree


def _written(text: str, symbols: tuple[str, ...]) -> list[str]:
    """The tokens of text :func:`parse` accepts, one Python token each: ``2v(1+p)`` becomes
    ``2 * v * ( 1 + p )``; names outside ``symbols``, the functions and ``pi`` are refused, and so are
    characters outside the allow-list."""
    tokenizer = _TOKEN_NO_E if "e" in symbols or "E" in symbols else _TOKEN
    out: list[str] = []
    previous = ""  # kind of the last token: num, name, func, ( , ) or op
    calls: list[bool] = []  # for each open parenthesis: does it hold a function's arguments?
    position = 0
    for spaces, number, word, symbol, other in tokenizer.findall(text):
        if other:  # not a token where the last one ended
            break
        token = number or word or symbol
        position += len(spaces) + len(token)
        parts: tuple[str, ...] | None = None  # the token, unless written as several
        if number:
            if previous == "num":
                raise ReadError(f"two numbers side by side ({cut(text, 40)}); give one answer")
            _check_underflow(token)
            kind = "num"
        elif word:
            if token in symbols or token in CONSTANTS:  # as _name says, sooner
                kind = "name"
            else:
                kind, parts = _name(token, symbols, text[position:position + 1] == "(" or
                                    _CALLED.match(text, position) is not None)
        else:
            kind, token = token, _WRITTEN.get(token, token)
            if kind == "(":
                calls.append(previous == "func")
            elif kind == ")" and calls:
                calls.pop()
            elif kind == ",":
                _check_comma(calls, previous, text[position:])
        if previous in _BEFORE_PRODUCT and kind in _AFTER_PRODUCT:
            out.append("*")
        if parts is None:
            out.append(token)
        else:
            out += parts
        previous = kind
        if len(out) > 3 * MAX_NODES:  # bounded work a cell: refused before it is parsed (parentheses counted)
            raise ReadError(f"more than {MAX_NODES} numbers, names and operations; simplify the answer")
    rest = text[position:].lstrip()
    if rest:
        if rest[0] == "∞":
            raise ReadError("infinity is not a finite number")
        raise ReadError(f"unexpected character '{rest[0]}'" if rest[0].isprintable() else
                          f"unexpected character U+{ord(rest[0]):04X}")
    return out


_WRITTEN = {"^": "**", "×": "*", "·": "*"}
_BEFORE_PRODUCT = frozenset(("num", "name", ")"))  # a token after which ...
_AFTER_PRODUCT = frozenset(("num", "name", "func", "("))  # ... one of these is multiplied: 2v, v(1 + p), (p)2


def _check_underflow(number: str) -> None:
    """Refuse a number float64 would read as 0 though its digits are not (``1e-400``)."""
    if float(number) == 0 and any(digit in "123456789" for digit in number.lower().partition("e")[0]):
        raise ReadError(f"{cut(number, 40)} is too small for a number (below about 5e-324 it would be read as 0); "
                        "write 0 if you mean 0")


@lru_cache(maxsize=4096)  # a class writes the same run of names (pv) again and again
def _name(word: str, symbols: tuple[str, ...], called: bool) -> tuple[str, tuple[str, ...]]:
    if word in symbols or word in CONSTANTS:
        return "name", (word,)
    if word in FUNCTIONS:
        if not called:
            raise ReadError(f"write {word}(...) with parentheses")
        return "func", (word,)
    split = _split_name(word, (*symbols, *CONSTANTS)) if len(word) <= MAX_NAME else None
    if split is None:
        if not symbols and word.lower() in ("inf", "infinity", "nan"):
            raise ReadError(f"{word} is not a finite number")
        if not symbols:
            raise ReadError(f"cannot read '{word[:30]}' as a number")
        raise ReadError(f"unknown name {word[:30]}; use {listed(symbols)}")
    return "name", tuple(part for name in split for part in ("*", name))[1:]


def _split_name(word: str, known: Sequence[str]) -> list[str] | None:
    """``pv`` as ``p*v`` when both are symbols: the first way to write ``word`` as known names."""
    ways: list[list[str] | None] = [[]] + [None] * len(word)
    for start in range(len(word)):
        way = ways[start]
        if way is None:
            continue
        for name in known:
            end = start + len(name)
            if name and word.startswith(name, start) and ways[end] is None:
                ways[end] = [*way, name]
    return ways[-1]


def _check_comma(calls: list[bool], previous: str, rest: str) -> None:
    if calls and calls[-1]:
        return
    if previous == "num" and rest[:1].isdigit():
        raise ReadError("a decimal comma; write a decimal point in an expression (0.5, not 0,5)")
    raise ReadError("a comma outside a function's parentheses; give one answer")


def cut(text: str, limit: int) -> str:
    """``text`` for a message, cut to ``limit`` characters."""
    return text if len(text) <= limit else text[:limit - 3] + "..."


def listed(symbols: Sequence[str]) -> str:
    if not symbols:
        return "no names"
    return symbols[0] if len(symbols) == 1 else ", ".join(symbols[:-1]) + " and " + symbols[-1]


def uses_a_name(tree: Node) -> bool:
    """Whether the tree uses a name (``pi`` is not one); stops at the first (``names`` walks all of it).

    >>> uses_a_name(tree_of("2*pi*(1 + 3)", ())), uses_a_name(tree_of("2*pi*v", ("v",)))
    (False, True)
    """
    stack = [tree]
    while stack:
        node = stack.pop()
        if isinstance(node, Op):
            stack.extend(node.args)
        elif isinstance(node, Sym) and node.name not in CONSTANTS:
            return True
    return False


def _count(tree: Node) -> int:
    count, stack = 0, [tree]
    while stack:
        node = stack.pop()
        count += 1
        if isinstance(node, Op):
            stack.extend(node.args)
    return count


def check_powers(tree: Node) -> None:
    """Exponents without names are numbers we can bound now (``p^(2^10)``); the others are bounded
    where the expression is evaluated."""
    if isinstance(tree, Op):
        for arg in tree.args:
            check_powers(arg)
        if tree.op == "pow" and not names(tree.args[1]) and abs(value_of(tree.args[1])) > MAX_EXPONENT:
            raise ReadError(f"the power {to_text(tree.args[1])} is larger than {MAX_EXPONENT}")


def value_of(tree: Node) -> float:
    """The value of an expression without names, every step finite and every power at most
    :data:`MAX_EXPONENT`, or :class:`ReadError` saying which step failed."""
    with np.errstate(all="ignore"):
        return _step(tree)


_PLAIN_ARITHMETIC: dict[str, Callable[..., float]] = {
    "add": operator.add, "sub": operator.sub, "mul": operator.mul, "div": operator.truediv, "neg": operator.neg}


def _step(node: Node) -> float:
    if isinstance(node, Num):
        try:
            return float(node.value)
        except OverflowError:
            raise ReadError(f"{cut(to_text(node), 40)} is too large for a number") from None
    if isinstance(node, Sym):
        if node.name == "pi":
            return math.pi
        raise ReadError(f"cannot read '{node.name}' as a number")
    args = [_step(arg) for arg in node.args]
    if node.op == "pow" and abs(args[1]) > MAX_EXPONENT:
        raise ReadError(f"the power {args[1]:g} is larger than {MAX_EXPONENT}")
    plain = _PLAIN_ARITHMETIC.get(node.op)
    try:
        # Python's own arithmetic on floats where it agrees with numpy's (a division by zero, an overflow
        # below end up as the non-finite numbers numpy would give): a numpy call on two floats costs 20 times
        # as much, and a 480-character cell has a hundred steps.
        result = float(plain(*args) if plain is not None else OPERATIONS[node.op](*args))
    except ZeroDivisionError:
        result = math.inf
    if math.isfinite(result):
        return result
    step = cut(to_text(node), 60)
    if node.op == "div" or (node.op == "pow" and args[0] == 0):
        raise ReadError(f"{step} divides by zero")
    if math.isnan(result) or node.op == "log":
        raise ReadError(f"{step} is not defined")
    raise ReadError(f"{step} is too large for a number (beyond about 1.8e308)")
