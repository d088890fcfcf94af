"""Blocks of equations with no closed form, solved numerically in the kernels (issue 24): Sample Problem 3/29
asked the other way round, where the speed before ties e to the normal component through a square root of a
sum of squares, checked against mpmath's findroot at 50 digits on the textbook's two equations; a question
with two physical answers refused naming both; the root finder itself."""

from __future__ import annotations

from pathlib import Path

import mpmath as mp
import numpy as np
import pytest
import yaml

from grader.assign.variants import ProblemVariant
from grader.bank.template import Template, parse_template
from grader.base.errors import ExpressionError, TemplateError
from grader.model.expr import ROOT, Num, Op, Sym, from_json, names, parse, to_json
from grader.model.kernel import Kernel, evaluate
from grader.model.roots import find_root
from grader.render.worked import worked
from grader.solve.compiled import Compiled
from grader.solve.solver import compile_template
from tests.scene_edits import answered, draws

DATA = Path(__file__).parent / "data"


@pytest.fixture(scope="module")
def rebound_inverse() -> tuple[Template, Compiled]:
    raw = yaml.safe_load((DATA / "rebound-inverse.yaml").read_text())
    template = parse_template(raw, "test:rebound-inverse", "rebound-inverse")
    return template, compile_template(template)


def _first_principles(printed: dict[str, str]) -> tuple[mp.mpf, mp.mpf]:
    """The angle in (degrees) and e, from the textbook's two equations at 50 digits: the tangential component
    is unchanged, ``v cos(theta) = v' cos(theta')``, and the normal one is e times it, ``e v sin(theta) = v'
    sin(theta')`` (mpmath's findroot on both at once, from a guess in the middle of the sampling)."""
    with mp.workdps(50):
        v, v_out = mp.mpf(printed["v"]), mp.mpf(printed["v_out"])
        theta_out = mp.radians(mp.mpf(printed["theta_out"]))
        theta, e = mp.findroot(lambda t, c: [v * mp.cos(t) - v_out * mp.cos(theta_out),
                                             c * v * mp.sin(t) - v_out * mp.sin(theta_out)],
                               (mp.mpf("0.8"), mp.mpf("0.5")))
        return mp.degrees(theta), e


def test_the_block_is_torn_and_solved_numerically(rebound_inverse: tuple[Template, Compiled]) -> None:
    """e and v_n are found together: e from the speed before, a residual of e alone once v_n is written in it;
    the compiled answer holds the root(...) tree the kernels evaluate."""
    _, compiled = rebound_inverse
    numeric = [step for step in compiled.steps if step.numeric]
    assert [(step.unknown, step.block) for step in numeric] == [("e", ("e", "v_n"))]
    answer = compiled.answers["e"].numeric
    assert isinstance(answer, Op) and answer.op == ROOT and names(answer) == {"v", "v_out", "theta_out"}
    assert any("solved numerically (to 1e−15)" in check.message for check in compiled.checks)


def test_answers_agree_with_mpmath_on_the_textbook_equations(rebound_inverse: tuple[Template, Compiled]) -> None:
    """On 60 sampled variants the angle and e agree with the 50-digit solution to 1e-12 relative."""
    template, compiled = rebound_inverse
    rows = draws(template, 60)
    result = answered(template, compiled, rows)
    for index, row in enumerate(rows):
        assert result.refusals[index] is None, (row, result.refusals[index])
        theta, e = _first_principles(row)
        assert result.values["theta"][index] == pytest.approx(float(theta), rel=1e-12)
        assert result.values["e"][index] == pytest.approx(float(e), rel=1e-12)


def test_the_worked_solution_says_it_was_solved_numerically(rebound_inverse: tuple[Template, Compiled]) -> None:
    """(a) and (b) are written out, then "solved together numerically (to 1e−15, relative)" gives e, and v_n
    follows from (b) with the numbers."""
    template, compiled = rebound_inverse
    printed = {name: str(value) for name, value in template.example.items()}
    variant = ProblemVariant("1", template.id, "x", dict(template.example), printed, ())
    steps = worked(template, variant, compiled).steps
    relations = [str(step.relation) for step in steps]
    first = next(i for i, relation in enumerate(relations) if relation.startswith('#"(a) ";'))
    assert relations[first + 1].startswith('#"(b) ";') and steps[first].equation == "v = sqrt(v_n^2 + v_t^2)"
    assert relations[first + 2] == '#"(a) and (b) solved together numerically (to 1e−15, relative) give";'
    theta, e = _first_principles(printed)
    assert steps[first + 2].chain == ("e", f"{float(e):.4g}")
    assert steps[-1].chain[0] == "theta" and steps[-1].chain[-1] == f"{float(theta):.4g} degree"


def test_two_physical_answers_are_refused_naming_both() -> None:
    """Given e instead of the rebound's angle, the speeds fix the angle only up to its supplement: a ball coming
    in at theta or at 180° - theta rebounds at the same speed, and nothing in the scene tells them apart."""
    raw = yaml.safe_load((DATA / "rebound-inverse.yaml").read_text())
    raw["parameters"]["e"] = {"unit": "", "domain": "[0, 1]", "sample": {"uniform": [0.3, 0.7]}, "decimals": 2,
                              "description": "effective coefficient of restitution"}
    del raw["parameters"]["theta_out"]
    raw["answers"] = {"theta": raw["answers"]["theta"]}
    raw["example"] = {"v": 12, "v_out": 8.5, "e": 0.5}
    raw["statement"] = "A ball strikes a plate at {{ v }} m/s and leaves it at {{ v_out }} m/s; e = {{ e }}."
    with pytest.raises(TemplateError, match="two physical solutions that nothing in it") as error:
        compile_template(parse_template(raw, "test:rebound-two", "rebound-two"))
    # v'^2 = v^2 (cos^2 theta + e^2 sin^2 theta), so sin^2 theta = (v^2 - v'^2)/(v^2 (1 - e^2)).
    with mp.workdps(30):
        theta = mp.asin(mp.sqrt((12**2 - mp.mpf("8.5") ** 2) / (12**2 * (1 - mp.mpf("0.5") ** 2))))
        one, other = float(theta), float(mp.pi - theta)
    assert f"which give theta = {one:.6g} or theta = {other:.6g} (SI) at e = 0.5, m = 1, v = 12, v_out = 8.5" \
        in str(error.value)


def test_the_root_finder_names_one_root_or_none() -> None:
    """One root in the interval: found to the last bits; two (cos on [-4, 4]): NaN; a sign change across a pole
    (tan at 90°) is no root."""
    c = np.array([0.5, 1.0, 2.0])
    root = find_root(lambda x, rows: np.tan(x) - c[rows], 0.0, 3.0, 3)
    assert np.allclose(root, np.arctan(c), rtol=4e-16, atol=0)
    assert np.isnan(find_root(lambda x, rows: np.cos(x) + 0 * rows, -4.0, 4.0, 1)).all()
    wide = find_root(lambda x, rows: x * x - np.array([1e-6, 4e10])[rows], 0.0, 1e12, 2)
    assert wide.tolist() == [1e-3, 2e5]


def test_a_root_tree_is_evaluated_alike_by_the_kernel_and_the_tree_walk() -> None:
    """Kernel and evaluate agree to the bit on long columns (the kernel's blocks), the tree keeps its bound name
    out of the names it uses, survives JSON, and no student or template can write it."""
    tree = Op(ROOT, (parse("cos(x) - c*x"), Sym("x"), Num(0.0), Num(2.0)))
    c = np.linspace(0.1, 3.0, 5000)
    by_kernel = Kernel({"a": Op("mul", (tree, Sym("k")))})({"c": c, "k": 2.0})["a"]
    assert np.array_equal(by_kernel, 2.0 * evaluate(tree, {"c": c}))
    assert names(tree) == {"c"} and from_json(to_json(tree)) == tree
    with pytest.raises(ValueError, match="not an expression tree"):
        from_json([ROOT, "x", ["add", "a", "b"], {"f": 0.0}, {"f": 1.0}])
    with pytest.raises(ExpressionError, match="'root' is not an allowed function"):
        parse("root(x - 1, x, 0, 2)")
