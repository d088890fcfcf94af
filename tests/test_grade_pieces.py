"""Grading a class a piece of students at a time (what lets a million students fit in memory) writes the same
bytes as grading it at once: every verdict depends on its own student's answers alone, and the class's files
are put together in the order the whole class would give them."""

from __future__ import annotations

import csv
import json
import shutil
from pathlib import Path

import pytest

import grader.grade.run
from grader.assign.key_columns import write_key_columns
from grader.cli import main
from grader.grade.key import load_key
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
    for size in (students, 1, 4, 7):
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
