"""Generating benchmark: whole `grader generate` commands from process start, beside what a competent
user would do instead, interleaved, with the machine's load printed next to the figures.

- **Key only** (``--no-pdf``): 1,000, 2,000 and 10,000 students x the sample's 5 problems. Beside it,
  a minimal numpy script a competent user would write (written out by this benchmark, run the same
  way): the same SHA-256-keyed generator per student and problem, the same draws rounded as printed,
  the answers by functions ``sympy.lambdify`` made from the solver's own expressions (inlined as
  numpy code, so no sympy import at run time), key.json and key.csv with the same structure. It
  leaves out what grader does besides: redrawing degenerate variants, symbolic answers, collisions.
  Median of ``--runs``. Targets: 2,000 students in under 1 s; time per student at 10,000 at most
  1.2x that at 1,000 (linear).
- **With PDFs**, ``--jobs 2``: 200 and 1,000 students; seconds per student, the CPU time of the
  process tree per student (user + system: the machine's other work changes it little; on 2 idle
  cores the wall time is about half of it) and the tree's peak memory (``wait4``). Beside it at
  200 students: the same documents typeset whole with the ``typst`` package, as its user would (a
  document per sheet in 2 threads, the key as one document, the class file joined with pypdf): what
  grader did before the key was typeset in parts.
  Targets: at most 50 ms per student; peak memory at most 300 MiB, at 200 students and at 1,000.

Run: ``python benchmarks/generate.py [--runs 3] [--pdf 200,1000]``; it writes
``benchmarks/results/generate.md``. Let the machine be quiet (the load is printed with each figure).
"""

from __future__ import annotations

import argparse
import inspect
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "benchmarks" / "results"
# The commands run as an installed copy runs: Python writes bytecode (a sandbox that sets
# PYTHONDONTWRITEBYTECODE made every command compile grader from source, ~30 ms a process).
os.environ.pop("PYTHONDONTWRITEBYTECODE", None)
GRADER = [sys.executable, "-m", "grader"]
ASSIGNMENT = ROOT / "grader" / "sample" / "assignment.yaml"
KEY_SIZES = (1_000, 2_000, 10_000)

MINIMAL = '''
import csv, hashlib, json, sys
from functools import reduce
import numpy
from numpy import *

def sind(x):
    return numpy.sin(numpy.radians(x))

def cosd(x):
    return numpy.cos(numpy.radians(x))

hypot = numpy.hypot
TOLERANCE = {{"mode": "rtol", "rtol": 0.01, "atol": 0.0}}
{functions}
PLAN = {plan}

def printed(value, decimals, sig_figs):
    return f"{{value:.{{decimals}}f}}" if decimals is not None else repr(float(f"{{value:.{{sig_figs - 1}}e}}"))

def main(roster_path, out):
    with open(roster_path, encoding="utf-8", newline="") as stream:
        roster = list(csv.DictReader(stream))
    students = [{{"id": r["id"], "name": r["name"], "email": r["email"], "section": r["section"], "problems": []}}
                for r in roster]
    rows = []
    for problem in PLAN["problems"]:
        texts = {{p["name"]: [] for p in problem["params"]}}
        for r in roster:
            digest = hashlib.sha256("\\x1f".join((PLAN["seed"], problem["key"], r["id"])).encode()).digest()
            rng = numpy.random.Generator(numpy.random.PCG64(int.from_bytes(digest[:16], "big")))
            for p in problem["params"]:
                if p["kind"] == "choice":
                    value = float(rng.choice(p["values"]))
                elif p["kind"] == "log_uniform":
                    value = float(numpy.exp(rng.uniform(*numpy.log(p["values"]))))
                else:
                    value = float(rng.uniform(*p["values"]))
                texts[p["name"]].append(printed(value, p["decimals"], p["sig_figs"]))
        columns = {{name: numpy.array([float(t) for t in values]) for name, values in texts.items()}}
        values = {{a["name"]: numpy.broadcast_to(globals()[a["function"]](**{{n: columns[n] for n in a["args"]}}),
                                              (len(roster),)).tolist() for a in problem["answers"]}}
        for i, (student, r) in enumerate(zip(students, roster)):
            given = {{name: t[i] for name, t in texts.items()}}
            answers = {{}}
            for a in problem["answers"]:
                answers[a["name"]] = {{"value": values[a["name"]][i], "unit": a["unit"], "label": a["label"],
                                      "points": a["points"], "tolerance": TOLERANCE}}
                rows.append([r["id"], r["name"], r["section"], problem["key"], problem["template"], a["label"],
                             a["name"], values[a["name"]][i], a["unit"], a["points"], "1 %",
                             "; ".join(f"{{n}}={{t}}" for n, t in given.items())])
            student["problems"].append({{"key": problem["key"], "template": problem["template"],
                                        "params": {{n: float(t) for n, t in given.items()}}, "printed": given,
                                        "answers": answers}})
    with open(out + "/key.json", "w", encoding="utf-8") as stream:
        json.dump({{"schema": "minimal", "students": students}}, stream, ensure_ascii=False)
    with open(out + "/key.csv", "w", encoding="utf-8", newline="") as stream:
        writer = csv.writer(stream)
        writer.writerow(["student_id", "name", "section", "problem", "template", "label", "answer", "value", "unit",
                         "points", "tolerance", "parameters"])
        writer.writerows(rows)

main(sys.argv[1], sys.argv[2])
'''

WHOLE = '''
import concurrent.futures, sys
from pathlib import Path
from pypdf import PdfWriter
from grader.assign.assignment import load_assignment, load_roster
from grader.assign.variants import generate
from grader.bank.template import load_bank
from grader.render import documents as D
from grader.render.typeset import compile_typst, font_paths, one_pdf

assignment, roster, out = load_assignment(Path(sys.argv[1])), load_roster(Path(sys.argv[2])), Path(sys.argv[3])
generation = generate(assignment, roster, load_bank())
documents, fonts, everyone = D.Documents(assignment, generation, load_bank()), font_paths(), range(len(roster))
(out / "students").mkdir(parents=True)
sheets = [(out / "students" / f"{s.student.id}.pdf", D.student_source(documents, [i]))
          for i, s in enumerate(generation.students)]
with concurrent.futures.ThreadPoolExecutor(2) as pool:
    list(pool.map(lambda job: job[0].write_bytes(one_pdf(compile_typst(job[1], fonts=fonts))), sheets))
key = D.key_source(documents, cover=D.cover(documents, []), people=everyone,
                   glances=[documents.glance(p, everyone, "", False) for p in range(len(assignment.problems))])
(out / "answer-key.pdf").write_bytes(one_pdf(compile_typst(key, tagged=False, fonts=fonts)))
writer = PdfWriter()
for path, _ in sheets:
    writer.append(str(path))
with open(out / "class.pdf", "wb") as stream:
    writer.write(stream)
'''


def load() -> str:
    """The machine's load averages over 1, 5 and 15 minutes."""
    return "/".join(f"{x:.2f}" for x in os.getloadavg())


def roster(count: int, folder: Path) -> Path:
    """A synthetic roster of ``count`` students (columns id, name, email, section)."""
    path = folder / f"roster-{count}.csv"
    lines = ["id,name,email,section"] + [f"{9000000 + i},Student {i},s{i}@example.edu,L0{i % 4}" for i in range(count)]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def minimal_script(folder: Path) -> Path:
    """The competent user's script: the sample assignment's draws and the solver's answer
    expressions as numpy functions (made by ``sympy.lambdify`` here, before any timing)."""
    import numpy as np
    import sympy

    from grader.assign.assignment import load_assignment
    from grader.bank.template import load_bank
    from grader.physics.symbolic import from_node
    from grader.solve.cache import compiled_for

    degrees = {"sind": lambda x: np.sin(np.radians(x)), "cosd": lambda x: np.cos(np.radians(x)), "hypot": np.hypot}
    assignment, bank = load_assignment(ASSIGNMENT), load_bank()
    functions, problems = [], []
    for problem in assignment.problems:
        template = bank[problem.template]
        compiled = compiled_for(template)
        params = []
        for name, parameter in template.parameters.items():
            kind, values = parameter.sample.kind, list(problem.narrowed.get(name) or parameter.sample.values)
            if name in problem.fixed:
                kind, values = "choice", [problem.fixed[name]]
            params.append({"name": name, "kind": kind, "values": values, "decimals": parameter.decimals,
                           "sig_figs": parameter.sig_figs})
        answers = []
        for index, (name, answer) in enumerate(compiled.answers.items()):
            if answer.numeric is None:
                continue  # a symbolic answer: its text is left out
            expression = from_node(answer.numeric, {})
            expression = expression.subs({s: compiled.constants[str(s)] for s in expression.free_symbols
                                          if str(s) in compiled.constants})
            args = sorted(str(s) for s in expression.free_symbols)
            made = sympy.lambdify([sympy.Symbol(a, real=True) for a in args], expression, modules=[degrees, "numpy"])
            function = f"answer_{len(functions)}"
            functions.append(inspect.getsource(made).replace("_lambdifygenerated", function))
            answers.append({"name": name, "function": function, "args": args, "unit": template.answers[name].unit.text,
                            "label": f"{problem.key}{chr(ord('a') + index)}",
                            "points": problem.points.get(name, problem.points.get("*", 1.0))})
        problems.append({"key": problem.key, "template": template.id, "params": params, "answers": answers})
    plan = {"seed": assignment.seed, "problems": problems}
    path = folder / "minimal.py"
    path.write_text(MINIMAL.format(functions="\n".join(functions), plan=repr(plan)), encoding="utf-8")
    return path


def timed(command: Sequence[str]) -> tuple[float, float, float]:
    """Wall time from process start, the peak memory (MiB) of the process tree, and its CPU time
    (user + system: what the machine's other work does not change much)."""
    started = time.perf_counter()
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(process.pid, 0)
    seconds = time.perf_counter() - started
    if status != 0:
        raise SystemExit(f"{' '.join(map(str, command))} failed:\n{process.stderr.read().decode()}")  # type: ignore[union-attr]
    return seconds, usage.ru_maxrss / 1024, usage.ru_utime + usage.ru_stime  # Linux: kB


def key_rows(folder: Path, runs: int) -> list[dict[str, object]]:
    script = minimal_script(folder)
    subprocess.run([*GRADER, "generate", str(ASSIGNMENT), "--roster", str(roster(30, folder)), "--out",
                    str(folder / "warm"), "--no-pdf"], check=True, capture_output=True)  # compiled templates cached
    rows = []
    for count in KEY_SIZES:
        path = roster(count, folder)
        ours, cpu, theirs, loads = [], [], [], []
        for run in range(runs):  # interleaved: the machine's state affects both alike
            loads.append(os.getloadavg()[0])
            out = folder / f"min-{count}-{run}"
            out.mkdir()
            theirs.append(timed([sys.executable, str(script), str(path), str(out)])[0])
            seconds, _, used = timed([*GRADER, "generate", str(ASSIGNMENT), "--roster", str(path), "--out",
                                      str(folder / f"key-{count}-{run}"), "--no-pdf"])
            ours.append(seconds)
            cpu.append(used)
        rows.append({"students": count, "ours": statistics.median(ours), "cpu": statistics.median(cpu),
                     "theirs": statistics.median(theirs), "load": max(loads)})
    return rows


def pdf_rows(folder: Path, sizes: Sequence[int]) -> list[dict[str, object]]:
    rows = []
    (folder / "whole.py").write_text(WHOLE, encoding="utf-8")
    for count in sizes:
        path = roster(count, folder)
        row: dict[str, object] = {"students": count}
        if count == min(sizes):  # typeset whole: about 2 GiB at 200 students, 9 GiB at 1,000
            row["theirs"], row["theirs_mib"], row["theirs_cpu"] = timed(
                [sys.executable, str(folder / "whole.py"), str(ASSIGNMENT), str(path), str(folder / f"whole-{count}")])
        row["load"] = os.getloadavg()[0]
        row["ours"], row["ours_mib"], row["ours_cpu"] = timed(
            [*GRADER, "generate", str(ASSIGNMENT), "--roster", str(path), "--out", str(folder / f"pdf-{count}"),
             "--jobs", "2"])
        rows.append(row)
    return rows


def report(keys: list[dict[str, object]], pdfs: list[dict[str, object]], command: str, seconds: float) -> str:
    per = {row["students"]: float(row["ours"]) / int(row["students"]) for row in keys}  # type: ignore[arg-type]
    lines = [
        "# Generate benchmark", "",
        f"Python {platform.python_version()}, {os.cpu_count()} CPUs. `{command}`; whole commands from process "
        "start; baseline and grader interleaved; load = the 1-minute load average when the figure was taken.", "",
        "| what | size | grader | baseline | ratio | load | target |", "| --- | --- | --: | --: | --: | --: | --- |",
    ]
    for row in keys:
        count, ours, theirs = int(row["students"]), float(row["ours"]), float(row["theirs"])  # type: ignore[arg-type]
        target = f"< 1 s: {'met' if ours < 1 else '**not met**'}" if count == 2000 else ""
        lines.append(f"| `generate --no-pdf` vs minimal numpy script | {count:,} students x 5 | {ours:.2f} s "
                     f"({ours / count * 1e3:.3f} ms/student; CPU {float(row['cpu']):.2f} s) | {theirs:.2f} s | "  # type: ignore[arg-type]
                     f"{ours / theirs:.2f}x | "
                     f"{float(row['load']):.2f} | {target} |")  # type: ignore[arg-type]
    linear = per[max(per)] / per[min(per)]
    lines.append(f"| time per student, {max(per):,} vs {min(per):,} students | | {linear:.2f}x | | | | "
                 f"<= 1.2x: {'met' if linear <= 1.2 else '**not met**'} |")
    for row in pdfs:
        count, ours, mib = int(row["students"]), float(row["ours"]), float(row["ours_mib"])  # type: ignore[arg-type]
        baseline = _pdf_cell(float(row["theirs"]), float(row["theirs_cpu"]), count) \
            if "theirs" in row else "not run (it needs about 9 MiB a student)"  # type: ignore[arg-type]
        ratio = f"{ours / float(row['theirs']):.2f}x" if "theirs" in row else ""  # type: ignore[arg-type]
        met = "met" if ours / count <= 0.05 else "**not met**"
        lines.append(f"| `generate --jobs 2` with PDFs vs typeset whole | {count:,} students | "
                     f"{_pdf_cell(ours, float(row['ours_cpu']), count)} | {baseline} | {ratio} | "  # type: ignore[arg-type]
                     f"{float(row['load']):.2f} | <= 50 ms/student: {met} |")
        their_mib = f"{float(row['theirs_mib']):,.0f} MiB" if "theirs_mib" in row else ""  # type: ignore[arg-type]
        lines.append(f"| peak memory of the process tree | {count:,} students | {mib:,.0f} MiB | {their_mib} | | | "
                     f"<= 300 MiB: {'met' if mib <= 300 else '**not met**'} |")
    lines += ["", f"Total benchmark time {seconds:.0f} s."]
    return "\n".join(lines) + "\n"


def _pdf_cell(seconds: float, cpu: float, count: int) -> str:
    return f"{seconds:.2f} s ({seconds / count * 1e3:.0f} ms/student; CPU {cpu / count * 1e3:.0f} ms/student)"


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("--runs", type=int, default=3, help="runs of each key-only command (median)")
    parser.add_argument("--pdf", default="200,1000", help="class sizes for the runs with PDFs")
    arguments = parser.parse_args(argv)
    started = time.perf_counter()
    print(f"load before: {load()}", file=sys.stderr)
    with tempfile.TemporaryDirectory() as scratch:
        keys = key_rows(Path(scratch), arguments.runs)
        pdfs = pdf_rows(Path(scratch), [int(n) for n in arguments.pdf.split(",")])
    command = "python benchmarks/generate.py" + "".join(f" {a}" for a in (argv if argv is not None else sys.argv[1:]))
    text = report(keys, pdfs, command, time.perf_counter() - started)
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "generate.md").write_text(text, encoding="utf-8")
    print(text)
    print(f"load after: {load()}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
