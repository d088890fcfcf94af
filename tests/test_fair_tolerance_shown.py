"""Issue 15, what users see: the sheets and the key say how to round, and a tolerance widened for that
rounding is shown with its reason wherever a tolerance is shown: the answer key (each student's answers
and the cover), key.csv, details.csv, the feedback's figure, ``grader check`` and the class report.

The widened tolerances are made here as the generator stores them (``rtol`` widened, ``reason``), on a
generation or on the demo's key.json, after every tolerance is set back to the one configured, so that
these tests hold whatever the generator widens."""

from __future__ import annotations

import csv
import dataclasses
import io
import json
import re
import shutil
from pathlib import Path

import pytest
from pypdf import PdfReader

from grader.assign.assignment import Assignment, load_assignment, load_roster
from grader.assign.keyfile import key_csv
from grader.assign.variants import Generation, StudentVariants, generate, tolerance
from grader.bank.template import Template
from grader.base.resources import sample_dir
from grader.cli import main
from grader.grade.class_report import class_report
from grader.grade.class_summary import summarize
from grader.grade.grading import grade
from grader.grade.key import Key, KeyPart, load_key
from grader.grade.run import run
from grader.grade.submissions import Answer, StudentRef, read_submissions
from grader.model.tolerance import Tolerance
from grader.render.documents import Documents, cover, key_source, student_source
from grader.render.typeset import compile_typst
from tests.demo_output import DemoRun

REASON = "rounding T and T′ to 4 figures moves loss_pct by up to {:.2g} %"
WIDENED_LABEL = "5d"  # oblique-spheres' loss_pct, which the textbook computes as (T − T′)/T


def reason(rtol: float) -> str:
    return REASON.format(100 * rtol / 2)


@pytest.fixture(scope="module")
def assignment(tmp_path_factory: pytest.TempPathFactory) -> Assignment:
    """The sample assignment, asking for five figures in intermediate steps."""
    text = (sample_dir() / "assignment.yaml").read_text(encoding="utf-8")
    path = tmp_path_factory.mktemp("assignment") / "assignment.yaml"
    path.write_text(text.replace("problems:\n", "grading: {intermediate_sig_figs: 5}\nproblems:\n", 1),
                    encoding="utf-8")
    return load_assignment(path)


def widened(entry: StudentVariants, rtol: float, text: str | None = None) -> StudentVariants:
    """The student's variants with problem 5's loss_pct widened to ``rtol`` (``text``: its reason)."""
    problems = list(entry.problems)
    answers = tuple(dataclasses.replace(part, tolerance=Tolerance(rtol=rtol, reason=text or reason(rtol)))
                    if part.label == WIDENED_LABEL else part for part in problems[4].answers)
    problems[4] = dataclasses.replace(problems[4], answers=answers)
    return dataclasses.replace(entry, problems=tuple(problems))


def configured(assignment: Assignment, bank: dict[str, Template]) -> dict[tuple[str, str], Tolerance]:
    """Each answer's tolerance as the assignment configures it, by (problem key, answer name)."""
    return {(spec.key, name): tolerance(spec, bank[spec.template], name)
            for spec in assignment.problems for name in bank[spec.template].answers}


def as_configured(entry: StudentVariants, rules: dict[tuple[str, str], Tolerance]) -> StudentVariants:
    """The student's variants with every answer's tolerance as configured (none widened)."""
    return dataclasses.replace(entry, problems=tuple(
        dataclasses.replace(variant, answers=tuple(dataclasses.replace(part, tolerance=rules[variant.key, part.name])
                                                   for part in variant.answers))
        for variant in entry.problems))


@pytest.fixture(scope="module")
def generation(assignment: Assignment, bank: dict[str, Template]) -> Generation:
    """Six students; the first, third and fifth with 5d widened to 2.7 %, 2.5 % and 2.3 %, no other widened."""
    made = generate(assignment, load_roster(sample_dir() / "roster.csv")[:6], bank)
    rules = configured(assignment, bank)
    students = tuple(widened(entry, 0.027 - 0.001 * index) if index % 2 == 0 else entry
                     for index, entry in enumerate(as_configured(entry, rules) for entry in made.students))
    return Generation(students, made.collisions)


def pdf_text(source: str) -> str:
    """A Typst source's text as a reader of its PDF gets it, with white space made single."""
    pdf = compile_typst(source)
    assert isinstance(pdf, bytes)
    return " ".join(" ".join(page.extract_text() for page in PdfReader(io.BytesIO(pdf)).pages).split())


def test_the_sheet_and_the_keys_cover_print_the_assignments_rounding_rule(
        assignment: Assignment, generation: Generation, bank: dict[str, Template]) -> None:
    documents = Documents(assignment, generation, bank)
    rule = "Keep five significant figures in intermediate steps; give answers to three."
    assert rule in pdf_text(student_source(documents, [1]))
    front = pdf_text(key_source(documents, cover=cover(documents, [])))
    assert rule in front and "at most ±5 %" in front
    default = dataclasses.replace(assignment, grading=dataclasses.replace(assignment.grading,
                                                                          intermediate_sig_figs=4))
    sheet = pdf_text(student_source(Documents(default, generation, bank), [1]))
    assert "Keep four significant figures in intermediate steps; give answers to three." in sheet


def test_the_key_shows_a_widened_tolerance_with_its_reason_and_the_cover_counts_them(
        assignment: Assignment, generation: Generation, bank: dict[str, Template]) -> None:
    documents = Documents(assignment, generation, bank)
    mine = pdf_text(key_source(documents, people=[0]))
    assert "±2.7 % (widened)" in mine
    # On the page the quantities are math and the answer is "it", not its name in the template (issue 32).
    assert "5d widened to ±2.7 %: rounding 𝑇 and 𝑇 ′ to 4 figures moves it by up to 1.4 %" in mine
    other = pdf_text(key_source(documents, people=[1]))
    assert "widened" not in other and "±1 %" in other
    front = pdf_text(key_source(documents, cover=cover(documents, [])))
    assert "5d: widened for 3 of 6 students, up to ±2.7 %" in front
    assert "±2.7 %" not in front.replace("up to ±2.7 %", "")  # the table gives the tolerance configured
    assert front.count("widened for") == 1


def test_key_csv_says_each_widened_tolerance_with_its_own_reason(generation: Generation) -> None:
    # Two tolerances of one figure with different reasons (equal as tolerances: the reason does not grade)
    students = list(generation.students)
    students[2] = widened(students[2], 0.027, "rounding the two speeds to 4 figures moves loss_pct by up to 1 %")
    rows = list(csv.DictReader(io.StringIO(key_csv(Generation(tuple(students), generation.collisions)))))
    shown = [row["tolerance"] for row in rows if row["label"] == WIDENED_LABEL]
    assert shown == [f"±2.7 %: {reason(0.027)}", "±1 %",
                     "±2.7 %: rounding the two speeds to 4 figures moves loss_pct by up to 1 %", "±1 %",
                     f"±2.3 %: {reason(0.023)}", "±1 %"]
    assert {row["tolerance"] for row in rows if row["label"] == "5a"} == {"±1 %"}


def demo_key(demo_run: DemoRun, bank: dict[str, Template], folder: Path, widen: bool) -> Path:
    """The demo's key (and submissions) in ``folder``, every tolerance as configured; with ``widen``, 5d
    widened for every other student, to 2 % + 0.05 % per student (the first 20 students), the later ones
    repeating those figures for another reason."""
    document = json.loads((demo_run.out / "key.json").read_text(encoding="utf-8"))
    rules = configured(load_assignment(demo_run.out / "assignment.yaml"), bank)
    for index, student in enumerate(document["students"]):
        for problem in student["problems"]:
            for name, answer in problem["answers"].items():
                answer["tolerance"] = rules[problem["key"], name].to_json()
        if widen and index % 2 == 0:
            rtol = round(0.02 + 0.0005 * (index % 20), 4)
            answer = next(p for p in student["problems"] if p["key"] == "5")["answers"]["loss_pct"]
            why = reason(rtol) if index < 20 else reason(rtol).replace("T and T′", "v₁′ and v₂′")
            answer["tolerance"] = {"mode": "rtol", "rtol": rtol, "atol": 0.0, "reason": why}
    (folder / "key.json").write_text(json.dumps(document, ensure_ascii=False), encoding="utf-8")
    shutil.copy(demo_run.out / "submissions.csv", folder / "submissions.csv")
    return folder / "key.json"


@pytest.fixture(scope="module")
def widened_key(demo_run: DemoRun, bank: dict[str, Template], tmp_path_factory: pytest.TempPathFactory) -> Path:
    return demo_key(demo_run, bank, tmp_path_factory.mktemp("widened"), widen=True)


def test_grading_a_widened_key_says_the_reason_in_details_and_the_figure_in_the_feedback(
        widened_key: Path) -> None:
    folder = widened_key.parent
    run(widened_key, [folder / "submissions.csv"], folder / "grades")
    with (folder / "grades" / "details.csv").open(encoding="utf-8", newline="") as file:
        rows = [row for row in csv.DictReader(file) if row["label"] == WIDENED_LABEL]
    key = json.loads(widened_key.read_text(encoding="utf-8"))
    tolerances = {s["id"]: next(p for p in s["problems"] if p["key"] == "5")["answers"]["loss_pct"]["tolerance"]
                  for s in key["students"]}
    assert len(rows) == 30
    for row in rows:
        tolerance = tolerances[row["student_id"]]
        figure = f"±{100 * tolerance['rtol']:.3g} %"
        expected = f"{figure}: {tolerance['reason']}" if "reason" in tolerance else "±1 %"
        assert row["tolerance"] == expected
        if row["verdict"] in ("correct", "incorrect"):  # a sentence that quotes the figure that decided
            assert row["feedback"].endswith(f"{figure} is accepted")
    assert sum("reason" in t for t in tolerances.values()) == 15
    assert any("v₁′ and v₂′" in row["tolerance"] for row in rows)


def test_rules_widened_alike_for_different_reasons_are_compared_together() -> None:
    from grader.grade.grading import _grade_column  # how a part's cells are grouped is not seen outside

    def part(why: str) -> KeyPart:
        return KeyPart("1", "loss_pct", "1a", 30.0, "%", 2.0, {"mode": "rtol", "rtol": 0.027, "atol": 0.0,
                                                               "reason": why}, None, {})

    cells = [(part(why), Answer("a.csv", line, "s", "1a", typed, ",", None))
             for line, (why, typed) in enumerate([("by T", "30.5"), ("by v", "29.5"), ("by T", "35")], start=2)]
    key = Key("key.json", 2, "HW", True, (), ())
    column = _grade_column([part for part, _ in cells], [answer for _, answer in cells], key)
    assert [indices for _, indices in column.wrong] == [[2]]  # one group: one comparison, one reconsideration
    assert [row.tolerance for row in column.rows] == ["±2.7 %: by T", "±2.7 %: by v", "±2.7 %: by T"]
    assert [row.verdict for row in column.rows] == ["correct", "correct", "incorrect"]


def test_the_class_report_counts_the_widened_per_part_and_gives_the_widest(widened_key: Path) -> None:
    key = load_key(widened_key)
    students = [StudentRef(s.id, s.email) for s in key.students]
    graded = grade(key, read_submissions([widened_key.parent / "submissions.csv"], students, key.labels))
    part = next(p for p in summarize(graded).parts if p.label == WIDENED_LABEL)
    assert part.widened is not None and (part.widened.variants, part.widened.of) == (15, 30)
    assert part.widened.widest.rtol == pytest.approx(0.029) and part.widened.widest.reason == reason(0.029)
    assert part.tolerances == (("±1 %", 15),)  # the configured tolerance, for the others
    assert all(p.widened is None for p in summarize(graded).parts if p.label != WIDENED_LABEL)
    page = class_report(graded)
    assert "<td>±1 % <small class=\"muted\">(15 of 30)</small></td><td>widened for 15 of 30 students, up to ±2.9 %" \
        in page
    assert f"(the widest: {reason(0.029)})" in page and "15 answers in all" in page
    assert page.count("widened for ") == 1


def test_a_report_with_no_tolerance_widened_says_so(demo_run: DemoRun, bank: dict[str, Template],
                                                   tmp_path: Path) -> None:
    key = demo_key(demo_run, bank, tmp_path, widen=False)
    run(key, [tmp_path / "submissions.csv"], tmp_path / "grades")
    page = (tmp_path / "grades" / "report.html").read_text(encoding="utf-8")
    assert "student's tolerance: none was." in page and "widened for " not in page


def test_check_gives_the_widened_figure_and_its_reason(widened_key: Path, capsys: pytest.CaptureFixture[str]) -> None:
    student = json.loads(widened_key.read_text(encoding="utf-8"))["students"][2]["id"]  # widened to 2.1 %
    arguments = ["check", "--key", str(widened_key), "--student", student, "--label", WIDENED_LABEL, "48"]
    assert main([*arguments, "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert (result["tolerance"], result["tolerance_reason"]) == ("±2.1 %", reason(0.021))
    assert result["feedback"].endswith("only ±2.1 % is accepted")
    assert main(arguments) == 0
    text = capsys.readouterr().out
    assert re.search(r"^tolerance  ±2\.1 % \(widened: rounding T and T′ to 4 figures moves loss_pct by up to "
                     r"1\.1 %\)$", text, re.MULTILINE)
    plain = json.loads(widened_key.read_text(encoding="utf-8"))["students"][1]["id"]
    assert main(["check", "--key", str(widened_key), "--student", plain, "--label", WIDENED_LABEL, "48",
                 "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert (result["tolerance"], result["tolerance_reason"]) == ("±1 %", "")


def test_check_batch_reads_a_tolerance_with_its_reason(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    lines = tmp_path / "lines.jsonl"
    lines.write_text(json.dumps({"submitted": "31.5", "expected": 31.0, "unit": "%",
                                 "tolerance": {"rtol": 0.027, "reason": reason(0.027)}}) + "\n", encoding="utf-8")
    assert main(["check", "--batch", str(lines)]) == 0
    result = json.loads(capsys.readouterr().out)
    assert (result["verdict"], result["tolerance"], result["tolerance_reason"]) == ("correct", "±2.7 %",
                                                                                     reason(0.027))
