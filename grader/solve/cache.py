"""Compiled templates and their alternatives kept on disk, so only the first run of a template pays for sympy.

The key is the template file's hash, the package version and a fingerprint of the solver's
source: editing either recompiles. The folder is ``$GRADER_CACHE_DIR``, else
``$XDG_CACHE_HOME/grader``, else ``~/.cache/grader``; if it cannot be written, templates are
compiled each run and nothing fails.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
from collections.abc import Callable
from functools import lru_cache
from pathlib import Path
from typing import Any, Protocol, TypeVar

from grader import __version__
from grader.bank.template import Template
from grader.solve.alternatives import Alternatives
from grader.solve.compiled import FORMAT, Compiled
from grader.solve.routes import Routes

# Every stage folder whose source can change what the solver compiles: editing any file in them
# recompiles (a test checks that everything the solver imports is inside).
SOLVER_FOLDERS = ("model", "physics", "bank", "solve")


def cache_dir() -> Path:
    """Where compiled templates are kept."""
    if os.environ.get("GRADER_CACHE_DIR"):
        return Path(os.environ["GRADER_CACHE_DIR"])
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "grader"


def source_fingerprint(package: Path) -> str:
    """A digest of the version, the compiled format and every source file of ``SOLVER_FOLDERS``."""
    digest = hashlib.sha256(f"{__version__}/{FORMAT}".encode())
    for folder in SOLVER_FOLDERS:
        for source in sorted((package / folder).rglob("*.py")):
            digest.update(source.relative_to(package).as_posix().encode())
            digest.update(source.read_bytes())
    return digest.hexdigest()


@lru_cache(maxsize=1)
def _fingerprint() -> str:
    return source_fingerprint(Path(__file__).resolve().parent.parent)


def compiled_for(template: Template) -> Compiled:
    """The compiled form of a template: from the cache, or compiled now and cached."""
    def compile_now() -> Compiled:
        from grader.solve.solver import compile_template

        return compile_template(template)

    return _cached(template, "", Compiled.from_json, compile_now)


def alternatives_for(template: Template) -> Alternatives:
    """A template's alternatives (error carried forward, diagnosed mistakes): from the cache, or
    compiled now and cached beside its compiled form."""
    def compile_now() -> Alternatives:
        from grader.solve.derived import compile_alternatives

        return compile_alternatives(template)

    return _cached(template, "-alternatives", Alternatives.from_json, compile_now)


def routes_for(template: Template) -> Routes:
    """A template's solution routes with their rounding slopes: from the cache, or compiled now and
    cached beside its compiled form."""
    def compile_now() -> Routes:
        from grader.solve.derived_routes import compile_routes

        return compile_routes(template)

    return _cached(template, "-routes", Routes.from_json, compile_now)


class _Stored(Protocol):
    def to_json(self) -> dict[str, Any]: ...


_T = TypeVar("_T", bound=_Stored)


def _cached(template: Template, kind: str, read: Callable[[Any], _T], compile_now: Callable[[], _T]) -> _T:
    """What ``compile_now`` makes for a template, kept as ``<id>-<hash><kind>.json`` (``read`` reads it back)."""
    key = hashlib.sha256(f"{template.source_hash}/{_fingerprint()}".encode()).hexdigest()[:20]
    path = cache_dir() / f"{template.id}-{key}{kind}.json"
    try:
        return read(json.loads(path.read_text(encoding="utf-8")))
    except (OSError, ValueError, KeyError, TypeError, IndexError):
        pass
    made = compile_now()
    from grader.files import write_atomic  # only a first run writes

    with contextlib.suppress(OSError):  # a read-only home folder only costs time
        write_atomic(path, json.dumps(made.to_json()))
    return made
