"""The documentation the tests read: README.md, then every page of docs/ in name order."""

from __future__ import annotations

from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PAGES = (ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md")))


def text(page: Path) -> str:
    """A page's Markdown."""
    return page.read_text(encoding="utf-8")


def all_text() -> str:
    """Every page, README first, one after the other (a passage is found wherever it was moved)."""
    return "\n".join(text(page) for page in PAGES)
