"""Benchmark: the solver's kernels and commands, each against what a competent user would use instead.

Three parts, each timed with its baseline interleaved in one run, and each printed with the machine's
load average (``os.getloadavg()``) measured beside it:

1. **Kernels**, per template of the shipped bank, at each of ``--sets`` sizes (default 100,000 and
   2,000 parameter sets, where a call's fixed cost counts), sets drawn from the parameters' sampling
   specs: :class:`grader.model.kernel.Kernel` over the template's numeric answers against
   ``sympy.lambdify(symbols, answers, "numpy")`` of the same expressions (the target: at least as fast,
   at every size), and with ``cse=True``; both get grader's own ``sind``, ``cosd`` and numpy's ``hypot``
   (the expressions use them). Best of ``--rounds`` interleaved rounds (on short columns each round
   times several calls). Context: the tree walk (:func:`grader.model.kernel.evaluate` on each tree, as
   the kernels were before), ``solve_columns`` (checks and answers) and ``expr.subs(values).evalf()``
   one set at a time on ``--baseline-sets`` sets, extrapolated. lambdify's and subs' values must agree
   with the kernel's to 1e-9.
2. **``grader solve ID --batch FILE.csv --json``** against ``benchmarks/minimal_solve.py`` (numpy.loadtxt,
   the closed form in numpy, ``json.dumps`` per row), for every template the minimal script covers, on the
   same CSV of ``--batch-rows`` rows printed as a sheet prints them (draws grader refuses, or where an
   answer is undefined, are left out: the minimal script has no checks): whole processes from start,
   interleaved, median of ``--runs``; the two outputs must be the same JSON lines (values to 1e-9).
3. **Start-up**: ``grader --help``, ``grader list`` and a warm ``grader solve pile-driver ...`` against
   ``python -c "import numpy, yaml"``, interleaved, median of ``--startup-runs``; one cold solve (empty
   compile cache) for context. Warm is a user's second run: each command is run once, untimed, before the
   rounds, with Python writing bytecode as it does by default (``PYTHONDONTWRITEBYTECODE`` is cleared for
   these runs: with it set, every run compiled grader's modules from source, which no installed copy does,
   while numpy's and PyYAML's bytecode came with their wheels).

Run: ``python benchmarks/solve.py [--sets 100000 2000] [--quick]``. Writes ``benchmarks/results/solve.md``,
``solve.csv``, ``solve_batch.csv``, ``solve_startup.csv`` and, with matplotlib, ``solve.png``.
``--only startup`` (or ``kernels``: part 1) measures that part alone, as the whole run measures it, and
prints its table (the result files are left as they are).
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict, dataclass
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np
import sympy as sp
from minimal_solve import UNITS

from grader.bank.template import Parameter, Template, load_bank
from grader.model import kernel
from grader.model.kernel import Kernel, evaluate
from grader.physics import symbolic
from grader.physics.symbolic import from_node
from grader.solve.cache import compiled_for
from grader.solve.compiled import Compiled
from grader.solve.evaluate import solve_columns

HERE = Path(__file__).resolve().parent
RESULTS = HERE / "results"
# The commands run as an installed copy runs: Python writes bytecode (a sandbox that sets
# PYTHONDONTWRITEBYTECODE made every command compile grader from source, ~30 ms a process).
os.environ.pop("PYTHONDONTWRITEBYTECODE", None)
MINIMAL = HERE / "minimal_solve.py"
AGREEMENT_RTOL = 1e-9
TARGET_LAMBDIFY = 1.0  # kernels at least as fast as lambdify
TARGET_RATE = 1e6  # kernels: parameter sets per second
TARGET_SUBS = 1e3  # kernels against subs().evalf() one set at a time (context)
TARGET_BATCH = 1.5  # solve --batch --json within 1.5x of the minimal script
TARGET_STARTUP = 2.0  # warm start-up within 2x of python -c "import numpy, yaml"
SOLVE_ARGS = ("solve", "pile-driver", "--set", "m_ram=800", "--set", "m_pile=2400", "--set", "h_drop=2",
              "--set", "h_rebound=0.1")
LAMBDIFY_MODULES = [{"sind": kernel.sind, "cosd": kernel.cosd, "hypot": np.hypot}, "numpy"]


@dataclass(frozen=True)
class KernelRow:
    """One template's kernel timings (seconds for all sets) and agreement."""

    template: str
    answers: int
    steps: int
    sets: int
    kernel_s: float
    lambdify_s: float
    lambdify_cse_s: float
    tree_walk_s: float
    columns_s: float
    subs_s_per_set: float
    baseline_sets: int
    max_rel_diff: float
    load: float

    @property
    def vs_lambdify(self) -> float:
        """How many times faster than lambdify (>= 1 is the target)."""
        return self.lambdify_s / self.kernel_s

    @property
    def vs_subs(self) -> float:
        """How many times faster than subs().evalf() per set (context)."""
        return self.subs_s_per_set * self.sets / self.kernel_s


@dataclass(frozen=True)
class BatchRow:
    """One template's whole-command times: grader solve --batch --json and the minimal script."""

    template: str
    rows: int
    grader_s: float
    minimal_s: float
    grader_runs: tuple[float, ...]
    minimal_runs: tuple[float, ...]
    load: float

    @property
    def ratio(self) -> float:
        """grader's time over the minimal script's (<= 1.5 is the target)."""
        return self.grader_s / self.minimal_s


@dataclass(frozen=True)
class StartupRow:
    """One command's median wall time from process start, beside the baseline's in the same rounds."""

    command: str
    seconds: float
    runs: tuple[float, ...]
    load: float


def parse_args(argv: Sequence[str] | None = None) -> argparse.Namespace:
    """The command-line options."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("--sets", type=int, nargs="+", default=[100_000, 2_000],
                        help="parameter sets per template, one or more sizes (default 100000 2000)")
    parser.add_argument("--rounds", type=int, default=25, help="kernel timings: best of this many interleaved "
                                                              "rounds (default 25)")
    parser.add_argument("--baseline-sets", type=int, default=200,
                        help="sets evaluated with subs().evalf() (default 200)")
    parser.add_argument("--batch-rows", type=int, default=100_000, help="rows of the batch CSV (default 100000)")
    parser.add_argument("--runs", type=int, default=5, help="batch commands: median of this many (default 5)")
    parser.add_argument("--startup-runs", type=int, default=15, help="start-up: median of this many (default 15)")
    parser.add_argument("--quick", action="store_true", help="a smoke run: few sets, rows and runs")
    parser.add_argument("--only", choices=("startup", "kernels"), help="measure this part alone and print its "
                        "table (the result files are not written)")
    parser.add_argument("--seed", type=int, default=20240601, help="numpy random seed (default 20240601)")
    parser.add_argument("--out", type=Path, default=RESULTS, help=f"output folder (default {RESULTS})")
    arguments = parser.parse_args(argv)
    if arguments.quick:
        arguments.sets, arguments.rounds, arguments.baseline_sets = [5_000, 200], 3, 5
        arguments.batch_rows, arguments.runs, arguments.startup_runs = 2_000, 1, 3
    if min(*arguments.sets, arguments.rounds, arguments.baseline_sets, arguments.batch_rows, arguments.runs,
           arguments.startup_runs) < 1 or arguments.baseline_sets > min(arguments.sets):
        parser.error("every count must be >= 1, and --baseline-sets <= --sets")
    return arguments


def load() -> float:
    """The machine's 1-minute load average."""
    return os.getloadavg()[0]


# --- 1. kernels ----------------------------------------------------------------------------------

def sample_column(parameter: Parameter, count: int, rng: np.random.Generator) -> np.ndarray:
    """``count`` draws of one parameter from its sampling spec, kept inside its domain."""
    kind, values = parameter.sample.kind, parameter.sample.values
    if kind == "uniform":
        column = rng.uniform(values[0], values[1], count)
    elif kind == "log_uniform":
        column = np.exp(rng.uniform(np.log(values[0]), np.log(values[1]), count))
    elif kind == "choice":
        column = rng.choice(np.asarray(values, dtype=float), count)
    elif kind == "integers":  # each whole number from a to b
        column = rng.integers(int(values[0]), int(values[1]), count, endpoint=True).astype(float)
    else:
        raise ValueError(f"{parameter.name}: unknown sampling kind {kind!r}")
    # exp(log(b)) can land one ulp past b: clip to the sampling range, which lies inside the domain.
    column = np.clip(column, min(values), max(values))
    if not np.all(parameter.domain.contains(column)):
        raise AssertionError(f"{parameter.name}: a draw fell outside the domain {parameter.domain}")
    return column


def draw_table(template: Template, count: int, rng: np.random.Generator) -> dict[str, np.ndarray]:
    """One column of ``count`` draws per parameter."""
    return {name: sample_column(parameter, count, rng) for name, parameter in template.parameters.items()}


def numeric_answers(compiled: Compiled) -> dict[str, Any]:
    """The answers that have a numeric tree (symbolic answers have no kernel)."""
    return {name: answer.numeric for name, answer in compiled.answers.items() if answer.numeric is not None}


def interleaved_best(contenders: Mapping[str, Callable[[], Any]], rounds: int, calls: int = 1) -> dict[str, float]:
    """The shortest time of one call of each contender over ``rounds`` rounds, each round timing ``calls``
    calls of each in turn."""
    best = dict.fromkeys(contenders, float("inf"))
    for _ in range(rounds):
        for name, function in contenders.items():
            start = time.perf_counter()
            for _ in range(calls):
                function()
            best[name] = min(best[name], (time.perf_counter() - start) / calls)
    return best


def lambdified(compiled: Compiled, trees: Mapping[str, Any], cse: bool) -> tuple[Callable[..., Any], list[str]]:
    """``sympy.lambdify`` of the answers (constants such as g substituted), and its arguments' names."""
    exprs = [from_node(tree, {}) for tree in trees.values()]
    symbols = sorted({s for expr in exprs for s in expr.free_symbols}, key=lambda s: s.name)
    constants = {s: compiled.constants[s.name] for s in symbols if s.name in compiled.constants}
    arguments = [s for s in symbols if s.name not in compiled.constants]
    function = sp.lambdify(arguments, [expr.subs(constants) for expr in exprs], LAMBDIFY_MODULES, cse=cse)
    return function, [s.name for s in arguments]


def subs_per_set(compiled: Compiled, trees: Mapping[str, Any], table: Mapping[str, np.ndarray],
                 rows: int) -> tuple[float, dict[str, np.ndarray]]:
    """Seconds per set of ``expr.subs(values).evalf()`` over the first ``rows`` sets, and the values."""
    # sympy evaluates grader's sind and cosd only at a number, not at an angle it computes (billiards' line
    # of centres): a user of subs() writes them with sympy's sin and cos of radians.
    radians = {symbolic.sind: lambda x: sp.sin(x * sp.pi / 180), symbolic.cosd: lambda x: sp.cos(x * sp.pi / 180)}
    exprs = {name: from_node(tree, {}).replace(lambda e: e.func in radians, lambda e: radians[e.func](*e.args))
             for name, tree in trees.items()}
    symbols = {s.name: s for expr in exprs.values() for s in expr.free_symbols}

    def one_set(row: int) -> dict[str, float]:
        values = {symbols[k]: float(v[row]) for k, v in table.items() if k in symbols}
        values |= {symbols[k]: v for k, v in compiled.constants.items() if k in symbols}
        return {name: _to_float(expr.subs(values).evalf()) for name, expr in exprs.items()}

    one_set(0)  # warm-up: sympy's first calls pay for lazy set-up
    start = time.perf_counter()
    results = [one_set(row) for row in range(rows)]
    elapsed = time.perf_counter() - start
    return elapsed / rows, {name: np.array([r[name] for r in results]) for name in exprs}


def _to_float(value: Any) -> float:
    try:
        return float(value)
    except (TypeError, ValueError):
        return float("nan")


def worst_difference(ours: Mapping[str, Any], theirs: Mapping[str, Any]) -> float:
    """Largest relative difference over the answers both give (rows where ours is finite)."""
    worst = 0.0
    for name, reference in theirs.items():
        reference = np.asarray(reference, dtype=float)
        mine = np.ravel(np.asarray(ours[name], dtype=float))
        mine = np.full(reference.size, mine[0]) if mine.size == 1 else mine[: reference.size]
        keep = np.isfinite(mine)
        with np.errstate(all="ignore"):
            rel = np.abs(mine[keep] - reference[keep]) / np.maximum(np.abs(reference[keep]), 1e-300)
        worst = max(worst, float(np.nan_to_num(rel, nan=np.inf).max(initial=0.0)))
    return worst


SHORT_CALLS = 200_000  # on short columns a round times several calls: about this many sets in all


def bench_kernels(template: Template, arguments: argparse.Namespace, rng: np.random.Generator) -> list[KernelRow]:
    """At each size: kernel, lambdify (plain and cse) and tree walk interleaved, solve_columns for context;
    subs().evalf() once (its time per set does not depend on the size)."""
    compiled = compiled_for(template)
    trees = numeric_answers(compiled)
    ours = Kernel(trees, compiled.constants)
    plain, names = lambdified(compiled, trees, cse=False)
    shared, _ = lambdified(compiled, trees, cse=True)
    rows: list[KernelRow] = []
    for sets in arguments.sets:
        table = draw_table(template, sets, rng)
        columns = [table[name] for name in names]
        inputs = {name: table[name] for name in ours.inputs}
        env = {**table, **compiled.constants}
        contenders = {"kernel": partial(ours, inputs), "lambdify": partial(plain, *columns),
                      "lambdify_cse": partial(shared, *columns), "tree_walk": partial(_walk, trees, env)}
        with np.errstate(all="ignore"):
            best = interleaved_best(contenders, arguments.rounds, max(1, SHORT_CALLS // sets))
            results = ours(inputs)
            worst = max(worst_difference(results, dict(zip(trees, plain(*columns), strict=True))),
                        worst_difference(results, dict(zip(trees, shared(*columns), strict=True))))
            columns_s = min(_timed(partial(solve_columns, template, compiled, table)) for _ in range(5))
        if not rows:  # subs().evalf() on the first size's first sets
            per_set, subs_values = subs_per_set(compiled, trees, table, arguments.baseline_sets)
            subs_worst = worst_difference(results, subs_values)
        rows.append(KernelRow(template.id, len(trees), len(ours), sets, best["kernel"], best["lambdify"],
                              best["lambdify_cse"], best["tree_walk"], columns_s, per_set, arguments.baseline_sets,
                              max(worst, subs_worst), load()))
    return rows


def _walk(trees: Mapping[str, Any], env: Mapping[str, Any]) -> list[Any]:
    """The tree walk: each tree on its own, node by node (how the kernels evaluated before)."""
    return [evaluate(tree, env) for tree in trees.values()]


def _timed(function: Callable[[], Any]) -> float:
    start = time.perf_counter()
    function()
    return time.perf_counter() - start


# --- 2. solve --batch --json against the minimal script ------------------------------------------

def printed(parameter: Parameter, value: float) -> str:
    """A value as a sheet prints it: to its decimals or significant figures."""
    if parameter.decimals is not None:
        return f"{value:.{parameter.decimals}f}"
    return f"{float(f'{value:.{parameter.sig_figs}g}'):g}"


def write_batch(template: Template, rows: int, rng: np.random.Generator, path: Path) -> None:
    """A comma-separated batch of ``rows`` sampled parameter sets as printed on sheets, each one grader
    answers in full (refused draws and undefined answers are drawn again, as ``generate`` does)."""
    parameters = list(template.parameters.values())
    lines: list[str] = []
    while len(lines) < rows:
        table = draw_table(template, rows, rng)
        text = [[printed(p, v) for p, v in zip(parameters, row, strict=True)]
                for row in zip(*table.values(), strict=True)]
        numbers = {name: np.array([float(row[i]) for row in text]) for i, name in enumerate(template.parameters)}
        answered = solve_columns(template, compiled_for(template), numbers)
        usable = [row for index, row in enumerate(text) if answered.refusals[index] is None
                  and not any(reasons[index] for reasons in answered.undefined.values())]
        if not usable:
            raise RuntimeError(f"{template.id}: no sampled draw is answered in full")
        lines += [",".join(row) for row in usable]
    with path.open("w", encoding="utf-8") as handle:
        handle.write(",".join(template.parameters) + "\n")
        handle.write("".join(line + "\n" for line in lines[:rows]))


def grader_command(*args: str) -> list[str]:
    """``grader ARGS`` as a user runs it: the installed script beside this Python, else ``-m grader``."""
    script = Path(sys.executable).parent / "grader"
    return [str(script), *args] if script.is_file() else [sys.executable, "-m", "grader", *args]


def run(command: Sequence[str], out: Path | None = None, env: Mapping[str, str] | None = None) -> float:
    """Wall time of a whole process from start (its output to ``out`` or discarded)."""
    with (out.open("wb") if out else open(os.devnull, "wb")) as sink:
        start = time.perf_counter()
        done = subprocess.run(command, stdout=sink, stderr=subprocess.PIPE, env=env, check=False)
        elapsed = time.perf_counter() - start
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(command)} failed ({done.returncode}): {done.stderr.decode()[-500:]}")
    return elapsed


def same_lines(ours: Path, theirs: Path) -> None:
    """The two outputs are the same JSON lines: keys, units, rows and parameters equal, answers to 1e-9."""
    with ours.open(encoding="utf-8") as mine, theirs.open(encoding="utf-8") as other:
        for number, (a, b) in enumerate(zip(mine, other, strict=True), 1):
            first, second = json.loads(a), json.loads(b)
            if first.keys() != second.keys() or any(first[k] != second[k] for k in first if k != "answers"):
                raise AssertionError(f"line {number}: {a.strip()} != {b.strip()}")
            for name, answer in first["answers"].items():
                other_answer = second["answers"][name]
                if answer["unit"] != other_answer["unit"] or not np.isclose(
                        answer["value"], other_answer["value"], rtol=AGREEMENT_RTOL, atol=1e-12):
                    raise AssertionError(f"line {number}, {name}: {answer} != {other_answer}")


def bench_batch(template: Template, arguments: argparse.Namespace, rng: np.random.Generator,
                folder: Path) -> BatchRow:
    """The two commands on the same CSV, interleaved; median of ``--runs`` each."""
    path = folder / f"{template.id}.csv"
    write_batch(template, arguments.batch_rows, rng, path)
    ours = grader_command("solve", template.id, "--batch", str(path), "--json")
    theirs = [sys.executable, str(MINIMAL), template.id, str(path)]
    run(ours, folder / "grader.jsonl")
    run(theirs, folder / "minimal.jsonl")
    same_lines(folder / "grader.jsonl", folder / "minimal.jsonl")
    times: dict[str, list[float]] = {"grader": [], "minimal": []}
    for _ in range(arguments.runs):
        times["grader"].append(run(ours))
        times["minimal"].append(run(theirs))
    return BatchRow(template.id, arguments.batch_rows, statistics.median(times["grader"]),
                    statistics.median(times["minimal"]), tuple(times["grader"]), tuple(times["minimal"]), load())


# --- 3. start-up ---------------------------------------------------------------------------------

STARTUP = {"python -c \"import numpy, yaml\"": [sys.executable, "-c", "import numpy, yaml"],
           "grader --help": grader_command("--help"), "grader list": grader_command("list"),
           "grader solve pile-driver ... (warm)": grader_command(*SOLVE_ARGS)}


def bench_startup(arguments: argparse.Namespace) -> tuple[list[StartupRow], float]:
    """Each command's median over interleaved rounds (its caches filled and bytecode written by one untimed
    run first), and one cold solve."""
    with tempfile.TemporaryDirectory(prefix="grader-bench-cache-") as cache:
        env = {**os.environ, "GRADER_CACHE_DIR": cache}  # PYTHONDONTWRITEBYTECODE is cleared at the top
        cold = run(grader_command(*SOLVE_ARGS), env=env)  # an empty cache: compiles with sympy
        for command in STARTUP.values():
            run(command, env=env)  # warm: what a user's second run finds
        times: dict[str, list[float]] = {name: [] for name in STARTUP}
        for _ in range(arguments.startup_runs):
            for name, command in STARTUP.items():
                times[name].append(run(command, env=env))
    now = load()
    return [StartupRow(name, statistics.median(runs), tuple(runs), now) for name, runs in times.items()], cold


# --- report --------------------------------------------------------------------------------------

def rate(value: float) -> str:
    """A rate with thousands separators and about three significant figures."""
    return f"{value:,.0f}" if value >= 100 else f"{value:.3g}"


def verdict(ok: bool) -> str:
    """A target verdict for the tables."""
    return "met" if ok else "**NOT met**"


def kernel_table(rows: Sequence[KernelRow]) -> str:
    """Sets per second through each, and the kernel's speed-ups."""
    lines = ["| template | sets | answers | kernel steps | kernel sets/s | lambdify sets/s "
             "| kernel / lambdify (target >= 1) | lambdify cse=True sets/s | kernel / cse | tree walk (before) sets/s "
             "| solve_columns sets/s | subs().evalf() sets/s | kernel / subs | max rel. diff | load |",
             "|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|"]
    for row in rows:
        lines.append(
            f"| {row.template} | {row.sets:,} | {row.answers} | {row.steps} | {rate(row.sets / row.kernel_s)} "
            f"| {rate(row.sets / row.lambdify_s)} | {row.vs_lambdify:.2f}x | {rate(row.sets / row.lambdify_cse_s)} "
            f"| {row.lambdify_cse_s / row.kernel_s:.2f}x | {rate(row.sets / row.tree_walk_s)} "
            f"| {rate(row.sets / row.columns_s)} | {rate(1 / row.subs_s_per_set)} | {rate(row.vs_subs)}x "
            f"| {row.max_rel_diff:.1e} | {row.load:.2f} |")
    return "\n".join(lines)


def batch_table(rows: Sequence[BatchRow]) -> str:
    """Whole-command times for the batch."""
    lines = ["| template | rows | `grader solve --batch --json` | minimal numpy script | ratio (target <= 1.5) "
             "| load |", "|---|--:|--:|--:|--:|--:|"]
    lines += [f"| {r.template} | {r.rows:,} | {r.grader_s:.3f} s | {r.minimal_s:.3f} s | {r.ratio:.2f}x "
              f"| {r.load:.2f} |" for r in rows]
    return "\n".join(lines)


def startup_table(rows: Sequence[StartupRow], cold: float) -> str:
    """Start-up medians against the numpy+yaml baseline."""
    base = rows[0].seconds
    lines = ["| command (whole process) | median | / baseline (target <= 2) | load |", "|---|--:|--:|--:|"]
    lines += [f"| `{r.command}` | {r.seconds:.3f} s | {r.seconds / base:.2f}x | {r.load:.2f} |" for r in rows]
    lines.append(f"| `grader solve pile-driver ...` (cold: empty cache, compiles with sympy) | {cold:.3f} s "
                 f"| {cold / base:.2f}x | |")
    return "\n".join(lines)


def targets(kernels: Sequence[KernelRow], batches: Sequence[BatchRow], startup: Sequence[StartupRow]) -> str:
    """One line per target, with the worst figure."""
    sizes = sorted({r.sets for r in kernels}, reverse=True)
    slowest = [min((r for r in kernels if r.sets == size), key=lambda r: r.vs_lambdify) for size in sizes]
    fewest = min(kernels, key=lambda r: r.sets / r.kernel_s)
    least = min(kernels, key=lambda r: r.vs_subs)
    batch = max(batches, key=lambda r: r.ratio)
    base, worst = startup[0].seconds, max(startup[1:], key=lambda r: r.seconds)
    agree = max(r.max_rel_diff for r in kernels)
    return "\n".join([
        *(f"- kernels >= {TARGET_LAMBDIFY:g}x sympy.lambdify on every template at {row.sets:,} sets: "
          f"{verdict(row.vs_lambdify >= TARGET_LAMBDIFY)} (lowest: {row.template}, {row.vs_lambdify:.2f}x)"
          for row in slowest),
        f"- kernels >= {TARGET_RATE:,.0f} sets/s on every template at every size: "
        f"{verdict(fewest.sets / fewest.kernel_s >= TARGET_RATE)} (lowest: {fewest.template} at {fewest.sets:,} sets, "
        f"{rate(fewest.sets / fewest.kernel_s)} sets/s)",
        f"- kernels >= {TARGET_SUBS:,.0f}x subs().evalf() (context): {verdict(least.vs_subs >= TARGET_SUBS)} "
        f"(lowest: {least.template} at {least.sets:,} sets, {rate(least.vs_subs)}x)",
        f"- `solve --batch --json` within {TARGET_BATCH:g}x of the minimal numpy script: "
        f"{verdict(batch.ratio <= TARGET_BATCH)} (highest: {batch.template}, {batch.ratio:.2f}x)",
        f"- warm start-up within {TARGET_STARTUP:g}x of `python -c \"import numpy, yaml\"`: "
        f"{verdict(worst.seconds <= TARGET_STARTUP * base)} (slowest: `{worst.command}`, {worst.seconds / base:.2f}x)",
        f"- lambdify and subs().evalf() agree with the kernels to rel. {AGREEMENT_RTOL:g}: "
        f"{verdict(agree <= AGREEMENT_RTOL)} (worst {agree:.1e})",
    ])


def environment(arguments: argparse.Namespace) -> str:
    """What the numbers were measured on, and how."""
    return (f"Python {platform.python_version()}, numpy {np.__version__}, sympy {sp.__version__}, "
            f"{os.cpu_count()} CPUs ({platform.machine()}), seed {arguments.seed}. Kernels: "
            f"{' and '.join(f'{sets:,}' for sets in arguments.sets)} sets, "
            f"best of {arguments.rounds} interleaved rounds; subs().evalf() on {arguments.baseline_sets} sets. "
            f"Batch: {arguments.batch_rows:,} rows, median of {arguments.runs} interleaved runs. Start-up: median of "
            f"{arguments.startup_runs} interleaved runs. Load: the 1-minute load average after each part.")


def report(kernels: Sequence[KernelRow], batches: Sequence[BatchRow], startup: Sequence[StartupRow], cold: float,
           arguments: argparse.Namespace, loads: Sequence[float]) -> str:
    """The whole Markdown report."""
    return "\n\n".join([
        "# Solve benchmark", environment(arguments),
        f"Load average (1, 5, 15 min) at the start: {loads[0]:.2f}, {loads[1]:.2f}, {loads[2]:.2f}.",
        "## Kernels against sympy.lambdify", kernel_table(kernels),
        "A set is all of a template's numeric answers for one parameter set. lambdify gets the same expressions "
        "(the constants substituted) and grader's sind and cosd; the tree walk is how the kernels evaluated "
        "before (each tree on its own, node by node); solve_columns adds the domain, constraint and physics "
        "checks; subs().evalf() is one set at a time, its figure extrapolated.",
        "## `grader solve --batch --json` against a minimal numpy script", batch_table(batches),
        "## Start-up", startup_table(startup, cold), "## Targets", targets(kernels, batches, startup),
    ]) + "\n"


def write_csv(kernels: Sequence[KernelRow], batches: Sequence[BatchRow], startup: Sequence[StartupRow],
              folder: Path) -> None:
    """``solve.csv`` (kernels), ``solve_batch.csv`` and ``solve_startup.csv``."""
    for name, rows in (("solve.csv", kernels), ("solve_batch.csv", batches), ("solve_startup.csv", startup)):
        with (folder / name).open("w", newline="", encoding="utf-8") as handle:
            writer = csv.writer(handle)
            writer.writerow(list(asdict(rows[0])))
            for row in rows:
                writer.writerow([" ".join(f"{v:.6f}" for v in value) if isinstance(value, tuple) else value
                                 for value in asdict(row).values()])


def plot(rows: Sequence[KernelRow], path: Path) -> str:
    """A log-scale bar chart of sets/s per template; a note when matplotlib is missing."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return "matplotlib is not installed: skipped the plot (pip install matplotlib)"
    series = (("kernel", "kernel_s", "#1f77b4"), ("sympy.lambdify", "lambdify_s", "#d62728"),
              ("lambdify cse=True", "lambdify_cse_s", "#ff9896"), ("tree walk (before)", "tree_walk_s", "#2ca02c"),
              ("solve_columns", "columns_s", "#9467bd"))
    rows = [row for row in rows if row.sets == max(r.sets for r in rows)]  # the largest size
    x, width = np.arange(len(rows)), 0.15
    figure, axes = plt.subplots(figsize=(max(12.0, 0.9 * len(rows)), 6), dpi=120)
    for index, (label, field, colour) in enumerate(series):
        values = [row.sets / getattr(row, field) for row in rows]
        bars = axes.bar(x + (index - 2.5) * width, values, width, label=label, color=colour)
        axes.bar_label(bars, labels=[f"{v / 1e6:.3g}M" for v in values], fontsize=7, padding=2, rotation=90)
    subs = [1 / row.subs_s_per_set for row in rows]
    bars = axes.bar(x + 2.5 * width, subs, width, label="subs().evalf()", color="#7f7f7f")
    axes.bar_label(bars, labels=[rate(v) for v in subs], fontsize=7, padding=2, rotation=90)
    axes.set_yscale("log")
    axes.set_ylim(top=axes.get_ylim()[1] * 20)
    axes.set_xticks(x, [row.template for row in rows], rotation=30, ha="right")
    axes.set_ylabel("parameter sets per second (log scale)")
    axes.set_title(f"Answers for {rows[0].sets:,} parameter sets per template: kernels against sympy")
    axes.legend(loc="upper right", fontsize=8, ncols=3)
    axes.grid(axis="y", which="major", alpha=0.3)
    figure.tight_layout()
    figure.savefig(path)
    plt.close(figure)
    return f"plot written to {path}"


def main(argv: Sequence[str] | None = None) -> int:
    """Run every measurement, print the report and write the result files."""
    arguments = parse_args(argv)
    loads = os.getloadavg()
    print(f"load average at the start: {loads[0]:.2f} {loads[1]:.2f} {loads[2]:.2f}", file=sys.stderr, flush=True)
    if arguments.only == "startup":
        startup, cold = bench_startup(arguments)
        print(startup_table(startup, cold))
        return 0
    rng = np.random.default_rng(arguments.seed)
    bank = load_bank()
    kernels = []
    for template in bank.values():
        print(f"kernels: {template.id} ...", file=sys.stderr, flush=True)
        kernels += bench_kernels(template, arguments, rng)
    kernels.sort(key=lambda row: -row.sets)  # one table per size, largest first
    if arguments.only == "kernels":
        print(kernel_table(kernels))
        return 0
    folder = Path(tempfile.mkdtemp(prefix="grader-bench-batch-"))
    try:
        batches = []
        for template_id in (name for name in bank if name in UNITS):  # the templates the minimal script answers
            print(f"batch: {template_id} ...", file=sys.stderr, flush=True)
            batches.append(bench_batch(bank[template_id], arguments, rng, folder))
    finally:
        shutil.rmtree(folder)
    print("start-up ...", file=sys.stderr, flush=True)
    startup, cold = bench_startup(arguments)
    text = report(kernels, batches, startup, cold, arguments, loads)
    arguments.out.mkdir(parents=True, exist_ok=True)
    (arguments.out / "solve.md").write_text(text, encoding="utf-8")
    write_csv(kernels, batches, startup, arguments.out)
    print(text)
    print(plot(kernels, arguments.out / "solve.png"), file=sys.stderr)
    return 1 if any(row.max_rel_diff > AGREEMENT_RTOL for row in kernels) else 0


if __name__ == "__main__":
    raise SystemExit(main())
