"""What ``grader list`` shows of each template of the banks, kept on disk: a warm listing reads no YAML and
imports neither the effects catalogue nor numpy.

An entry holds each template file's path and SHA-256 and what the listing shows of it, and is read back
only when the banks have exactly those files with exactly those bytes and grader is the same (its
version, Python's, the installed PyYAML and Jinja2, and the source of everything that reads and checks a
template: :data:`SOURCES`), and each template it lists is one its file could hold (:meth:`Listed.from_json`).
Anything else (a template edited, added or removed, an upgrade, an entry missing, unreadable, cut short or
holding what no template file says) reads and checks the banks with :func:`grader.bank.template.load_banks`,
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

from grader.bank.folders import NAME, TEMPLATE_ID, TOPICS, bank_folders, one_line, template_files
from grader.base.caching import PACKAGE, entry, read_entry, source_fingerprint, write_entry
from grader.base.errors import GraderError
from grader.base.inputs import YAML_BYTES, read_bytes

if TYPE_CHECKING:
    from grader.bank.template import Template

FORMAT = 1
SOURCES = ("model", "physics", "bank", "base/errors.py", "base/inputs.py", "base/resources.py", "base/yaml_loader.py")
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
    def from_json(cls, data: Any, where: str) -> Listed:
        """The template of the file ``where`` as :func:`dataclasses.asdict` wrote it, if it is one that file could
        hold: its id the file's name, a topic of the list, a title of one line, names that are names. Anything
        else is a ``ValueError``.

        >>> row = {"id": "drop", "title": "A drop", "topic": "drops and rebounds", "version": 1,
        ...        "where": "bank/drop.yaml", "parameters": ["h"], "answers": ["e"]}
        >>> Listed.from_json(row, "bank/drop.yaml").title
        'A drop'
        >>> Listed.from_json({**row, "title": "\\x1b[2J"}, "bank/drop.yaml")
        Traceback (most recent call last):
        ...
        ValueError: not a template of bank/drop.yaml: ...
        """
        if not _is_row(data):
            raise ValueError(f"not a listed template: {data!r:.100}")
        listed = cls(data["id"], data["title"], data["topic"], data["version"], data["where"],
                     tuple(data["parameters"]), tuple(data["answers"]))
        if not listed._could_be_in(where):
            raise ValueError(f"not a template of {where}: {data!r:.100}")
        return listed

    def _could_be_in(self, where: str) -> bool:
        """Whether the template file ``where`` could read as this (as :mod:`grader.bank.template` checks one)."""
        return (self.where == where and self.id == Path(where).stem and bool(TEMPLATE_ID.match(self.id))
                and self.topic in TOPICS and self.version >= 1
                and bool(self.title) and self.title == self.title.strip() and one_line(self.title)
                and all(NAME.match(name) for name in self.parameters + self.answers))


def _is_row(data: Any) -> bool:
    """Whether ``data`` is a :class:`Listed` as :func:`dataclasses.asdict` writes one, field by field."""
    return (isinstance(data, dict) and set(data) == {field.name for field in fields(Listed)}
            and all(isinstance(data[key], str) for key in ("id", "title", "topic", "where"))
            and type(data["version"]) is int
            and all(isinstance(names, list) and all(isinstance(name, str) for name in names)
                    for names in (data["parameters"], data["answers"])))


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
    """The listing kept for exactly these files, a template for each, in their order; None for anything else."""
    stored = read_entry(kept)
    if not isinstance(stored, dict) or stored.get("files") != files or stored.get("key") != _key():
        return None
    rows = stored.get("templates")
    if not isinstance(rows, list) or len(rows) != len(files):
        return None
    try:
        listed = [Listed.from_json(row, where) for row, (where, _) in zip(rows, files, strict=True)]
    except ValueError:
        return None
    return listed if len({row.id for row in listed}) == len(listed) else None


@lru_cache(maxsize=1)
def _key() -> str:
    return source_fingerprint(PACKAGE, SOURCES, f"listing {FORMAT}", LIBRARIES)


def _digest(data: str | bytes) -> str:
    return hashlib.sha256(data.encode() if isinstance(data, str) else data).hexdigest()
