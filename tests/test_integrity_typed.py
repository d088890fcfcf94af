"""The integrity check's reading of how an answer was typed: a plain number (an exponent, a unit after it) is read
straight off the text, and must read as :func:`~grader.grade.cells.typed_place` reads it, whatever the text."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from grader.grade.cells import typed_place
from grader.grade.integrity_typed import halves, place, step

# Pieces students type: digits, points, signs, exponents, spaces of several kinds, units, superscripts, text.
PIECES = ["0", "1", "7", "12", "3.41", ".", "-", "+", "e", "E", "e+03", "e-4", " ", "\u2009", "\u00a0", "m", "/s",
          "m/s", "cm/s", "N·s", "kJ", "kN", "deg", "°", "%", "²", "^2", "^99999", "ft", "s", "x", "×10^3", ",", "5",
          "sqrt(", ")", "rad", "J", "or", "\t", "µm"]


@pytest.mark.parametrize(("text", "expected"), [
    ("3.41", (3.41, 0.01)), ("-7.92", (-7.92, 0.01)), ("50", (50.0, 1.0)), ("3.", (3.0, 1.0)),
    ("5.79e+03", (5790.0, 10.0)), ("2.5E-3", (0.0025, 0.0001)), ("165 cm/s", (165.0, 1.0)),
    ("1.06e+03 N·s", (1060.0, 10.0)), ("12 %", (12.0, 1.0)), ("46.2 deg", (46.2, 0.1)), ("3.41m/s", (3.41, 0.01)),
    ("1 234", (1234.0, 1.0)), ("1e99999", None), ("3.4.5", None), ("3.41 m/s or 2", None), ("six", None),
    ("3.41.", None), ("3.41,", None), ("3..", None),
])
def test_a_typed_number_reads_as_typed_place_reads_it(text: str, expected: tuple[float, float] | None) -> None:
    assert typed_place(text) == expected
    assert place(text) == expected


@settings(max_examples=200, deadline=None)
@given(st.lists(st.sampled_from(PIECES), min_size=1, max_size=6))
def test_any_text_reads_as_typed_place_reads_it(pieces: list[str]) -> None:
    text = "".join(pieces)
    assert place(text) == typed_place(text)
    typed = typed_place(text)
    expected = math.inf if typed is None or typed[0] == 0 else 0.5 * typed[1] * abs(1.7 / typed[0])
    assert halves([text], np.array([1.7])) == [step(text, 1.7)] == [expected]


def test_the_half_unit_is_of_the_last_digit_in_the_sheets_unit() -> None:
    assert step("165 cm/s", 1.65) == pytest.approx(0.005)  # half a cm/s, in m/s
    assert step("0", 0.0) == math.inf and step(None, 1.0) == math.inf and step("sqrt(2)", 1.41) == math.inf
