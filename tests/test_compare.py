"""Comparing a submitted number with the key: tolerance modes, angles, errors, feedback, symbolic answers.

Boundary values are computed here with exact decimal arithmetic (``Fraction``), never with the code
under test; every number is meant as the decimal it prints as.
"""

from __future__ import annotations

import json
import math
from decimal import Decimal
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from grader.base.errors import GraderError
from grader.grade.compare import (
    LARGEST,
    errors,
    feedback,
    feedbacks,
    is_correct,
)
from grader.grade.equivalence import _functions, _survey, _values, _walk, equivalent
from grader.grade.grading import symbolic_outcome
from grader.model.expr import names, parse, to_text
from grader.model.tolerance import Tolerance, ToleranceError


def exact(value: float) -> Fraction:
    return Fraction(repr(value))


def to_float(value: Fraction) -> float:
    """The float that prints as ``value``; refuses a value float64 cannot print exactly."""
    text = format(Decimal(value.numerator) / Decimal(value.denominator), "f") if value.denominator != 1 \
        else str(value.numerator)
    result = float(text)
    assert exact(result) == value, f"{value} does not print exactly as a float"
    return result


def floor_log10(value: Fraction) -> int:
    """Independent of the code: walk powers of ten exactly."""
    k = math.floor(math.log10(value))
    while Fraction(10) ** k > value:
        k -= 1
    while Fraction(10) ** (k + 1) <= value:
        k += 1
    return k


def nudge(band: Fraction) -> Fraction:
    """A step well inside the band's last digits, yet far above float64's rounding (``to_float`` checks)."""
    return Fraction(10) ** (floor_log10(band) - 2)


def band(t: float, tolerance: Tolerance) -> Fraction:
    """The accepted distance from ``t``, from the rules as the issue states them."""
    key = exact(t)
    if tolerance.mode == "rtol":
        return exact(tolerance.atol) + exact(tolerance.rtol) * abs(key)
    if tolerance.mode == "decimals":
        return Fraction(51, 100) * Fraction(10) ** -tolerance.digits
    k = 0 if key == 0 else floor_log10(abs(key))
    return Fraction(51, 100) * Fraction(10) ** (k - tolerance.digits + 1)


BOUNDARY_CASES = [
    *((t, Tolerance(rtol=r, atol=a)) for t in (6.26, -6.26, 123456.789, 1e-200, 2.5e250, 0.0)
      for r, a in ((0.01, 0.0), (0.01, 0.05), (0.0, 0.05), (0.005, 0.0))
      if (t or a) and (1e-3 < abs(t) < 1e6 or not a)),  # 1e-200 + 0.05 has no float that prints it
    *((t, Tolerance("sigfigs", digits=n)) for t in (6.26, 1000.0, 999.9, 0.001, -0.0472, 1e-300, 1e308, 0.0, 1.0)
      for n in (1, 3, 5)),
    *((t, Tolerance("decimals", digits=n)) for t in (6.26, 0.0, -3.14159, 1e6) for n in (0, 2, 5)),
]


@pytest.mark.parametrize(("t", "tolerance"), BOUNDARY_CASES, ids=lambda x: repr(x))
def test_boundaries_inside_on_outside(t: float, tolerance: Tolerance) -> None:
    """Just inside is correct, just outside is not; on the boundary only ``rtol``'s ``<=`` accepts."""
    width = band(t, tolerance)
    key = exact(t)
    step = nudge(width)
    on_accepted = tolerance.mode == "rtol"
    for side in (1, -1):
        edge = key + side * width
        assert is_correct(to_float(edge - side * step), t, tolerance), "just inside"
        assert is_correct(to_float(edge), t, tolerance) == on_accepted, "on the boundary"
        assert not is_correct(to_float(edge + side * step), t, tolerance), "just outside"


# Worked by hand from PrairieLearn's rules: sigfigs eps = 0.51*10^(floor(log10|t|) - n + 1), decimals 0.51*10^-n.
PRAIRIELEARN = [
    # t, n, submitted, correct   (sigfigs)
    ("sigfigs", 6.26, 3, 6.2649, True), ("sigfigs", 6.26, 3, 6.2551, True), ("sigfigs", 6.26, 3, 6.2549, False),
    ("sigfigs", 6.26, 3, 6.2651, False), ("sigfigs", 6.26, 3, 6.3, False), ("sigfigs", 6.26, 2, 6.3, True),
    ("sigfigs", 1234.0, 2, 1284.0, True), ("sigfigs", 1234.0, 2, 1285.0, False),
    ("sigfigs", 1234.0, 2, 1184.0, True), ("sigfigs", 1234.0, 2, 1183.0, False),
    ("sigfigs", 0.00472, 2, 0.00477, True), ("sigfigs", 0.00472, 2, 0.004771, False),
    ("sigfigs", 0.00472, 2, 0.0047, True),
    ("sigfigs", 0.0, 3, 0.005, True), ("sigfigs", 0.0, 3, 0.0051, False), ("sigfigs", 0.0, 3, -0.005, True),
    ("sigfigs", 100.0, 2, 105.0, True), ("sigfigs", 100.0, 2, 105.1, False), ("sigfigs", 100.0, 2, 95.0, True),
    ("sigfigs", 100.0, 2, 94.9, False),
    ("sigfigs", 99.99, 2, 100.4, True), ("sigfigs", 99.99, 2, 100.5, False), ("sigfigs", 99.99, 2, 99.49, True),
    ("sigfigs", -19.1, 3, -19.14, True), ("sigfigs", -19.1, 3, -19.16, False),
    ("decimals", 6.26, 2, 6.265, True), ("decimals", 6.26, 2, 6.2651, False), ("decimals", 6.26, 0, 6.76, True),
    ("decimals", 6.26, 0, 6.77, False), ("decimals", -1.5, 1, -1.55, True), ("decimals", -1.5, 1, -1.551, False),
    ("decimals", -1.5, 1, -1.45, True), ("decimals", -1.5, 1, -1.449, False), ("decimals", 0.0, 3, 0.0005, True),
]


@pytest.mark.parametrize(("mode", "t", "n", "submitted", "correct"), PRAIRIELEARN)
def test_prairielearn_table(mode: str, t: float, n: int, submitted: float, correct: bool) -> None:
    tolerance = Tolerance.from_json({"mode": mode, "digits": n})
    assert bool(is_correct(submitted, t, tolerance)) is correct


RTOL_TABLE = [
    (6.3226, 6.26, Tolerance(), True), (6.1974, 6.26, Tolerance(), True), (6.3227, 6.26, Tolerance(), False),
    (6.31, 6.26, Tolerance(rtol=0, atol=0.05), True), (6.3101, 6.26, Tolerance(rtol=0, atol=0.05), False),
    (0.0, 0.0, Tolerance(), True), (1e-300, 0.0, Tolerance(), False), (0.05, 0.0, Tolerance(atol=0.05), True),
]


@pytest.mark.parametrize(("submitted", "t", "tolerance", "correct"), RTOL_TABLE)
def test_rtol_table(submitted: float, t: float, tolerance: Tolerance, correct: bool) -> None:
    assert bool(is_correct(submitted, t, tolerance)) is correct


def test_subnormal_and_extreme_keys() -> None:
    """floor(log10|t|) is exact for subnormals and 1e308; a subnormal key is its own match."""
    sigfigs = Tolerance("sigfigs", digits=3)
    assert is_correct(5e-324, 5e-324, sigfigs)
    assert not is_correct(1e-323, 5e-324, sigfigs)  # one subnormal step is 100 % away
    assert is_correct(1.0049e308, 1e308, sigfigs) and not is_correct(1.0052e308, 1e308, sigfigs)
    assert not is_correct(1e308, -1e308, Tolerance())  # the difference overflows float64
    assert is_correct(1e308, -1e308, Tolerance(rtol=3))


ANGLES = [
    (340.9, -19.1, Tolerance(), "deg", True), (-19.1, 340.9, Tolerance(), "deg", True),
    (359.5, 0.5, Tolerance(rtol=0, atol=1), "deg", True), (0.5, 359.5, Tolerance(rtol=0, atol=1), "deg", True),
    (359.4, 0.5, Tolerance(rtol=0, atol=1), "deg", False),
    (180.0, -180.0, Tolerance(rtol=0, atol=0), "deg", True), (179.9, -179.9, Tolerance(rtol=0, atol=0.2), "deg", True),
    (179.8, -179.9, Tolerance(rtol=0, atol=0.2), "deg", False),
    (720.5, 0.5, Tolerance(rtol=0, atol=0), "deg", True), (-1079.5, 0.5, Tolerance(rtol=0, atol=0), "deg", True),
    # The tolerance comes from the key as stored: 1 % of 340.9 is 3.409, 1 % of -19.1 only 0.191.
    (-15.7, 340.9, Tolerance(), "deg", True), (344.3, -19.1, Tolerance(), "deg", False),
    (340.9, -19.1, Tolerance("sigfigs", digits=3), "deg", True),
    (2 * math.pi - 0.001, 0.0, Tolerance(rtol=0, atol=0.002), "rad", True),
    (math.pi, -math.pi, Tolerance(rtol=0, atol=0), "rad", True),
    (2 * math.pi, 0.0, Tolerance(rtol=0, atol=0), "rad", True),
    (340.9, -19.1, Tolerance(), None, False),
]


@pytest.mark.parametrize(("submitted", "t", "tolerance", "unit", "correct"), ANGLES)
def test_angles_compare_as_directions(submitted: float, t: float, tolerance: Tolerance, unit: str | None,
                                      correct: bool) -> None:
    assert bool(is_correct(submitted, t, tolerance, angle_unit=unit)) is correct


def test_bad_angle_unit_refused() -> None:
    with pytest.raises(ValueError, match="angle_unit: expected 'deg', 'rad' or None, got 'grad'"):
        is_correct(1.0, 1.0, Tolerance(), angle_unit="grad")


def test_not_finite_is_never_correct() -> None:
    values = [math.nan, math.inf, -math.inf]
    assert not is_correct(values, 1.0, Tolerance(rtol=1e299)).any()
    assert not is_correct(1.0, values, Tolerance(rtol=1e299)).any()
    assert not is_correct(math.inf, math.inf, Tolerance()).any()


def test_errors_are_finite_with_documented_choices() -> None:
    absolute, relative = errors([6.5, 0.25, math.nan, 1e308, 1e300], [6.26, 0.0, 1.0, -1e308, 1e-300])
    assert np.isfinite(absolute).all() and np.isfinite(relative).all()
    assert relative[1] == absolute[1] == 0.25  # key 0: relative is the absolute error
    assert absolute[2] == relative[2] == LARGEST  # not a number
    assert absolute[3] == LARGEST  # overflow
    assert relative[4] == LARGEST  # 1e300 / 1e-300 overflows
    assert errors(-19.1, 340.9, angle_unit="deg")[0] == pytest.approx(0.0, abs=1e-12)


DESCRIBED = [
    (Tolerance(), "", "±1 %"), (Tolerance(atol=0.05), "", "±1 % + 0.05"),
    (Tolerance(atol=0.05), "m/s", "±1 % + 0.05 m/s"), (Tolerance(rtol=0.07), "", "±7 %"),
    (Tolerance(rtol=0.005), "", "±0.5 %"), (Tolerance(rtol=0, atol=0.5), "deg", "±0.5°"),
    (Tolerance("sigfigs", digits=3), "", "3 significant figures"),
    (Tolerance("sigfigs", digits=1), "", "1 significant figure"),
    (Tolerance("decimals", digits=2), "", "2 decimal places"), (Tolerance("decimals", digits=1), "", "1 decimal place"),
]


@pytest.mark.parametrize(("tolerance", "unit", "text"), DESCRIBED)
def test_describe(tolerance: Tolerance, unit: str, text: str) -> None:
    assert tolerance.describe(unit) == text


SENTENCES = [
    ((6.32, 6.26, "m/s", Tolerance(), True), "6.32 m/s is 0.96 % above 6.26 m/s; within ±1 % is accepted"),
    ((6.5, 6.26, "m/s", Tolerance(), False), "6.5 m/s is 3.8 % above 6.26 m/s; only ±1 % is accepted"),
    ((6.0, 6.26, "", Tolerance(), False), "6 is 4.2 % below 6.26; only ±1 % is accepted"),
    ((6.34, 6.26, "m", Tolerance(atol=0.1), True),
     "6.34 m is 0.08 m (1.3 %) above 6.26 m; within ±1 % + 0.1 m is accepted"),
    ((0.04, 0.0, "J", Tolerance(atol=0.05), True), "0.04 J is 0.04 J above 0 J; within ±1 % + 0.05 J is accepted"),
    ((6.26, 6.26, "", Tolerance(), True), "6.26 equals 6.26; within ±1 % is accepted"),
    ((6.262, 6.26, "", Tolerance("sigfigs", digits=3), True), "6.262 matches 6.26 to 3 significant figures"),
    ((6.2, 6.2, "", Tolerance("sigfigs", digits=3), True), "6.2 matches 6.20 to 3 significant figures"),
    ((6.3, 6.26, "", Tolerance("sigfigs", digits=3), False),
     "6.3 does not match 6.26 to 3 significant figures (it is 0.04 above)"),
    ((6.3, 6.26, "", Tolerance("decimals", digits=2), False),
     "6.3 does not match 6.26 to 2 decimal places (it is 0.04 above)"),
    ((340.9, -19.1, "deg", Tolerance(), True), "340.9° is the same direction as -19.1°; within ±1 % is accepted"),
    ((340.95, -19.1, "deg", Tolerance(), True),
     "340.95° is the same direction as -19.05°, which is 0.26 % above -19.1°; within ±1 % is accepted"),
    ((math.nan, 1.5, "m", Tolerance(), False), "nan is not a finite number, so it cannot match 1.5 m"),
    ((1.0, math.inf, "m", Tolerance(), False),
     "this answer has no finite value in the key; please ask your instructor to check it"),
]


@pytest.mark.parametrize(("arguments", "sentence"), SENTENCES)
def test_feedback_sentences(arguments: tuple[float, float, str, Tolerance, bool], sentence: str) -> None:
    submitted, expected, unit, tolerance, correct = arguments
    angle_unit = "deg" if unit == "deg" else None
    assert feedback(submitted, expected, unit, tolerance, correct, angle_unit=angle_unit) == sentence


@pytest.mark.parametrize("tolerance", [Tolerance(), Tolerance(rtol=0.02, atol=0.5), Tolerance(rtol=0, atol=1e-3),
                                       Tolerance("sigfigs", digits=1), Tolerance("decimals", digits=0),
                                       Tolerance("decimals", digits=17)])
def test_json_round_trip(tolerance: Tolerance) -> None:
    assert Tolerance.from_json(tolerance.to_json()) == tolerance


def test_json_reads_key_version_1() -> None:
    assert Tolerance.from_json({"rtol": 0.02}) == Tolerance(rtol=0.02)
    assert Tolerance.from_json({"atol": 1}) == Tolerance(atol=1.0)
    assert Tolerance.from_json({}) == Tolerance()
    assert Tolerance().to_json() == {"mode": "rtol", "rtol": 0.01, "atol": 0.0}
    assert Tolerance.from_json({"sigfigs": 2}) == Tolerance("sigfigs", digits=2)
    assert Tolerance.from_json({"decimals": 0}) == Tolerance("decimals", digits=0)


BAD_JSON = [
    ([0.01], "tolerance: expected a mapping"),
    ({"mode": "fuzzy"}, "tolerance.mode: expected 'rtol', 'sigfigs' or 'decimals', got 'fuzzy'"),
    ({"rtol": -1}, "tolerance.rtol: expected a number from 0 to 1e300, got -1"),
    ({"rtol": "1%"}, "tolerance.rtol: expected a number from 0 to 1e300, got '1%'"),
    ({"atol": True}, "tolerance.atol: expected a number from 0 to 1e300, got True"),
    ({"rtol": math.nan}, "got nan"), ({"atol": math.inf}, "got inf"),
    ({"mode": "sigfigs", "digits": 0}, "tolerance.digits: expected a whole number from 1 to 17, got 0"),
    ({"mode": "sigfigs", "digits": 2.5}, "tolerance.digits: expected a whole number from 1 to 17, got 2.5"),
    ({"mode": "decimals", "digits": 18}, "tolerance.digits: expected a whole number from 0 to 17, got 18"),
    ({"mode": "sigfigs", "rtol": 0.01}, "expected only the keys digits, mode, reason in sigfigs mode, got rtol"),
    ({"tol": 0.01}, "expected only the keys atol, mode, reason, rtol in rtol mode, got tol"),
]


@pytest.mark.parametrize(("data", "message"), BAD_JSON)
def test_bad_json_refused(data: object, message: str) -> None:
    with pytest.raises(ToleranceError) as caught:
        Tolerance.from_json(data)  # type: ignore[arg-type]
    assert message in str(caught.value)
    assert isinstance(caught.value, ValueError) and isinstance(caught.value, GraderError)


def test_settings_foreign_to_the_mode_refused() -> None:
    with pytest.raises(ToleranceError, match="no digits in rtol mode"):
        Tolerance(digits=4)
    with pytest.raises(ToleranceError, match="no rtol or atol in sigfigs mode"):
        Tolerance("sigfigs", atol=0.1)


# ---- equivalent ---------------------------------------------------------------------------------

DOMAINS = {"v": (1.0, 10.0), "p": (0.1, 5.0)}
KEY = parse("v*(1 - 0.1*p)/(p + 1)")


@pytest.mark.parametrize(("student", "verdict"), [
    ("(v - 0.1*p*v)/(1 + p)", True),
    ("v*(1 - 0.1*p)/(p + 2)", False),
    ("v*(1 - 0.1*p)/(p + 1) + 1e-3", False),
    ("v*(1 - 0.1*p)/(p + 1)*(1 + 1e-9)", True),  # inside rtol 1e-6
    ("v/(p - p)", "the expression cannot be evaluated at any test point (division by zero?)"),
    ("v*w", "the expression uses w, which this answer does not know"),
    ("sqrt(p - 2) + v*(1 - 0.1*p)/(p + 1) - sqrt(p - 2)", False),  # undefined where the key is defined
])
def test_equivalent(student: str, verdict: bool | str) -> None:
    assert equivalent(parse(student), KEY, DOMAINS, seed="2024-hw3") == verdict


def test_equivalent_skips_points_where_the_key_is_undefined() -> None:
    key = parse("sqrt(p - 2)*v")
    assert equivalent(parse("v*(p - 2)^0.5"), key, DOMAINS, seed="s") is True
    assert equivalent(parse("v"), parse("v/(p - p)"), DOMAINS, seed="s") == (
        "the key's expression cannot be evaluated at any test point; please ask your instructor to check it")


def test_equivalent_is_seeded_and_graded_once_a_text() -> None:
    student, wrong = parse("(v - 0.1*p*v)/(1 + p)"), parse("v*(1 - 0.1*p)/(p + 1.0001)")
    first = [equivalent(wrong, KEY, DOMAINS, seed=f"seed{i}", rtol=1e-5) for i in range(5)]
    assert first == [equivalent(wrong, KEY, DOMAINS, seed=f"seed{i}", rtol=1e-5) for i in range(5)]
    assert all(equivalent(student, KEY, DOMAINS, seed=f"seed{i}") is True for i in range(5))
    domains = tuple(sorted(DOMAINS.items()))
    verdict = symbolic_outcome("(v - 0.1pv)/(1 + p)", ",", domains, to_text(KEY), "seed0")
    hits = symbolic_outcome.cache_info().hits
    assert symbolic_outcome("(v - 0.1pv)/(1 + p)", ",", domains, to_text(KEY), "seed0") == verdict
    assert symbolic_outcome.cache_info().hits == hits + 1
    assert verdict[:2] == ("correct", 1.0) and verdict[3] == "(v - 0.1*p*v)/(1 + p)"


def test_equivalent_refuses_bad_settings() -> None:
    with pytest.raises(ValueError, match="domain of v"):
        equivalent(KEY, KEY, {"v": (2.0, 1.0), "p": (0.0, 1.0)}, seed="s")
    with pytest.raises(ValueError, match="1 <= points <= 1000"):
        equivalent(KEY, KEY, DOMAINS, seed="s", points=0)


# ---- properties ---------------------------------------------------------------------------------

finite = st.floats(allow_nan=False, allow_infinity=False)
anything = st.floats()
angle_units = st.sampled_from([None, "deg", "rad"])
tolerances = st.one_of(
    st.builds(Tolerance, rtol=st.floats(0, 1e3), atol=st.floats(0, 1e3)),
    st.builds(Tolerance, mode=st.just("sigfigs"), digits=st.integers(1, 17)),
    st.builds(Tolerance, mode=st.just("decimals"), digits=st.integers(0, 17)),
)
band_free = st.one_of(  # modes whose accepted band does not depend on the key
    st.builds(Tolerance, rtol=st.just(0.0), atol=st.floats(0, 1e3)),
    st.builds(Tolerance, mode=st.just("decimals"), digits=st.integers(0, 17)),
)


@given(finite, tolerances, angle_units)
def test_key_always_matches_itself(t: float, tolerance: Tolerance, unit: str | None) -> None:
    assert is_correct(t, t, tolerance, angle_unit=unit)


@given(finite, finite, band_free, angle_units)
def test_symmetric_where_the_band_does_not_depend_on_the_key(s: float, t: float, tolerance: Tolerance,
                                                              unit: str | None) -> None:
    assert is_correct(s, t, tolerance, angle_unit=unit) == is_correct(t, s, tolerance, angle_unit=unit)


@given(st.lists(st.tuples(anything, anything), min_size=1, max_size=20), tolerances, angle_units)
def test_vectorised_equals_scalar_and_nothing_is_nan(pairs: list[tuple[float, float]], tolerance: Tolerance,
                                                     unit: str | None) -> None:
    s, t = (np.array(column) for column in zip(*pairs, strict=True))
    together = is_correct(s, t, tolerance, angle_unit=unit)
    assert together.dtype == bool and together.shape == s.shape
    assert together.tolist() == [bool(is_correct(a, b, tolerance, angle_unit=unit)) for a, b in pairs]
    absolute, relative = errors(s, t, angle_unit=unit)
    assert np.isfinite(absolute).all() and np.isfinite(relative).all()
    assert (absolute >= 0).all() and (relative >= 0).all()


@given(finite.filter(lambda x: abs(x) < 1e300), st.floats(-0.5, 0.5), tolerances)
def test_near_misses_agree_with_the_exact_rule(t: float, offset: float, tolerance: Tolerance) -> None:
    """Submissions near the boundary: the verdict equals the rule evaluated in exact arithmetic."""
    width = band(t, tolerance)
    s = float(exact(t) + width * (1 + Fraction(offset)))
    distance = abs(exact(s) - exact(t))
    expected = distance <= width if tolerance.mode == "rtol" else distance < width
    assert bool(is_correct(s, t, tolerance)) is expected


@given(st.lists(st.tuples(anything, anything, st.booleans()), min_size=1, max_size=20), tolerances,
       st.sampled_from(["", "m/s", "deg", "rad", "%"]))
def test_a_class_of_sentences_reads_as_each_alone(answers: list[tuple[float, float, bool]], tolerance: Tolerance,
                                                  unit: str) -> None:
    """`feedbacks` on a whole column says of each answer what `feedback` says of it alone (one pass of
    numpy for the distances, the words worked out once, typed numbers remembered)."""
    angle_unit = unit if unit in ("deg", "rad") else None
    s, t, right = (list(column) for column in zip(*answers, strict=True))
    assert feedbacks(s, t, unit, tolerance, right, angle_unit=angle_unit) == [
        feedback(a, b, unit, tolerance, ok, angle_unit=angle_unit) for a, b, ok in answers]


def test_feedbacks_refuses_columns_of_different_lengths() -> None:
    with pytest.raises(ValueError, match="one length"):
        feedbacks([1.0, 2.0], [1.0], "", Tolerance(), [True, True])


def test_a_widened_tolerance_keeps_its_reason_through_the_key_and_grades_like_its_figure() -> None:
    widened = Tolerance(rtol=0.027, reason="rounding T and T′ to 4 figures moves loss_pct by up to 1.3 %")
    back = Tolerance.from_json(json.loads(json.dumps(widened.to_json())))
    assert back.reason == widened.reason and back.explained() == "±2.7 %: " + widened.reason
    assert back == Tolerance(rtol=0.027)  # the reason does not change how answers are graded
    with pytest.raises(ToleranceError, match=r"tolerance\.reason: expected text of at most 300 characters"):
        Tolerance(rtol=0.02, reason="x" * 301)


_PIECES = st.sampled_from(["v", "p", "pi", "2.5", "(p + 1)", "sqrt(p*v)", "exp(-p/4)", "Max(p, v)", "abs(p - 1)",
                           "atan2(p, v)", "hypot(p, 3)", "log(v)", "p^-1.5", "sin(pi)"])


@given(pieces=st.lists(_PIECES, min_size=1, max_size=5), joins=st.lists(st.sampled_from("+-*/^"),
                                                                          min_size=4, max_size=4))
def test_one_walk_of_a_symbolic_answer_finds_its_names_and_functions(pieces: list[str], joins: list[str]) -> None:
    """The survey symbolic comparison makes of a tree in one walk finds the names and functions the separate
    walks find, and watches only sub-terms that use a name (those it watches carry their own names)."""
    tree = parse("".join(piece + join for piece, join in zip(pieces, [*joins[:len(pieces) - 1], ""], strict=True)))
    found = _survey(tree)
    assert found.names == names(tree) and found.functions == _functions(tree)
    assert all(watched.names == names(watched.node) and watched.names for watched in found.watched)


@given(pieces=st.lists(_PIECES, min_size=1, max_size=5), joins=st.lists(st.sampled_from("+-*/^"),
                                                                          min_size=4, max_size=4))
def test_the_evaluating_walk_finds_what_the_survey_and_the_evaluation_find(pieces: list[str], joins: list[str]) -> None:
    """Symbolic comparison surveys and evaluates a student's tree in one walk: the same functions and watched
    sub-terms as the survey, the same values as evaluating the tree (NaN where it is undefined), and for each
    watched sub-term its own values."""
    tree = parse("".join(piece + join for piece, join in zip(pieces, [*joins[:len(pieces) - 1], ""], strict=True)))
    env = {"p": np.linspace(-1.0, 3.0, 9), "v": np.linspace(0.0, 10.0, 9)}
    walked, survey = _walk(tree, env), _survey(tree)
    assert walked is not None
    assert walked.functions == survey.functions and walked.watched == survey.watched
    np.testing.assert_array_equal(walked.values, _values(tree, env))
    for watched, values in zip(walked.watched, walked.watched_values, strict=True):
        if values is not None:
            np.testing.assert_array_equal(values, _values(watched.node, env))
