"""Integrity benchmark (issue 28 part 3): answers from another student's variant, found and not imagined.

- **Honest classes**: the sample assignment (5 problems, 13 numeric parts) for ``--classes`` classes of
  ``--size`` students, each with its own seed, answered by the demo's answer generator
  (:mod:`grader.assign.sample_answers`: most answers right, some off by 6 to 30 %, diagnosed mistakes,
  errors carried forward, blanks), graded with the shipped bank; every pair flagged at the assignment's
  default threshold is a false alarm. Target: at most 1 in all.
- **Planted copies**: the same classes, one student in each copying 3 numeric answers of another (three
  parts the other got right, typed as the other typed them; the two drawn at random); found when that pair
  is flagged. Target: at least 95 %.
- **Scale**: a key for ``--students`` students (``grader generate --no-pdf``) and answers typed as the
  grading benchmark types them (``benchmarks/grade.py``); ``grader.grade.run``'s grading timed in process,
  then the integrity check alone. Target: fast (the check a small share of grading).

Run: ``python benchmarks/integrity.py [--classes 200] [--size 100] [--students 100000]``; it writes
``benchmarks/results/integrity.md``.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import platform
import random
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
RESULTS = ROOT / "benchmarks" / "results"
COPIED = 3


def classes(count: int, size: int, jobs: int) -> dict[str, object]:
    """Honest and planted runs over ``count`` classes of ``size``, in ``jobs`` processes."""
    with ProcessPoolExecutor(max_workers=jobs) as pool:
        runs = list(pool.map(_one_class, range(count), [size] * count, chunksize=max(1, count // (4 * jobs))))
    return {"classes": count, "size": size, "false_alarms": [alarm for run in runs for alarm in run["alarms"]],
            "found": sum(run["found"] for run in runs), "planted": sum(run["planted"] for run in runs),
            "missed": [run["missed"] for run in runs if run["missed"]],
            "check_seconds": sum(run["seconds"] for run in runs)}


def _one_class(number: int, size: int) -> dict[str, Any]:
    """Class ``number``: its false alarms, and whether its planted copy was found."""
    from grader.assign.assignment import Student, load_assignment
    from grader.assign.keyfile import key_document, key_json
    from grader.assign.sample_answers import sample_answers, submissions_csv
    from grader.assign.variants import generate
    from grader.bank.template import load_bank
    from grader.base.resources import sample_dir
    from grader.grade.integrity import check
    from grader.grade.key import load_key
    from grader.grade.run import _graded

    bank = load_bank()
    assignment = dataclasses.replace(load_assignment(sample_dir() / "assignment.yaml"), seed=f"integrity-{number}")
    roster = tuple(Student(f"s{i:04d}", f"Student {i}", f"s{i}@example.edu", "1") for i in range(size))
    found: dict[str, Any] = {"alarms": [], "found": 0, "planted": 0, "missed": "", "seconds": 0.0}
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        generation = generate(assignment, roster, bank)
        (folder / "key.json").write_text(key_json(key_document(assignment, generation, bank, folder)))
        key = load_key(folder / "key.json")
        answers = sample_answers(assignment, generation, bank)
        (folder / "honest.csv").write_text(submissions_csv(answers))
        graded = _graded(key, [folder / "honest.csv"], "auto", (), bank)
        started = time.perf_counter()
        result = check(graded)
        found["seconds"] = time.perf_counter() - started
        found["alarms"] = [(number, key.students[p.student].id, key.students[p.partner].id, p.labels, p.corrected)
                           for p in result.flagged]
        copier, source, copied = _copy(answers, key, random.Random(f"integrity-{number}"))
        if copier is None or source is None:
            return found
        found["planted"] = 1
        (folder / "copied.csv").write_text(submissions_csv(copied))
        result = check(_graded(key, [folder / "copied.csv"], "auto", (), bank))
        pair = result.pair(key.positions[copier], key.positions[source])
        if pair is not None and pair in result.flagged:
            found["found"] = 1
        else:
            found["missed"] = (f"class {number}: {copier} from {source}: "
                               + ("no pair" if pair is None else f"{', '.join(pair.labels)} matched of {pair.wrong} "
                                  f"wrong, chance {pair.chance:.2g}, corrected {pair.corrected:.2g}"))
    return found


def _copy(answers: list, key: object, rng: random.Random) -> tuple[str | None, str | None, list]:
    """The answers with one student's answers to three numeric parts replaced by another's, right ones."""
    from grader.grade.key import Key

    assert isinstance(key, Key)
    numeric = {label for label in key.labels if not key.students[0].parts[label].symbolic}
    right: dict[str, dict[str, object]] = {}
    for answer in answers:
        if answer.label in numeric and answer.deserves == "correct" and answer.form != "late resubmission":
            right.setdefault(answer.student_id, {})[answer.label] = answer
    ids = sorted(right)
    for _ in range(100):
        copier, source = rng.sample(ids, 2)
        labels = sorted(right[source])
        if len(labels) < COPIED:
            continue
        taken = rng.sample(labels, COPIED)
        copied = [answer for answer in answers if not (answer.student_id == copier and answer.label in taken)]
        stamp = next((a.timestamp for a in answers if a.student_id == copier), answers[0].timestamp)
        copied += [dataclasses.replace(right[source][label], student_id=copier, timestamp=stamp)  # type: ignore[type-var]
                   for label in taken]
        return copier, source, copied
    return None, None, answers


def scale(students: int) -> dict[str, object]:
    """Grading and the check alone, in process, for a class of ``students``."""
    from benchmarks.grade import make_inputs
    from grader.bank.template import load_bank
    from grader.base.heap import collector_paused
    from grader.grade.diagnosis import physics_for
    from grader.grade.grading import grade
    from grader.grade.integrity import check
    from grader.grade.key import load_key
    from grader.grade.submissions import StudentRef, read_submissions

    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        key_path, answers, cells = make_inputs(folder, students, random.Random(7))
        bank = load_bank()
        with collector_paused():  # as grader grade runs
            started = time.perf_counter()
            key = load_key(key_path)
            submissions = read_submissions([answers], [StudentRef(s.id, s.email) for s in key.students],
                                           key.labels, "auto", (), zone=key.zone, attempts=key.attempts)
            graded = grade(key, submissions, physics_for(key, bank))
            grading = time.perf_counter() - started
            started = time.perf_counter()
            result = check(graded)
            checking = time.perf_counter() - started
    return {"students": students, "cells": cells, "grading": grading, "check": checking,
            "wrong": result.wrong, "matched": result.matched, "rows": len(result.listed),
            "pairs": int((result.ranked.parts() >= 2).sum()), "flagged": len(result.flagged)}


def report(run: dict[str, object], big: dict[str, object] | None, seconds: float, jobs: int) -> str:
    alarms, planted, found = run["false_alarms"], run["planted"], run["found"]
    assert isinstance(alarms, list) and isinstance(planted, int) and isinstance(found, int)
    share = found / planted if planted else 0.0
    lines = ["# Integrity benchmark", "",
             f"Python {platform.python_version()}, {os.cpu_count()} CPUs. `python benchmarks/integrity.py "
             f"--classes {run['classes']} --size {run['size']} --jobs {jobs}"
             + (f" --students {big['students']}`" if big else " --students 0`")
             + f"; load average (1/5/15 min) at the end: {'/'.join(f'{x:.2f}' for x in os.getloadavg())}.", "",
             "| what | measured | target |", "| --- | --: | --- |",
             f"| pairs flagged in {run['classes']} honest classes of {run['size']} | {len(alarms)} | at most 1: "
             f"{'met' if len(alarms) <= 1 else 'missed'} |",
             f"| planted copies ({COPIED} answers) found | {found} of {planted} ({100 * share:.1f} %) | at least "
             f"95 %: {'met' if share >= 0.95 else 'missed'} |",
             f"| integrity check, {run['classes']} classes of {run['size']} (in all) | {run['check_seconds']:.2f} s "
             "| |"]
    if big:
        grading, check = big["grading"], big["check"]
        assert isinstance(grading, float) and isinstance(check, float)
        lines.append(f"| {big['students']:,} students ({big['cells']:,} cells): grading in process, then the "
                     f"check alone | {grading:.1f} s, {check:.2f} s ({100 * check / grading:.1f} % of grading) | "
                     "fast (sort and join, not all pairs) |")
    lines.append("")
    lines += [f"False alarm: class {n}, {a} from {b} ({', '.join(labels)}; corrected chance {c:.2g})"
              for n, a, b, labels, c in alarms]
    missed = run["missed"]
    assert isinstance(missed, list)
    if missed:
        lines += ["", "Planted copies not flagged:", *(f"- {line}" for line in missed)]
    if big:
        lines += ["", f"At {big['students']:,} students: {big['wrong']:,} wrong answers compared, {big['matched']:,} "
                  f"matching some other student's value, {big['rows']:,} rows of integrity.csv, {big['pairs']:,} "
                  f"pairs matching in two or more parts with a corrected chance under 1, {big['flagged']:,} flagged."]
    lines += ["", f"Total benchmark time {seconds:.0f} s.", ""]
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--classes", type=int, default=200)
    parser.add_argument("--size", type=int, default=100)
    parser.add_argument("--students", type=int, default=100_000, help="0: leave out the timing at scale")
    parser.add_argument("--jobs", type=int, default=2, help="processes for the classes (the scale run has its own)")
    parser.add_argument("--out", type=Path, default=RESULTS / "integrity.md")
    args = parser.parse_args()
    started = time.perf_counter()
    with ProcessPoolExecutor(max_workers=1) as pool:  # beside the classes: the machine is shared, the share is read
        big_run = pool.submit(scale, args.students) if args.students else None
        run = classes(args.classes, args.size, args.jobs)
        big = big_run.result() if big_run is not None else None
    text = report(run, big, time.perf_counter() - started, args.jobs)
    print(text)
    args.out.write_text(text, encoding="utf-8")


if __name__ == "__main__":
    main()
