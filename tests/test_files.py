"""The output-folder mechanism of ``grader.base.files``: manifests, refusals, and errors that name their path."""

from __future__ import annotations

import errno
import hashlib
import json
import os
import signal
from collections.abc import Iterator
from pathlib import Path

import pytest

from grader.base.errors import GraderError
from grader.base.files import MANIFEST, describe_os_error, manifest_mismatches, output_folder, write_atomic
from tests.demo_output import DemoRun


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
    import grader.base.files

    out = _written(tmp_path / "out")
    renames, rename = [], os.rename

    def rename_then_interrupt(source: str, destination: str) -> None:
        rename(source, destination)
        renames.append(destination)
        if len(renames) == 1:  # the previous output just went aside
            signal.raise_signal(signal.SIGINT)

    monkeypatch.setattr(grader.base.files.os, "rename", rename_then_interrupt)
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
    import grader.base.files

    def full(handle: int, mode: str = "rb") -> object:
        os.close(handle)
        return open("/dev/full", mode)

    monkeypatch.setattr(grader.base.files.os, "fdopen", full)
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


# --- --force replaces only what the same command wrote (issue 22, item 1) ---------------------------------


def _tree(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def _refused(capsys: pytest.CaptureFixture[str], *argv: object) -> str:
    from grader.cli import main

    code = main([str(a) for a in argv])
    captured = capsys.readouterr()
    assert (code, captured.out) == (2, ""), captured.err
    assert captured.err.count("\n") == 1 and "Traceback" not in captured.err, captured.err
    return captured.err


def _other_commands(demo: Path, elsewhere: Path) -> dict[str, list[object]]:
    """Each command, with inputs outside the folders it is pointed at (copies of the demo's own)."""
    from grader.base.resources import sample_dir

    elsewhere.mkdir()
    key, submissions = elsewhere / "key.json", elsewhere / "submissions.csv"
    key.write_bytes((demo / "key.json").read_bytes())
    submissions.write_bytes((demo / "submissions.csv").read_bytes())
    return {"grader grade": ["grade", "--key", key, submissions, "--force"],
            "grader generate": ["generate", sample_dir() / "assignment.yaml", "--roster", sample_dir() / "roster.csv",
                                "--no-pdf", "--force"],
            "grader demo": ["demo", "--force"]}


@pytest.mark.parametrize(("command", "folder", "writer"), [
    ("grader grade", ".", "grader demo"),  # deleted the demo's PDFs, students/, key.json, submissions.csv ...
    ("grader generate", "grades", "grader grade"),  # deleted a grading run's grades.csv, details.csv, canvas.csv
    ("grader demo", "grades", "grader grade"),
    ("grader generate", ".", "grader demo"),
], ids=["grade-over-a-demo", "generate-over-grades", "demo-over-grades", "generate-over-a-demo"])
def test_force_does_not_replace_a_folder_another_command_wrote(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], demo_run: DemoRun, command: str, folder: str,
        writer: str) -> None:
    """`--force` replaced a folder written by any grader command; now it names the command that wrote it
    and says to choose another --out, and the folder is left byte for byte."""
    import shutil

    demo = tmp_path / "grader-demo"
    shutil.copytree(demo_run.out, demo)
    argv = _other_commands(demo, tmp_path / "elsewhere")[command]
    out = demo / folder if folder != "." else demo
    before = _tree(demo)
    err = _refused(capsys, *argv, "--out", out)
    assert (f"{out}: written by {writer} (as its {MANIFEST} says); {command} --force replaces only a folder "
            f"{command} wrote, never another command's files; choose another --out") in err
    assert _tree(demo) == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["elsewhere", "grader-demo"]


@pytest.mark.parametrize("written_by", [None, "", 7, "grader\x1b[31m grade"], ids=["none", "empty", "number",
                                                                                  "escape"])
def test_force_does_not_replace_a_folder_whose_manifest_names_no_command_of_ours(tmp_path: Path,
                                                                                written_by: object) -> None:
    """A manifest without the command, or with one that is not text: refused, its value shown as data."""
    out = _written(tmp_path / "out")
    manifest = json.loads((out / MANIFEST).read_text(encoding="utf-8"))
    manifest["command"] = written_by
    if written_by is None:
        del manifest["command"]
    (out / MANIFEST).write_text(json.dumps(manifest), encoding="utf-8")
    before = _tree(out)
    with pytest.raises(GraderError, match=r"written by .* \(as its \.grader-manifest\.json says\); test --force "
                                          "replaces only a folder test wrote") as raised, \
            output_folder(out, command="test", force=True):
        pass
    assert "\x1b" not in str(raised.value)
    assert _tree(out) == before


@pytest.mark.parametrize("which", ["key", "submissions", "canvas"])
def test_grade_force_does_not_replace_a_grading_folder_that_holds_one_of_its_inputs(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], demo_run: DemoRun, which: str) -> None:
    """The key, a submissions file or the Canvas export inside --out is an input: the folder is kept."""
    import shutil

    grades = tmp_path / "grades"
    shutil.copytree(demo_run.out / "grades", grades)
    key, submissions = tmp_path / "key.json", tmp_path / "submissions.csv"
    shutil.copyfile(demo_run.out / "key.json", key)
    shutil.copyfile(demo_run.out / "submissions.csv", submissions)
    canvas: list[object] = []
    if which == "key":
        key = Path(shutil.copyfile(key, grades / "key.json"))
    elif which == "submissions":
        submissions = Path(shutil.copyfile(submissions, grades / "submissions.csv"))
    else:
        canvas = ["--canvas", grades / "canvas.csv"]  # grader's import file reads as an export
    inside = {"key": key, "submissions": submissions, "canvas": grades / "canvas.csv"}[which]
    before = _tree(grades)
    err = _refused(capsys, "grade", "--key", key, submissions, *canvas, "--out", grades, "--force")
    assert f"{grades}: is or holds the input {inside}, and --out is replaced whole" in err
    assert _tree(grades) == before


def test_an_input_inside_out_by_another_spelling_of_its_path_is_still_an_input(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """On a case-insensitive disk `--key HW/key.json --out hw` names a file inside hw, which neither
    the paths nor their real paths show (Path.resolve keeps the case as typed). Modelled here by a link
    that resolve() is kept from following: the folder is found to be the same by its identity."""
    out = _written(tmp_path / "out")
    (tmp_path / "OUT").symlink_to(out)
    monkeypatch.setattr(Path, "resolve", lambda self, strict=False: Path(os.path.abspath(self)))
    with pytest.raises(GraderError, match=r"is or holds the input .*OUT/key\.csv"), \
            output_folder(out, command="test", inputs=(tmp_path / "OUT" / "key.csv",), force=True):
        pass
    assert (out / "key.csv").read_text() == "id\n"
