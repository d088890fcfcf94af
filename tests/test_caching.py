"""What YAML files read as, kept on disk by grader.base.inputs.parse_yaml through grader.base.caching: the same
bytes read back exactly, refusals made every time with their messages, damaged entries read as misses."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import pytest
from hypothesis import given
from hypothesis import strategies as st

import grader.base.yaml_loader
from grader.base import caching
from grader.base.errors import GraderError
from grader.base.inputs import YAML_SOURCES, parse_yaml, plain_data
from grader.base.resources import bank_dir, sample_dir
from grader.base.yaml_loader import load_yaml

SHIPPED = sorted(bank_dir().glob("*.yaml")) + sorted(sample_dir().glob("*.yaml"))


@pytest.fixture
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """An empty cache folder of this test's own."""
    folder = tmp_path / "cache"
    monkeypatch.setenv("GRADER_CACHE_DIR", str(folder))
    return folder


def same(a: Any, b: Any) -> bool:
    """Equal, and of the same types throughout (1 is not 1.0 nor True; -0.0 is not 0.0)."""
    if type(a) is not type(b):
        return False
    if isinstance(a, dict):
        return list(a) == list(b) and all(same(a[key], b[key]) for key in a)
    if isinstance(a, list):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, float):
        return a == b and math.copysign(1, a) == math.copysign(1, b)
    return bool(a == b)


def no_loading(monkeypatch: pytest.MonkeyPatch) -> None:
    """From here on, reading YAML with PyYAML fails the test: the data must come from the entry."""
    def fail(*args: object) -> None:
        raise AssertionError("the YAML was read again")

    monkeypatch.setattr(grader.base.yaml_loader, "load_yaml", fail)


@pytest.mark.parametrize("path", SHIPPED, ids=lambda path: path.name)
def test_each_shipped_file_reads_back_as_pyyaml_reads_it(cache: Path, path: Path,
                                                        monkeypatch: pytest.MonkeyPatch) -> None:
    data = path.read_bytes()
    fresh = load_yaml(data.decode("utf-8"), path)
    assert same(parse_yaml(data, path), fresh)
    assert len(list(cache.glob("yaml-*.json"))) == 1
    no_loading(monkeypatch)
    assert same(parse_yaml(data, path), fresh)


@pytest.mark.parametrize(("text", "message"), [
    ("h: 1\nh: 2\n", "a.yaml: line 2: the key 'h' appears twice (expected each key once)"),
    ("h: [1, 2\n", "a.yaml: expected valid YAML, got expected ',' or ']', but got '<stream end>'"),
    ("h: 1e999\n", "a.yaml: line 1: expected a finite number within float64"),
], ids=["duplicate key", "broken", "overflow"])
def test_a_refused_file_is_refused_every_time_and_kept_nowhere(cache: Path, text: str, message: str) -> None:
    for _ in range(2):
        with pytest.raises(GraderError, match=message.replace("[", r"\[").replace("(", r"\(").replace(")", r"\)")):
            parse_yaml(text.encode(), Path("a.yaml"))
    assert not list(cache.glob("yaml-*.json"))


@pytest.mark.parametrize("text", ["a: &x [1, 2]\nb: *x\n", "t: !!timestamp 2024-01-01\n", "s: !!set {a, b}\n",
                                  "b: !!binary aGVsbG8=\n"], ids=["alias", "timestamp", "set", "binary"])
def test_data_json_would_not_give_back_is_read_each_time(cache: Path, text: str) -> None:
    first = parse_yaml(text.encode(), Path("a.yaml"))
    assert not list(cache.glob("yaml-*.json"))
    assert parse_yaml(text.encode(), Path("a.yaml")) == first


@pytest.mark.parametrize("damage", ["", '{"data": ', "[1]", '{"data": 1, "more": 2}', '{"other": {}}'],
                         ids=["empty", "cut short", "a list", "extra key", "no data"])
def test_a_damaged_entry_is_a_miss(cache: Path, damage: str) -> None:
    text = b"h: 1\nlist: [1, 2.5]\n"
    first = parse_yaml(text, Path("a.yaml"))
    (entry,) = cache.glob("yaml-*.json")
    entry.write_text(damage, encoding="utf-8")
    assert same(parse_yaml(text, Path("a.yaml")), first)
    assert same(caching.read_entry(entry)["data"], first)  # written again


@pytest.mark.parametrize("stored", [[1], {"data": 1, "more": 2}, {"other": {}}, None],
                         ids=["a list", "extra key", "no data", "null"])
def test_an_entry_of_the_wrong_shape_is_a_miss(cache: Path, stored: Any) -> None:
    """Written as grader writes entries (under its name, with its digest): only its shape is wrong."""
    text = b"h: 1\nlist: [1, 2.5]\n"
    first = parse_yaml(text, Path("a.yaml"))
    (entry,) = cache.glob("yaml-*.json")
    caching.write_entry(entry, stored)
    assert same(parse_yaml(text, Path("a.yaml")), first)
    assert same(caching.read_entry(entry)["data"], first)


def test_a_cache_that_cannot_be_written_only_costs_time(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    blocked = tmp_path / "a-file"
    blocked.write_text("not a folder", encoding="utf-8")
    monkeypatch.setenv("GRADER_CACHE_DIR", str(blocked / "cache"))
    for _ in range(2):
        assert parse_yaml(b"h: 1\n", Path("a.yaml")) == {"h": 1}


def test_an_edit_of_the_yaml_reader_reads_files_again(tmp_path: Path) -> None:
    """The key covers the reader's source: the same bytes under an edited reader are another entry."""
    import shutil

    copy = tmp_path / "grader"
    shutil.copytree(caching.PACKAGE, copy, ignore=shutil.ignore_patterns("__pycache__"))
    sources, salt = YAML_SOURCES, "yaml 1"
    before = caching.source_fingerprint(copy, sources, salt, ("yaml",))
    loader = copy / "base" / "yaml_loader.py"
    loader.write_text(loader.read_text(encoding="utf-8") + "\n# reads differently\n", encoding="utf-8")
    assert caching.source_fingerprint(copy, sources, salt, ("yaml",)) != before


PLAIN = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats(allow_nan=False, allow_infinity=False) | st.text(),
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(st.text(), inner, max_size=4), max_leaves=20)


@given(PLAIN)
def test_json_gives_back_exactly_what_plain_data_accepts(data: Any) -> None:
    assert plain_data(data)
    assert same(json.loads(json.dumps(data)), data)


def test_without_a_home_folder_nothing_is_kept_and_everything_works(monkeypatch: pytest.MonkeyPatch) -> None:
    """No $GRADER_CACHE_DIR, no $XDG_CACHE_HOME, and Path.home() finds none (no $HOME, a user id without a
    password entry): files are read, and the bank listed, each time."""
    from grader.bank.listing import listing
    from grader.bank.template import load_banks

    def no_home(cls: type[Path]) -> Path:
        raise RuntimeError("Could not determine home directory.")

    for name in ("GRADER_CACHE_DIR", "XDG_CACHE_HOME"):
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setattr(Path, "home", classmethod(no_home))
    assert caching.entry("anything.json") is None
    for _ in range(2):
        assert parse_yaml(b"h: 1\n", Path("a.yaml")) == {"h": 1}
        assert [row.id for row in listing()] == list(load_banks())


def _yaml_entry(cache: Path, text: bytes) -> Path:
    """Where parse_yaml keeps what ``text`` reads as (after reading it once)."""
    parse_yaml(text, Path("a.yaml"))
    (entry,) = cache.glob("yaml-*.json")
    return entry


def _in_time(work: Any, seconds: float = 20) -> Any:
    """``work()``'s result, failing the test if it has none within ``seconds`` (a blocked read never returns)."""
    import threading

    results: list[Any] = []
    thread = threading.Thread(target=lambda: results.append(work()), daemon=True)
    thread.start()
    thread.join(seconds)
    assert results, f"still running after {seconds} s"
    return results[0]


def test_an_entry_that_is_a_named_pipe_is_a_miss_not_a_hang(cache: Path) -> None:
    """Opening a FIFO for reading waits for a writer: `grader list` hung for good on one."""
    import os

    text = b"h: 1\n"
    entry = _yaml_entry(cache, text)
    entry.unlink()
    os.mkfifo(entry)
    assert _in_time(lambda: parse_yaml(text, Path("a.yaml"))) == {"h": 1}


@pytest.mark.parametrize("device", ["/dev/zero", "/dev/urandom"])
def test_an_entry_that_is_a_device_is_a_miss_not_a_memory_error(cache: Path, device: str) -> None:
    """An entry linked to an endless device was read whole: MemoryError."""
    text = b"h: 1\n"
    entry = _yaml_entry(cache, text)
    entry.unlink()
    entry.symlink_to(device)
    assert _in_time(lambda: parse_yaml(text, Path("a.yaml"))) == {"h": 1}


def test_an_entry_nested_deeper_than_json_reads_is_a_miss_not_a_recursion_error(cache: Path) -> None:
    text = b"h: 1\n"
    entry = _yaml_entry(cache, text)
    entry.write_text('{"data": ' + "[" * 100_000 + "]" * 100_000 + "}", encoding="utf-8")
    assert parse_yaml(text, Path("a.yaml")) == {"h": 1}


def test_an_entry_larger_than_any_grader_writes_is_not_read(cache: Path) -> None:
    text = b"h: 1\n"
    entry = _yaml_entry(cache, text)
    with entry.open("r+b") as stream:
        stream.truncate(caching.ENTRY_BYTES + 1)  # what is in it is never looked at
    assert parse_yaml(text, Path("a.yaml")) == {"h": 1}


def test_data_larger_than_an_entry_may_be_is_not_kept(cache: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(caching, "ENTRY_BYTES", 200)  # 113 bytes of seal
    caching.write_entry(cache / "big.json", {"text": "x" * 100})
    caching.write_entry(cache / "small.json", {"text": "x"})
    assert [path.name for path in cache.iterdir()] == ["small.json"]


def test_an_entry_moved_under_another_files_name_is_a_miss(cache: Path) -> None:
    """What another file reads as, under this file's name (copied, restored from a backup): this file's data was
    taken to be the other's."""
    parse_yaml(b"h: 2\n", Path("b.yaml"))
    (other,) = cache.glob("yaml-*.json")
    entry = _yaml_entry_beside(cache, b"h: 1\n")
    entry.write_bytes(other.read_bytes())
    assert parse_yaml(b"h: 1\n", Path("a.yaml")) == {"h": 1}


def _yaml_entry_beside(cache: Path, text: bytes) -> Path:
    before = set(cache.glob("yaml-*.json"))
    parse_yaml(text, Path("a.yaml"))
    (entry,) = set(cache.glob("yaml-*.json")) - before
    return entry


def test_an_entry_changed_since_it_was_written_is_a_miss(cache: Path) -> None:
    """A number changed in an entry that stays JSON of the right shape (a flipped bit, a hand edit) changed the
    result."""
    entry = _yaml_entry(cache, b"h: 12345\n")
    entry.write_bytes(entry.read_bytes().replace(b"12345", b"12945"))
    assert parse_yaml(b"h: 12345\n", Path("a.yaml")) == {"h": 12345}


def test_an_entry_another_user_wrote_is_a_miss(cache: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Whoever can write the cache folder decided what a template read as: only this user's entries (or root's)
    are read."""
    import os

    entry = _yaml_entry(cache, b"h: 1\n")
    caching.write_entry(entry, {"data": {"h": 7}})  # what another user could write
    assert parse_yaml(b"h: 1\n", Path("a.yaml")) == {"h": 7}  # mine: read
    if os.geteuid() == 0:
        os.chown(entry, 65534, 65534)
    else:
        monkeypatch.setattr(os, "geteuid", lambda: os.getuid() + 1)
    assert parse_yaml(b"h: 1\n", Path("a.yaml")) == {"h": 1}


@pytest.mark.parametrize("mode", [0o666, 0o646, 0o664], ids=["anyone", "others", "the group"])
def test_an_entry_others_may_write_is_a_miss_and_written_again_for_me_alone(cache: Path, mode: int) -> None:
    import os

    caching_entry = _yaml_entry(cache, b"h: 1\n")
    caching.write_entry(caching_entry, {"data": {"h": 7}})
    os.chmod(caching_entry, mode)
    assert parse_yaml(b"h: 1\n", Path("a.yaml")) == {"h": 1}
    assert caching_entry.stat().st_mode & 0o022 == 0
    assert caching.read_entry(caching_entry) == {"data": {"h": 1}}


def test_entries_are_written_for_me_alone_whatever_the_umask(cache: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Under umask 002 (many distributions' default for users) entries were group-writable."""
    import grader.base.files

    monkeypatch.setattr(grader.base.files, "UMASK", 0o002)
    entry = _yaml_entry(cache, b"h: 1\n")
    assert entry.stat().st_mode & 0o777 == 0o644


@pytest.mark.parametrize("data", [{"h": float("nan")}, {"h": [1, float("inf")]}, {"h": -float("inf")}],
                         ids=["NaN", "Infinity", "-Infinity"])
def test_an_entry_holding_what_no_yaml_file_reads_as_is_a_miss(cache: Path, data: Any) -> None:
    """JSON's NaN and Infinity tokens were read back as numbers no YAML file gives (the loader refuses them): a
    template's `version: NaN` was refused, naming the user's file."""
    entry = _yaml_entry(cache, b"h: 1\n")
    caching.write_entry(entry, {"data": data})
    assert parse_yaml(b"h: 1\n", Path("a.yaml")) == {"h": 1}
