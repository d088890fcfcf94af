"""Deadlines, late policies, extensions and which attempt counts, against scores computed by hand with
Canvas' late-policy rules (a partial interval counts whole; deductions are of the points possible; the
lowest grade floors them; a score already below it loses nothing) and Gradescope's grace and late due date."""

from __future__ import annotations

import csv
import io
import json
from datetime import datetime, timedelta
from fractions import Fraction
from pathlib import Path
from typing import Any

import pytest

from grader.assign.assignment import check_extensions, load_assignment, load_roster
from grader.assign.deadlines import LatePolicy, late_from, student_due, zone
from grader.base.errors import GraderError, TemplateError
from grader.cli import main
from grader.grade.key import load_key
from grader.grade.lateness import deductions, intervals

CHICAGO = "America/Chicago"
POLICY = {"grace": "15 min", "deduct": "10 %", "per": "day", "lowest": "40 %", "after": "7 days"}
DUE = "2026-12-04T23:59:00-06:00"
# Two parts of 5 points: 1a is 2, 1b is 3. (student, 1a, 1b, timestamp as a form writes it, in Chicago
# unless it says otherwise), with what each scores by hand: (late minutes, deduction, total after it).
ROWS = {
    "on": ("2", "3", "2026-12-04 23:50", (0, 0, 10)),
    "grace": ("2", "3", "12/5/2026 12:10:00 AM", (11, 0, 10)),  # 11 min late: within 15 min, on time
    "dayone": ("2", "3", "2026-12-06 00:00", (1441, 2, 8)),  # 1 day 1 min: two days, 20 % of 10
    "utc": ("2", "3", "2026-12-05T06:30:00Z", (31, 1, 9)),  # 00:30 in Chicago: one day, 10 %
    "floor": ("2", "9", "2026-12-07 23:59", (4320, 1, 4)),  # 5 of 10, 3 days: 30 % would leave 2; floor 4
    "below": ("7", "9", "2026-12-05 23:59", (1440, 0, 0)),  # 0 of 10, under the floor: nothing to take
    "closed": ("2", "3", "2026-12-11 23:59:01", (10081, 10, 0)),  # past 7 days: no credit
    "seven": ("2", "3", "2026-12-11 23:59", (10080, 6, 4)),  # 7 days exactly: 70 %, floored at 40 %
    "ext": ("2", "3", "2026-12-06 20:00", (0, 0, 10)),  # an extension to Dec 6 23:59
    "unknown": ("2", "3", "soon", (None, 0, 10)),  # a time that does not read: not known, listed
}


def key_document(late: dict[str, str] | None = POLICY, attempts: str = "latest") -> dict[str, Any]:
    """A key of one problem, two parts of 5 points, due Dec 4 23:59 in Chicago, with the students of ROWS
    and one who submits nothing (``missing``) and one who resubmits a part late (``mixed``)."""
    def student(student_id: str) -> dict[str, Any]:
        answers = {name: {"value": value, "unit": "", "label": label, "points": 5,
                          "tolerance": {"mode": "rtol", "rtol": 0.01, "atol": 0}}
                   for name, label, value in (("x", "1a", 2.0), ("y", "1b", 3.0))}
        entry = {"id": student_id, "name": student_id, "email": f"{student_id}@uni.edu", "section": "1",
                 "problems": [{"key": "1", "answers": answers}]}
        if student_id == "ext":
            entry["due"] = "2026-12-06T23:59:00-06:00"
        return entry

    return {"schema": "grader-key", "version": 2,
            "assignment": {"title": "HW", "due": "2026-12-04 23:59", "deadline": DUE, "timezone": CHICAGO,
                           "late": late, "grading": {"attempts": attempts}},
            "problems": [{"key": "1", "title": "Two numbers", "answers": [
                {"name": "x", "label": "1a", "unit": "", "points": 5},
                {"name": "y", "label": "1b", "unit": "", "points": 5}]}],
            "students": [student(s) for s in (*ROWS, "missing", "mixed")]}


def grade(tmp_path: Path, document: dict[str, Any], rows: list[tuple[str, str, str, str]]) -> dict[str, Any]:
    """Grade ``rows`` (student, label, answer, timestamp) against ``document``: the reports, read."""
    (tmp_path / "key.json").write_text(json.dumps(document), encoding="utf-8")
    text = io.StringIO()
    csv.writer(text, lineterminator="\n").writerows([("student_id", "label", "answer", "timestamp"), *rows])
    (tmp_path / "subs.csv").write_text(text.getvalue(), encoding="utf-8")
    out = tmp_path / "out"
    assert main(["grade", "--key", str(tmp_path / "key.json"), str(tmp_path / "subs.csv"), "--out", str(out)]) == 0

    def table(name: str) -> list[dict[str, str]]:
        return list(csv.DictReader(io.StringIO((out / name).read_text(encoding="utf-8"))))

    return {"grades": {row["student_id"]: row for row in table("grades.csv")},
            "details": {(row["student_id"], row["label"]): row for row in table("details.csv")},
            "problems": table("problems.csv"), "canvas": {row["SIS User ID"]: row for row in table("canvas.csv")},
            "report": (out / "report.html").read_text(encoding="utf-8")}


def class_rows() -> list[tuple[str, str, str, str]]:
    rows = [(s, label, answer, stamp) for s, (a, b, stamp, _) in ROWS.items() for label, answer in (("1a", a),
                                                                                                  ("1b", b))]
    return [*rows, ("mixed", "1a", "2", "2026-12-04 20:00"), ("mixed", "1b", "1", "2026-12-04 20:00"),
            ("mixed", "1b", "3", "2026-12-06 00:00")]


def number(text: str) -> float | None:
    return None if text == "" else float(text)


def test_a_late_policy_deducts_as_canvas_counts(tmp_path: Path) -> None:
    graded = grade(tmp_path, key_document(), class_rows())
    for student_id, (*_, (late, deduction, total)) in ROWS.items():
        row = graded["grades"][student_id]
        assert (number(row["late"]), number(row["deduction"]), number(row["total"])) == (late, deduction, total), \
            student_id
        assert float(graded["canvas"][student_id]["HW"]) == total
    missing = graded["grades"]["missing"]
    assert (missing["late"], number(missing["deduction"]), number(missing["total"])) == ("", 0, 0)
    # Per part: 1a on time, 1b's resubmission (the latest counts) 1 day 1 min late: 20 % of its 5 points.
    mixed = graded["grades"]["mixed"]
    assert (number(mixed["late"]), number(mixed["deduction"]), number(mixed["total"])) == (1441, 1, 9)
    details = graded["details"]
    assert [(details["mixed", label]["late"], details["mixed", label]["deduction"]) for label in ("1a", "1b")] == [
        ("0", "0"), ("1441", "1")]
    assert (details["closed", "1a"]["late"], details["closed", "1a"]["deduction"]) == ("10081", "5")
    assert details["missing", "1a"]["late"] == "" and details["unknown", "1a"]["late"] == ""
    unread = [p for p in graded["problems"] if p["student_id"] == "unknown"]
    assert len(unread) == 2 and all("how late it was is not known" in p["reason"] for p in unread)
    assert "Late work: 8 students had answers that count come in after their due time" in graded["report"]


def test_without_a_late_policy_late_work_is_graded_as_on_time_and_its_lateness_reported(tmp_path: Path) -> None:
    graded = grade(tmp_path, key_document(late=None), class_rows())
    row = graded["grades"]["closed"]
    assert (row["late"], row["deduction"], row["total"]) == ("10081", "0", "10")
    assert "without a late policy, late work is graded as on time" in graded["report"]


@pytest.mark.parametrize(("late", "expected"), [
    (timedelta(seconds=1), 9), (timedelta(days=1), 9), (timedelta(days=1, minutes=1), 8),
    (timedelta(days=2, hours=23), 7), (timedelta(days=5), 5)])
def test_canvas_counts_a_partial_day_as_a_whole_one(late: timedelta, expected: float) -> None:
    """10 % a day of 10 points, no floor: a second late loses a day's 10 %; 1 day 1 minute, 20 %."""
    policy = LatePolicy(Fraction(1, 10))
    total, _ = deductions(policy, ((10.0, 10.0, intervals(policy, late)),))
    assert 10 - total == expected


def test_hourly_deductions_and_the_floor_over_parts_submitted_together() -> None:
    hourly = late_from({"deduct": "5 %", "per": "hour"}, "a.yaml")
    assert deductions(hourly, ((8.0, 10.0, intervals(hourly, timedelta(hours=2, minutes=30))),))[0] == Fraction(3, 2)
    # Canvas floors the assignment, not each part: 10 + 0 of 20 at 50 % a day, floor 40 % (8): loses 2.
    policy = late_from({"deduct": "50 %", "lowest": "40 %"}, "a.yaml")
    total, shares = deductions(policy, ((10.0, 10.0, 1), (0.0, 10.0, 1)))
    assert (total, shares) == (2, (1, 1))


def test_an_old_key_without_deadlines_reads_and_grades_as_before(tmp_path: Path) -> None:
    document = key_document()
    for entry in ("deadline", "timezone", "late", "grading"):
        del document["assignment"][entry]
    del document["students"][list(ROWS).index("ext")]["due"]
    (tmp_path / "key.json").write_text(json.dumps(document), encoding="utf-8")
    key = load_key(tmp_path / "key.json")
    assert (key.deadline, key.late, key.attempts, str(key.zone)) == (None, None, "latest", "UTC")
    graded = grade(tmp_path, document, class_rows())
    assert {(row["late"], row["deduction"]) for row in graded["grades"].values()} == {("", "0")}


@pytest.mark.parametrize(("entry", "value", "message"), [
    ("late", {"deduct": "10 %", "lowest": "40"}, "assignment.late.lowest: expected a percentage"),
    ("late", {"deduct": "10 %", "afer": "7 days"}, "assignment.late.afer: expected one of grace, deduct, per, "
                                                    "lowest, after (did you mean after?)"),
    ("timezone", "America/Chicgo", "assignment.timezone: expected an IANA time zone such as America/Chicago or UTC "
                                   "(did you mean America/Chicago?)"),
    ("deadline", "2026-12-04 23:59", "assignment.deadline: expected a date-time with its offset")])
def test_a_key_with_a_bad_deadline_entry_is_refused_naming_it(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                              entry: str, value: Any, message: str) -> None:
    document = key_document()
    document["assignment"][entry] = value
    (tmp_path / "key.json").write_text(json.dumps(document), encoding="utf-8")
    assert main(["grade", "--key", str(tmp_path / "key.json"), str(tmp_path / "key.json"), "--out",
                 str(tmp_path / "out")]) == 2
    assert message in capsys.readouterr().err


def assignment(tmp_path: Path, extra: str) -> Path:
    path = tmp_path / "a.yaml"
    path.write_text('title: T\ncourse: C\nseed: s\nproblems: [{template: drop-rebound}]\n' + extra, encoding="utf-8")
    return path


def test_the_assignments_deadline_fields_are_read_and_checked(tmp_path: Path) -> None:
    read = load_assignment(assignment(tmp_path, f'due: "2026-12-04 23:59"\ntimezone: {CHICAGO}\n'
                                                'late: {grace: "15 min", deduct: "10 %", per: day, lowest: "40 %", '
                                                'after: "7 days"}\ngrading: {attempts: best}\n'))
    assert (read.deadline.isoformat() if read.deadline else None, read.timezone) == (DUE, CHICAGO)
    assert read.late is not None and read.late.to_json() == POLICY and read.grading.attempts == "best"
    assert load_assignment(assignment(tmp_path, 'due: "Friday"\n')).deadline is None  # printed, not a deadline
    with pytest.raises(TemplateError, match=r"a.yaml: due: expected a date-time such as 2026-12-04 23:59 \(the late "
                                            r"policy needs one\), got 'Friday'"):
        load_assignment(assignment(tmp_path, 'due: "Friday"\nlate: {deduct: "10 %"}\n'))
    with pytest.raises(TemplateError, match=r"grading.attempts: expected latest, best or first"):
        load_assignment(assignment(tmp_path, "grading: {attempts: last}\n"))
    with pytest.raises(TemplateError, match=r"late.per: expected day or hour, got 'week'"):
        load_assignment(assignment(tmp_path, 'due: "2026-12-04"\nlate: {deduct: "10 %", per: week}\n'))


def test_roster_extensions_are_a_date_time_in_the_assignments_zone_or_a_delay(tmp_path: Path) -> None:
    roster = tmp_path / "roster.csv"
    roster.write_text("id,name,email,section,due\n1,A,,L1,\n2,B,,L1,+2 days\n3,C,,L1,2026-12-10 12:00\n",
                      encoding="utf-8")
    due = datetime.fromisoformat(DUE)
    assert [student_due(s.due, due, zone(CHICAGO)) for s in load_roster(roster)] == [
        None, due + timedelta(days=2), datetime.fromisoformat("2026-12-10T12:00:00-06:00")]
    roster.write_text("id,name,email,section,due\n1,A,,L1,next week\n", encoding="utf-8")
    with pytest.raises(GraderError, match=r"roster.csv: line 2: due: 'next week' is neither a date-time"):
        load_roster(roster)


def test_generate_writes_the_deadline_and_extensions_into_the_key(tmp_path: Path) -> None:
    path = assignment(tmp_path, f'due: "2026-12-04 23:59"\ntimezone: {CHICAGO}\nlate: {{deduct: "10 %"}}\n')
    (tmp_path / "roster.csv").write_text("id,name,email,section,due\n1,A,,L1,+1 hour\n2,B,,L1,\n", encoding="utf-8")
    assert main(["generate", str(path), "--roster", str(tmp_path / "roster.csv"), "--out", str(tmp_path / "out"),
                 "--no-pdf"]) == 0
    document = json.loads((tmp_path / "out" / "key.json").read_text(encoding="utf-8"))
    assert {name: document["assignment"][name] for name in ("deadline", "timezone", "late")} == {
        "deadline": DUE, "timezone": CHICAGO,
        "late": {"grace": "0 min", "deduct": "10 %", "per": "day", "lowest": "0 %"}}
    assert [student.get("due") for student in document["students"]] == ["2026-12-05T00:59:00-06:00", None]
    key = load_key(tmp_path / "out" / "key.json")
    assert key.students[0].due == datetime.fromisoformat(DUE) + timedelta(hours=1)


def attempts_rows() -> list[tuple[str, str, str, str]]:
    """``on`` answers 1a right, then wrong, then right again; 1b wrong, then right a day late."""
    return [("on", "1a", "2", "2026-12-04 10:00"), ("on", "1a", "5", "2026-12-04 11:00"),
            ("on", "1a", "2", "2026-12-04 12:00"), ("on", "1b", "1", "2026-12-04 10:00"),
            ("on", "1b", "3", "2026-12-05 10:00")]


def test_the_first_attempt_can_be_the_one_that_counts(tmp_path: Path) -> None:
    graded = grade(tmp_path, key_document(attempts="first"), attempts_rows())
    assert [graded["details"]["on", label]["source"].rsplit(":", 1)[1] for label in ("1a", "1b")] == ["2", "5"]
    assert graded["grades"]["on"]["total"] == "5"
    reasons = sorted(p["reason"] for p in graded["problems"])
    assert reasons[0].endswith("(submitted earlier: the first attempt counts)")


def test_the_best_attempt_counts_per_part_after_its_own_late_deduction(tmp_path: Path) -> None:
    """1b right a day late (10 % of the part's 5 points: 4.5) beats 1b wrong on time (0); of 1a's equal right
    answers, the first counts."""
    graded = grade(tmp_path, key_document(attempts="best"), attempts_rows())
    assert [graded["details"]["on", label]["source"].rsplit(":", 1)[1] for label in ("1a", "1b")] == ["2", "6"]
    row = graded["grades"]["on"]
    assert (row["late"], row["deduction"], row["total"]) == ("601", "0.5", "9.5")  # 10 h 1 min late: one day
    reasons = {p["line"]: p["reason"] for p in graded["problems"]}
    assert reasons["3"].startswith("not counted: ") and "scored more (5 points, this one 0" in reasons["3"]
    assert reasons["4"].startswith("the same answer as ") and "line 2" in reasons["4"]
    assert "scored more (4.5 points, this one 0" in reasons["5"]


@pytest.mark.parametrize(("attempts", "sources", "total"), [
    ("latest", ["3", "3"], "5"), ("first", ["2", "2"], "5"), ("best", ["2", "3"], "10")])
def test_in_a_wide_file_latest_and_first_take_a_submission_whole_and_best_each_part(
        tmp_path: Path, attempts: str, sources: list[str], total: str) -> None:
    (tmp_path / "key.json").write_text(json.dumps(key_document(attempts=attempts)), encoding="utf-8")
    (tmp_path / "wide.csv").write_text("Timestamp,student_id,1a,1b\n2026-12-04 10:00,on,2,1\n"
                                       "2026-12-04 11:00,on,5,3\n", encoding="utf-8")
    out = tmp_path / "out"
    assert main(["grade", "--key", str(tmp_path / "key.json"), str(tmp_path / "wide.csv"), "--out", str(out)]) == 0
    details = {row["label"]: row for row in csv.DictReader(io.StringIO((out / "details.csv").read_text()))
               if row["student_id"] == "on"}
    assert [details[label]["source"].rsplit(":", 1)[1] for label in ("1a", "1b")] == sources
    grades = {row["student_id"]: row for row in csv.DictReader(io.StringIO((out / "grades.csv").read_text()))}
    assert grades["on"]["total"] == total


def test_microsoft_forms_completion_time_is_the_timestamp(tmp_path: Path) -> None:
    (tmp_path / "key.json").write_text(json.dumps(key_document()), encoding="utf-8")
    (tmp_path / "forms.csv").write_text("Start time,Completion time,student_id,1a,1b\n"
                                        "12/5/2026 23:50,12/5/2026 23:59,dayone,2,3\n", encoding="utf-8")
    out = tmp_path / "out"
    assert main(["grade", "--key", str(tmp_path / "key.json"), str(tmp_path / "forms.csv"), "--out", str(out),
                 "--format", "wide"]) == 0
    grades = {row["student_id"]: row for row in csv.DictReader(io.StringIO((out / "grades.csv").read_text()))}
    assert (grades["dayone"]["late"], grades["dayone"]["deduction"]) == ("1440", "1")


def test_a_delay_in_the_roster_needs_the_assignments_due_time(tmp_path: Path) -> None:
    roster = tmp_path / "roster.csv"
    roster.write_text("id,name,email,section,due\n7,A,,L1,+2 days\n", encoding="utf-8")
    with pytest.raises(GraderError, match=r"roster.csv: student '7': due: '\+2 days' is a delay, but the "
                                          r"assignment's due is no date-time"):
        check_extensions(load_assignment(assignment(tmp_path, 'due: "Friday"\n')), load_roster(roster), roster)
