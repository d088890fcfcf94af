"""The step chain: one equation and one new unknown per step, across stages, forward and inverse."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
import sympy as sp
import yaml

from grader.bank.template import Template, parse_template
from grader.model.expr import names
from grader.solve.compiled import Compiled
from grader.solve.evaluate import solve_one
from grader.solve.solver import compile_template
from tests.scenes import TWO_BOUNCES


@pytest.fixture(scope="module")
def two_bounces() -> tuple[Template, Compiled]:
    template = parse_template(yaml.safe_load(TWO_BOUNCES), "test:two-bounces", "two-bounces")
    return template, compile_template(template)


def test_second_bounce_height_is_e_to_the_fourth_times_the_drop(two_bounces: tuple[Template, Compiled]) -> None:
    """Each bounce keeps e**2 of the height: h2 = e**4 h_drop; each impact loses 1 - e**2."""
    template, compiled = two_bounces
    solution = solve_one(template, compiled, {"h_drop": 2.0, "e": 0.8, "J": 0.25})
    assert solution.answers is not None, solution.error
    assert solution.answers["h2"].value == pytest.approx(0.8**4 * 2.0, rel=1e-14)
    assert solution.answers["f2"].value == pytest.approx(1 - 0.8**2, rel=1e-14)
    assert solution.answers["J_plus_h2"].value == pytest.approx(0.25 + 0.8**4 * 2.0, rel=1e-14)


def test_default_names_never_collide_with_the_templates_or_each_other(
        two_bounces: tuple[Template, Compiled]) -> None:
    """A parameter named J keeps its name; the two impacts' impulses get distinct names."""
    _, compiled = two_bounces
    unknowns = [step.unknown for step in compiled.steps]
    assert "J" not in unknowns
    assert len(unknowns) == len(set(unknowns))


def test_each_step_solves_one_equation_for_one_new_unknown(two_bounces: tuple[Template, Compiled],
                                                           compiled: dict[str, Compiled],
                                                           bank: dict[str, Template]) -> None:
    """A step's equation uses only what is known by then, plus the one unknown it solves for; a block's
    equations use only what is known before it, plus the block's unknowns, and its steps follow one another.
    Two shipped templates need a block: head-on-approach (cart 1's velocity before, from its rebound), and
    billiards-inverse (e from the cue ball's turned path), whose block is torn: e is solved numerically from what
    is known, and the block's other unknowns follow from it as steps of their own."""
    cases = [two_bounces, *((bank[t], compiled[t]) for t in bank)]
    with_blocks = set()
    for template, chain in cases:
        known = set(template.parameters) | set(template.symbols) | {"g"}
        steps = list(chain.steps)
        index = 0
        while index < len(steps):
            step = steps[index]
            if step.block:
                with_blocks.add(template.id)
            if step.numeric:  # the torn block's one numeric root, from what is known before it
                assert step.unknown in step.block and names(step.solved) <= known, (template.id, step)
                known.add(step.unknown)
                index += 1
                continue
            if step.block:
                size = len(step.block)
                together = steps[index:index + size]
                assert [s.unknown for s in together] == list(step.block), (template.id, step)
                assert all(s.block == step.block for s in together), (template.id, step)
                for member in together:
                    used = names(member.equation[0]) | names(member.equation[1])
                    assert used <= known | set(step.block), (template.id, member)
                    assert names(member.solved) <= known, (template.id, member)
                known |= set(step.block)
                index += size
                continue
            used = names(step.equation[0]) | names(step.equation[1])
            assert step.unknown in used, (template.id, step)
            assert used - known == {step.unknown}, (template.id, step)
            assert names(step.solved) <= known, (template.id, step)
            known.add(step.unknown)
            index += 1
    assert with_blocks == {"head-on-approach", "billiards-inverse"}


def test_a_block_s_steps_follow_one_another_and_use_what_is_known_before_it() -> None:
    """The head-on impact asked the other way round: (a) and (b) together give v1 and J from what is given."""
    raw = yaml.safe_load((Path(__file__).parent / "data" / "head-on-before.yaml").read_text())
    template = parse_template(raw, "test:head-on-before", "head-on-before")
    steps = compile_template(template).steps
    known = set(template.parameters)
    block = set(steps[0].block)
    assert block == {"v1", "J"} and [step.unknown for step in steps[:2]] == list(steps[0].block)
    for step in steps[:2]:
        assert step.block == steps[0].block
        assert names(step.equation[0]) | names(step.equation[1]) <= known | block
        assert names(step.solved) <= known


def test_inverse_template_derives_e_from_the_heights(compiled: dict[str, Compiled]) -> None:
    """drop-rebound gives e = sqrt(h_rebound/h_drop) through the rebound velocity, as a student would."""
    steps = {step.unknown: step for step in compiled["drop-rebound"].steps}
    assert steps["e"].relation.startswith("coefficient of restitution")
    assert names(steps["e"].solved) == {"v_after", "v_impact"}


def test_forward_and_inverse_from_one_scene() -> None:
    """Swapping which quantities are given turns the same scene around (no formula is rewritten):
    from the first bounce's height, e and then the second bounce follow."""
    raw = yaml.safe_load(TWO_BOUNCES)
    raw["parameters"]["h1"] = raw["parameters"].pop("e") | {"domain": "(0, inf)", "unit": "m"}
    del raw["parameters"]["J"]  # no answer here uses it (an unused parameter is refused)
    raw["answers"] = {"e": {"value": "e", "unit": ""}, "h2": {"value": "h2", "unit": "m"}}
    raw["statement"] = "Dropped from {{ h_drop }} m, the first bounce reaches {{ h1 }} m."
    inverse = parse_template(raw, "test:inverse", "inverse")
    solution = solve_one(inverse, compile_template(inverse), {"h_drop": 2.0, "h1": 0.8**2 * 2.0})
    assert solution.answers is not None, solution.error
    assert math.isclose(solution.answers["e"].value, 0.8, rel_tol=1e-14)
    assert math.isclose(solution.answers["h2"].value, 0.8**4 * 2.0, rel_tol=1e-14)


def test_coupled_unknowns_with_no_closed_form_are_solved_numerically() -> None:
    """Given only the second bounce, e appears in both impacts with h1 between them, through square roots of
    heights: no block of the equations is polynomial (it was refused as "nothing fixes e"). Torn at e, it is
    one equation in e, solved numerically: the second bounce is h_drop e^4, so e = (h2/h_drop)^(1/4)."""
    raw = yaml.safe_load(TWO_BOUNCES)
    raw["parameters"]["h2"] = raw["parameters"].pop("e") | {"domain": "(0, inf)", "unit": "m"}
    del raw["parameters"]["J"]  # no answer here uses it (an unused parameter is refused)
    raw["answers"] = {"e": {"value": "e", "unit": ""}}
    raw["statement"] = "Dropped from {{ h_drop }} m, the second bounce reaches {{ h2 }} m."
    template = parse_template(raw, "test:coupled", "coupled")
    compiled = compile_template(template)
    assert [step.unknown for step in compiled.steps if step.numeric] == ["e"]
    for h_drop, h2 in [("2", "0.8192"), ("1.5", "0.01"), ("1.25", "1.2")]:
        solution = solve_one(template, compiled, {"h_drop": float(h_drop), "h2": float(h2)})
        assert solution.answers is not None, solution.error
        exact = (sp.Rational(h2) / sp.Rational(h_drop)) ** sp.Rational(1, 4)
        assert math.isclose(solution.answers["e"].value, float(exact), rel_tol=1e-14)
