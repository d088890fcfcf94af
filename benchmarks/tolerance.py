"""Fair-tolerance benchmark (issue 15): what the rounding bounds cost, and what three figures still miss.

- **Cost**: ``grader generate --no-pdf`` of the sample assignment (5 problems) for 2,000 students, whole
  command from process start, with the bounds (this tree) and without them (the tree at ``--base``,
  exported with ``git archive``), interleaved, each with its own warm compile cache; the 1-minute
  load average is printed with every run. Target: with the bounds at most 1.5x the time without.
- **Share**: for every student, answer and route of the same key, the route evaluated with every value
  written down rounded to three significant figures (the sheet asks for four) and the answer to three,
  graded against the stored tolerance (:func:`grader.grade.compare.is_correct`); how many land outside,
  and the same with four figures (which must be none).

Run: ``python benchmarks/tolerance.py [--runs 5] [--students 2000] [--base 3c0bfaf]``; it writes
``benchmarks/results/tolerance.md``.
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import subprocess
import sys
import tarfile
import tempfile
import time
from collections import Counter
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "benchmarks" / "results"
# The commands run as an installed copy runs: Python writes bytecode (a sandbox that sets
# PYTHONDONTWRITEBYTECODE made every command compile grader from source, ~30 ms a process).
os.environ.pop("PYTHONDONTWRITEBYTECODE", None)
ASSIGNMENT = ROOT / "grader" / "sample" / "assignment.yaml"


def load() -> float:
    return os.getloadavg()[0]


def roster(path: Path, students: int) -> Path:
    path.write_text("id,name,email,section\n" + "".join(f"s{i:05d},Student {i},s{i}@example.edu,L{i % 4}\n"
                                                        for i in range(students)), encoding="utf-8")
    return path


def export(base: str, into: Path) -> Path:
    """The package as it was at ``base``, unpacked into ``into``."""
    archive = subprocess.run(["git", "-C", str(ROOT), "archive", "--format=tar", base, "grader"], check=True,
                             capture_output=True).stdout
    with tarfile.open(fileobj=__import__("io").BytesIO(archive)) as tar:
        tar.extractall(into, filter="data")
    return into


def run_generate(tree: Path, cache: Path, roster_path: Path, out: Path) -> float:
    """Seconds for one whole ``grader generate --no-pdf`` with the package at ``tree``."""
    env = {**os.environ, "PYTHONPATH": str(tree), "GRADER_CACHE_DIR": str(cache)}
    started = time.perf_counter()
    subprocess.run([sys.executable, "-m", "grader", "generate", str(ASSIGNMENT), "--roster", str(roster_path),
                    "--out", str(out), "--no-pdf", "--force"], check=True, env=env, capture_output=True)
    return time.perf_counter() - started


def cost(runs: int, students: int, base: str, work: Path) -> list[str]:
    roster_path = roster(work / "roster.csv", students)
    trees = {"with bounds": ROOT, "without (base)": export(base, work / "base")}
    times: dict[str, list[float]] = {name: [] for name in trees}
    loads: list[float] = []
    for name, tree in trees.items():  # warm each cache: the first run of a template compiles it
        run_generate(tree, work / f"cache-{len(name)}", roster_path, work / "out")
    for index in range(runs):
        for name, tree in (trees.items() if index % 2 == 0 else reversed(list(trees.items()))):
            loads.append(load())
            times[name].append(run_generate(tree, work / f"cache-{len(name)}", roster_path, work / "out"))
            print(f"  run {index + 1} {name}: {times[name][-1]:.2f} s (load {loads[-1]:.2f})", flush=True)
    ours, theirs = statistics.median(times["with bounds"]), statistics.median(times["without (base)"])
    ratio = ours / theirs
    verdict = "met" if ratio <= 1.5 else "**not met**"
    return [
        "| what | size | with bounds | without (base) | ratio | load | target |",
        "| --- | --- | --: | --: | --: | --: | --- |",
        f"| `generate --no-pdf`, median of {runs} | {students:,} students x 5 | {ours:.2f} s | {theirs:.2f} s | "
        f"{ratio:.2f}x | {min(loads):.2f}-{max(loads):.2f} | <= 1.5x: {verdict} |",
        "",
        "All runs (s): with bounds " + ", ".join(f"{t:.2f}" for t in times["with bounds"]) + "; without "
        + ", ".join(f"{t:.2f}" for t in times["without (base)"]) + ".",
    ]


def share(students: int, work: Path) -> list[str]:
    """Three-figure and four-figure routes graded against the stored tolerance."""
    from grader.assign.assignment import load_assignment, load_roster
    from grader.assign.variants import generate
    from grader.bank.template import load_bank
    from grader.grade.compare import is_correct
    from grader.model.quantities import round_figures
    from grader.model.tolerance import ANSWER_SIG_FIGS
    from grader.solve.cache import routes_for
    from grader.solve.routes import walk_route

    bank = load_bank()
    generation = generate(load_assignment(ASSIGNMENT), load_roster(roster(work / "share.csv", students)), bank)
    outside: dict[int, Counter[str]] = {3: Counter(), 4: Counter()}
    total: Counter[str] = Counter()
    widened: Counter[str] = Counter()
    for index, variant in enumerate(generation.students[0].problems):
        template = bank[variant.template]
        routes = routes_for(template)
        variants = [s.problems[index] for s in generation.students]
        params = {name: np.array([v.params[name] for v in variants]) for name in variant.params}
        for position, part in enumerate(variant.answers):
            expected = np.array([v.answers[position].value if isinstance(v.answers[position].value, float)
                                 else np.nan for v in variants])
            tolerances = [v.answers[position].tolerance for v in variants]
            widened[f"{variant.template}.{part.name}"] += sum(bool(t.reason) for t in tolerances)
            for route in routes.for_answer(part.name):
                label = f"{variant.template}.{part.name} ({route.id})"
                defined = np.isfinite(expected)
                total[label] += int(defined.sum())
                for figures in (3, 4):
                    given = round_figures(walk_route(routes, route, params,
                                                     lambda _, v, f=figures: round_figures(v, f)), ANSWER_SIG_FIGS)
                    for tolerance in set(tolerances):
                        rows = defined & np.array([t == tolerance for t in tolerances])
                        right = is_correct(given[rows], expected[rows], tolerance,
                                           angle_unit="deg" if part.unit == "deg" else None)
                        outside[figures][label] += int((~right).sum())
    all3, all4, every = sum(outside[3].values()), sum(outside[4].values()), sum(total.values())
    lines = [f"{students:,} students x the sample's 5 problems: {every:,} (student, answer, route) evaluations.",
             "",
             f"- intermediates to 4 figures (as the sheet asks), answer to 3: **{all4} outside** the stored tolerance",
             f"- intermediates to 3 figures, answer to 3: **{all3:,} outside ({all3 / every:.1%})**",
             "",
             "| answer (route) | evaluations | 3 figures: outside | 4 figures: outside |",
             "| --- | --: | --: | --: |"]
    lines += [f"| {label} | {total[label]:,} | {outside[3][label]:,} ({outside[3][label] / total[label]:.1%}) | "
              f"{outside[4][label]} |" for label in total]
    lines += ["", "Variants with a widened tolerance, per answer: "
              + ", ".join(f"{name} {count:,}" for name, count in widened.items() if count) + "."]
    return lines


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--students", type=int, default=2000)
    parser.add_argument("--base", default="3c0bfaf", help="the commit without the bounds")
    args = parser.parse_args()
    started = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="grader-tolerance-") as folder:
        work = Path(folder)
        print("cost:", flush=True)
        timing = cost(args.runs, args.students, args.base, work)
        print("share:", flush=True)
        shares = share(args.students, work)
    text = "\n".join([
        "# Fair-tolerance benchmark", "",
        f"Python {platform.python_version()}, {os.cpu_count()} CPUs. `python benchmarks/tolerance.py --runs "
        f"{args.runs} --students {args.students} --base {args.base}`; whole commands from process start, with "
        "and without the bounds interleaved; load = the 1-minute load average before each run.", "",
        "## What the bounds cost", "", *timing, "",
        "## Routes with three-figure intermediates against the stored tolerance", "", *shares, "",
        f"Total benchmark time {time.perf_counter() - started:.0f} s.", ""])
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / "tolerance.md").write_text(text, encoding="utf-8")
    print(text)


if __name__ == "__main__":
    main()
