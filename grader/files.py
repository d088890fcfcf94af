"""Atomic file writing: a temporary file in the same folder, then ``os.replace``.

A failed run leaves either the old file or none, never half a file.

>>> import tempfile, pathlib
>>> folder = pathlib.Path(tempfile.mkdtemp())
>>> write_atomic(folder / "key.json", '{"ok": true}')
>>> (folder / "key.json").read_text()
'{"ok": true}'
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


UMASK = _umask()
"""The process umask, read once: temporary files are private until they take their final name."""


def usual_mode(path: Path, folder: bool = False) -> None:
    """Give a file or folder made by ``tempfile`` the permissions a normally created one has."""
    os.chmod(path, (0o777 if folder else 0o666) & ~UMASK)


def write_atomic(path: Path, text: str | bytes) -> None:
    """Write ``text`` (UTF-8) or bytes to ``path`` atomically."""
    path.parent.mkdir(parents=True, exist_ok=True)
    handle, temporary = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(handle, "wb") as stream:
            stream.write(text.encode("utf-8") if isinstance(text, str) else text)
        usual_mode(Path(temporary))
        os.replace(temporary, path)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise
