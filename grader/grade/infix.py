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

from grader.model.expr import FUNCTIONS, MAX_DEPTH, MAX_EXPONENT, MAX_LENGTH, Node, Num, Op, Sym

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
        tree, height = reader.sum()
    except _UnusualError:
        return None
    # parse refuses a tree deeper than MAX_DEPTH, counting a unary plus (not in the tree) as a level.
    return tree if reader.at == len(tokens) and height <= MAX_DEPTH else None


class _Reader:
    """Python's grammar for ``sum``, ``term``, ``factor``, ``power`` and ``primary``, over tokens; each returns a
    tree and its height in Python's syntax tree."""

    __slots__ = ("at", "nested", "tokens")

    def __init__(self, tokens: Sequence[str]) -> None:
        self.tokens, self.at, self.nested = [*tokens, ""], 0, 0  # "": the end, never a token

    def take(self, token: str) -> None:
        if self.tokens[self.at] != token:
            raise _UnusualError
        self.at += 1

    def sum(self) -> tuple[Node, int]:
        tree, height = self.term()
        while (op := _ADDING.get(self.tokens[self.at])) is not None:
            self.at += 1
            right, right_height = self.term()
            tree, height = Op(op, (tree, right)), max(height, right_height) + 1
        return tree, height

    def term(self) -> tuple[Node, int]:
        tree, height = self.factor()
        while (op := _MULTIPLYING.get(self.tokens[self.at])) is not None:
            self.at += 1
            right, right_height = self.factor()
            tree, height = Op(op, (tree, right)), max(height, right_height) + 1
        return tree, height

    def factor(self) -> tuple[Node, int]:
        sign = self.tokens[self.at]
        if sign == "-" or sign == "+":
            self.at += 1
            operand, height = self.factor()
            return (Op("neg", (operand,)) if sign == "-" else operand), height + 1
        return self.power()

    def power(self) -> tuple[Node, int]:
        base, height = self.primary()
        if self.tokens[self.at] != "**":
            return base, height
        self.at += 1
        exponent, exponent_height = self.factor()
        if isinstance(exponent, Num) and abs(float(exponent.value)) > MAX_EXPONENT:
            raise _UnusualError
        return Op("pow", (base, exponent)), max(height, exponent_height) + 1

    def primary(self) -> tuple[Node, int]:
        token = self.tokens[self.at]
        self.at += 1
        first = token[:1]  # "" at the end
        if first.isdigit() or first == ".":
            return _number(token), 0
        if first == "(":
            self.nested += 1
            if self.nested > _NESTED:
                raise _UnusualError
            tree, height = self.sum()
            self.take(")")
            self.nested -= 1
            return tree, height
        if not (first.isalpha() or first == "_") or keyword.iskeyword(token):
            raise _UnusualError
        if self.tokens[self.at] != "(":
            return _symbol(token), 0
        if token not in FUNCTIONS:
            raise _UnusualError
        self.at += 1
        args, height = [], 0
        for index in range(FUNCTIONS[token]):
            if index:
                self.take(",")
            arg, arg_height = self.sum()
            args.append(arg)
            height = max(height, arg_height)
        self.take(")")
        return Op(token, tuple(args)), height + 1


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
    return Num(Fraction(repr(value)))
