"""`grader demo` end to end: it generates, plays a class (`submissions.csv` in the forms students type),
grades it into `grades/`, reruns byte for byte, and the grading excerpts of the README and docs/ are its real
output."""

from __future__ import annotations

import csv
import io
import json
import re
import shlex
import shutil
from dataclasses import replace
from datetime import datetime
from pathlib import Path
from typing import Any

import pytest

import grader.demo
from grader.assign.assignment import load_assignment, load_roster
from grader.assign.sample_answers import NUMERIC, SYMBOLIC, SampleAnswer, sample_answers, submissions_csv
from grader.assign.variants import Generation
from grader.bank.template import Template
from grader.base.files import MANIFEST
from grader.base.resources import sample_dir
from grader.base.spreadsheet import original_cell
from grader.cli import main
from grader.render.generate import Job
from tests.demo_output import DemoRun
from tests.documents import all_text

DOCS = all_text()  # README.md and docs/*.md
REGRADE = ("grader grade --key grader-demo/key.json grader-demo/submissions.csv --out grader-demo/grades --feedback "
           "--force")


@pytest.fixture(scope="module")
def answers(bank: dict[str, Template], sample_generation: Generation) -> list[SampleAnswer]:
    """The sample assignment's simulated answers, made in process."""
    return sample_answers(load_assignment(sample_dir() / "assignment.yaml"), sample_generation, bank)


def rows(path: Path) -> list[dict[str, str]]:
    with open(path, encoding="utf-8", newline="") as stream:
        return list(csv.DictReader(stream))


def tree(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def three_figures(text: str) -> bool:
    return float(f"{float(text):.3g}") == float(text)


def test_the_demo_exits_0_and_says_how_the_class_graded_and_how_to_grade_again(demo_run: DemoRun) -> None:
    assert demo_run.code == 0, demo_run.stderr
    lines = demo_run.stdout.splitlines()
    assert lines[0].startswith("30 students x 5 problems -> grader-demo (76 files, ")
    assert lines[1] == ("submissions.csv (simulated answers) graded: 30 students (29 submitted), 450 parts graded "
                        "(331 correct, 17 ecf, 24 mistake, 44 incorrect, 1 invalid, 33 missing); 1 row set aside "
                        "(superseded or not a student), 0 rows not graded (see problems.csv) -> grader-demo/grades")
    assert lines[2] == "Each student's graded sheet, with their worked solutions: grader-demo/grades/feedback"
    assert lines[-2:] == ["Grade the submissions again, or your own file, with", f"  {REGRADE}"]
    assert sorted(p.name for p in (demo_run.out / "grades").iterdir()) == [
        MANIFEST, "canvas.csv", "details.csv", "feedback", "grades.csv", "integrity.csv", "problems.csv",
        "report.html"]


def test_submissions_csv_is_the_simulated_class(demo_run: DemoRun, answers: list[SampleAnswer]) -> None:
    """What the demo wrote is what sample_answers makes in process, in the long format."""
    assert (demo_run.out / "submissions.csv").read_text(encoding="utf-8") == submissions_csv(answers)
    assert submissions_csv(answers).startswith("student_id,label,answer,timestamp\n")


# What each form looks like as typed (fullmatch).
FORMS = {
    "3 s.f.": r"-?\d+(\.\d+)?",
    "unit": r"-?\d+(\.\d+)? (m/s|ft/s)|-?\d+(\.\d+)?[°%]",
    "other unit": r"-?\d+(\.\d+)? (cm/s|km/h|m/s|mph|rad)",
    "decimal comma": r"-?\d+,\d+",
    "×10^": r"-?\d\.\d\d×10\^-?\d+",
    "unrounded": r"-?\d+\.\d{4,}",
    "blank": r"",
    "off by 6-30 %": r"-?\d+(\.\d+)?",
    "percentage as a fraction": r"0\.\d+",
    "radians for degrees": r"-?\d\.\d+",
    "no /s": r"-?\d+(\.\d+)? (m|ft)",
    "implicit products": r"[^* ]*v[^* ]*",
    "as in the key": r"[^ ]+\*[^ ]+ .*",
    "sign error": r"[^* ]*v[^* ]*",
    "words": r"about \d+(\.\d+)?",
    "late resubmission": r"-?\d+(\.\d+)?",
    "diagnosed mistake": r"-?\d+(\.\d+)?",
    "error carried forward": r"-?\d+(\.\d+)?",
}


@pytest.mark.parametrize("form", FORMS)
def test_every_form_is_in_the_file_and_typed_as_students_type_it(answers: list[SampleAnswer], form: str) -> None:
    typed = [a.text for a in answers if a.form == form]
    assert typed, f"no answer of the form {form}"
    assert all(re.fullmatch(FORMS[form], text) for text in typed), typed
    if form in ("3 s.f.", "late resubmission", "diagnosed mistake", "error carried forward"):
        assert all(three_figures(text) for text in typed)


def test_the_forms_tested_are_all_the_forms() -> None:
    drawn = {form for form, _ in (*NUMERIC, *SYMBOLIC)} - {"wrong"}
    assert drawn | {"off by 6-30 %", "percentage as a fraction", "radians for degrees", "no /s", "words",
                    "late resubmission", "diagnosed mistake", "error carried forward"} == set(FORMS)


def test_one_student_submits_nothing_and_one_resubmits_late(answers: list[SampleAnswer]) -> None:
    roster = [s.id for s in load_roster(sample_dir() / "roster.csv")]
    assert len({a.student_id for a in answers}) == len(roster) - 1
    late = answers[-1]
    assert late.form == "late resubmission"
    first = [a for a in answers[:-1] if (a.student_id, a.label) == (late.student_id, late.label)]
    assert len(first) == 1 and first[0].deserves == "incorrect"
    due = datetime.fromisoformat(load_assignment(sample_dir() / "assignment.yaml").due)
    assert datetime.fromisoformat(first[0].timestamp) < due < datetime.fromisoformat(late.timestamp)


def test_every_answer_gets_the_verdict_it_deserves(demo_run: DemoRun, answers: list[SampleAnswer]) -> None:
    """Right in any form: correct; right for an earlier wrong answer: ecf; a diagnosed mistake: mistake, with
    its id; another mistake: incorrect; blank: missing; words: invalid; not submitted: missing. The later of
    two answers is the one graded."""
    final = {(a.student_id, a.label): a for a in answers}
    details = rows(demo_run.out / "grades" / "details.csv")
    assert len(details) == 30 * 15
    for row in details:
        answer = final.get((row["student_id"], row["label"]))
        expected = ("missing", "") if answer is None else (answer.deserves, answer.diagnosis)
        assert (row["verdict"], row["diagnosis"]) == expected, (answer, row)
        assert original_cell(row["submitted"]) == ("" if answer is None else answer.text)  # "-5.59°" is guarded


def test_numbers_are_numbers_and_sentences_guarded_in_details_and_key_csv(demo_run: DemoRun) -> None:
    """Issue 28: details.csv wrote '-0.369 for a negative number (text to a spreadsheet), and its errors and
    key.csv's values printed binary noise (0.00019999999999975593, 0.7999999999999999)."""
    details = rows(demo_run.out / "grades" / "details.csv")
    negative = [row for row in details if row["expected"].startswith(("-", "'-"))]
    assert negative and all(re.fullmatch(r"-[0-9.e-]+", row["expected"]) for row in negative)
    assert all(re.fullmatch(r"-[0-9.e-]+", row["parsed"]) for row in details if row["parsed"].startswith(("-", "'-")))
    sentences = [row["feedback"] for row in details if row["feedback"][:2] in ("-0", "-1", "'-")]
    assert sentences and all(text.startswith("'-") for text in sentences)  # "-5.59° is …" is no number
    for row in details:
        for column in ("abs_error", "rel_error"):
            assert not row[column] or float(row[column]) == float(f"{float(row[column]):.6g}"), row
    values = [row["value"] for row in rows(demo_run.out / "key.csv") if re.fullmatch(r"-?[0-9.]+", row["value"])]
    assert values and all(len(value.replace("-", "").replace(".", "").lstrip("0")) <= 12 for value in values)


def test_the_class_shows_errors_carried_forward_and_each_kind_of_diagnosed_mistake(demo_run: DemoRun) -> None:
    """The report has something to show: errors carried forward from several parts, and mistakes of the
    impact, its energy, flight and angles (the sample's problems ask no flight answer a mistake can change
    except through the pile driver's)."""
    details = rows(demo_run.out / "grades" / "details.csv")
    carried = {row["diagnosis"] for row in details if row["verdict"] == "ecf"}
    mistakes = {row["diagnosis"] for row in details if row["verdict"] == "mistake"}
    assert len(carried) >= 3 and all(re.fullmatch(r"ecf:\d[a-d]", item) for item in carried)
    assert {item.split(".")[0] for item in mistakes} == {"impact", "energy", "flight", "angle"}
    assert all(row["credit"] == "0" for row in details if row["verdict"] == "mistake")
    assert all(row["credit"] == "1" for row in details if row["verdict"] == "ecf")


def test_the_absent_student_scores_0_and_the_superseded_row_is_the_only_problem(
        demo_run: DemoRun, answers: list[SampleAnswer]) -> None:
    grades = {row["student_id"]: row for row in rows(demo_run.out / "grades" / "grades.csv")}
    absent = set(grades) - {a.student_id for a in answers}
    assert len(absent) == 1
    student = grades[absent.pop()]
    assert student["total"] == "0"
    assert f"{student['student_id']}, who submitted nothing, has 0 of {student['possible']} points" in DOCS
    late = answers[-1]
    line = len(answers) + 1  # the header is line 1
    superseded = next(i for i, a in enumerate(answers) if (a.student_id, a.label) == (late.student_id, late.label))
    assert rows(demo_run.out / "grades" / "problems.csv") == [{
        "file": "grader-demo/submissions.csv", "line": str(superseded + 2), "student_id": late.student_id,
        "label": late.label, "reason": f"superseded by grader-demo/submissions.csv line {line} (submitted later)"}]


def test_the_grades_are_in_the_demo_folder_manifest_and_have_their_own(demo_run: DemoRun) -> None:
    """One transaction writes everything, and grader grade --force may replace grades/ later."""
    outer = json.loads((demo_run.out / MANIFEST).read_text(encoding="utf-8"))
    inner = json.loads((demo_run.out / "grades" / MANIFEST).read_text(encoding="utf-8"))
    assert outer["command"] == "grader demo" and inner["command"] == "grader grade"
    assert "grades" in outer["folders"] and f"grades/{MANIFEST}" in outer["files"]
    assert {f"grades/{name}" for name in inner["files"]} <= set(outer["files"])
    assert "submissions.csv" in outer["files"]


@pytest.mark.slow  # 12 s: three whole demos; tests/test_files.py and test_hardening.py keep --force's rules
def test_demo_force_then_the_documented_regrade_then_demo_force_again_change_nothing(
        demo_run: DemoRun, tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    """A second `grader demo --force` rewrites the folder byte for byte; the docs' `grader grade ... --force`
    regrades it to the same files and prints what the docs show; `grader demo --force` still works after."""
    shutil.copytree(demo_run.out, tmp_path / "grader-demo")
    monkeypatch.chdir(tmp_path)
    before = tree(demo_run.out)
    assert main(["demo", "--out", "grader-demo", "--force"]) == 0
    assert tree(tmp_path / "grader-demo") == before
    capsys.readouterr()
    command = _documented_regrade()
    assert command == REGRADE
    assert main(shlex.split(command)[1:]) == 0  # a superseded row is set aside by rule: nothing for anyone to do
    assert capsys.readouterr().err.splitlines() == _documented_block_after(command)
    assert tree(tmp_path / "grader-demo") == before
    assert main(["demo", "--out", "grader-demo", "--force"]) == 0
    assert tree(tmp_path / "grader-demo") == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["grader-demo"]


def test_a_failure_while_grading_leaves_nothing_behind(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Generating, simulating and grading are one output folder: a failure in the last step removes all."""
    write_outputs = grader.demo.write_outputs

    def without_pdfs(job: Job, *args: Any) -> int:
        return write_outputs(replace(job, pdf=False), *args)

    def broken(*args: object, **keywords: object) -> None:
        raise RuntimeError("disk full")

    monkeypatch.setattr(grader.demo, "write_outputs", without_pdfs)
    monkeypatch.setattr(grader.demo, "grade_into", broken)
    with pytest.raises(RuntimeError, match="disk full"):
        main(["demo", "--out", str(tmp_path / "out")])
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("header", ["student_id,label,submitted,verdict,expected,feedback,diagnosis",
                                    "file,line,student_id,label,reason"])
def test_the_documented_excerpts_are_rows_of_the_demo_output(demo_run: DemoRun, header: str) -> None:
    """Each excerpt row is a real row of details.csv (or problems.csv), in the excerpt's columns."""
    block = next(b for b in re.findall(r"```text\n(.*?)```", DOCS, flags=re.S) if b.startswith(header + "\n"))
    excerpt = block.splitlines()
    real = rows(demo_run.out / "grades" / ("details.csv" if "verdict" in header else "problems.csv"))
    columns = header.split(",")
    stream = io.StringIO()
    csv.writer(stream, lineterminator="\n").writerows([row[c] for c in columns] for row in real)
    assert len(excerpt) > 1 and set(excerpt[1:]) <= set(stream.getvalue().splitlines())


@pytest.mark.parametrize("typed", ["2.06 m/s", "7.77°", "778 cm/s", "25.6 mph", "9.18 km/h", "63,5", "5.57×10^-1",
                                   "2.22 m", "about 48", "v(1-0.07p)/(p+1)"])
def test_the_documented_examples_of_forms_are_in_the_demo_file(answers: list[SampleAnswer], typed: str) -> None:
    assert f"`{typed}`" in DOCS or f'`"{typed}"`' in DOCS
    assert typed in {a.text for a in answers}


def _documented_regrade() -> str:
    found = re.search(r"```sh\n(grader grade --key grader-demo/[^\n]*)\n```", DOCS)
    assert found is not None, "the docs show how to grade the demo's submissions again"
    return found.group(1)


def _documented_block_after(command: str) -> list[str]:
    """The lines of the first ```text block after the command's."""
    after = DOCS[DOCS.index(command):]
    found = re.search(r"```text\n(.*?)```", after, flags=re.S)
    assert found is not None
    return found.group(1).splitlines()
