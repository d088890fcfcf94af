"""What grader keeps on disk so a second run skips work the first did, and the keys that keep a stale
entry from ever being read back.

The folder is ``$GRADER_CACHE_DIR``, else ``$XDG_CACHE_HOME/grader``, else ``~/.cache/grader``. An entry
is a JSON file whose name or contents carry its key: a digest of everything the result depends on (the
input's bytes, grader's version, the source of the code that made it). It is sealed with a digest of its
name and its contents, and written by the user alone: an entry that is missing, unreadable, not a regular
file, not JSON, made for another key, changed since, or that another user wrote or could have written is a
miss, and the work is done again; a folder that cannot be written only costs time.

>>> import tempfile, pathlib
>>> entry = pathlib.Path(tempfile.mkdtemp()) / "sub" / "entry.json"
>>> read_entry(entry) is None
True
>>> write_entry(entry, {"key": "k1", "rows": [1, 2]})
>>> read_entry(entry)
{'key': 'k1', 'rows': [1, 2]}
>>> _ = entry.write_bytes(entry.read_bytes()[:-5])  # cut short: a miss, not an error
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

PACKAGE = Path(__file__).resolve().parent.parent

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

    >>> source_fingerprint(PACKAGE, ["base/errors.py"], "1") == source_fingerprint(PACKAGE, ["base/errors.py"], "2")
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


def read_entry(path: Path | None, *, shipped: bool = False) -> Any:
    """What :func:`write_entry` kept at ``path``, or None when there is nothing grader kept there for this user:
    a file missing or unreadable; not a regular file (a named pipe would block the read, a device never end
    it); larger than :data:`ENTRY_BYTES`; written by another user, or writable by one (only the user and root
    can have written what is read); kept under another name, or changed since (:func:`seal`); JSON nested
    deeper than Python reads. A ``shipped`` entry is one the package itself carries (installed with grader's
    code, so whoever installed it is trusted as the code is): its owner is not asked, the rest is."""
    if path is None:
        return None
    try:
        handle = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))  # a FIFO opens without a writer
        with os.fdopen(handle, "rb") as stream:
            status = os.fstat(handle)
            if not _mine(status, owner=not shipped):
                return None
            sealed = read_at_most(stream, ENTRY_BYTES + 1, status.st_size + 1)
    except OSError:
        return None
    text = unsealed(path.name, sealed)
    if text is None:
        return None
    try:
        return json.loads(text)
    except (ValueError, RecursionError):
        return None


def read_at_most(stream: Any, most: int, chunk: int) -> bytes:
    """At most ``most`` bytes of ``stream``, read ``chunk`` bytes at a time (a regular file's size and one more
    byte, to see that it has not grown: one read).

    >>> import io
    >>> read_at_most(io.BytesIO(b"abcdef"), 4, 3), read_at_most(io.BytesIO(b"ab"), 4, 3)
    (b'abcd', b'ab')
    """
    parts, size = [], 0
    while size < most:
        part = stream.read(min(max(chunk, 1), most - size))
        if not part:
            break
        parts.append(part)
        size += len(part)
    return b"".join(parts)


def write_entry(path: Path | None, data: Any) -> None:
    """Keep ``data`` as JSON at ``path``, sealed (:func:`seal`), atomically (a reader never sees half an entry)
    and writable by this user alone; a folder that cannot be written is left as it is, and data larger than
    :data:`ENTRY_BYTES` is not kept."""
    if path is None:
        return
    sealed = seal(path.name, json.dumps(data).encode())
    if len(sealed) > ENTRY_BYTES:
        return
    from grader.base.files import write_atomic  # only a miss writes: a hit does not pay for its imports

    with contextlib.suppress(OSError):
        write_atomic(path, sealed, mode=0o644)


_HEAD = b'{"grader cache entry": 1, "sha256": "'
_DATA = b'", "data": '


def seal(name: str, text: bytes) -> bytes:
    """JSON ``text`` as an entry named ``name`` holds it: in a JSON object with the SHA-256 of the name and the
    text, so that an entry read under another name (copied, renamed, linked), cut short or changed since
    is a miss, and grader's entries are told from any other file.

    >>> sealed = seal("yaml-1.json", b"[1]")
    >>> sealed[:60]
    b'{"grader cache entry": 1, "sha256": "b0676677d4515849b7bf85d'
    >>> unsealed("yaml-1.json", sealed), unsealed("yaml-2.json", sealed), unsealed("yaml-1.json", sealed[:-2])
    (b'[1]', None, None)
    """
    return _HEAD + _digest(name, text) + _DATA + text + b"}"


def unsealed(name: str, sealed: bytes) -> bytes | None:
    """The JSON text :func:`seal` sealed under ``name``, or None when ``sealed`` is not that."""
    start = len(_HEAD) + 64 + len(_DATA)
    text = sealed[start:-1]
    return text if sealed.endswith(b"}") and sealed[:start] == _HEAD + _digest(name, text) + _DATA else None


def _digest(name: str, text: bytes) -> bytes:
    return hashlib.sha256(name.encode() + b"\0" + text).hexdigest().encode()


def _mine(status: os.stat_result, owner: bool = True) -> bool:
    """Whether a file is a regular one of at most :data:`ENTRY_BYTES` that no one but this user (or root) can
    have written: theirs, and writable by no one else (without ``owner``: any regular file of that size).
    Where files have no owner (Windows), any."""
    if not stat.S_ISREG(status.st_mode) or status.st_size > ENTRY_BYTES:
        return False
    if not owner or not hasattr(os, "geteuid"):
        return True
    return status.st_uid in (os.geteuid(), 0) and not status.st_mode & 0o022


def grader_entries(folder: Path) -> list[Path]:
    """The entries grader wrote in ``folder`` for this user: regular files (not links to one) sealed under their
    own name (the check :func:`read_entry` makes), in name order; nothing else there is grader's to count or
    remove.

    >>> import tempfile, pathlib
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> write_entry(folder / "yaml-1.json", [1])
    >>> _ = (folder / "notes.txt").write_text("mine")
    >>> [path.name for path in grader_entries(folder)]
    ['yaml-1.json']
    """
    try:
        candidates = sorted(folder.iterdir())
    except OSError:
        return []
    return [path for path in candidates
            if path.name.endswith(".json") and not path.is_symlink() and read_entry(path) is not None]


def clear(folder: Path) -> tuple[int, int]:
    """Remove grader's entries from ``folder`` (:func:`grader_entries`); the number removed and their bytes.
    Other files, folders and the folder itself stay."""
    removed = size = 0
    for path in grader_entries(folder):
        try:
            bytes_ = path.stat().st_size
            path.unlink()
        except FileNotFoundError:  # another run removed it first
            continue
        removed, size = removed + 1, size + bytes_
    return removed, size


ANY = object()
"""A shape :func:`fits` takes anything for (what the reader checks itself, as an expression tree's reader does)."""


def fits(data: Any, shape: Any) -> bool:
    """Whether an entry's JSON ``data`` has ``shape``, so that reading it back cannot miss a field or meet
    another type: an entry damaged or made by other code is told apart from a bug in the reader, which keeps
    its traceback. A shape is :data:`ANY`; a JSON type or a tuple of them (``bool`` is not ``int`` here);
    ``[shape]``, a list of those; ``{str: shape}``, an object of any names whose values have ``shape``; or
    ``{"name": shape, ...}``, an object with at least those names.

    >>> fits({"a": [1, 2.5], "b": None}, {"a": [(int, float)], "b": ANY}), fits({"a": [True]}, {"a": [int]})
    (True, False)
    >>> fits({"x": {"n": "1"}}, {str: {"n": str}}), fits({"x": []}, {str: {"n": str}}), fits({}, {"a": str})
    (True, False, False)
    """
    if shape is ANY:
        return True
    if isinstance(shape, list):
        return type(data) is list and all(fits(item, shape[0]) for item in data)
    if isinstance(shape, dict):
        if type(data) is not dict:
            return False
        if list(shape) == [str]:
            return all(type(name) is str and fits(value, shape[str]) for name, value in data.items())
        return all(name in data and fits(data[name], value) for name, value in shape.items())
    return type(data) in (shape if isinstance(shape, tuple) else (shape,))
