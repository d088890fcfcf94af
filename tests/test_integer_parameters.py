"""Integer parameters (issue 14): ``integer: true``, sampled with ``{integers: [a, b]}`` (or a choice of whole
numbers), printed as whole numbers, and refused with the reason when a given value is not a whole number in
the domain, in every command that takes parameters. Grading an answer is unchanged."""

from __future__ import annotations

import csv
import io
import json
from collections import Counter
from pathlib import Path

import pytest
import yaml

from grader.bank.template import parse_template
from grader.base.errors import TemplateError
from grader.cli import main
from grader.simulate.walker import simulate

BOUNCES = {
    "id": "counted", "title": "t", "version": 1, "gravity": "9.81 m/s^2",
    "bodies": {"ball": {"mass": "m"}, "floor": {"fixed": True}},
    "symbols": {"m": {"unit": "kg"}},
    "parameters": {
        "h0": {"unit": "m", "domain": "(0, inf)", "sample": {"uniform": [1, 2]}, "decimals": 2},
        "e": {"unit": "", "domain": "[0, 1]", "sample": {"uniform": [0.5, 0.8]}, "decimals": 2},
        "n": {"unit": "", "integer": True, "domain": "[1, inf)", "sample": {"integers": [1, 4]},
              "description": "bounces counted"},
    },
    "stages": [{"effect": "bounces", "bodies": ["ball", "floor"], "height": "h0", "restitution": "e", "count": "n",
                "rebound": "h_n"}],
    "answers": {"h_n": {"value": "h_n", "unit": "m"}},
    "statement": "After {{ n }} bounces from {{ h0 }} m with e = {{ e }}?",
}


def _template(**changes: object) -> dict[str, object]:
    raw = json.loads(json.dumps(BOUNCES))
    for name, spec in changes.items():
        raw["parameters"]["n"] = {**raw["parameters"]["n"], **spec} if spec is not None else None  # type: ignore[index]
        assert name == "n"
    return raw


def test_an_integer_parameter_prints_as_a_whole_number_and_samples_its_range() -> None:
    template = parse_template(_template(), "test:counted", "x")
    n = template.parameters["n"]
    assert n.integer and n.decimals == 0 and n.sig_figs is None
    assert (n.sample.kind, n.sample.values) == ("integers", (1.0, 4.0))


@pytest.mark.parametrize(("spec", "expected"), [
    ({"sig_figs": 2}, "parameters.n: expected no printed precision, or decimals: 0"),
    ({"decimals": 1}, "parameters.n: expected no printed precision, or decimals: 0"),
    ({"sample": {"uniform": [1, 4]}}, "parameters.n.sample: expected {integers: [a, b]} (each whole number from a to "
                                      "b) or {choice: [n, ...]} for an integer parameter"),
    ({"sample": {"integers": [1, 4.5]}}, "parameters.n.sample.integers: expected whole numbers (the parameter is an "
                                         "integer), got [1, 4.5]"),
    ({"sample": {"choice": [1, 2.5]}}, "expected whole numbers"),
    ({"sample": {"integers": [0, 3]}}, "expected values inside the domain [1, inf), got 0"),
    ({"integer": "yes"}, "parameters.n.integer: expected true or false"),
])
def test_an_integer_parameter_written_wrong_is_refused_naming_the_key(spec: dict[str, object], expected: str) -> None:
    with pytest.raises(TemplateError) as caught:
        parse_template(_template(n=spec), "test:counted", "x")
    assert expected in str(caught.value)


def test_integers_sampling_is_only_for_integer_parameters() -> None:
    raw = _template()
    raw["parameters"]["h0"]["sample"] = {"integers": [1, 3]}  # type: ignore[index]
    with pytest.raises(TemplateError, match=r"parameters.h0.sample: .*\{integers: \[a, b\]\} only with integer: true"):
        parse_template(raw, "test:counted", "x")


def test_an_example_that_is_not_a_whole_number_is_refused() -> None:
    raw = _template()
    raw["example"] = {"n": 2.5}
    with pytest.raises(TemplateError, match=r"example.n: expected a whole number \(n is an integer parameter"):
        parse_template(raw, "test:counted", "x")


@pytest.mark.parametrize(("value", "reason"), [
    ("2.5", "n = 2.5 is not a whole number; n is an integer parameter (number of bounces counted)"),
    ("0", "n = 0 is outside its domain [1, inf)"),
])
def test_solve_refuses_a_count_that_is_not_a_whole_number_at_least_1(capsys: pytest.CaptureFixture[str], value: str,
                                                                     reason: str) -> None:
    code = main(["solve", "successive-bounces", "--set", "h0=2", "--set", "e=0.5", "--set", f"n={value}"])
    assert code == 3
    assert f"refused: {reason}" in capsys.readouterr().out


def test_simulate_refuses_a_count_that_is_not_a_whole_number(capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["simulate", "successive-bounces", "--set", "h0=2", "--set", "e=0.5", "--set", "n=2.5"])
    assert code == 3
    assert "n = 2.5 is not a whole number" in capsys.readouterr().out


def test_simulate_called_directly_refuses_it_too(bank: dict[str, object]) -> None:
    from grader.base.errors import GraderError

    with pytest.raises(GraderError, match=r"n = 1.5 is not a whole number; n is an integer parameter"):
        simulate(bank["successive-bounces"], {"h0": 2.0, "e": 0.5, "n": 1.5})  # type: ignore[arg-type]


def _assignment(tmp_path: Path, problem: dict[str, object]) -> Path:
    path = tmp_path / "hw.yaml"
    path.write_text(yaml.safe_dump({"title": "HW", "course": "C", "seed": "s", "due": "d", "problems": [
        {"key": "1", "template": "successive-bounces", "points": 1, **problem}]}), encoding="utf-8")
    (tmp_path / "roster.csv").write_text("id,name,email,section\n" + "".join(
        f"{1000 + i},Student {i},s{i}@x.org,A\n" for i in range(60)), encoding="utf-8")
    return path


@pytest.mark.parametrize(("problem", "expected"), [
    ({"fixed": {"n": 2.5}}, "problems[0].fixed.n: expected a whole number (n is an integer parameter: number of "
                            "bounces counted), got 2.5"),
    ({"fixed": {"n": 0}}, "problems[0].fixed.n: expected a whole number in the parameter's domain [1, inf), got 0"),
    ({"narrow": {"n": [2, 3.5]}}, "problems[0].narrow.n: expected a whole number (n is an integer parameter"),
])
def test_an_assignment_fixing_a_count_that_is_not_a_whole_number_is_refused(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], problem: dict[str, object], expected: str) -> None:
    path = _assignment(tmp_path, problem)
    code = main(["generate", str(path), "--roster", str(tmp_path / "roster.csv"), "--out", str(tmp_path / "out"),
                 "--no-pdf"])
    assert code == 2
    assert expected in capsys.readouterr().err


def _key(tmp_path: Path, problem: dict[str, object], capsys: pytest.CaptureFixture[str]) -> dict[str, object]:
    path = _assignment(tmp_path, problem)
    code = main(["generate", str(path), "--roster", str(tmp_path / "roster.csv"), "--out", str(tmp_path / "out"),
                 "--no-pdf"])
    assert code == 0, capsys.readouterr().err
    return json.loads((tmp_path / "out" / "key.json").read_text(encoding="utf-8"))  # type: ignore[no-any-return]


def test_generate_draws_every_whole_number_of_the_range_and_prints_it_so(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    key = _key(tmp_path, {}, capsys)
    problems = [p for s in key["students"] for p in s["problems"]]  # type: ignore[attr-defined]
    counts = Counter(p["printed"]["n"] for p in problems)
    assert set(counts) == {"2", "3", "4", "5"}  # the bank's {integers: [2, 5]}, ends included
    assert all(p["params"]["n"] == int(p["printed"]["n"]) for p in problems)


def test_a_narrowed_count_is_drawn_from_the_narrowed_whole_numbers(tmp_path: Path,
                                                                   capsys: pytest.CaptureFixture[str]) -> None:
    key = _key(tmp_path, {"narrow": {"n": [1, 2]}}, capsys)
    assert {p["printed"]["n"] for s in key["students"] for p in s["problems"]} == {"1", "2"}  # type: ignore[attr-defined]


def test_the_key_of_a_counted_problem_grades_to_full_marks(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    key = _key(tmp_path, {"fixed": {"n": 3}}, capsys)
    capsys.readouterr()
    stream = io.StringIO()
    writer = csv.writer(stream, lineterminator="\n")
    writer.writerow(["student_id", "label", "answer"])
    for student in key["students"]:  # type: ignore[attr-defined]
        assert student["problems"][0]["printed"]["n"] == "3"
        for answer in student["problems"][0]["answers"].values():
            writer.writerow([student["id"], answer["label"], f"{answer['value']:.4g}"])
    (tmp_path / "answers.csv").write_text(stream.getvalue(), encoding="utf-8")
    code = main(["grade", "--key", str(tmp_path / "out" / "key.json"), str(tmp_path / "answers.csv"), "--out",
                 str(tmp_path / "grades"), "--json"])
    summary = json.loads(capsys.readouterr().out)
    assert code == 0 and summary["verdicts"]["correct"] == summary["parts"] == 180


def test_show_says_the_parameter_is_a_whole_number(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["show", "successive-bounces", "--json"]) == 0
    shown = json.loads(capsys.readouterr().out)
    assert shown["parameters"]["n"]["integer"] is True and shown["parameters"]["h0"]["integer"] is False
    assert shown["example"]["n"] == "3"
