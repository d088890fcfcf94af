"""The bank's listing kept on disk: read back only for the same files with the same bytes and the same grader;
anything else reads and checks the banks again, with their messages."""

from __future__ import annotations

import os
import shutil
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

import grader.bank.template
from grader.bank import listing as listing_module
from grader.bank.listing import Listed, listing
from grader.bank.template import load_banks
from grader.base import caching
from grader.base.errors import GraderError
from grader.base.resources import bank_dir
from tests.test_layout import GRAPH, stage_of


@pytest.fixture
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """An empty cache folder of this test's own."""
    folder = tmp_path / "cache"
    monkeypatch.setenv("GRADER_CACHE_DIR", str(folder))
    return folder


@pytest.fixture
def mine(tmp_path: Path) -> Path:
    """A bank folder of two templates copied from the shipped bank: my-drop and my-pile."""
    folder = tmp_path / "mine"
    folder.mkdir()
    for template_id, mine in (("drop-rebound", "my-drop"), ("pile-driver", "my-pile")):
        text = (bank_dir() / f"{template_id}.yaml").read_text(encoding="utf-8")
        (folder / f"{mine}.yaml").write_text(text.replace(f"id: {template_id}", f"id: {mine}"), encoding="utf-8")
    return folder


def expected(folders: list[Path], shipped: bool = True) -> list[Listed]:
    return [Listed.of(template) for template in load_banks(folders, shipped).values()]


def no_reading(monkeypatch: pytest.MonkeyPatch) -> None:
    """From here on, reading the banks fails the test: the listing must come from the entry."""
    def fail(*args: object, **kwargs: object) -> None:
        raise AssertionError("the banks were read again")

    monkeypatch.setattr(grader.bank.template, "load_banks", fail)


def test_the_listing_is_what_loading_the_banks_gives(cache: Path, mine: Path) -> None:
    for folders, shipped in (([], True), ([mine], False), ([mine], True)):
        first = listing(folders, shipped)
        assert first == expected(folders, shipped) == listing(folders, shipped)
    assert len(list(cache.glob("bank-*.json"))) == 3  # one entry for each set of banks


def test_a_second_listing_reads_no_template(cache: Path, mine: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    first = listing([mine], False)
    no_reading(monkeypatch)
    assert listing([mine], False) == first


def test_an_edit_that_keeps_size_and_time_is_seen(cache: Path, mine: Path) -> None:
    """The entry is keyed by the bytes, not by the size or modification time a quick edit may keep."""
    listing([mine], False)
    path = mine / "my-pile.yaml"
    status = path.stat()
    text = path.read_text(encoding="utf-8")
    title = next(line for line in text.splitlines() if line.startswith("title:"))
    path.write_text(text.replace(title, "title: " + "X" * (len(title) - len("title: "))), encoding="utf-8")
    os.utime(path, ns=(status.st_atime_ns, status.st_mtime_ns))
    assert path.stat().st_size == status.st_size
    titles = {row.id: row.title for row in listing([mine], False)}
    assert set(titles["my-pile"]) == {"X"}


def test_a_template_added_or_removed_is_seen(cache: Path, mine: Path) -> None:
    listing([mine], False)
    shutil.copy(bank_dir() / "car-collision.yaml", mine)
    assert [row.id for row in listing([mine], False)] == ["car-collision", "my-drop", "my-pile"]
    (mine / "my-drop.yaml").unlink()
    assert [row.id for row in listing([mine], False)] == ["car-collision", "my-pile"]


@pytest.mark.parametrize("breaking", [
    ("my-pile.yaml", "unit: kg", "unit: furlongs"),
    ("my-pile.yaml", "title:", "title: [a, list]\nx_title:"),
    ("my-drop.yaml", "id: my-drop", "id: my-drop\nid: again"),
], ids=["bad unit", "unknown key", "duplicate key"])
def test_a_broken_template_is_refused_with_the_banks_message_every_time(
        cache: Path, mine: Path, breaking: tuple[str, str, str]) -> None:
    listing([mine], False)  # an entry for the good bank
    name, old, new = breaking
    path = mine / name
    path.write_text(path.read_text(encoding="utf-8").replace(old, new, 1), encoding="utf-8")
    with pytest.raises(GraderError) as loading:
        load_banks([mine], False)
    for _ in range(2):
        with pytest.raises(GraderError) as listed:
            listing([mine], False)
        assert str(listed.value) == str(loading.value)


def test_folders_that_cannot_be_listed_are_refused_as_loading_refuses_them(cache: Path, mine: Path,
                                                                           tmp_path: Path) -> None:
    """A missing or empty folder after one with a broken template: the template's message comes first."""
    listing([mine], False)
    (tmp_path / "empty").mkdir()
    (mine / "my-pile.yaml").write_text("id: [", encoding="utf-8")
    for folders in ([tmp_path / "nowhere"], [tmp_path / "empty"], [mine, tmp_path / "nowhere"]):
        with pytest.raises(GraderError) as loading:
            load_banks(folders, False)
        with pytest.raises(GraderError) as listed:
            listing(folders, False)
        assert str(listed.value) == str(loading.value)


def _rows_retyped(entry: Any) -> Any:
    """The right key and files, a row whose version is text: read as a miss, not trusted."""
    entry["templates"][0]["version"] = str(entry["templates"][0]["version"])
    return entry


def _row_renamed(entry: Any) -> Any:
    entry["templates"][0]["there"] = entry["templates"][0].pop("where")
    return entry


CUT = {"empty": lambda text: b"", "cut short": lambda text: text[:len(text) // 2],
       "a digit changed": lambda text: text.replace(b'"version": 1', b'"version": 2', 1)}
DAMAGE = {"a list": lambda entry: [], "null": lambda entry: None, "no key": lambda entry: {"templates": []},
          "bad rows": _rows_retyped, "a row missing": _row_renamed}


@pytest.mark.parametrize("damage", CUT.values(), ids=CUT.keys())
def test_a_damaged_entry_is_a_miss(cache: Path, mine: Path, monkeypatch: pytest.MonkeyPatch,
                                   damage: Callable[[bytes], bytes]) -> None:
    good = listing([mine], False)
    (entry,) = cache.glob("bank-*.json")
    entry.write_bytes(damage(entry.read_bytes()))
    assert listing([mine], False) == good
    no_reading(monkeypatch)
    assert listing([mine], False) == good  # and written again


def test_an_entry_that_is_not_utf8_is_a_miss(cache: Path, mine: Path) -> None:
    good = listing([mine], False)
    (entry,) = cache.glob("bank-*.json")
    entry.write_bytes(b"\xff\xfe{")
    assert listing([mine], False) == good


def test_a_cache_that_cannot_be_written_only_costs_time(tmp_path: Path, mine: Path,
                                                        monkeypatch: pytest.MonkeyPatch) -> None:
    blocked = tmp_path / "a-file"
    blocked.write_text("not a folder", encoding="utf-8")
    monkeypatch.setenv("GRADER_CACHE_DIR", str(blocked / "cache"))
    assert listing([mine], False) == listing([mine], False) == expected([mine], False)


def test_an_entry_made_by_another_grader_is_a_miss(cache: Path, mine: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    listing([mine], False)
    (entry,) = cache.glob("bank-*.json")
    stale = caching.read_entry(entry)
    for row in stale["templates"]:
        row["title"] = "stale " + row["title"]
    caching.write_entry(entry, stale)
    monkeypatch.setattr(listing_module, "_key", lambda: "another grader's key")
    assert all(not row.title.startswith("stale") for row in listing([mine], False))


def test_the_key_covers_everything_reading_a_template_runs() -> None:
    """Editing any file that loading a template imports must make the listing read the banks again."""
    needed: set[str] = set()
    todo = ["grader.bank.template"]
    while todo:
        module = todo.pop()
        if module not in needed and module != "grader.base.caching":  # it keeps what reading gives, never decides it
            needed.add(module)
            todo.extend(GRAPH[module])
    covered = {name.removesuffix(".py") for name in listing_module.SOURCES}

    def is_covered(module: str) -> bool:
        if stage_of(module) == "base":  # the bottom layer (or grader itself: its version is in the key)
            return module == "grader" or module.removeprefix("grader.").replace(".", "/") in covered
        return stage_of(module) in covered

    outside = sorted(module for module in needed if not is_covered(module))
    assert not outside, f"reading a template imports modules the listing's key does not read: {outside}"


def _first_row(**changes: Any) -> Callable[[Any], Any]:
    def change(entry: Any) -> Any:
        entry["templates"][0].update(changes)
        return entry
    return change


def _ghost(entry: Any) -> Any:
    entry["templates"].append({**entry["templates"][0], "id": "ghost", "title": "Not a template"})
    return entry


def _swapped(entry: Any) -> Any:
    entry["templates"].reverse()
    return entry


def _twice(entry: Any) -> Any:
    entry["templates"][1] = dict(entry["templates"][0])
    return entry


HOSTILE = {
    "a topic not in the list": _first_row(topic="no such topic"), "no topic": _first_row(topic=""),
    "an escape sequence": _first_row(title="\x1b[2J\x1b[31mpwned"), "a line break": _first_row(title="a\rb"),
    "an empty title": _first_row(title=""), "a title with spaces around": _first_row(title=" a "),
    "a template no file holds": _ghost,
    "a template missing": lambda entry: {**entry, "templates": entry["templates"][1:]},
    "rows swapped": _swapped, "one template twice": _twice, "an id not the file's": _first_row(id="my-other"),
    "an id with a slash": _first_row(id="../../etc/passwd"), "version 0": _first_row(version=0),
    "a parameter that is no name": _first_row(parameters=["h\x1b[31m"]), "an answer that is no name": _first_row(
        answers=["e\n"]), "a file elsewhere": _first_row(where="/etc/passwd"),
}


@pytest.mark.parametrize("damage", [*DAMAGE.values(), *HOSTILE.values()], ids=[*DAMAGE, *HOSTILE])
def test_an_entry_holding_what_no_template_file_says_is_a_miss(cache: Path, mine: Path, damage: Callable[[Any], Any],
                                                                monkeypatch: pytest.MonkeyPatch) -> None:
    """Sealed as grader seals entries, for these very files: only what it holds is wrong. A topic outside the list
    stopped `grader list` with a traceback, a title with a line break too, and a row no template file has was
    listed."""
    good = listing([mine], False)
    (entry,) = cache.glob("bank-*.json")
    caching.write_entry(entry, damage(caching.read_entry(entry)))
    assert listing([mine], False) == good
    no_reading(monkeypatch)
    assert listing([mine], False) == good  # and written again
