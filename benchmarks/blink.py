"""Blink benchmark (issue 29, target 3): grading the demo's class (30 students, 450 cells, every report) as a
whole command from process start, against ``python -c "import numpy, yaml"`` (what any Python tool of this
kind pays before doing anything), the two alternated in one run so that both see the same machine; the
machine's load is printed beside them.

Target: the grading at most 5x the baseline.

The grading is ``grader grade --key DEMO/key.json DEMO/submissions.csv --out X`` after ``grader demo --out
DEMO`` (made once, before the rounds; a fresh ``X`` each round). Also printed: where a grading run's time
goes inside the process (imports, the figures, the rest), from one run in-process; grading imports no
matplotlib (the figures are written as SVG text), which the in-process run checks.

Run: ``python benchmarks/blink.py [--rounds 7]``; it writes ``benchmarks/results/blink.md``.
"""

from __future__ import annotations

import argparse
import os
import platform
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "benchmarks" / "results"
TARGET = 5.0
BASELINE = [sys.executable, "-c", "import numpy, yaml"]
PHASES = """
import sys, time
start = time.perf_counter()
import numpy, yaml
numpy_yaml = time.perf_counter()
from grader.grade import run
grader_modules = time.perf_counter()
from grader.grade import class_report
drawing = [0.0]
def timed(function):
    def wrapper(*arguments, **options):
        began = time.perf_counter()
        try:
            return function(*arguments, **options)
        finally:
            drawing[0] += time.perf_counter() - began
    return wrapper
class_report._figures = timed(class_report._figures)  # all the figures
from grader.cli import main
began = time.perf_counter()
main(["grade", "--key", sys.argv[1], sys.argv[2], "--out", sys.argv[3]])
done = time.perf_counter()
assert "matplotlib" not in sys.modules, "grading imported matplotlib"
print(f"{numpy_yaml - start:.3f} {grader_modules - numpy_yaml:.3f} {drawing[0]:.3f} {done - began - drawing[0]:.3f}")
"""


def timed(command: list[str], cwd: Path) -> tuple[float, float]:
    """Seconds from process start to exit, and the CPU seconds it and its children used (on a loaded
    machine the steadier of the two); the command must succeed."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run(command, cwd=cwd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("--rounds", type=int, default=7, help="rounds of baseline-then-grading (default 7)")
    arguments = parser.parse_args()
    if arguments.rounds < 1:
        parser.error("--rounds must be >= 1")
    start_load = os.getloadavg()
    with tempfile.TemporaryDirectory(prefix="grader-blink-") as folder:
        work = Path(folder)
        subprocess.run([sys.executable, "-m", "grader", "demo", "--out", "demo"], cwd=work, check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        key, submissions = work / "demo" / "key.json", work / "demo" / "submissions.csv"
        baseline, grading, loads = [], [], []
        for number in range(arguments.rounds):
            baseline.append(timed(BASELINE, work))
            grading.append(timed([sys.executable, "-m", "grader", "grade", "--key", str(key), str(submissions),
                                  "--out", f"graded-{number}"], work))
            loads.append(os.getloadavg()[0])
            print(f"round {number + 1}: baseline {baseline[-1][0]:.3f} s, grading {grading[-1][0]:.3f} s, "
                  f"load {loads[-1]:.2f}", flush=True)
        phases = subprocess.run([sys.executable, "-c", PHASES, str(key), str(submissions), str(work / "phases")],
                                cwd=work, check=True, capture_output=True, text=True).stdout.split()[-4:]
    base, grade = (statistics.median(wall for wall, _ in baseline), statistics.median(wall for wall, _ in grading))
    base_cpu, grade_cpu = (statistics.median(cpu for _, cpu in baseline), statistics.median(cpu for _, cpu in grading))
    ratio = grade / base
    verdict = "met" if ratio <= TARGET else "**NOT met**"
    names = ("numpy and yaml", "grader's modules", "the figures (7, written as SVG text)",
             "the rest (reading, grading, writing)")
    text = "\n".join([
        "# Blink benchmark: the demo's class graded", "",
        f"Python {platform.python_version()}, {os.cpu_count()} CPUs. `python benchmarks/blink.py --rounds "
        f"{arguments.rounds}`; whole commands from process start, medians of {arguments.rounds} rounds, each the "
        f"baseline then the grading; load = the 1-minute load average (at the start: "
        f"{', '.join(f'{x:.2f}' for x in start_load)}; over the rounds {min(loads):.2f} to {max(loads):.2f}).", "",
        "| command | median | of the baseline | CPU | of the baseline's | target |",
        "| --- | --: | --: | --: | --: | --- |",
        f"| `python -c \"import numpy, yaml\"` | {base:.3f} s | 1.00x | {base_cpu:.3f} s | 1.00x | |",
        f"| `grader grade --key DEMO/key.json DEMO/submissions.csv --out X` | {grade:.3f} s | {ratio:.2f}x "
        f"| {grade_cpu:.3f} s | {grade_cpu / base_cpu:.2f}x | <= {TARGET:.0f}x: {verdict} |", "",
        "CPU: the seconds of CPU the command and its children used.", "",
        "Where one grading run's time goes (wall, in-process, after the interpreter's own start):", "",
        "| phase | seconds |", "| --- | --: |",
        *(f"| {name} | {float(value):.3f} |" for name, value in zip(names, phases, strict=True)), ""])
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / "blink.md").write_text(text, encoding="utf-8")
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
