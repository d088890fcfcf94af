"""The answers of plain submission files kept in columns (:class:`AnswerColumns`): a million students' 15 million
answers as :class:`~grader.grade.latest.Answer` tuples, each with its text and line number, take about 250 bytes
each; in columns, about 30 beside the characters typed. An answer is made when it is asked for: grading asks for a
piece of students' at a time (:func:`grader.grade.grading.graded_pieces`)."""

from __future__ import annotations

import functools
import itertools
from collections.abc import Iterator, Sequence
from typing import overload

import numpy as np
import numpy.typing as npt

from grader.grade.latest import Answer
from grader.grade.texts import Texts

Ints = npt.NDArray[np.int64]


class AnswerColumns(Sequence[Answer]):
    """Answers in columns: each one's student (an index into ``ids``, the key's order), label (into
    ``labels``), file (into ``files``, each with its delimiter), line (a file under 64 MiB has fewer than 2**31),
    and text; none has a timestamp."""

    __slots__ = ("_delimiters", "_file", "_files", "_ids", "_label", "_labels", "_line", "_texts", "student")

    def __init__(self, ids: Sequence[str], labels: Sequence[str], files: Sequence[tuple[str, str]],
                 student: npt.NDArray[np.int32], label: npt.NDArray[np.int16], file: npt.NDArray[np.int16],
                 line: npt.NDArray[np.int32], texts: Texts) -> None:
        self._ids, self._labels = ids, labels
        self._files, self._delimiters = [name for name, _ in files], [delimiter for _, delimiter in files]
        self.student, self._label, self._file, self._line, self._texts = student, label, file, line, texts

    @classmethod
    def joined(cls, ids: Sequence[str], labels: Sequence[str], files: Sequence[tuple[str, str]],
               blocks: Sequence[tuple[int, np.ndarray, np.ndarray, np.ndarray, Texts]]) -> AnswerColumns:
        """The answers of ``blocks``, one after another: each (its file's index in ``files``, the students'
        indices, the labels' indices, the lines, the texts)."""
        return cls(ids, labels, files, _column([block[1] for block in blocks], np.int32),
                   _column([block[2] for block in blocks], np.int16),
                   _column([np.full(len(block[3]), block[0]) for block in blocks], np.int16),
                   _column([block[3] for block in blocks], np.int32), Texts.joined([block[4] for block in blocks]))

    def __len__(self) -> int:
        return len(self.student)

    def __eq__(self, other: object) -> bool:
        """Equal to the same answers in a sequence of any kind (a tuple of them, as rows read one by one give)."""
        if not isinstance(other, Sequence) or isinstance(other, str):
            return NotImplemented
        return len(self) == len(other) and tuple(self) == tuple(other)

    __hash__ = None  # type: ignore[assignment]  # equal to a tuple, whose hash it cannot share cheaply

    @overload
    def __getitem__(self, index: int) -> Answer: ...

    @overload
    def __getitem__(self, index: slice) -> list[Answer]: ...

    def __getitem__(self, index: int | slice) -> Answer | list[Answer]:
        if isinstance(index, slice):
            return self.take(np.arange(len(self))[index])
        if not -len(self) <= index < len(self):
            raise IndexError("answer index out of range")
        return self.take(np.array([index % len(self)]))[0]

    def __iter__(self) -> Iterator[Answer]:
        for start in range(0, len(self), _BLOCK):
            yield from self.take(np.arange(start, min(start + _BLOCK, len(self))))

    def take(self, indices: Ints) -> list[Answer]:
        """The answers ``indices``, in their order."""
        files = self._file[indices].tolist()
        return list(map(functools.partial(tuple.__new__, Answer), zip(
            map(self._files.__getitem__, files), self._line[indices].tolist(),
            map(self._ids.__getitem__, self.student[indices].tolist()),
            map(self._labels.__getitem__, self._label[indices].tolist()), self._texts.take(indices),
            map(self._delimiters.__getitem__, files), itertools.repeat(None), strict=False)))  # repeat: endless


_BLOCK = 65_536  # answers made at a time when they are gone through


def _column(pieces: Sequence[Sequence[int] | np.ndarray], dtype: type) -> np.ndarray:
    return np.concatenate([np.asarray(piece, dtype) for piece in pieces] or [np.zeros(0, dtype)])
