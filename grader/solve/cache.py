"""Compiled templates kept on disk, so only the first run of a template pays for sympy.

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
from functools import lru_cache
from pathlib import Path

from grader import __version__
from grader.bank.template import Template
from grader.solve.compiled import FORMAT, Compiled

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
    key = hashlib.sha256(f"{template.source_hash}/{_fingerprint()}".encode()).hexdigest()[:20]
    path = cache_dir() / f"{template.id}-{key}.json"
    try:
        return Compiled.from_json(json.loads(path.read_text(encoding="utf-8")))
    except (OSError, ValueError, KeyError, TypeError, IndexError):
        pass
    from grader.files import write_atomic  # only a first run writes
    from grader.solve.solver import compile_template

    compiled = compile_template(template)
    with contextlib.suppress(OSError):  # a read-only home folder only costs time
        write_atomic(path, json.dumps(compiled.to_json()))
    return compiled
