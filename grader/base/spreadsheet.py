"""CSV files people open in a spreadsheet: written with one writer, and every text cell that could be read as a
formula guarded (docs/design.md: formula injection).

The rule. Excel, LibreOffice Calc and Google Sheets read a cell that starts with ``= + - @`` (or a tab, CR or
LF before one) as a formula, and OWASP's guidance on CSV injection is to escape such a cell with a leading
``'``. A cell whose whole text is a plain decimal number (``-0.369``, ``-1.5e-07``) is the one exception: every
spreadsheet reads it as that number, nothing in it can run, and a ``'`` would only turn the number into
text a column's sum skips. Anything else that starts so stays guarded, a sentence too: ``-0.369 m/s is 3 %
above …`` is no number, so a spreadsheet tries it as a formula (Excel shows ``#NAME?`` or an error), and the
rest of such a sentence may be what a student typed (``-1+1|…`` is how a formula that runs a command
begins).

>>> csv_text([["id", "answer", "expected"], [safe_cell("2026001"), safe_cell("=1+1"), safe_cell("-0.369")]])
"id,answer,expected\\n2026001,'=1+1,-0.369\\n"
"""

from __future__ import annotations

import bisect
import csv
import io
import itertools
import math
import operator
import re
from collections.abc import Iterable, Iterator, Sequence

# A formula's first characters, their full-width forms (an East Asian keyboard's ＝, which a spreadsheet may
# read as =) and small forms, and the guard's own.
_GUARDED_START = frozenset("=+-@\t\r\n'" "\uff1d\uff0b\uff0d\uff20" "\ufe66\ufe62\ufe63\ufe6b")
_FIRST = operator.itemgetter(slice(0, 1))  # a text's first character, or "" for ""
# A negative number as a spreadsheet reads one, and nothing else: ASCII digits, a point, an exponent.
_NEGATIVE_NUMBER = re.compile(r"-(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][-+]?[0-9]+)?")


def safe_cell(text: str) -> str:
    """A CSV text cell a spreadsheet will not run as a formula (the module's rule): a cell starting with
    ``= + - @`` (or their full-width forms ``＝ ＋ － ＠``, or small forms), tab, CR or LF gets a leading ``'``,
    unless its whole text is a negative number; one that already starts with ``'`` gets another, so the
    original is always recovered by :func:`original_cell`.

    >>> safe_cell("=HYPERLINK(1)"), safe_cell("Ana"), safe_cell("'quoted"), safe_cell("＝HYPERLINK(1)")
    ("'=HYPERLINK(1)", 'Ana', "''quoted", "'＝HYPERLINK(1)")
    >>> safe_cell("-0.369"), safe_cell("-1.5e-07"), safe_cell("-0.369 m/s is 3 % above"), safe_cell("-1+1")
    ('-0.369', '-1.5e-07', "'-0.369 m/s is 3 % above", "'-1+1")
    """
    if text[:1] not in _GUARDED_START or _NEGATIVE_NUMBER.fullmatch(text):
        return text
    return "'" + text


def safe_cells(texts: Sequence[str]) -> list[str]:
    """:func:`safe_cell` of each text, called only for those that start with a character it guards.

    >>> safe_cells(["Ana", "=1+1", "-0.369", ""])
    ['Ana', "'=1+1", '-0.369', '']
    """
    firsts = list(map(_FIRST, texts))
    if _GUARDED_START.isdisjoint(firsts):
        return list(texts)
    return [safe_cell(text) if first in _GUARDED_START else text for text, first in zip(texts, firsts, strict=True)]


def original_cell(cell: str) -> str:
    """The text :func:`safe_cell` guarded: one leading ``'`` dropped.

    >>> original_cell("'=1+1"), original_cell("''quoted"), original_cell("Ana")
    ('=1+1', "'quoted", 'Ana')
    """
    return cell[1:] if cell.startswith("'") else cell


def number_cell(value: float, figures: int | None = None) -> str:
    """A number as a CSV cell: the shortest text that reads back as the same float (a whole number without
    ``.0``), or, for a column people read, ``value`` rounded to ``figures`` significant figures first, so
    that arithmetic's binary noise (``0.7999999999999999``) does not show.

    >>> number_cell(0.00019999999999975593), number_cell(0.00019999999999975593, 6), number_cell(2.0)
    ('0.00019999999999975593', '0.0002', '2')
    >>> number_cell(3.4149999999999996, 12), number_cell(-1.5e-07, 6)
    ('3.415', '-1.5e-07')
    """
    if not math.isfinite(value):
        raise ValueError("a CSV cell is not a finite number")  # a bug: no report holds one
    if figures is not None:
        value = float(f"{value:.{figures}g}")
    return repr(value + 0.0).removesuffix(".0") if value.is_integer() and abs(value) < 1e15 else repr(value)


def number_cells(values: Sequence[float], figures: int) -> list[str]:
    """:func:`number_cell` of each value rounded to ``figures`` significant figures, formatted in one call:
    ``%g`` to that many figures (at most 15, which any float64 near them holds) writes the text of the number
    rounded so, the shortest that reads back as it, but for a number with more digits before the point than
    ``figures``, which it writes with an exponent (``1.23e+05``, where :func:`number_cell` writes ``123000``),
    and one too small for float64 to hold so many figures (``4.94e-324``, read back as ``5e-324``): those,
    with an exponent of ``+`` or ``-3..``, are written one by one.

    >>> number_cells([0.012345, -0.0, 2.0, 123456.0, 1.5e-07, 5e-324], 3)
    ['0.0123', '0', '2', '123000', '1.5e-07', '5e-324']
    """
    if not all(map(math.isfinite, values)):
        raise ValueError("a CSV cell is not a finite number")  # a bug: no report holds one
    if figures > _EXACT_FIGURES:
        return [number_cell(value, figures) for value in values]
    texts = (f"%.{figures}g\n" * len(values) % tuple(value + 0.0 for value in values)).split("\n")  # + 0.0: no -0
    texts.pop()  # after the last line end
    return [number_cell(value, figures) if "e+" in text or "e-3" in text else text
            for text, value in zip(texts, values, strict=True)]


_EXACT_FIGURES = 15  # decimal digits that every float64 from 1e-299 up reads back as (DBL_DIG)


def csv_text(rows: Iterable[Sequence[object]]) -> str:
    """The CSV text of ``rows`` (``\\n`` line ends; cells as given: guard text cells with :func:`safe_cell`)."""
    return "".join(csv_pieces(rows))


def csv_pieces(rows: Iterable[Sequence[object]], rows_per_piece: int = 2000) -> Iterator[str]:
    """The CSV text of ``rows`` in pieces of ``rows_per_piece`` rows, to be written as they come: the
    whole text of a big file would be held twice (its writer's buffer and the text)."""
    stream = io.StringIO()
    writer = csv.writer(stream, lineterminator="\n")
    rows = iter(rows)
    writer.writerows(itertools.islice(rows, rows_per_piece))  # a piece's rows in one call: no loop in Python
    while stream.tell():  # every row writes at least its line end: an empty piece is the end
        yield stream.getvalue()
        stream.seek(0)
        stream.truncate()
        writer.writerows(itertools.islice(rows, rows_per_piece))
    yield ""


def csv_columns_text(columns: Sequence[Sequence[str]]) -> str:
    """The CSV text of the rows that ``columns`` of text cells make, as :func:`csv_text` writes them (the
    writer's own quoting for a cell that needs it), at the cost of joining text: a column without a delimiter,
    quote or line break in any cell is taken as it is, found in one search of its joined text.

    >>> csv_columns_text([["id", "7"], ["answer", 'say "hi", then'], ["note", "a\\nb"]])
    'id,answer,note\\n7,"say ""hi"", then","a\\nb"\\n'
    """
    if len(columns) < 2:  # a row of one empty cell is written as "": the writer knows its rules
        return csv_text(zip(*columns, strict=True))
    text = "\n".join(map(",".join, zip(*map(quoted_cells, columns), strict=True)))
    return text + "\n" if text else ""  # a row of two cells or more is never empty: "" is no row


def quoted_cell(cell: str) -> str:
    """A cell as the CSV writer writes it in a row of two cells or more (``excel``'s dialect: a cell with a
    delimiter, quote or line break is quoted, its quotes doubled): for a column of a few distinct cells, each
    quoted once.

    >>> quoted_cell("±1 %"), quoted_cell('say "hi", then')
    ('±1 %', '"say ""hi"", then"')
    """
    return '"' + cell.replace('"', '""') + '"' if _QUOTED.search(cell) else cell


def quoted_cells(column: Sequence[str]) -> Sequence[str]:
    """The cells of a column as the CSV writer writes them (:func:`quoted_cell`); the cells to quote are found
    by searching the column's joined text (each place found is in the cell whose end comes next).

    >>> quoted_cells(["a", "b,c", "d"])
    ['a', '"b,c"', 'd']
    """
    joined = "".join(column)
    places = [place for special in _SPECIAL for place in _places(joined, special)]
    if not places:  # most columns
        return column
    ends = list(itertools.accumulate(map(len, column)))
    written = list(column)
    for index in {bisect.bisect_right(ends, place) for place in places}:
        written[index] = quoted_cell(written[index])
    return written


def _places(text: str, special: str) -> Iterator[int]:
    """Where ``special`` is in ``text`` (str.find: faster than a regular expression over a long text)."""
    place = text.find(special)
    while place >= 0:
        yield place
        place = text.find(special, place + 1)


# What a cell may hold that the writer quotes, asked of the writer (a carriage return: from Python 3.12).
_SPECIAL = tuple(special for special in (",", '"', "\n", "\r") if csv_text([(special, "")]).startswith('"'))
_QUOTED = re.compile("[" + re.escape("".join(_SPECIAL)) + "]")
