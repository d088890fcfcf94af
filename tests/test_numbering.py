"""``grader.base.numbering`` against ``numpy.unique``: the same arrays, of the same types, for values counted
(a narrow range) and searched (a wide one, a sample that misses rare values), int32 and int64, and rows."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from grader.base.numbering import numbered, numbered_first, numbered_rows


def _same(got: tuple[np.ndarray, ...], expected: tuple[np.ndarray, ...]) -> bool:
    return all(np.array_equal(a, b) and a.dtype == b.dtype for a, b in zip(got, expected, strict=True))


@settings(max_examples=150, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), size=st.integers(0, 3000), kinds=st.integers(1, 60),
       digits=st.integers(0, 18), narrow=st.booleans(), skew=st.sampled_from([0.05, 1.0, 10.0]))
def test_numbered_is_numpys_unique(seed: int, size: int, kinds: int, digits: int, narrow: bool, skew: float) -> None:
    """Rare values (a skewed choice) are often missed by the sample: they are searched again."""
    rng = np.random.default_rng(seed)
    pool = rng.integers(-(10**digits) - 1, 10**digits + 1, kinds)
    if narrow:
        pool = pool % 97 - 3
    values = rng.choice(pool, size, p=rng.dirichlet(np.full(kinds, skew)))
    values = values.astype(np.int32) if np.abs(values).max(initial=0) < 2**31 and seed % 2 else values
    distinct, index, inverse = np.unique(values, return_index=True, return_inverse=True)
    assert _same(numbered_first(values), (distinct, inverse.ravel(), index))
    assert _same(numbered(values), (distinct, inverse.ravel()))


@settings(max_examples=100, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), size=st.integers(0, 3000), width=st.integers(0, 6),
       largest=st.integers(0, 40))
def test_numbered_rows_is_numpys_unique_of_rows(seed: int, size: int, width: int, largest: int) -> None:
    """Rows of no entries too (a layout of a student without parts)."""
    rows = np.random.default_rng(seed).integers(0, largest + 1, (size, width))
    distinct, index, inverse = np.unique(rows, axis=0, return_index=True, return_inverse=True)
    assert _same(numbered_rows(rows), (distinct, inverse.ravel(), index))
