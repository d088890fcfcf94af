r"""Where a bank's templates are (the shipped folder and the ones given, each template file of each), the
topics ``grader list`` groups them by, and what a template's id, title and names may be: what a listing
needs before any template is read, and to check one read back from the cache.

>>> [path.name for path in template_files(bank_folders()[0])][:2], template_paths()[0].name
(['ball-plate.yaml', 'ballistic-pendulum.yaml'], 'ball-plate.yaml')
>>> bool(TEMPLATE_ID.match("pile-driver")), bool(NAME.match("h_drop")), bool(NAME.match("h_drop\n"))
(True, True, False)
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from pathlib import Path

from grader.base.errors import CONTROL, GraderError, UsageError
from grader.base.resources import bank_dir

TOPICS = ("direct impact", "oblique impact", "drops and rebounds", "impact and a swing", "impact and sliding",
          "impact with flight")
"""The topics ``grader list`` groups the bank by, in its order. A template names one (``topic:``), or
its scene decides: a scene with a slide is impact and sliding, one with a projectile's flight impact
with flight; else an impact with t components (or a velocity from its components) is oblique; else
a scene with a swing is an impact and a swing; else a scene with a fall, a rise or bounces is drops and
rebounds; else it is a direct impact."""


TEMPLATE_ID = re.compile(r"[a-z0-9][a-z0-9-]*\Z")
"""A template's id (its file's name without ``.yaml``): lower-case letters, digits and ``-``."""

NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*\Z")
"""A parameter's, a symbol's, an answer's or a body's name: letters, digits and ``_``, a letter first."""


def one_line(text: str) -> bool:
    r"""Whether ``text`` is one line a terminal shows as it is: no control character (an escape sequence, a
    line break of any kind) and no bidirectional override (which reorders what follows it).

    >>> one_line("Ball dropped onto a rigid floor"), one_line("Ball\rdropped"), one_line("\x1b[31mBall")
    (True, False, False)
    """
    return not CONTROL.search(text) and "\u2028" not in text and "\u2029" not in text  # the two line breaks


def template_files(folder: Path) -> list[Path]:
    """The ``*.yaml`` files of a bank folder, by name; a folder that is missing or has none is refused."""
    if not folder.is_dir():
        raise GraderError(f"{folder}: problem bank folder not found")
    paths = sorted(folder.glob("*.yaml"))
    if not paths:
        raise GraderError(f"{folder}: no templates in this folder; expected problem templates as *.yaml files")
    for path in paths:
        if not path.is_file():  # a named pipe would block the run, a folder cannot be read
            kind = "a folder" if path.is_dir() else "a special file (a pipe or a device)"
            raise GraderError(f"{path}: expected a template file, got {kind}")
    return paths


def bank_folders(folders: Sequence[Path] = (), shipped: bool = True) -> list[Path]:
    """The shipped bank's folder (unless ``shipped`` is false), then ``folders``, each once."""
    sources, seen = [], set()
    for folder in ([bank_dir()] if shipped else []) + list(folders):
        if folder.resolve() not in seen:
            seen.add(folder.resolve())
            sources.append(folder)
    if not sources:
        raise UsageError("no problem bank: without the shipped bank (--no-shipped-bank), give --bank DIR")
    return sources


def template_paths(folders: Sequence[Path] = (), shipped: bool = True) -> list[Path]:
    """Every template file of the banks (:func:`bank_folders`), folder by folder, each folder's by name."""
    return [path for folder in bank_folders(folders, shipped) for path in template_files(folder)]
