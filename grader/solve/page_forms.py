"""Forms on the page, as a textbook writes them, each with the value of the kernel's form it stands for
(:mod:`grader.solve.textbook_steps` puts them together into a worked solution's route):

- a bounce measured by heights: ``e = √(h′/h)`` (Problem 3/251), not ``e = −v′/v`` with the numbers;
- an angle from its sine, cosine or tangent: ``θ = sin⁻¹(b/(2r))``, ``θ′ = tan⁻¹(v′_n/v′_t)``, the angle between
  two velocities ``cos⁻¹`` of their dot product over their speeds, where the inverse's principal value is the
  kernel's ``atan2``; a speed already found stands for its components' root (``v`` for ``√(v_n² + v_t²)``), and a
  speed with one component zero is that component's size;
- reciprocal sums combined: ``1/(1/m1 + 1/m2)`` is ``m1 m2/(m1 + m2)``, and a factor shared by a fraction's
  denominator cancelled; square roots multiplied together under one: ``√(2H/g)``;
- numbers put in without a double sign: ``−(−3.072)`` is ``3.072``.

``asin``, ``acos`` and ``atan`` are functions only the page knows (:func:`page_value` evaluates them): no template
or student writes them.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import replace
from fractions import Fraction
from typing import Any

from grader.model.expr import Node, Num, Op, Sym, bottom_up, fold
from grader.model.kernel import evaluate
from grader.solve.compiled import Step

INVERSE_TRIG = {"asin": "sin", "acos": "cos", "atan": "tan"}
"""The page's inverse functions, by the function they invert."""

_RISES = re.compile(r"conservation of energy, \S+ rises through (\w+)")
_FALLS = re.compile(r"conservation of energy, \S+ falls through (\w+)")
_COMPONENT = re.compile(r"(\w+): component along ([nt])")


_ONE = Num(Fraction(1))


def is_zero(node: Node | None) -> bool:
    """No node (at rest, nothing given) or the number 0."""
    return node is None or (isinstance(node, Num) and node.value == 0)


def _times(factor: Node, other: Node) -> Node:
    return other if factor == _ONE else Op("mul", (factor, other))


def page_value(node: Node, env: Mapping[str, Any]) -> Any:
    """A page form's value: the kernel's evaluation, with ``asin``, ``acos`` and ``atan`` as ``atan2``.

    >>> round(float(page_value(Op("asin", (Num(0.5),)), {})) * 6, 12)
    3.14159265359
    """
    return evaluate(kernel_form(node), env)


def kernel_form(node: Node) -> Node:
    """A page form in the functions the kernels know: ``sin⁻¹ x`` is ``atan2(x, √(1 − x²))``, and so on."""
    return bottom_up(node, _as_atan2)


def _as_atan2(node: Op) -> Node:
    if node.op not in INVERSE_TRIG:
        return node
    (x,) = node.args
    other = Op("sqrt", (Op("sub", (_ONE, Op("pow", (x, Num(Fraction(2))))),),))
    return Op("atan2", {"asin": (x, other), "acos": (other, x), "atan": (x, _ONE)}[node.op])


def bounce_heights(steps: list[Step]) -> list[Step]:
    """``e = -v'/v`` with ``v = √(2 g h)`` and ``v' = -√(2 g h')``: ``e = √(h'/h)``."""
    heights: dict[str, tuple[str, str]] = {}
    for step in steps:
        for kind, pattern in (("rise", _RISES), ("fall", _FALLS)):
            found = pattern.fullmatch(step.relation)
            if found:
                heights[step.unknown] = (kind, found.group(1))
    result = []
    for step in steps:
        ratio = _ratio(step.solved)
        if step.relation.startswith("coefficient of restitution") and ratio is not None:
            (rise, fall) = (heights.get(ratio[0]), heights.get(ratio[1]))
            if rise and fall and rise[0] == "rise" and fall[0] == "fall":
                step = replace(step, solved=Op("sqrt", (Op("div", (Sym(rise[1]), Sym(fall[1]))),)))
        result.append(step)
    return result


def _ratio(node: Node) -> tuple[str, str] | None:
    """``(x, y)`` of ``-x/y`` (or ``(-x)/y``), names both."""
    if isinstance(node, Op) and node.op == "neg" and isinstance(node.args[0], Op) and node.args[0].op == "div":
        top, bottom = node.args[0].args
    elif isinstance(node, Op) and node.op == "div" and isinstance(node.args[0], Op) and node.args[0].op == "neg":
        top, bottom = node.args[0].args[0], node.args[1]
    else:
        return None
    return (top.name, bottom.name) if isinstance(top, Sym) and isinstance(bottom, Sym) else None


def inverse_trig(steps: list[Step], positive: dict[str, Node]) -> list[Step]:
    """An angle from ``sin θ = ...``, ``cos θ = ...`` or ``tan θ = y/x`` solved by ``atan2``: ``sin⁻¹(...)``, and
    so on, as the relation reads, where the inverse's principal value is the kernel's angle (``positive``: the
    page checks it per variant, and shows the kernel's ``atan2`` elsewhere)."""
    result = []
    for step in steps:
        lhs, rhs = step.equation
        if (isinstance(step.solved, Op) and step.solved.op == "atan2" and isinstance(lhs, Op)
                and lhs.op in INVERSE_TRIG.values() and lhs.args == (Sym(step.unknown),)):
            inverse = next(k for k, v in INVERSE_TRIG.items() if v == lhs.op)
            # The kernel's atan2(y, x) is the principal value only where x > 0 (sin⁻¹, tan⁻¹) or y > 0 (cos⁻¹)
            positive[step.unknown] = step.solved.args[0 if inverse == "acos" else 1]
            step = replace(step, solved=Op(inverse, (rhs,)))
        swing = _SWING_ANGLE.fullmatch(step.relation)
        if swing and step.unknown == swing.group(2) and isinstance(lhs, Sym) and _is_half_angle(step.solved):
            # v = √(2gL(1 − cos θ)): θ = cos⁻¹(1 − v²/(2gL)), the kernel's 2 atan2(v, √(4gL − v²)) where v > 0
            positive[step.unknown] = lhs
            height = Op("div", (Op("pow", (lhs, Num(Fraction(2)))),
                                Op("mul", (Op("mul", (Num(Fraction(2)), Sym("g"))), Sym(swing.group(1))))))
            step = replace(step, solved=Op("acos", (Op("sub", (_ONE, height)),)))
        result.append(step)
    return result


_SWING_ANGLE = re.compile(r"conservation of energy in the swing of \S+ on its cord of length (\w+) .*"
                          r"to stop at (\w+) from the vertical")


def _is_half_angle(node: Node) -> bool:
    """``2 atan2(...)``: the kernel's stable form of an angle from its half-angle's tangent."""
    return (isinstance(node, Op) and node.op == "mul" and node.args[0] == Num(Fraction(2))
            and isinstance(node.args[1], Op) and node.args[1].op == "atan2")


def magnitudes(steps: list[Step]) -> list[Step]:
    """A speed found once stands for its components' root afterwards (``v`` for ``√(v_n² + v_t²)``, where ``v_n =
    v cos θ`` and ``v_t = v sin θ``), and the root of one component and a zero is that component's size."""
    known: dict[frozenset[Node], Node] = {}
    components: dict[str, dict[str, str]] = {}
    zero = {s.unknown for s in steps if is_zero(s.solved)}
    result = []
    for original in steps:
        step = replace(original, equation=tuple(_speeds(side, known, zero) for side in original.equation),  # type: ignore[arg-type]
                       solved=_speeds(original.solved, known, zero))
        result.append(step)
        found = _COMPONENT.fullmatch(step.relation)
        if found:
            parts = components.setdefault(found.group(1), {})
            parts[found.group(2)] = step.unknown
            if len(parts) == 2:
                known[frozenset({Sym(parts["n"]), Sym(parts["t"])})] = Sym(found.group(1))
        if isinstance(original.solved, Op) and original.solved.op == "hypot":  # its own page form may be |v_n|
            known[frozenset(original.solved.args)] = Sym(step.unknown)
    return result


def _speeds(node: Node, known: Mapping[frozenset[Node], Node], zero: set[str]) -> Node:
    if not isinstance(node, Op):
        return node
    args = tuple(_speeds(a, known, zero) for a in node.args)
    if node.op == "hypot":
        if frozenset(args) in known:
            return known[frozenset(args)]
        kept = [a for a in args if not (isinstance(a, Sym) and a.name in zero) and not is_zero(a)]
        if len(kept) == 1:
            return Op("abs", (kept[0],))
    return Op(node.op, args)


def combine_reciprocals(node: Node) -> Node:
    """Reciprocal sums as one fraction: ``c/a + c/b`` is ``c (a + b)/(a b)``, and a quotient by a quotient is a
    product over one denominator, so ``1/(1/m1 + 1/m2)`` reads ``m1 m2/(m1 + m2)``.

    >>> from grader.model.expr import parse, to_text
    >>> to_text(combine_reciprocals(parse("v*(1 + e)/(1/m + 1/(m*p))")))
    'v*(1 + e)*(m*(m*p))/(m*p + m)'
    """
    return bottom_up(node, _one_fraction)


def _factors(node: Node) -> list[Node]:
    if isinstance(node, Op) and node.op == "mul":
        return _factors(node.args[0]) + _factors(node.args[1])
    return [node]


def product(factors: list[Node]) -> Node:
    """The factors multiplied left to right (1 for none)."""
    if not factors:
        return _ONE
    result = factors[0]
    for factor in factors[1:]:
        result = Op("mul", (result, factor))
    return result


def _cancelled(top: list[Node], bottom: list[Node]) -> Node | None:
    """``top/bottom`` with the factors they share taken out, or None where they share none."""
    top, bottom = list(top), list(bottom)
    shared = False
    for factor in list(top):
        if factor in bottom and not isinstance(factor, Num):
            top.remove(factor)
            bottom.remove(factor)
            shared = True
    if not shared:
        return None
    return product(top) if not bottom else Op("div", (product(top), product(bottom)))


def _one_fraction(node: Op) -> Node:
    args = node.args
    if node.op == "mul" and any(isinstance(a, Op) and a.op == "div" for a in args):
        # m_A (m_A + m_B)/(m_A m_B) is (m_A + m_B)/m_B: a factor over the fraction's denominator cancels
        fraction, other = (args[1], args[0]) if isinstance(args[1], Op) and args[1].op == "div" else args
        top, bottom = fraction.args  # type: ignore[union-attr]
        cancelled = _cancelled(_factors(other) + _factors(top), _factors(bottom))
        if cancelled is not None:
            return cancelled
    if node.op == "add" and all(isinstance(a, Op) and a.op == "div" for a in args):
        (c1, a), (c2, b) = (arg.args for arg in args)  # type: ignore[union-attr]
        if c1 == c2:
            return Op("div", (_times(c1, Op("add", (b, a))), Op("mul", (a, b))))
    if node.op == "div" and isinstance(args[1], Op) and args[1].op == "div":
        top, bottom = args[1].args
        return Op("div", (Op("mul", (args[0], bottom)), top))
    if node.op == "mul" and isinstance(args[1], Op) and args[1].op == "div" and isinstance(args[0], Op) \
            and args[0].op == "div":
        return Op("div", (Op("mul", (args[0].args[0], args[1].args[0])), Op("mul", (args[0].args[1], args[1].args[1]))))
    return node


def one_root(node: Node) -> Node:
    """A product or quotient of square roots as one root, as a textbook writes it: ``√2 √H/√g`` is ``√(2H/g)``.

    >>> from grader.model.expr import parse, to_text
    >>> to_text(one_root(parse("sqrt(2)*sqrt(H)/sqrt(g)"))), to_text(one_root(parse("v*sqrt(2)")))
    ('sqrt(2*H/g)', 'v*sqrt(2)')
    """
    return bottom_up(node, _one_root)


def _one_root(node: Op) -> Node:
    if node.op not in ("mul", "div"):
        return node
    roots = [a for a in node.args if isinstance(a, Op) and a.op == "sqrt"]
    if len(roots) != 2:
        return node
    (left,), (right,) = (a.args for a in roots)
    return Op("sqrt", (Op(node.op, (left, right)),))


def folded(step: Step) -> Step:
    """Whole numbers added up (``1 + 1`` is 2) where a route put them side by side."""
    if step.numeric:
        return step
    return replace(step, equation=(fold(step.equation[0]), fold(step.equation[1])), solved=fold(step.solved))


def one_fraction(step: Step) -> Step:
    """Reciprocal sums combined, and roots multiplied together (:func:`one_root`); an equation that only said the
    unknown is a nested fraction is the solved form."""
    if step.numeric:
        return step
    lhs, rhs = (one_root(combine_reciprocals(side)) for side in step.equation)
    solved = one_root(combine_reciprocals(step.solved))
    if lhs == Sym(step.unknown) and rhs != step.equation[1]:
        rhs = solved
    return replace(step, equation=(lhs, rhs), solved=solved)


_DOUBLE_NEGATIVE = (
    (re.compile(r" - \(-([0-9.]+)\)(?!\^)"), r" + \1"),
    (re.compile(r" \+ \(-([0-9.]+)\)(?!\^)"), r" - \1"),
    (re.compile(r"(^|[(, ])-\(-([0-9.]+)\)(?!\^)"), r"\1\2"),
    (re.compile(r"abs\(\((-[0-9.]+)\)\)"), r"abs(\1)"),
)


def tidy_signs(shown: str) -> str:
    """A substituted form without a double sign: ``-(-3.072)`` is ``3.072``, ``x - (-2)`` is ``x + 2``.

    >>> tidy_signs("atan2(-(-3.072), 19.43)"), tidy_signs("0.54 - (-2.100)")
    ('atan2(3.072, 19.43)', '0.54 + 2.100')
    """
    for pattern, replacement in _DOUBLE_NEGATIVE:
        shown = pattern.sub(replacement, shown)
    return shown
