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
