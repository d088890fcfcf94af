"""Compiled templates and their alternatives kept on disk, so only the first run of a template pays for sympy.

The key is the template file's hash, the package version and a fingerprint of the solver's
source: editing either recompiles. The folder is :func:`grader.base.caching.cache_dir`; if it cannot be
written, templates are compiled each run and nothing fails.

The shipped bank's entries come with the package too (:data:`SHIPPED`, written by ``python -m
grader.solve.ship``; a test checks that they are current), under the names the cache gives them: a first run
on a new machine reads them and pays for sympy only for an instructor's own templates. An entry made from
other source, or for another version of a template, has another name and is simply not found.
"""

from __future__ import annotations

import hashlib
import sys
from collections.abc import Callable
from functools import lru_cache
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol, TypeVar

from grader.bank.template import Template
from grader.base import caching
from grader.base.caching import ANY, cache_dir
from grader.solve.compiled import FORMAT, Compiled

if TYPE_CHECKING:  # each read where it is asked for: a warm `grader solve` needs neither
    from grader.solve.alternatives import Alternatives
    from grader.solve.routes import Routes

# Every stage folder whose source can change what the solver compiles: editing any file in them
# recompiles (a test checks that everything the solver imports is inside).
SOLVER_FOLDERS = ("model", "physics", "bank", "solve")
SHIPPED = caching.PACKAGE / "solve" / "shipped"
"""The compiled forms of the shipped bank, carried by the package."""
KINDS = ("", "-alternatives", "-routes")
"""What is kept of a template: its compiled form, its alternatives, its routes (the end of the entry's name)."""

_NUMBERS = {str: (int, float)}
SHAPES = {
    "": {"format": int, "template": str, "source_hash": str, "parameters": [str], "constants": _NUMBERS,
         "steps": [{"unknown": str, "relation": str, "equation": [ANY], "solved": ANY}],
         "checks": [{"holds": ANY, "message": str, "subject": ANY}],
         "answers": {str: {"unit": str, "numeric": ANY, "symbolic": ANY, "undefined": [{"when": ANY, "reason": str}]}}},
    "-alternatives": {"template": str, "source_hash": str, "constants": _NUMBERS,
                      "items": [{"answer": str, "kind": str, "id": str, "says": str, "value": ANY}]},
    "-routes": {"template": str, "source_hash": str, "constants": _NUMBERS, "symbols": [str],
                "items": [{"answer": str, "id": str, "says": str, "names": [str], "steps": [ANY], "value": ANY,
                           "composed": [ANY], "slopes": [ANY]}]},
}
"""What each kind's ``to_json`` writes, as :func:`grader.base.caching.fits` checks an entry before it is read
(expression trees, :data:`~grader.base.caching.ANY` here, are checked by their reader)."""

__all__ = ["KINDS", "SHIPPED", "SOLVER_FOLDERS", "alternatives_for", "cache_dir", "compiled_for", "entry_name",
           "routes_for", "source_fingerprint"]


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
        import time

        from grader.solve.derived import compile_alternatives

        # seconds of sympy for an instructor's own template, the first time grading needs it: say so
        start = time.perf_counter()
        print(f"grader: deriving the chains of errors carried forward and of mistakes for {template.id} "
              "(once; kept in the cache)...", file=sys.stderr, flush=True)
        found = compile_alternatives(template)
        print(f"grader: {template.id}: {len(found.items)} chains in {time.perf_counter() - start:.1f} s",
              file=sys.stderr, flush=True)
        return found

    return _cached(template, "-alternatives", Alternatives.from_json, compile_now)


def routes_for(template: Template) -> Routes:
    """A template's solution routes with their rounding slopes: from the cache, or compiled now and
    cached beside its compiled form."""
    from grader.solve.routes import Routes

    def compile_now() -> Routes:
        from grader.solve.derived_routes import compile_routes

        return compile_routes(template, compiled_for(template))

    return _cached(template, "-routes", Routes.from_json, compile_now)


class _Stored(Protocol):
    @property
    def template_id(self) -> str: ...
    @property
    def source_hash(self) -> str: ...
    def to_json(self) -> dict[str, Any]: ...


_T = TypeVar("_T", bound=_Stored)


def entry_name(template: Template, kind: str) -> str:
    """The name a template's entry of ``kind`` (one of :data:`KINDS`) is kept under: ``<id>-<hash><kind>.json``,
    the hash that of the template's file and of the solver's source."""
    key = hashlib.sha256(f"{template.source_hash}/{_fingerprint()}".encode()).hexdigest()[:20]
    return f"{template.id}-{key}{kind}.json"


def _cached(template: Template, kind: str, read: Callable[[Any], _T], compile_now: Callable[[], _T]) -> _T:
    """What ``compile_now`` makes for a template, kept as :func:`entry_name` says (``read`` reads it back): from the
    package's shipped entries, else the cache; an entry not of the kind's shape (:data:`SHAPES`), or that ``read``
    refuses, or made from another template, is made again."""
    name = entry_name(template, kind)
    kept = _kept(template, kind, read, caching.read_entry(SHIPPED / name, shipped=True))
    if kept is not None:
        return kept
    path = caching.entry(name)
    kept = _kept(template, kind, read, caching.read_entry(path))
    if kept is not None:
        return kept
    made = compile_now()
    caching.write_entry(path, made.to_json())  # only a first run writes
    return made


def _kept(template: Template, kind: str, read: Callable[[Any], _T], stored: Any) -> _T | None:
    """What an entry holds, if it is this template's: None for an entry missing, not of the kind's shape, made
    from another template, or that ``read`` refuses (a ``ValueError``: another format, an expression tree it does
    not write; a ``RecursionError``: a tree nested deeper than Python reads). Any other exception is a bug of
    the reader and keeps its traceback (a regression would otherwise be a silent recompile on every run)."""
    if (stored is None or not caching.fits(stored, SHAPES[kind]) or stored["template"] != template.id
            or stored["source_hash"] != template.source_hash):
        return None
    try:
        return read(stored)
    except (ValueError, RecursionError):
        return None
