"""The answer key as grading reads it (`grader.grade.key`): a hand-edited key that would be graded wrongly,
or crash, is refused naming the entry (issue 22, items 4, 5 and 8).

Each row was a traceback (two parts sharing a label), wrong totals (a problem key given twice: grades.csv
counted both problems twice, 34 of a possible 28, while canvas.csv showed 25) or taken silently (``version:
true``, an empty label, ``max_tolerance: -1``)."""

from __future__ import annotations

import copy
import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from grader.base.resources import sample_dir
from grader.cli import main

Document = dict[str, Any]


@pytest.fixture(scope="module")
def key_document(sample_key: Path) -> Document:
    """The sample assignment's key (30 students, 5 problems), as JSON."""
    return json.loads(sample_key.read_text(encoding="utf-8"))  # type: ignore[no-any-return]


def _relabel(document: Document, problem: int, answer: int, label: str) -> None:
    """Give part ``answer`` of ``problem`` the ``label``, in the problem list and for every student."""
    part = document["problems"][problem]["answers"][answer]
    part["label"] = label
    for student in document["students"]:
        student["problems"][problem]["answers"][part["name"]]["label"] = label


def _rekey(document: Document, problem: int, key: str) -> None:
    document["problems"][problem]["key"] = key
    for student in document["students"]:
        student["problems"][problem]["key"] = key


def _student_problem_twice(document: Document) -> None:
    problems = document["students"][2]["problems"]
    problems.append(copy.deepcopy(problems[0]))


def _grading(**fields: Any) -> Callable[[Document], None]:
    return lambda document: document["assignment"]["grading"].update(fields)


KEYS_REFUSED = [  # (what is changed in the sample key, what the refusal says)
    # two parts sharing a label: KeyError: '1b' at grade/grading.py
    (lambda d: _relabel(d, 1, 0, "1b"), "problems[1].answers[0].label: the label '1b' appears twice (also "
                                        "problems[0].answers[1].label); expected each part's label once"),
    (lambda d: _relabel(d, 0, 1, "1a"), "problems[0].answers[1].label: the label '1a' appears twice (also "
                                        "problems[0].answers[0].label)"),
    # a problem key twice: both problems counted twice in grades.csv (34 of a possible 28)
    (lambda d: _rekey(d, 1, "1"), "problems[1].key: the problem key '1' appears twice (also problems[0].key); "
                                  "expected each problem once"),
    (lambda d: d["problems"].append(copy.deepcopy(d["problems"][0])), "problems[5].key: the problem key '1' "
                                                                      "appears twice"),
    (_student_problem_twice, "student 2026174: the problem key '1' appears twice; expected each problem once"),
    (lambda d: d["students"].append(copy.deepcopy(d["students"][0])),
     "students[30].id: the student id '2026100' appears twice (also students[0].id); expected each student once"),
    # taken silently
    (lambda d: d.update(version=True), "expected key schema version 1 or 2, got True (not the whole number 1 or 2)"),
    (lambda d: d.update(version=2.0), "expected key schema version 1 or 2, got 2.0 (not the whole number 1 or 2)"),
    (lambda d: _relabel(d, 0, 0, ""), "problems[0].answers[0].label: expected a label such as 1a, got ''"),
    (lambda d: _relabel(d, 2, 1, "  "), "problems[2].answers[1].label: expected a label such as 1a, got '  '"),
    (_grading(max_tolerance=-1), "assignment.grading.max_tolerance: expected a relative tolerance from 0.001 to "
                                 "0.5 (0.05 is ±5 %), got -1"),
    (_grading(intermediate_sig_figs=0), "assignment.grading.intermediate_sig_figs: expected a whole number of "
                                        "significant figures from 2 to 10, got 0"),
    (_grading(max_tolerence=0.1), "assignment.grading.max_tolerence: expected one of attempts, ecf_credit, "
                                  "integrity_threshold, intermediate_sig_figs, max_tolerance, mistake_credit, "
                                  "numeric_expressions (did you mean max_tolerance?), got an unknown field"),
    (_grading(partial=1), "assignment.grading.partial: expected one of attempts, ecf_credit, integrity_threshold, "
                          "intermediate_sig_figs, max_tolerance, mistake_credit, numeric_expressions, got an "
                          "unknown field"),
    (lambda d: d["assignment"].update(grading=[1]), "assignment.grading: expected a mapping {numeric_expressions: "
                                                    "true or false, ecf_credit: 0 to 1,"),
]
IDS = ["label-across-problems", "label-within-a-problem", "problem-key-renamed", "problem-appended",
       "problem-twice-for-a-student", "student-twice", "version-true", "version-2.0", "label-empty", "label-blank",
       "max-tolerance-negative", "sig-figs-0", "grading-field-misspelt", "grading-field-unknown",
       "grading-not-a-mapping"]


@pytest.mark.parametrize(("change", "message"), KEYS_REFUSED, ids=IDS)
def test_a_key_graded_wrongly_or_not_at_all_is_refused_naming_the_entry(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], key_document: Document,
        change: Callable[[Document], None], message: str) -> None:
    """Exit 2, one line naming the key file and the entry, nothing written."""
    document = copy.deepcopy(key_document)
    change(document)
    (tmp_path / "key.json").write_text(json.dumps(document), encoding="utf-8")
    (tmp_path / "a.csv").write_text("student_id,label,answer\n2026100,1a,0.5\n", encoding="utf-8")
    code = main(["grade", "--key", str(tmp_path / "key.json"), str(tmp_path / "a.csv"), "--out", str(tmp_path / "g")])
    captured = capsys.readouterr()
    assert (code, captured.out) == (2, "") and captured.err.count("\n") == 1, captured.err
    assert f"{tmp_path / 'key.json'}: " in captured.err and message in captured.err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.csv", "key.json"]


def test_the_key_written_by_generate_is_still_read(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                   key_document: Document) -> None:
    """The checks refuse nothing grader itself writes: version 2, its grading section, distinct labels."""
    (tmp_path / "key.json").write_text(json.dumps(key_document), encoding="utf-8")
    (tmp_path / "a.csv").write_text("student_id,label,answer\n2026100,1a,0.5\n", encoding="utf-8")
    assert main(["grade", "--key", str(tmp_path / "key.json"), str(tmp_path / "a.csv"), "--out",
                 str(tmp_path / "g")]) == 0, capsys.readouterr().err


@pytest.mark.parametrize(("grading", "message"), [
    ("{max_tolerence: 0.1}", "grading.max_tolerence: expected one of attempts, ecf_credit, integrity_threshold, "
                             "intermediate_sig_figs, max_tolerance, mistake_credit, numeric_expressions (did you "
                             "mean max_tolerance?)"),
    ("{ecf_credits: 1}", "grading.ecf_credits: expected one of attempts, ecf_credit, integrity_threshold, "
                         "intermediate_sig_figs, max_tolerance, mistake_credit, numeric_expressions (did you mean "
                         "ecf_credit?)"),
    ("{integrity_threshold: 2}", "grading.integrity_threshold: expected a chance from 0 to 1 (0.05: pairs whose "
                                 "matches would come about by accident at most 1 time in 20 are flagged), got 2"),
    ("{max_tolerance: -1}", "grading.max_tolerance: expected a relative tolerance from 0.001 to 0.5 (0.05 is ±5 %), "
                            "got -1"),
])
def test_an_assignments_grading_field_is_checked_as_the_keys_is(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], grading: str, message: str) -> None:
    """The same fields, ranges and did-you-mean on both sides: one function reads them."""
    (tmp_path / "a.yaml").write_text(f"title: HW\ncourse: C\nseed: s\ngrading: {grading}\n"
                                     "problems:\n  - template: drop-rebound\n", encoding="utf-8")
    code = main(["generate", str(tmp_path / "a.yaml"), "--roster", str(sample_dir() / "roster.csv"), "--out",
                 str(tmp_path / "hw"), "--no-pdf"])
    err = capsys.readouterr().err
    assert code == 2 and f"{tmp_path / 'a.yaml'}: {message}" in err, err
    assert not (tmp_path / "hw").exists()
