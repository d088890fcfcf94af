"""A million students on one machine (issue 29, target 2): whole ``grader generate --no-pdf`` and ``grader grade``
commands from process start, at growing class sizes, each with its wall time, CPU time (user + system) and the
peak memory of its process tree (``wait4``'s ``ru_maxrss``), the machine's load printed beside them.

- **generate**: the sample assignment (5 problems, 11 answer parts a student) for a synthetic roster of each size
  given with ``--generate``. Targets: peak memory at most 4 GiB at 1,000,000 students; time per student at
  1,000,000 at most 1.2x that at 100,000 (linear).
- **grade**: each size given with ``--grade`` (it must also be a ``--generate`` size, whose key it grades), the
  submissions made from that run's key.csv a row at a time (nine numbers in ten right, one in ten 7 % off, every
  student one row per part), split into files of at most ``CSV_BYTES`` as ``grade``'s refusal of a larger file
  tells a user to. A key over what ``grade`` reads without its sidecar (``KEY_BYTES``) is not run: the row says
  it is refused, and why.

Run: ``python benchmarks/million.py [--generate 10000,100000,1000000] [--grade 10000,100000] [--folder DIR]``; it writes
``benchmarks/results/million.md``. The folder (default: a temporary one, removed at the end) needs about 5 GB a
million students. Let the machine be quiet: one run, not interleaved (the baseline of a million students is the
same command at a tenth of the size).
"""

from __future__ import annotations

import argparse
import csv
import os
import platform
import random
import shutil
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from pathlib import Path

from generate import load, timed  # the same clock and load as generate.py's

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "benchmarks" / "results"
GRADER = [sys.executable, "-m", "grader"]
ASSIGNMENT = ROOT / "grader" / "sample" / "assignment.yaml"
GIB = 1024.0


def roster(count: int, folder: Path) -> Path:
    """A synthetic roster of ``count`` students (columns id, name, email, section), written a line at a time."""
    path = folder / f"roster-{count}.csv"
    with open(path, "w", encoding="utf-8", newline="") as stream:
        stream.write("id,name,email,section\n")
        for i in range(count):
            stream.write(f"{9000000 + i},Student {i},s{i}@example.edu,L0{i % 4}\n")
    return path


def submissions(key_csv: Path, path: Path, rng: random.Random) -> int:
    """Answers for every row of a key.csv (nine numbers in ten its value, one in ten 7 % off; expressions as
    written), read and written a row at a time; returns how many cells."""
    cells = 0
    with open(key_csv, encoding="utf-8", newline="") as source, open(path, "w", encoding="utf-8", newline="") as out:
        writer = csv.writer(out, lineterminator="\n")
        writer.writerow(["student_id", "label", "answer"])
        for row in csv.DictReader(source):
            answer = row["value"]  # an expression (a ratio in symbols) is answered as the key writes it
            if _number(answer) and rng.random() >= 0.9:
                answer = repr(float(answer) * 1.07)
            writer.writerow([row["student_id"], row["label"], answer])
            cells += 1
    return cells


def pieces(path: Path, limit: int) -> list[Path]:
    """The submissions file split as a user would split it when ``grade`` refuses it for its size (the refusal
    says so): files of at most ``limit`` bytes, each with the header, a student's rows kept together (key.csv is
    in the key's order, so a student's rows are next to each other); ``path`` itself when it is small enough."""
    if path.stat().st_size <= limit:
        return [path]
    written: list[Path] = []
    header = ""
    piece: list[str] = []  # the lines of the file being filled, then of the student being read
    student: list[str] = []
    size = 0

    def student_ends() -> None:
        nonlocal piece, size
        more = sum(len(line.encode()) for line in student)
        if size + more > limit and len(piece) > 1:
            written.append(_piece(path, len(written), piece))
            piece, size = [header], len(header.encode())
        piece += student
        size += more
        student.clear()

    with open(path, encoding="utf-8", newline="") as source:
        header = source.readline()
        piece, size = [header], len(header.encode())
        for line in source:
            if student and line.split(",", 1)[0] != student[0].split(",", 1)[0]:
                student_ends()
            student.append(line)
        student_ends()
    written.append(_piece(path, len(written), piece))
    path.unlink()
    return written


def _piece(path: Path, number: int, lines: list[str]) -> Path:
    piece = path.with_name(f"{path.stem}-{number + 1:02d}{path.suffix}")
    piece.write_text("".join(lines), encoding="utf-8", newline="")
    return piece


def _number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def refusal(key: Path) -> str | None:
    """Why ``grade`` would refuse this key for its size, or None (submissions are split into files it reads,
    :func:`pieces`)."""
    from grader.assign.key_columns import sidecar
    from grader.grade.key import KEY_BYTES

    if key.stat().st_size > KEY_BYTES and not sidecar(key).is_file():  # with its sidecar, a key has no limit
        return f"refused: key.json is {key.stat().st_size / 2**30:.2f} GiB, over KEY_BYTES ({KEY_BYTES >> 20} MiB), " \
               "and has no key.columns.npz"
    return None


def measure(sizes: Sequence[int], graded: Sequence[int], folder: Path,
            done: Callable[[list[dict[str, object]]], None]) -> list[dict[str, object]]:
    """The rows, each handed to ``done`` with those before it as it is measured (a run stopped part way keeps
    what it measured)."""
    rows: list[dict[str, object]] = []
    subprocess.run([*GRADER, "generate", str(ASSIGNMENT), "--roster", str(roster(30, folder)), "--out",
                    str(folder / "warm"), "--no-pdf"], check=True, capture_output=True)  # compiled templates cached
    for size in sizes:
        out = folder / f"hw-{size}"
        seconds, peak, cpu = timed([*GRADER, "generate", str(ASSIGNMENT), "--roster", str(roster(size, folder)),
                                    "--out", str(out), "--no-pdf"])
        rows.append({"what": "`generate --no-pdf`", "size": size, "seconds": seconds, "cpu": cpu, "peak": peak,
                     "load": load(), "bytes": (out / "key.json").stat().st_size})
        done(rows)
        if size in graded:
            from grader.base.inputs import CSV_BYTES

            cells = submissions(out / "key.csv", folder / f"answers-{size}.csv", random.Random(7))
            answers = pieces(folder / f"answers-{size}.csv", CSV_BYTES)
            why = refusal(out / "key.json")
            if why is None:
                seconds, peak, cpu = timed([*GRADER, "grade", "--key", str(out / "key.json"), *map(str, answers),
                                            "--out", str(folder / f"graded-{size}")])
                rows.append({"what": f"`grade` ({cells:,} cells)", "size": size, "seconds": seconds, "cpu": cpu,
                             "peak": peak, "load": load()})
            else:
                rows.append({"what": f"`grade` ({cells:,} cells)", "size": size, "refused": why, "load": load()})
            done(rows)
            shutil.rmtree(folder / f"graded-{size}", ignore_errors=True)
            for piece in answers:
                piece.unlink()
        shutil.rmtree(out)
    return rows


def _cell(row: dict[str, object]) -> str:
    if "refused" in row:
        return str(row["refused"])
    seconds, size = float(row["seconds"]), int(row["size"])  # type: ignore[arg-type]
    return f"{seconds:.1f} s ({seconds / size * 1e3:.3f} ms/student; CPU {float(row['cpu']):.1f} s)"  # type: ignore[arg-type]


def _peak(row: dict[str, object]) -> str:
    return "" if "peak" not in row else f"{float(row['peak']):,.0f} MiB"  # type: ignore[arg-type]


def table(rows: Sequence[dict[str, object]], command: str, started: str, total: float) -> str:
    lines = ["# A million students on one machine", "",
             f"Python {platform.python_version()}, {os.cpu_count()} CPUs. `{command}`; whole commands from process "
             f"start, one run each (not interleaved); peak = the process tree's peak memory (`wait4`); load = the "
             f"1-, 5- and 15-minute load averages as each command ended (at the start: {started}).", "",
             "| command | students | time | peak memory | key.json | load |", "| --- | --: | --: | --: | --: | --- |"]
    for row in rows:
        size = f"{row['bytes'] / 2**20:,.0f} MiB" if "bytes" in row else ""  # type: ignore[operator]
        lines.append(f"| {row['what']} | {int(row['size']):,} | {_cell(row)} | {_peak(row)} | {size} | "  # type: ignore[call-overload]
                     f"{row['load']} |")
    lines += ["", *targets(rows), "", f"Total benchmark time {total:.0f} s.", ""]
    return "\n".join(lines)


def targets(rows: Sequence[dict[str, object]]) -> list[str]:
    """The target lines: peak memory at 1,000,000 students, and the time per student there against 100,000."""
    generated = {int(r["size"]): r for r in rows if r["what"] == "`generate --no-pdf`"}  # type: ignore[call-overload]
    found = []
    if 1_000_000 in generated:
        peak = float(generated[1_000_000]["peak"]) / GIB  # type: ignore[arg-type]
        found.append(f"- `generate --no-pdf`, 1,000,000 students: peak {peak:.2f} GiB (target at most 4 GiB: "
                     f"{'met' if peak <= 4 else '**not met**'}).")
        if 100_000 in generated:
            big, small = generated[1_000_000], generated[100_000]
            wall, cpu = (float(big[k]) / float(small[k]) / 10 for k in ("seconds", "cpu"))  # type: ignore[arg-type]
            found.append(f"- time per student at 1,000,000 / at 100,000: {wall:.2f}x wall, {cpu:.2f}x CPU (target at "
                         f"most 1.2x: {'met' if wall <= 1.2 else '**not met**'} in wall time; on a loaded machine "
                         "read the CPU).")
    return found


def main(argv: Sequence[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--generate", default="10000,100000,1000000", help="class sizes to generate (comma-separated)")
    parser.add_argument("--grade", default="10000,100000", help="of those, the sizes to grade too")
    parser.add_argument("--folder", type=Path, help="where the files go (default: a temporary folder)")
    parser.add_argument("--out", type=Path, default=RESULTS / "million.md")
    arguments = parser.parse_args(argv)
    sizes = [int(n) for n in arguments.generate.split(",") if n]
    graded = [int(n) for n in arguments.grade.split(",") if n]
    started, begun = load(), time.perf_counter()
    command = ("python benchmarks/million.py " + " ".join(sys.argv[1:] if argv is None else argv)).strip()

    def done(rows: list[dict[str, object]]) -> None:
        print(rows[-1], flush=True)
        arguments.out.write_text(table(rows, command, started, time.perf_counter() - begun), encoding="utf-8")

    with tempfile.TemporaryDirectory(dir=arguments.folder) as folder:
        rows = measure(sizes, graded, Path(folder), done)
    print(table(rows, command, started, time.perf_counter() - begun))


if __name__ == "__main__":
    main()
