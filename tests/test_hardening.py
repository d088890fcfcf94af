"""Hostile and careless input (issue 9): each case is named after what broke. Every one must end
with exit 2 (or 3 for refused rows) and one message naming where the problem is, quickly, with
nothing half-written; never a traceback, a hang, or invalid JSON."""

from __future__ import annotations

import gc
import json
import re
import tempfile
import time
import tracemalloc
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from grader.base.resources import bank_dir, sample_dir
from grader.base.spreadsheet import original_cell, safe_cell
from grader.cli import main

ROSTER = sample_dir() / "roster.csv"
ONE_PROBLEM = "title: HW\ncourse: C\nseed: s\nproblems:\n  - template: drop-rebound\n"
ONLY = ("--no-shipped-bank", "--bank")  # a folder's drop-rebound in place of the shipped one, not beside it


def run(capsys: pytest.CaptureFixture[str], *argv: object) -> tuple[int, str, str]:
    code = main([str(a) for a in argv])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def refused(capsys: pytest.CaptureFixture[str], *argv: object, within: float = 5.0) -> str:
    """Run; expect exit 2 with one line on stderr and nothing on stdout, within ``within`` seconds of this
    process's CPU time: what catches work without end or that grows with the input's size (the machine's
    other work does not count). The garbage of the tests before is collected first: a full collection of
    the test session's heap, falling due inside the command, took longer than the command itself."""
    gc.collect()
    started = time.process_time()
    code, out, err = run(capsys, *argv)
    assert time.process_time() - started < within
    assert (code, out) == (2, ""), err
    assert err.startswith("grader: error: ") and err.count("\n") == 1, err
    return err


def write(path: Path, text: str | bytes) -> Path:
    if isinstance(text, bytes):
        path.write_bytes(text)
    else:
        path.write_text(text, encoding="utf-8")
    return path


def generate_refused(capsys: pytest.CaptureFixture[str], tmp_path: Path, assignment: str | bytes,
                     roster: str | bytes | None = None, bank: Path | None = None) -> str:
    """``grader generate`` of these files is refused and writes no --out."""
    a = write(tmp_path / "a.yaml", assignment)
    r = write(tmp_path / "r.csv", roster) if roster is not None else ROSTER
    argv = ([*ONLY, bank] if bank else []) + ["generate", a, "--roster", r, "--out", tmp_path / "out", "--no-pdf"]
    err = refused(capsys, *argv)
    assert not (tmp_path / "out").exists()
    return err


def bank_with(tmp_path: Path, template: str, old: str, new: str) -> Path:
    """A --bank folder holding one shipped template with ``old`` replaced by ``new``."""
    folder = tmp_path / "bank"
    folder.mkdir(exist_ok=True)
    text = (bank_dir() / f"{template}.yaml").read_text(encoding="utf-8")
    assert old in text
    write(folder / f"{template}.yaml", text.replace(old, new, 1))
    return folder


# --- YAML: aliases, depth, duplicate keys, encodings, numbers ---------------------------------------

BOMB = "".join(f"l{i}: &l{i} [" + ", ".join([f"*l{i - 1}" if i else '"x"'] * 9) + "]\n" for i in range(9))


@pytest.mark.parametrize("key", ["title", "fixed", "problems"])
def test_a_yaml_alias_bomb_is_refused_at_once_not_expanded(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                            key: str) -> None:
    """9**9 values through aliases ran for minutes at 1.6 GB (the message repr'd the expansion)."""
    body = {"title": f"{BOMB}title: *l8\ncourse: C\nseed: s\nproblems: [{{template: drop-rebound}}]\n",
            "fixed": f"{BOMB}{ONE_PROBLEM}    fixed: *l8\ncourse2: x\n",
            "problems": f"{BOMB}title: T\ncourse: C\nseed: s\nproblems: *l8\n"}[key]
    err = generate_refused(capsys, tmp_path, body)
    assert "expands to more than 100,000 values through aliases" in err and len(err) < 300


def test_a_yaml_document_of_too_many_values_without_aliases_is_refused(tmp_path: Path,
                                                                       capsys: pytest.CaptureFixture[str]) -> None:
    """Without an alias the composer's count is the document's size; 100,001 values fit in 1 MiB."""
    err = generate_refused(capsys, tmp_path, "title: [" + "1," * 100_001 + "]\n")
    assert "line 1: holds more than 100,000 values; expected a template-sized structure" in err


def test_yaml_nested_100k_deep_is_refused_not_a_recursion_error(tmp_path: Path,
                                                                  capsys: pytest.CaptureFixture[str]) -> None:
    err = generate_refused(capsys, tmp_path, "title: " + "[" * 100_000 + "]" * 100_000 + "\n")
    assert "a.yaml: line 1: nested deeper than 64 levels" in err


@pytest.mark.parametrize(("text", "key"), [
    ("title: A\ntitle: B\ncourse: C\nseed: s\nproblems: [{template: drop-rebound}]\n", "'title'"),
    ("title: A\ncourse: C\nseed: s\nproblems:\n  - template: drop-rebound\n    template: pile-driver\n",
     "'template'"),
])
def test_duplicate_yaml_keys_are_refused_not_last_wins(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                        text: str, key: str) -> None:
    err = generate_refused(capsys, tmp_path, text)
    assert f"the key {key} appears twice" in err


def test_duplicate_keys_in_a_template_are_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    folder = bank_with(tmp_path, "drop-rebound", "title:", "title: twice\ntitle:")
    err = refused(capsys, *ONLY, folder, "list")
    assert "drop-rebound.yaml: line 4: the key 'title' appears twice" in err  # the second title


def test_non_utf8_files_are_refused_with_the_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    err = generate_refused(capsys, tmp_path, "title: Caf\xe9\n".encode("latin-1") + ONE_PROBLEM[10:].encode())
    assert "a.yaml: line 1: expected UTF-8 text, got the byte 0xe9" in err
    folder = tmp_path / "bank"
    folder.mkdir()
    write(folder / "x.yaml", b"id: x\ntitle: \xff\n")
    assert "x.yaml: line 2: expected UTF-8 text" in refused(capsys, *ONLY, folder, "list")


def test_yaml_1e308_without_a_dot_is_a_number(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """YAML 1.1 read 1e308 as text; as a number it is outside no domain here but prints too long."""
    err = generate_refused(capsys, tmp_path, ONE_PROBLEM + "    fixed: {h_drop: 1e308}\n")
    assert "h_drop = 1e+308 prints as 309 characters" in err


@pytest.mark.parametrize("where", ["points: {e: X}", "fixed: {h_drop: X}", "narrow: {h_drop: [1, X]}",
                                   "tolerance: {e: {rtol: X}}"])
def test_400_digit_integers_in_an_assignment_are_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                          where: str) -> None:
    err = generate_refused(capsys, tmp_path, ONE_PROBLEM + "    " + where.replace("X", "9" * 400) + "\n")
    assert "a.yaml: line 6: expected a finite number within float64" in err


@pytest.mark.parametrize(("old", "new", "message"), [
    ("example: {h_drop: 2100", "example: {h_drop: " + "9" * 400, "expected a finite number within float64"),
    ("gravity: 9.81 m/s^2", "gravity: 9.81e400 m/s^2", "gravity: expected a positive acceleration below 1e300"),
    ("gravity: 9.81 m/s^2", "gravity: 9.8.1 m/s^2", "gravity: expected a positive acceleration"),
    ('domain: "(0, inf)"', 'domain: "[., 1]"', "domain: expected an interval"),
    ('domain: "(0, inf)"', 'domain: "[e, 5000]"', "domain: expected an interval"),
    ('domain: "(0, inf)"', 'domain: "[0, 1e400]"', "domain: expected bounds within float64"),
    ("example: {h_drop: 2100", "example: {h_drop: abc", "example.h_drop: expected a number, got 'abc'"),
    ("sample: {uniform: [1500, 2500]}", "sample: {choice: [.inf]}", "expected a finite number within float64"),
    ("unit: mm", "unit: kg", "stages[0].height: expected a length (check the parameters' units), got 'h_drop', "
                             "which is a mass"),
    ("unit: mm", "unit: mm^9999999", "expected powers from -9 to 9"),
    ("statement: |\n", "statement: |\n  {{ " + "(" * 50_000 + "1" + ")" * 50_000 + " }}\n",
     "statement: expected values filled in, not code, got expressions nested too deeply"),
])
def test_bad_template_values_are_refused_not_a_traceback(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                          old: str, new: str, message: str) -> None:
    folder = bank_with(tmp_path, "drop-rebound", old, new)
    assert message in refused(capsys, *ONLY, folder, "list")


@pytest.mark.parametrize(("restitution", "message"), [
    ("2", "a condition that never holds: the coefficient of restitution is 2; above 1"),
    ("0.5", "parameters.h_rebound: expected a parameter the answers depend on"),
])
def test_a_constant_restitution_that_is_impossible_or_overdetermines_is_refused(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], restitution: str, message: str) -> None:
    """A constant e = 2 gave loss_pct = -300 %; e = 0.5 with h_rebound given ignored h_rebound."""
    folder = bank_with(tmp_path, "drop-rebound", "restitution: e", f"restitution: {restitution}")
    text = (folder / "drop-rebound.yaml").read_text(encoding="utf-8")
    write(folder / "drop-rebound.yaml", text.replace("  e:\n    value: e\n", "  e_asked:\n    value: 0.5\n"))
    err = refused(capsys, *ONLY, folder, "solve", "drop-rebound", "--set", "h_drop=2000", "--set", "h_rebound=900")
    assert message in err


def test_an_empty_bank_folder_is_refused_not_an_empty_list(tmp_path: Path,
                                                            capsys: pytest.CaptureFixture[str]) -> None:
    assert "no templates in this folder" in refused(capsys, *ONLY, tmp_path, "list")


# --- CSV: headers, rows, ids, sizes, line numbers ---------------------------------------------------

@pytest.mark.parametrize("template", ["drop-rebound", "pile-driver", "ball-plate", "oblique-spheres",
                                      "car-collision"])
def test_a_header_only_batch_is_refused_for_every_template(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                            bank: dict[str, Any], template: str) -> None:
    batch = write(tmp_path / "b.csv", ",".join(bank[template].parameters) + "\n")
    assert "no data rows" in refused(capsys, "solve", template, "--batch", batch)


@pytest.mark.parametrize(("text", "message"), [
    ("h_drop,h_rebound,h_drop\n1,1,1\n", "the column 'h_drop' appears twice"),
    ("h_drop,,h_rebound\n1,,1\n", "column 2 has no name"),
    ('h_drop,h_rebound\n"2000,1000\n', "line 2: unexpected end of data (check the quotes); expected CSV"),
    ("h_drop,h_rebound\n" + "1" * 100_000 + ",1\n", "a cell of 100,000 characters; expected at most 1000"),
    ("h_drop,h_rebound\n\0,1\n", "line 2: expected text, got a NUL byte"),
])
def test_malformed_batch_files_are_refused_naming_the_line(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                            text: str, message: str) -> None:
    """Duplicate headers made the last one win; a 100 KB cell took 36 s in a quadratic regex."""
    batch = write(tmp_path / "b.csv", text)
    assert message in refused(capsys, "solve", "drop-rebound", "--batch", batch)


def test_a_batch_row_with_more_cells_than_columns_is_a_refused_row(tmp_path: Path,
                                                                  capsys: pytest.CaptureFixture[str]) -> None:
    """One bad row costs that row, not the run (a short row already did the same)."""
    batch = write(tmp_path / "b.csv", "h_drop,h_rebound\n2000,1000,5\n2100,1100\n")
    code, out, _ = run(capsys, "solve", "drop-rebound", "--batch", batch, "--json")
    first, second = (json.loads(line) for line in out.splitlines())
    assert code == 3 and first["error"] == "line 2: 3 cells, but the header has 2 columns; expected one cell per column"
    assert second["answers"]["e"]["value"] == pytest.approx((1100 / 2100) ** 0.5, rel=1e-12)


def test_batch_line_numbers_count_blank_lines_and_quoted_line_breaks(tmp_path: Path,
                                                                     capsys: pytest.CaptureFixture[str]) -> None:
    """Blank lines before the header gave "empty file"; errors named the wrong line after blank lines
    or a cell spanning lines; a trailing comma gave "unknown parameter(s)" with an empty name."""
    batch = write(tmp_path / "b.csv", '\n\nh_drop,h_rebound,\n2100,1100,\n\n"2\n1",1\nx,1\n')
    code, out, _ = run(capsys, "solve", "drop-rebound", "--batch", batch, "--json")
    records = [json.loads(line) for line in out.splitlines()]
    assert code == 3
    assert records[0]["answers"]["e"]["value"] == pytest.approx((1100 / 2100) ** 0.5, rel=1e-12)
    assert records[1]["error"].startswith("line 6, h_drop:")
    assert records[2]["error"].startswith("line 8, h_drop:")


@pytest.mark.parametrize("which", ["batch", "roster"])
def test_dev_zero_as_a_csv_is_refused_by_size_not_memory(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                         which: str) -> None:
    if not Path("/dev/zero").exists():
        pytest.skip("no /dev/zero on this system")
    if which == "batch":
        err = refused(capsys, "solve", "drop-rebound", "--batch", "/dev/zero")
    else:
        a = write(tmp_path / "a.yaml", ONE_PROBLEM)
        err = refused(capsys, "generate", a, "--roster", "/dev/zero", "--out", tmp_path / "o", "--no-pdf")
    assert "/dev/zero: larger than 64 MiB" in err


def test_a_sparse_2_gb_key_is_refused_by_its_size_before_reading_it(tmp_path: Path,
                                                                    capsys: pytest.CaptureFixture[str]) -> None:
    """A regular file's size is known: it took 3 s and 1 GiB of memory to read the first GiB of it first."""
    key = tmp_path / "key.json"
    with open(key, "wb") as stream:
        stream.truncate(2 << 30)  # sparse: no disk space used
    answers = write(tmp_path / "a.csv", "student_id,label,answer\n")
    tracemalloc.start()
    try:
        err = refused(capsys, "grade", "--key", key, answers, "--out", tmp_path / "g")
        assert tracemalloc.get_traced_memory()[1] < 50 << 20
    finally:
        tracemalloc.stop()
    # Without a sidecar (key.columns.npz) the key would be read whole: refused, saying how to get one.
    assert f"key.json: {2 << 30:,} bytes, more than the {1 << 30:,} a key.json is read whole within" in err
    assert "regenerate the key with grader generate, which writes key.columns.npz beside it" in err


@pytest.mark.parametrize(("row", "message"), [
    ("a,Ana,a@x,1,extra", "line 2: 5 cells, but the header has 4 columns"),
    ('"a\nb",Ana,a@x,1', "U+000A"),
    ("a\u200bb,Ana,a@x,1", "U+200B (ZERO WIDTH SPACE)"),
    ("a\u202eb,Ana,a@x,1", "U+202E (RIGHT-TO-LEFT OVERRIDE)"),
    ("..,Ana,a@x,1", "would name a hidden or parent folder"),
    (".,Ana,a@x,1", "would name a hidden or parent folder"),
    # names are printed: no control characters, no bidi overrides (they reorder what follows), not invisible
    ("s1,Ana\u202eevil,a@x,1", "holds the control character U+202E (RIGHT-TO-LEFT OVERRIDE)"),
    ("s1,\u200b\u200b,a@x,1", "has no visible character"),
    ('s1,"Ana\nBo",a@x,1', "U+000A"),
])
def test_roster_rows_that_cannot_be_ids_or_names_are_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                    row: str, message: str) -> None:
    err = generate_refused(capsys, tmp_path, ONE_PROBLEM, f"id,name,email,section\n{row}\n")
    assert message in err


def test_a_roster_with_two_id_columns_is_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    err = generate_refused(capsys, tmp_path, ONE_PROBLEM, "id,name,email,section,ID\na,A,a@x,1,b\n")
    assert "the column 'ID', 'id' appears twice" in err


# --- numbers in and out -----------------------------------------------------------------------------

def test_a_unit_power_of_millions_is_refused_at_once(capsys: pytest.CaptureFixture[str]) -> None:
    err = refused(capsys, "solve", "drop-rebound", "--set", "h_drop=2 mm^9999999", "--set", "h_rebound=1")
    assert "expected powers from -9 to 9" in err


@pytest.mark.parametrize("value", ["1e309", "inf", "9" * 400])
def test_input_beyond_float64_is_refused_like_inf_and_json_stays_valid(tmp_path: Path,
                                                                      capsys: pytest.CaptureFixture[str],
                                                                      value: str) -> None:
    """`--set h_drop=1e309` printed "Infinity" in --json."""
    err = refused(capsys, "solve", "drop-rebound", "--set", f"h_drop={value}", "--set", "h_rebound=1", "--json")
    assert "--set h_drop: expected a finite number in mm, got" in err
    batch = write(tmp_path / "b.csv", f"h_drop,h_rebound\n{value},1\n")
    code, out, _ = run(capsys, "solve", "drop-rebound", "--batch", batch, "--json")
    record = json.loads(out, parse_constant=lambda c: pytest.fail(f"{c} in JSON"))
    assert code == 3 and "expected a finite number in mm" in record["error"]


def test_minus_zero_is_printed_as_zero(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "solve", "drop-rebound", "--set", "h_drop=2000", "--set", "h_rebound=-0", "--json")
    record = json.loads(out)
    assert code == 0 and "-0" not in out
    assert record["params"]["h_rebound"] == 0 and record["answers"]["e"]["value"] == 0


@pytest.mark.parametrize("p", ["1e-309", "5e-324", "2.2e-308"])
def test_a_subnormal_input_with_ordinary_answers_is_answered(capsys: pytest.CaptureFixture[str], p: str) -> None:
    """p = 1e-309 is a float64, and vA/v = 1: it was refused because a step, 1/p, overflows float64 (issue 22).
    Such rows are worked out again in numpy's longdouble."""
    code, out, _ = run(capsys, "solve", "car-collision", "--set", f"p={p}", "--set", "e=0.5", "--json")
    answers = json.loads(out)["answers"]
    assert code == 0 and (answers["vA_ratio"]["value"], answers["vB_ratio"]["value"]) == (1.0, 1.5)


@pytest.mark.parametrize(("fixed", "answer"), [
    ("{h_drop: 1.0e+30}", "h_drop = 1e+30 prints as 31 characters with 0 decimals"),
    ("{h_drop: 1.0e+300}", "h_drop = 1e+300 prints as 301 characters"),
])
def test_large_fixed_values_are_refused_not_a_decimal_error(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                            fixed: str, answer: str) -> None:
    err = generate_refused(capsys, tmp_path, ONE_PROBLEM + f"    fixed: {fixed}\n")
    assert "a.yaml: problem 1 (drop-rebound): " + answer in err


@pytest.mark.parametrize(("template", "fixed", "answer"), [
    ("ball-plate", "{theta: 90, e: 0}", "answer v_out is 0 for every variant"),
    ("car-collision", "{p: 1, e: 1}", "answer vA_ratio is 0 for every variant"),
])
def test_fixed_parameters_that_zero_an_answer_for_everyone_stop_the_run(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], template: str, fixed: str, answer: str) -> None:
    """The near-zero redraw compared with a typical size taken from the same fixed draws: 0."""
    text = f"title: HW\ncourse: C\nseed: s\nproblems:\n  - template: {template}\n    fixed: {fixed}\n"
    err = generate_refused(capsys, tmp_path, text)
    assert f"problem 1 ({template}): {answer}" in err and "cannot be graded with a relative tolerance" in err


@pytest.mark.parametrize("points", ["1e308", "-2", "{e: 2000000}"])
def test_points_beyond_a_million_or_negative_are_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                          points: str) -> None:
    """1e308 per part was accepted: a total of two overflows to inf."""
    err = generate_refused(capsys, tmp_path, ONE_PROBLEM + f"    points: {points}\n")
    assert "problems[0].points: expected a number, or answer name -> number (0 to 1,000,000)" in err
    assert "'*'" not in err  # the file's own words, not the internal form


# --- key.csv ids ------------------------------------------------------------------------------------

@given(st.text(max_size=20))
def test_a_guarded_key_csv_cell_gives_back_the_original(text: str) -> None:
    cell = safe_cell(text)
    assert original_cell(cell) == text
    number = re.fullmatch(r"-[0-9]*\.?[0-9]*(e[-+]?[0-9]+)?", text, re.I) and any(c.isdigit() for c in text)
    assert number or not cell.startswith(("=", "+", "-", "@", "\t", "\r", "\n", "\uff1d", "\uff0b", "\uff0d",
                                          "\uff20"))


@pytest.mark.parametrize("text", ["-0.369", "-2", "-1.5e-07", "-.5", "-3.", "-1E+300"])
def test_a_negative_number_is_written_as_a_number(text: str) -> None:
    """Issue 28: details.csv wrote '-0.369, text a spreadsheet's sum skips; a plain number runs nothing."""
    assert safe_cell(text) == text


@pytest.mark.parametrize("text", ["-0.369 m/s is 3 % above 0.358 m/s", "-1+1", "-2+3+cmd|' /C calc'!A0", "-", "-e5",
                                  "-1e", "-0.5 ", "-١", "-inf", "-nan", "--1", "-1,5"])
def test_a_text_starting_with_a_minus_stays_guarded(text: str) -> None:
    """What is not a plain number (a sentence, a formula, a digit a spreadsheet does not read as one) is
    text a spreadsheet would read as a formula: guarded."""
    assert safe_cell(text) == "'" + text


def test_a_formula_like_id_is_guarded_in_key_csv_and_kept_in_key_json(tmp_path: Path,
                                                                       capsys: pytest.CaptureFixture[str]) -> None:
    a = write(tmp_path / "a.yaml", ONE_PROBLEM)
    r = write(tmp_path / "r.csv", "id,name,email,section\n=1+1,Ana,a@x,1\n'q,Bo,b@x,1\n")
    code, _, err = run(capsys, "generate", a, "--roster", r, "--out", tmp_path / "out", "--no-pdf")
    assert code == 0, err
    import csv

    with open(tmp_path / "out" / "key.csv", encoding="utf-8", newline="") as stream:
        ids = [row["student_id"] for row in csv.DictReader(stream)]
    assert ids[0] == "'=1+1" and ids[-1] == "''q"
    assert {original_cell(i) for i in ids} == {"=1+1", "'q"}
    students = json.loads((tmp_path / "out" / "key.json").read_text(encoding="utf-8"))["students"]
    assert [s["id"] for s in students] == ["=1+1", "'q"]


# --- arbitrary bytes --------------------------------------------------------------------------------

FUZZ = settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
CSV_ALPHABET = st.sampled_from([b"h_drop", b"h_rebound", b"id", b"name", b"email", b"section", b",", b";", b"\t",
                                b"\n", b"\r\n", b'"', b"1", b"2.5e3", b"-0", b"1e309", b" mm", b"\xff", b"\0",
                                b"\xef\xbb\xbf", b"=1+1", "\u200b".encode()])


def csv_bytes() -> st.SearchStrategy[bytes]:
    return st.one_of(st.binary(max_size=200), st.lists(CSV_ALPHABET, max_size=40).map(b"".join))


YAML_ALPHABET = st.sampled_from([b"title: ", b"course: ", b"seed: ", b"problems:", b"\n", b"  - ", b"template: ",
                                 b"drop-rebound", b"fixed: ", b"{h_drop: ", b"}", b"[", b"]", b"&a ", b"*a", b"1e400",
                                 b"9" * 50, b"points: ", b"x", b"\xff", b"'", b'"', b": ", b"- ", b"\t", b"{", b","])


def yaml_bytes() -> st.SearchStrategy[bytes]:
    return st.one_of(st.binary(max_size=200), st.lists(YAML_ALPHABET, max_size=40).map(b"".join))


def assert_clean_exit(code: int, out: str, err: str, out_folder: Path | None = None) -> None:
    assert code in (0, 2, 3), err
    assert "Traceback" not in err
    for line in out.splitlines():
        json.loads(line, parse_constant=lambda c: pytest.fail(f"{c} in JSON"))
    if out_folder is not None:
        assert out_folder.exists() == (code == 0)
        assert sorted(p.name for p in out_folder.parent.iterdir() if p.name.startswith(".")) == []


@FUZZ
@given(data=csv_bytes())
def test_arbitrary_bytes_as_a_batch_csv(tmp_path: Path, capsys: pytest.CaptureFixture[str], data: bytes) -> None:
    batch = write(Path(tempfile.mkdtemp(dir=tmp_path)) / "b.csv", data)
    assert_clean_exit(*run(capsys, "solve", "drop-rebound", "--batch", batch, "--json"))


@FUZZ
@given(data=csv_bytes())
def test_arbitrary_bytes_as_a_roster(tmp_path: Path, capsys: pytest.CaptureFixture[str], data: bytes) -> None:
    case = Path(tempfile.mkdtemp(dir=tmp_path))  # Hypothesis runs every example in one tmp_path
    a, r, out = write(case / "a.yaml", ONE_PROBLEM), write(case / "r.csv", data), case / "out"
    code, stdout, err = run(capsys, "generate", a, "--roster", r, "--out", out, "--no-pdf")
    assert_clean_exit(code, stdout, err, out)


@FUZZ
@given(data=yaml_bytes())
def test_arbitrary_bytes_as_an_assignment(tmp_path: Path, capsys: pytest.CaptureFixture[str], data: bytes) -> None:
    case = Path(tempfile.mkdtemp(dir=tmp_path))
    a, out = write(case / "a.yaml", data), case / "out"
    code, stdout, err = run(capsys, "generate", a, "--roster", ROSTER, "--out", out, "--no-pdf")
    assert_clean_exit(code, stdout, err, out)



# --- found by the hostile sweep of the merged command line -------------------------------------------

@pytest.mark.parametrize(("old", "new", "message"), [
    # YAML 1.1 read these keys as true, None, a number: a parameter named `on` is ordinary text now
    ("  h_drop:", "  1:", "line 13: expected a key that is a name, got 1"),
    ("symbols:\n  m: {unit: kg, description: mass of the ball (it cancels)}", "symbols: m",
     "symbols: expected a mapping of names"),
    ("constraints:\n  - require: h_rebound <= h_drop\n    message: the ball cannot bounce higher than it was "
     "dropped from\n", "constraints: 5\n", "constraints: expected a list, got 5"),
    ("  - effect: free_fall", "  - effect: [free_fall]", "stages[0].effect: expected one of angle_between, "),
    ("    body: ball\n    height: h_drop", "    body: {b: 1}\n    height: h_drop", "stages[0].body: expected one"),
    ("value: f_loss", "value: h_drop**h_drop", "answers.loss_pct.value: expected an expression whose terms have one "
                                               "dimension, got 'h_drop**h_drop', which raises to a power that is a "
                                               "length"),
    ("value: f_loss", "value: sqrt(-e)", "drop-rebound.yaml: stages or answers: expected only real, finite"),
    ("restitution: e\n", "restitution: e**e**e**e\n", "drop-rebound.yaml: stages or answers: expected "
                                                          "expressions the solver can work with"),
])
def test_hostile_template_structures_are_refused_naming_the_file(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                                 old: str, new: str, message: str) -> None:
    folder = bank_with(tmp_path, "drop-rebound", old, new)
    err = refused(capsys, *ONLY, folder, "solve", "drop-rebound", "--set", "h_drop=2000", "--set", "h_rebound=900")
    assert message in err, err


def test_a_parameter_named_on_is_a_name_not_true(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    text = (bank_dir() / "drop-rebound.yaml").read_text(encoding="utf-8")
    folder = tmp_path / "bank"
    folder.mkdir()
    write(folder / "drop-rebound.yaml", text.replace("h_drop", "on"))
    code, out, err = run(capsys, *ONLY, folder, "solve", "drop-rebound", "--set", "on=2100", "--set",
                         "h_rebound=1100", "--json")
    assert code == 0, err
    assert json.loads(out)["answers"]["e"]["value"] == pytest.approx((1100 / 2100) ** 0.5, rel=1e-12)


@pytest.mark.parametrize(("template", "old", "new"), [
    ("ball-plate", "restitution: e", "restitution: 1/0"),
    ("ball-plate", "before: {ball: {n: v_n, t: v_t}}", "before: {}"),
])
def test_expressions_the_solver_cannot_handle_are_template_errors(tmp_path: Path,
                                                                  capsys: pytest.CaptureFixture[str],
                                                                  template: str, old: str, new: str) -> None:
    folder = bank_with(tmp_path, template, old, new)
    err = refused(capsys, *ONLY, folder, "solve", template, "--set", "v=1", "--set", "theta=30", "--set", "e=0.5")
    assert f"{template}.yaml: " in err and "expected" in err


def test_a_constant_answer_beyond_float64_is_a_refused_row(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    folder = bank_with(tmp_path, "drop-rebound", "value: f_loss", "value: 1e308")
    code, out, _ = run(capsys, *ONLY, folder, "solve", "drop-rebound", "--set", "h_drop=2", "--set", "h_rebound=1")
    assert code == 3 and "answer loss_pct: a step of the solution is not a finite number" in out


def test_a_named_pipe_in_the_bank_is_refused_not_waited_on(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    import os

    os.mkfifo(tmp_path / "fifo.yaml")
    assert "fifo.yaml: expected a template file, got a special file" in refused(capsys, *ONLY, tmp_path, "list")


def test_a_header_of_20000_columns_is_refused_quickly_with_a_short_message(tmp_path: Path,
                                                                          capsys: pytest.CaptureFixture[str]) -> None:
    batch = write(tmp_path / "b.csv", "h_drop,h_rebound," + ",".join(f"c{i}" for i in range(20_000)) + "\n1,1\n")
    err = refused(capsys, "solve", "drop-rebound", "--batch", batch)
    assert "unknown parameter(s) c0, c1, c2, c3, c4, c5, c6, c7, c8, c9 and 19,990 more" in err and len(err) < 400


def test_a_deeply_nested_manifest_is_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "out"
    out.mkdir()
    write(out / ".grader-manifest.json", '{"a":' + "[" * 100_000 + "1" + "]" * 100_000 + "}")
    a = write(tmp_path / "a.yaml", ONE_PROBLEM)
    err = refused(capsys, "generate", a, "--roster", ROSTER, "--out", out, "--no-pdf", "--force")
    assert ".grader-manifest.json: expected a manifest grader wrote" in err


def test_plot_into_a_missing_folder_is_refused_and_creates_nothing(tmp_path: Path,
                                                                   capsys: pytest.CaptureFixture[str]) -> None:
    err = refused(capsys, "simulate", "drop-rebound", "--set", "h_drop=2100", "--set", "h_rebound=1100", "--plot",
                  tmp_path / "no" / "such" / "p.png", within=5)
    assert "does not exist; create it first" in err and not (tmp_path / "no").exists()


@pytest.mark.parametrize("how", ["ctrl-c", "sigterm"])
def test_an_interrupted_run_is_one_line_and_leaves_nothing(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                           monkeypatch: pytest.MonkeyPatch, how: str) -> None:
    """Ctrl-C printed a KeyboardInterrupt traceback; a SIGTERM left the .partial work folder behind."""
    import os
    import signal

    import grader.render.generate as job

    def stop(*_: object) -> None:
        if how == "ctrl-c":
            raise KeyboardInterrupt
        os.kill(os.getpid(), signal.SIGTERM)

    monkeypatch.setattr(job, "ClassDraws", stop)  # while the class is drawn (without PDFs, a piece at a time)
    a = write(tmp_path / "a.yaml", ONE_PROBLEM)
    code, out, err = run(capsys, "generate", a, "--roster", ROSTER, "--out", tmp_path / "out", "--no-pdf")
    assert (code, out) == (130, "") and err == "grader: error: interrupted; nothing was left half-written\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.yaml"]


def test_a_closed_standard_output_is_one_line(capsys: pytest.CaptureFixture[str],
                                              monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr("sys.stdout", None)
    assert main(["list"]) == 2
    assert "standard output is closed" in capsys.readouterr().err


def test_a_batch_from_a_closed_standard_input_is_one_line(capsys: pytest.CaptureFixture[str],
                                                          monkeypatch: pytest.MonkeyPatch) -> None:
    """`grader check --batch - <&-` was an AttributeError's traceback."""
    monkeypatch.setattr("sys.stdin", None)
    assert "--batch -: standard input is closed" in refused(capsys, "check", "--batch", "-")


def test_control_characters_from_input_are_escaped_in_messages(capsys: pytest.CaptureFixture[str]) -> None:
    err = refused(capsys, "solve", "ball-plate", "--set", "v=5 \x1b[31mred", "--set", "theta=30", "--set", "e=0.5")
    assert "\x1b" not in err and "\\x1b[31mred" in err
