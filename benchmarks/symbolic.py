"""Symbolic grading benchmark: hardened comparison of honest answers against sympy, and the adversarial list.

Run: ``python benchmarks/symbolic.py [--answers N] [--sympy-sample S]`` (defaults 20,000 and 100). It writes
``benchmarks/results/symbolic.md``.

- **Honest answers**: N distinct rewritings of car-collision's keys (``v*(1 - 0.1*p)/(p + 1)`` and
  ``1.1*v/(p + 1)``): reordered, expanded, factored, scaled by a constant above and below, decimals as fractions.
  Each is graded as ``grader grade`` grades a distinct cell (read, refused functions, compared) in process, with
  no cache shared between them (every text is new). Every one must be ``correct``.
- **Sympy baselines**, what a competent user would write, timed on a sample and extrapolated:
  ``sympy.simplify(parse_expr(student) - key) == 0`` (decimals read as fractions); and ``sympy.lambdify`` of
  both at 8 random points.
  Target: ours at least 100x faster per answer than each.
- The same with Python's cyclic collector paused, as ``grader grade`` runs; printed, not held to the target.
- **Adversarial answers**: the table of ``tests/test_symbolic_gaming.py``; none may be ``correct``.

The machine's load average is printed with the figures (the machine is shared).
"""

from __future__ import annotations

import argparse
import os
import platform
import random
import statistics
import sys
import time
from pathlib import Path

RESULTS = Path(__file__).resolve().parent / "results" / "symbolic.md"
ROUNDS = 3
KEYS = ("v*(1 - 0.1*p)/(p + 1)", "1.1*v/(p + 1)")
DOMAINS = {"p": (0.3, 3.0), "v": (1.0, 10.0)}


def honest(count: int, rng: random.Random) -> list[tuple[str, str]]:
    """``count`` distinct (key, answer) pairs, each answer an equivalent rewriting of its key."""
    forms_a = ["{c}*v*(1 - 0.1*p)/(p + 1)/{c}", "v({c} - 0.1*{c}*p)/({c}*(1 + p))", "(v - 0.1pv)*{c}/({c}p + {c})",
               "v/(p + 1)*(1 - 0.1p)*{c}/{c}", "({c}v - {c}*p*v/10)/({c}*(1+p))", "v(1 - p/10)/(1 + p)*({c}/{c})"]
    forms_b = ["{c}*1.1*v/(({c})*(p + 1))", "11/10*v*{c}/({c}+{c}p)", "1.1v({c})/(p*{c} + {c})",
               "v*(1.1*{c})/({c}*(1 + p))", "(11*{c}/10)v/({c}(p+1))"]
    pairs, seen = [], set()
    while len(pairs) < count:
        c = round(rng.uniform(1.0, 999.0), rng.choice((1, 2, 3)))
        key, forms = (KEYS[0], forms_a) if rng.random() < 0.5 else (KEYS[1], forms_b)
        text = rng.choice(forms).format(c=c)
        if text not in seen:
            seen.add(text)
            pairs.append((key, text))
    return pairs


def ours(pairs: list[tuple[str, str]]) -> tuple[float, dict[str, int]]:
    """Each answer graded as ``grader grade`` grades a symbolic cell (read, refused functions, compared; one
    verdict per distinct text), with Python's cyclic collector on (as ``grader check`` runs)."""
    from grader.grade.grading import symbolic_outcome

    domains = tuple(sorted(DOMAINS.items()))
    verdicts: dict[str, int] = {}
    started = time.perf_counter()
    for key, text in pairs:
        verdict = symbolic_outcome(text, ",", domains, key, "bench")[0]
        verdicts[verdict] = verdicts.get(verdict, 0) + 1
    return time.perf_counter() - started, verdicts


def sympy_simplify(pairs: list[tuple[str, str]]) -> float:
    import sympy
    from sympy.parsing.sympy_parser import (
        implicit_multiplication_application,
        parse_expr,
        rationalize,
        standard_transformations,
    )

    # Decimals read as exact fractions, as ours reads them (else float residues of 1e-16 remain).
    transformations = (*standard_transformations, implicit_multiplication_application, rationalize)
    p, v = sympy.symbols("p v", positive=True)
    names = {"p": p, "v": v}
    started = time.perf_counter()
    for key, text in pairs:
        student = parse_expr(text.replace("^", "**"), local_dict=names, transformations=transformations)
        key_tree = parse_expr(key, local_dict=names, transformations=transformations)
        assert sympy.simplify(student - key_tree) == 0, text
    return (time.perf_counter() - started) / len(pairs)


def sympy_lambdify(pairs: list[tuple[str, str]], rng: random.Random) -> float:
    import numpy as np
    import sympy
    from sympy.parsing.sympy_parser import implicit_multiplication_application, parse_expr, standard_transformations

    transformations = (*standard_transformations, implicit_multiplication_application)
    p, v = sympy.symbols("p v")
    names = {"p": p, "v": v}
    started = time.perf_counter()
    for key, text in pairs:
        at_p, at_v = np.array([rng.uniform(*DOMAINS["p"]) for _ in range(8)]), np.array(
            [rng.uniform(*DOMAINS["v"]) for _ in range(8)])
        student = sympy.lambdify((p, v), parse_expr(text, local_dict=names, transformations=transformations))
        expected = sympy.lambdify((p, v), parse_expr(key, local_dict=names))
        assert np.allclose(student(at_p, at_v), expected(at_p, at_v), rtol=1e-6), text
    return (time.perf_counter() - started) / len(pairs)


def adversarial() -> tuple[int, dict[str, int], float]:
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
    from test_symbolic_gaming import ADVERSARIAL
    from test_symbolic_gaming import DOMAINS as TABLE_DOMAINS

    from grader.grade.check import check, expectation

    found: dict[str, int] = {}
    started = time.perf_counter()
    for key, answer, _ in ADVERSARIAL:
        verdict = str(check(answer, expectation(key, symbols=["p", "v"], domains=TABLE_DOMAINS))["verdict"])
        found[verdict] = found.get(verdict, 0) + 1
    return len(ADVERSARIAL), found, time.perf_counter() - started


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("--answers", type=int, default=20_000)
    parser.add_argument("--sympy-sample", type=int, default=100)
    arguments = parser.parse_args()
    loads = [os.getloadavg()]
    rng = random.Random(22)
    # Ours and the sympy baselines alternated, three rounds (the machine is shared): the medians are compared.
    # Each round grades answers no earlier round saw (grade keeps one verdict per distinct text).
    rounds: list[tuple[float, float, float]] = []
    for round_ in range(ROUNDS):
        pairs = honest(arguments.answers, random.Random(22 + 100 * round_))
        seconds, verdicts = ours(pairs)
        sample = rng.sample(pairs, arguments.sympy_sample)
        rounds.append((seconds / len(pairs), sympy_simplify(sample), sympy_lambdify(sample, rng)))
    loads.append(os.getloadavg())
    each, simplify_each, lambdify_each = (statistics.median(column) for column in zip(*rounds, strict=True))
    seconds = each * len(pairs)
    # A class repeats itself: as benchmarks/grade.py, 20,000 answers of 5,000 distinct texts, each read once.
    distinct = honest(arguments.answers // 4, random.Random(23))
    repeated_seconds, _ = ours(distinct)
    repeated_each = repeated_seconds / arguments.answers
    # grader grade pauses the cyclic collector while it grades (grader.base.heap): other distinct answers graded so
    # (the same ones would be found in the comparison's cache).
    from grader.base.heap import collector_paused

    with collector_paused():
        paused_seconds, _ = ours(honest(arguments.answers, random.Random(24)))
    loads.append(os.getloadavg())
    listed, found, adversarial_seconds = adversarial()
    rows = [("`sympy.simplify(parse_expr(student) - key) == 0` (decimals as fractions)", simplify_each),
            ("`sympy.lambdify` of both at 8 random points", lambdify_each)]
    passed = found.get("correct", 0)
    lines = [
        "# Symbolic grading benchmark", "",
        f"Python {platform.python_version()}, {os.cpu_count()} CPUs. `python benchmarks/symbolic.py --answers "
        f"{arguments.answers} --sympy-sample {arguments.sympy_sample}`; in process; ours and sympy alternated, "
        f"{ROUNDS} rounds, medians. Load average (1/5/15 min) before, after the rounds, at the end: "
        + ", ".join("/".join(f"{x:.2f}" for x in load) for load in loads) + ".",
        "",
        f"{len(pairs):,} distinct honest answers graded (read, refused functions, compared) in {seconds:.2f} s "
        f"(median of the rounds), {each * 1e3:.3f} ms each; rounds: "
        + ", ".join(f"{ours_each * 1e3:.3f}" for ours_each, _, _ in rounds) + " ms; last round's verdicts: "
        + ", ".join(f"{n:,} {k}" for k, n in sorted(verdicts.items())) + ".",
        "",
        f"With the cyclic collector paused, as `grader grade` grades (`grader.base.heap`), not counted against the "
        f"target below: {arguments.answers:,} other distinct honest answers in {paused_seconds:.2f} s, "
        f"{paused_seconds / arguments.answers * 1e3:.3f} ms each.",
        "",
        f"{arguments.answers:,} answers of {len(distinct):,} distinct texts (a class repeats itself; grade reads "
        f"each distinct text once): {repeated_seconds:.2f} s, {repeated_each * 1e3:.3f} ms an answer.",
        "",
        "| baseline (per answer, on a sample of " + f"{arguments.sympy_sample})" + " | sympy | ours | ratio | target |",
        "| --- | --: | --: | --: | --- |",
        *(f"| {name} vs ours, {label} | {baseline * 1e3:.2f} ms | {ours_each * 1e3:.3f} ms | "
          f"{baseline / ours_each:,.0f}x faster | >= 100x: {'met' if baseline / ours_each >= 100 else 'NOT met'} |"
          for name, baseline in rows
          for label, ours_each in (("every answer distinct", each), ("a quarter distinct", repeated_each))),
        "",
        f"Adversarial answers (`tests/test_symbolic_gaming.py`): {listed}, graded in {adversarial_seconds:.2f} s; "
        + ", ".join(f"{n} {k}" for k, n in sorted(found.items()))
        + f". None correct: {'met' if passed == 0 else 'NOT met'}.",
    ]
    RESULTS.write_text("\n".join(lines) + "\n", encoding="utf-8")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
