"""An assignment's ``parts:``: a problem asks some of its template's answers, and only those are on the sheet,
the key, the submissions and the grades; the simulated class's answers to one problem never move when
another problem asks more."""

from __future__ import annotations

import csv
import io
import json
from pathlib import Path

import pytest
import yaml

from grader.assign.assignment import load_assignment, load_roster
from grader.assign.sample_answers import sample_answers
from grader.assign.variants import generate
from grader.bank.template import Template
from grader.base.resources import sample_dir
from grader.cli import main
from grader.render.documents import statement
from grader.solve.evaluate import solve_one

ROSTER = sample_dir() / "roster.csv"
PILE = {"key": "P1", "template": "pile-driver", "parts": ["v_pile", "energy_lost", "impulse"]}


def _assignment(path: Path, *problems: dict[str, object]) -> Path:
    path.write_text(yaml.safe_dump({"title": "HW", "course": "C", "seed": "parts", "due": "2026-12-04 23:59",
                                    "problems": list(problems)}), encoding="utf-8")
    return path


def _run(capsys: pytest.CaptureFixture[str], *argv: str | Path) -> tuple[int, str, str]:
    code = main([str(a) for a in argv])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


@pytest.fixture(scope="module")
def key(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict]:
    folder = tmp_path_factory.mktemp("parts")
    out = folder / "out"
    assert main(["generate", str(_assignment(folder / "a.yaml", PILE)), "--roster", str(ROSTER), "--out", str(out),
                 "--no-pdf"]) == 0
    return out, json.loads((out / "key.json").read_text(encoding="utf-8"))


def test_the_key_holds_the_parts_asked_lettered_as_the_sheet_prints_them(key: tuple[Path, dict],
                                                                         bank: dict[str, Template],
                                                                         compiled: dict) -> None:
    """Relabelled a, b, c in the template's order; each value the solver's for the student's printed numbers."""
    for student in key[1]["students"]:
        (problem,) = student["problems"]
        assert [(name, answer["label"]) for name, answer in problem["answers"].items()] == [
            ("v_pile", "P1a"), ("energy_lost", "P1b"), ("impulse", "P1c")]
        solution = solve_one(bank["pile-driver"], compiled["pile-driver"], problem["params"])
        assert solution.answers is not None
        for name, answer in problem["answers"].items():
            assert answer["value"] == solution.answers[name].value


def test_the_key_submitted_as_answers_grades_to_full_marks(key: tuple[Path, dict], tmp_path: Path,
                                                           capsys: pytest.CaptureFixture[str]) -> None:
    out, document = key
    stream = io.StringIO()
    writer = csv.writer(stream, lineterminator="\n")
    writer.writerow(["student_id", "label", "answer"])
    for student in document["students"]:
        for answer in student["problems"][0]["answers"].values():
            writer.writerow([student["id"], answer["label"], f"{answer['value']:.4g}"])
    (tmp_path / "answers.csv").write_text(stream.getvalue(), encoding="utf-8")
    code, printed, _ = _run(capsys, "grade", "--key", out / "key.json", tmp_path / "answers.csv", "--out",
                            tmp_path / "grades", "--json")
    summary = json.loads(printed)
    assert code == 0 and summary["verdicts"]["correct"] == summary["parts"] == 3 * len(document["students"])


def test_the_sheet_asks_only_the_parts_asked(tmp_path: Path, bank: dict[str, Template]) -> None:
    """The statement's question is restated from the parts' descriptions; the scene is the template's."""
    assignment = load_assignment(_assignment(tmp_path / "a.yaml", PILE))
    variant = generate(assignment, load_roster(ROSTER)[:1], bank).students[0].problems[0]
    shown = str(statement(bank["pile-driver"], variant))
    assert "bounces back up" in shown and "coefficient of restitution" not in shown
    assert shown.rstrip().endswith("Find the velocity of the pile just after the impact, the kinetic energy lost "
                                   "in the impact and the magnitude of the impulse of the ram on the pile during "
                                   "the impact.")
    every = generate(load_assignment(_assignment(tmp_path / "b.yaml", {"template": "pile-driver"})),
                     load_roster(ROSTER)[:1], bank).students[0].problems[0]
    assert "and that energy in kilojoules" in " ".join(str(statement(bank["pile-driver"], every)).split())


@pytest.mark.parametrize("change, message", [
    ({"parts": ["v_pile", "energy"]}, "a.yaml: problems[0].parts (problem P1): expected answer names of pile-driver "
                                      "(v_pile, e, loss_pct, energy_lost, impulse), got energy"),
    ({"parts": []}, "a.yaml: problems[0].parts: expected a non-empty list of the template's answer names"),
    ({"parts": "v_pile"}, "a.yaml: problems[0].parts: expected a non-empty list"),
    ({"parts": ["e", "e"]}, "a.yaml: problems[0].parts: expected each answer name once, got e twice"),
    ({"parts": ["e"], "points": {"v_pile": 2}}, "expected points and tolerances only for the parts asked (e), got "
                                                "v_pile, not in parts"),
    ({"template": "skid", "parts": ["v_A"]}, "a.yaml: problems[0].parts (problem P1): expected no parts: every "
                                             "answer of skid, since its statement's question is not a sentence "
                                             "beginning Find"),
], ids=["unknown", "empty", "not-a-list", "twice", "points-not-asked", "question-not-restatable"])
def test_a_bad_parts_list_exits_2_naming_the_file_the_problem_and_the_parts(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], change: dict[str, object], message: str) -> None:
    assignment = _assignment(tmp_path / "a.yaml", {**PILE, **change})
    code, out, err = _run(capsys, "generate", assignment, "--roster", ROSTER, "--out", tmp_path / "out", "--no-pdf")
    assert (code, out) == (2, "")
    assert message in err, err
    assert not (tmp_path / "out").exists()


def test_a_part_added_to_one_problem_moves_no_other_problems_simulated_answers(tmp_path: Path,
                                                                              bank: dict[str, Template]) -> None:
    """Problem 2 asking two more parts leaves every student's simulated answers to problem 1 as they were."""
    first = {"key": "1", "template": "drop-rebound"}
    roster = load_roster(ROSTER)
    rows = {}
    for name, parts in (("few", ["v_pile", "e", "loss_pct"]), ("more", None)):
        second = {"key": "2", "template": "pile-driver", **({"parts": parts} if parts else {})}
        assignment = load_assignment(_assignment(tmp_path / f"{name}.yaml", first, second))
        answers = sample_answers(assignment, generate(assignment, roster, bank), bank)
        rows[name] = [(a.student_id, a.label, a.text) for a in answers if a.label.startswith("1")]
    assert rows["few"] == rows["more"] and len(rows["few"]) > 40
