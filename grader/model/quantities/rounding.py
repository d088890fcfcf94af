"""Numbers as written: the number grammar of templates, ``--set`` and batch files, and the one rule
for significant figures that the printed parameters, the sample answers, the worked solutions, the
tolerances and the grading of "three significant figures" share.

The rule: **a value is rounded as it prints**, from the shortest decimal that reads back as the same
float (Python's ``repr``), **halves rounded up** (away from zero), as a person rounds the digits on the
page. ``2.675`` is 2.68 to three figures, though the float nearest to it lies just below; ``0.125`` is
0.13. A value's leading exponent is that decimal's, so ``999.9999999999999`` has two digits before the
point, not the three a float ``log10`` says.

>>> printed_text(2.675, None, 3), printed_text(0.125, None, 2), printed_text(2398.7, None, 3)
('2.68', '0.13', '2400')
>>> [leading_exponent(x) for x in (1000.0, 999.9999999999999, 1e-5, 5e-324, 1e308, -0.02)]
[3, 2, -5, -324, 308, -2]
"""

from __future__ import annotations

import math
import re
from decimal import MAX_EMAX, MIN_EMIN, ROUND_HALF_EVEN, ROUND_HALF_UP, Context, Decimal
from typing import Any

import numpy as np

NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")
"""A number as a value is written in a template, ``--set`` or a batch file."""
MAX_TEXT = 100
"""Characters of a number with its unit."""

_EXACT = Context(prec=1000, Emax=MAX_EMAX, Emin=MIN_EMIN)  # any float64, printed exactly


def split_quantity(text: str) -> tuple[float, str] | None:
    """A number and the unit text after it (``"2.1 m"`` -> ``(2.1, "m")``), or None when the text
    does not start with a finite float64 number or is longer than ``MAX_TEXT``. Linear in the text.

    >>> split_quantity(" 2.1e3 mm "), split_quantity("1e309"), split_quantity("abc")
    ((2100.0, 'mm'), None, None)
    """
    text = text.strip()
    match = NUMBER.match(text) if len(text) <= MAX_TEXT else None
    if match is None:
        return None
    value = float(match.group())
    return (value, text[match.end():].strip()) if math.isfinite(value) else None


def significant(value: float, figures: int) -> Decimal:
    """``value`` to ``figures`` significant figures by the rule above, exactly, as a decimal whose last
    digit is the last figure kept (``significant(2398.7, 3)`` is ``2.40E+3``); 0 stays 0."""
    number = Decimal(repr(float(value)))
    if number.is_zero():
        return Decimal(0)
    return number.quantize(Decimal(1).scaleb(number.adjusted() - (figures - 1)), ROUND_HALF_UP, context=_EXACT)


def significant_binary(value: float, figures: int) -> Decimal:
    """The variant the worked solutions keep: the float's exact binary value to ``figures`` significant
    figures, halves to even, as Python's ``format`` rounds (``45.125`` is 45.12 here, 45.13 by the rule,
    and ``0.45375``, whose float lies just below the half, 0.4537 here, 0.4538 by the rule).

    The answer keys printed so far round this way: the demo's alone has three such numbers in its worked
    solutions, so the rule would change keys already handed out. Only :func:`grader.render.typst_math.number`
    uses it."""
    if value == 0:
        return Decimal(0)
    number = Decimal(float(value))
    return number.quantize(Decimal(1).scaleb(number.adjusted() - (figures - 1)), ROUND_HALF_EVEN, context=_EXACT)


def leading_exponent(value: float) -> int:
    """``floor(log10|value|)`` exactly, of the number as it prints (0 for 0)."""
    if value == 0:
        return 0
    return int(Decimal(repr(float(value))).adjusted())


def printed_text(value: float, decimals: int | None, sig_figs: int | None) -> str:
    """A value as printed on the page: fixed decimals, or significant figures, by the rule above.
    Never ``-0``: a value that rounds to zero prints without a sign.

    >>> printed_text(-0.004, 2, None), printed_text(1e30, None, 2), printed_text(-0.0, None, 3)
    ('0.00', '1000000000000000000000000000000', '0')
    """
    number = Decimal(repr(float(value)))
    if decimals is not None:
        rounded = number.quantize(Decimal(1).scaleb(-decimals), ROUND_HALF_UP, context=_EXACT)
        return str(abs(rounded) if rounded.is_zero() else rounded)
    if sig_figs is None:
        raise ValueError("a printed precision needs decimals or sig_figs")
    rounded = significant(value, sig_figs)
    if rounded.is_zero():
        return "0"
    return f"{rounded:f}" if rounded.as_tuple().exponent < 0 else str(int(rounded))  # type: ignore[operator]


def scientific(rounded: Decimal, figures: int) -> tuple[str, int]:
    """A nonzero value rounded to ``figures`` significant figures as a mantissa with one digit before the
    point and its power of ten: ``scientific(significant(17683.2, 3), 3)`` is ``("1.77", 4)``."""
    exponent = rounded.adjusted()
    return f"{rounded.scaleb(-exponent, context=_EXACT):.{figures - 1}f}", exponent


def round_figures(values: Any, figures: int) -> np.ndarray:
    """Values rounded to ``figures`` significant figures by the rule above, as floats (0 stays 0; what is
    not finite stays as it is).

    >>> round_figures(np.array([0.0123456, -2345.6, 0.0, 0.125]), 2).tolist()
    [0.012, -2300.0, 0.0, 0.13]
    """
    x = np.asarray(values, dtype=float)
    flat = [float(significant(v, figures)) if math.isfinite(v) else v for v in x.ravel().tolist()]
    return np.array(flat, dtype=float).reshape(x.shape)


def half_unit(values: Any, figures: int) -> np.ndarray:
    """Half a unit in the ``figures``-th significant figure of each value: the most rounding it to that
    many figures moves it (0 for 0, and for what is not finite). A bound, vectorised: the exponent comes
    from a float ``log10``, which may say 3 for ``999.9999999999999`` where :func:`leading_exponent` says 2,
    and is never smaller, so the bound is only ever wider.

    >>> half_unit(np.array([45.09, 0.6315, 0.0]), 3).tolist()
    [0.05, 0.0005, 0.0]
    """
    x = np.abs(np.asarray(values, dtype=float))
    with np.errstate(all="ignore"):
        exponent = np.floor(np.log10(np.where(x > 0, x, 1.0))) - (figures - 1)
        return np.where((x > 0) & np.isfinite(x), 0.5 * 10.0**exponent, 0.0)
