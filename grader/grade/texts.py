"""A column of texts held as one string (:class:`Texts`): a class's answers as typed, a million students' 15
million of them, each its own string, take about 60 bytes each beside their characters."""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from operator import is_not

import numpy as np
import numpy.typing as npt

Ints = npt.NDArray[np.int64]


class Texts:
    """A column of texts (None: no text), held as one string and where each text ends in it: a class's answers
    as typed, each its own string, take about 60 bytes each beside their characters."""

    __slots__ = ("_ends", "_given", "_text")

    def __init__(self, text: str, ends: np.ndarray, given: npt.NDArray[np.bool_]) -> None:
        self._text, self._ends, self._given = text, ends, given

    @classmethod
    def of(cls, texts: Sequence[str | None]) -> Texts:
        """The column of ``texts``."""
        count = len(texts)
        given = np.fromiter(map(is_not, texts, itertools.repeat(None)), bool, count)
        plain: Sequence[str] = texts if given.all() else ["" if text is None else text for text in texts]  # type: ignore[assignment]
        return cls("".join(plain), _narrow(np.cumsum(np.fromiter(map(len, plain), np.int64, count))), given)

    @classmethod
    def joined(cls, pieces: Sequence[Texts]) -> Texts:
        """The columns ``pieces``, one after another."""
        shifts = np.cumsum([0, *(len(piece._text) for piece in pieces)])
        return cls("".join(piece._text for piece in pieces),
                   _narrow(np.concatenate([piece._ends.astype(np.int64) + shift
                                           for piece, shift in zip(pieces, shifts.tolist(), strict=False)]
                                          or [np.zeros(0, np.int64)])),
                   np.concatenate([piece._given for piece in pieces] or [np.zeros(0, bool)]))

    def __len__(self) -> int:
        return len(self._ends)

    @property
    def given(self) -> npt.NDArray[np.bool_]:
        """Which cells have a text."""
        return self._given

    def take(self, indices: Sequence[int] | Ints) -> list[str | None]:
        """The texts of the cells ``indices``, in their order."""
        at = np.asarray(indices, np.int64)
        stops = self._ends[at]
        starts = np.where(at > 0, self._ends[at - 1], 0) if len(at) else stops
        text = self._text
        found: list[str | None] = [text[start:stop] for start, stop in zip(starts.tolist(), stops.tolist(),
                                                                          strict=True)]
        for index in np.flatnonzero(~self._given[at]).tolist():
            found[index] = None
        return found


def _narrow(ends: Ints) -> np.ndarray:
    """Where each text ends, in 4 bytes each where the texts are under 2 GiB characters (a part's of a class are)."""
    return ends.astype(np.int32) if not len(ends) or ends[-1] < 1 << 31 else ends
