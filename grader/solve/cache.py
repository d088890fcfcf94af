"""Compiled templates and their alternatives kept on disk, so only the first run of a template pays for sympy.

The key is the template file's hash, the package version and a fingerprint of the solver's
source: editing either recompiles. The folder is :func:`grader.caching.cache_dir`; if it cannot be
written, templates are compiled each run and nothing fails.
"""

from __future__ import annotations

import hashlib
from collections.abc import Callable
from functools import lru_cache
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol, TypeVar

from grader import caching
from grader.bank.template import Template
from grader.caching import cache_dir
from grader.errors import GraderError
from grader.solve.compiled import FORMAT, Compiled

if TYPE_CHECKING:  # each read where it is asked for: a warm `grader solve` needs neither
    from grader.solve.alternatives import Alternatives
    from grader.solve.routes import Routes

# Every stage folder whose source can change what the solver compiles: editing any file in them
# recompiles (a test checks that everything the solver imports is inside).
SOLVER_FOLDERS = ("model", "physics", "bank", "solve")

__all__ = ["SOLVER_FOLDERS", "alternatives_for", "cache_dir", "compiled_for", "routes_for", "source_fingerprint"]


def source_fingerprint(package: Path) -> str:
    """A digest of the version, the compiled format and every source file of ``SOLVER_FOLDERS``."""
    return caching.source_fingerprint(package, SOLVER_FOLDERS, str(FORMAT))


@lru_cache(maxsize=1)
def _fingerprint() -> str:
    return source_fingerprint(caching.PACKAGE)


def compiled_for(template: Template) -> Compiled:
    """The compiled form of a template: from the cache, or compiled now and cached."""
    def compile_now() -> Compiled:
        from grader.solve.solver import compile_template

        return compile_template(template)

    return _cached(template, "", Compiled.from_json, compile_now)


def alternatives_for(template: Template) -> Alternatives:
    """A template's alternatives (error carried forward, diagnosed mistakes): from the cache, or
    compiled now and cached beside its compiled form."""
    from grader.solve.alternatives import Alternatives

    def compile_now() -> Alternatives:
        from grader.solve.derived import compile_alternatives

        return compile_alternatives(template)

    return _cached(template, "-alternatives", Alternatives.from_json, compile_now)


def routes_for(template: Template) -> Routes:
    """A template's solution routes with their rounding slopes: from the cache, or compiled now and
    cached beside its compiled form."""
    from grader.solve.routes import Routes

    def compile_now() -> Routes:
        from grader.solve.derived_routes import compile_routes

        return compile_routes(template)

    return _cached(template, "-routes", Routes.from_json, compile_now)


class _Stored(Protocol):
    @property
    def template_id(self) -> str: ...
    @property
    def source_hash(self) -> str: ...
    def to_json(self) -> dict[str, Any]: ...


_T = TypeVar("_T", bound=_Stored)


def _cached(template: Template, kind: str, read: Callable[[Any], _T], compile_now: Callable[[], _T]) -> _T:
    """What ``compile_now`` makes for a template, kept as ``<id>-<hash><kind>.json`` (``read`` reads it back); an
    entry ``read`` cannot read, or made from another template, is made again."""
    key = hashlib.sha256(f"{template.source_hash}/{_fingerprint()}".encode()).hexdigest()[:20]
    path = caching.entry(f"{template.id}-{key}{kind}.json")
    stored = caching.read_entry(path)
    if stored is not None:
        try:
            kept = read(stored)
        except (ValueError, KeyError, TypeError, IndexError, AttributeError, RecursionError, GraderError):
            pass  # what grader writes reads back: anything else is not grader's, or not this grader's
        else:
            if kept.template_id == template.id and kept.source_hash == template.source_hash:
                return kept
    made = compile_now()
    caching.write_entry(path, made.to_json())  # only a first run writes
    return made
