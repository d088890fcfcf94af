"""Joining PDFs a part at a time: every page in order, the text and fonts intact, each part's
bookmarks in order pointing at the right pages, the same bytes every time, memory of one part."""

from __future__ import annotations

from pathlib import Path

import pytest
from pypdf import PdfReader

from grader.render.joining import PdfFormatError, join, read_part
from grader.render.typeset import compile_typst, one_pdf

ODD = "/Next 3 0 R (x"  # a heading that looks like PDF syntax, with an unbalanced parenthesis


def part(folder: Path, name: str, source: str, tagged: bool = False) -> Path:
    path = folder / f"{name}.pdf"
    path.write_bytes(one_pdf(compile_typst(f'#set page(width: 8cm, height: 6cm)\n{source}', tagged=tagged)))
    return path


@pytest.fixture
def parts(tmp_path: Path) -> list[Path]:
    return [
        part(tmp_path, "a", "= First\nalpha\n== Inside\n#pagebreak()\n= Second\nbeta"),
        part(tmp_path, "b", "no headings here, but tags", tagged=True),
        part(tmp_path, "c", f'= #"{ODD}"\ngamma\n#pagebreak()\ndelta\n#pagebreak()\n= Ärger 李\nepsilon'),
    ]


def outline(reader: PdfReader) -> list[tuple[str, int, int]]:
    """(title, depth, page from 0) of every bookmark, in order."""
    found: list[tuple[str, int, int]] = []

    def walk(items: list[object], depth: int) -> None:
        for item in items:
            if isinstance(item, list):
                walk(item, depth + 1)
            else:
                found.append((item.title, depth, reader.get_destination_page_number(item)))  # type: ignore[attr-defined]

    walk(reader.outline, 0)
    return found


def test_pages_and_top_level_bookmarks_of_a_part_are_read(parts: list[Path]) -> None:
    assert [(p.pages, p.bookmarks) for p in map(read_part, parts)] == [(2, (0, 1)), (1, ()), (3, (0, 2))]


def test_the_joined_file_has_every_page_text_and_bookmark_in_order(tmp_path: Path, parts: list[Path]) -> None:
    target = tmp_path / "joined.pdf"
    join([read_part(p) for p in parts], target, title="Class (all)", author="ENGR 李", lang="en")
    reader = PdfReader(target, strict=True)
    texts = [page.extract_text() for page in reader.pages]
    assert [next(w for w in ("alpha", "beta", "tags", "gamma", "delta", "epsilon") if w in t) for t in texts] == \
        ["alpha", "beta", "tags", "gamma", "delta", "epsilon"]
    assert outline(reader) == [("First", 0, 0), ("Inside", 1, 0), ("Second", 0, 1), (ODD, 0, 3), ("Ärger 李", 0, 5)]
    assert reader.metadata is not None and reader.metadata.title == "Class (all)"
    assert reader.metadata.author == "ENGR 李"
    assert "/StructTreeRoot" not in reader.trailer["/Root"]  # a part's tags describe that part alone


def test_joining_again_gives_the_same_bytes(tmp_path: Path, parts: list[Path]) -> None:
    for name in ("one.pdf", "two.pdf"):
        join([read_part(p) for p in parts], tmp_path / name)
    assert (tmp_path / "one.pdf").read_bytes() == (tmp_path / "two.pdf").read_bytes()


def test_a_file_that_is_not_a_typst_pdf_is_refused(tmp_path: Path) -> None:
    broken = tmp_path / "broken.pdf"
    broken.write_bytes(b"%PDF-1.7\nnot really\n")
    with pytest.raises(PdfFormatError, match="cross-reference"):
        read_part(broken)
