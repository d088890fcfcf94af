"""Joining the PDFs Typst wrote into one file, a part at a time, so memory does not grow with the class.

pypdf's ``PdfWriter`` holds every object of every part until it writes: about ten times the file
(450 MiB for a class file of 1,000 sheets). Typst writes plain PDF 1.7: numbered objects and a
classic cross-reference table, no object streams. So each part is read on its own, the objects
its pages and bookmarks use (content, fonts, images, outline entries; not its tagged structure,
which describes that document alone) are copied as bytes with their references renumbered, and
the part is let go. What stays in memory is an offset per object written.

Each part's bookmarks follow the previous part's at the top level of the joined outline. A page may
be stamped with a page of another PDF drawn over it (the answer key's page numbers, which no part
knows: each page's own content and the stamp become two form XObjects the page draws in turn).

>>> _text_string("Ana (TA)"), _text_string("李华")
(b'(Ana \\\\(TA\\\\))', b'<FEFF674E534E>')
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import BinaryIO

_DELIMITER = rb"\s()<>\[\]{}/%"
# What the copier must see in an object's dictionary: a reference, a literal string (which may
# hold anything), a name, the start of stream data, a comment. Everything else is copied as is.
_TOKEN = re.compile(
    rb"(?<![\w.+-])(\d+)\s+(\d+)\s+R(?![^" + _DELIMITER + rb"])"  # 1: a reference
    rb"|(\()"  # 3: a literal string
    rb"|(/[^" + _DELIMITER + rb"]*)"  # 4: a name
    rb"|(?<![^" + _DELIMITER + rb"])(stream)(?:\r\n|\n|\r)"  # 5: stream data follows
    rb"|%[^\r\n]*")
_STRING_PART = re.compile(rb"\\.|[()]", re.DOTALL)
_INTEGER = re.compile(rb"\s*[+-]?\d+")
_OBJECT_HEAD = re.compile(rb"\s*(\d+)\s+(\d+)\s+obj\b")
_KIDS = re.compile(rb"/Kids\s*\[([^\]]*)\]")
_REFS = re.compile(rb"(\d+)\s+\d+\s+R")
_INHERITED = re.compile(rb"/(?:Resources|MediaBox|CropBox|Rotate)\b")
_DROPPED = (b"/StructParents", b"/StructParent")  # keys into the part's own structure tree


class PdfFormatError(ValueError):
    """A part is not a PDF as Typst writes it (a bug: parts come only from Typst)."""


@dataclass(frozen=True)
class Part:
    """A PDF to join, read once for what the join and a table of contents need: its page count
    and the page (from 0) each of its top-level bookmarks points to."""

    path: Path
    pages: int
    bookmarks: tuple[int, ...] = ()


def read_part(path: Path) -> Part:
    """A PDF Typst wrote, with its page count and where its top-level bookmarks point."""
    source = _Source(path)
    index = {number: page for page, number in enumerate(source.pages)}
    return Part(path, len(source.pages), tuple(index[source.destination(item)] for item in source.top_bookmarks()))


def join(parts: Sequence[Part], target: Path, *, title: str = "", author: str = "", lang: str = "",
         stamps: Part | None = None) -> None:
    """Write ``parts`` in order as one PDF at ``target``, with their bookmarks and the given
    title, author and language; with ``stamps`` (a PDF of as many pages as the parts together),
    each page with the stamp's page of the same number drawn over it. Nothing in it depends on
    when it was made: the same parts give the same bytes."""
    with target.open("wb") as stream:
        _Joiner(stream, parts, stamps).write(title, author, lang)


_MARK_INFO = re.compile(rb"/Suspects\s*false")


def without_false_suspects(data: bytes) -> bytes:
    """A PDF as Typst writes it, without the ``/Suspects false`` of its catalog's mark information
    (blanked, so every offset stays): false is the default, and poppler (``pdfinfo``, 22.x) warns
    "Suspects object is wrong type (boolean)" at any Suspects entry that is not true.

    >>> without_false_suspects(b"<</MarkInfo<</Marked true/Suspects false>>>>")
    b'<</MarkInfo<</Marked true               >>>>'
    """
    at = data.find(b"/MarkInfo")
    found = _MARK_INFO.search(data, at, data.find(b">>", at) + 2) if at >= 0 else None
    if found is None:
        return data
    return data[:found.start()] + b" " * (found.end() - found.start()) + data[found.end():]


# --- reading a part -----------------------------------------------------------------------------

class _Source:
    """A part's bytes, where each object is, its page objects in order, its outline."""

    def __init__(self, path: Path) -> None:
        self.path, self.data = path, path.read_bytes()
        try:
            start = int(self.data[self.data.rindex(b"startxref") + 9:].split()[0])
            trailer_at = self.data.index(b"trailer", start)
        except ValueError:
            raise PdfFormatError(f"{path}: no cross-reference table") from None
        self.offsets = self._xref(start, trailer_at)
        ends = sorted({*self.offsets.values(), start})
        self.ends = {offset: ends[i + 1] for i, offset in enumerate(ends[:-1])}
        catalog = self.body(self.ref(b"/Root", _masked(self.data[trailer_at:])))
        self.pages: list[int] = []
        self._collect(self.ref(b"/Pages", catalog))
        outlines = _find_ref(b"/Outlines", catalog)
        self.outline = None if outlines is None else _masked(self.body(outlines))

    def _xref(self, start: int, end: int) -> dict[int, int]:
        if not self.data.startswith(b"xref", start):
            raise PdfFormatError(f"{self.path}: expected a classic cross-reference table (as Typst writes)")
        lines = iter(self.data[start + 4:end].split(b"\n"))
        offsets = {}
        for line in lines:
            head = line.split()
            if len(head) == 2:  # a subsection: first number, count
                for number in range(int(head[0]), int(head[0]) + int(head[1])):
                    entry = next(lines).split()
                    if entry[2] == b"n":
                        offsets[number] = int(entry[0])
        return offsets

    def body(self, number: int) -> bytes:
        """An object's text between ``N G obj`` and ``endobj``."""
        offset = self.offsets[number]
        text = self.data[offset:self.ends[offset]]
        head = _OBJECT_HEAD.match(text)
        end = text.rfind(b"endobj")
        if head is None or end < 0:
            raise PdfFormatError(f"{self.path}: object {number} is not where the cross-reference table says")
        return text[head.end():end]

    def ref(self, key: bytes, text: bytes) -> int:
        """The object number of ``key``'s value in a dictionary's (masked) text."""
        found = _find_ref(key, text)
        if found is None:
            raise PdfFormatError(f"{self.path}: no {key.decode()}")
        return found

    def _collect(self, number: int) -> None:
        node = _masked(self.body(number))
        kids = _KIDS.search(node)
        if kids is None:
            self.pages.append(number)
            return
        if _INHERITED.search(node[:kids.start()] + node[kids.end():]):
            raise PdfFormatError(f"{self.path}: pages inherit attributes from the page tree")
        for kid in _REFS.finditer(kids.group(1)):
            self._collect(int(kid.group(1)))

    def top_bookmarks(self) -> list[int]:
        """The object numbers of the outline's top-level entries, in order."""
        items, item = [], None if self.outline is None else _find_ref(b"/First", self.outline)
        while item is not None:
            items.append(item)
            item = _find_ref(b"/Next", _masked(self.body(item)))
        return items

    def destination(self, item: int) -> int:
        """The page object a bookmark points to."""
        found = re.search(rb"/Dest\s*(\[)?\s*(\d+)\s+\d+\s+R", _masked(self.body(item)))
        if found is None:
            raise PdfFormatError(f"{self.path}: bookmark {item} has no destination")
        if found.group(1):
            return int(found.group(2))
        array = _REFS.search(_masked(self.body(int(found.group(2)))))  # [page /XYZ left top zoom]
        if array is None:
            raise PdfFormatError(f"{self.path}: bookmark {item} has no destination")
        return int(array.group(1))


def _find_ref(key: bytes, text: bytes) -> int | None:
    found = re.search(re.escape(key) + rb"\s*(\d+)\s+\d+\s+R", text)
    return int(found.group(1)) if found else None


def _masked(text: bytes) -> bytes:
    """``text`` with the inside of each literal string blanked (same length): what a search for
    keys must not look into (a student named ``/Next 3 0 R`` is a string)."""
    out, position = [], 0
    while (start := text.find(b"(", position)) >= 0:
        end = _string_end(text, start + 1)
        out += [text[position:start + 1], b" " * (end - start - 2), b")"]
        position = end
    out.append(text[position:])
    return b"".join(out)


def _string_end(data: bytes, position: int) -> int:
    """Where the literal string whose ``(`` ends at ``position`` ends (nested, escaped parentheses)."""
    depth = 1
    for found in _STRING_PART.finditer(data, position):
        if found.group() == b"(":
            depth += 1
        elif found.group() == b")":
            depth -= 1
            if depth == 0:
                return found.end()
    raise PdfFormatError("a string that does not end")


# --- writing the joined file --------------------------------------------------------------------

class _Joiner:
    """Writes the parts' pages and bookmarks with what they use, then the page tree, the outline,
    the catalog and the document information."""

    CATALOG, PAGES, OUTLINES, FIRST = 1, 2, 3, 4

    def __init__(self, stream: BinaryIO, parts: Sequence[Part], stamps: Part | None = None) -> None:
        self.stream, self.parts = stream, parts
        self.offsets: dict[int, int] = {}
        total = sum(part.pages for part in parts)
        self.page_numbers = list(range(self.FIRST, self.FIRST + total))
        self.next = self.FIRST + total
        self.bookmarks = 0  # the outline's visible entries
        self.first_bookmark: int | None = None
        self.last_bookmark: int | None = None
        self.next_bookmark: int | None = None  # the number the next part's first bookmark takes
        self.stamps = None if stamps is None else _Source(stamps.path)
        if self.stamps is not None and len(self.stamps.pages) != total:
            raise PdfFormatError(f"{self.stamps.path}: {len(self.stamps.pages)} pages of stamps for {total} pages")
        self.stamp_numbers: dict[int, int] = {}  # the stamps' objects written, by their number there

    def write(self, title: str, author: str, lang: str) -> None:
        self.stream.write(b"%PDF-1.7\n%\x80\x80\x80\x80\n")
        first_page = 0
        for index, part in enumerate(self.parts):
            later = any(p.bookmarks for p in self.parts[index + 1:])
            self._copy(_Source(part.path), first_page, later)
            first_page += part.pages
        kids = b" ".join(b"%d 0 R" % n for n in self.page_numbers)
        self._object(self.PAGES, b"<</Type/Pages/Count %d/Kids[%s]>>" % (len(self.page_numbers), kids))
        catalog = b"<</Type/Catalog/Pages %d 0 R" % self.PAGES
        if self.first_bookmark is not None:
            catalog += b"/Outlines %d 0 R" % self.OUTLINES
        catalog += b"/Lang" + _text_string(lang) if lang else b""
        catalog += b"/ViewerPreferences<</DisplayDocTitle true>>" if title else b""
        self._object(self.CATALOG, catalog + b">>")
        info = self._new()
        self._object(info, b"<<" + b"".join(b"/%s%s" % (key, _text_string(value)) for key, value in
                                             ((b"Title", title), (b"Author", author)) if value) + b">>")
        self._finish(info)

    def _new(self) -> int:
        self.next += 1
        return self.next - 1

    def _object(self, number: int, body: bytes) -> None:
        self.offsets[number] = self.stream.tell()
        self.stream.write(b"%d 0 obj\n%s\nendobj\n" % (number, body))

    def _copy(self, source: _Source, first_page: int, more_bookmarks_later: bool) -> None:
        """Copy a part's pages, its bookmarks and every object they reach, renumbered."""
        numbers = {old: self.page_numbers[first_page + i] for i, old in enumerate(source.pages)}
        parents = dict.fromkeys(source.pages, self.PAGES)
        added: dict[int, bytes] = {}
        top = source.top_bookmarks()
        if top:
            numbers[top[0]] = self.next_bookmark or self._new()
            parents.update(dict.fromkeys(top, self.OUTLINES))
            if self.last_bookmark is not None:
                added[top[0]] = b"/Prev %d 0 R" % self.last_bookmark
            if more_bookmarks_later:
                self.next_bookmark = self._new()
                added[top[-1]] = added.get(top[-1], b"") + b"/Next %d 0 R" % self.next_bookmark
            count = re.search(rb"/Count\s*(\d+)", source.outline or b"")
            self.bookmarks += int(count.group(1)) if count else len(top)
        pending = [*top[::-1], *source.pages[::-1]]
        forms: dict[int, bytes] = {}
        done: set[int] = set()
        while pending:
            old = pending.pop()
            if old in done:
                continue
            done.add(old)
            body = self._renumbered(source.body(old), numbers, pending, parents.get(old))
            if old in added:
                body = body[:body.rindex(b">>")] + added[old] + b">>"
            if old in forms:  # a page's content, drawn as a form
                body = body.replace(b"<<", b"<<" + forms[old], 1)
            if self.stamps is not None and old in parents and parents[old] == self.PAGES:
                body = self._stamped(source, old, body, first_page + source.pages.index(old), numbers, pending, forms)
            self._object(numbers[old], body.strip())
        if top:
            self.first_bookmark = self.first_bookmark or numbers[top[0]]
            self.last_bookmark = numbers[top[-1]]

    def _stamped(self, source: _Source, page: int, body: bytes, position: int, numbers: dict[int, int],
                 pending: list[int], forms: dict[int, bytes]) -> bytes:
        """A page's (renumbered) dictionary drawing its content, then the stamp of its position; its
        content and resources become a form's (``forms``, written as the content is copied)."""
        content, resources = (source.ref(key, _masked(source.body(page))) for key in (b"/Contents", b"/Resources"))
        box = re.search(rb"/MediaBox\s*\[([^\]]*)\]", body)
        if box is None:
            raise PdfFormatError(f"{source.path}: page {page} has no media box")
        if resources not in numbers:
            numbers[resources] = self._new()
            pending.append(resources)
        forms[content] = b"/Type/XObject/Subtype/Form/BBox[%s]/Resources %d 0 R" % (box.group(1), numbers[resources])
        stamp = self._stamp(position, box.group(1))
        drawn = self._new()
        draw = b"/Page Do /Stamp Do"
        self._object(drawn, b"<</Length %d>>\nstream\n%s\nendstream" % (len(draw), draw))
        body = re.sub(rb"/Contents\s*\d+\s+\d+\s+R", b"/Contents %d 0 R" % drawn, body, count=1)
        return re.sub(rb"/Resources\s*\d+\s+\d+\s+R", b"/Resources<</XObject<</Page %d 0 R/Stamp %d 0 R>>>>"
                      % (numbers[content], stamp), body, count=1)

    def _stamp(self, position: int, box: bytes) -> int:
        """Write the stamps' page ``position`` as a form (with what it uses, once); returns its number."""
        assert self.stamps is not None
        source, numbers = self.stamps, self.stamp_numbers
        page = _masked(source.body(source.pages[position]))
        content, resources = source.ref(b"/Contents", page), source.ref(b"/Resources", page)
        pending = [resources]
        for old in (content, resources):
            if old not in numbers:
                numbers[old] = self._new()
        while pending:
            old = pending.pop()
            self._object(numbers[old], self._renumbered(source.body(old), numbers, pending, None).strip())
        body = self._renumbered(source.body(content), numbers, pending, None).strip()
        self._object(numbers[content], body.replace(b"<<", b"<</Type/XObject/Subtype/Form/BBox[%s]/Resources %d 0 R"
                                                    % (box, numbers[resources]), 1))
        for old in pending:  # a content stream refers to nothing, but were it to, it is written too
            raise PdfFormatError(f"{source.path}: a page's content refers to object {old}")
        return numbers[content]

    def _renumbered(self, body: bytes, numbers: dict[int, int], pending: list[int], parent: int | None) -> bytes:
        """An object's text with its references renumbered (new objects queued to copy), its
        ``/Parent`` replaced by ``parent`` when given, and the keys into the structure tree dropped."""
        out, position, name = [], 0, b""
        while (token := _TOKEN.search(body, position)) is not None:
            out.append(body[position:token.start()])
            position = token.end()
            if token.group(1) is not None:
                if parent is not None and name == b"/Parent":
                    out.append(b"%d 0 R" % parent)
                else:
                    old = int(token.group(1))
                    if old not in numbers:
                        numbers[old] = self._new()
                        pending.append(old)
                    out.append(b"%d 0 R" % numbers[old])
            elif token.group(3) is not None:
                position = _string_end(body, position)
                out.append(body[token.start():position])
            elif token.group(4) is not None:
                name = token.group(4)
                if name in _DROPPED:
                    value = _INTEGER.match(body, position)
                    position = value.end() if value else position
                else:
                    out.append(name)
                continue
            elif token.group(5) is not None:
                out.append(body[token.start():])  # the stream data, copied as it is
                return b"".join(out)
            else:
                out.append(token.group(0))
            name = b""
        out.append(body[position:])
        return b"".join(out)

    def _finish(self, info: int) -> None:
        if self.first_bookmark is not None and self.last_bookmark is not None:
            self._object(self.OUTLINES, b"<</Type/Outlines/First %d 0 R/Last %d 0 R/Count %d>>"
                         % (self.first_bookmark, self.last_bookmark, self.bookmarks))
        start = self.stream.tell()
        lines = [b"xref\n0 %d\n0000000000 65535 f \n" % self.next]
        lines += [b"%010d 00000 n \n" % self.offsets[n] if n in self.offsets else b"0000000000 65535 f \n"
                  for n in range(1, self.next)]  # the outline's number is free in a file without bookmarks
        self.stream.write(b"".join(lines))
        self.stream.write(b"trailer\n<</Size %d/Root %d 0 R/Info %d 0 R>>\nstartxref\n%d\n%%%%EOF\n"
                          % (self.next, self.CATALOG, info, start))


def _text_string(text: str) -> bytes:
    """A PDF text string: printable ASCII as a literal, anything else as UTF-16BE with a byte-order mark."""
    if text.isascii() and text.isprintable():
        return b"(" + text.encode("ascii").replace(b"\\", b"\\\\").replace(b"(", b"\\(").replace(b")", b"\\)") + b")"
    return b"<FEFF" + text.encode("utf-16-be").hex().upper().encode("ascii") + b">"
