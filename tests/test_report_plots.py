"""The class report's figures, written as SVG text (issue 29): round-numbered ticks chosen as a plotting
library chooses them (a step of 1, 2, 2.5 or 5 times a power of ten), and bars as tall or as wide as the
counts they stand for, worked out here by hand from the classes below."""

from __future__ import annotations

import re

import pytest

from grader.grade.class_summary import summarize
from grader.grade.report_plots import ACCENT, COLORS, WARN, score_histogram, verdict_bars
from grader.grade.svg_figure import tick_labels, ticks
from tests.test_class_report import make_class


@pytest.mark.parametrize(("low", "high", "most", "whole", "expected"), [
    (0.0, 100.0, 5, False, [0, 20, 40, 60, 80, 100]),  # 100/5 = 20: step 2 x 10
    (-5.0, 105.0, 4, False, [0, 25, 50, 75, 100]),  # 110/4 = 27.5: 10 too many, 20 six ticks, 25 five
    (1600.0, 2500.0, 3, False, [1750, 2000, 2250, 2500]),  # 300: 100 and 200 too many, 250 four
    (0.4, 0.9, 3, False, [0.4, 0.6, 0.8]),  # 0.167: 0.1 six ticks, 0.2 three
    (0.0, 10.5, 5, True, [0, 2, 4, 6, 8, 10]),  # whole numbers of students
    (0.0, 1.05, 5, True, [0, 1]),  # a step under 1 is no step for counting students
    (-1e300, 1e300, 4, False, [-1e300, -5e299, 0, 5e299, 1e300]),  # near float64's limit, no overflow
    (3.0, 3.0, 4, False, [3.0]),  # no span: the one value
])
def test_ticks_are_round_numbers_within_the_range(low: float, high: float, most: int, whole: bool,
                                                  expected: list[float]) -> None:
    assert ticks(low, high, most, whole) == pytest.approx(expected, rel=1e-12, abs=1e-12)


@pytest.mark.parametrize(("values", "expected"), [
    ([0.0, 20.0, 40.0], ["0", "20", "40"]),
    ([0.4, 0.6000000000000001, 0.8], ["0.4", "0.6", "0.8"]),  # a step's rounding error is not printed
    ([1.5, 2.0, 2.5], ["1.5", "2.0", "2.5"]),  # one number of decimals along an axis
    ([-0.5, 0.0, 0.5], ["\u22120.5", "0.0", "0.5"]),  # a minus sign, not a hyphen
    ([0.0, 250000.0, 500000.0], ["0", "2.5e5", "5.0e5"]),
    ([1e-4, 2e-4], ["1e\u22124", "2e\u22124"]),
])
def test_tick_labels_say_each_tick_with_as_few_digits_as_tell_them_apart(values: list[float],
                                                                        expected: list[str]) -> None:
    assert tick_labels(values) == expected


def _bars(figure: str, fill: str) -> list[tuple[float, float, float, float]]:
    """Each rectangle of color ``fill``: x, y, width, height."""
    found = re.findall(r'<rect x="([\d.]+)" y="([\d.]+)" width="([\d.]+)" height="([\d.]+)" fill="' + fill, figure)
    return [(float(x), float(y), float(w), float(h)) for x, y, w, h in found]


def test_the_histograms_bars_are_as_tall_as_the_students_in_each_5_percent_step() -> None:
    """Four students score 100 %, 100 %, 50 % and 0 % (one part worth 2 points, so the scores are whole
    shares): one student in [0, 5), one in [50, 55), two in [95, 100]."""
    graded = make_class({"1a": ["correct", "correct", "incorrect", "incorrect"],
                         "1b": ["correct", "correct", "correct", "incorrect"]})
    assert summarize(graded).percent.tolist() == [100.0, 100.0, 50.0, 0.0]
    bars = _bars(score_histogram(summarize(graded)), ACCENT)
    assert len(bars) == 3
    (x0, _, w0, h0), (x50, _, _, h50), (x95, _, w95, h95) = bars
    assert h0 == pytest.approx(h50, abs=0.11) and h95 == pytest.approx(2 * h0, abs=0.11)
    assert w0 == pytest.approx(w95, abs=0.11)
    assert (x50 - x0) / (x95 - x0) == pytest.approx(50 / 95, abs=0.002)  # the steps' left ends 0, 50 and 95


def test_the_verdict_bars_are_split_as_the_class_answered() -> None:
    """A part three students of four got right and one wrong: 75 % green, 25 % red, and those numbers
    written on them."""
    figure = verdict_bars(summarize(make_class({"1a": ["correct", "correct", "correct", "incorrect"]})))
    correct, incorrect = (_bars(figure, COLORS[kind])[0][2] for kind in ("correct", "incorrect"))  # then the legend's
    assert correct / incorrect == pytest.approx(3, abs=0.01)
    assert re.findall(r">(\d+)</text>", figure)[-2:] == ["75", "25"]


def test_a_hard_range_of_a_parameter_is_drawn_in_red() -> None:
    """The class of ``test_a_hard_corner_of_the_parameter_space_is_listed``: the ranges of e above 0.8
    scored 0, and each listed range is one red mark."""
    values = [0.05 * i for i in range(1, 20)] * 3
    summary = summarize(make_class({"1a": ["incorrect" if e > 0.8 else "correct" for e in values]},
                                   params=[{"e": e, "h": 1.0} for e in values]))
    from grader.grade.report_plots import difficulty

    figure = difficulty(summary.problems[0])
    assert figure.count(f'fill="{WARN}"') == len(summary.problems[0].hard_corners()) > 0
