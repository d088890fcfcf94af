"""The output-folder mechanism of ``grader.files``: manifests, refusals, and errors that name their path."""

from __future__ import annotations

import errno
import hashlib
import json
import os
import signal
from collections.abc import Iterator
from pathlib import Path

import pytest

from grader.errors import GraderError
from grader.files import MANIFEST, describe_os_error, manifest_mismatches, output_folder, write_atomic


def _written(folder: Path) -> Path:
    with output_folder(folder, command="test") as staging:
        write_atomic(staging / "key.csv", "id\n")
        write_atomic(staging / "students" / "1.pdf", b"%PDF")
    return folder


def test_the_manifest_lists_every_file_with_its_sha256_and_every_folder(tmp_path: Path) -> None:
    """What a run wrote, and nothing else: files by relative name, folders, the command."""
    manifest = json.loads((_written(tmp_path / "out") / MANIFEST).read_text(encoding="utf-8"))
    assert manifest["schema"] == "grader-manifest" and manifest["command"] == "test"
    assert manifest["folders"] == ["students"]
    assert manifest["files"] == {"key.csv": hashlib.sha256(b"id\n").hexdigest(),
                                 "students/1.pdf": hashlib.sha256(b"%PDF").hexdigest()}


def test_a_file_gone_from_an_output_is_no_mismatch_but_a_link_is(tmp_path: Path) -> None:
    """Replacing a folder with a file missing loses nothing; a link in it is something grader never writes."""
    out = _written(tmp_path / "out")
    (out / "key.csv").unlink()
    assert manifest_mismatches(out) == []
    (out / "elsewhere").symlink_to(tmp_path)
    assert manifest_mismatches(out) == ["elsewhere (a link or special file, not written by grader)"]


def test_force_replaces_an_output_that_matches_its_manifest(tmp_path: Path) -> None:
    """The previous output goes (it is what a run wrote); the new one comes with its own manifest."""
    out = _written(tmp_path / "out")
    with output_folder(out, command="test", force=True) as staging:
        write_atomic(staging / "grades.csv", "id,score\n")
    assert sorted(p.name for p in out.iterdir()) == [MANIFEST, "grades.csv"]
    assert [p.name for p in tmp_path.iterdir()] == ["out"]


@pytest.mark.skipif(not hasattr(signal, "pthread_sigmask"), reason="needs pthread_sigmask")
def test_ctrl_c_between_the_two_renames_of_force_leaves_one_whole_output(tmp_path: Path,
                                                                          monkeypatch: pytest.MonkeyPatch) -> None:
    """--force moves the previous output aside, then the new one in. A Ctrl-C between the two left no
    output at --out (the previous one stranded in the work folder, which then blocked every later run);
    now the signal waits for the second rename, and the run ends with the new output in place."""
    import grader.files

    out = _written(tmp_path / "out")
    renames, rename = [], os.rename

    def rename_then_interrupt(source: str, destination: str) -> None:
        rename(source, destination)
        renames.append(destination)
        if len(renames) == 1:  # the previous output just went aside
            signal.raise_signal(signal.SIGINT)

    monkeypatch.setattr(grader.files.os, "rename", rename_then_interrupt)
    with pytest.raises(KeyboardInterrupt), output_folder(out, command="test", force=True) as staging:
        write_atomic(staging / "grades.csv", "id,score\n")
    assert len(renames) == 2
    assert sorted(p.name for p in out.iterdir()) == [MANIFEST, "grades.csv"]
    assert [p.name for p in tmp_path.iterdir()] == ["out"]


def test_an_exception_inside_leaves_no_work_folder_and_no_new_parents(tmp_path: Path) -> None:
    """A failing run removes its work folder and the folders it made above --out."""
    with pytest.raises(RuntimeError), output_folder(tmp_path / "a" / "b" / "out", command="test") as staging:
        write_atomic(staging / "key.csv", "id\n")
        raise RuntimeError("stop")
    assert list(tmp_path.iterdir()) == []


def test_an_os_error_inside_names_the_output_path_not_the_work_folder(tmp_path: Path) -> None:
    """ENOSPC on a file being written in the work folder is shown as the file it stands for in --out."""
    out = tmp_path / "out"
    with pytest.raises(GraderError) as caught, output_folder(out, command="test") as staging:
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(staging / "students" / "1.pdf"))
    assert str(caught.value) == (f"{out / 'students' / '1.pdf'}: No space left on device; nothing was written to "
                                 f"{out}; free some space and run again")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs /dev/full")
def test_write_atomic_on_a_full_disk_names_the_file_and_leaves_no_temporary(tmp_path: Path,
                                                                           monkeypatch: pytest.MonkeyPatch) -> None:
    """A failed write() names no file; write_atomic's error names the one it was writing."""
    import grader.files

    def full(handle: int, mode: str = "rb") -> object:
        os.close(handle)
        return open("/dev/full", mode)

    monkeypatch.setattr(grader.files.os, "fdopen", full)
    with pytest.raises(OSError) as caught:
        write_atomic(tmp_path / "key.json", "{}")
    monkeypatch.undo()
    assert (caught.value.errno, caught.value.filename) == (errno.ENOSPC, str(tmp_path / "key.json"))
    assert list(tmp_path.iterdir()) == []


def test_write_atomic_writes_text_in_pieces_and_nothing_when_they_fail(tmp_path: Path) -> None:
    """Text in pieces (details.csv of a big class) is written as it comes, as UTF-8; a failure while the
    pieces come leaves the file as it was and no temporary beside it."""
    write_atomic(tmp_path / "details.csv", iter(["a,±1 %\n", "", "b,2\n"]))
    assert (tmp_path / "details.csv").read_bytes() == "a,±1 %\nb,2\n".encode()

    def broken() -> Iterator[str]:
        yield "c,3\n"
        raise RuntimeError("a bug while writing")

    with pytest.raises(RuntimeError):
        write_atomic(tmp_path / "details.csv", broken())
    assert [p.name for p in tmp_path.iterdir()] == ["details.csv"]
    assert (tmp_path / "details.csv").read_text(encoding="utf-8") == "a,±1 %\nb,2\n"


def test_describe_os_error_says_where_why_and_what_to_do() -> None:
    """The path, the operating system's reason, then the advice."""
    error = OSError(errno.ENAMETOOLONG, os.strerror(errno.ENAMETOOLONG), "x" * 300)
    assert describe_os_error(error) == f"{'x' * 300}: File name too long; choose a shorter name"
