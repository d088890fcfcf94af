"""`grader grade` end to end: the key submitted as answers scores full marks, every input row is
accounted for, reruns are byte-identical, and unusable input leaves nothing behind."""

from __future__ import annotations

import csv
import io
import json
from dataclasses import replace
from pathlib import Path
from typing import Any

import pytest

from grader.base.errors import GraderError
from grader.base.resources import sample_dir
from grader.cli import main
from grader.grade.diagnosis import physics_for
from grader.grade.grading import grade, grade_part
from grader.grade.key import load_key
from grader.grade.submissions import StudentRef, read_submissions


def run(capsys: pytest.CaptureFixture[str], *argv: object) -> tuple[int, str, str]:
    code = main([str(a) for a in argv])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


@pytest.fixture(scope="module")
def key_path(sample_key: Path) -> Path:
    """The sample assignment's key (30 students, 5 problems), as the demo and ``grader generate`` write it."""
    return sample_key


def key_document(path: Path) -> dict[str, Any]:
    return json.loads(path.read_text(encoding="utf-8"))  # type: ignore[no-any-return]


def key_answers(path: Path, rounding: str | None = None) -> list[tuple[str, str, str]]:
    """(student id, label, answer text) for every part: the key's own value, or blank where undefined."""
    rows = []
    for student in key_document(path)["students"]:
        for problem in student["problems"]:
            for answer in problem["answers"].values():
                value = answer["value"]
                text = "" if value is None else value if isinstance(value, str) else (
                    format(value, rounding) if rounding else repr(value))
                rows.append((student["id"], answer["label"], text))
    return rows


def long_csv(rows: list[tuple[str, str, str]]) -> str:
    stream = io.StringIO()
    writer = csv.writer(stream, lineterminator="\n")
    writer.writerow(["student_id", "label", "answer"])
    writer.writerows(rows)
    return stream.getvalue()


def read(path: Path) -> list[dict[str, str]]:
    with open(path, encoding="utf-8", newline="") as stream:
        return list(csv.DictReader(stream))


@pytest.mark.parametrize("rounding", [None, ".3g"])
def test_the_key_submitted_as_answers_scores_full_marks(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                        key_path: Path, rounding: str | None) -> None:
    """Every template's answers, exact and rounded to 3 significant figures (within the 1 % default)."""
    submissions = tmp_path / "answers.csv"
    submissions.write_text(long_csv(key_answers(key_path, rounding)), encoding="utf-8")
    code, out, err = run(capsys, "grade", "--key", key_path, submissions, "--out", tmp_path / "grades", "--json")
    assert code == 0, err
    summary = json.loads(out)
    assert summary["rows_not_graded"] == 0 and summary["verdicts"]["correct"] == summary["parts"]
    grades = read(tmp_path / "grades" / "grades.csv")
    assert len(grades) == 30 and all(row["total"] == row["possible"] for row in grades)
    details = read(tmp_path / "grades" / "details.csv")
    assert {row["verdict"] for row in details} == {"correct"}
    assert all(row["feedback"] for row in details)


def test_wide_submissions_with_form_style_headers_grade_alike(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                               key_path: Path) -> None:
    rows = key_answers(key_path)
    labels = list(dict.fromkeys(label for _, label, _ in rows))
    by_student: dict[str, dict[str, str]] = {}
    for student, label, text in rows:
        by_student.setdefault(student, {})[label] = text
    stream = io.StringIO()
    writer = csv.writer(stream, lineterminator="\n")
    writer.writerow(["Timestamp", "Student ID", "Name", *(f"{label} (your answer)" for label in labels)])
    for student, answers in by_student.items():
        writer.writerow(["2026-12-04 10:00:00", student, "someone", *(answers[label] for label in labels)])
    (tmp_path / "wide.csv").write_text(stream.getvalue(), encoding="utf-8")
    code, out, err = run(capsys, "grade", "--key", key_path, tmp_path / "wide.csv", "--out", tmp_path / "g", "--json")
    assert code == 0, err
    assert json.loads(out)["verdicts"]["correct"] == len(rows)
    assert "Name" in err  # the ignored column is reported once


def test_every_row_is_accounted_for_and_nobody_is_lost(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                       key_path: Path) -> None:
    """A student who submitted nothing is in grades.csv with 0; an unknown student's row is in
    problems.csv; a wrong answer is incorrect with feedback; exit 3 because a row was not graded."""
    rows = key_answers(key_path)
    first = rows[0][0]
    kept = [r for r in rows if r[0] != first]  # the first student submits nothing
    student, label, text = kept[0]
    kept[0] = (student, label, str(float(text) * 1.5))
    kept.append(("nobody", "1a", "0.5"))
    (tmp_path / "a.csv").write_text(long_csv(kept), encoding="utf-8")
    code, _, err = run(capsys, "grade", "--key", key_path, tmp_path / "a.csv", "--out", tmp_path / "g")
    assert code == 3, err
    grades = {row["student_id"]: row for row in read(tmp_path / "g" / "grades.csv")}
    assert len(grades) == 30 and grades[first]["total"] == "0"
    details = {(row["student_id"], row["label"]): row for row in read(tmp_path / "g" / "details.csv")}
    assert details[(first, "1a")]["verdict"] == "missing"
    wrong = details[(student, label)]
    assert wrong["verdict"] == "incorrect" and "50 % above" in wrong["feedback"], wrong
    problems = read(tmp_path / "g" / "problems.csv")
    assert [(p["student_id"], p["line"]) for p in problems] == [("nobody", str(len(kept) + 1))]


def test_rows_set_aside_by_rule_are_listed_but_end_the_run_with_0(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                                   key_path: Path) -> None:
    """A resubmission, a header row repeated where two files were pasted together and Canvas' points-possible
    row are listed in problems.csv and counted apart; only a row someone should look at (here none) makes the
    exit code 3."""
    rows = key_answers(key_path)
    student, label, text = rows[0]
    half = len(rows) // 2  # two exports pasted into one: the second's header row is in the middle
    (tmp_path / "a.csv").write_text(long_csv([(student, label, "999"), *rows[:half], ("Student_ID ", "label", "answer"),
                                              *rows[half:], ("Points Possible", "", "")]), encoding="utf-8")
    code, out, err = run(capsys, "grade", "--key", key_path, tmp_path / "a.csv", "--out", tmp_path / "g", "--json")
    assert code == 0, err
    summary = json.loads(out)
    assert (summary["rows_not_graded"], summary["rows_set_aside"]) == (0, 3)
    assert "3 rows set aside (superseded or not a student), 0 rows not graded" in err
    problems = read(tmp_path / "g" / "problems.csv")
    resubmitted = rows.index((student, label, text)) + 3
    assert [(p["line"], p["reason"]) for p in problems][1] == (
        str(half + 3), "not a student row (the header repeated: were two files pasted into one?)")
    assert [(p["line"], p["reason"].split(" (")[0]) for p in problems] == [
        ("2", f"superseded by {tmp_path / 'a.csv'} line {resubmitted + (resubmitted > half + 2)}"),
        (str(half + 3), "not a student row"), (str(len(rows) + 4), "not a student row")]
    assert {row["verdict"] for row in read(tmp_path / "g" / "details.csv")} == {"correct"}


def test_reruns_are_byte_identical(tmp_path: Path, capsys: pytest.CaptureFixture[str], key_path: Path) -> None:
    (tmp_path / "a.csv").write_text(long_csv(key_answers(key_path, ".2g")), encoding="utf-8")
    for out in ("g1", "g2"):
        run(capsys, "grade", "--key", key_path, tmp_path / "a.csv", "--out", tmp_path / out)
    for name in ("grades.csv", "details.csv", "problems.csv", "canvas.csv", "report.html"):
        assert (tmp_path / "g1" / name).read_bytes() == (tmp_path / "g2" / name).read_bytes(), name


@pytest.mark.parametrize(("key_text", "message"), [
    ("{}", "expected a grader answer key"),
    ('{"schema": "grader-key", "version": 9}', "expected key schema version 1 or 2, got 9"),
    ("not json", "got invalid JSON"),
    ('{"schema": "grader-key", "version": 2, "students": [{"id": NaN}]}', "got invalid JSON"),
])
def test_an_unusable_key_exits_2_and_writes_nothing(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                    key_text: str, message: str) -> None:
    (tmp_path / "key.json").write_text(key_text, encoding="utf-8")
    (tmp_path / "a.csv").write_text("student_id,label,answer\ns1,1a,1\n", encoding="utf-8")
    code, out, err = run(capsys, "grade", "--key", tmp_path / "key.json", tmp_path / "a.csv", "--out", tmp_path / "g")
    assert (code, out) == (2, "") and message in err
    assert not (tmp_path / "g").exists()


def test_a_version_1_key_still_grades(tmp_path: Path, capsys: pytest.CaptureFixture[str], key_path: Path) -> None:
    """Keys written before version 2: no grading section, no symbol ranges, tolerances without a mode."""
    document = key_document(key_path)
    document["version"] = 1
    document["assignment"].pop("grading")
    for problem in document["problems"]:
        for answer in problem["answers"]:
            answer.pop("symbols", None)
    for student in document["students"]:
        for problem in student["problems"]:
            for answer in problem["answers"].values():
                answer["tolerance"].pop("mode")
    (tmp_path / "key.json").write_text(json.dumps(document), encoding="utf-8")
    (tmp_path / "a.csv").write_text(long_csv(key_answers(key_path)), encoding="utf-8")
    code, out, err = run(capsys, "grade", "--key", tmp_path / "key.json", tmp_path / "a.csv", "--out",
                         tmp_path / "g", "--json")
    assert code == 0, err
    summary = json.loads(out)
    assert summary["verdicts"]["correct"] == summary["parts"]


def test_text_cells_in_the_reports_cannot_run_as_formulas(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                          key_path: Path) -> None:
    rows = key_answers(key_path)
    student, label, _ = rows[0]
    rows[0] = (student, label, '=HYPERLINK("http://x")')
    (tmp_path / "a.csv").write_text(long_csv(rows), encoding="utf-8")
    run(capsys, "grade", "--key", key_path, tmp_path / "a.csv", "--out", tmp_path / "g")
    details = {(row["student_id"], row["label"]): row for row in read(tmp_path / "g" / "details.csv")}
    row = details[(student, label)]
    assert row["submitted"].startswith("'=") and row["verdict"] == "invalid"


@pytest.mark.parametrize("starter", ["\uff1d", "\uff0b", "\uff0d", "\uff20"], ids=["equals", "plus", "minus", "at"])
def test_a_full_width_formula_starter_is_guarded_in_details_csv(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                                key_path: Path, starter: str) -> None:
    """A cell starting with a full-width ``＝`` (U+FF1D), ``＋``, ``－`` or ``＠`` reached details.csv unguarded
    (issue 22): a spreadsheet with an East Asian locale may read it as a formula."""
    rows = key_answers(key_path)
    student, label, _ = rows[0]
    rows[0] = (student, label, f'{starter}HYPERLINK("http://x")')
    (tmp_path / "a.csv").write_text(long_csv(rows), encoding="utf-8")
    run(capsys, "grade", "--key", key_path, tmp_path / "a.csv", "--out", tmp_path / "g")
    row = next(row for row in read(tmp_path / "g" / "details.csv") if (row["student_id"], row["label"]) == (student,
                                                                                                          label))
    assert row["submitted"] == f"'{starter}HYPERLINK(\"http://x\")"


def test_control_characters_a_student_typed_are_shown_as_escapes_in_the_reports(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], key_path: Path) -> None:
    """An escape sequence or a right-to-left override typed into an answer (or a stray label) reaches
    details.csv and problems.csv as visible text, never as the raw character a terminal acts on."""
    rows = key_answers(key_path)
    (student, label, _), (other, other_label, _) = rows[0], rows[1]
    rows[0] = (student, label, "6.26\x1b[2J m/s")
    rows[1] = (other, other_label, "\u202e5.1")
    rows.append((student, "9\x1bz", "1"))
    (tmp_path / "a.csv").write_text(long_csv(rows), encoding="utf-8")
    run(capsys, "grade", "--key", key_path, tmp_path / "a.csv", "--out", tmp_path / "g")
    for name in ("details.csv", "problems.csv"):
        text = (tmp_path / "g" / name).read_text(encoding="utf-8")
        assert "\x1b" not in text and "\u202e" not in text, name
    details = {(row["student_id"], row["label"]): row for row in read(tmp_path / "g" / "details.csv")}
    assert details[(student, label)]["submitted"] == "6.26\\x1b[2J m/s"
    assert details[(other, other_label)]["submitted"] == "\\u202e5.1"
    assert "9\\x1bz" in (tmp_path / "g" / "problems.csv").read_text(encoding="utf-8")


def test_a_key_whose_student_lacks_a_part_is_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                     key_path: Path) -> None:
    """A hand-edited key (a part deleted for one student) is refused, not a KeyError halfway."""
    document = key_document(key_path)
    document["students"][0]["problems"][0]["answers"].popitem()
    (tmp_path / "key.json").write_text(json.dumps(document), encoding="utf-8")
    (tmp_path / "a.csv").write_text("student_id,label,answer\n", encoding="utf-8")
    code, _, err = run(capsys, "grade", "--key", tmp_path / "key.json", tmp_path / "a.csv", "--out", tmp_path / "g")
    assert code == 2 and "a missing or malformed entry" in err and not (tmp_path / "g").exists()


def _first_answer(document: dict[str, Any], problem: int = 0) -> dict[str, Any]:
    return next(iter(document["students"][0]["problems"][problem]["answers"].values()))  # type: ignore[no-any-return]


HOSTILE_KEYS = [  # (what is changed in the key, what the refusal says): each was a traceback, a refusal naming
    # no file mid-run, or was taken as it came (points of -5, an id null read as the student "None")
    (lambda d: _first_answer(d).update(points=1e308), "answer e: points: expected a number from 0 to 1,000,000"),
    (lambda d: _first_answer(d).update(points=-5), "answer e: points: expected a number from 0 to 1,000,000"),
    (lambda d: _first_answer(d).update(value=10 ** 400), "answer e: a value beyond float64"),
    (lambda d: _first_answer(d).update(tolerance={"mode": "sigfigs", "digits": 99}),
     "answer e: tolerance.digits: expected a whole number from 1 to 17, got 99"),
    (lambda d: _first_answer(d).update(unit="kg^99"), "answer e: unit: the power 99"),
    (lambda d: _first_answer(d, 1).update(value="__import__('os').system('id')"), "is not an allowed function"),
    (lambda d: _first_answer(d, 1).update(value="v**9**9**9"), "the power 9**9 is larger than 64"),
    (lambda d: _first_answer(d, 1).update(value="w*v"), "uses w, not among its symbols (p, v)"),
    (lambda d: d["problems"][1]["answers"][0].update(symbols={"p": [0.1, 10], "v": [-1.7e308, 1.7e308]}),
     "answer 2a: symbols.v: expected [LOW, HIGH] with LOW < HIGH, finite"),
    (lambda d: d["students"][0].update(id=None), "a student's id: expected text"),
    (lambda d: d["students"][1].update(id=d["students"][0]["id"]), "the student id '2026100' appears twice"),
    (lambda d: d["students"][0].update(name="x" * 10**6), "name: expected text of at most 1000 characters"),
    (lambda d: d["assignment"].update(grading={"numeric_expressions": "no"}),
     "numeric_expressions: expected true or false, got 'no'"),
    (lambda d: _first_answer(d).update(value=None, undefined={"a": 1}), "undefined: expected the reason as text"),
    (lambda d: d["problems"][1]["answers"][0].update(symbols={"p": [], "v": [1, 10]}),
     "answer 2a: symbols.p: expected [LOW, HIGH]"),  # an IndexError's traceback
    (lambda d: d.update(students=[]), "expected at least one student, got none"),  # 0 students, all rows refused
    (lambda d: d["students"][0].update(section="\ud800"),  # a UnicodeEncodeError writing grades.csv
     "students[0].section: expected text, got half of a character ('\\ud800')"),
    (lambda d: d["assignment"].update(course="Dynamics \udc00"), "assignment.course: expected text, got half of a "
                                                                 "character ('\\udc00')"),  # a field _text never saw
    (lambda d: d["problems"][0].update(key="\ud800"), "problems[0].key: expected text, got half of a character"),
]


@pytest.mark.parametrize(("change", "message"), HOSTILE_KEYS, ids=[
    "points-1e308", "points-negative", "value-10**400", "digits-99", "unit-kg^99", "expression-import",
    "expression-power", "expression-unknown-name", "range-overflows", "id-null", "id-twice", "name-1e6-chars",
    "numeric-expressions-text", "undefined-not-text", "range-empty", "no-students", "section-lone-surrogate",
    "course-lone-surrogate", "problem-key-lone-surrogate"])
def test_a_hand_edited_key_that_cannot_be_graded_is_refused_naming_the_entry(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], key_path: Path, change: Any, message: str) -> None:
    document = key_document(key_path)
    change(document)
    (tmp_path / "key.json").write_text(json.dumps(document), encoding="utf-8")
    (tmp_path / "a.csv").write_text(long_csv(key_answers(key_path)), encoding="utf-8")
    code, out, err = run(capsys, "grade", "--key", tmp_path / "key.json", tmp_path / "a.csv", "--out", tmp_path / "g")
    assert (code, out) == (2, "") and err.count("\n") == 1, err
    assert f"{tmp_path / 'key.json'}: " in err and message in err
    assert not (tmp_path / "g").exists()


def test_the_assignments_tolerance_mode_and_grading_section_reach_the_verdicts(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """`tolerance: {e: {decimals: 2}}` and `grading: {numeric_expressions: false, ecf_credit: 0.5,
    mistake_credit: 0.25}` go through the key to grading."""
    (tmp_path / "a.yaml").write_text("title: HW\ncourse: C\nseed: s\ngrading: {numeric_expressions: false, "
                                     "ecf_credit: 0.5, mistake_credit: 0.25}\n"
                                     "problems:\n  - template: drop-rebound\n    tolerance: {e: {decimals: 2}}\n",
                                     encoding="utf-8")
    assert main(["generate", str(tmp_path / "a.yaml"), "--roster", str(sample_dir() / "roster.csv"), "--out",
                 str(tmp_path / "hw"), "--no-pdf"]) == 0
    key = tmp_path / "hw" / "key.json"
    student = key_document(key)["students"][0]
    e = student["problems"][0]["answers"]["e"]
    assert e["tolerance"] == {"mode": "decimals", "digits": 2}
    loss = student["problems"][0]["answers"]["loss_pct"]["value"]
    other = key_document(key)["students"][1]
    params = other["problems"][0]["params"]
    ratio = params["h_rebound"] / params["h_drop"]  # e = h'/h: v = 2gh for sqrt(2gh); 1b carried forward from it
    rows = [(student["id"], "1a", f"{e['value']:.2f}"), (student["id"], "1b", f"sqrt({loss ** 2})"),
            (other["id"], "1a", f"{ratio:.2f}"), (other["id"], "1b", f"{100 * (1 - ratio**2):.3g}")]
    (tmp_path / "s.csv").write_text(long_csv(rows), encoding="utf-8")
    capsys.readouterr()
    run(capsys, "grade", "--key", key, tmp_path / "s.csv", "--out", tmp_path / "g")
    details = {row["label"]: row for row in read(tmp_path / "g" / "details.csv")
               if row["student_id"] == student["id"]}
    assert details["1a"]["verdict"] == "correct" and details["1a"]["tolerance"] == "2 decimal places"
    assert details["1b"]["verdict"] == "invalid"  # arithmetic is refused when numeric_expressions is false
    theirs = {row["label"]: row for row in read(tmp_path / "g" / "details.csv") if row["student_id"] == other["id"]}
    assert [(theirs[label]["verdict"], theirs[label]["credit"]) for label in ("1a", "1b")] == [
        ("mistake", "0.25"), ("ecf", "0.5")]
    assert load_key(key).ecf_credit == 0.5 and load_key(key).mistake_credit == 0.25


@pytest.mark.parametrize("grading", ["{ecf_credit: 2}", "{mistake_credit: -0.1}", "{ecf_credit: yes}",
                                     "{partial: 1}", "{intermediate_sig_figs: 3.5}", "{intermediate_sig_figs: 1}",
                                     "{intermediate_sig_figs: true}", "{max_tolerance: 0}", "{max_tolerance: 5}"])
def test_a_credit_that_is_no_fraction_of_the_points_is_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                               grading: str) -> None:
    (tmp_path / "a.yaml").write_text(f"title: HW\ncourse: C\nseed: s\ngrading: {grading}\n"
                                     "problems:\n  - template: drop-rebound\n", encoding="utf-8")
    code, _, err = run(capsys, "generate", tmp_path / "a.yaml", "--roster", sample_dir() / "roster.csv", "--out",
                       tmp_path / "hw", "--no-pdf")
    assert code == 2 and "grading" in err and not (tmp_path / "hw").exists()


def test_one_answer_graded_alone_is_graded_as_in_its_class(tmp_path: Path, key_path: Path) -> None:
    """`grade_part` (one answer, as `grader check` grades it) gives the verdict that grading the whole
    class by columns gives: right, wrong, with units, blank, unreadable, symbolic, undefined."""
    rows = key_answers(key_path, ".3g")
    forms = ["{}", "{} m/s", "{} ft", "", "six", "=1+1", "-{}", "{}e1"]
    rows = [(student, label, forms[index % len(forms)].format(text) if index % 3 else text)
            for index, (student, label, text) in enumerate(rows) if index % 11]
    (tmp_path / "a.csv").write_text(long_csv(rows), encoding="utf-8")
    key = load_key(key_path)
    submissions = read_submissions([tmp_path / "a.csv"], [StudentRef(s.id, s.email) for s in key.students],
                                   key.labels)
    physics = physics_for(key)
    graded = grade(key, submissions, physics)
    answers = {(a.student_id, a.label): a for a in submissions.answers}
    parts = {(s.id, label): part for s in key.students for label, part in s.parts.items()}
    verdicts = graded.verdicts
    assert len(verdicts) == len(parts) and {v.verdict for v in verdicts} == {"correct", "mistake", "incorrect",
                                                                             "invalid", "missing"}
    for verdict in verdicts:  # "-{}" is a velocity with its sign turned, an energy lost as T' - T
        where = (verdict.student_id, verdict.label)
        assert grade_part(parts[where], verdict.student_id, answers.get(where), key, physics) == verdict


def test_a_key_laid_out_otherwise_reads_the_same(tmp_path: Path, key_path: Path) -> None:
    """Students are read as they are decoded from a key laid out as grader writes it; any other valid
    JSON (indented, students first, a name given twice: the last one counts) reads the same."""
    document = key_document(key_path)
    reordered = {"students": document["students"], **{k: v for k, v in document.items() if k != "students"}}
    (tmp_path / "indented.json").write_text(json.dumps(reordered, indent=2), encoding="utf-8")
    text = key_path.read_text(encoding="utf-8")
    (tmp_path / "twice.json").write_text('{"students": [], ' + text.lstrip()[1:], encoding="utf-8")
    usual = replace(load_key(key_path), where="")
    assert replace(load_key(tmp_path / "indented.json"), where="") == usual
    assert replace(load_key(tmp_path / "twice.json"), where="") == usual


def test_a_cut_key_is_refused_with_what_json_says(tmp_path: Path, key_path: Path) -> None:
    """A key cut off among its students: the same reason as json.loads gives, where it gives it."""
    text = key_path.read_text(encoding="utf-8")
    cut = text[:len(text) * 2 // 3]
    (tmp_path / "key.json").write_text(cut, encoding="utf-8")
    with pytest.raises(json.JSONDecodeError) as expected:
        json.loads(cut)
    with pytest.raises(GraderError) as caught:
        load_key(tmp_path / "key.json")
    assert f"got invalid JSON ({expected.value})" in str(caught.value)


def test_the_grading_sections_rounding_settings_are_read_with_their_defaults(tmp_path: Path) -> None:
    from grader.assign.assignment import load_assignment
    path = tmp_path / "a.yaml"
    path.write_text("title: HW\ncourse: C\nseed: s\nproblems:\n  - template: drop-rebound\n", encoding="utf-8")
    grading = load_assignment(path).grading
    assert (grading.intermediate_sig_figs, grading.max_tolerance) == (4, 0.05)
    path.write_text("title: HW\ncourse: C\nseed: s\ngrading: {intermediate_sig_figs: 5, max_tolerance: 0.1}\n"
                    "problems:\n  - template: drop-rebound\n", encoding="utf-8")
    grading = load_assignment(path).grading
    assert (grading.intermediate_sig_figs, grading.max_tolerance) == (5, 0.1)


@pytest.mark.parametrize("path", [("problems", 0), ("students", 0), ("problems", 0, "answers", 0)])
def test_a_key_with_null_in_place_of_an_object_is_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                          key_path: Path, path: tuple[Any, ...]) -> None:
    """A problem, a student or an answer written as ``null`` is refused naming it (it was a TypeError)."""
    document = key_document(key_path)
    holder = document
    for step in path[:-1]:
        holder = holder[step]
    holder[path[-1]] = None
    (tmp_path / "key.json").write_text(json.dumps(document), encoding="utf-8")
    (tmp_path / "a.csv").write_text("student_id,label,answer\n", encoding="utf-8")
    code, _, err = run(capsys, "grade", "--key", tmp_path / "key.json", tmp_path / "a.csv", "--out", tmp_path / "g")
    assert code == 2 and "expected an object, got None" in err and not (tmp_path / "g").exists()
