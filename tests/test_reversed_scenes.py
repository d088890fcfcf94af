"""The numbers do not depend on how a scene is written: every shipped template with its bodies and stages
listed in reverse, and each impact's two bodies swapped (its n turned round, the velocities along n written
with their signs turned; a fixed body stays second, as the scene parser asks), gives the same answers to
1e-12 and refuses the same draws (its first reason may be another of the scene's conditions). The whole bank
is slow; the templates where the order matters most (a bullet embedding in a block, two carts, a ram on a
pile) run by default."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
import yaml

from grader.bank.template import Template, load_bank, parse_template
from grader.solve.cache import compiled_for
from grader.solve.solver import compile_template
from tests.scene_edits import answered, draws, reversed_scene

DRAWS = 200


def _same_either_way(template: Template) -> None:
    raw = yaml.safe_load(Path(template.where).read_text())
    turned = parse_template(reversed_scene(raw), f"test:{template.id}:reversed", template.id)
    rows = draws(template, DRAWS)
    forward = answered(template, compiled_for(template), rows)
    backward = answered(turned, compile_template(turned), rows)
    # The same draws are refused; the reason given first may differ (the checks follow the stages' order).
    assert [r is None for r in forward.refusals] == [r is None for r in backward.refusals], template.id
    usable = [i for i, reason in enumerate(forward.refusals) if reason is None]
    assert usable, template.id
    for name, values in forward.values.items():
        assert forward.undefined[name] == backward.undefined[name], (template.id, name)
        for i in usable:
            if forward.undefined[name][i] is None:
                assert math.isclose(values[i], backward.values[name][i], rel_tol=1e-12, abs_tol=1e-300), \
                    (template.id, name, rows[i], values[i], backward.values[name][i])


@pytest.mark.parametrize("template_id", ["ballistic-pendulum", "coupling", "head-on", "pile-driver"])
def test_the_order_of_bodies_and_stages_changes_nothing(template_id: str) -> None:
    _same_either_way(load_bank()[template_id])


@pytest.mark.slow
def test_the_order_changes_nothing_in_the_whole_bank() -> None:
    for template in load_bank().values():
        _same_either_way(template)


@pytest.mark.parametrize("reverse", [False, True], ids=["bullet first", "block first"])
def test_the_common_speed_is_worked_out_by_momentum_whichever_body_is_listed_first(reverse: bool) -> None:
    """Issue 24: ``bodies: [bullet, block]`` showed the block's speed as ``v_b - J/m_b`` (400 - 398 m/s, the
    digits a student would lose) though the kernel used the stable form; the worked step is now the textbook's
    conservation of momentum, ``m_b v = (m_b + m_blk) v'``, either way round, with no impulse in it."""
    from grader.render.worked import worked_form
    from tests.test_bankcheck import BULLET_BLOCK

    raw = yaml.safe_load(BULLET_BLOCK)
    template = parse_template(reversed_scene(raw) if reverse else raw, "test:bullet-block", "bullet-block")
    compiled = compile_template(template)
    assert [step.unknown for step in compiled.steps] == ["v_block"]
    step = worked_form(template, compiled).steps[0]
    assert "conservation of momentum" in str(step.relation)
    assert step.solved_math == '(m_b v)/(m_b + m_"blk")' and "J" not in step.solved_math
