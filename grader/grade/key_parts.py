"""A key's answer parts: :class:`KeyPart`, and the parts of a key read from its sidecar kept as columns
(:class:`PartTable`), each student's seen through a :class:`StudentParts` mapping that builds a part when it is
asked for. A class of 100,000 has 1.3 million parts, nearly all alike but for their value: the table holds each
distinct rest of a part once and the values as one float64 column, 12 bytes a part where a part object and its
value took 136, and a student's mapping 80 bytes where a dict took 500.

>>> tolerance = {"mode": "rtol", "rtol": 0.01, "atol": 0}
>>> shapes = [KeyPart("1", "e", "1a", None, "", 2.0, tolerance, None, {}),
...           KeyPart("1", "h", "1b", None, "m", 1.0, tolerance, None, {})]
>>> table = PartTable(shapes, np.array([0, 1, 0, 1], np.int32), np.array([0.7, 1.5, 0.6, np.nan]),
...                   {3: (None, {})})
>>> first, second = table.place(np.array([0, 2]), np.array([0, 0]), [{"1a": 0, "1b": 1}])
>>> first["1a"].value, second["1a"].value, second["1b"].value, list(second), second.possible()
(0.7, 0.6, None, ['1a', '1b'], 3.0)
>>> [part.value for part in table.column("1b")]  # a label's parts of every student at once
[1.5, None]
>>> table.entries("1b", "value"), table.entries("1b", "unit")  # or one entry of them, without the parts
([1.5, None], ['m', 'm'])
"""

from __future__ import annotations

import itertools
import operator
from collections.abc import Iterator, Mapping
from typing import Any, NamedTuple

import numpy as np


class KeyPart(NamedTuple):
    """One answer part of one student: what is expected and how it is graded. A named tuple: a class's key
    has millions, made in one go from columns (:meth:`PartTable.column`)."""

    problem: str
    name: str
    label: str
    value: float | str | None  # a number, an expression's text (symbolic), or None (undefined)
    unit: str
    points: float
    tolerance: Mapping[str, Any]  # the key's form: {"mode", "rtol", "atol"} or {"mode", "digits"}
    undefined: str | None
    symbols: Mapping[str, tuple[float, float]]  # symbolic answers: where each name is drawn

    @property
    def symbolic(self) -> bool:
        """Whether an expression, not a number, is expected."""
        return isinstance(self.value, str)


_NEW = tuple.__new__  # a KeyPart from its nine entries, without the named tuple's own __new__ (a Python call)


class PartTable:
    """Every part of every student: ``shapes[shape_of[row]]`` is the part of ``row`` but its value (its
    ``value`` None), ``values[row]`` its value where it is a number, and ``specials`` the value and the symbols'
    ranges of the rows whose value is no number (an expression, or None). Students' rows are consecutive."""

    __slots__ = (
        "_heads",
        "_kinds",
        "_layout_of",
        "_numbers",
        "_offsets",
        "_points",
        "_shape_of",
        "_shapes",
        "_special",
        "_specials",
        "_starts",
        "_tails",
        "_values",
        "students",
    )

    def __init__(self, shapes: list[KeyPart], shape_of: np.ndarray, values: np.ndarray,
                 specials: dict[int, tuple[str | None, Mapping[str, tuple[float, float]]]]) -> None:
        self._shapes = shapes
        self._heads = [shape[:3] for shape in shapes]  # problem, name, label
        self._tails = [shape[4:] for shape in shapes]  # unit, points, tolerance, undefined, symbols
        self._points = [shape.points for shape in shapes]
        self._kinds = np.ascontiguousarray(shape_of, np.int32)
        self._shape_of = self._kinds.data  # indexed one at a time: Python ints, without numpy's scalars
        self._numbers = np.ascontiguousarray(values, np.float64)
        self._values = self._numbers.data
        self._special = np.zeros(len(shape_of), bool)
        self._special[list(specials)] = True
        self._specials = specials
        self._starts, self._layout_of = np.zeros(0, np.int64), np.zeros(0, np.int64)
        self._offsets: list[dict[str, int]] = []
        self.students: Any = None  # the key's students made with these parts (set by who made them)

    def place(self, starts: np.ndarray, layout_of: np.ndarray, offsets: list[dict[str, int]]) -> list[StudentParts]:
        """The students' parts: a student's rows start at ``starts[i]``, and their labels are at
        ``offsets[layout_of[i]]`` from there (each label's rows found at once by :meth:`column`)."""
        self._starts, self._layout_of, self._offsets = starts, layout_of, offsets
        sizes = np.array([len(found) for found in offsets] or [0], np.int64)[layout_of]
        possible: list[float] = [0] * len(starts)
        points = np.array(self._points or [0.0])[self._kinds]
        for size in np.unique(sizes[sizes > 0]).tolist():  # no parts: 0, as a sum of none is
            members = np.flatnonzero(sizes == size)
            # The sum of each distinct row of points, as a sum over the parts gives it (a class has a few).
            distinct, inverse = np.unique(points[starts[members][:, None] + np.arange(size)], axis=0,
                                          return_inverse=True)
            sums = [sum(row) for row in distinct.tolist()]
            for member, which in zip(members.tolist(), inverse.ravel().tolist(), strict=True):
                possible[member] = sums[which]
        return list(map(StudentParts, itertools.repeat(self), starts.tolist(), map(offsets.__getitem__,
                                                                                     layout_of.tolist()), possible))

    def part(self, row: int) -> KeyPart:
        """The part of ``row``."""
        shape = self._shape_of[row]
        special = self._specials.get(row) if self._specials else None
        if special is None:
            return _NEW(KeyPart, self._heads[shape] + (self._values[row],) + self._tails[shape])
        return _NEW(KeyPart, (*self._heads[shape], special[0], *self._tails[shape][:-1], special[1]))

    def column(self, label: str, start: int = 0, stop: int | None = None) -> list[KeyPart]:
        """Every placed student's part ``label`` (of students ``start`` to ``stop``), made together
        (:class:`KeyError` where one has none)."""
        rows = self._rows(label, start, stop)
        shapes, values = self._kinds[rows].tolist(), self._numbers[rows].tolist()
        parts = list(map(_NEW, itertools.repeat(KeyPart), map(operator.add, map(
            operator.add, map(self._heads.__getitem__, shapes), zip(values)), map(self._tails.__getitem__, shapes))))
        for index in np.flatnonzero(self._special[rows]).tolist():
            parts[index] = self.part(int(rows[index]))
        return parts

    def entries(self, label: str, field: str, start: int = 0, stop: int | None = None) -> list[Any]:
        """Every placed student's entry ``field`` (``value``, ``tolerance``, ...) of their part ``label`` (of
        students ``start`` to ``stop``), without making the parts."""
        rows = self._rows(label, start, stop)
        found: list[Any]
        if field == "value":
            found = self._numbers[rows].tolist()
        else:
            position = KeyPart._fields.index(field)
            found = list(map([shape[position] for shape in self._shapes].__getitem__, self._kinds[rows].tolist()))
        if field in ("value", "symbols"):  # where the value is an expression or null, the table's own
            for index in np.flatnonzero(self._special[rows]).tolist():
                found[index] = getattr(self.part(int(rows[index])), field)
        return found

    def _rows(self, label: str, start: int = 0, stop: int | None = None) -> np.ndarray:
        """Each placed student's row of their part ``label`` (of students ``start`` to ``stop``)."""
        return self._starts[start:stop] + np.array([offsets[label] for offsets in self._offsets],
                                                   np.int64)[self._layout_of[start:stop]]


class StudentParts(Mapping[str, KeyPart]):
    """A student's parts by label, in the sheet's order: rows ``start + offsets[label]`` of ``table`` (the
    students of one layout share ``offsets``), and the sum of their points. A part is made each time it is
    asked for."""

    __slots__ = ("_offsets", "_possible", "_start", "_table")

    def __init__(self, table: PartTable, start: int, offsets: dict[str, int], possible: float) -> None:
        self._table, self._start, self._offsets, self._possible = table, start, offsets, possible

    def __getitem__(self, label: str) -> KeyPart:
        return self._table.part(self._start + self._offsets[label])

    def __contains__(self, label: object) -> bool:
        return label in self._offsets

    def __iter__(self) -> Iterator[str]:
        return iter(self._offsets)

    def __len__(self) -> int:
        return len(self._offsets)

    def __repr__(self) -> str:
        return repr(dict(self))

    @property
    def table(self) -> PartTable:
        """The table the parts are rows of."""
        return self._table

    def possible(self) -> float:
        """The sum of the parts' points, in order (as a sum over the parts themselves gives it)."""
        return self._possible
