"""Typst: compiling a source, the fonts it may use, the private folder it compiles in, and which
characters no font has.

Typst's embedded fonts (Libertinus Serif, New Computer Modern, DejaVu Sans Mono) cover Latin,
Greek and Cyrillic, but not Chinese, Japanese, Korean or emoji: a student named 李华 would get
empty boxes. So the documents also use, when present, the Noto CJK and Noto Color Emoji fonts
of the usual Linux packages (``fonts-noto-cjk``, ``fonts-noto-color-emoji``), and any folders given
with ``--font-dir``. System fonts in general stay ignored: the same fonts give the same bytes.

Typst compiles inside an empty private folder (its root, and its package folders too), so a
document can read no file and load no package.
"""

from __future__ import annotations

import atexit
import io
import shutil
import tempfile
import threading
import unicodedata
from collections.abc import Iterable, Sequence
from functools import lru_cache
from pathlib import Path
from typing import Any, Literal

from grader.base.errors import GraderError, UsageError
from grader.render.typst_text import text

TIMESTAMP = 0  # the PDFs' creation date: fixed, so that output is reproducible

# Noto CJK (Chinese, Japanese, Korean) and Noto Color Emoji where Debian/Ubuntu, Fedora and Arch
# install them; the first file found of each name is used.
SYSTEM_FONTS = {
    name: [Path(folder) / name for folder in ("/usr/share/fonts/opentype/noto", "/usr/share/fonts/noto-cjk",
                                               "/usr/share/fonts/google-noto-cjk", "/usr/share/fonts/truetype/noto",
                                               "/usr/share/fonts/noto", "/usr/share/fonts/google-noto-color-emoji")]
    for name in ("NotoSerifCJK-Regular.ttc", "NotoSerifCJK-Bold.ttc", "NotoSansCJK-Regular.ttc",
                 "NotoSansCJK-Bold.ttc", "NotoColorEmoji.ttf")
}


@lru_cache(maxsize=1)
def _private() -> Path:
    folder = Path(tempfile.mkdtemp(prefix="grader-typst-"))
    atexit.register(shutil.rmtree, folder, ignore_errors=True)
    (folder / "root").mkdir()
    return folder


def typst_root() -> Path:
    """An empty folder, private to this process: Typst's root and package folders."""
    return _private() / "root"


def system_fonts() -> list[Path]:
    """The Noto CJK and emoji font files found on this machine (possibly none)."""
    return [found[0] for found in ([p for p in paths if p.is_file()] for paths in SYSTEM_FONTS.values()) if found]


@lru_cache(maxsize=8)
def font_paths(font_dirs: tuple[Path, ...] = ()) -> tuple[str, ...]:
    """The folders Typst reads fonts from: one of links to :func:`system_fonts`, then ``font_dirs``."""
    for folder in font_dirs:
        if not folder.is_dir():
            raise UsageError(f"--font-dir {folder}: expected a folder of font files (.ttf, .otf, .ttc), "
                             "got " + ("a file" if folder.exists() else "nothing (it does not exist)"))
    found = system_fonts()
    paths = [str(folder.resolve()) for folder in font_dirs]
    if not found:
        return tuple(paths)
    links = _private() / "system-fonts"
    if not links.is_dir():
        links.mkdir()
        for font in found:
            try:
                (links / font.name).symlink_to(font)
            except OSError:  # no symlinks here: a copy does the same
                shutil.copyfile(font, links / font.name)
    return (str(links), *paths)


# --- compiling ----------------------------------------------------------------------------------

_LOCAL = threading.local()


def compile_typst(source: str, fmt: Literal["pdf", "png", "svg"] = "pdf", ppi: float | None = None,
                  tagged: bool = True, fonts: tuple[str, ...] = ()) -> bytes | list[bytes]:
    """Compile a source with the embedded fonts and those in the ``fonts`` folders (see
    :func:`font_paths`), the fixed timestamp, and an empty private root (one compiler per thread
    and font set); ``tagged``: with the PDF structure tags screen readers use."""
    import typst

    compilers = _LOCAL.__dict__.setdefault("compilers", {})
    if fonts not in compilers:
        root = typst_root()
        compilers[fonts] = typst.Compiler(root=root, font_paths=list(fonts), ignore_system_fonts=True,
                                          package_path=root, package_cache_path=root)
    try:
        result = compilers[fonts].compile(source.encode("utf-8"), format=fmt, ppi=ppi, timestamp=TIMESTAMP,
                                          pdf_tags=tagged, root=typst_root())
    except typst.TypstError as error:
        where = "\n".join(str(error.diagnostic).splitlines()[:6])
        raise GraderError(f"Typst could not typeset a document: {error.message}\n{where}") from None
    if result is None:
        raise GraderError("Typst produced no output")
    return result  # type: ignore[no-any-return]


MEMO_AGE = 10  # the typst package evicts a memo entry that this many compiles have not used


def release_memory(forget: bool = False) -> None:
    """Return the memory Typst has freed to the system; with ``forget``, first let go of all that
    its memo cache holds from earlier documents (only while no other thread compiles: a document
    being typeset would lose what it laid out so far and lay it out again).

    The ``typst`` package evicts an entry once ``MEMO_AGE`` compiles have not used it, so as many
    empty compiles age everything out. Typst works on threads of its own and glibc keeps what they
    free in per-thread arenas, so a long run's size grew with the class although the memo cache did
    not; ``malloc_trim`` gives those pages back. Without glibc, only the memo is let go."""
    for age in range(MEMO_AGE if forget else 0):
        compile_typst(f"{age}", tagged=False)
    trim = _malloc_trim()
    if trim is not None:
        trim(0)


@lru_cache(maxsize=1)
def _malloc_trim() -> Any:
    import ctypes

    try:
        return ctypes.CDLL(None).malloc_trim
    except (AttributeError, OSError, TypeError):  # no glibc (macOS, musl), or no process handle (Windows)
        return None


def one_pdf(result: bytes | list[bytes]) -> bytes:
    """The bytes of a PDF compile (which returns one document)."""
    assert isinstance(result, bytes)  # a PDF compile returns one document, never pages
    return result


# --- coverage -----------------------------------------------------------------------------------

def _needs_probe(char: str) -> bool:
    # Printable ASCII is in every embedded font; controls, spaces, joiners and variation selectors
    # draw nothing of their own.
    return not (" " <= char <= "~") and unicodedata.category(char) not in ("Cc", "Cf", "Zs", "Zl", "Zp") \
        and not ("\ufe00" <= char <= "\ufe0f")


def uncovered(texts: Iterable[str], fonts: tuple[str, ...]) -> set[str]:
    """The characters of ``texts`` that no font has (each would print as an empty box).

    Typst itself is asked: one page per character, and a page whose text shows glyph 0 (the
    "missing glyph" box) in an ordinary (Type 0) font has a character no font covers.
    """
    chars = sorted({c for t in texts for c in t if _needs_probe(c)})
    return {c for c, covered in zip(chars, _probe(tuple(chars), fonts), strict=True) if not covered}


@lru_cache(maxsize=16)
def _probe(chars: tuple[str, ...], fonts: tuple[str, ...]) -> tuple[bool, ...]:
    if not chars:
        return ()
    from pypdf import PdfReader

    pages = "\n#pagebreak()\n".join(text(c) for c in chars)
    pdf = compile_typst(f'#set page(width: 2cm, height: 2cm)\n#set text(font: "Libertinus Serif")\n{pages}\n',
                        fonts=fonts, tagged=False)
    reader = PdfReader(io.BytesIO(one_pdf(pdf)))
    return tuple(not _shows_missing_glyph(page, reader) for page in reader.pages)


def _shows_missing_glyph(page: Any, reader: Any) -> bool:
    from pypdf.generic import ContentStream

    fonts = page["/Resources"]["/Font"]
    current = None
    for operands, operator in ContentStream(page.get_contents(), reader).operations:
        if operator == b"Tf":
            current = fonts[operands[0]].get_object()
        elif operator in (b"Tj", b"TJ") and current is not None and current.get("/Subtype") == "/Type0":
            strings = operands[0] if operator == b"TJ" else [operands[0]]
            for string in strings:
                code = getattr(string, "original_bytes", string)  # pypdf may have decoded it as text
                if isinstance(code, bytes) and any(code[i:i + 2] == b"\0\0" for i in range(0, len(code), 2)):
                    return True
    return False


def missing_glyph_warnings(people: Sequence[tuple[str, str]], fonts: tuple[str, ...]) -> list[str]:
    """A warning per student (id, name) whose name has characters no font covers."""
    missing = uncovered((name for _, name in people), fonts)
    warnings = []
    for student_id, name in people:
        lacking = sorted({c for c in name if c in missing})
        if lacking:
            shown = ", ".join(f"{c} (U+{ord(c):04X})" for c in lacking)
            warnings.append(f"warning: student {student_id} ({name}): no font has {shown}; it prints as an empty "
                            "box. Install fonts-noto-cjk / fonts-noto-color-emoji, or give --font-dir DIR with a "
                            "font that has it")
    return warnings
