"""Benchmark: answers for many parameter sets, compiled kernels against a sympy baseline.

For each template of the shipped bank this draws ``--sets`` parameter sets from the parameters'
sampling specs and times

* the raw kernels: :func:`grader.model.kernel.evaluate` on every numeric answer tree (best of ``--repeat``);
* :func:`grader.solve.evaluate.solve_batch`: checks plus one Python result object per row (best of 3);
* the baseline: each numeric answer tree turned back into sympy and evaluated with
  ``expr.subs(values).evalf()``, one set at a time, on the first ``--baseline-sets`` sets only
  (the full run would take minutes); its 10^5-set time is extrapolated from the per-set time.

The baseline's values must agree with the kernels' (relative 1e-9) on that subset. It also times
``python -m grader solve pile-driver ...`` with an empty compile cache (cold) and a filled one (warm).

Run: ``python benchmarks/solve.py [--sets 100000] [--baseline-sets 300]``. Writes
``benchmarks/results/solve.md``, ``solve.csv``, ``solve_startup.csv`` and, with matplotlib, ``solve.png``.
"""

from __future__ import annotations

import argparse
import csv
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np
import sympy as sp

from grader.bank.template import Parameter, Template, load_bank
from grader.model.kernel import evaluate
from grader.physics.symbolic import from_node
from grader.solve.cache import compiled_for
from grader.solve.compiled import Compiled
from grader.solve.evaluate import Solution, solve_batch, solve_columns

RESULTS = Path(__file__).resolve().parent / "results"
AGREEMENT_RTOL = 1e-9
TARGET_SPEEDUP = 1_000.0
TARGET_RATE = 1e6
TARGET_WARM_S = 1.0
SOLVE_BATCH_REPEAT = 3
CLI_COMMAND = ("solve", "pile-driver", "--set", "m_ram=800", "--set", "m_pile=2400",
               "--set", "h_drop=2", "--set", "h_rebound=0.1")


@dataclass(frozen=True)
class Row:
    """The measurements for one template."""

    template: str
    answers: int
    sets: int
    refused: int
    kernel_s: float
    columns_s: float
    solve_batch_s: float
    baseline_sets: int
    sympy_s_per_set: float
    max_rel_diff: float
    disagreements: int

    @property
    def kernel_rate(self) -> float:
        """Parameter sets per second through the raw kernels."""
        return self.sets / self.kernel_s

    @property
    def columns_rate(self) -> float:
        """Parameter sets per second through ``solve_columns`` (checks and answers, as arrays)."""
        return self.sets / self.columns_s

    @property
    def solve_batch_rate(self) -> float:
        """Parameter sets per second through ``solve_batch``."""
        return self.sets / self.solve_batch_s

    @property
    def sympy_rate(self) -> float:
        """Parameter sets per second through the sympy baseline."""
        return 1.0 / self.sympy_s_per_set


@dataclass(frozen=True)
class Startup:
    """Wall time of one CLI solve with an empty cache and with a filled one."""

    cold_s: float
    warm_s: float
    warm_runs: tuple[float, ...]


def parse_args(argv: Sequence[str] | None = None) -> argparse.Namespace:
    """The command-line options."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("--sets", type=int, default=100_000, help="parameter sets per template (default 100000)")
    parser.add_argument("--baseline-sets", type=int, default=300,
                        help="sets evaluated with the sympy baseline (default 300)")
    parser.add_argument("--repeat", type=int, default=5, help="kernel timings: best of this many (default 5)")
    parser.add_argument("--seed", type=int, default=20240601, help="numpy random seed (default 20240601)")
    parser.add_argument("--out", type=Path, default=RESULTS, help=f"output folder (default {RESULTS})")
    arguments = parser.parse_args(argv)
    if arguments.sets < 1 or not 1 <= arguments.baseline_sets <= arguments.sets or arguments.repeat < 1:
        parser.error("need --sets >= 1, 1 <= --baseline-sets <= --sets and --repeat >= 1")
    return arguments


def sample_column(parameter: Parameter, count: int, rng: np.random.Generator) -> np.ndarray:
    """``count`` draws of one parameter from its sampling spec, kept inside its domain."""
    kind, values = parameter.sample.kind, parameter.sample.values
    if kind == "uniform":
        column = rng.uniform(values[0], values[1], count)
    elif kind == "log_uniform":
        column = np.exp(rng.uniform(np.log(values[0]), np.log(values[1]), count))
    elif kind == "choice":
        column = rng.choice(np.asarray(values, dtype=float), count)
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


def best_of(function: Callable[[], Any], repeat: int) -> tuple[float, Any]:
    """The shortest of ``repeat`` timed calls, and the last call's result."""
    best, result = float("inf"), None
    for _ in range(repeat):
        result = None  # let the previous result go before timing the next call
        start = time.perf_counter()
        result = function()
        best = min(best, time.perf_counter() - start)
    return best, result


def numeric_answers(compiled: Compiled) -> dict[str, Any]:
    """The answers that have a numeric tree (symbolic answers have no kernel)."""
    return {name: answer.numeric for name, answer in compiled.answers.items() if answer.numeric is not None}


def run_kernels(trees: Mapping[str, Any], env: Mapping[str, Any], count: int) -> dict[str, np.ndarray]:
    """Every numeric answer for all sets at once, straight through the kernels."""
    with np.errstate(all="ignore"):
        return {name: np.broadcast_to(np.asarray(evaluate(tree, env), dtype=float), (count,))
                for name, tree in trees.items()}


def sympy_baseline(compiled: Compiled, trees: Mapping[str, Any], table: Mapping[str, np.ndarray],
                   example: Mapping[str, float], rows: int) -> tuple[float, dict[str, np.ndarray]]:
    """Seconds per set of ``expr.subs(values).evalf()`` over the first ``rows`` sets, and the values."""
    exprs = {name: from_node(tree, {}) for name, tree in trees.items()}
    symbols = {s.name: s for expr in exprs.values() for s in expr.free_symbols}

    def one_set(params: Mapping[str, float]) -> dict[str, float]:
        values = {symbols[k]: v for k, v in {**params, **compiled.constants}.items() if k in symbols}
        return {name: _to_float(expr.subs(values).evalf()) for name, expr in exprs.items()}

    one_set(example)  # warm-up outside the timing: sympy's first calls pay for lazy set-up
    start = time.perf_counter()
    results = [one_set({k: float(column[row]) for k, column in table.items()}) for row in range(rows)]
    elapsed = time.perf_counter() - start
    return elapsed / rows, {name: np.array([r[name] for r in results]) for name in exprs}


def _to_float(value: Any) -> float:
    """A sympy number as a float; NaN when it is not a real number."""
    try:
        return float(value)
    except (TypeError, ValueError):
        return float("nan")


def compare(kernel: Mapping[str, np.ndarray], baseline: Mapping[str, np.ndarray],
            solutions: Sequence[Solution]) -> tuple[float, int]:
    """Largest relative difference kernel vs sympy, and how many values exceed ``AGREEMENT_RTOL``.

    Rows that ``solve_batch`` refused, and answers it reports as undefined, are not compared.
    """
    worst, bad = 0.0, 0
    for name, reference in baseline.items():
        rows = len(reference)
        keep = np.array([s.answers is not None and s.answers[name].value is not None for s in solutions[:rows]])
        ours, ref = kernel[name][:rows][keep], reference[keep]
        with np.errstate(all="ignore"):
            rel = np.abs(ours - ref) / np.maximum(np.abs(ref), np.finfo(float).tiny)
        rel = np.where(np.isnan(rel), np.inf, rel)
        worst = max(worst, float(rel.max(initial=0.0)))
        bad += int(np.count_nonzero(rel > AGREEMENT_RTOL))
    return worst, bad


def check_solve_batch(kernel: Mapping[str, np.ndarray], solutions: Sequence[Solution]) -> None:
    """``solve_batch``'s numbers must be the raw kernels' numbers (same trees, same inputs)."""
    for name, values in kernel.items():
        theirs = np.array([np.nan if s.answers is None or not isinstance(s.answers[name].value, float)
                           else s.answers[name].value for s in solutions])
        same = np.isnan(theirs) | (theirs == values)
        if not same.all():
            raise AssertionError(f"{name}: solve_batch differs from the kernel in {np.count_nonzero(~same)} rows")


def bench_template(template: Template, arguments: argparse.Namespace, rng: np.random.Generator) -> Row:
    """All measurements for one template."""
    compiled = compiled_for(template)
    table = draw_table(template, arguments.sets, rng)
    env = {**table, **compiled.constants}
    trees = numeric_answers(compiled)
    kernel_s, kernel = best_of(lambda: run_kernels(trees, env, arguments.sets), arguments.repeat)
    columns_s, _ = best_of(lambda: solve_columns(template, compiled, table), arguments.repeat)
    batch_s, solutions = best_of(lambda: solve_batch(template, compiled, table), SOLVE_BATCH_REPEAT)
    check_solve_batch(kernel, solutions)
    per_set, baseline = sympy_baseline(compiled, trees, table, template.example, arguments.baseline_sets)
    worst, bad = compare(kernel, baseline, solutions)
    refused = sum(solution.error is not None for solution in solutions)
    return Row(template.id, len(trees), arguments.sets, refused, kernel_s, columns_s, batch_s,
               arguments.baseline_sets, per_set, worst, bad)


def run_cli(cache: Path) -> tuple[float, str]:
    """Wall time and output of ``python -m grader solve pile-driver ...`` with ``cache`` as cache folder."""
    env = {**os.environ, "GRADER_CACHE_DIR": str(cache)}
    start = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "grader", *CLI_COMMAND], env=env, capture_output=True,
                          text=True, check=False)
    elapsed = time.perf_counter() - start
    if done.returncode != 0:
        raise RuntimeError(f"grader solve failed ({done.returncode}): {done.stderr.strip()}")
    return elapsed, done.stdout


def measure_startup(warm_runs: int = 3) -> Startup:
    """Cold (empty cache: compiles with sympy) and warm (median of ``warm_runs``) CLI solves."""
    with tempfile.TemporaryDirectory(prefix="grader-bench-cache-") as folder:
        cache = Path(folder)
        cold, expected = run_cli(cache)
        if not any(cache.glob("pile-driver-*.json")):
            raise AssertionError("the cold run left no compiled template in the cache folder")
        files = sorted(cache.iterdir())
        warm = []
        for _ in range(warm_runs):
            elapsed, output = run_cli(cache)
            if output != expected:
                raise AssertionError("a warm run printed something else than the cold run")
            if sorted(cache.iterdir()) != files:
                raise AssertionError("a warm run compiled again (did a solver source change meanwhile?)")
            warm.append(elapsed)
    return Startup(cold, statistics.median(warm), tuple(warm))


def rate(value: float) -> str:
    """A rate with thousands separators and about three significant figures."""
    return f"{value:,.0f}" if value >= 100 else f"{value:.3g}"


def verdict(ok: bool) -> str:
    """A target verdict for the tables."""
    return "met" if ok else "**NOT met**"


def throughput_table(rows: Sequence[Row]) -> str:
    """The per-template Markdown table."""
    first = rows[0]
    lines = [f"| template | answers | kernel sets/s | solve_columns sets/s | solve_batch sets/s | sympy sets/s "
             f"({first.baseline_sets}-set subset) | sympy, {first.sets:,} sets (extrapolated) | speed-up (kernel / "
             "sympy) | speed-up (solve_batch / sympy) | refused rows | max rel. diff vs sympy |",
             "|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|"]
    for row in rows:
        lines.append(f"| {row.template} | {row.answers} | {rate(row.kernel_rate)} | {rate(row.columns_rate)} "
                     f"| {rate(row.solve_batch_rate)} "
                     f"| {rate(row.sympy_rate)} | {row.sympy_s_per_set * row.sets:,.0f} s "
                     f"| {rate(row.kernel_rate / row.sympy_rate)}× | {rate(row.solve_batch_rate / row.sympy_rate)}× "
                     f"| {row.refused} / {row.sets:,} | {row.max_rel_diff:.1e} |")
    return "\n".join(lines)


def startup_table(startup: Startup) -> str:
    """The cold / warm Markdown table."""
    runs = ", ".join(f"{t:.3f}" for t in startup.warm_runs)
    return "\n".join([
        "| `python -m grader solve pile-driver ...` | seconds |", "|---|--:|",
        f"| cold (empty cache: compiles with sympy) | {startup.cold_s:.3f} |",
        f"| warm (cache filled), median of {len(startup.warm_runs)} ({runs}) | {startup.warm_s:.3f} |",
    ])


def targets(rows: Sequence[Row], startup: Startup) -> str:
    """One line per target, with the worst template's figure."""
    speed = min(rows, key=lambda r: r.kernel_rate / r.sympy_rate)
    slow = min(rows, key=lambda r: r.kernel_rate)
    agree = all(r.disagreements == 0 for r in rows)
    worst = max(r.max_rel_diff for r in rows)
    factor = speed.kernel_rate / speed.sympy_rate
    return "\n".join([
        f"- kernels >= {TARGET_SPEEDUP:,.0f}× the sympy baseline: {verdict(factor >= TARGET_SPEEDUP)}"
        f" (lowest: {speed.template}, {rate(factor)}×)",
        f"- >= 10^6 answer sets/s through the kernels: {verdict(slow.kernel_rate >= TARGET_RATE)}"
        f" (lowest: {slow.template}, {rate(slow.kernel_rate)} sets/s)",
        f"- warm CLI solve < {TARGET_WARM_S:g} s: {verdict(startup.warm_s < TARGET_WARM_S)} ({startup.warm_s:.3f} s)",
        f"- sympy baseline agrees with the kernels to rel. {AGREEMENT_RTOL:g}: {verdict(agree)} (worst {worst:.1e})",
    ])


def environment(arguments: argparse.Namespace) -> str:
    """What the numbers were measured on."""
    return (f"Python {platform.python_version()}, numpy {np.__version__}, sympy {sp.__version__}, "
            f"{os.cpu_count()} CPUs ({platform.machine()}), seed {arguments.seed}. Kernel timings: best of "
            f"{arguments.repeat}; solve_batch: best of {SOLVE_BATCH_REPEAT}; sympy baseline "
            "(`expr.subs(values).evalf()` per set, every numeric answer): one pass over the first "
            f"{arguments.baseline_sets} sets, its {arguments.sets:,}-set time extrapolated from the per-set time.")


def report(rows: Sequence[Row], startup: Startup, arguments: argparse.Namespace) -> str:
    """The whole Markdown report."""
    return "\n\n".join([
        f"# Solve benchmark: {arguments.sets:,} parameter sets per template", environment(arguments),
        "## Throughput", throughput_table(rows),
        "A set is all of a template's numeric answers for one parameter set. The kernel column evaluates the "
        "answer trees only; solve_columns also checks domains, constraints and physics and returns arrays; "
        "solve_batch adds one Python result per row (car-collision's two symbolic answers "
        "are written out as text per row, which dominates its time).",
        "## Startup", startup_table(startup), "## Targets", targets(rows, startup),
    ]) + "\n"


def write_csv(rows: Sequence[Row], startup: Startup, folder: Path) -> None:
    """``solve.csv`` (one line per template) and ``solve_startup.csv``."""
    with (folder / "solve.csv").open("w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        fields = list(asdict(rows[0]))
        writer.writerow([*fields, "kernel_sets_per_s", "solve_columns_sets_per_s", "solve_batch_sets_per_s",
                         "sympy_sets_per_s",
                         "speedup_kernel", "speedup_solve_batch"])
        for row in rows:
            writer.writerow([*asdict(row).values(), row.kernel_rate, row.columns_rate, row.solve_batch_rate,
                             row.sympy_rate,
                             row.kernel_rate / row.sympy_rate, row.solve_batch_rate / row.sympy_rate])
    with (folder / "solve_startup.csv").open("w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        writer.writerow(["cold_s", "warm_median_s", "warm_runs_s"])
        writer.writerow([startup.cold_s, startup.warm_s, " ".join(f"{t:.6f}" for t in startup.warm_runs)])


def short(value: float) -> str:
    """A compact bar label: 3.2M, 85k, 210."""
    for limit, suffix in ((1e9, "G"), (1e6, "M"), (1e3, "k")):
        if value >= limit:
            return f"{value / limit:.3g}{suffix}"
    return f"{value:.3g}"


def plot(rows: Sequence[Row], path: Path) -> str:
    """A log-scale bar chart of sets/s per template; a note when matplotlib is missing."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return "matplotlib is not installed: skipped the plot (pip install matplotlib)"
    series = (("kernel", "kernel_rate", "#1f77b4"), ("solve_columns", "columns_rate", "#2ca02c"),
              ("solve_batch", "solve_batch_rate", "#ff7f0e"),
              (f"sympy baseline ({rows[0].baseline_sets} sets)", "sympy_rate", "#7f7f7f"))
    x, width = np.arange(len(rows)), 0.2
    figure, axes = plt.subplots(figsize=(11, 5.5), dpi=120)
    for index, (label, field, colour) in enumerate(series):
        values = [getattr(row, field) for row in rows]
        bars = axes.bar(x + (index - 1.5) * width, values, width, label=label, color=colour)
        axes.bar_label(bars, labels=[short(v) for v in values], fontsize=8, padding=2)
    axes.axhline(TARGET_RATE, color="#d62728", linestyle="--", linewidth=1, label="target: $10^6$ sets/s")
    axes.set_yscale("log")
    axes.set_ylim(top=axes.get_ylim()[1] * 4)
    axes.set_xticks(x, [row.template for row in rows])
    axes.set_ylabel("parameter sets per second (log scale)")
    axes.set_title(f"Answers for {rows[0].sets:,} parameter sets per template: compiled kernels vs sympy")
    axes.legend(loc="upper right", fontsize=9, ncols=2)
    axes.grid(axis="y", which="major", alpha=0.3)
    figure.tight_layout()
    figure.savefig(path)
    plt.close(figure)
    return f"plot written to {path}"


def main(argv: Sequence[str] | None = None) -> int:
    """Run every measurement, print the report and write the result files."""
    arguments = parse_args(argv)
    rng = np.random.default_rng(arguments.seed)
    rows = []
    for template in load_bank().values():
        print(f"benchmarking {template.id} ...", file=sys.stderr, flush=True)
        rows.append(bench_template(template, arguments, rng))
    print("timing the CLI, cold and warm ...", file=sys.stderr, flush=True)
    startup = measure_startup()
    text = report(rows, startup, arguments)
    arguments.out.mkdir(parents=True, exist_ok=True)
    (arguments.out / "solve.md").write_text(text, encoding="utf-8")
    write_csv(rows, startup, arguments.out)
    print(text)
    print(plot(rows, arguments.out / "solve.png"), file=sys.stderr)
    return 1 if any(row.disagreements for row in rows) else 0


if __name__ == "__main__":
    raise SystemExit(main())
