"""`grader cache` says where the cache is and how much it holds; `grader cache clear` removes grader's own
entries there and nothing else (a run deletes nothing it did not write)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from grader.base import caching
from grader.cli import main


@pytest.fixture
def folder(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A cache folder holding two of grader's entries and what a user put there."""
    folder = tmp_path / "cache"
    monkeypatch.setenv("GRADER_CACHE_DIR", str(folder))
    caching.write_entry(folder / "yaml-1.json", {"data": [1]})
    caching.write_entry(folder / "drop-rebound-0123.json", {"steps": []})
    (folder / "notes.json").write_text('{"mine": true}', encoding="utf-8")  # JSON, not sealed
    (folder / "README").write_text("my notes", encoding="utf-8")
    (folder / "sub").mkdir()
    caching.write_entry(folder / "sub" / "yaml-2.json", {"data": [2]})  # not where grader keeps entries
    sealed_elsewhere = caching.seal("yaml-9.json", b"[9]")
    (folder / "renamed.json").write_bytes(sealed_elsewhere)  # sealed under another name: not grader's here
    caching.write_entry(tmp_path / "elsewhere" / "yaml-3.json", {"data": [3]})
    (folder / "yaml-3.json").symlink_to(tmp_path / "elsewhere" / "yaml-3.json")  # the user's link to one
    return folder


def _run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str]:
    code = main(["cache", *argv])
    return code, capsys.readouterr().out


def test_cache_says_where_and_how_much(folder: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, out = _run(capsys, "--json")
    summary = json.loads(out)
    assert code == 0
    assert summary["folder"] == str(folder) and summary["entries"] == 2
    assert summary["bytes"] == sum((folder / n).stat().st_size for n in ("yaml-1.json", "drop-rebound-0123.json"))
    code, out = _run(capsys)
    assert out.startswith(f"{folder}: 2 entries, ")


def test_clear_removes_graders_entries_and_nothing_else(folder: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, out = _run(capsys, "clear")
    assert code == 0 and out.startswith("removed 2 entries (") and str(folder) in out
    assert sorted(p.name for p in folder.iterdir()) == ["README", "notes.json", "renamed.json", "sub",
                                                              "yaml-3.json"]
    assert (folder / "sub" / "yaml-2.json").exists()
    assert _run(capsys, "clear", "--json")[1].strip() == json.dumps({"folder": str(folder), "removed": 0, "bytes": 0})


def test_a_cache_folder_that_is_not_there_holds_nothing(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                        capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setenv("GRADER_CACHE_DIR", str(tmp_path / "never made"))
    assert _run(capsys, "clear") == (0, f"removed 0 entries (0 bytes) from {tmp_path / 'never made'}\n")
    assert not (tmp_path / "never made").exists()


def test_an_unknown_action_is_a_usage_error(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as stopped:
        main(["cache", "purge"])
    assert stopped.value.code == 2
    assert "invalid choice: 'purge'" in capsys.readouterr().err


def test_entries_a_run_writes_are_what_clear_removes(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                     capsys: pytest.CaptureFixture[str]) -> None:
    """A real run's entries (what its YAML files read as, the bank's listing) are all grader's."""
    monkeypatch.setenv("GRADER_CACHE_DIR", str(tmp_path / "cache"))
    assert main(["list"]) == 0
    written = sorted(p.name for p in (tmp_path / "cache").iterdir())
    assert written and all(p.endswith(".json") for p in written)
    capsys.readouterr()
    assert _run(capsys, "clear")[1].startswith(f"removed {len(written)} entries")
    assert not list((tmp_path / "cache").iterdir())


def test_a_cache_folder_that_is_a_file_is_a_usage_error(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                        capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "a file").write_text("mine", encoding="utf-8")
    monkeypatch.setenv("GRADER_CACHE_DIR", str(tmp_path / "a file"))
    assert main(["cache", "clear"]) == 2
    assert f"the cache folder {tmp_path / 'a file'} is a file, not a folder" in capsys.readouterr().err
    assert (tmp_path / "a file").read_text(encoding="utf-8") == "mine"
