"""Reading the files users hand us (templates, assignments, rosters, batch CSVs), with bounds.

Every reader names the file and the line of a problem, and refuses what could hang or exhaust
memory before it does: files over a size limit, YAML aliases that expand beyond a small budget,
nesting too deep, duplicate keys (YAML's "last one wins" silently drops the first), numbers
beyond float64, NUL bytes and cells too long to be an answer.

>>> import tempfile, pathlib
>>> folder = pathlib.Path(tempfile.mkdtemp())
>>> _ = (folder / "a.yaml").write_text("h: 1e308\\nlist: [1, 2]\\n")
>>> read_yaml(folder / "a.yaml")
{'h': 1e+308, 'list': [1, 2]}
>>> _ = (folder / "b.yaml").write_text("h: 1\\nh: 2\\n")
>>> read_yaml(folder / "b.yaml")
Traceback (most recent call last):
...
grader.base.errors.GraderError: ...b.yaml: line 2: the key 'h' appears twice (expected each key once)

YAML is read by :mod:`grader.base.yaml_loader`, and what a file's bytes read as is remembered on disk (see
:func:`parse_yaml`): a second run with the same bytes imports no PyYAML.
"""

from __future__ import annotations

import codecs
import hashlib
import io
import itertools
import math
import os
import re
import stat
import sys
from collections import Counter
from collections.abc import Iterator
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path
from typing import Any, NamedTuple

from grader.base import caching
from grader.base.errors import GraderError

YAML_BYTES = 1 << 20  # 1 MiB: a template or an assignment is a few kB
CSV_BYTES = 64 << 20  # 64 MiB: 100,000 rows of 50 cells
CELL_CHARS = 1000  # no answer, id or parameter value is longer


def regular_size(path: Path) -> int:
    """The size of ``path`` if it is a regular file; 0 for another kind of file or one that cannot be read (its
    reader then says why), whose size is not known before it is read.

    >>> regular_size(Path("/dev/null")), regular_size(Path("no such file"))
    (0, 0)
    """
    try:
        return path.stat().st_size if path.is_file() else 0
    except OSError:
        return 0


def read_bytes(path: Path, limit: int) -> bytes:
    """A file's bytes, refused beyond ``limit`` (read no further: ``/dev/zero`` is a file too; a
    regular file's size is known, so a 2 GB file is refused before any of it is read). Memory is taken for
    what the file holds, not for ``limit``: ``read(n)`` asks for ``n`` bytes at once, 1 GiB for a key of a
    few kB, which a memory limit (``ulimit -v``) refuses."""
    try:
        with open(path, "rb") as stream:
            status = os.fstat(stream.fileno())
            regular = stat.S_ISREG(status.st_mode)
            too_large = regular and status.st_size > limit
            chunk = status.st_size + 1 if regular else 1 << 20
            data = b"" if too_large else caching.read_at_most(stream, limit + 1, chunk)
    except OSError as error:
        raise GraderError(f"{path}: cannot read ({error.strerror or error})") from None
    if too_large or len(data) > limit:
        raise GraderError(f"{path}: larger than {limit >> 20 or 1} MiB; expected a text file of ordinary size")
    return data


def read_input(path: Path, limit: int) -> bytes | None:
    """:func:`read_bytes` of ``path``, or, when ``path`` is ``-``, standard input's bytes within the same bound
    (read 1 MiB at a time: its size is not known); None when standard input is closed (``<&-``)."""
    if str(path) != "-":
        return read_bytes(path, limit)
    if sys.stdin is None:
        return None
    data = caching.read_at_most(sys.stdin.buffer, limit + 1, 1 << 20)
    if len(data) > limit:
        raise GraderError(f"standard input: more than {limit:,} bytes; split the batch")
    return data


def decode_text(data: bytes, path: Path) -> str:
    """UTF-8 text (a byte-order mark is dropped); NUL bytes are refused as binary data."""
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as error:
        line = data[:error.start].count(b"\n") + 1
        raise GraderError(f"{path}: line {line}: expected UTF-8 text, got the byte 0x{data[error.start]:02x} "
                          "(save the file as UTF-8)") from None
    _refuse_nul(text, path)
    return text


def _refuse_nul(text: str, path: Path) -> None:
    """A NUL character is binary data, in whatever encoding."""
    if "\0" in text:
        line = text[:text.index("\0")].count("\n") + 1
        raise GraderError(f"{path}: line {line}: expected text, got a NUL byte (is this a binary file?)")


def decode_export(data: bytes, path: Path) -> tuple[str, str]:
    """Text as spreadsheets and LMSs export it, and the encoding it was read in: UTF-8 (with or
    without a byte-order mark), UTF-16 with a byte-order mark (Excel's "Unicode text"), or else a
    clean Windows-1252/Latin-1 file (no control characters, no UTF-8 sequences: not a mix). Anything
    else is refused with the byte offset of the first byte that is not UTF-8.

    >>> decode_export("Zoë".encode("utf-16"), Path("a.txt"))
    ('Zoë', 'UTF-16')
    >>> decode_export("Zoë".encode("cp1252"), Path("a.csv"))
    ('Zoë', 'Windows-1252')
    >>> decode_export(b"id\\n\\x89PNG\\x00", Path("a.csv"))
    Traceback (most recent call last):
    ...
    grader.base.errors.GraderError: a.csv: byte offset 3 (line 2): expected UTF-8 or UTF-16 text, got the byte 0x89 ...
    """
    unmarked = _utf16_without_bom(data)
    if unmarked:
        raise GraderError(f"{path}: {unmarked} text without a byte-order mark; expected UTF-8, or UTF-16 that starts "
                          'with its byte-order mark (save the file as "CSV UTF-8")')
    if data.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)):
        try:
            text, encoding = data.decode("utf-16"), "UTF-16"
        except UnicodeDecodeError as error:
            raise GraderError(f"{path}: byte offset {error.start}: expected UTF-16 text after the UTF-16 byte-order "
                              f"mark, got {error.reason}") from None
    else:
        bom = len(codecs.BOM_UTF8) if data.startswith(codecs.BOM_UTF8) else 0
        try:
            text, encoding = data[bom:].decode("utf-8"), "UTF-8"
        except UnicodeDecodeError as error:
            legacy = _clean_cp1252(data)
            if legacy is None:
                offset = bom + error.start
                line = data[:offset].count(b"\n") + 1
                raise GraderError(f"{path}: byte offset {offset} (line {line}): expected "
                                  f"UTF-8 or UTF-16 text, got the byte 0x{data[offset]:02x} (save the file as "
                                  '"CSV UTF-8")') from None
            text, encoding = legacy, "Windows-1252"
    _refuse_nul(text, path)
    return text, encoding


def _utf16_without_bom(data: bytes) -> str | None:
    """``"UTF-16LE"`` or ``"UTF-16BE"`` when ``data`` looks like UTF-16 saved without its byte-order mark
    (read as UTF-8 it would fail far into the file, or look binary): among its first characters, NUL
    bytes on one side of at least half of them (the high byte of ASCII text) and never on the other.

    >>> _utf16_without_bom("id,1a".encode("utf-16-le")), _utf16_without_bom("id,1a".encode("utf-16"))
    ('UTF-16LE', None)
    """
    if data.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)) or b"\0" not in data[:1024]:
        return None
    sample = data[:min(len(data), 1024) // 2 * 2]
    pairs, even, odd = len(sample) // 2, sample[0::2].count(0), sample[1::2].count(0)
    if odd * 2 >= pairs and not even:
        return "UTF-16LE"
    if even * 2 >= pairs and not odd:
        return "UTF-16BE"
    return None


_UTF8_SEQUENCE = re.compile(rb"[\xc2-\xdf][\x80-\xbf]|[\xe0-\xef][\x80-\xbf]{2}|[\xf0-\xf4][\x80-\xbf]{3}")
_CONTROL = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\x7f]")


def _clean_cp1252(data: bytes) -> str | None:
    """``data`` as Windows-1252 when it reads as such throughout: no bytes it leaves undefined, no
    control characters (binary data), and no UTF-8 sequences (a UTF-8 file with one stray byte would
    otherwise turn every ``é`` into ``Ã©``)."""
    if _UTF8_SEQUENCE.search(data):
        return None
    try:
        text = data.decode("cp1252")
    except UnicodeDecodeError:
        return None
    return None if _CONTROL.search(text) else text


# --- YAML ---------------------------------------------------------------------------------------

YAML_SOURCES = ("base/inputs.py", "base/yaml_loader.py")
"""The source of what a YAML file reads as (with grader's version, Python's and the installed PyYAML)."""


def read_yaml(path: Path) -> Any:
    """A YAML file's data, with the bounds of :mod:`grader.base.yaml_loader`; errors name the file and the line."""
    return parse_yaml(read_bytes(path, YAML_BYTES), path)


def parse_yaml(data: bytes, path: Path) -> Any:
    """YAML data read from ``path`` (for messages), with the bounds of :mod:`grader.base.yaml_loader`.

    What the bytes read as is kept in the cache folder (:mod:`grader.base.caching`), keyed by their SHA-256 and
    by :data:`YAML_SOURCES`: the same bytes again are read back from JSON, without PyYAML. Only data JSON
    gives back exactly is kept (:func:`plain_data`: all a template or an assignment holds), and only such data
    is read back; a file that is refused is read, and refused with its message, every time.
    """
    entry = caching.entry(f"yaml-{_yaml_key(data)}.json")
    stored = caching.read_entry(entry)
    if isinstance(stored, dict) and set(stored) == {"data"} and plain_data(stored["data"]):  # JSON has NaN
        return stored["data"]
    from grader.base.yaml_loader import load_yaml

    raw = load_yaml(decode_text(data, path), path)
    if plain_data(raw):
        caching.write_entry(entry, {"data": raw})
    return raw


def plain_data(data: Any) -> bool:
    """Whether JSON gives ``data`` back exactly: mappings with text keys, lists, text, whole numbers,
    finite floats, booleans and None, no container twice (YAML's aliases share one, JSON would copy it).

    >>> plain_data({"h": [1, 2.5, -0.0, True, None, "x"]}), plain_data({"h": (1,)}), plain_data({1: 2})
    (True, False, False)
    >>> shared = [1]
    >>> plain_data({"a": shared, "b": shared}), plain_data({"h": float("inf")})
    (False, False)
    """
    seen: set[int] = set()
    todo = [data]
    while todo:
        value = todo.pop()
        kind = type(value)
        if kind is dict or kind is list:
            if id(value) in seen or (kind is dict and not all(type(key) is str for key in value)):
                return False
            seen.add(id(value))
            todo.extend(value.values() if kind is dict else value)
        elif kind is float:
            if not math.isfinite(value):
                return False
        elif kind not in (str, int, bool, type(None)):
            return False
    return True


def _yaml_key(data: bytes) -> str:
    return hashlib.sha256(_yaml_reader().encode() + data).hexdigest()[:32]


@lru_cache(maxsize=1)
def _yaml_reader() -> str:
    return caching.source_fingerprint(caching.PACKAGE, YAML_SOURCES, "yaml 1", ("yaml",))


# --- CSV ----------------------------------------------------------------------------------------

class CsvRow(NamedTuple):
    """One data row: the line it starts on, its cells by header name (stripped), and what is wrong
    with the row as a whole (more cells than columns), for the caller to refuse the row or the file.
    (A named tuple: made ten million times for a big file, a frozen dataclass took a second a million.)"""

    line: int
    cells: dict[str, str]
    problem: str | None = None


@dataclass(frozen=True)
class CsvTable:
    """A CSV file: its header (stripped, as written) and its non-blank data rows; the delimiter and
    the encoding it was read with."""

    path: Path
    header: tuple[str, ...]
    rows: tuple[CsvRow, ...]
    header_line: int
    delimiter: str = ","
    encoding: str = "UTF-8"


@dataclass(frozen=True)
class CsvStream:
    """A CSV file whose header is read and whose data rows are read as :meth:`rows` is iterated (from the
    start on each call): a file of ten million short rows costs its text, not an object per row."""

    path: Path
    header: tuple[str, ...]
    header_line: int
    delimiter: str
    encoding: str
    exports: bool
    text: str = field(repr=False)  # from the header's line on
    skipped: int = 0  # blank lines before the header's

    def records(self) -> Iterator[tuple[int, list[str]]]:
        """The non-blank data rows as the csv module reads them: the line each starts on and its cells, as
        they are (not stripped, nor measured: :meth:`rows` does that)."""
        records = _records(_lines(self.text), self.path, self.delimiter, self.skipped)
        next(records)  # the header
        return records

    def rows(self) -> Iterator[CsvRow]:
        """The non-blank data rows, as :func:`read_csv` describes them."""
        header, width = self.header, len(self.header)
        for line, cells in self.records():
            problem = None
            longest = max(map(len, cells))
            if longest > CELL_CHARS:
                if not self.exports:
                    _check_cell_lengths(cells, self.path, line)
                problem = f"line {line}: a cell of {longest:,} characters; expected at most {CELL_CHARS}"
            problem = _width_problem(cells, width, line) or problem
            if len(cells) != width:  # cells beyond the header's are dropped, missing ones are empty
                cells = (cells + [""] * width)[:width]
            yield CsvRow(line, dict(zip(header, map(str.strip, cells), strict=True)), problem)


def read_csv(path: Path, *, exports: bool = False) -> CsvTable:
    """A CSV file: UTF-8 with or without a byte-order mark; comma, semicolon or tab, whichever the
    header uses most outside quotes. Blank lines are skipped (before the header too); a row's line is where it
    starts, so a quoted cell over several lines does not shift the numbers. Refused, naming the
    line: duplicate or missing header names (an empty column at the end is dropped), unclosed
    quotes, cells longer than ``CELL_CHARS``, NUL bytes, files over ``CSV_BYTES``. A row with more
    cells than columns carries its ``problem``.

    ``exports=True`` reads files as LMSs and spreadsheets export them, where one bad row must not
    cost the others: the encodings of :func:`decode_export`, and a data row with a cell longer than
    ``CELL_CHARS`` carries its ``problem`` instead of refusing the file (a 10 MB cell too).

    >>> import tempfile, pathlib
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "b.csv"
    >>> _ = path.write_text('\\nh_drop;h_rebound;\\n2100;1100;\\n\\n"2,0";1\\n')
    >>> table = read_csv(path)
    >>> table.header, [(row.line, row.cells) for row in table.rows]
    (('h_drop', 'h_rebound'), [(3, {'h_drop': '2100', 'h_rebound': '1100'}), (5, {'h_drop': '2,0', 'h_rebound': '1'})])
    """
    stream = open_csv(path, exports=exports)
    return CsvTable(path, stream.header, tuple(stream.rows()), stream.header_line, stream.delimiter,
                    stream.encoding)


def open_csv(path: Path, *, exports: bool = False) -> CsvStream:
    """A CSV file as :func:`read_csv` reads it, its header read and its rows to come (:meth:`CsvStream.rows`)."""
    head, _ = _open_csv(path, exports)
    return head


@dataclass(frozen=True)
class CsvColumns:
    """A CSV file read column by column (for many rows of few columns): each column's cells (stripped)
    by header name, each data row's line, and what is wrong with a row as a whole (see ``CsvRow``)."""

    path: Path
    header: tuple[str, ...]
    columns: dict[str, list[str]]
    lines: list[int]
    problems: list[str | None]


def read_csv_columns(path: Path) -> CsvColumns:
    """A CSV file as :func:`read_csv` reads it (``exports=False``), as columns: no object per row.

    >>> import tempfile, pathlib
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "c.csv"
    >>> _ = path.write_text('h_drop,h_rebound\\n2100, 1100\\n\\n2000\\n1,2,3\\n')
    >>> table = read_csv_columns(path)
    >>> table.columns, table.lines
    ({'h_drop': ['2100', '2000', '1'], 'h_rebound': ['1100', '', '2']}, [2, 4, 5])
    >>> table.problems
    [None, None, 'line 5: 3 cells, but the header has 2 columns; expected one cell per column']
    """
    head, records = _open_csv(path, False)
    width = len(head.header)
    lines, grid = [], []
    try:
        for line, cells in records:
            lines.append(line)
            grid.append(cells)
    except GraderError:
        _check_every_cell_length(grid, lines, path)  # a long cell before the line that cannot be read comes first
        raise
    _check_every_cell_length(grid, lines, path)
    problems: list[str | None] = [None] * len(grid)
    if set(map(len, grid)) != {width}:  # a row with fewer cells than the header, or more
        for row, cells in enumerate(grid):
            problems[row] = _width_problem(cells, width, lines[row])
            grid[row] = cells[:width] + [""] * (width - len(cells))
    columns = zip(*grid, strict=True) if grid else iter([()] * width)
    return CsvColumns(path, head.header, {name: list(map(str.strip, column))
                                          for name, column in zip(head.header, columns, strict=True)},
                      lines, problems)


def _check_every_cell_length(grid: list[list[str]], lines: list[int], path: Path) -> None:
    """Refuse the first row (in file order) with a cell longer than ``CELL_CHARS``, as read_csv does."""
    if grid and max(map(len, itertools.chain.from_iterable(grid))) > CELL_CHARS:
        for line, cells in zip(lines, grid, strict=True):
            _check_cell_lengths(cells, path, line)


def _open_csv(path: Path, exports: bool) -> tuple[CsvStream, Iterator[tuple[int, list[str]]]]:
    """The file, its header read, and its non-blank data rows to come: ``(line, cells)``."""
    data = read_bytes(path, CSV_BYTES)
    text, encoding = decode_export(data, path) if exports else (decode_text(data, path), "UTF-8")
    del data  # a file's bytes beside its text would double what it costs
    text = _unified(text)
    text_starts = len(text) - len(text.lstrip())  # on the first line that is not blank
    if text_starts == len(text):
        raise GraderError(f"{path}: empty file; expected a header line")
    first = text.count("\n", 0, text_starts)
    start = text.rfind("\n", 0, text_starts) + 1
    end = text.find("\n", text_starts)
    header_text = text[start:] if end < 0 else text[start:end]
    delimiter = max(",;\t", key=lambda candidate: _count_outside_quotes(header_text, candidate))
    if start:
        text = text[start:]
    records = _records(_lines(text), path, delimiter, first)
    first_record = next(records, None)
    if first_record is None:  # only quotes or delimiters: no cell has text
        raise GraderError(f"{path}: no header line with text; expected a header line")
    header_line, header_cells = first_record
    _check_cell_lengths(header_cells, path, header_line)
    return CsvStream(path, _header(header_cells, path, header_line), header_line, delimiter, encoding, exports, text,
                     first), records


def _lines(text: str, piece: int = 1 << 20) -> Iterator[str]:
    """The lines of ``text`` (split at ``\\n`` only, as ``io.StringIO`` splits them), read through a
    ``StringIO`` of about ``piece`` characters at a time: one of the whole text would take four bytes a
    character beside it."""
    return itertools.chain.from_iterable(map(io.StringIO, _pieces(text, piece)))


def _pieces(text: str, piece: int) -> Iterator[str]:
    start = 0
    while start < len(text):
        end = text.find("\n", start + piece)
        end = len(text) if end < 0 else end + 1
        yield text[start:end]
        start = end


def _width_problem(cells: list[str], width: int, line: int) -> str | None:
    if len(cells) > width and any(c.strip() for c in cells[width:]):
        return (f"line {line}: {len(cells)} cells, but the header has {width} column"
                f"{'s' if width > 1 else ''}; expected one cell per column")
    return None


def _unified(text: str) -> str:
    r"""Text as the ``csv`` module reads it: a lone CR (Excel for Mac's "CSV (Macintosh)", or a file with
    mixed line ends) is a line end, and a byte-order mark after the start (two exports pasted together)
    is dropped rather than stuck to the cell it precedes.

    >>> _unified("id,1a\r456,1\r\n\ufeff789,2\n")
    'id,1a\n456,1\r\n789,2\n'
    """
    if "\ufeff" in text:
        text = text.replace("\ufeff", "")
    return _LONE_CR.sub("\n", text) if "\r" in text else text


_LONE_CR = re.compile(r"\r(?!\n)")


def _count_outside_quotes(line: str, delimiter: str) -> int:
    """How often ``delimiter`` separates cells of ``line`` (a quoted ``"1a, speed"`` is one cell)."""
    return sum(part.count(delimiter) for part in line.split('"')[::2])


def _check_cell_lengths(cells: list[str], path: Path, line: int) -> None:
    if cells and max(map(len, cells)) <= CELL_CHARS:
        return
    long = next((c for c in cells if len(c) > CELL_CHARS), None)
    if long is not None:
        raise GraderError(f"{path}: line {line}: a cell of {len(long):,} characters; expected at most {CELL_CHARS}")


def _records(stream: Iterator[str], path: Path, delimiter: str, offset: int) -> Iterator[tuple[int, list[str]]]:
    """The non-blank records of the text and the line each starts on; an error names the line of the
    record it is in (where a quote left open begins, not the end of the file it ran to)."""
    import csv  # here: `grader solve --set` and `grader list` read no CSV

    # The csv module's own limit (131,072 characters a cell) would refuse a whole export for one pasted
    # essay; cells are measured by the caller instead, so the limit is the largest file's.
    csv.field_size_limit(max(csv.field_size_limit(), CSV_BYTES))
    reader = csv.reader(stream, delimiter=delimiter, strict=True)  # an unclosed quote is an error, not a cell
    end = 0
    try:
        for cells in reader:
            start, end = end + 1, reader.line_num
            if "".join(cells).strip():  # a row with a cell of text
                yield offset + start, cells
    except csv.Error as error:  # the record that fails starts after the last one read
        raise GraderError(f"{path}: line {offset + end + 1}: {error} (check the quotes); expected CSV") from None


def _header(cells: list[str], path: Path, line: int) -> tuple[str, ...]:
    names = [cell.strip() for cell in cells]
    while names and not names[-1]:
        names.pop()  # a trailing delimiter, as spreadsheets write
    if "" in names:
        raise GraderError(f"{path}: line {line}: column {names.index('') + 1} has no name; expected a name "
                          "for every column of the header")
    counts = Counter(n.lower() for n in names)
    twice = sorted({n for n in names if counts[n.lower()] > 1})[:10]
    if twice:
        raise GraderError(f"{path}: line {line}: the column {', '.join(map(repr, twice))} appears twice; "
                          "expected each column once")
    return tuple(names)
