"""Blocks of equations solved together: the head-on impact asked the other way round (cart 1's velocity before
and cart 2's after, from e, cart 2's velocity before and cart 1's rebound), a 2x2 linear system a textbook
solves "simultaneously"; a block with no single solution refused, naming why."""

from __future__ import annotations

from fractions import Fraction
from pathlib import Path

import pytest
import sympy as sp
import yaml

from grader.assign.variants import ProblemVariant
from grader.bank.template import Template, load_bank, parse_template
from grader.base.errors import TemplateError
from grader.cli import main
from grader.render.worked import worked
from grader.solve.cache import compiled_for
from grader.solve.compiled import Compiled
from grader.solve.evaluate import solve_one
from grader.solve.solver import compile_template
from tests.scene_edits import answered, draws, swapped

DATA = Path(__file__).parent / "data"


@pytest.fixture(scope="module")
def head_on_before() -> tuple[Template, Compiled]:
    raw = yaml.safe_load((DATA / "head-on-before.yaml").read_text())
    template = parse_template(raw, "test:head-on-before", "head-on-before")
    return template, compile_template(template)


def _exact(printed: dict[str, str]) -> dict[str, Fraction]:
    """The textbook's two equations, momentum (a) and restitution (b), solved exactly for the printed numbers."""
    m1, m2, v2, e, v1_out = (sp.Rational(printed[n]) for n in ("m1", "m2", "v2", "e", "v1_out"))
    v1, v2_out = sp.symbols("v1 v2_out")
    roots = sp.solve([sp.Eq(m1 * v1 + m2 * v2, m1 * v1_out + m2 * v2_out),
                      sp.Eq(e * (v1 - v2), v2_out - v1_out)], [v1, v2_out], dict=True)
    assert len(roots) == 1
    return {"v1": roots[0][v1], "v2_out": roots[0][v2_out]}


def test_the_two_unknowns_are_solved_together(head_on_before: tuple[Template, Compiled]) -> None:
    """v1 and the impulse come from one block of two equations, then v2_out from one equation."""
    _, compiled = head_on_before
    blocks = [step.block for step in compiled.steps]
    assert blocks[:2] == [("v1", "J"), ("v1", "J")] and not blocks[2]
    assert compiled.steps[2].unknown == "v2_out"


def test_answers_agree_with_the_exact_simultaneous_solution(head_on_before: tuple[Template, Compiled]) -> None:
    """On 60 sampled variants, every answer matches the exact solution of momentum and restitution to 1e-12."""
    template, compiled = head_on_before
    rows = draws(template, 60)
    result = answered(template, compiled, rows)
    checked = 0
    for row, refusal in zip(rows, result.refusals, strict=True):
        assert refusal is None, (row, refusal)
        exact = _exact(row)
        index = rows.index(row)
        for name, value in exact.items():
            assert float(result.values[name][index]) == pytest.approx(float(value), rel=1e-12, abs=1e-12)
        checked += 1
    assert checked == 60


def test_the_worked_solution_shows_the_simultaneous_step(head_on_before: tuple[Template, Compiled]) -> None:
    """The equations labelled (a) and (b), then "simultaneous solution of (a) and (b) gives", with the numbers."""
    template, compiled = head_on_before
    printed = {name: str(value) for name, value in template.example.items()}
    variant = ProblemVariant("1", template.id, "x", dict(template.example), printed, ())
    steps = worked(template, variant, compiled).steps
    assert str(steps[0].relation).startswith('#"(a) ";') and str(steps[1].relation).startswith('#"(b) ";')
    assert steps[0].equation and steps[1].equation and steps[0].chain == steps[1].chain == ()
    assert [str(step.relation) for step in steps[2:4]] == ['#"simultaneous solution of (a) and (b) gives";'] * 2
    v1 = steps[2].chain
    assert v1[0] == "v_1" and v1[-1] == '3.339 thin "m/s"'  # 10.35/3.1 for the example's numbers
    assert "1.5 dot (-5.0)" in v1[2]  # the variant's numbers substituted


def test_a_block_that_fixes_nothing_at_a_draw_refuses_it(head_on_before: tuple[Template, Compiled]) -> None:
    """Where m1 = e m2 and cart 1 rebounds at cart 2's velocity, any velocity before fits: the draw is refused
    with the reason, never answered with a quotient of roundings."""
    template, compiled = head_on_before
    solution = solve_one(template, compiled, {"m1": 1.0, "m2": 2.0, "v2": -5.0, "e": 0.5, "v1_out": -5.0})
    assert solution.answers is None
    assert "do not fix v1, J for these values" in (solution.error or "")


def test_two_solutions_nothing_tells_apart_are_refused_naming_both() -> None:
    """Given the height at which the ball strikes the wall, the time of flight is a root of a quadratic: rising
    at some draws, falling at others, and nothing in the scene says which; the refusal names both times."""
    template = load_bank()["wall-throw"]
    raw = yaml.safe_load(Path(template.where).read_text())
    forward = solve_one(template, compiled_for(template), template.example).answers
    assert forward is not None
    turned = swapped(raw, template, "y_hit", "D", [0.5, 5.0], float(forward["y_hit"].value or 0))
    with pytest.raises(TemplateError, match="two physical solutions that nothing in it") as error:
        compile_template(parse_template(turned, "test:turned", "turned"))
    # Independently: h0 + v_y t - g t²/2 = y_hit at the example (v0 = 15 m/s at 25°, h0 = 1.5 m), both roots.
    t = sp.symbols("t")
    v_y, g = 15 * sp.sin(sp.pi * 25 / 180), sp.Rational(981, 100)
    y_hit = sp.Float(forward["y_hit"].value, 17)
    times = sorted(float(r) for r in sp.solve(sp.Rational(3, 2) + v_y * t - g * t**2 / 2 - y_hit, t))
    assert f"which give t_1 = {times[0]:.6g} or t_1 = {times[1]:.6g} (SI) at " in str(error.value)


@pytest.mark.slow
def test_a_velocity_before_from_the_energy_lost_is_refused_naming_both_roots() -> None:
    """Given the share of energy lost, cart 1's velocity before is a root of a quadratic: both roots are
    collisions (the template's constraint on it went with it), and the refusal names them (a 3x3 block,
    some seconds of sympy)."""
    template = load_bank()["head-on"]
    raw = yaml.safe_load(Path(template.where).read_text())
    forward = solve_one(template, compiled_for(template), template.example).answers
    assert forward is not None
    turned = swapped(raw, template, "loss_pct", "v1", [10.0, 40.0], float(forward["loss_pct"].value or 0))
    with pytest.raises(TemplateError, match="two physical solutions that nothing in it") as error:
        compile_template(parse_template(turned, "test:turned", "turned"))
    # The example's own v1 (4 m/s) and the quadratic's other root, 16/7, both collisions (v1 > v2 = -2).
    assert ("which give v1 = 4 or v1 = 2.28571 (SI) at e = 0.6, f_loss = 0.628364, m1 = 2, m2 = 3, v2 = -2"
            in str(error.value))


def test_show_says_which_steps_are_solved_together(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """`grader show` marks a block before its first step."""
    (tmp_path / "head-on-before.yaml").write_text((DATA / "head-on-before.yaml").read_text(), encoding="utf-8")
    assert main(["show", "head-on-before", "--bank", str(tmp_path)]) == 0
    chain = capsys.readouterr().out.split("Step chain")[1].splitlines()
    assert chain[1] == "  (steps 1-2: these equations solved together for v1, J)"
    assert chain[2].startswith("  1. impulse along n")



def test_a_condition_that_always_holds_once_a_block_is_solved_is_dropped_not_refused() -> None:
    """incline-slide asked the other way round (the speed up the slope from the speed back): the slope's
    condition reduces, once the block is solved, to positive factors only (sympy's ``True``); it was refused
    as "a value that is a function no expression may call". Now it round-trips to 1e-9 on its variants."""
    from tests.test_inverse_walk import VARIANTS, round_trips

    (trip,) = round_trips(load_bank()["incline-slide"], {("v_back", "v0")})
    assert trip.refusal is None and trip.rows == VARIANTS and not trip.bad, trip
