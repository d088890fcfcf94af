"""Feedback benchmark: the time per student of each student's graded sheet (``grader grade --feedback``) beside
what the answer key takes per student.

Run: ``python benchmarks/feedback.py [--students N]`` (default 60). The sample assignment is generated for N
students (``generate --no-pdf``), their simulated answers graded, then timed in this process, one after the
other, on the same variants: the answer key's parts (4 students a part, as ``grader generate`` typesets
them), the students' sheets, and the feedback files in PDF and in HTML (each with ``index.csv``). Target: a
student's feedback within the time of their sheet and their part of the key, which is what it holds. The
machine's load average is printed with the figures (the machine is shared).
"""

from __future__ import annotations

import argparse
import csv
import os
import tempfile
import time
from pathlib import Path

from grader.assign.sample_answers import sample_answers, submissions_csv
from grader.bank.template import load_bank
from grader.base.resources import bank_dir, sample_dir
from grader.grade.feedback_rows import key_generation, key_templates, returned
from grader.grade.grading import grade
from grader.grade.key import load_key
from grader.grade.submissions import StudentRef, read_submissions
from grader.render.documents import Documents, key_source, student_source
from grader.render.feedback import write_feedback
from grader.render.generate import Job, load_inputs, write_outputs
from grader.render.typeset import compile_typst


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--students", type=int, default=60)
    count = parser.parse_args().students
    bank = load_bank(bank_dir())
    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(scratch)
        with open(folder / "roster.csv", "w", encoding="utf-8", newline="") as stream:
            writer = csv.writer(stream)
            writer.writerow(["id", "name", "email", "section"])
            writer.writerows([f"{i:05d}", f"Student {i:05d}", f"s{i:05d}@example.edu", "L01"] for i in range(count))
        job = Job(sample_dir() / "assignment.yaml", folder / "roster.csv", folder / "hw", pdf=False)
        assignment, roster = load_inputs(job, bank)
        (folder / "hw").mkdir()
        generation, _ = write_outputs(job, assignment, roster, bank, folder / "hw")
        (folder / "answers.csv").write_text(submissions_csv(sample_answers(assignment, generation, bank)),
                                            encoding="utf-8")
        key = load_key(folder / "hw" / "key.json")
        submissions = read_submissions([folder / "answers.csv"], [StudentRef(s.id, s.email) for s in key.students],
                                       key.labels)
        graded = grade(key, submissions)
        templates = key_templates(key)
        from_key, variants = key_generation(key, templates)
        back = returned(graded)
        compile_typst(key_source(Documents(from_key, variants, templates), people=[0]))  # fonts and memo warmed
        figures = {"answer key": _key(Documents(from_key, variants, templates), count),
                   "sheets": _sheets(Documents(from_key, variants, templates), count)}
        for fmt in ("pdf", "html"):
            started = time.perf_counter()
            write_feedback(from_key, variants, templates, back, folder / fmt, fmt)  # type: ignore[arg-type]
            figures[f"feedback ({fmt})"] = time.perf_counter() - started
    print(f"{count} students; load average {os.getloadavg()[0]:.1f}")
    for what, seconds in figures.items():
        print(f"{what:16} {1000 * seconds / count:6.0f} ms a student")
    print(f"{'sheet + key':16} {1000 * (figures['answer key'] + figures['sheets']) / count:6.0f} ms a student")


def _key(documents: Documents, count: int) -> float:
    started = time.perf_counter()
    for start in range(0, count, 4):
        compile_typst(key_source(documents, people=range(start, min(count, start + 4))))
    return time.perf_counter() - started


def _sheets(documents: Documents, count: int) -> float:
    started = time.perf_counter()
    for index in range(count):
        compile_typst(student_source(documents, [index]))
    return time.perf_counter() - started


if __name__ == "__main__":
    main()
