"""First-run benchmark: what a new user's first ``grader demo`` and first ``grader solve`` cost against their
second, as whole commands from process start, interleaved, with the machine's load printed beside them.

*First* is a new machine after the README's install: an empty cache folder (``GRADER_CACHE_DIR``) and none of
grader's own bytecode written yet (an editable install compiles none; every ``__pycache__`` below ``grader/``
is removed before each first run). *Warm* is the run right after it, in the same cache folder. Each round runs
the first and then the warm command, so both see the same machine. The shipped bank's compiled forms come
with the package (``grader/solve/shipped``), which is what makes the first run cheap; an instructor's own
template still pays for sympy once.

Targets (issue 21): the first ``grader demo`` within 1.3x a warm one; the first ``grader solve`` within 1.5x.

Run: ``python benchmarks/first_run.py [--rounds 5]``; it writes ``benchmarks/results/first_run.md``. Let the
machine be quiet (the load is printed with each figure).
"""

from __future__ import annotations

import argparse
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "benchmarks" / "results"
os.environ.pop("PYTHONDONTWRITEBYTECODE", None)  # a user's Python writes bytecode: the warm run has it
GRADER = [sys.executable, "-m", "grader"]
SOLVE = ["solve", "pile-driver", "--set", "m_ram=800", "--set", "m_pile=2400", "--set", "h_drop=2",
         "--set", "h_rebound=0.1"]
TARGETS = {"demo": 1.3, "solve": 1.5}


def forget_bytecode() -> None:
    """What a new clone has: none of grader's own modules compiled."""
    for folder in (ROOT / "grader").rglob("__pycache__"):
        shutil.rmtree(folder, ignore_errors=True)


def timed(command: list[str], env: dict[str, str], cwd: Path) -> float:
    """Seconds from process start to exit; the command must succeed."""
    start = time.perf_counter()
    subprocess.run(command, env=env, cwd=cwd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - start


def rounds(name: str, arguments: list[str], count: int) -> tuple[list[float], list[float], float]:
    """``count`` rounds of a first run then a warm one; the times, and the load after."""
    first, warm = [], []
    for _ in range(count):
        with tempfile.TemporaryDirectory(prefix=f"grader-first-{name}-") as folder:
            work = Path(folder)
            env = {**os.environ, "GRADER_CACHE_DIR": str(work / "cache")}
            extra = ["--out", "demo"] if name == "demo" else []
            forget_bytecode()
            first.append(timed([*GRADER, *arguments, *extra], env, work))
            again = ["--out", "demo2"] if name == "demo" else []
            warm.append(timed([*GRADER, *arguments, *again], env, work))
    return first, warm, os.getloadavg()[0]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("--rounds", type=int, default=5, help="rounds of first-then-warm (default 5)")
    arguments = parser.parse_args()
    if arguments.rounds < 1:
        parser.error("--rounds must be >= 1")
    start_load = os.getloadavg()
    began = time.perf_counter()
    rows = []
    for name, command in (("demo", ["demo"]), ("solve", SOLVE)):
        first, warm, load = rounds(name, command, arguments.rounds)
        ratio = statistics.median(first) / statistics.median(warm)
        target = TARGETS[name]
        verdict = "met" if ratio <= target else "**NOT met**"
        shown = "grader demo" if name == "demo" else "grader solve pile-driver ..."
        rows.append(f"| `{shown}` | {statistics.median(first):.2f} s | {statistics.median(warm):.2f} s "
                    f"| {ratio:.2f}x | <= {target}x: {verdict} | {load:.2f} |")
        print(rows[-1], flush=True)
    text = "\n".join([
        "# First-run benchmark", "",
        f"Python {platform.python_version()}, {os.cpu_count()} CPUs. `python benchmarks/first_run.py "
        f"--rounds {arguments.rounds}`; whole commands from process start, median of {arguments.rounds} rounds, "
        "each a first run (empty cache folder, none of grader's bytecode) then a warm one; load = the 1-minute "
        f"load average after each row (at the start: {', '.join(f'{x:.2f}' for x in start_load)}).", "",
        "| command | first run | warm run | first / warm | target | load |",
        "| --- | --: | --: | --: | --- | --: |", *rows, "",
        f"Total benchmark time {time.perf_counter() - began:.0f} s.", ""])
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / "first_run.md").write_text(text, encoding="utf-8")
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
