"""The close search of the integrity check (issue 29, target 2): it forms only the pairs that could be kept, and
finds the same pairs, chances and listed matches, to the bit, as the band search alone and as every pair of the
class tested one by one; on random small classes with ties at the band's edge, blanks, text that is no number,
copies and near copies, one student, and every student alike."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from test_integrity import graded, make_key

from grader.grade import integrity, integrity_close
from grader.grade.integrity import Integrity, Pair, check
from grader.grade.integrity_close import bound, window
from grader.grade.key import Key
from grader.grade.report import integrity_csv

SETTINGS = settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])


def _class(draw: st.DrawFn) -> tuple[list[list[float]], dict[tuple[str, str], str]]:
    """A small class: values from a few (ties, bands whose edges hold another value exactly) or spread out;
    answers right, copied (as typed or in full), near copies, slips, blanks and text."""
    count = draw(st.integers(1, 14))
    parts = draw(st.integers(1, 4))
    few = draw(st.booleans())
    base = [1.0, 1.01, 1.02, 2.0, 2.02, 3.0, 100.0]
    values = [[draw(st.sampled_from(base)) if few else draw(st.floats(0.5, 3.0)) for _ in range(parts)]
              for _ in range(count)]
    typed: dict[tuple[str, str], str] = {}
    for i in range(count):
        source = draw(st.integers(0, count - 1))
        for j in range(parts):
            label = f"1{chr(ord('a') + j)}"
            kind = draw(st.sampled_from(["own", "copy", "full", "near", "slip", "blank", "text", "edge"]))
            theirs = values[source][j]
            typed[(f"s{i}", label)] = {
                "own": f"{values[i][j]:.4g}", "copy": f"{theirs:.3g}", "full": repr(theirs),
                "near": f"{theirs * 1.004:.5g}", "slip": f"{values[i][j] * 1.07:.4g}", "blank": "",
                "text": "abc", "edge": repr(theirs * 1.01)}[kind]
    return values, typed


@st.composite
def classes(draw: st.DrawFn) -> tuple[list[list[float]], dict[tuple[str, str], str]]:
    return _class(draw)


def _key(values: list[list[float]], unit: str) -> Key:
    """:func:`make_key`'s key with the parts in ``unit`` (``deg``: angles, compared modulo a turn)."""
    key = make_key(values)
    students = tuple(dataclasses.replace(student, parts={label: part._replace(unit=unit)
                                                         for label, part in student.parts.items()})
                     for student in key.students)
    return dataclasses.replace(key, students=students)


def _every_pair(result_graded: object, kept: float,
                monkeypatch: pytest.MonkeyPatch) -> set[tuple[int, int, tuple[str, ...]]]:
    """The pairs kept when every ordered pair of the class is tested, none left out by any search."""
    captured = {}
    original = integrity._pairs

    def capture(parts, answers, spread, found, examined, block=integrity.PAIRS):  # type: ignore[no-untyped-def]
        captured.update(parts=parts, answers=answers, spread=spread, examined=examined)
        return original(parts, answers, spread, found, examined, block)

    monkeypatch.setattr(integrity, "_pairs", capture)
    check(result_graded)  # type: ignore[arg-type]
    monkeypatch.setattr(integrity, "_pairs", original)
    if not captured:
        return set()
    parts, answers, spread = captured["parts"], captured["answers"], captured["spread"]
    students = len(answers.per_student)
    owners, partners = (grid.ravel() for grid in np.meshgrid(np.arange(students), np.arange(students), indexing="ij"))
    hits = integrity._hits(parts, answers, owners, partners)
    two = hits.sum(axis=1) >= 2
    if not two.any():
        return set()
    most = int(answers.per_student[owners[two]].max())
    found = integrity._figures(parts, answers, spread, owners[two], partners[two], captured["examined"], 2, kept,
                               hits[two], most)
    return {(pair.student, pair.partner, pair.labels) for pair in found.records()}


def _two(result: Integrity) -> set[tuple[int, int, tuple[str, ...]]]:
    return {(p.student, p.partner, p.labels) for p in result.pairs if len(p.labels) >= 2 and p.corrected < 1}


@pytest.mark.parametrize("kept", [1.0, 1e-3, 1e-9])
@SETTINGS
@given(drawn=classes(), unit=st.sampled_from(["m/s", "deg"]))
def test_the_close_search_finds_what_the_band_search_and_every_pair_find(
        monkeypatch: pytest.MonkeyPatch, kept: float, drawn: tuple[list[list[float]], dict[tuple[str, str], str]],
        unit: str) -> None:
    """The same findings, to the bit (and the same integrity.csv), with the close search and with the band search
    alone; the pairs kept are those of every ordered pair tested. ``kept`` below 1 narrows the windows, as a
    big class does; angles (``deg``) have windows of their own."""
    values, typed = drawn
    if unit == "deg":
        values = [[value * 120.0 for value in row] for row in values]  # up to a turn, 360 itself among them
        typed = {where: text if not text[:1].isdigit() else f"{float(text) * 120.0:.4g}"
                 for where, text in typed.items()}
    result_graded = graded(_key(values, unit), typed)
    monkeypatch.setattr(integrity, "KEPT", kept)
    close = check(result_graded)
    monkeypatch.setattr(integrity_close, "CLOSE", False)
    banded = check(result_graded)
    monkeypatch.setattr(integrity_close, "CLOSE", True)
    assert close == banded
    assert "".join(integrity_csv(result_graded, close)) == "".join(integrity_csv(result_graded, banded))
    if kept == 1.0:
        assert _two(close) == _every_pair(result_graded, kept, monkeypatch)


def test_a_class_of_one_and_a_class_all_alike() -> None:
    """One student matches nobody; students who all have the same values match nobody (a value their own band
    holds is not a match), however they answer."""
    one = graded(make_key([[2.0, 3.0]]), {("s0", "1a"): "2.5", ("s0", "1b"): "9"})
    assert check(one).pairs == () and check(one).matches == ()
    alike = graded(make_key([[2.0, 3.0]] * 6), {(f"s{i}", label): "2.5" for i in range(6) for label in ("1a", "1b")})
    assert check(alike).pairs == () and check(alike).matches == ()


def test_a_copy_in_full_is_found_among_many_alike(monkeypatch: pytest.MonkeyPatch) -> None:
    """Forty students share one value in each part (a crowd every wrong answer near it falls in); student 0 types
    student 41's values in full: the pair is found by the close search as by the band search."""
    values = [[2.0, 3.0]] * 40 + [[2.5, 3.5], [2.7, 3.9], [2.9, 4.4]]
    typed = {(f"s{i}", label): f"{v * 1.3:.3g}"
             for i, row in enumerate(values) for label, v in zip(("1a", "1b"), row, strict=True)}
    typed |= {("s0", "1a"): repr(2.7), ("s0", "1b"): repr(3.9)}
    result_graded = graded(make_key(values), typed)
    close = check(result_graded)
    monkeypatch.setattr(integrity_close, "CLOSE", False)
    assert check(result_graded) == close
    pair = close.pair(0, 41)
    assert isinstance(pair, Pair) and pair.labels == ("1a", "1b")


def test_the_window_is_where_the_distribution_holds_the_mass() -> None:
    # A uniform distribution on [0, 1] (its cumulative 0 to 1): from 0.5, a mass of 0.2 is reached at 0.3 and 0.7.
    grid = np.linspace(0.0, 1.0, 11)
    low, high = window(grid, grid.copy(), np.array([0.5, 0.05]), np.array([0.2, 0.2]))
    assert low.tolist() == pytest.approx([0.3, -np.inf]) and high.tolist() == pytest.approx([0.7, 0.25])


def test_the_bound_on_the_least_likely_part_of_a_kept_pair() -> None:
    # 10,000 pairs examined: two matched parts must multiply to under 1/10,000, so one is under 1/100 (x 2).
    assert bound(10_000, 1.0, np.array([2, 4, 0])).tolist() == pytest.approx([0.02, 0.2, np.inf])
    assert bound(10_000, 2.0, np.array([2])).tolist() == [np.inf]  # every pair kept: no bound
