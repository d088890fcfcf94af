"""What grader keeps on disk so a second run skips work the first did, and the keys that keep a stale
entry from ever being read back.

The folder is ``$GRADER_CACHE_DIR``, else ``$XDG_CACHE_HOME/grader``, else ``~/.cache/grader``. An entry
is a JSON file whose name or contents carry its key: a digest of everything the result depends on (the
input's bytes, grader's version, the source of the code that made it). An entry that is missing,
unreadable, not JSON or made for another key is a miss, and the work is done again; a folder that cannot
be written only costs time.

>>> import tempfile, pathlib
>>> entry = pathlib.Path(tempfile.mkdtemp()) / "sub" / "entry.json"
>>> read_entry(entry) is None
True
>>> write_entry(entry, {"key": "k1", "rows": [1, 2]})
>>> read_entry(entry)
{'key': 'k1', 'rows': [1, 2]}
>>> _ = entry.write_text('{"key": "k1", "ro')  # cut short: a miss, not an error
>>> read_entry(entry) is None
True
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import stat
import sys
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from grader import __version__

PACKAGE = Path(__file__).resolve().parent

ENTRY_BYTES = 16 << 20
"""The largest entry written or read (16 MiB): what a 1 MiB YAML file reads as is at most a few times its size
as JSON (``\\u`` escapes); a compiled template is tens of kB."""


def cache_dir() -> Path:
    """Where the entries are kept."""
    if os.environ.get("GRADER_CACHE_DIR"):
        return Path(os.environ["GRADER_CACHE_DIR"])
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "grader"


def source_fingerprint(package: Path, sources: Iterable[str], salt: str, libraries: Iterable[str] = ()) -> str:
    """A digest of grader's version, ``salt`` (an entry's format) and the source of ``sources``: folders
    of ``package`` (every ``*.py`` in them, at any depth) and single files, by their path in it; with
    ``libraries``, also Python's version and each library's installed copy (:func:`library_stamp`).

    >>> source_fingerprint(PACKAGE, ["errors.py"], "1") == source_fingerprint(PACKAGE, ["errors.py"], "2")
    False
    """
    digest = hashlib.sha256(f"{__version__}/{salt}".encode())
    for name in sources:
        where = package / name
        for source in sorted(where.rglob("*.py")) if where.is_dir() else [where]:
            digest.update(source.relative_to(package).as_posix().encode())
            digest.update(source.read_bytes())
    libraries = list(libraries)
    if libraries:
        digest.update(f"{sys.version}/{[library_stamp(name) for name in libraries]}".encode())
    return digest.hexdigest()


def library_stamp(name: str) -> tuple[str, int, int] | None:
    """Where a library's package file is, its size and modification time, found without importing it
    (installing another version rewrites the file); None when it is not installed.

    >>> library_stamp("yaml")[0].endswith("__init__.py"), library_stamp("no_such_library")
    (True, None)
    """
    from importlib.util import find_spec

    spec = find_spec(name)
    if spec is None or spec.origin is None:
        return None
    try:
        status = os.stat(spec.origin)
    except OSError:
        return None
    return spec.origin, status.st_size, status.st_mtime_ns


def entry(name: str) -> Path | None:
    """Where the entry ``name`` is kept: in :func:`cache_dir`, or nowhere (None) when there is no folder to
    keep it in (no ``$HOME``, and no home folder for the user)."""
    try:
        return cache_dir() / name
    except RuntimeError:  # Path.home() found none
        return None


def read_entry(path: Path | None) -> Any:
    """An entry's JSON, or None when it is missing, cannot be read, is not a regular file (a named pipe
    would block the read, a device never end it), is larger than :data:`ENTRY_BYTES`, or is not JSON (or
    JSON nested deeper than Python reads)."""
    if path is None:
        return None
    try:
        handle = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))  # a FIFO opens without a writer
        with os.fdopen(handle, "rb") as stream:
            status = os.fstat(handle)
            if not stat.S_ISREG(status.st_mode) or status.st_size > ENTRY_BYTES:
                return None
            data = stream.read(ENTRY_BYTES + 1)
    except OSError:
        return None
    if len(data) > ENTRY_BYTES:  # grown since
        return None
    try:
        return json.loads(data)
    except (ValueError, RecursionError):  # a bad UTF-8 byte is a ValueError too
        return None


def write_entry(path: Path | None, data: Any) -> None:
    """Keep ``data`` as JSON at ``path``, atomically (a reader never sees half an entry); a folder that
    cannot be written is left as it is, and data larger than :data:`ENTRY_BYTES` is not kept."""
    if path is None:
        return
    text = json.dumps(data)
    if len(text) > ENTRY_BYTES:  # ASCII: as many bytes as characters
        return
    from grader.files import write_atomic  # only a miss writes: a hit does not pay for its imports

    with contextlib.suppress(OSError):
        write_atomic(path, text)
