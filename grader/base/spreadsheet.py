"""CSV files people open in a spreadsheet: written with one writer, and every text cell that could be read as a
formula guarded (docs/design.md: formula injection).

>>> csv_text([["id", "answer"], [safe_cell("2026001"), safe_cell("=1+1")]])
"id,answer\\n2026001,'=1+1\\n"
"""

from __future__ import annotations

import csv
import io
from collections.abc import Iterable, Iterator, Sequence

# A formula's first characters, their full-width forms (an East Asian keyboard's ＝, which a spreadsheet may
# read as =) and small forms, and the guard's own.
_GUARDED_START = frozenset("=+-@\t\r\n'" "\uff1d\uff0b\uff0d\uff20" "\ufe66\ufe62\ufe63\ufe6b")


def safe_cell(text: str) -> str:
    """A CSV text cell a spreadsheet will not run as a formula (docs/design.md: formula injection): a cell
    starting with ``= + - @`` (or their full-width forms ``＝ ＋ － ＠``, or small forms), tab, CR or LF gets a
    leading ``'``, and so does one that already starts with ``'``, so the original is always recovered by
    :func:`original_cell`.

    >>> safe_cell("=HYPERLINK(1)"), safe_cell("Ana"), safe_cell("'quoted"), safe_cell("＝HYPERLINK(1)")
    ("'=HYPERLINK(1)", 'Ana', "''quoted", "'＝HYPERLINK(1)")
    """
    return "'" + text if text[:1] in _GUARDED_START else text


def original_cell(cell: str) -> str:
    """The text :func:`safe_cell` guarded: one leading ``'`` dropped.

    >>> original_cell("'=1+1"), original_cell("''quoted"), original_cell("Ana")
    ('=1+1', "'quoted", 'Ana')
    """
    return cell[1:] if cell.startswith("'") else cell


def csv_text(rows: Iterable[Sequence[object]]) -> str:
    """The CSV text of ``rows`` (``\\n`` line ends; cells as given: guard text cells with :func:`safe_cell`)."""
    return "".join(csv_pieces(rows))


def csv_pieces(rows: Iterable[Sequence[object]], rows_per_piece: int = 2000) -> Iterator[str]:
    """The CSV text of ``rows`` in pieces of ``rows_per_piece`` rows, to be written as they come: the
    whole text of a big file would be held twice (its writer's buffer and the text)."""
    stream = io.StringIO()
    writer = csv.writer(stream, lineterminator="\n")
    for count, row in enumerate(rows, 1):
        writer.writerow(row)
        if count % rows_per_piece == 0:
            yield stream.getvalue()
            stream.seek(0)
            stream.truncate()
    yield stream.getvalue()
