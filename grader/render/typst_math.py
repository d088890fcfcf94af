"""Names, numbers and expression trees in Typst math, as a textbook prints them: ``h_drop`` as ``h_"drop"``,
``v1_n_after`` as ``v'_(1, n)``, a tree with the variant's numbers substituted.

>>> from grader.model.expr import parse
>>> math(parse("sqrt(2*g*h_drop)"))
'sqrt(2 g h_"drop")'
>>> math(parse("v_n - J/m"), {"v_n": "3.5", "J": "2.1 m"})
'3.5 - (2.1 m)/m'
"""

from __future__ import annotations

import math as _m
import re
from collections.abc import Mapping
from dataclasses import dataclass
from fractions import Fraction
from functools import lru_cache

from grader.model.expr import FUNCTIONS, Node, Num, Op, Sym, format_number
from grader.model.quantities import scientific, significant_binary
from grader.render.readable import counted
from grader.render.typst_text import string

GREEK = {"alpha", "beta", "gamma", "delta", "epsilon", "zeta", "eta", "theta", "iota", "kappa", "lambda",
         "mu", "nu", "xi", "pi", "rho", "sigma", "tau", "upsilon", "phi", "chi", "psi", "omega",
         "Gamma", "Delta", "Theta", "Lambda", "Xi", "Pi", "Sigma", "Phi", "Psi", "Omega"}


def _atom(word: str) -> str:
    if word in GREEK or re.fullmatch(r"[A-Za-z]|\d+", word):
        return word
    return str(string(word))


@lru_cache(maxsize=4096)  # a class's worked solutions name the same few quantities thousands of times
def name(quantity: str) -> str:
    """A quantity's name in Typst math: ``h_drop`` -> ``h_"drop"``, ``v1_n_after`` -> ``v'_(1, n)``.

    ``after`` becomes a prime, as in the textbook; a trailing digit or capital of the first part is
    a subscript (``vA`` -> ``v_A``, ``theta1`` -> ``theta_1``).

    A time interval ``dt`` (the catalogue's name for a contact time) is ``Δt``, as the page's sentences say.

    >>> name("theta"), name("vA_after"), name("E_lost"), name("dt")
    ('theta', "v'_A", 'E_"lost"', 'Delta t')
    """
    parts = quantity.split("_")
    if parts[0] == "dt":
        parts[0] = "t"
        return "Delta " + name("_".join(parts))
    primes = parts.count("after")
    rest = [p for p in parts[1:] if p and p != "after"]
    base = parts[0]
    split = re.fullmatch(r"([a-z]+)([A-Z]+)", base) or re.fullmatch(r"([A-Za-z]+?)(\d+)", base)
    if split and (split.group(1) in GREEK or len(split.group(1)) == 1):
        base, rest = split.group(1), [split.group(2), *rest]
    result = _atom(base) + "'" * primes
    if rest:
        subs = [_atom(p) for p in rest]
        result += f"_{subs[0]}" if len(subs) == 1 else f"_({', '.join(subs)})"
    return result


def number(value: float, figures: int = 4) -> str:
    """A number in Typst math to ``figures`` significant figures (trailing zeros kept), rounded as
    :func:`grader.model.quantities.significant_binary` says (the answer keys' worked solutions always have).

    >>> number(6.0459), number(0.000012346), number(-2.5), number(17683.2)
    ('6.046', '1.235 times 10^(-5)', '-2.500', '17680')
    """
    if value == 0 or not _m.isfinite(value):
        return "0" if value == 0 else str(string("undefined"))
    rounded = significant_binary(value, figures)
    mantissa, exponent = scientific(rounded, figures)
    if -3 <= exponent < 5:
        return f"{rounded:.{max(0, figures - 1 - exponent)}f}"
    return f"{mantissa} times 10^({exponent})"


# --- expression trees in Typst math --------------------------------------------------------------

_LEVEL = {"add": 4, "sub": 4, "mul": 5, "div": 5, "neg": 6, "pow": 7}
_CALLS = {"sqrt": "sqrt", "sin": "sin", "cos": "cos", "tan": "tan", "sind": "sin", "cosd": "cos",
          "log": "ln", "abs": "abs", "Max": "max", "Min": "min", "atan2": 'op("atan2")',
          # the worked solutions' inverse functions (solve/textbook_steps.py), which no template or student writes
          "asin": "sin^(-1)", "acos": "cos^(-1)", "atan": "tan^(-1)"}
_TRIG = {"sin", "cos", "tan", "sind", "cosd"}


@dataclass(frozen=True)
class _Math:
    """Converts trees; ``values`` replace names (substitution), ``degrees`` inside trig calls."""

    values: Mapping[str, str]
    degrees: Mapping[str, str]

    def convert(self, node: Node, trig: bool = False) -> tuple[str, int, bool]:
        """Typst math, precedence level and whether it shows a number."""
        if isinstance(node, Num):
            shown = self._num(node)
            return (f"({shown})", 9, True) if shown.startswith("-") or "/" in shown else (shown, 9, True)
        if isinstance(node, Sym):
            value = (self.degrees.get(node.name) if trig else None) or self.values.get(node.name)
            if value is None:  # a name of two atoms (Delta t) is grouped under a slash or a power, as a product is
                shown = name(node.name)
                return shown, 8 if " " in re.sub(r"\([^()]*\)", "", shown) else 9, False  # a space outside v_(1, n)
            bare = re.fullmatch(r"[0-9.]+|[0-9.]+ degree", value)
            return (value if bare else f"({value})"), 9, True
        if node.op in FUNCTIONS or node.op in _CALLS:
            return self._call(node), 9, False
        if node.op == "mul":
            return self._product(node), 5, False
        return self._operator(node)

    def _num(self, node: Num) -> str:
        if isinstance(node.value, float):
            return number(node.value)
        return format_number(node.value)

    def _call(self, node: Op) -> str:
        trig = node.op in _TRIG
        args = [self.convert(a, trig)[0] for a in node.args]
        if node.op == "hypot":
            squares = [self._power(a, "2") for a in node.args]
            return f"sqrt({' + '.join(squares)})"
        if node.op == "exp":
            return f"e^({args[0]})"
        return f"{_CALLS[node.op]}({', '.join(args)})"

    def _power(self, base: Node, exponent: str) -> str:
        shown, level, _ = self.convert(base)
        return f"{shown if level >= 9 else f'({shown})'}^{exponent}"

    def _factors(self, node: Node) -> list[Node]:
        if isinstance(node, Op) and node.op == "mul":
            return self._factors(node.args[0]) + self._factors(node.args[1])
        return [node]

    def _product(self, node: Op) -> str:
        pieces: list[tuple[str, bool]] = []
        for factor, count in counted(self._factors(node)):
            if count > 1:
                pieces.append((self._power(factor, str(count)), self.convert(factor)[2]))
                continue
            shown, level, numeric = self.convert(factor)
            if not pieces and _is_fraction(factor):  # 1/2 m v^2: Typst's fraction takes the 2 alone
                pieces.append((shown, False))
                continue
            # A fraction among factors stays bare: Typst's slash takes the group just before it, so
            # sqrt(x) (1 + e)/(1 - e) is the root times the fraction.
            if (level <= 5 and not _is_quotient(factor)) or (pieces and shown.startswith("-")):
                shown = f"({shown})"
            pieces.append((shown, numeric or shown[:1].isdigit()))
        result = pieces[0][0]
        for shown, numeric in pieces[1:]:
            result += (" dot " if numeric else " ") + shown
        return result

    def _operator(self, node: Op) -> tuple[str, int, bool]:
        level = _LEVEL[node.op]
        if node.op == "neg":
            shown, inner, _ = self.convert(node.args[0])
            return ("-" + (shown if inner >= 5 else f"({shown})")), 6, False
        if node.op == "pow":
            exponent = node.args[1]
            if isinstance(exponent, Num) and exponent.value == Fraction(1, 2):
                return f"sqrt({self.convert(node.args[0])[0]})", 9, False
            power = self.convert(exponent)[0]
            return self._power(node.args[0], power if re.fullmatch(r"\d+", power) else f"({power})"), 7, False
        left, left_level, _ = self.convert(node.args[0])
        right, right_level, _ = self.convert(node.args[1])
        if node.op == "div":
            numerator = left if left_level >= 9 else f"({left})"
            denominator = right if right_level >= 9 else f"({right})"
            return f"{numerator}/{denominator}", 5, False
        if (node.op == "sub" and right_level <= 4) or right.startswith("-"):
            right = f"({right})"
        sign = " + " if node.op == "add" else " - "
        return left + sign + right, level, False


def _is_quotient(node: Node) -> bool:
    return isinstance(node, Op) and node.op == "div"


def _is_fraction(node: Node) -> bool:
    """A quotient of two whole numbers: a product's leading coefficient, as :mod:`readable` writes it."""
    return isinstance(node, Op) and node.op == "div" and all(
        isinstance(arg, Num) and isinstance(arg.value, Fraction) and arg.value.denominator == 1 for arg in node.args)


def math(node: Node, values: Mapping[str, str] | None = None, degrees: Mapping[str, str] | None = None) -> str:
    """Typst math of a tree; ``values`` are shown instead of names (numbers substituted)."""
    return _Math(values or {}, degrees or {}).convert(node)[0]
