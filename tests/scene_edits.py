"""Shipped templates rewritten as another author might have written the same scene, for the tests that
hold the solver to the scene and not to how it is written: the bodies and stages in reverse, and a
template turned round (an answer given, a parameter asked)."""

from __future__ import annotations

import copy
from collections.abc import Mapping
from typing import Any

import numpy as np

from grader.assign.assignment import Assignment, ProblemSpec
from grader.assign.variants import ProblemDraws, variant_generator
from grader.bank.template import Template
from grader.solve.evaluate import Columns, solve_columns


def _negated(value: Any) -> Any:
    """A velocity along n seen along the opposite n: ``-(v)``, or ``{n: -(v_n), t: v_t}``."""
    if isinstance(value, Mapping):
        return {**value, "n": f"-({value['n']})"} if "n" in value else dict(value)
    return f"-({value})"


def reversed_scene(raw: Mapping[str, Any]) -> dict[str, Any]:
    """The same scene written the other way round: the bodies and the stages listed in reverse, and each
    impact's two bodies swapped, which turns its n (from the first body into the second) round, so every
    velocity along n it is given or names is written with its sign turned. The quantities keep their names
    and meanings, so the answers are the same."""
    result = copy.deepcopy(dict(raw))
    result["bodies"] = dict(reversed(list(raw["bodies"].items())))
    stages = []
    for stage in reversed(raw["stages"]):
        stage = copy.deepcopy(dict(stage))
        movable = all(raw["bodies"][body].get("mass") is not None for body in stage.get("bodies", ()))
        if stage["effect"] == "impact" and movable:  # a fixed body is listed second, however the author writes
            stage["bodies"] = list(reversed(stage["bodies"]))
            for when in ("before", "after"):
                if when in stage:
                    stage[when] = {body: _negated(value) for body, value in stage[when].items()}
        stages.append(stage)
    result["stages"] = stages
    return result


def draws(template: Template, count: int, seed: str = "scene-edits") -> list[dict[str, str]]:
    """``count`` draws of a template's parameters, printed as a sheet prints them (as check-bank draws)."""
    problem = ProblemSpec("1", template.id, {"*": 1.0}, {}, {}, {})
    assignment = Assignment(template.where, "tests", "", seed, "", "", (problem,))
    drawer = ProblemDraws(assignment, problem, template)
    rng, _ = variant_generator(seed, template.id, "draws")
    return [drawer.draw_row(rng) for _ in range(count)]


def answered(template: Template, compiled: Any, rows: list[dict[str, str]]) -> Columns:
    """The answers of ``template`` (compiled as ``compiled``) for the printed rows."""
    table = {name: np.array([float(row[name]) for row in rows]) for name in template.parameters}
    return solve_columns(template, compiled, table)


def swapped(raw: Mapping[str, Any], template: Template, answer: str, parameter: str,
            values: Any, example: float) -> dict[str, Any]:
    """``raw`` turned round: the quantity ``answer`` names becomes a given (its forward ``values`` set its
    sampling and domain, ``example`` its example) and ``parameter`` the one thing asked. Constraints on
    ``parameter`` go with it; the statement only prints the givens."""
    quantity = template.answers[answer].value.name  # a bare quantity (the caller checks)
    result = copy.deepcopy(dict(raw))
    given = dict(raw["parameters"][parameter])
    parameters = {name: spec for name, spec in raw["parameters"].items() if name != parameter}
    low, high = float(np.min(values)), float(np.max(values))
    domain = "(0, inf)" if low > 0 else "(-inf, 0)" if high < 0 else "(-inf, inf)"
    parameters[quantity] = {"unit": template.answers[answer].unit.text, "domain": domain,
                            "sample": {"uniform": [low, high] if low < high else [low, low + abs(low) + 1]},
                            "sig_figs": 6, "description": f"the forward answer {answer}"}
    result["parameters"] = parameters
    result["constraints"] = [c for c in raw.get("constraints", []) if parameter not in str(c["require"])]
    result["answers"] = {parameter: {"value": parameter, "unit": given["unit"], "description": given["description"]}}
    result["statement"] = "Given " + ", ".join(f"{{{{ {name} }}}}" for name in parameters) + "."
    result["example"] = {**{name: value for name, value in raw.get("example", {}).items() if name != parameter},
                         quantity: example}
    return result
