"""Feedback benchmark: the time per student of each student's graded sheet (``grader grade --feedback``) beside
what the answer key takes per student.

Run: ``python benchmarks/feedback.py [--students N] [--rounds R]`` (default 60 students, 3 rounds). The
sample assignment is generated for N students (``generate --no-pdf``), their simulated answers graded, then
timed in this process on the same variants, alternated round after round so that each sees the same
machine: the answer key's parts (``STUDENTS_PER_PART`` students a part, untagged, as ``grader generate``
typesets them), the students' sheets, and the feedback files in PDF and in HTML (each with ``index.csv``).
Each is timed from a fresh start (its worked solutions computed again). Printed per student: the median
over the rounds of the wall time, and of the CPU time (this process's, Typst's threads included: what a
shared machine's other work does not inflate as much). Target (issue 30): a student's feedback "in the
time the answer key takes per student"; the file holds their part of the key and their marked sheet, so
the sheet and the key together are printed too, and each as a ratio to the key. The machine's load average
is printed with the figures; they are also written to ``benchmarks/results/feedback.md``.
"""

from __future__ import annotations

import argparse
import csv
import os
import platform
import resource
import statistics
import tempfile
import time
from collections.abc import Callable
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
from grader.render.pdfs import STUDENTS_PER_PART
from grader.render.typeset import compile_typst

RESULTS = Path(__file__).resolve().parent / "results"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--students", type=int, default=60)
    parser.add_argument("--rounds", type=int, default=3)
    arguments = parser.parse_args()
    count = arguments.students
    bank = load_bank(bank_dir())
    loads = [os.getloadavg()[0]]
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
        timed: dict[str, Callable[[int], object]] = {
            "answer key": lambda _: _key(Documents(from_key, variants, templates), count),
            "sheets": lambda _: _sheets(Documents(from_key, variants, templates), count),
            "feedback (pdf)": lambda n: write_feedback(from_key, variants, templates, back, folder / f"pdf{n}", "pdf"),
            "feedback (html)": lambda n: write_feedback(from_key, variants, templates, back, folder / f"html{n}",
                                                        "html")}
        figures: dict[str, list[tuple[float, float]]] = {what: [] for what in timed}
        for number in range(arguments.rounds):
            for what, run in timed.items():
                figures[what].append(_timed(run, number))
            loads.append(os.getloadavg()[0])
    medians = {what: tuple(statistics.median(f[i] for f in found) for i in (0, 1)) for what, found in figures.items()}
    medians["sheet + key"] = tuple(medians["answer key"][i] + medians["sheets"][i] for i in (0, 1))
    key_wall, key_cpu = medians["answer key"]
    lines = [f"{count} students, {arguments.rounds} rounds; load average {min(loads):.1f} to {max(loads):.1f}",
             f"{'':16} {'wall':>6} {'CPU':>6} {'wall/key':>9} {'CPU/key':>8}  (ms a student, median of the rounds)"]
    lines += [f"{what:16} {1000 * wall / count:6.0f} {1000 * cpu / count:6.0f} {wall / key_wall:8.2f}x "
              f"{cpu / key_cpu:7.2f}x" for what, (wall, cpu) in medians.items()]
    print("\n".join(lines))
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "feedback.md").write_text(
        f"# Feedback benchmark\n\nPython {platform.python_version()}, {os.cpu_count()} CPUs, "
        f"{time.strftime('%d %B %Y', time.gmtime())}. `python benchmarks/feedback.py --students {count} "
        f"--rounds {arguments.rounds}`; target (issue 30): the feedback in the time the answer key takes per student "
        "(wall/key at most 1.00x).\n\n```\n" + "\n".join(lines) + "\n```\n", encoding="utf-8")


def _cpu() -> float:
    used = resource.getrusage(resource.RUSAGE_SELF)
    return used.ru_utime + used.ru_stime


def _timed(run: Callable[[int], object], number: int) -> tuple[float, float]:
    """The wall and CPU seconds ``run(number)`` takes."""
    wall, cpu = time.perf_counter(), _cpu()
    run(number)
    return time.perf_counter() - wall, _cpu() - cpu


def _key(documents: Documents, count: int) -> None:
    for start in range(0, count, STUDENTS_PER_PART):
        compile_typst(key_source(documents, people=range(start, min(count, start + STUDENTS_PER_PART))), tagged=False)


def _sheets(documents: Documents, count: int) -> None:
    for index in range(count):
        compile_typst(student_source(documents, [index]))


if __name__ == "__main__":
    main()
