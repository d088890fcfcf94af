"""Assignments: seeded, stable variants; a key that equals `grader solve`; every bad input refused."""

from __future__ import annotations

import errno
import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from grader.assign.assignment import load_assignment, load_roster
from grader.assign.variants import generate
from grader.bank.template import Template
from grader.base.files import MANIFEST
from grader.base.resources import sample_dir
from grader.cli import main
from grader.solve.compiled import Compiled
from grader.solve.evaluate import solve_one
from tests.demo_output import DemoRun

ONLY = ("--no-shipped-bank", "--bank")  # a folder's drop-rebound in place of the shipped one, not beside it

ASSIGNMENT = sample_dir() / "assignment.yaml"
ROSTER = sample_dir() / "roster.csv"


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main([str(a) for a in argv])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def test_same_inputs_give_byte_identical_keys(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Two runs, same assignment and roster: key.json and key.csv are identical to the byte."""
    for name in ("one", "two"):
        assert run(capsys, "generate", ASSIGNMENT, "--roster", ROSTER, "--out", tmp_path / name, "--no-pdf")[0] == 0
    for file in ("key.json", "key.csv"):
        assert (tmp_path / "one" / file).read_bytes() == (tmp_path / "two" / file).read_bytes()


def test_a_run_leaves_the_garbage_collector_as_it_found_it(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The collector is paused while the key is made and the variants frozen out of its passes
    for the run; afterwards it is on again and nothing stays frozen."""
    import gc

    assert run(capsys, "generate", ASSIGNMENT, "--roster", ROSTER, "--out", tmp_path / "out", "--no-pdf")[0] == 0
    assert gc.isenabled() and gc.get_freeze_count() == 0


def test_removing_a_student_changes_nobody_elses_numbers(bank: dict[str, Template]) -> None:
    """Variants are keyed on (seed, problem key, student id), not on positions in the roster."""
    assignment, roster = load_assignment(ASSIGNMENT), load_roster(ROSTER)
    everyone = {s.student.id: s.problems for s in generate(assignment, roster, bank).students}
    fewer = generate(assignment, roster[:3] + roster[4:], bank)
    assert len(fewer.students) == len(roster) - 1
    for entry in fewer.students:
        assert entry.problems == everyone[entry.student.id]


def test_a_different_seed_changes_the_numbers(bank: dict[str, Template]) -> None:
    """The assignment seed is part of every variant's key."""
    assignment, roster = load_assignment(ASSIGNMENT), load_roster(ROSTER)
    other = type(assignment)(**{**assignment.__dict__, "seed": "another"})
    first, second = generate(assignment, roster, bank), generate(other, roster, bank)
    assert first.students[0].problems[0].printed != second.students[0].problems[0].printed


def test_every_answer_in_the_key_equals_solving_the_printed_parameters(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], bank: dict[str, Template],
        compiled: dict[str, Compiled]) -> None:
    """The key's answers are the solver's answers for the numbers on the student's page."""
    run(capsys, "generate", ASSIGNMENT, "--roster", ROSTER, "--out", tmp_path / "out", "--no-pdf")
    key = json.loads((tmp_path / "out" / "key.json").read_text(encoding="utf-8"))
    assert key["schema"] == "grader-key" and key["version"] == 2
    for student in key["students"]:
        for problem in student["problems"]:
            assert {n: float(t) for n, t in problem["printed"].items()} == problem["params"]
            solution = solve_one(bank[problem["template"]], compiled[problem["template"]], problem["params"])
            assert solution.answers is not None
            for name, answer in problem["answers"].items():
                assert answer["value"] == solution.answers[name].value
    student, problem = key["students"][7], key["students"][7]["problems"][2]
    sets = [f"--set={n}={t}" for n, t in problem["printed"].items()]
    code, out, _ = run(capsys, "solve", problem["template"], *sets, "--json")
    assert code == 0 and student["id"]
    solved = json.loads(out)["answers"]
    for name, answer in problem["answers"].items():  # the parts the assignment asks
        assert solved[name]["value"] == answer["value"]


def test_printed_values_keep_their_precision_and_labels_follow_the_problem_keys(bank: dict[str, Template]) -> None:
    """h_drop has 2 decimals on the page ("2.10", not "2.1"); answers are labelled 3a, 3b, 3c."""
    variants = generate(load_assignment(ASSIGNMENT), load_roster(ROSTER), bank).students[0].problems
    pile = variants[2]
    assert all(len(pile.printed[n].split(".")[1]) == 2 for n in ("h_drop", "h_rebound"))
    assert [a.label for a in pile.answers] == ["3a", "3b", "3c"]
    assert [a.points for a in variants[0].answers] == [2.0, 2.0]
    assert pile.answers[2].tolerance.rtol == 0.02


def _write(path: Path, text: str) -> Path:
    path.write_text(text, encoding="utf-8")
    return path


def _assignment(tmp_path: Path, change: dict[str, object]) -> Path:
    raw = yaml.safe_load(ASSIGNMENT.read_text(encoding="utf-8"))
    raw["problems"][0].update(change)
    return _write(tmp_path / "assignment.yaml", yaml.safe_dump(raw))


ROSTER_TEXT = ROSTER.read_text(encoding="utf-8")


@pytest.mark.parametrize(("change", "roster", "message"), [
    ({"template": "drop-rebond"}, None, "problems[0].template: expected a template id of the bank (did you mean "
                                        "drop-rebound or two-rebounds?)"),
    ({"fixed": {"h_drop": -5}}, None, "problems[0].fixed.h_drop: expected a value in the parameter's domain (0, inf)"),
    ({"fixed": {"height": 5}}, None, "problems[0].fixed: expected parameters of drop-rebound"),
    ({"fixed": {"h_drop": 1000, "h_rebound": 1500}}, None, "problem 1 (drop-rebound): no valid variant for student "),
    ({}, "id,name,email,section\n1,A,a@x,L1\n1,B,b@x,L1\n", "line 3: student id '1' appears twice"),
    ({}, "id,name,email,section\n1,A,a@x,L1\n,B,b@x,L1\n", "line 3: empty student id"),
    ({}, "id,name,email,section\n", "the roster has no students"),
    ({}, "id,email\n1,a@x\n", "missing column(s) name; expected a header with id, name, and optionally email, "
                                "section and due (got id, email)"),
], ids=["unknown-template", "fixed-outside-domain", "unknown-parameter", "infeasible-constraint", "duplicate-id",
        "empty-id", "empty-roster", "missing-columns"])
def test_bad_input_exits_2_and_leaves_nothing_behind(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                     change: dict[str, object], roster: str | None,
                                                     message: str) -> None:
    """A clear message naming where the problem is; no output folder, no half-written files."""
    assignment = _assignment(tmp_path, change)
    roster_path = _write(tmp_path / "roster.csv", roster if roster is not None else ROSTER_TEXT)
    code, out, err = run(capsys, "generate", assignment, "--roster", roster_path, "--out", tmp_path / "out",
                         "--no-pdf")
    assert (code, out) == (2, "")
    assert message in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["assignment.yaml", "roster.csv"]


def test_infeasible_constraint_names_the_template_and_the_constraint(tmp_path: Path,
                                                                     capsys: pytest.CaptureFixture[str]) -> None:
    """The refusal says which constraint every draw broke."""
    assignment = _assignment(tmp_path, {"fixed": {"h_drop": 1000, "h_rebound": 1500}})
    _, _, err = run(capsys, "generate", assignment, "--roster", ROSTER, "--out", tmp_path / "out", "--no-pdf")
    assert "constraint h_rebound <= h_drop fails" in err


def test_an_existing_output_folder_is_kept_unless_forced(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A non-empty --out is refused (exit 2) and untouched; --force replaces an earlier run's output whole."""
    out = tmp_path / "out"
    assert run(capsys, "generate", ASSIGNMENT, "--roster", ROSTER, "--out", out, "--no-pdf")[0] == 0
    code, _, err = run(capsys, "generate", ASSIGNMENT, "--roster", ROSTER, "--out", out, "--no-pdf")
    assert code == 2 and "exists and is not empty" in err
    assert run(capsys, "generate", ASSIGNMENT, "--roster", ROSTER, "--out", out, "--no-pdf", "--force")[0] == 0
    assert sorted(p.name for p in out.iterdir()) == [".grader-manifest.json", "key.columns.npz", "key.csv",
                                                        "key.json"]
    assert [p.name for p in tmp_path.iterdir()] == ["out"]


@pytest.mark.parametrize("delimiter", [",", ";", "\t"])
def test_rosters_with_bom_and_any_of_three_delimiters_read_alike(tmp_path: Path, delimiter: str) -> None:
    """UTF-8 with a byte-order mark, comma, semicolon or tab: the same students."""
    text = ROSTER_TEXT.replace(",", delimiter) if delimiter != "," else ROSTER_TEXT
    if delimiter != ",":
        text = "\n".join(line.replace(",", delimiter) for line in ROSTER_TEXT.splitlines())
    path = tmp_path / "roster.csv"
    path.write_bytes(b"\xef\xbb\xbf" + text.encode("utf-8"))
    assert load_roster(path) == load_roster(ROSTER)


def test_collisions_are_reported_when_the_parameter_space_is_too_small(tmp_path: Path,
                                                                       capsys: pytest.CaptureFixture[str]) -> None:
    """With every parameter fixed, all students share their numbers, and the run says so."""
    assignment = _assignment(tmp_path, {"fixed": {"h_drop": 2000, "h_rebound": 1000}})
    code, out, _ = run(capsys, "generate", assignment, "--roster", ROSTER, "--out", tmp_path / "out", "--no-pdf")
    assert code == 0
    assert "problem 1: 30" in out
    assert json.loads((tmp_path / "out" / "key.json").read_text(encoding="utf-8"))["collisions"]["1"] == 30


def test_key_csv_neutralizes_formulas_in_text_cells(tmp_path: Path, bank: dict[str, Template]) -> None:
    """A name starting with '=' is written so that a spreadsheet shows it as text."""
    from grader.assign.keyfile import key_csv

    roster = _write(tmp_path / "roster.csv", "id,name,email,section\n7,=cmd|' /C calc'!A0,x@y,L1\n")
    csv_text = key_csv(generate(load_assignment(ASSIGNMENT), load_roster(roster), bank))
    assert "'=cmd|' /C calc'!A0" in csv_text


def test_demo_writes_its_inputs_and_generate_from_them_reproduces_it(tmp_path: Path, demo_run: DemoRun,
                                                                     capsys: pytest.CaptureFixture[str]) -> None:
    """`grader demo --out DIR` then `grader generate DIR/assignment.yaml --roster DIR/roster.csv --out OTHER`
    give the same key and the same PDFs, byte for byte."""
    demo, other = demo_run.out, tmp_path / "other"
    assert demo_run.code == 0 and "30 students x 5 problems" in demo_run.stdout
    assert run(capsys, "generate", demo / "assignment.yaml", "--roster", demo / "roster.csv", "--out", other)[0] == 0
    produced = sorted(p.relative_to(demo) for p in demo.rglob("*") if p.is_file())
    assert {"key.json", "key.csv", "class.pdf", "answer-key.pdf"} <= {str(p) for p in produced}
    assert len([p for p in produced if str(p).startswith("students")]) == 30
    generated = [p for p in produced if p.parts[0] not in ("assignment.yaml", "roster.csv", MANIFEST,
                                                           "submissions.csv", "grades")]  # the demo's own
    assert generated == sorted(p.relative_to(other) for p in other.rglob("*") if p.is_file() and p.name != MANIFEST)
    for path in generated:
        assert (demo / path).read_bytes() == (other / path).read_bytes(), path


def test_a_failure_while_rendering_leaves_nothing_behind(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                         capsys: pytest.CaptureFixture[str]) -> None:
    """Key files already written to the staging folder are removed with it; --out never appears."""
    import grader.render.pdfs

    def broken(*args: object, **kwargs: object) -> list[Path]:
        raise RuntimeError("disk full")

    monkeypatch.setattr(grader.render.pdfs, "render_all", broken)
    with pytest.raises(RuntimeError, match="disk full"):
        main(["generate", str(ASSIGNMENT), "--roster", str(ROSTER), "--out", str(tmp_path / "out")])
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("command", ["generate", "demo"])
def test_jobs_below_one_exits_2(tmp_path: Path, capsys: pytest.CaptureFixture[str], command: str) -> None:
    """--jobs 0 is refused before anything is written."""
    inputs = [ASSIGNMENT, "--roster", ROSTER] if command == "generate" else []
    code, out, err = run(capsys, command, *inputs, "--out", tmp_path / "out", "--jobs", "0")
    assert (code, out) == (2, "")
    assert "--jobs must be 1 or more, got 0" in err
    assert list(tmp_path.iterdir()) == []


# --- hostile templates (hardening) ----------------------------------------------------------------

ONE_PROBLEM = {"title": "HW", "course": "C", "seed": "s1",
               "problems": [{"key": "1", "template": "drop-rebound", "points": 1}]}
SUBCLASSES = ("{% for c in ''.__class__.__mro__[1].__subclasses__() %}{% if c.__name__ == 'Popen' %}"
              "{{ c.__init__.__globals__['system']('touch F') }}{% endif %}{% endfor %}")


def hostile_bank(folder: Path, statement: str) -> Path:
    """A --bank folder holding drop-rebound with ``statement`` put first in its statement, an
    assignment of that one problem, a roster of four and a secret file, all in ``folder``."""
    bank_folder = folder / "bank"
    bank_folder.mkdir()
    raw = yaml.safe_load((Path(__file__).parents[1] / "problem_bank" / "drop-rebound.yaml").read_text("utf-8"))
    raw["statement"] = statement + "\n" + raw["statement"]
    (bank_folder / "drop-rebound.yaml").write_text(yaml.safe_dump(raw), encoding="utf-8")
    (folder / "a.yaml").write_text(yaml.safe_dump(ONE_PROBLEM), encoding="utf-8")
    (folder / "roster.csv").write_text("\n".join(ROSTER.read_text("utf-8").splitlines()[:5]) + "\n", "utf-8")
    (folder / "secret.txt").write_text("TOPSECRET", encoding="utf-8")
    return bank_folder


@pytest.mark.parametrize(("statement", "got"), [
    (SUBCLASSES, "got a for loop"),
    ("{{ ''.__class__ }}", "got attribute access"),
    ("{{ 'x' * 10**9 }}", "got arithmetic"),
    ("{{ 2 ** 1000000000 }}", "got arithmetic"),
    ("{{ h_drop * 3 }}", "got arithmetic (values are filled in as printed text"),
    ("{% if h_drop %}x{% endif %}", "got a condition"),
    ("#for i in range(100000000) {}", "Typst code that is not markup: #for i in range(100000000) {}"),
    ("#range(30000000).map(x => x).len()", "Typst code that is not markup: #range(30000000)"),
    ("#datetime.today().display()", "Typst code that is not markup: #datetime.today()"),
    ("#emph[a].text", "Typst code that is not markup: #emph[a].text"),
    ("x" * 20_001, "more than 20000 characters of output"),
    ("{{ 'x'|center(10**9) }}", "filter 'center'"),
    ("{{ '%0999999999d' % 1 }}", "got arithmetic"),
    ('#read("secret.txt")', 'a Typst call that reads files: read("secret.txt")'),
    ('$ read("secret.txt") $', 'reads files: read("secret.txt")'),
    ('#image("secret.txt")', "reads files: image("),
    ('#import "@preview/cetz:0.2.2": *', 'reads files: import "@preview/cetz:0.2.2"'),
    ('#include "secret.txt"', "reads files: include"),
    ('#let r = std.read; #r("secret.txt")', "reads files: std.read"),
    ('#eval("re" + "ad(\\"secret.txt\\")")', "reads files: eval("),
    ('#re{{ h_drop|string|lower|trim|default }}ad("secret.txt")', "reads files: read("),
])
def test_a_hostile_template_statement_is_refused_with_exit_2_before_anything_runs(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch, statement: str,
        got: str) -> None:
    """Code in a statement never runs, a costly one is refused in well under a second, Typst that
    reads files is refused when the template loads: exit 2, the file and `statement` named, no output."""
    import time

    bank_folder = hostile_bank(tmp_path, statement)
    monkeypatch.chdir(tmp_path)
    started = time.process_time()
    code, _, err = run(capsys, *ONLY, bank_folder, "generate", "a.yaml", "--roster", "roster.csv", "--out", "out")
    assert time.process_time() - started < 1.0
    assert code == 2
    assert f"{bank_folder / 'drop-rebound.yaml'}: statement: expected" in err and got in err, err
    assert not (tmp_path / "F").exists() and not (tmp_path / "out").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.yaml", "bank", "roster.csv", "secret.txt"]


def test_a_font_dir_that_is_not_a_folder_exits_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run(capsys, "demo", "--out", tmp_path / "out", "--font-dir", tmp_path / "nowhere")
    assert code == 2 and "--font-dir" in err and "does not exist" in err
    assert not (tmp_path / "out").exists()


# --- the output folder: --force, races, file-system errors (hardening) --------------------------------------


def _inputs_in(folder: Path) -> tuple[Path, Path]:
    folder.mkdir(parents=True, exist_ok=True)
    return _write(folder / "assignment.yaml", ASSIGNMENT.read_text(encoding="utf-8")), _write(
        folder / "roster.csv", ROSTER_TEXT)


def _tree(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def _one_line_error(code: int, out: str, err: str) -> str:
    assert (code, out) == (2, ""), err
    assert err.count("\n") == 1 and err.startswith("grader: error: ") and "Traceback" not in err, err
    return err


def test_force_does_not_delete_the_inputs_of_the_demo_folder(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                             demo_run: DemoRun) -> None:
    """`demo --out d`, then `generate d/assignment.yaml --roster d/roster.csv --out d --force`: refused, d kept."""
    demo = tmp_path / "d"
    shutil.copytree(demo_run.out, demo)
    assert "roster.csv" in json.loads((demo / MANIFEST).read_text(encoding="utf-8"))["files"]
    before = _tree(demo)
    err = _one_line_error(*run(capsys, "generate", demo / "assignment.yaml", "--roster", demo / "roster.csv",
                               "--out", demo, "--no-pdf", "--force"))
    assert f"{demo}: is or holds the input {demo / 'assignment.yaml'}" in err
    assert _tree(demo) == before
    assert [p.name for p in tmp_path.iterdir()] == ["d"]


@pytest.mark.parametrize("where", ["out", "ancestor"])
def test_force_does_not_delete_the_inputs_or_unrelated_files(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                             where: str) -> None:
    """--out that holds the assignment and roster (directly or further down), and notes.txt: nothing goes."""
    hw = tmp_path / "hw"
    assignment, roster = _inputs_in(hw / "inputs" if where == "ancestor" else hw)
    _write(hw / "notes.txt", "mine")
    before = _tree(hw)
    err = _one_line_error(*run(capsys, "generate", assignment, "--roster", roster, "--out", hw, "--no-pdf",
                               "--force"))
    assert "is or holds the input" in err and "choose an --out that holds none of the inputs" in err
    assert _tree(hw) == before
    assert [p.name for p in tmp_path.iterdir()] == ["hw"]


def test_force_does_not_delete_a_folder_grader_did_not_write(tmp_path: Path,
                                                             capsys: pytest.CaptureFixture[str]) -> None:
    """A folder without a manifest is never replaced, not even with --force."""
    out = tmp_path / "out"
    out.mkdir()
    _write(out / "notes.txt", "mine")
    err = _one_line_error(*run(capsys, "generate", ASSIGNMENT, "--roster", ROSTER, "--out", out, "--no-pdf",
                               "--force"))
    assert f"{out}: exists and is not empty, and no grader run wrote it (there is no {MANIFEST})" in err
    assert _tree(out) == {"notes.txt": b"mine"}


@pytest.mark.parametrize(("change", "listed"), [
    ("add", "notes.txt (not written by grader)"),
    ("edit", "key.csv (changed since grader wrote it)"),
    ("folder", "mine/ (a folder not made by grader)"),
], ids=["extra-file", "edited-file", "extra-folder"])
def test_force_refuses_a_folder_that_does_not_match_its_manifest(tmp_path: Path,
                                                                 capsys: pytest.CaptureFixture[str],
                                                                 change: str, listed: str) -> None:
    """An extra file or folder, or an edited file, in an earlier output: --force is refused and names it."""
    out = tmp_path / "out"
    assert run(capsys, "generate", ASSIGNMENT, "--roster", ROSTER, "--out", out, "--no-pdf")[0] == 0
    if change == "add":
        _write(out / "notes.txt", "mine")
    elif change == "edit":
        _write(out / "key.csv", "my corrections")
    else:
        (out / "mine").mkdir()
    before = _tree(out)
    err = _one_line_error(*run(capsys, "generate", ASSIGNMENT, "--roster", ROSTER, "--out", out, "--no-pdf",
                               "--force"))
    assert listed in err and "move those out of it, or choose another --out" in err
    assert _tree(out) == before and (change != "folder" or (out / "mine").is_dir())
    assert [p.name for p in tmp_path.iterdir()] == ["out"]


@pytest.mark.parametrize("where", [".", "..", "home"])
def test_out_that_is_the_current_or_home_folder_is_refused(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                          capsys: pytest.CaptureFixture[str], where: str) -> None:
    """`--out .` (even an empty cwd), an ancestor of it, or the home folder: refused, nothing written."""
    cwd = tmp_path / "work"
    cwd.mkdir()
    monkeypatch.chdir(cwd)
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    (tmp_path / "home").mkdir()
    out = tmp_path / "home" if where == "home" else Path(where)
    err = _one_line_error(*run(capsys, "generate", ASSIGNMENT, "--roster", ROSTER, "--out", out, "--no-pdf",
                               "--force"))
    assert "folder or holds it, and --out is replaced whole" in err
    assert sorted(p.name for p in tmp_path.rglob("*")) == ["home", "work"]


def test_a_second_run_into_the_same_out_fails_while_the_first_is_writing(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The work folder .out.partial is made exclusively: a run that finds it refuses and leaves it alone."""
    work = tmp_path / ".out.partial"
    work.mkdir()
    err = _one_line_error(*run(capsys, "generate", ASSIGNMENT, "--roster", ROSTER, "--out", tmp_path / "out",
                               "--no-pdf"))
    assert "another grader run is writing it" in err and f"delete {work}" in err
    assert [p.name for p in tmp_path.iterdir()] == [".out.partial"]


def test_an_output_that_appears_during_the_run_is_not_replaced(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                               capsys: pytest.CaptureFixture[str]) -> None:
    """Race: --out is new when the run checks it and exists (written by someone else) before the move."""
    import grader.render.generate

    out = tmp_path / "out"
    real = grader.render.generate.write_key

    def racing(*args: object) -> object:
        out.mkdir()
        _write(out / "key.json", "the other run")
        return real(*args)  # type: ignore[arg-type]

    monkeypatch.setattr(grader.render.generate, "write_key", racing)
    err = _one_line_error(*run(capsys, "generate", ASSIGNMENT, "--roster", ROSTER, "--out", out, "--no-pdf"))
    assert f"{out}: appeared while this run was writing it" in err
    assert _tree(out) == {"key.json": b"the other run"}
    assert [p.name for p in tmp_path.iterdir()] == ["out"]


@pytest.mark.parametrize("failing", [1, 2], ids=["moving-the-old-aside", "moving-the-new-in"])
def test_a_failed_replace_leaves_the_previous_output_and_no_work_folder(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], failing: int) -> None:
    """os.rename fails (EBUSY, as for a mount point) at either step of --force: old output intact, no leftovers."""
    import grader.base.files

    out = tmp_path / "out"
    assert run(capsys, "generate", ASSIGNMENT, "--roster", ROSTER, "--out", out, "--no-pdf")[0] == 0
    before = _tree(out)
    calls: list[int] = []
    real = os.rename

    def busy(source: str, destination: str) -> None:
        calls.append(1)
        if len(calls) == failing:
            raise OSError(errno.EBUSY, os.strerror(errno.EBUSY), source)
        real(source, destination)

    monkeypatch.setattr(grader.base.files.os, "rename", busy)
    err = _one_line_error(*run(capsys, "generate", ASSIGNMENT, "--roster", ROSTER, "--out", out, "--no-pdf",
                               "--force"))
    assert "Device or resource busy" in err and "the previous output is unchanged" in err
    assert _tree(out) == before
    assert [p.name for p in tmp_path.iterdir()] == ["out"]


def _read_only(error: int) -> object:
    def refuse(self: Path, *args: object, **kwargs: object) -> None:
        raise OSError(error, os.strerror(error), str(self))
    return refuse


@pytest.mark.parametrize("case", ["through-a-file", "name-too-long", "read-only-parent", "missing-parents"])
def test_file_system_errors_are_one_line_naming_the_path(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                        capsys: pytest.CaptureFixture[str], case: str) -> None:
    """--out afile/sub, a 250-character name, a read-only (EROFS) parent: exit 2, one line, nothing left."""
    _write(tmp_path / "afile", "text")
    out = {"through-a-file": tmp_path / "afile" / "sub", "name-too-long": tmp_path / ("x" * 250),
           "read-only-parent": tmp_path / "ro" / "out", "missing-parents": tmp_path / "a" / "b" / "out"}[case]
    expected = {"through-a-file": f"{out}: expected a path through folders, but {tmp_path / 'afile'} is a file",
                "name-too-long": "expected a folder name of at most 246 bytes", "read-only-parent":
                f"{out}: cannot write in {out.parent} (Read-only file system); choose an --out in a folder",
                "missing-parents": f"{out}: cannot create its folder ({out.parent}: Read-only file system"}[case]
    if case == "read-only-parent":
        (tmp_path / "ro").mkdir()
        monkeypatch.setattr(Path, "mkdir", _read_only(errno.EROFS))
    if case == "missing-parents":
        monkeypatch.setattr(os, "mkdir", lambda path, *a, **k: (_ for _ in ()).throw(
            OSError(errno.EROFS, os.strerror(errno.EROFS), str(path))))
    err = _one_line_error(*run(capsys, "generate", ASSIGNMENT, "--roster", ROSTER, "--out", out, "--no-pdf"))
    monkeypatch.undo()
    assert expected in err
    assert sorted(p.name for p in tmp_path.rglob("*")) == ["afile"] + (["ro"] if case == "read-only-parent" else [])


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into read-only folders: see the EROFS case above")
def test_a_read_only_parent_folder_is_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A real read-only folder (chmod 555) as --out's parent: exit 2, one line naming it."""
    locked = tmp_path / "locked"
    locked.mkdir(mode=0o555)
    try:
        err = _one_line_error(*run(capsys, "generate", ASSIGNMENT, "--roster", ROSTER, "--out", locked / "out",
                                   "--no-pdf"))
    finally:
        locked.chmod(0o755)
    assert f"cannot write in {locked} (Permission denied)" in err
    assert list(locked.iterdir()) == []


@pytest.mark.slow  # about 3.5 s; the full disk while the students' lines wait stays in the default run
@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs /dev/full")
def test_a_full_disk_while_writing_the_key_is_one_line_and_leaves_nothing(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    """Every atomic write goes to /dev/full (ENOSPC from the kernel): the path, the reason, nothing left (key.csv
    and key.json are written side by side, a piece of the class at a time: the first to fill names itself)."""
    import grader.base.files

    def full(handle: int, mode: str = "rb") -> object:
        os.close(handle)
        return open("/dev/full", mode)

    monkeypatch.setattr(grader.base.files.os, "fdopen", full)
    err = _one_line_error(*run(capsys, "generate", ASSIGNMENT, "--roster", ROSTER, "--out", tmp_path / "out",
                               "--no-pdf"))
    monkeypatch.undo()
    assert re.search(f"{re.escape(str(tmp_path / 'out'))}/key\\.(json|csv): No space left on device; nothing was "
                     "written to", err)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs /dev/full")
@pytest.mark.parametrize("command", [["list"], ["solve", "drop-rebound", "--set", "h_drop=2", "--set",
                                                 "h_rebound=1", "--json"]], ids=["list", "solve-json"])
def test_a_full_stdout_is_one_line_on_stderr_not_a_traceback(command: list[str]) -> None:
    """`grader list > /dev/full`: exit 2 and one line on stderr, no traceback, no 'Exception ignored'."""
    with open("/dev/full", "w") as full:
        result = subprocess.run([sys.executable, "-m", "grader", *command], stdout=full, stderr=subprocess.PIPE,
                                text=True, timeout=60)
    assert result.returncode == 2
    assert result.stderr == ("grader: error: cannot write to standard output (No space left on device); free some "
                             "space, or send the output to a file or program that takes it\n")


def test_a_roster_of_ids_and_names_only_is_enough(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """An LMS export often has no email or section: those columns may be left out (empty for everyone)."""
    assignment = _assignment(tmp_path, {})
    roster_path = _write(tmp_path / "roster.csv", "id,name\n1,Ann Lee\n2,Bo Chan\n")
    code, _, err = run(capsys, "generate", assignment, "--roster", roster_path, "--out", tmp_path / "out", "--no-pdf")
    assert code == 0, err
    students = json.loads((tmp_path / "out" / "key.json").read_text(encoding="utf-8"))["students"]
    assert [(s["id"], s["name"], s["email"], s["section"]) for s in students] == [("1", "Ann Lee", "", ""),
                                                                                  ("2", "Bo Chan", "", "")]


@pytest.mark.parametrize("size", [1, 64, 1000], ids=["one-student-a-piece", "uneven-pieces", "one-piece"])
def test_a_key_written_a_piece_at_a_time_is_the_key_written_whole(tmp_path: Path, bank: dict[str, Template],
                                                                   size: int) -> None:
    """key.json and key.csv written as the class is drawn, a piece at a time (how `generate --no-pdf` writes a big
    class), are the bytes of the class drawn whole and encoded at once; the collisions counted over the pieces
    are the students whose printed numbers another student has too, counted over the whole class here."""
    from collections import Counter

    from grader.assign.assignment import Student
    from grader.assign.keyfile import key_csv, key_document, key_json, write_key_files
    from grader.assign.variants import ClassDraws

    assignment = load_assignment(ASSIGNMENT)
    roster = (load_roster(ROSTER) + tuple(Student(f"90{i:04d}", f"Student {i}", f"s{i}@example.edu", "L02")
                                          for i in range(270)))[:300 if size != 1 else 40]
    whole = generate(assignment, roster, bank)
    draws = ClassDraws(assignment, roster, bank)
    write_key_files(tmp_path, assignment, draws.chunks(size), draws.collisions, bank, tmp_path)
    assert (tmp_path / "key.json").read_text(encoding="utf-8") == key_json(key_document(assignment, whole, bank,
                                                                                         tmp_path))
    assert (tmp_path / "key.csv").read_text(encoding="utf-8") == key_csv(whole)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["key.csv", "key.json"]  # no temporary file left
    for index, problem in enumerate(assignment.problems):
        printed = Counter(tuple(s.problems[index].printed.values()) for s in whole.students)
        shared = sum(printed[tuple(s.problems[index].printed.values())] > 1 for s in whole.students)
        assert draws.collisions()[problem.key] == whole.collisions[problem.key] == shared
    if size == 64:
        assert any(whole.collisions.values())  # the case that counts: some students do share their numbers


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs /dev/full")
def test_a_full_disk_while_the_students_lines_wait_names_key_json(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                                   capsys: pytest.CaptureFixture[str]) -> None:
    """key.json's students wait in an unnamed temporary file while the class is drawn; a write to it that fails
    (ENOSPC from /dev/full) names no file by itself: the message names key.json, and nothing is left."""
    import grader.assign.keyfile

    monkeypatch.setattr(grader.assign.keyfile.tempfile, "TemporaryFile", lambda dir: open("/dev/full", "w+b"))  # noqa: SIM115
    err = _one_line_error(*run(capsys, "generate", ASSIGNMENT, "--roster", ROSTER, "--out", tmp_path / "out",
                               "--no-pdf"))
    monkeypatch.undo()
    assert f"{tmp_path / 'out' / 'key.json'}: No space left on device; nothing was written to" in err
    assert list(tmp_path.iterdir()) == []
