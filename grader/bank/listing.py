"""What ``grader list`` shows of each template of the banks, kept on disk: a warm listing reads no YAML and
imports neither the effects catalogue nor numpy.

An entry holds each template file's path and SHA-256 and what the listing shows of it, and is read back
only when the banks have exactly those files with exactly those bytes and grader is the same (its
version, Python's, the installed PyYAML and Jinja2, and the source of everything that reads and checks a
template: :data:`SOURCES`). Anything else (a template edited, added or removed, an upgrade, an entry
missing, unreadable or cut short) reads and checks the banks with :func:`grader.bank.template.load_banks`,
which refuses what it refuses with its own messages, and keeps the listing when they load.

>>> listed = listing()
>>> [(t.id, t.topic) for t in listed if t.id == "pile-driver"]
[('pile-driver', 'drops and rebounds')]
>>> listing() == listed  # the second time from the entry
True
"""

from __future__ import annotations

import hashlib
from collections.abc import Sequence
from dataclasses import asdict, dataclass, fields
from functools import lru_cache
from pathlib import Path
from typing import TYPE_CHECKING, Any

from grader.bank.folders import bank_folders, template_files
from grader.caching import PACKAGE, entry, read_entry, source_fingerprint, write_entry
from grader.errors import GraderError
from grader.inputs import YAML_BYTES, read_bytes

if TYPE_CHECKING:
    from grader.bank.template import Template

FORMAT = 1
SOURCES = ("model", "physics", "bank", "errors.py", "inputs.py", "resources.py", "yaml_loader.py")
"""Everything reading and checking a template runs (a test walks the imports to see that it is all here)."""
LIBRARIES = ("yaml", "jinja2")


@dataclass(frozen=True)
class Listed:
    """What the listing shows of a template."""

    id: str
    title: str
    topic: str
    version: int
    where: str
    parameters: tuple[str, ...]
    answers: tuple[str, ...]

    @classmethod
    def of(cls, template: Template) -> Listed:
        """What the listing shows of a loaded template."""
        return cls(template.id, template.title, template.topic, template.version, template.where,
                   tuple(template.parameters), tuple(template.answers))

    @classmethod
    def from_json(cls, data: Any) -> Listed:
        """A listed template as :func:`dataclasses.asdict` wrote it; anything else is a ``ValueError``."""
        if not isinstance(data, dict) or set(data) != {field.name for field in fields(cls)}:
            raise ValueError(f"not a listed template: {data!r:.100}")
        names = [data["parameters"], data["answers"]]
        if not (all(isinstance(data[key], str) for key in ("id", "title", "topic", "where"))
                and type(data["version"]) is int
                and all(isinstance(part, list) and all(isinstance(n, str) for n in part) for part in names)):
            raise ValueError(f"not a listed template: {data!r:.100}")
        return cls(data["id"], data["title"], data["topic"], data["version"], data["where"],
                   tuple(data["parameters"]), tuple(data["answers"]))


def listing(folders: Sequence[Path] = (), shipped: bool = True) -> list[Listed]:
    """The templates :func:`grader.bank.template.load_banks` loads from these banks, as the listing shows
    them, in its order; refused as it refuses them."""
    sources = bank_folders(folders, shipped)
    named = _digest("\n".join(map(str, sources)))[:20]
    kept = entry(f"bank-{named}.json")
    files = _files(sources)
    if files is not None:
        listed = _read(kept, files)
        if listed is not None:
            return listed
    from grader.bank.template import load_banks

    bank = load_banks(folders, shipped)
    listed = [Listed.of(template) for template in bank.values()]
    # The bytes each template was read from, not those hashed above: a file edited meanwhile is read again.
    write_entry(kept, {"key": _key(), "files": [[t.where, t.source_hash] for t in bank.values()],
                        "templates": [asdict(row) for row in listed]})
    return listed


def _files(sources: Sequence[Path]) -> list[list[str]] | None:
    """Each template file of the banks with the SHA-256 of its bytes, as the bank is read; None when a folder
    or file cannot be read (then reading the banks says why, in its order)."""
    try:
        return [[str(path), _digest(read_bytes(path, YAML_BYTES))] for folder in sources
                for path in template_files(folder)]
    except GraderError:
        return None


def _read(kept: Path | None, files: list[list[str]]) -> list[Listed] | None:
    stored = read_entry(kept)
    if not isinstance(stored, dict) or stored.get("files") != files or stored.get("key") != _key():
        return None
    try:
        return [Listed.from_json(row) for row in stored["templates"]]
    except (KeyError, TypeError, ValueError):
        return None


@lru_cache(maxsize=1)
def _key() -> str:
    return source_fingerprint(PACKAGE, SOURCES, f"listing {FORMAT}", LIBRARIES)


def _digest(data: str | bytes) -> str:
    return hashlib.sha256(data.encode() if isinstance(data, str) else data).hexdigest()
