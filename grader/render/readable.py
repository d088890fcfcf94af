"""Expressions as a textbook prints them: the worked solution's forms, rewritten for a reader.

The solver's forms come out of sympy in sympy's order, with square roots split
(``-sqrt(2)*sqrt(h)*sqrt(g)``) and sums sorted by name (``e + 1``). A reader expects what the
textbook writes, and :func:`readable` rewrites a tree into that, changing its value nowhere:

- one square root of a product: ``√2·√g·√h`` is ``√(2 g h)``, and of a quotient: ``√2·√h/√g`` is
  ``√(2 h/g)``, which stands in front of a fraction of the other factors (``√(2 h/g) (1 + e)/(1 - e)``);
- a sum of names of one kind stands with them, after them: ``(m1 + m2) v'``, ``m (u + v)``;
- factors in the textbook's order: the number first, then dimensionless symbols (``e``, ``p``), masses,
  ``g``, lengths, velocities, other quantities, functions (``cos θ``, roots), sums with a dimension
  (``v1 - v2``), and last the dimensionless sums (``1 + e``); names of one kind in the order the problem
  introduces them (``m_ram m_pile``);
- a whole number common to a sum's terms is taken out: ``2/m1 + 2/m2`` is ``2 (1/m1 + 1/m2)``;
- a sum starts with its positive constant (``1 + e``), then positive terms, then negative ones (simple
  terms before compound ones), so signs sit in front and ``-J/m + v`` reads ``v - J/m``;
- a minus sign in front of a product: ``-(e - 1)`` is ``1 - e``, and ``(1 + e)(1 - e)`` is ``1 - e²``;
- the square of a root is its radicand: ``hypot(a, b)²`` is ``a² + b²``;
- a factor above and below cancels: ``m_A m_B/(m_A (m_A + m_B))`` is ``m_B/(m_A + m_B)``;
- a product with a fraction for its number writes it above and below (``p/4``, ``3 p/4``, ``v²/(2 g)``),
  except the half of an energy, which leads (``1/2 m v²``), and a decimal of the problem's data (``0.1 p``,
  ``0.05 p``).

>>> from grader.model.expr import parse, to_text
>>> names = Names({"g": (1, 0, -2, 0), "h": (1, 0, 0, 0), "m": (0, 1, 0, 0), "v_n": (1, 0, -1, 0),
...                "e": (0, 0, 0, 0)}, ["m", "v_n", "e", "h"])
>>> to_text(readable(parse("-sqrt(2)*sqrt(h)*sqrt(g)"), names))
'-sqrt(2*g*h)'
>>> to_text(readable(parse("v_n*m*(e + 1)"), names))
'm*v_n*(1 + e)'
>>> to_text(readable(parse("m*(e + 1)*(1 - e)*v_n*v_n/2"), names))
'1/2*m*v_n**2*(1 - e**2)'
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from fractions import Fraction

from grader.model.expr import FUNCTIONS, Node, Num, Op, Sym, to_text

# Factor kinds, in the order a product shows them (numbers come first, as the coefficient).
_DIMENSIONLESS, _MASS, _ACCELERATION, _LENGTH, _VELOCITY, _OTHER, _CALL, _SUM, _PURE_SUM = range(9)
_KIND_OF_DIMENSION = {(0, 1, 0, 0): _MASS, (1, 0, -2, 0): _ACCELERATION, (1, 0, 0, 0): _LENGTH,
                      (1, 0, -1, 0): _VELOCITY, (0, 0, 0, 0): _DIMENSIONLESS, (0, 0, 0, 1): _DIMENSIONLESS}
_HALF = Fraction(1, 2)


@dataclass(frozen=True)
class Names:
    """What :func:`readable` knows of the names: each one's dimension (exponents of length, mass,
    time, angle) and the order the problem introduces them in."""

    dimensions: Mapping[str, Sequence[int | Fraction]]
    order: Sequence[str] = ()
    _position: dict[str, int] = field(default_factory=dict, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        self._position.update({name: index for index, name in reversed(list(enumerate(self.order)))})

    def kind(self, name: str) -> int:
        """The kind of a name: its dimension's (a mass, a velocity, ...), else "other"."""
        dimension = self.dimensions.get(name)
        if dimension is None or any(Fraction(d).denominator != 1 for d in dimension):
            return _OTHER
        length, mass, time, angle = (int(d) for d in dimension)
        return _KIND_OF_DIMENSION.get((length, mass, time, angle), _OTHER)

    def position(self, name: str) -> int:
        return self._position.get(name, len(self._position))


def readable(node: Node, names: Names) -> Node:
    """The same expression, written as a textbook writes it (see the module's docstring)."""
    if isinstance(node, (Num, Sym)):
        return node
    if node.op in ("add", "sub"):
        return _sum(node, names)
    if node.op in ("mul", "div", "neg") or _is_root(node) or (node.op == "pow" and _negative_power(node)):
        return _product(node, names)
    return Op(node.op, tuple(readable(arg, names) for arg in node.args))


# --- products ------------------------------------------------------------------------------------

@dataclass
class _Product:
    """``(-1 if negative) * coefficient * prod(numerator) / prod(denominator)``."""

    negative: bool = False
    coefficient: Fraction | float = Fraction(1)
    numerator: list[Node] = field(default_factory=list)
    denominator: list[Node] = field(default_factory=list)

    def take(self, node: Node, names: Names, below: bool = False) -> None:
        """Multiply by ``node`` (divide, when ``below``)."""
        if isinstance(node, Num):
            value = node.value
            if value < 0:
                self.negative, value = not self.negative, -value
            if value == 0 and not below:
                self.coefficient = Fraction(0)
            elif value != 0:
                self.coefficient = self.coefficient / value if below else self.coefficient * value
        elif isinstance(node, Op) and node.op == "neg":
            self.negative = not self.negative
            self.take(node.args[0], names, below)
        elif isinstance(node, Op) and node.op == "mul":
            self.take(node.args[0], names, below)
            self.take(node.args[1], names, below)
        elif isinstance(node, Op) and node.op == "div":
            self.take(node.args[0], names, below)
            self.take(node.args[1], names, not below)
        elif isinstance(node, Op) and node.op == "pow" and _negative_power(node):
            exponent = node.args[1]
            assert isinstance(exponent, Num)
            power = node.args[0] if exponent.value == -1 else Op("pow", (node.args[0], Num(-exponent.value)))
            self.take(power, names, not below)
        else:
            factor = Op("sqrt", (readable(node.args[0], names),)) if isinstance(node, Op) and _is_root(node) \
                else readable(node, names)
            if isinstance(factor, Op) and factor.op in ("mul", "neg"):  # a sum with a common factor taken out
                self.take(factor, names, below)
            else:
                (self.denominator if below else self.numerator).append(factor)


def _product(node: Node, names: Names) -> Node:
    product = _Product()
    product.take(node, names)
    if product.coefficient == 0:
        return Num(Fraction(0))
    product.numerator, product.denominator = _cancelled(product.numerator, product.denominator)
    product.numerator = [_unsquared(f, names) for f in _powers(_one_root(product.numerator, names))]
    product.denominator = [_unsquared(f, names) for f in _powers(_one_root(product.denominator, names))]
    _root_of_quotient(product, names)
    if product.negative:
        product.negative = not _turn_a_sum_round(product.numerator) and \
            not _turn_a_sum_round(product.denominator)
    product.numerator = _difference_of_squares(product.numerator, names)
    key = _factor_key(names)
    return _built(product, sorted(product.numerator, key=key), sorted(product.denominator, key=key))


def _cancelled(numerator: list[Node], denominator: list[Node]) -> tuple[list[Node], list[Node]]:
    """A factor above and below cancels (a whole power counted as its factors): ``m_A m_B/(m_A (m_A + m_B))``
    is ``m_B/(m_A + m_B)``.

    >>> from grader.model.expr import parse
    >>> [[to_text(f) for f in side] for side in _cancelled([parse("m**2"), parse("v")], [parse("m")])]
    [['m', 'v'], []]
    """
    above, below = _one_by_one(numerator), _one_by_one(denominator)
    for factor in list(above):
        if factor in below:
            above.remove(factor)
            below.remove(factor)
    return above, below


def _one_by_one(factors: list[Node]) -> list[Node]:
    """Factors with each whole power (up to the ninth) written out as its factors: ``v²`` is ``v v``."""
    result: list[Node] = []
    for factor in factors:
        exponent = factor.args[1] if isinstance(factor, Op) and factor.op == "pow" else None
        if isinstance(factor, Op) and isinstance(exponent, Num) and isinstance(exponent.value, Fraction) and \
                exponent.value.denominator == 1 and 1 <= exponent.value <= 9:
            result += [factor.args[0]] * int(exponent.value)
        else:
            result.append(factor)
    return result


def _root_of_quotient(product: _Product, names: Names) -> None:
    """A root above and a root below as one root of their quotient: ``√(2 h)/√g`` is ``√(2 h/g)``."""
    above = [f for f in product.numerator if _is_root(f)]
    below = [f for f in product.denominator if _is_root(f)]
    if not (above and below):
        return
    quotient = Op("div", tuple(root.args[0] for root in (above[0], below[0]) if isinstance(root, Op)))
    product.numerator = [f for f in product.numerator if not _is_root(f)] + [Op("sqrt", (readable(quotient, names),))]
    product.denominator = [f for f in product.denominator if not _is_root(f)]


def _built(product: _Product, numerator: list[Node], denominator: list[Node]) -> Node:
    roots = [f for f in numerator if _is_root(f)]
    if roots and len(numerator) > 1 and denominator and product.coefficient == 1:
        # √(2 h/g) (1 + e)/(1 - e): a root of the whole stands in front of the fraction of the rest.
        numerator.remove(roots[0])
        rest = _built(_Product(), numerator, denominator)
        whole = Op("mul", (roots[0], rest))
        return Op("neg", (whole,)) if product.negative else whole
    coefficient = product.coefficient
    if _decimal(coefficient):  # a number of the problem's data (0.1 p), not of the physics (1/2 m v^2)
        numerator.insert(0, Num(coefficient))
    elif isinstance(coefficient, Fraction) and coefficient == _HALF and not denominator and _squared(numerator):
        # 1/2 m v^2, 1/2 k x^2: the half of an energy leads, kept apart (as a quotient of two numbers)
        numerator.insert(0, Op("div", (Num(Fraction(1)), Num(Fraction(2)))))
    elif isinstance(coefficient, Fraction) and coefficient.denominator != 1 and numerator:
        # p/4, 3 p/4, m v/(2 (1 + p)): a fraction's number above and below, as the textbook writes it
        if coefficient.numerator != 1:
            numerator.insert(0, Num(Fraction(coefficient.numerator)))
        denominator.insert(0, Num(Fraction(coefficient.denominator)))
    elif isinstance(coefficient, Fraction) and coefficient.denominator != 1:
        numerator.insert(0, Op("div", (Num(Fraction(coefficient.numerator)), Num(Fraction(coefficient.denominator)))))
    elif coefficient != 1:
        numerator.insert(0, Num(coefficient))
    top = _chain("mul", numerator) if numerator else Num(Fraction(1))
    result = Op("div", (top, _chain("mul", denominator))) if denominator else top
    return Op("neg", (result,)) if product.negative else result


def _squared(factors: Sequence[Node]) -> bool:
    """Whether a factor is a square or a sum of them (the ``v²`` of ``1/2 m v²``, ``1/2 m (u² + v²)``)."""
    def square(node: Node) -> bool:
        if isinstance(node, Op) and node.op in ("add", "sub"):
            return any(square(term) for term in node.args)
        return isinstance(node, Op) and node.op == "pow" and node.args[1] == Num(Fraction(2))
    return any(square(factor) for factor in factors)


def _decimal(value: Fraction | float) -> bool:
    """A value printed with decimals: a fraction that is a decimal of two places or more (its denominator
    at least 10, of twos and fives: 0.42 is 21/50, 0.05 is 1/20); a half, a quarter or an eighth is a
    fraction (``p/4``).

    >>> _decimal(Fraction(21, 50)), _decimal(Fraction(1, 20)), _decimal(Fraction(1, 4)), _decimal(Fraction(1, 3))
    (True, True, False, False)
    """
    if not isinstance(value, Fraction) or value.denominator < 10:
        return False
    denominator = value.denominator
    for prime in (2, 5):
        while denominator % prime == 0:
            denominator //= prime
    return denominator == 1


def _chain(op: str, nodes: Sequence[Node]) -> Node:
    result = nodes[0]
    for node in nodes[1:]:
        result = Op(op, (result, node))
    return result


def _is_root(node: Node) -> bool:
    return isinstance(node, Op) and (node.op == "sqrt" or (
        node.op == "pow" and isinstance(node.args[1], Num) and node.args[1].value == _HALF))


def _negative_power(node: Op) -> bool:
    exponent = node.args[1]
    return isinstance(exponent, Num) and isinstance(exponent.value, Fraction) and exponent.value < 0 and \
        exponent.value.denominator == 1


def _one_root(factors: list[Node], names: Names) -> list[Node]:
    """The square roots among ``factors`` as one root of their product (its radicand made readable)."""
    roots = [f for f in factors if _is_root(f)]
    if len(roots) < 2:
        return factors
    assert all(isinstance(root, Op) for root in roots)
    radicand = _chain("mul", [root.args[0] for root in roots if isinstance(root, Op)])
    return [f for f in factors if not _is_root(f)] + [Op("sqrt", (readable(radicand, names),))]


def counted(factors: Sequence[Node]) -> list[tuple[Node, int]]:
    """Each distinct factor, in order of first appearance, with how often it occurs.

    >>> from grader.model.expr import parse
    >>> [(to_text(f), n) for f, n in counted([parse("v"), parse("m"), parse("v")])]
    [('v', 2), ('m', 1)]
    """
    result: list[tuple[Node, int]] = []
    for factor in factors:
        for index, (seen, count) in enumerate(result):
            if seen == factor:
                result[index] = (seen, count + 1)
                break
        else:
            result.append((factor, 1))
    return result


def _powers(factors: list[Node]) -> list[Node]:
    """Equal factors as one power: ``v v`` is ``v²``."""
    return [factor if count == 1 else Op("pow", (factor, Num(Fraction(count)))) for factor, count in counted(factors)]


def _unsquared(factor: Node, names: Names) -> Node:
    """The square of a root as its radicand: ``hypot(a, b)²`` is ``a² + b²``, ``(√x)²`` is ``x``."""
    if not (isinstance(factor, Op) and factor.op == "pow" and factor.args[1] == Num(Fraction(2))):
        return factor
    root = factor.args[0]
    if isinstance(root, Op) and root.op == "hypot":
        squares = [Op("pow", (arg, Num(Fraction(2)))) for arg in root.args]
        return readable(Op("add", (squares[0], squares[1])), names)
    return root.args[0] if isinstance(root, Op) and root.op == "sqrt" else factor


def _difference_of_squares(factors: list[Node], names: Names) -> list[Node]:
    """``(1 + x)(1 - x)`` as ``1 - x²``: a constant plus and minus the same term."""
    result = list(factors)
    for plus in factors:
        for minus in factors:
            if plus in result and minus in result and _opposite(plus, minus):
                assert isinstance(plus, Op)
                constant, term = plus.args
                assert isinstance(constant, Num)
                square = Op("sub", (Num(constant.value * constant.value), Op("pow", (term, Num(Fraction(2))))))
                result.remove(plus)
                result.remove(minus)
                result.append(readable(square, names))
    return result


def _opposite(plus: Node, minus: Node) -> bool:
    return (isinstance(plus, Op) and plus.op == "add" and isinstance(minus, Op) and minus.op == "sub"
            and isinstance(plus.args[0], Num) and plus.args[0] == minus.args[0] and plus.args[1] == minus.args[1])


def _turn_a_sum_round(factors: list[Node]) -> bool:
    """Absorb a minus sign into a sum that then starts with a positive constant (``-(e - 1)`` is
    ``1 - e``); whether one was found."""
    for index, factor in enumerate(factors):
        if isinstance(factor, Op) and factor.op == "sub" and isinstance(factor.args[1], Num):
            factors[index] = Op("sub", (factor.args[1], factor.args[0]))
            return True
    return False


def _factor_key(names: Names) -> Callable[[Node], tuple[int, bool, int, str]]:
    def key(factor: Node) -> tuple[int, bool, int, str]:
        used = _names_of(factor)
        first = min((names.position(n) for n in used), default=0)
        return _kind(factor, names), _is_sum(factor), first, to_text(factor)
    return key


def _kind(factor: Node, names: Names) -> int:
    if isinstance(factor, Sym):
        return names.kind(factor.name)
    if isinstance(factor, Num):
        return _DIMENSIONLESS
    if factor.op == "pow":
        return _kind(factor.args[0], names)
    if factor.op in ("add", "sub"):
        terms = _terms(factor)
        if any(isinstance(term, Num) for term in terms) or \
                all(names.kind(n) == _DIMENSIONLESS for n in _names_of(factor)):
            return _PURE_SUM
        # A sum of names of one kind stands with them: (m1 + m2) v' as a mass, after the masses alone.
        kinds = {_kind(_unsigned(term), names) if isinstance(_unsigned(term), Sym) else _SUM for term in terms}
        return kinds.pop() if len(kinds) == 1 and _SUM not in kinds else _SUM
    return _CALL if factor.op in FUNCTIONS else _OTHER


def _unsigned(term: Node) -> Node:
    return term.args[0] if isinstance(term, Op) and term.op == "neg" else term


def _is_sum(factor: Node) -> bool:
    base = factor.args[0] if isinstance(factor, Op) and factor.op == "pow" else factor
    return isinstance(base, Op) and base.op in ("add", "sub")


def _names_of(node: Node) -> list[str]:
    if isinstance(node, Sym):
        return [node.name]
    if isinstance(node, Op):
        return [name for arg in node.args for name in _names_of(arg)]
    return []


# --- sums ----------------------------------------------------------------------------------------

def _terms(node: Node) -> list[Node]:
    if isinstance(node, Op) and node.op in ("add", "sub"):
        right = node.args[1] if node.op == "add" else Op("neg", (node.args[1],))
        return _terms(node.args[0]) + _terms(right)
    return [node]


def _sum(node: Node, names: Names) -> Node:
    signed: list[tuple[bool, Node]] = []
    for term in _terms(node):
        shown = readable(term, names)
        negative = isinstance(shown, Op) and shown.op == "neg"
        if isinstance(shown, Num) and shown.value < 0:
            negative, shown = True, Num(-shown.value)
        signed.append((negative, shown.args[0] if negative and isinstance(shown, Op) else shown))

    def order(entry: tuple[bool, Node]) -> tuple[int, int, int, str]:
        negative, term = entry
        group = 0 if isinstance(term, Num) and not negative else 2 if negative else 1
        first = min((names.position(n) for n in _names_of(term)), default=0)
        return group, _size(term), first, to_text(term)

    common = _common_number([term for _, term in signed], names)
    if common != 1:
        signed = [(negative, _product(Op("div", (term, Num(Fraction(common)))), names)) for negative, term in signed]
    turned = all(negative for negative, _ in signed)  # -a - b is -(a + b)
    ordered = sorted(((not negative, term) if turned else (negative, term) for negative, term in signed), key=order)
    negative, first = ordered[0]
    result = Op("neg", (first,)) if negative else first
    for negative, term in ordered[1:]:
        result = Op("sub" if negative else "add", (result, term))
    result = Op("mul", (Num(Fraction(common)), result)) if common != 1 else result
    return Op("neg", (result,)) if turned else result


def _common_number(terms: Sequence[Node], names: Names) -> int:
    """The whole number every term is a multiple of (``2/m1 + 2/m2`` is ``2 (1/m1 + 1/m2)``), or 1."""
    common = 0
    for term in terms:
        product = _Product()
        product.take(term, names)
        coefficient = product.coefficient
        if not (isinstance(coefficient, Fraction) and coefficient.denominator == 1):
            return 1
        common = math.gcd(common, coefficient.numerator)
    return max(common, 1)


def _size(node: Node) -> int:
    return 1 + sum(_size(arg) for arg in node.args) if isinstance(node, Op) else 1
