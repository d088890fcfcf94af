"""The common shapes of an expression read straight from its tokens, into the tree :func:`grader.model.expr.parse`
makes of their text, without Python's compiler in between (a third of the time a student's cell takes to read).

:func:`grader.model.expr.parse` stays the authority: :func:`read_tokens` reads numbers, names, ``+ - * / **``,
parentheses and calls of the allowed functions, Python's precedence and nothing else, and gives up (None) on
anything else, an error included, so that ``parse`` reads it and says what is wrong. Where it gives a tree, it is
the one ``parse`` gives for the joined tokens (a property test holds it to that).

>>> from grader.model.expr import parse, to_text
>>> tokens = ["2", "*", "v", "*", "(", "1", "-", "0.1", "*", "p", ")", "**", "-", "2"]
>>> read_tokens(tokens) == parse("".join(tokens)), to_text(read_tokens(tokens))
(True, '2*v*(1 - 0.1*p)**(-2)')
>>> read_tokens(["p", "*", "*", "v"]) is None  # joined, '**': parse reads it
True
"""

from __future__ import annotations

import keyword
import math
from collections.abc import Sequence
from fractions import Fraction
from functools import lru_cache

from grader.model.expr import (
    FUNCTIONS,
    MAX_DEPTH,
    MAX_EXPONENT,
    MAX_LENGTH,
    Node,
    Num,
    Op,
    Sym,
    _decimal_fraction,  # parse's own reading of a float's text: one place
)

_NESTED = 50  # parentheses inside each other beyond which parse decides (Python's own limit is 200)
_ADDING = {"+": "add", "-": "sub"}
_MULTIPLYING = {"*": "mul", "/": "div"}


class _UnusualError(Exception):
    """Tokens outside the common shapes (or wrong): parse reads them."""


def read_tokens(tokens: Sequence[str]) -> Node | None:
    """The tree :func:`grader.model.expr.parse` makes of ``"".join(tokens)``, ``tokens`` one Python token each; or
    None where the tokens are not a common shape (then ``parse`` reads them and says what is wrong)."""
    if not tokens or sum(map(len, tokens)) > MAX_LENGTH:
        return None
    reader = _Reader(tokens)
    try:
        tree = reader.sum()
    except _UnusualError:
        return None
    if reader.at != len(tokens):
        return None
    # parse refuses a tree deeper than MAX_DEPTH. Each level of Python's tree has a token of its own (an operator,
    # a sign, a function's name), so only a longer list can be too deep; there, a unary plus (a level of Python's
    # tree, not of ours) is left to parse.
    if len(tokens) > MAX_DEPTH and (reader.plus or _height(tree) > MAX_DEPTH):
        return None
    return tree


class _Reader:
    """Python's grammar for ``sum``, ``term``, ``factor`` (with ``power``) and ``primary``, over tokens."""

    __slots__ = ("at", "nested", "plus", "tokens")

    def __init__(self, tokens: Sequence[str]) -> None:
        self.tokens, self.at, self.nested, self.plus = [*tokens, ""], 0, 0, False  # "": the end, never a token

    def take(self, token: str) -> None:
        if self.tokens[self.at] != token:
            raise _UnusualError
        self.at += 1

    def sum(self) -> Node:
        tree = self.term()
        while (op := _ADDING.get(self.tokens[self.at])) is not None:
            self.at += 1
            tree = Op(op, (tree, self.term()))
        return tree

    def term(self) -> Node:
        tree = self.factor()
        while (op := _MULTIPLYING.get(self.tokens[self.at])) is not None:
            self.at += 1
            tree = Op(op, (tree, self.factor()))
        return tree

    def factor(self) -> Node:
        sign = self.tokens[self.at]
        if sign == "-":
            self.at += 1
            return Op("neg", (self.factor(),))
        if sign == "+":
            self.at, self.plus = self.at + 1, True
            return self.factor()
        base = self.primary()
        if self.tokens[self.at] != "**":
            return base
        self.at += 1
        exponent = self.factor()  # Python's power: a primary, '**', a factor (-p**2 is -(p**2), p**-2 is p**(-2))
        if isinstance(exponent, Num) and not -MAX_EXPONENT <= exponent.value <= MAX_EXPONENT:
            raise _UnusualError
        return Op("pow", (base, exponent))

    def primary(self) -> Node:
        tokens = self.tokens
        token = tokens[self.at]
        self.at += 1
        first = token[:1]  # "" at the end
        if first.isdigit() or first == ".":
            return _number(token)
        if first.isalpha() or first == "_":
            if tokens[self.at] != "(":
                if keyword.iskeyword(token):
                    raise _UnusualError
                return _symbol(token)
            return self.call(token)
        if first != "(":
            raise _UnusualError
        self.nested += 1
        if self.nested > _NESTED:
            raise _UnusualError
        tree = self.sum()
        self.take(")")
        self.nested -= 1
        return tree

    def call(self, name: str) -> Node:
        if name not in FUNCTIONS:
            raise _UnusualError
        self.at += 1
        args = []
        for index in range(FUNCTIONS[name]):
            if index:
                self.take(",")
            args.append(self.sum())
        self.take(")")
        return Op(name, tuple(args))


def _height(tree: Node) -> int:
    return 1 + max(map(_height, tree.args)) if isinstance(tree, Op) else 0


@lru_cache(maxsize=4096)
def _symbol(name: str) -> Sym:
    return Sym(name)


@lru_cache(maxsize=4096)  # a class writes the same numbers, an answer often one number twice
def _number(token: str) -> Num:
    """The number parse reads from a literal: an integer exactly, any other as float64 then the exact value of its
    shortest text (``0.1`` is 1/10)."""
    if not token.isascii() or (token[:1] == "0" and token[1:2].isdigit()):
        raise _UnusualError  # Python reads ASCII digits only, and no leading zeros in an integer
    if token.isdigit():
        return Num(Fraction(int(token)))
    value = float(token)
    if not math.isfinite(value):
        raise _UnusualError
    return Num(_decimal_fraction(repr(value)))  # as parse makes it (Fraction(text) is four times slower)
