"""The textbook's printed answers (tests/data/golden-answers.yaml, with its provenance) reproduced to 3 significant
figures."""

from __future__ import annotations

from pathlib import Path

import pytest
import sympy as sp
import yaml

from grader.bank.template import Template
from grader.solve.compiled import Compiled
from grader.solve.evaluate import solve_one

GOLDEN_FILE = Path(__file__).resolve().parent / "data" / "golden-answers.yaml"
GOLDEN = yaml.safe_load(GOLDEN_FILE.read_text(encoding="utf-8"))
CASES = [(template_id, name, value) for template_id, case in GOLDEN.items()
         for name, value in case["answers"].items()]


def _three_significant_figures(value: float) -> float:
    return float(f"{value:.3g}")


@pytest.mark.parametrize(("template_id", "answer", "printed"), CASES, ids=[f"{t}.{a}" for t, a, _ in CASES])
def test_textbook_answer_is_reproduced(template_id: str, answer: str, printed: float | str,
                                       bank: dict[str, Template], compiled: dict[str, Compiled]) -> None:
    """Each printed answer: numbers agree to the printed figures, expressions are equivalent."""
    solution = solve_one(bank[template_id], compiled[template_id], GOLDEN[template_id]["params"])
    assert solution.error is None
    got = solution.answers[answer].value
    if isinstance(printed, str):
        assert isinstance(got, str)
        names = {n: sp.Symbol(n) for n in ("p", "v")}
        assert sp.simplify(sp.sympify(got, locals=names) - sp.sympify(printed, locals=names)) == 0
    else:
        assert isinstance(got, float)
        figures = len(str(printed).replace(".", "").lstrip("0"))
        assert float(f"{got:.{max(figures, 3)}g}") == pytest.approx(printed, rel=1e-12), (got, printed)
        assert _three_significant_figures(got) == _three_significant_figures(printed)


def test_every_seed_template_has_a_golden_case(bank: dict[str, Template]) -> None:
    """The golden file covers the five seed templates, by their required ids."""
    assert set(GOLDEN) == {"drop-rebound", "car-collision", "pile-driver", "ball-plate", "oblique-spheres"}
    assert set(GOLDEN) <= set(bank)
