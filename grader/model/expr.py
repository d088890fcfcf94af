"""Expressions as small frozen trees: parsed safely, printed, substituted, folded.

One representation serves templates (stage fields, constraints, answers), the compiled
kernels of the solver (stored as JSON in the cache) and, later, students' answers. Text is
parsed with Python's ``ast`` and an allow-list; nothing is ever passed to ``eval``.

>>> tree = parse("v*(1 - e*p)/(p + 1)")
>>> to_text(tree)
'v*(1 - e*p)/(p + 1)'
>>> to_text(fold(substitute(tree, {"e": Num(Fraction(1, 10))})))
'v*(1 - 0.1*p)/(p + 1)'
>>> sorted(names(tree))
['e', 'p', 'v']
>>> parse("__import__('os')")  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
grader.base.errors.ExpressionError: '__import__' is not an allowed function (allowed: Max, Min, abs, ...)
"""

from __future__ import annotations

import ast
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from fractions import Fraction
from functools import lru_cache
from typing import Any

from grader.base.errors import ExpressionError

MAX_LENGTH = 500
MAX_DEPTH = 40
MAX_EXPONENT = 64

FUNCTIONS = {
    "sqrt": 1, "sin": 1, "cos": 1, "tan": 1, "sind": 1, "cosd": 1,
    "exp": 1, "log": 1, "abs": 1, "sign": 1, "atan2": 2, "hypot": 2, "Max": 2, "Min": 2,
}
"""Functions an expression may call, with their number of arguments."""

CONSTANTS = {"pi"}

ROOT = "root"
"""``root(r, x, low, high)``: the one root ``x`` in ``[low, high]`` of the residual ``r``, in which ``x`` is a bound
name (the solver's numeric blocks: :mod:`grader.model.roots`). Never parsed from text: only the solver writes it."""

_BINARY = {ast.Add: "add", ast.Sub: "sub", ast.Mult: "mul", ast.Div: "div", ast.Pow: "pow"}
_COMPARE = {ast.Lt: "lt", ast.LtE: "le", ast.Gt: "gt", ast.GtE: "ge"}
_BOOLEAN = {ast.And: "and", ast.Or: "or"}


@dataclass(frozen=True)
class Num:
    """A number: exact (``Fraction``) where it can be, else a float."""

    value: Fraction | float

    def __post_init__(self) -> None:
        if isinstance(self.value, float) and self.value != self.value:
            raise ExpressionError("a number in an expression is NaN")


@dataclass(frozen=True)
class Sym:
    """A named quantity."""

    name: str


@dataclass(frozen=True)
class Op:
    """An operation: arithmetic (add, sub, mul, div, pow, neg), a function, or a comparison."""

    op: str
    args: tuple[Node, ...]


Node = Num | Sym | Op


def parse(text: str, *, allow_compare: bool = False) -> Node:
    """Parse ``text`` into a tree, refusing anything outside the allow-list.

    ``^`` means power, as students write it. Comparisons (``h_r <= h``) and ``and``/``or``
    are allowed only with ``allow_compare`` (template constraints).

    >>> to_text(parse("2^3 + x"))
    '2**3 + x'
    >>> parse("h <= 2", allow_compare=True)
    Op(op='le', args=(Sym(name='h'), Num(value=Fraction(2, 1))))
    """
    if not isinstance(text, str):
        raise ExpressionError(f"expected an expression as text, got {type(text).__name__}")
    if len(text) > MAX_LENGTH:
        raise ExpressionError(f"expression is {len(text)} characters long; at most {MAX_LENGTH} are allowed")
    if not text.strip():
        raise ExpressionError("expression is empty")
    try:
        # '^' is power as students write it; Python would read it as xor, with the wrong precedence.
        tree = ast.parse(text.strip().replace("^", "**"), mode="eval")
    except SyntaxError as error:
        raise ExpressionError(f"'{text}' is not a valid expression ({error.msg})") from None
    except (RecursionError, MemoryError):
        raise ExpressionError(f"expression is nested more than {MAX_DEPTH} levels deep") from None
    try:
        return _convert(tree.body, allow_compare, 0)
    except _TooDeepError:
        terms = _longest_chain(tree.body)
        if terms > MAX_DEPTH:  # a flat sum or product nests one level a term
            raise ExpressionError(f"a sum or product of {terms} terms; at most {MAX_DEPTH + 1} terms are allowed "
                                  "in a row (group some in parentheses, or simplify)") from None
        raise ExpressionError(f"expression is nested more than {MAX_DEPTH} levels deep") from None


class _TooDeepError(ExpressionError):
    """A tree deeper than :data:`MAX_DEPTH` (said to the user by :func:`parse`)."""


def _longest_chain(tree: ast.AST) -> int:
    """The most terms joined by one kind of operator (``+ -`` or ``* /``) in a row: ``a + b - c`` is 3.

    >>> _longest_chain(ast.parse("a + b*c*d - e", mode="eval").body)
    3
    """
    kinds = {ast.Add: 0, ast.Sub: 0, ast.Mult: 1, ast.Div: 1}
    longest = 1
    for node in ast.walk(tree):
        if not isinstance(node, ast.BinOp) or type(node.op) not in kinds:
            continue
        terms, left = 2, node.left
        while isinstance(left, ast.BinOp) and kinds.get(type(left.op)) == kinds[type(node.op)]:
            terms, left = terms + 1, left.left
        longest = max(longest, terms)
    return longest


def _convert(node: ast.AST, allow_compare: bool, depth: int) -> Node:
    if depth > MAX_DEPTH:
        raise _TooDeepError(f"expression is nested more than {MAX_DEPTH} levels deep")
    deeper = depth + 1
    if isinstance(node, ast.Constant):
        return _number(node.value)
    if isinstance(node, ast.Name):
        return Sym(node.id)
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
        operand = _convert(node.operand, allow_compare, deeper)
        return Op("neg", (operand,)) if isinstance(node.op, ast.USub) else operand
    if isinstance(node, ast.BinOp) and type(node.op) in _BINARY:
        left = _convert(node.left, allow_compare, deeper)
        right = _convert(node.right, allow_compare, deeper)
        op = _BINARY[type(node.op)]
        if op == "pow":
            _check_exponent(right)
        return Op(op, (left, right))
    if isinstance(node, ast.Call):
        return _call(node, allow_compare, deeper)
    if allow_compare and isinstance(node, ast.Compare) and len(node.ops) == 1 and type(node.ops[0]) in _COMPARE:
        left = _convert(node.left, allow_compare, deeper)
        right = _convert(node.comparators[0], allow_compare, deeper)
        return Op(_COMPARE[type(node.ops[0])], (left, right))
    if allow_compare and isinstance(node, ast.BoolOp) and type(node.op) in _BOOLEAN:
        return Op(_BOOLEAN[type(node.op)], tuple(_convert(v, allow_compare, deeper) for v in node.values))
    raise ExpressionError(f"'{ast.unparse(node)}' is not allowed in an expression "
                          "(numbers, names, + - * / ** and the listed functions only)")


def _number(value: Any) -> Num:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ExpressionError(f"{value!r} is not a number")
    if isinstance(value, float):
        if value != value or value in (float("inf"), float("-inf")):
            raise ExpressionError(f"{value!r} is not a finite number")
        return Num(_decimal_fraction(repr(value)))
    return Num(Fraction(value))


def _decimal_fraction(text: str) -> Fraction:
    """The exact value of a float's ``repr`` (``Fraction(text)`` does the same, four times slower).

    >>> _decimal_fraction("0.1"), _decimal_fraction("-2.5e-07"), _decimal_fraction("1e+300") == 10**300
    (Fraction(1, 10), Fraction(-1, 4000000), True)
    """
    mantissa, _, exponent = text.partition("e")
    whole, _, decimals = mantissa.partition(".")
    power = int(exponent or 0) - len(decimals)
    digits = int(whole + decimals)
    return Fraction(digits * 10**power) if power >= 0 else Fraction(digits, 10**-power)


def _call(node: ast.Call, allow_compare: bool, depth: int) -> Node:
    name = node.func.id if isinstance(node.func, ast.Name) else ast.unparse(node.func)
    if name not in FUNCTIONS:
        raise ExpressionError(f"'{name}' is not an allowed function (allowed: {', '.join(sorted(FUNCTIONS))})")
    if node.keywords or len(node.args) != FUNCTIONS[name]:
        raise ExpressionError(f"{name}() takes {FUNCTIONS[name]} argument(s)")
    return Op(name, tuple(_convert(a, allow_compare, depth) for a in node.args))


def _check_exponent(exponent: Node) -> None:
    if isinstance(exponent, Num) and not -MAX_EXPONENT <= exponent.value <= MAX_EXPONENT:
        shown = to_text(exponent)
        shown = shown if len(shown) <= 24 else shown[:20] + "…"  # a number of 400 digits by its first digits
        raise ExpressionError(f"exponent {shown} is larger than {MAX_EXPONENT}")


def names(node: Node) -> set[str]:
    """The names an expression uses (``pi`` excluded)."""
    if isinstance(node, Sym):
        return set() if node.name in CONSTANTS else {node.name}
    if isinstance(node, Op) and node.op == ROOT:
        residual, bound, *ends = node.args
        return (names(residual) - names(bound)).union(*(names(end) for end in ends))
    if isinstance(node, Op):
        return set().union(*(names(a) for a in node.args))
    return set()


def bottom_up(node: Node, rule: Callable[[Op], Node]) -> Node:
    """``node`` rewritten from its leaves up: ``rule`` meets each operation with its arguments rewritten already.

    >>> to_text(bottom_up(parse("Max(0, h - r)/h"), lambda op: op.args[1] if op.op == "Max" else op))
    '(h - r)/h'
    """
    if not isinstance(node, Op):
        return node
    return rule(Op(node.op, tuple(bottom_up(arg, rule) for arg in node.args)))


def substitute(node: Node, values: Mapping[str, Node]) -> Node:
    """Replace names by trees."""
    if isinstance(node, Sym):
        return values.get(node.name, node)
    if isinstance(node, Op) and node.op == ROOT:
        residual, bound, *ends = node.args
        inside = {name: value for name, value in values.items() if name not in names(bound)}
        return Op(ROOT, (substitute(residual, inside), bound, *(substitute(end, values) for end in ends)))
    if isinstance(node, Op):
        return Op(node.op, tuple(substitute(a, values) for a in node.args))
    return node


_EXACT: dict[str, Callable[..., Fraction | None]] = {
    "add": lambda a, b: a + b, "sub": lambda a, b: a - b, "mul": lambda a, b: a * b,
    "div": lambda a, b: a / b if b != 0 else None, "neg": lambda a: -a,
    "pow": lambda a, b: a ** b if b.denominator == 1 and (a != 0 or b >= 0) else None,
}


def fold(node: Node) -> Node:
    """Fold arithmetic on exact numbers, so ``1 + 0.1`` prints as ``1.1``."""
    if not isinstance(node, Op):
        return node
    args = tuple(fold(a) for a in node.args)
    rule = _EXACT.get(node.op)
    exact = [a.value for a in args if isinstance(a, Num) and isinstance(a.value, Fraction)]
    if rule and len(exact) == len(args):
        value = rule(*exact)
        if value is not None:
            return Num(Fraction(value))
    if node.op == "mul" and isinstance(args[1], Num) and not isinstance(args[0], Num):
        args = (args[1], args[0])
    if node.op == "mul" and isinstance(args[0], Num) and args[0].value == 1:
        return args[1]
    if node.op == "mul" and isinstance(args[1], Num) and args[1].value == 1:
        return args[0]
    return Op(node.op, args)


_PRECEDENCE = {"or": 1, "and": 2, "lt": 3, "le": 3, "gt": 3, "ge": 3,
               "add": 4, "sub": 4, "mul": 5, "div": 5, "neg": 6, "pow": 7}
_SYMBOL = {"add": " + ", "sub": " - ", "mul": "*", "div": "/", "pow": "**",
           "lt": " < ", "le": " <= ", "gt": " > ", "ge": " >= ", "and": " and ", "or": " or "}


def to_text(node: Node) -> str:
    """Python/sympy-parseable text of an expression, with as few parentheses as needed."""
    return _text(node)[0]


_LEFT_ASSOCIATIVE = frozenset(("sub", "div", "mul"))


def _text(node: Node) -> tuple[str, int]:
    if isinstance(node, Sym):
        return node.name, 9
    if isinstance(node, Num):
        text = format_number(node.value)
        return text, (6 if text.startswith("-") else 9) if "/" not in text else 5
    op, args = node.op, node.args
    if op in FUNCTIONS or op == ROOT:
        return f"{op}({', '.join(_text(a)[0] for a in args)})", 9
    level = _PRECEDENCE[op]
    if op == "neg":
        inner, inner_level = _text(args[0])
        # -(a*b) and (-a)*b are the same number, so a product needs no parentheses.
        bare = inner_level > level or (isinstance(args[0], Op) and args[0].op in ("mul", "div"))
        return "-" + (inner if bare else f"({inner})"), level
    # Left-associative operators keep a right operand of equal level in parentheses,
    # power is right-associative and does the opposite.
    if len(args) == 2:  # all but a long 'and' or 'or': no list, no loop
        (left, left_level), (right, right_level) = _text(args[0]), _text(args[1])
        if left_level < level or (left_level == level and op == "pow"):
            left = f"({left})"
        if right_level < level or (right_level == level and op in _LEFT_ASSOCIATIVE):
            right = f"({right})"
        return left + _SYMBOL[op] + right, level
    parts = []
    for index, arg in enumerate(args):
        inner, inner_level = _text(arg)
        needs = inner_level < level or (inner_level == level and (
            (index > 0 and op in _LEFT_ASSOCIATIVE) or (index == 0 and op == "pow")))
        parts.append(f"({inner})" if needs else inner)
    return _SYMBOL[op].join(parts), level


def format_number(value: Fraction | float) -> str:
    """Shortest faithful text of a number: exact decimals stay exact.

    >>> format_number(Fraction(11, 10)), format_number(Fraction(1, 3)), format_number(2.5)
    ('1.1', '1/3', '2.5')
    """
    if isinstance(value, float):
        return repr(value)
    return _fraction_text(value.numerator, value.denominator)


@lru_cache(maxsize=4096)  # a class writes the same numbers; a fraction's own hash costs as much as this
def _fraction_text(numerator: int, denominator: int) -> str:
    if denominator == 1:
        return str(numerator)
    rest, twos, fives = denominator, 0, 0
    while rest % 2 == 0:
        rest, twos = rest // 2, twos + 1
    while rest % 5 == 0:
        rest, fives = rest // 5, fives + 1
    if rest != 1:
        return f"{numerator}/{denominator}"
    places = max(twos, fives)
    scaled = numerator * (10**places // denominator)  # exact: the denominator divides 10**places
    sign = "-" if scaled < 0 else ""
    digits = str(abs(scaled)).rjust(places + 1, "0")
    return f"{sign}{digits[:-places]}.{digits[-places:]}"


def to_json(node: Node) -> Any:
    """A JSON-ready form of a tree (for the compiled-template cache)."""
    if isinstance(node, Sym):
        return node.name
    if isinstance(node, Num):
        if isinstance(node.value, Fraction):
            return {"q": [node.value.numerator, node.value.denominator]}
        return {"f": node.value}
    return [node.op, *(to_json(a) for a in node.args)]


def from_json(data: Any) -> Node:
    """Inverse of :func:`to_json`; anything :func:`to_json` does not write (an unknown operation, a wrong number
    of arguments, a zero denominator, a NaN, a number as text) is a ``ValueError``.

    >>> tree = parse("hypot(a, -2.5*b)")
    >>> from_json(to_json(tree)) == tree
    True
    >>> from_json(["__import__", "os"])
    Traceback (most recent call last):
    ...
    ValueError: not an expression tree: ['__import__', 'os']
    """
    if type(data) is str:
        return Sym(data)
    if type(data) is dict:
        return _number_from_json(data)
    if type(data) is list and data and _takes(data[0], len(data) - 1):
        node = Op(data[0], tuple(from_json(a) for a in data[1:]))
        if node.op != ROOT or isinstance(node.args[1], Sym):
            return node
    raise ValueError(f"not an expression tree: {data!r:.80}")


_ARGUMENTS = {**FUNCTIONS, **dict.fromkeys(("add", "sub", "mul", "div", "pow", *_COMPARE.values()), 2), "neg": 1,
              ROOT: 4}


def _takes(op: Any, count: int) -> bool:
    """Whether the operation ``op`` takes ``count`` arguments (``and`` and ``or`` two or more)."""
    if op in _BOOLEAN.values():
        return count >= 2
    return type(op) is str and _ARGUMENTS.get(op) == count


def _number_from_json(data: dict[str, Any]) -> Num:
    exact, inexact = data.get("q"), data.get("f")
    if (len(data) == 1 and type(exact) is list and len(exact) == 2 and all(type(n) is int for n in exact)
            and exact[1] != 0):
        return Num(Fraction(exact[0], exact[1]))
    if len(data) == 1 and type(inexact) is float and inexact == inexact:
        return Num(inexact)
    raise ValueError(f"not an expression tree: {data!r:.80}")
