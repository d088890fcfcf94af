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
from grader.grade.integrity_close import Elsewhere, bound, window
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


def _drawn(drawn: tuple[list[list[float]], dict[tuple[str, str], str]], unit: str) -> object:
    """The class drawn, graded; for angles (``deg``), its values and answers scaled to up to a turn (360
    itself among them)."""
    values, typed = drawn
    if unit == "deg":
        values = [[value * 120.0 for value in row] for row in values]
        typed = {where: text if not text[:1].isdigit() else f"{float(text) * 120.0:.4g}"
                 for where, text in typed.items()}
    return graded(_key(values, unit), typed)


def _every_two(result_graded: object, monkeypatch: pytest.MonkeyPatch) -> dict[str, object] | None:
    """What the check compares, and every ordered pair of the class with two or more matched parts (none left
    out by any search), with its matched parts: None when no pair has two."""
    captured: dict[str, object] = {}
    original = integrity._pairs

    def capture(parts, answers, spread, found, examined, block=integrity.PAIRS):  # type: ignore[no-untyped-def]
        captured.update(parts=parts, answers=answers, spread=spread, examined=examined, found=found)
        return original(parts, answers, spread, found, examined, block)

    monkeypatch.setattr(integrity, "_pairs", capture)
    check(result_graded)  # type: ignore[arg-type]
    monkeypatch.setattr(integrity, "_pairs", original)
    if not captured:
        return None
    parts, answers = captured["parts"], captured["answers"]
    students = len(answers.per_student)  # type: ignore[attr-defined]
    owners, partners = (grid.ravel() for grid in np.meshgrid(np.arange(students), np.arange(students), indexing="ij"))
    hits = integrity._hits(parts, answers, owners, partners)  # type: ignore[arg-type]
    two = hits.sum(axis=1) >= 2
    if not two.any():
        return None
    return captured | {"owners": owners[two], "partners": partners[two], "hits": hits[two],
                       "most": int(answers.per_student[owners[two]].max())}  # type: ignore[attr-defined]


def _figured(every: dict[str, object], below: float) -> integrity.Pairs:
    """:func:`integrity._figures` of every pair with two matched parts, those under ``below``."""
    return integrity._figures(every["parts"], every["answers"], every["spread"], every["owners"],  # type: ignore
                              every["partners"], every["examined"], 2, below, every["hits"], every["most"])


def _every_pair(result_graded: object, kept: float,
                monkeypatch: pytest.MonkeyPatch) -> set[tuple[int, int, tuple[str, ...]]]:
    """The pairs kept when every ordered pair of the class is tested, none left out by any search."""
    every = _every_two(result_graded, monkeypatch)
    if every is None:
        return set()
    return {(pair.student, pair.partner, pair.labels) for pair in _figured(every, kept).records()}


def _two(result: Integrity, kept: float) -> set[tuple[int, int, tuple[str, ...]]]:
    return {(p.student, p.partner, p.labels) for p in result.pairs if len(p.labels) >= 2 and p.corrected < kept}


@pytest.mark.parametrize("kept", [1.0, 1e-3, 1e-9])
@SETTINGS
@given(drawn=classes(), unit=st.sampled_from(["m/s", "deg"]))
def test_the_close_search_finds_what_the_band_search_and_every_pair_find(
        monkeypatch: pytest.MonkeyPatch, kept: float, drawn: tuple[list[list[float]], dict[tuple[str, str], str]],
        unit: str) -> None:
    """The same findings, to the bit (and the same integrity.csv), with the close search and with the band search
    alone; the pairs kept are those of every ordered pair tested. ``kept`` below 1 narrows the windows, as a
    big class does (and moves where each student's search is split between the two); angles (``deg``) have
    windows of their own."""
    result_graded = _drawn(drawn, unit)
    monkeypatch.setattr(integrity, "KEPT", kept)
    monkeypatch.setattr(integrity_close, "FEW", 0)  # a small class is searched by bands alone unless told
    close = check(result_graded)
    monkeypatch.setattr(integrity_close, "CLOSE", False)
    banded = check(result_graded)
    monkeypatch.setattr(integrity_close, "CLOSE", True)
    assert close == banded
    assert "".join(integrity_csv(result_graded, close)) == "".join(integrity_csv(result_graded, banded))
    assert _two(close, kept) == _every_pair(result_graded, kept, monkeypatch)


@SETTINGS
@given(drawn=classes(), unit=st.sampled_from(["m/s", "deg"]), kept=st.sampled_from([1.0, 1e-3, 1e-9]),
       seed=st.integers(0, 2**32 - 1))
def test_the_findings_are_the_same_wherever_each_students_search_is_split(
        monkeypatch: pytest.MonkeyPatch, drawn: tuple[list[list[float]], dict[tuple[str, str], str]], unit: str,
        kept: float, seed: int) -> None:
    """Each student's search split at a number of parts drawn at random (any from the band search alone to the
    close search alone), not the cheapest: the same findings, to the bit, and the pairs kept are those of every
    ordered pair tested (random small classes seldom make the cheapest split fall between the two)."""
    result_graded = _drawn(drawn, unit)
    monkeypatch.setattr(integrity, "KEPT", kept)
    cheapest = check(result_graded)
    original = integrity_close._formed
    rng = np.random.default_rng(seed)

    def anywhere(parts, spread, wrong, numbers, typed, ranges, rows_of, *rest):  # type: ignore[no-untyped-def]
        rank, owners, _cheapest, cost, needed = rest[:5]
        levels = np.zeros(len(needed), dtype=np.int64)
        for part, rows in zip(parts, rows_of, strict=True):
            levels[wrong[part.label][rows]] += 1
        drawn_split = rng.integers(needed[owners] - 1, levels[owners] + 1)
        return original(parts, spread, wrong, numbers, typed, ranges, rows_of, rank, owners, drawn_split,
                        np.maximum(cost, 1.0), needed, *rest[5:])

    monkeypatch.setattr(integrity_close, "_formed", anywhere)
    assert check(result_graded) == cheapest
    monkeypatch.setattr(integrity_close, "_formed", original)
    assert _two(cheapest, kept) == _every_pair(result_graded, kept, monkeypatch)


@SETTINGS
@given(drawn=classes(), unit=st.sampled_from(["m/s", "deg"]))
def test_the_bound_that_spares_the_figures_is_at_most_every_corrected_chance(
        monkeypatch: pytest.MonkeyPatch, drawn: tuple[list[list[float]], dict[tuple[str, str], str]],
        unit: str) -> None:
    """The cheap bound from below (:func:`integrity._at_least`) that leaves pairs out before their chances are
    worked out is at most the corrected chance :func:`integrity._figures` gives every pair with two matched
    parts, before that is capped at 1 (checked against the cap too: a capped pair is never kept): so a pair
    it leaves out could not have been kept. Copies as typed and in full, near copies and slips are among
    the answers; the classes are small, so the bound is tested as it is, not only where it leaves pairs out."""
    every = _every_two(_drawn(drawn, unit), monkeypatch)
    if every is None:
        return
    corrected = _figured(every, np.inf).corrected
    least = np.exp(integrity._at_least(every["parts"], every["answers"], every["spread"],  # type: ignore[arg-type]
                                       every["owners"], every["partners"], every["hits"],  # type: ignore[arg-type]
                                       every["examined"]))  # type: ignore[arg-type]
    assert len(least) == len(corrected)
    capped = corrected >= 1.0
    assert np.all(least[~capped] <= corrected[~capped] * (1 + 1e-9))
    # What it leaves out at the thresholds a big class reaches is never kept.
    for below in (1.0, 1e-3):
        possible = integrity._possible(every["parts"], every["answers"], every["spread"],  # type: ignore[arg-type]
                                       every["owners"], every["partners"], every["hits"],  # type: ignore[arg-type]
                                       every["examined"], below)  # type: ignore[arg-type]
        assert not np.any(~possible & (corrected < below))


@SETTINGS
@given(drawn=classes(), unit=st.sampled_from(["m/s", "deg"]))
def test_a_partner_let_go_before_its_bands_are_compared_holds_no_other_wrong_answer(
        monkeypatch: pytest.MonkeyPatch, drawn: tuple[list[list[float]], dict[tuple[str, str], str]],
        unit: str) -> None:
    """:class:`Elsewhere` keeps every pair found for a part whose partner's band holds another of the owner's
    wrong answers (every ordered pair of the class with two matched parts, tested one by one), and lets go
    pairs that hold no other (so it is not a check that keeps everything)."""
    every = _every_two(_drawn(drawn, unit), monkeypatch)
    if every is None:
        return
    parts, answers = every["parts"], every["answers"]
    students = len(answers.per_student)  # type: ignore[attr-defined]
    elsewhere = Elsewhere(parts, answers.wrong, [ranges for _, ranges in every["found"]],  # type: ignore
                          students)
    owners, partners = (grid.ravel() for grid in np.meshgrid(np.arange(students), np.arange(students), indexing="ij"))
    hits = integrity._hits(parts, answers, owners, partners)  # type: ignore[arg-type]
    for index in range(len(parts)):  # type: ignore[arg-type]
        rows = np.flatnonzero(hits[:, index])
        other = np.delete(hits[rows], index, axis=1).any(axis=1)
        kept = elsewhere(index, owners[rows], np.arange(len(rows)), partners[rows]) > 0
        assert np.all(kept[other])
        # A partner whose band holds none of the owner's other answers is in no other range but by the range's
        # slack: a partner with no value in any other part is never kept.
        valued = np.zeros(students, dtype=bool)
        for other_index, part in enumerate(parts):  # type: ignore[arg-type]
            if other_index != index:
                valued[part.order] = True
        assert not np.any(kept & ~valued[partners[rows]])


def test_elsewhere_lets_go_a_partner_out_of_every_other_range() -> None:
    """Two parts; student 0's wrong answers' ranges hold student 2 in the first part's order and student 1 in
    the second's: found for the first part, student 1 is kept (in the second part's range), student 2 is not."""
    from grader.grade.integrity_search import bands
    from grader.model.tolerance import Tolerance

    first, second = (bands(label, np.array([1.0, 2.0, 3.0]), [Tolerance().to_json()] * 3, "m")
                     for label in ("1a", "1b"))
    wrong = {"1a": np.array([0]), "1b": np.array([0])}
    ranges = [[(np.array([2]), np.array([3]))], [(np.array([1]), np.array([2]))]]
    elsewhere = Elsewhere([first, second], wrong, ranges, 3)
    assert elsewhere(0, np.array([0]), np.array([0, 0]), np.array([1, 2])).tolist() == [1, 0]
    assert elsewhere(1, np.array([0]), np.array([0, 0]), np.array([1, 2])).tolist() == [0, 1]
    # A student with no other wrong answer keeps no partner.
    assert elsewhere(0, np.array([1]), np.array([0]), np.array([2])).tolist() == [0]


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
    monkeypatch.setattr(integrity_close, "FEW", 0)
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
