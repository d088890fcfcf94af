"""Grading a class a piece of students at a time (what lets a million students fit in memory) writes the same
bytes as grading it at once: every verdict depends on its own student's answers alone, and the class's files
are put together in the order the whole class would give them."""

from __future__ import annotations

import csv
import json
import shutil
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

import grader.grade.run
import grader.grade.submissions
from grader.assign.key_columns import write_key_columns
from grader.cli import main
from grader.grade.answer_columns import AnswerColumns
from grader.grade.key import load_key
from grader.grade.submissions import Submissions
from tests.conftest import DemoRun

POLICY = {"grace": "15 min", "deduct": "10 %", "per": "day", "lowest": "40 %", "after": "7 days"}


def hard_class(tmp_path: Path, demo_run: DemoRun, sidecar: bool) -> tuple[Path, list[Path]]:
    """The demo's key with a late policy and the best attempt counting, a student with an extension, and a
    second file of late attempts: some better, some worse, some without a timestamp, one not of the class."""
    document = json.loads((demo_run.out / "key.json").read_text(encoding="utf-8"))
    document["assignment"]["late"] = POLICY
    document["assignment"]["grading"]["attempts"] = "best"
    document["students"][3]["due"] = "2026-12-08T23:59:00+00:00"
    key = tmp_path / "key.json"
    key.write_text(json.dumps(document), encoding="utf-8")
    if sidecar:
        assert write_key_columns(key)
    first = tmp_path / "submissions.csv"
    shutil.copyfile(demo_run.out / "submissions.csv", first)
    with first.open(encoding="utf-8", newline="") as stream:
        rows = list(csv.DictReader(stream))
    again = []
    for number, row in enumerate(rows):
        if number % 3 == 0:  # a later attempt: as given, another number, or nothing readable
            answer = [row["answer"], "1.5", "12 parsecs", row["answer"] + "0"][number % 4]
            stamp = ["2026-12-05 03:00", "2026-12-09 10:00", "", "not a time"][number % 4]
            again.append([row["student_id"], row["label"], answer, stamp])
    given = {row["student_id"] for row in rows}
    with (demo_run.out / "key.csv").open(encoding="utf-8", newline="") as stream:
        for row in csv.DictReader(stream):  # who gave nothing on time gives the key's values two days late
            if row["student_id"] not in given:
                again.append([row["student_id"], row["label"], row["value"], "2026-12-07 01:00"])
    again.append(["nobody", "1a", "1", "2026-12-05 03:00"])
    second = tmp_path / "again.csv"
    with second.open("w", encoding="utf-8", newline="") as stream:
        csv.writer(stream).writerows([["student_id", "label", "answer", "timestamp"], *again])
    return key, [first, second]


@pytest.mark.parametrize("sidecar", [False, True])
def test_a_class_graded_in_pieces_writes_the_bytes_it_writes_graded_at_once(
        tmp_path: Path, demo_run: DemoRun, monkeypatch: pytest.MonkeyPatch, sidecar: bool) -> None:
    key, files = hard_class(tmp_path, demo_run, sidecar)
    students = len(load_key(key).students)
    written = {}
    for size in (students, 1, 7):
        monkeypatch.setattr(grader.grade.run, "PIECE", size)
        out = tmp_path / f"out-{size}"
        assert main(["grade", "--key", str(key), *map(str, files), "--out", str(out)]) in (0, 3)
        written[size] = {path.name: path.read_bytes() for path in sorted(out.iterdir())}
    whole = written.pop(students)
    problems = whole["problems.csv"].decode()
    # The class has what pieces could get wrong: attempts not counted, late deductions, lateness not known.
    assert "the best attempt counts" in problems and "nobody" in problems
    details = whole["details.csv"].decode()
    assert ",incorrect," in details and ",invalid," in details and ",mistake," in details
    assert any(line.split(",")[-1] not in ("0", "0\r") for line in details.splitlines()[1:])  # a deduction
    for size, files_written in written.items():
        assert files_written == whole, size


def test_plain_files_kept_in_columns_grade_in_pieces_as_read_row_by_row(
        tmp_path: Path, demo_run: DemoRun, monkeypatch: pytest.MonkeyPatch) -> None:
    """The key's values, some changed, some unreadable, a student's left out, each answer once and without a
    timestamp, in two files: kept in columns and made a piece of students at a time, they grade to the bytes the
    row-by-row reading grades them to, at once."""
    rows = [["student_id", "label", "answer"]]
    with (demo_run.out / "key.csv").open(encoding="utf-8", newline="") as stream:
        for number, row in enumerate(csv.DictReader(stream)):
            if not row["student_id"].endswith("7"):
                rows.append([row["student_id"], row["label"], [row["value"], f"{row['value']}1", "12 parsecs",
                                                               f" {row['value']} {row['unit']}"][number % 4]])
    files = [tmp_path / "first.csv", tmp_path / "second.csv"]
    for path, part in zip(files, (rows[1:200], rows[200:]), strict=True):
        with path.open("w", encoding="utf-8", newline="") as stream:
            csv.writer(stream).writerows([rows[0], *part])
    key = demo_run.out / "key.json"
    written = {}
    for size, plain in ((1000, False), (1000, True), (4, True)):
        monkeypatch.setattr(grader.grade.run, "PIECE", size)
        if not plain:
            monkeypatch.setattr(grader.grade.submissions, "_plain_answers", lambda *given: None)
        else:
            monkeypatch.undo()
            monkeypatch.setattr(grader.grade.run, "PIECE", size)
        out = tmp_path / f"out-{size}-{plain}"
        kinds: list[type] = []
        monkeypatch.setattr(grader.grade.run, "read_submissions", spied(kinds))
        assert main(["grade", "--key", str(key), *map(str, files), "--out", str(out)]) in (0, 3)
        assert kinds == [AnswerColumns if plain else tuple]
        written[size, plain] = {path.name: path.read_bytes() for path in sorted(out.iterdir())}
    assert written[1000, True] == written[1000, False] == written[4, True]
    assert b",invalid," in written[4, True]["details.csv"]


def spied(kinds: list[type]) -> Callable[..., Submissions]:
    """``read_submissions``, noting the kind of the answers it read into ``kinds``."""
    read = grader.grade.submissions.read_submissions

    def reading(*given: Any, **named: Any) -> Submissions:
        found = read(*given, **named)
        kinds.append(type(found.answers))
        return found

    return reading


def test_a_piece_whose_students_have_no_due_time_is_timed_as_its_class(
        tmp_path: Path, demo_run: DemoRun, monkeypatch: pytest.MonkeyPatch) -> None:
    """No assignment due time, one student's own: the class's lateness is measured. A piece without that student
    measured none, and grades.csv's late column came out short: a traceback (ValueError from zip), where the
    class graded at once writes its files (found by the differential sweep of several submissions files)."""
    document = json.loads((demo_run.out / "key.json").read_text(encoding="utf-8"))
    assignment = document["assignment"]
    assignment["due"], assignment["late"] = "", None
    assignment.pop("deadline", None)
    document["students"][3]["due"] = "2026-12-08T23:59:00+00:00"
    key = tmp_path / "key.json"
    key.write_text(json.dumps(document), encoding="utf-8")
    submitted = tmp_path / "submissions.csv"
    shutil.copyfile(demo_run.out / "submissions.csv", submitted)
    written = {}
    for size in (1000, 2):
        monkeypatch.setattr(grader.grade.run, "PIECE", size)
        out = tmp_path / f"out-{size}"
        assert main(["grade", "--key", str(key), str(submitted), "--out", str(out)]) in (0, 3)
        written[size] = {path.name: path.read_bytes() for path in sorted(out.iterdir())}
    assert written[2] == written[1000]
    assert b"late" in written[2]["grades.csv"]
