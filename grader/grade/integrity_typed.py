"""How close a typed answer can claim to be, for the integrity check (:mod:`grader.grade.integrity`): the
half-unit of its last typed digit, in the sheet's unit.

A class's answers are read one text at a time, a few for each student and part, so the common shape (a plain
number, perhaps with an exponent, perhaps with a unit after it) is read straight off the text: the same as
:func:`~grader.grade.cells.typed_place` gives, which reads anything else.

>>> step("3.41 m/s", 3.41), step("5.79e+03", 5790.0), step("sqrt(2)", 1.41)
(0.005, 5.0, inf)
"""

from __future__ import annotations

import functools
import math
import re
from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from grader.grade.cells import typed_place

Floats = npt.NDArray[np.float64]

SHORT = 20  # characters: a text this short is at most 40 once cleaned, so its unit is found as typed_place finds it
_HEAD = re.compile(r"(-?)([0-9]+(?:\.[0-9]*)?)((?:[eE][-+]?[0-9]{1,4})?)")


def halves(texts: Sequence[str | None], numbers: Floats) -> list[float]:
    """:func:`step` of each text and number, read as it reads them (a loop of its own: a class has millions)."""
    head, unit_after, short = _HEAD.match, _unit_after, SHORT
    found = []
    for text, number in zip(texts, numbers.tolist(), strict=True):
        if text is not None and len(text) <= short and (plain := head(text)) and unit_after(
                _shape(plain[2]), plain[3], text[plain.end():]):
            exponent = plain[3][1:] or "0"
            value = float(f"{plain[1]}{plain[2]}e{exponent}")
            if value == 0 or not math.isfinite(value):
                found.append(math.inf)
            else:
                power = int(exponent) - len(plain[2].partition(".")[2])
                found.append(0.5 * float(f"1e{power}") * abs(number / value))
        else:
            found.append(step(text, number))
    return found


def step(text: str | None, number: float) -> float:
    """The half-unit of the last digit of a number as typed, in the sheet's unit: the place value of the typed
    number times the unit's factor (the number read over the number typed); inf: not a plain number."""
    typed = place(text) if text is not None else None
    if typed is None or typed[0] == 0:
        return math.inf
    return 0.5 * typed[1] * abs(number / typed[0])


def place(text: str) -> tuple[float, float] | None:
    """:func:`~grader.grade.cells.typed_place` of ``text``: read off the text when it is short and a plain
    number (``-``, digits, a point, an exponent) followed by what :func:`_unit_after` says is cut off as a
    unit; else by ``typed_place`` itself.

    >>> place("-6.50e-3 kN"), place("12 %"), place("1 234"), place("3.4.5")
    ((-0.0065, 1e-05), (12.0, 1.0), (1234.0, 1.0), None)
    """
    if len(text) <= SHORT and (head := _HEAD.match(text)) and _unit_after(_shape(head[2]), head[3],
                                                                            text[head.end():]):
        sign, mantissa, exponent = head[1], head[2], head[3][1:] or "0"
        power = int(exponent) - len(mantissa.partition(".")[2])
        value = float(f"{sign}{mantissa}e{exponent}")
        return (value, float(f"1e{power}")) if math.isfinite(value) else None
    return _typed_place(text)


@functools.lru_cache(maxsize=1 << 12)
def _unit_after(shape: str, exponent: str, tail: str) -> bool:
    """Whether ``typed_place`` reads a short text made of a plain number of the ``shape`` :func:`_shape` gives,
    its ``exponent`` (``e+03``; may be empty) and ``tail`` as the number alone: whether it reads the shape with
    the same exponent and tail as the shape with the exponent. Its decisions depend on the shape, exponent and
    tail alone: cleaning changes only the tail (the number is plain ASCII, not at either end's spaces); the
    unit is looked for at each letter (``°``, ``%``) after a character that is not one, of which the number has
    only its ``e``, and taken when the text before it ends in a digit or a point (a number's last character,
    either way) and the rest is a unit; a tail that goes on the number (a second point: ``3.41.``) does so as
    it goes on the shape; the number then read is the number alone, whatever its digits."""
    if not tail and not exponent:
        return True
    probe = typed_place(f"{shape}{exponent}{tail}")
    return probe is not None and probe == typed_place(f"{shape}{exponent}")


def _shape(mantissa: str) -> str:
    """A number of the same shape as ``mantissa``: without a point, ending in one, or with digits after it."""
    return "1" if "." not in mantissa else "1." if mantissa.endswith(".") else "1.0"


_typed_place = functools.lru_cache(maxsize=1 << 16)(typed_place)
