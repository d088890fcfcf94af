"""The band search's counts (how many students' bands hold each wrong answer), read from the sorted ends of the
bands, against every student's band tested one by one: angles across the turn, answers exactly at a band's end,
values the student's own band holds, and bands too wide to count by ends."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from grader.grade import integrity_search
from grader.grade.integrity_search import accepts, bands, holding
from grader.model.tolerance import Tolerance


def _one_by_one(part: integrity_search.Bands, wrong: np.ndarray, numbers: np.ndarray) -> list[int]:
    everyone = np.arange(len(part.values))
    return [int(accepts(part, np.full(len(everyone), owner), everyone, numbers).sum()) for owner in wrong.tolist()]


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), wide=st.booleans(), ends=st.booleans(), unit=st.sampled_from(["deg", "rad"]))
def test_an_angles_matches_counted_by_ends_are_those_counted_one_by_one(seed: int, wide: bool, ends: bool,
                                                                        unit: str) -> None:
    """The same counts as the search one by one (the same bytes); and, but for an answer on a band's end across
    the turn (where that search's ranges follow the rounding of a place in the turn) or a band wider than a
    quarter turn (its ranges may not hold it), as every band tested."""
    rng = np.random.default_rng(seed)
    turn = 360.0 if unit == "deg" else 2 * np.pi
    count = int(rng.integers(2, 40))
    # A few values (ties), some near either side of a whole turn, some below zero or above a turn.
    choices = np.array([0.0, 0.001, 0.3, 0.5, 0.999, 1.0, -0.002, 1.003, 0.25]) * turn
    values = rng.choice(choices, count) + rng.choice([0.0, 0.0, 1e-3 * turn], count)
    tolerance = (Tolerance(rtol=0.0, atol=0.3 * turn) if wide else Tolerance()).to_json()
    part = bands("1a", values, [tolerance] * count, unit)
    # Answers at a band's ends exactly (as float64 gives them), across the turn, and anywhere.
    reach = part.reach
    others = rng.integers(0, count, count)
    on_end = values[others] + rng.choice([-1.0, 1.0], count) * reach[others]
    anywhere = values[others] + rng.uniform(-3, 3, count) * reach[others]
    numbers = np.where(ends & (rng.random(count) < 0.5), on_end, anywhere)
    numbers += rng.choice([0.0, turn, -turn], count)
    wrong = np.flatnonzero(rng.random(count) < 0.8)
    counts, _ = holding(part, wrong, numbers)
    integrity_search.BY_ENDS = False
    try:
        assert counts.tolist() == holding(part, wrong, numbers)[0].tolist()  # as before: the same bytes
    finally:
        integrity_search.BY_ENDS = True
    if not wide and not ends:
        assert counts.tolist() == _one_by_one(part, wrong, numbers)


@pytest.mark.parametrize("by_ends", [True, False])
def test_an_answer_on_a_bands_end_across_the_turn_is_counted_once(monkeypatch: pytest.MonkeyPatch,
                                                                   by_ends: bool) -> None:
    """359.9 ± 1 % holds 3.499 (a turn on) and 356.301 exactly at its ends; 0.5's own band is not counted."""
    monkeypatch.setattr(integrity_search, "BY_ENDS", by_ends)
    values = np.array([359.9, 359.9, 0.5, 180.0])
    part = bands("1a", values, [Tolerance().to_json()] * 4, "deg")
    numbers = np.array([np.nan, np.nan, 359.9 + part.reach[0] - 360.0, 359.9 - part.reach[0]])
    counts, _ = holding(part, np.array([2, 3]), numbers)
    assert counts.tolist() == _one_by_one(part, np.array([2, 3]), numbers) == [2, 2]


@settings(max_examples=80, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), strict=st.booleans())
def test_answers_tested_one_by_one_skip_only_values_the_students_own_band_holds(seed: int, strict: bool) -> None:
    """An answer tested one by one is tested past the values the student's own band surely holds (none counts as
    a match): the counts are every band tested, for values on and just inside or outside the own band's edges,
    ties, bands of 1 %, 3 % and a tiny absolute one, strict bounds."""
    rng = np.random.default_rng(seed)
    count = int(rng.integers(2, 60))
    centre = float(rng.choice([1.0, -2.5, 1e6, 3e-4]))
    rules = [Tolerance(), Tolerance(rtol=0.03), Tolerance(rtol=0.0, atol=abs(centre) * 1e-13)]
    if strict:
        rules.append(Tolerance("sigfigs", digits=3))
    chosen = rng.integers(0, len(rules), count)
    values = centre * (1 + rng.choice([0.0, 0.005, -0.01, 0.01, 0.02, -0.03, 0.0101], count))
    part = bands("1a", values, [rules[i].to_json() for i in chosen], "m/s")
    others = rng.integers(0, count, count)
    # Values on the edges of another's band, just inside or outside; on the edges of the student's own; slips.
    scale = rng.choice([1.0, 1 - 1e-6, 1 + 1e-6, 1 - 2e-16, 1 - 3e-6], count)
    side = rng.choice([-1.0, 1.0], count)
    numbers = np.select([rng.random(count) < 0.4, rng.random(count) < 0.5],
                        [values[others] + side * part.reach[others] * scale, values + side * part.reach * scale],
                        values * (1 + rng.uniform(-0.05, 0.05, count)))
    wrong = np.flatnonzero(rng.random(count) < 0.9)
    integrity_search.BY_ENDS = False  # every answer tested one by one
    try:
        counts, _ = holding(part, wrong, numbers)
    finally:
        integrity_search.BY_ENDS = True
    assert counts.tolist() == _one_by_one(part, wrong, numbers)
