"""Where the shipped data lives: the problem bank and the document templates.

A wheel carries them inside the package (``grader/problem_bank``); a source checkout or an
editable install keeps them at the top of the repository. Both are found.
"""

from __future__ import annotations

from pathlib import Path

_PACKAGE = Path(__file__).resolve().parent.parent


def _find(name: str) -> Path:
    inside = _PACKAGE / name
    return inside if inside.is_dir() else _PACKAGE.parent / name


def bank_dir() -> Path:
    """The folder of the shipped problem templates."""
    return _find("problem_bank")


def sample_dir() -> Path:
    """The folder of the sample assignment and roster ``grader demo`` uses."""
    return _PACKAGE / "sample"


def templates_dir() -> Path:
    """The folder of the shipped Jinja2 document templates."""
    return _find("templates")
