"""The integrity check's time as the class grows (issue 29, target 2): linear, not the square of the class.

For each size, a key (``grader generate --no-pdf`` of the sample assignment) and submissions as
``benchmarks/million.py`` makes them (one number in ten 7 % off; nearly every student shares problem 2's numbers
with others, so a wrong answer lands in many bands), graded once in process; then the check alone, with the close
search (:mod:`grader.grade.integrity_close`) and with the band search alone (``CLOSE = False``, as before it),
alternated, CPU and wall time of each, and whether the two found the same (they must). ``--band-until`` leaves
the band search out above that size (it grows as the square). The check runs with the cycle collector paused, as
``grader grade`` runs it; submissions over what ``grade`` reads in one file are split into files under it, as
its refusal says to.

Run: ``python benchmarks/integrity_scale.py [--sizes 20000,100000] [--runs 2] [--folder DIR]``; it writes
``benchmarks/results/integrity-scale.md``.
"""

from __future__ import annotations

import argparse
import os
import platform
import random
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))
RESULTS = ROOT / "benchmarks" / "results"


def inputs(folder: Path, size: int) -> Path:
    """The key and submissions of ``size`` students in ``folder``; returns the folder."""
    import million

    out = folder / f"class-{size}"
    if not (out / "answers.csv").exists() and not (out / "answers-1.csv").exists():
        out.mkdir(parents=True, exist_ok=True)
        subprocess.run([sys.executable, "-m", "grader", "generate", str(million.ASSIGNMENT), "--roster",
                        str(million.roster(size, out)), "--out", str(out / "hw"), "--no-pdf"], check=True,
                       capture_output=True)
        million.submissions(out / "hw" / "key.csv", out / "answers.csv", random.Random(7))
        pieces(out / "answers.csv")
    return out


def pieces(path: Path) -> list[Path]:
    """The submissions file, or, over what ``grade`` reads in one file, its rows split into files under that
    (``answers-1.csv``, ...; the whole file removed)."""
    from grader.grade.submissions import SUBMISSIONS_BYTES

    if path.exists() and path.stat().st_size <= SUBMISSIONS_BYTES:
        return [path]
    if path.exists():
        count, lines, size = 0, [], 0
        with open(path, encoding="utf-8", newline="") as source:
            header = source.readline()
            for line in [*source, None]:
                if line is None or (size + len(line.encode()) > SUBMISSIONS_BYTES - 1024 and lines):
                    count += 1
                    path.with_name(f"answers-{count}.csv").write_text(header + "".join(lines), encoding="utf-8")
                    lines, size = [], 0
                if line is not None:
                    lines.append(line)
                    size += len(line.encode())
        path.unlink()
    return sorted(path.parent.glob("answers-*.csv"), key=lambda piece: int(piece.stem.split("-")[1]))


def measure(folder: Path, runs: int, band: bool) -> dict[str, object]:
    """Grade once, then time the check ``runs`` times with each search, alternated."""
    from grader.bank.template import load_bank
    from grader.base.heap import collector_paused
    from grader.grade import integrity_close
    from grader.grade.integrity import check
    from grader.grade.key import load_key
    from grader.grade.run import _graded

    with collector_paused():
        graded = _graded(load_key(folder / "hw" / "key.json"), pieces(folder / "answers.csv"), "auto", (), load_bank())
    times: dict[bool, list[tuple[float, float]]] = {True: [], False: []}
    found = {}
    for _ in range(runs):
        for close in (True, False) if band else (True,):
            integrity_close.CLOSE = close
            cpu, wall = time.process_time(), time.perf_counter()
            with collector_paused():  # as grader grade runs it
                found[close] = check(graded)
            times[close].append((time.process_time() - cpu, time.perf_counter() - wall))
    integrity_close.CLOSE = True
    result = found[True]
    return {"students": len(graded.key.students), "close": min(times[True]), "band": min(times[False], default=None),
            "same": found[True] == found[False] if band else None, "pairs": len(result.ranked),
            "flagged": len(result.flagged), "peak": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
            "load": "/".join(f"{x:.2f}" for x in os.getloadavg())}


def table(rows: list[dict[str, object]], command: str) -> str:
    lines = ["# Integrity check at scale", "",
             f"Python {platform.python_version()}, {os.cpu_count()} CPUs. `{command}`; the least of the runs, CPU "
             "seconds (wall in brackets); per student in µs of CPU.", "",
             "| students | close search | per student | band search alone | per student | same findings | pairs "
             "| peak | load |", "| --: | --: | --: | --: | --: | --- | --: | --: | --- |"]
    for row in rows:
        close, band, size = row["close"], row["band"], int(row["students"])  # type: ignore[call-overload]
        assert isinstance(close, tuple)
        band_cells = (f"{band[0]:.2f} s ({band[1]:.2f} s) | {1e6 * band[0] / size:.0f}" if isinstance(band, tuple)
                      else "not run | ")
        lines.append(f"| {size:,} | {close[0]:.2f} s ({close[1]:.2f} s) | {1e6 * close[0] / size:.0f} | {band_cells} "
                     f"| {row['same'] if row['same'] is not None else ''} | {row['pairs']:,} | "
                     f"{row['peak']:.0f} MiB | {row['load']} |")
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="20000,100000")
    parser.add_argument("--runs", type=int, default=2)
    parser.add_argument("--band-until", type=int, default=100_000)
    parser.add_argument("--folder", type=Path)
    parser.add_argument("--out", type=Path, default=RESULTS / "integrity-scale.md")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        folder = args.folder or Path(tmp)
        rows = []
        for size in (int(text) for text in args.sizes.split(",")):
            # Each size in its own process: the peak memory is that size's.
            code = ("import sys, json, pathlib; sys.path.insert(0, 'benchmarks'); import integrity_scale as s; "
                    f"print(json.dumps(s.measure(pathlib.Path({str(inputs(folder, size))!r}), {args.runs}, "
                    f"{size <= args.band_until})))")
            done = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True, cwd=ROOT)
            import json
            row = json.loads(done.stdout.splitlines()[-1])
            row["close"] = tuple(row["close"])
            row["band"] = tuple(row["band"]) if row["band"] else None
            rows.append(row)
            print(row, flush=True)
    text = table(rows, "python benchmarks/integrity_scale.py " + " ".join(sys.argv[1:]))
    print(text)
    args.out.write_text(text, encoding="utf-8")


if __name__ == "__main__":
    main()
