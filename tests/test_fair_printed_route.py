"""Fair rounding follows the printed route (issue 32): the rounding a tolerance allows for is the rounding a
student accumulates copying the worked solution's values as the page computes them, in its order.

Head-on's page finds the velocities after from momentum and restitution, then the impulse from one of them: a
reason on the key for a velocity after never names the impulse. Independently of the route machinery, a student
who walks the page's own steps (:func:`~grader.solve.textbook_steps.textbook_route`, each form evaluated as the
page evaluates it), rounds every value written down to the sheet's four figures and gives the answer to three
is marked right against the key's tolerance, over 200 variants of each template.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterator

import numpy as np
import pytest

from grader.assign.assignment import load_assignment, load_roster
from grader.assign.fair import display_name
from grader.assign.variants import Generation, ProblemVariant, generate
from grader.bank.template import Template
from grader.grade.compare import is_correct
from grader.model.expr import names
from grader.solve.cache import compiled_for, routes_for
from grader.solve.page_forms import page_value
from grader.solve.textbook_steps import textbook_route
from tests.test_fair import FIGURES, STUDENTS, _write_assignment

CHECKED = ("head-on", "coupling", "oblique-spheres", "pile-driver", "shell-landing", "billiards", "three-balls",
           "head-on-inverse", "drop-rebound", "ballistic-pendulum", "wall-throw")
_REASON = re.compile(rf"rounding (.+) to {FIGURES} figures along the worked solution moves (\w+) by up to ")


@pytest.fixture(scope="module")
def classes(bank: dict[str, Template], tmp_path_factory: pytest.TempPathFactory) -> Iterator[Generation]:
    """200 students, each with a variant of every checked template."""
    problems = [{"key": str(index + 1), "template": template_id} for index, template_id in enumerate(CHECKED)]
    assignment, roster = _write_assignment(tmp_path_factory.mktemp("printed-route"), problems)
    yield generate(load_assignment(assignment), load_roster(roster), bank)


def _printed_order(template: Template) -> list[str]:
    return [step.unknown for step in textbook_route(template, compiled_for(template)).steps]


def _written(reason_names: str) -> list[str]:
    """``T, J and v1_n′`` as the names they display."""
    return [n.strip() for n in re.split(r",| and ", reason_names) if n.strip()]


@pytest.mark.parametrize("template_id", CHECKED)
def test_the_worked_solutions_route_writes_down_the_pages_values_in_its_order(template_id: str,
                                                                             bank: dict[str, Template]) -> None:
    template = bank[template_id]
    order = _printed_order(template)
    compiled = compiled_for(template)
    numeric = {s.unknown for s in compiled.steps if s.numeric}
    for route in routes_for(template).items:
        if route.id != "chain" or numeric:
            continue
        assert set(route.names) <= set(order), (route.answer, route.names, order)
        positions = [order.index(name) for name in route.names]
        assert positions == sorted(positions), (route.answer, route.names, order)


def test_head_ons_velocity_after_is_not_moved_by_rounding_the_impulse_the_page_finds_after_it(
        bank: dict[str, Template]) -> None:
    routes = routes_for(bank["head-on"])
    assert _printed_order(bank["head-on"]).index("J") > _printed_order(bank["head-on"]).index("v1_out")
    for answer in ("v1_out", "v2_out"):
        for route in routes.for_answer(answer):
            assert "J" not in route.names, (answer, route.id, route.names)


def test_a_reason_names_only_values_the_page_computes_before_the_part(classes: Generation,
                                                                       bank: dict[str, Template]) -> None:
    """Every tolerance widened along the worked solution, over 200 students of each checked template, names values
    the page computes before the step that gives the part's answer."""
    reasons = 0
    for index, template_id in enumerate(CHECKED):
        template = bank[template_id]
        order = [display_name(name) for name in _printed_order(template)]
        for student in classes.students:
            for part in student.problems[index].answers:
                found = _REASON.match(part.tolerance.reason)
                if not found:
                    continue
                reasons += 1
                asked = names(template.answers[part.name].value)
                last = max(order.index(display_name(n)) for n in asked if display_name(n) in order)
                for written in _written(found.group(1)):
                    assert written in order[:last + 1], (template_id, part.name, part.tolerance.reason, order)
    assert reasons > 0


def _figures(values: np.ndarray, figures: int) -> np.ndarray:
    """Rounded to ``figures`` significant figures, by printing them (as a student copies a value down)."""
    return np.array([float(f"{v:.{figures - 1}e}") if math.isfinite(v) else v for v in values])


def _by_the_page(template: Template, variants: list[ProblemVariant], figures: int | None) -> dict[str, np.ndarray]:
    """Every answer (its unit) from the page's steps walked in order, each value written down rounded to ``figures``
    (None: kept exact); the parameters as printed, symbols without value at 1."""
    compiled = compiled_for(template)
    route = textbook_route(template, compiled)
    kernel_forms = {step.unknown: step.solved for step in compiled.steps}
    env: dict[str, object] = {**compiled.constants, **{s: np.ones(len(variants)) for s in template.symbols}}
    for name, parameter in template.parameters.items():
        env[name] = np.array([float(v.printed[name]) for v in variants]) * parameter.unit.to_si
    answers: dict[str, np.ndarray] = {}
    for step in route.steps:
        # a step the page writes tan⁻¹(y/x) shows the kernel's form where x < 0: its value is the kernel's form's
        form = kernel_forms[step.unknown] if step.unknown in route.positive else step.solved
        value = np.broadcast_to(np.asarray(page_value(form, env), dtype=float), (len(variants),))
        env[step.unknown] = value if figures is None else _figures(value, figures)
    for name, spec in template.answers.items():
        if not spec.symbolic:
            answers[name] = np.broadcast_to(np.asarray(page_value(spec.value, env), dtype=float),
                                            (len(variants),)) / spec.unit.to_si
    return answers


@pytest.mark.parametrize("position", range(len(CHECKED)))
def test_a_student_rounding_the_pages_values_to_four_figures_is_marked_right(position: int, classes: Generation,
                                                                            bank: dict[str, Template]) -> None:
    template = bank[CHECKED[position]]
    variants = [student.problems[position] for student in classes.students]
    exact = _by_the_page(template, variants, None)
    rounded = _by_the_page(template, variants, FIGURES)
    checked = 0
    for index, name in enumerate(part.name for part in variants[0].answers):
        if name not in rounded:
            continue
        unit = template.answers[name].unit.text
        for row, variant in enumerate(variants):
            key = variant.answers[index].value
            if not isinstance(key, float) or not math.isfinite(key):
                continue
            assert math.isclose(exact[name][row], key, rel_tol=1e-9, abs_tol=1e-12), (name, exact[name][row], key)
            given = _figures(np.array([rounded[name][row]]), 3)
            assert is_correct(given, np.array([key]), variant.answers[index].tolerance,
                              angle_unit="deg" if unit == "deg" else None)[0], \
                (template.id, name, given[0], key, variant.answers[index].tolerance)
            checked += 1
    assert checked >= STUDENTS

