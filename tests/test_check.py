"""`grader check`: one answer graded as `grader grade` grades it, against a key's part or a given value.

Expected values are written here by hand (the boundaries are PrairieLearn's rules worked out on paper).
"""

from __future__ import annotations

import csv
import io
import json
from pathlib import Path
from typing import Any

import pytest

from grader.cli import main
from grader.grade.check import FIELDS

KEY = {
    "schema": "grader-key", "version": 2,
    "assignment": {"title": "HW 3", "grading": {"numeric_expressions": True}},
    "problems": [{"key": "1", "title": "Pile", "answers": [
        {"name": "v", "label": "1a", "unit": "m/s", "points": 2},
        {"name": "theta", "label": "1b", "unit": "deg", "points": 1},
        {"name": "vA", "label": "1c", "unit": "m/s", "points": 1, "symbols": {"p": [0.1, 10], "v": [1, 10]}}]}],
    "students": [{"id": "00123", "name": "Ana", "email": "Ana@Example.edu", "section": "1", "problems": [{
        "key": "1", "answers": {
            "v": {"value": 6.26, "unit": "m/s", "label": "1a", "points": 2, "tolerance": {"rtol": 0.01, "atol": 0}},
            "theta": {"value": None, "unit": "deg", "label": "1b", "points": 1,
                      "tolerance": {"mode": "decimals", "digits": 1}, "undefined": "the ball stops"},
            "vA": {"value": "v*(1 - 0.1*p)/(1 + p)", "unit": "m/s", "label": "1c", "points": 1,
                   "tolerance": {"rtol": 0.01, "atol": 0}}}}]}],
}


@pytest.fixture
def key_path(tmp_path: Path) -> Path:
    path = tmp_path / "key.json"
    path.write_text(json.dumps(KEY), encoding="utf-8")
    return path


def run(capsys: pytest.CaptureFixture[str], *argv: object) -> tuple[int, str, str]:
    code = main(["check", *(str(a) for a in argv)])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def checked(capsys: pytest.CaptureFixture[str], *argv: object) -> dict[str, Any]:
    code, out, err = run(capsys, *argv, "--json")
    assert code == 0, err
    result = json.loads(out)
    assert tuple(result) == FIELDS
    return result  # type: ignore[no-any-return]


def test_an_answer_with_another_unit_against_a_given_value(capsys: pytest.CaptureFixture[str]) -> None:
    result = checked(capsys, "626 cm/s", "--expected", "6.26", "--unit", "m/s")
    assert result == {"verdict": "correct", "credit": 1.0, "parsed": 6.26, "expected": 6.26, "unit": "m/s",
                      "abs_error": 0.0, "rel_error": 0.0, "tolerance": "±1 %", "tolerance_reason": "",
                      "feedback": "626 cm/s = 6.26 m/s equals 6.26 m/s; within ±1 % is accepted", "diagnosis": ""}
    wrong = checked(capsys, "6.26 kg", "--expected", "6.26 m/s")
    assert (wrong["verdict"], wrong["feedback"]) == ("incorrect", "expected a speed (m/s), got a mass (kg)")


def test_negative_numbers_in_exponent_form_are_values_not_options(capsys: pytest.CaptureFixture[str]) -> None:
    """argparse alone takes ``-6.3e0`` for an unknown option; answers and expected values are often negative."""
    assert checked(capsys, "-6.3e0", "--expected", "-6.26e0", "--unit", "m/s")["verdict"] == "correct"
    assert checked(capsys, "-1e308", "--expected", "-1E308")["verdict"] == "correct"
    code, _, err = run(capsys, "1", "--expected", "1", "--atol", "-.5e-3")  # read, then refused for its sign
    assert code == 2 and "expected one argument" not in err and "atol" in err, err


@pytest.mark.parametrize(("answer", "mode", "verdict"), [
    ("6.3226", ["--rtol", "0.01"], "correct"),  # exactly 1 % above
    ("6.3227", ["--rtol", "0.01"], "incorrect"),
    ("6.36", ["--rtol", "0", "--atol", "0.1"], "correct"),  # on the absolute bound
    ("6.3601", ["--rtol", "0", "--atol", "0.1"], "incorrect"),
    ("6.265", ["--sigfigs", "3"], "correct"),  # 0.005 < 0.51e-2
    ("6.2652", ["--sigfigs", "3"], "incorrect"),  # 0.0052 > 0.0051
    ("6.3", ["--sigfigs", "2"], "correct"),  # 0.04 < 0.51e-1
    ("6.2", ["--sigfigs", "2"], "incorrect"),  # 0.06 > 0.051
    ("6.31", ["--decimals", "1"], "correct"),  # 0.05 < 0.051
    ("6.312", ["--decimals", "1"], "incorrect"),  # 0.052
])
def test_each_tolerance_mode_at_its_boundary(capsys: pytest.CaptureFixture[str], answer: str, mode: list[str],
                                             verdict: str) -> None:
    assert checked(capsys, answer, "--expected", "6.26", *mode)["verdict"] == verdict


def test_angles_and_expressions(capsys: pytest.CaptureFixture[str]) -> None:
    assert checked(capsys, "-19.1", "--expected", "340.9", "--unit", "deg")["verdict"] == "correct"
    same = checked(capsys, "(1+p)v", "--expected", "v + p v", "--domain", "p=0.1:10", "--domain", "v=1:30")
    assert (same["verdict"], same["parsed"], same["expected"]) == ("correct", "(1 + p)*v", "v + p*v")
    other = checked(capsys, "v(1-p)", "--expected", "v*(1+p)", "--symbols", "p,v")
    assert other["verdict"] == "incorrect"
    unknown = checked(capsys, "2m", "--expected", "2v", "--symbols", "p,v")
    assert (unknown["verdict"], unknown["feedback"]) == ("invalid", "could not read this answer: unknown name m; "
                                                                    "use p and v")


def test_against_a_students_part_of_a_key(capsys: pytest.CaptureFixture[str], key_path: Path) -> None:
    by_id = checked(capsys, "--key", key_path, "--student", "00123", "--label", "1a", "6,3 m/s")
    assert (by_id["verdict"], by_id["parsed"], by_id["expected"]) == ("correct", 6.3, 6.26)
    by_email = checked(capsys, "--key", key_path, "--student", "ana@example.EDU", "--label", "1c", "0.9v/(1+p)")
    assert by_email["verdict"] == "incorrect"
    symbolic = checked(capsys, "--key", key_path, "--student", "00123", "--label", "1c", "v(1-0.1p)/(1+p)")
    assert symbolic["verdict"] == "correct"
    human = run(capsys, "--key", key_path, "--student", "00123", "--label", "1a", "6.5")
    assert human[0] == 0 and "incorrect (credit 0)" in human[1] and "6.5 m/s is 3.8 % above 6.26 m/s" in human[1]


@pytest.mark.parametrize(("answer", "verdict"), [("", "correct"), ("undefined", "correct"), ("0", "incorrect")])
def test_an_undefined_key_value_accepts_a_blank_or_undefined(capsys: pytest.CaptureFixture[str], key_path: Path,
                                                             answer: str, verdict: str) -> None:
    result = checked(capsys, "--key", key_path, "--student", "00123", "--label", "1b", answer)
    assert result["verdict"] == verdict and result["expected"] is None and "the ball stops" in result["feedback"]


def test_check_agrees_with_grade_cell_for_cell(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                               key_path: Path) -> None:
    answers = {"1a": "≈ 6.1 m/s", "1b": "12.5", "1c": "v(1 - p/10)/(p+1)"}
    stream = io.StringIO()
    csv.writer(stream, lineterminator="\n").writerows([["student_id", "label", "answer"],
                                                       *(["00123", label, text] for label, text in answers.items())])
    (tmp_path / "answers.csv").write_text(stream.getvalue(), encoding="utf-8")
    assert main(["grade", "--key", str(key_path), str(tmp_path / "answers.csv"), "--out", str(tmp_path / "g")]) == 0
    capsys.readouterr()
    with open(tmp_path / "g" / "details.csv", encoding="utf-8", newline="") as file:
        details = {row["label"]: row for row in csv.DictReader(file)}
    for label, text in answers.items():
        result = checked(capsys, "--key", key_path, "--student", "00123", "--label", label, text)
        row = details[label]
        assert (result["verdict"], result["tolerance"], result["feedback"]) == \
               (row["verdict"], row["tolerance"], row["feedback"])
    assert [details[label]["verdict"] for label in answers] == ["incorrect", "incorrect", "correct"]


def test_a_batch_gives_one_line_per_line_in_order(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                  key_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    lines = [
        {"submitted": "626 cm/s", "expected": 6.26, "unit": "m/s"},
        {"submitted": "6.4", "expected": 6.26, "tolerance": {"mode": "decimals", "digits": 1}},
        "not json",
        {"submitted": "0.1pv", "expected": "p*v/10", "symbols": ["p", "v"], "domains": {"p": [0.1, 10]}},
        {"submitted": "", "expected": None},
        {"submitted": "1", "expected": 1, "tolerance": {"rtol": -1}},
        {"submitted": "6.26", "student": "00123", "label": "1a"},
        {"submitted": "1", "expected": 1, "domains": {"p": [2, 1]}},
    ]
    batch = tmp_path / "answers.jsonl"
    batch.write_text("\n".join(line if isinstance(line, str) else json.dumps(line) for line in lines) + "\n\n",
                     encoding="utf-8")
    code, out, _ = run(capsys, "--batch", batch)
    results = [json.loads(line) for line in out.splitlines()]
    assert code == 3 and len(results) == len(lines)
    assert [r.get("verdict") for r in results] == ["correct", "incorrect", None, "correct", "correct", None, None,
                                                   None]
    errors = {r["line"]: r["error"] for r in results if "error" in r}
    assert set(errors) == {3, 6, 7, 8}
    assert "invalid JSON" in errors[3] and "tolerance.rtol" in errors[6] and "need --key" in errors[7]
    assert "LOW < HIGH" in errors[8]
    monkeypatch.setattr("sys.stdin", io.TextIOWrapper(io.BytesIO(batch.read_bytes())))
    code, out, _ = run(capsys, "--batch", "-", "--key", key_path)
    assert json.loads(out.splitlines()[6])["verdict"] == "correct"
    good = tmp_path / "good.jsonl"
    good.write_text(json.dumps(lines[0]) + "\n", encoding="utf-8")
    assert run(capsys, "--batch", good)[0] == 0


def test_batch_lines_beyond_float64_are_error_lines_and_every_line_is_strict_json(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Each of these stopped the whole batch with a traceback (OverflowError, numpy's "high - low range
    exceeds valid bounds", a UnicodeEncodeError printing an error that echoed a lone surrogate)."""
    lines = [
        '{"submitted": "6.3", "expected": 1' + "0" * 400 + "}",
        '{"submitted": "v", "expected": "v", "domains": {"v": [1, 1' + "0" * 400 + "]}}",
        '{"submitted": "v", "expected": "v", "domains": {"v": [-1.7e308, 1.7e308]}}',
        '{"submitted": "6", "expected": 6, "unit": "\\ud800"}',
        '{"submitted": "6.3", "expected": 6.26}',
    ]
    batch = tmp_path / "answers.jsonl"
    batch.write_text("\n".join(lines) + "\n", encoding="utf-8")
    code, out, _ = run(capsys, "--batch", batch)
    out.encode("utf-8")  # strict: no lone surrogate
    results = [json.loads(line) for line in out.splitlines()]
    assert code == 3 and len(results) == len(lines)
    assert [r.get("line") for r in results] == [1, 2, 3, 4, None]
    assert "expected: expected a finite number" in results[0]["error"]
    assert all("LOW < HIGH" in r["error"] for r in results[1:3])
    assert results[3]["error"] == "unit: cannot read unit '\ud800' (write units like m, m/s, m/s^2, kg, deg, %)"


def test_a_batch_line_with_a_field_given_twice_is_an_error_line_naming_it(tmp_path: Path,
                                                                         capsys: pytest.CaptureFixture[str]) -> None:
    """JSON's rule, the last of two equal names wins, checked the line against the second "expected" and
    said nothing (issue 22); at any depth, the line and the field are named and the other lines go on."""
    lines = ['{"submitted": "1", "expected": 1, "expected": 2}',
             '{"submitted": "1", "expected": 1, "tolerance": {"rtol": 0.5, "rtol": 0.01}}',
             '{"submitted": "v", "expected": "v", "domains": {"v": [1, 2], "v": [3, 4]}}',
             '{"submitted": "1", "expected": 1}']
    batch = tmp_path / "answers.jsonl"
    batch.write_text("\n".join(lines) + "\n", encoding="utf-8")
    code, out, _ = run(capsys, "--batch", batch)
    assert code == 3
    assert [json.loads(line) for line in out.splitlines()][:3] == [
        {"line": number, "error": f"the field '{name}' appears twice; expected each field once (the last would win)"}
        for number, name in ((1, "expected"), (2, "rtol"), (3, "v"))]
    assert json.loads(out.splitlines()[3])["verdict"] == "correct"


@pytest.mark.parametrize(("argv", "feedback"), [
    (["1e308", "--expected=-1e308"], "1e308 is more than 1.8e308 % above -1e308; only ±1 % is accepted"),
    (["1e308", "--expected=1"], "1e308 is more than 1.8e308 % above 1; only ±1 % is accepted"),
    (["1e308", "--expected=-1e308", "--sigfigs", "3"],
     "1e308 does not match -1e308 to 3 significant figures (it is more than 1.8e308 above)"),
])
def test_a_difference_beyond_float64_is_said_in_words_never_inf(capsys: pytest.CaptureFixture[str],
                                                                argv: list[str], feedback: str) -> None:
    """The feedback said "1e308 is inf % above 1" (details.csv too)."""
    assert checked(capsys, *argv)["feedback"] == feedback


def test_the_printed_error_of_a_difference_beyond_float64_is_no_inf(capsys: pytest.CaptureFixture[str]) -> None:
    """The relative error as a percentage overflowed: "error  1.79769e+308 (inf %)"."""
    code, out, _ = run(capsys, "1e308", "--expected=-1e308")
    assert code == 0 and "error      1.79769e+308 (1.8e+308 %)" in out and "inf" not in out


def test_an_expected_minus_zero_is_zero(capsys: pytest.CaptureFixture[str]) -> None:
    assert str(checked(capsys, "0", "--expected", "-0")["expected"]) == "0.0"


def test_student_and_label_are_read_as_grade_reads_their_cells(capsys: pytest.CaptureFixture[str],
                                                                key_path: Path) -> None:
    """Spaces around an id, a label in other case: grade matches them; check said "no part ' 1A '"."""
    result = checked(capsys, "--key", key_path, "--student", " 00123 ", "--label", " 1A ", "6.26")
    assert (result["verdict"], result["expected"]) == ("correct", 6.26)


@pytest.mark.parametrize(("argv", "message"), [
    (["6.3"], "expected --expected VALUE"),
    (["--expected", "6.26"], "expected the answer to check"),
    (["6.3", "--expected", "6.26", "--sigfigs", "3", "--rtol", "0.1"], "choose one tolerance mode"),
    (["6.3", "--expected", "6.26", "--unit", "furlongs"], "unit: unknown unit 'furlongs'"),
    (["6.3", "--expected", "6.26 m/s", "--unit", "ft/s"], "give the unit once"),
    (["6.3", "--expected", "6.26", "--sigfigs", "0"], "tolerance.digits"),
    (["6.3", "--expected", "__import__('os')"], "expected \"__import__('os')\""),
    (["6.3", "--expected", "v", "--domain", "v=3:1"], "LOW < HIGH"),
    (["6.3", "--expected", "v", "--domain", "p=1:3"], "a domain for p"),
    (["6.3", "--expected", "v", "--domain", "v"], "expected NAME=LOW:HIGH"),
    (["6.3", "--key", "KEY", "--label", "1a"], "--key needs --student"),
    (["6.3", "--key", "KEY", "--student", "00123", "--label", "1a", "--unit", "m/s"], "come from the key"),
    (["6.3", "--key", "KEY", "--student", "123", "--label", "1a"], "did you mean 00123?"),
    (["6.3", "--key", "KEY", "--student", "00123", "--label", "9z"], "the parts are 1a, 1b, 1c"),
    (["6.3", "--batch", "x.jsonl"], "give it alone"),
    (["6.3", "--expected", "nan"], "expected 'nan': nan is not a finite number"),  # was an expression in "nan"
    (["6.3", "--expected", "inf", "--unit", "m"], "expected 'inf': inf is not a finite number"),
    (["6.3", "--expected", "v", "--symbols", ""], "symbols: expected names like p, v, got ['']"),  # "use ,  and"
    (["6.3", "--expected", "v", "--symbols", "p,,v"], "symbols: expected names like p, v"),
    # the last --domain won silently (issue 22)
    (["6.3", "--expected", "v", "--domain", "v=1:2", "--domain", "v=3:4"],
     "--domain v=3:4: v's domain is already given (--domain v=1:2); give each name once"),
])
def test_requests_that_cannot_be_carried_out_exit_2(capsys: pytest.CaptureFixture[str], key_path: Path,
                                                    argv: list[str], message: str) -> None:
    code, out, err = run(capsys, *(str(key_path) if a == "KEY" else a for a in argv))
    assert code == 2 and out == "" and message in err


def test_an_id_that_fits_two_students_once_zeros_are_restored_names_both(capsys: pytest.CaptureFixture[str],
                                                                         tmp_path: Path) -> None:
    """Issue 22: it said only "no student '123'"."""
    key = json.loads(json.dumps(KEY))
    key["students"].append({**key["students"][0], "id": "0123", "email": "bo@example.edu"})
    path = tmp_path / "key.json"
    path.write_text(json.dumps(key), encoding="utf-8")
    code, _out, err = run(capsys, "6.3", "--key", path, "--student", "123", "--label", "1a")
    assert code == 2 and "with leading zeros it could be 00123 or 0123: give the id in full" in err


@pytest.mark.parametrize(("answer", "feedback"), [
    ("6.26" + " +0" * 400, "could not read this answer: 1,204 characters; an answer has at most 1,000"),
    ("1.66 m^99999", "the power 99999 of the unit m is beyond the limit"),
    ("1e-400", "1e-400 is too small for a number"),
])
def test_issue_22_cells_say_what_is_wrong(capsys: pytest.CaptureFixture[str], answer: str, feedback: str) -> None:
    result = checked(capsys, answer, "--expected", "6.26", "--unit", "m")
    assert result["verdict"] == "invalid" and feedback in result["feedback"]


def test_a_batch_is_graded_a_chunk_at_a_time_not_a_line_at_a_time(monkeypatch: pytest.MonkeyPatch,
                                                                   key_path: Path) -> None:
    """Issue 22: 100,000 lines took 47 s, 145 s with --key: the work of a grading call was done a line at a
    time, and the key's students were searched a line at a time. The results are the same, in order."""
    from grader.grade import check as check_module
    from grader.grade.key import load_key

    calls = []
    real = check_module.grade_parts

    def counted(*args: Any, **kwargs: Any) -> Any:
        calls.append(len(args[0]))
        return real(*args, **kwargs)

    monkeypatch.setattr(check_module, "grade_parts", counted)
    key = load_key(key_path)
    lines = [json.dumps({"submitted": f"{6 + i / 1000}", "student": "00123", "label": "1a"}) for i in range(5000)]
    lines[7] = "not json"
    lines[9] = json.dumps({"submitted": "6.26 m/s", "expected": 6.26, "unit": "m/s"})
    results = list(check_module.batch(lines, key))
    assert len(results) == 5000 and results[7] == {"line": 8, "error": results[7]["error"]}
    verdicts = (results[9]["verdict"], results[0]["verdict"], results[300]["verdict"])
    assert verdicts == ("correct", "incorrect", "correct")
    assert [r["parsed"] for r in results[10:13]] == [6.01, 6.011, 6.012]
    assert sorted(calls) == [1, 904, 4094]  # two chunks; the line of a given value graded apart, one refused
