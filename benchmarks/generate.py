"""Benchmark: generating an assignment's key and PDFs.

- key only (variants, answers, key.json and key.csv) for 2,000 students x the sample's 5 problems;
- baseline in the same run: the same variants' answers by sympy substitution, one variant at a
  time (timed on a subset and extrapolated, as a full run would take minutes);
- PDFs for 200 students with ``--jobs 1`` and ``--jobs 2``: time per student PDF.

Targets: key for 2,000 x 5 in under 1 s; PDFs at <= 50 ms per student (2 cores, --jobs 2).

Run: ``python benchmarks/generate.py [--students 2000] [--pdf-students 200] [--baseline 100]``.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path

from grader.assign.assignment import Student, load_assignment
from grader.assign.keyfile import key_csv, key_document, key_json
from grader.assign.variants import generate
from grader.bank.template import load_bank
from grader.physics.symbolic import from_node
from grader.resources import sample_dir
from grader.solve.cache import compiled_for

RESULTS = Path(__file__).resolve().parent / "results"


def roster(count: int, folder: Path) -> Path:
    """A synthetic roster of ``count`` students."""
    lines = ["id,name,email,section"] + [f"{9000000 + i},Student {i},s{i}@example.edu,L0{i % 4}" for i in range(count)]
    path = folder / f"roster-{count}.csv"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def time_key(count: int, folder: Path, repeat: int = 3) -> tuple[float, object]:
    """Best wall time of variants + answers + key.json + key.csv for ``count`` students."""
    bank, assignment = load_bank(), load_assignment(sample_dir() / "assignment.yaml")
    students = tuple(Student(f"{9000000 + i}", f"Student {i}", f"s{i}@example.edu", "L01") for i in range(count))
    for template in bank.values():
        compiled_for(template)  # compile once, outside the timing, as a warm cache would
    best, generation = float("inf"), None
    for _ in range(repeat):
        started = time.perf_counter()
        generation = generate(assignment, students, bank)
        key_json(key_document(assignment, generation, bank))
        key_csv(generation)
        best = min(best, time.perf_counter() - started)
    return best, generation


def time_baseline(generation: object, subset: int) -> float:
    """Seconds per variant when every numeric answer is substituted into the sympy solution."""
    bank = load_bank()
    trees = {t: {n: from_node(a.numeric, {}) for n, a in compiled_for(bank[t]).answers.items()
                 if a.numeric is not None} for t in bank}
    variants = [v for s in generation.students for v in s.problems][:subset]  # type: ignore[attr-defined]
    started = time.perf_counter()
    for variant in variants:
        constants = compiled_for(bank[variant.template]).constants
        values = {**variant.params, **constants}
        for expr in trees[variant.template].values():
            float(expr.subs({symbol: values[symbol.name] for symbol in expr.free_symbols}).evalf())
    return (time.perf_counter() - started) / len(variants)


def time_pdfs(count: int, folder: Path, jobs: int) -> tuple[float, float]:
    """Seconds per student for a whole ``grader generate`` run in a fresh process (what a user
    waits for: key, every student PDF, the class PDF and the answer key), and for the student
    sheets alone (same process kind, sheets only). Fresh processes: Typst's memo cache is
    process-wide and one run would slow the next."""
    path = roster(count, folder)
    out = folder / f"pdf-{count}-{jobs}"
    started = time.perf_counter()
    subprocess.run([sys.executable, "-m", "grader", "generate", str(sample_dir() / "assignment.yaml"), "--roster",
                    str(path), "--out", str(out), "--jobs", str(jobs)], check=True, capture_output=True)
    whole = (time.perf_counter() - started) / count
    sheets = subprocess.run([sys.executable, "-c", _SHEETS, str(sample_dir() / "assignment.yaml"), str(path),
                             str(jobs)], check=True, capture_output=True, text=True)
    return whole, float(sheets.stdout) / count


_SHEETS = """
import sys, time, concurrent.futures as cf
from pathlib import Path
from grader.assign.assignment import load_assignment, load_roster
from grader.bank.template import load_bank
from grader.assign.variants import generate
from grader import render
assignment, roster, jobs = load_assignment(Path(sys.argv[1])), load_roster(Path(sys.argv[2])), int(sys.argv[3])
bank = load_bank()
generation = generate(assignment, roster, bank)
documents = render._Documents(assignment, generation, bank)
started = time.perf_counter()
sources = [render.student_source(documents, [i]) for i in range(len(roster))]
with cf.ThreadPoolExecutor(jobs) as pool:
    list(pool.map(render.compile_typst, sources))
print(time.perf_counter() - started)
"""


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--students", type=int, default=2000)
    parser.add_argument("--pdf-students", type=int, default=200)
    parser.add_argument("--baseline", type=int, default=100, help="variants timed for the sympy baseline")
    arguments = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(scratch)
        key_s, generation = time_key(arguments.students, folder)
        variants = arguments.students * 5
        per_variant = time_baseline(generation, arguments.baseline)
        pdf = {jobs: time_pdfs(arguments.pdf_students, folder, jobs) for jobs in (1, 2)}
    rows = [
        ("key: variants + answers + key.json + key.csv", f"{arguments.students:,} students x 5 problems",
         f"{key_s:.3f} s", f"{key_s / variants * 1e6:.1f} µs per variant", "< 1 s", key_s < 1),
        ("baseline: sympy substitution per variant", f"{arguments.baseline} variants, extrapolated",
         f"{per_variant * variants:.1f} s", f"{per_variant * 1e3:.2f} ms per variant",
         f"{per_variant * variants / key_s:,.0f}x slower", True),
    ]
    for jobs in (1, 2):
        whole, sheets = pdf[jobs]
        target = "<= 50 ms per student" if jobs == 2 else "-"
        rows += [
            (f"student PDFs only, --jobs {jobs}", f"{arguments.pdf_students} students",
             f"{sheets * arguments.pdf_students:.2f} s", f"{sheets * 1e3:.1f} ms per student PDF", target,
             jobs == 1 or sheets <= 0.05),
            (f"whole `grader generate`, --jobs {jobs}", f"{arguments.pdf_students} students (+ class PDF + key)",
             f"{whole * arguments.pdf_students:.2f} s", f"{whole * 1e3:.1f} ms per student", target,
             jobs == 1 or whole <= 0.05),
        ]
    table = ["| what | size | total | per item | target | |", "|---|---|--:|--:|---|---|"]
    table += [f"| {w} | {s} | {t} | {p} | {g} | {'met' if ok else '**NOT met**'} |" for w, s, t, p, g, ok in rows]
    report = "# Generate benchmark\n\n" + "\n".join(table) + "\n"
    print(report)
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "generate.md").write_text(report, encoding="utf-8")
    return 0 if all(ok for *_, ok in rows) else 1


if __name__ == "__main__":
    raise SystemExit(main())
