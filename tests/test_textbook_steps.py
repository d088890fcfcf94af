"""The answer key's routes (issue 32): every shipped template's worked solution takes the route a textbook
takes, and every form on the page gives the kernel's value.

The values: for two students' variants of every shipped template, each step's form as the page prints it,
evaluated with the kernels' values of the quantities it uses, is the kernels' value of its quantity to 1e-9,
and each equation the page writes (a momentum balance, a restitution equation) holds at the kernels' values.
The forms: no page shows the impulse form with its reciprocal sums (``J = v(1 + e)/(1/m + 1/(p m))``), an
``atan2``, a double sign (``−(−3.072)``), a root of a square and a zero (``√(2.954² + 0²)``) or ``r + r``; a
bounce measured by its heights gives ``e = √(h′/h)`` (Problem 3/251); two bodies that both move after an
impact are worked with momentum and restitution as two labelled equations (Sample Problems 3/28–3/30); an
answer in a unit other than SI is converted in a step; an answer asked as an expression of steps is a step.
"""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from grader.assign.assignment import load_assignment, load_roster
from grader.assign.variants import ProblemVariant, generate
from grader.bank.template import Template, load_bank
from grader.base.resources import sample_dir
from grader.model.expr import Num, Sym, names, parse, substitute, to_text
from grader.model.kernel import evaluate
from grader.render.readable import readable
from grader.render.typst_math import math as typst_math
from grader.render.worked import answer_math, chain_values, reader_names, si_parameters, worked, worked_form
from grader.solve.cache import compiled_for
from grader.solve.page_forms import page_value
from grader.solve.textbook_steps import textbook_route

BANK = load_bank()
ORDER = sorted(BANK)


@pytest.fixture(scope="module")
def variants() -> dict[str, list[ProblemVariant]]:
    """Two students' variants of every shipped template (one problem per template)."""
    import dataclasses

    from grader.assign.assignment import ProblemSpec

    assignment = load_assignment(sample_dir() / "assignment.yaml")
    problems = tuple(ProblemSpec(str(k), template, {"*": 1.0}, {}, {}, {}) for k, template in enumerate(ORDER, 1))
    assignment = dataclasses.replace(assignment, problems=problems)
    generation = generate(assignment, load_roster(sample_dir() / "roster.csv")[:2], BANK)
    found: dict[str, list[ProblemVariant]] = {template: [] for template in ORDER}
    for entry in generation.students:
        for variant in entry.problems:
            found[variant.template].append(variant)
    return found


def _kernel_values(template: Template, variant: ProblemVariant, symbols: float = 1.0) -> dict[str, float]:
    """The kernels' values of every quantity (SI), the symbols without value at ``symbols``."""
    return chain_values(compiled_for(template), {**si_parameters(template, variant),
                                                 **{s: symbols for s in template.symbols}})


def _close(page: float, kernel: float) -> bool:
    return math.isclose(page, kernel, rel_tol=1e-9, abs_tol=1e-12 * max(1.0, abs(kernel)))


@pytest.mark.parametrize("template_id", ORDER)
def test_every_form_on_the_page_gives_the_kernels_value(template_id: str,
                                                        variants: dict[str, list[ProblemVariant]]) -> None:
    template = BANK[template_id]
    compiled = compiled_for(template)
    route = textbook_route(template, compiled)
    form = worked_form(template, compiled)
    chain = {step.unknown for step in compiled.steps}
    for variant in variants[template_id]:
        for symbols in (1.0, 2.0):  # a mass that cancels must cancel on the page too
            kernel = _kernel_values(template, variant, symbols)
            env = dict(kernel)
            for extra in route.extra:  # in order, as the page finds them: T′ from a t-velocity only the page names
                env[extra.unknown] = float(page_value(extra.solved, env))
            for step, shown in zip(route.steps, form.steps, strict=True):
                if step.numeric:
                    continue
                for tree in (step.solved, shown.solved):
                    if step.unknown in chain:
                        assert _close(float(page_value(tree, env)), kernel[step.unknown]), (template_id, step.unknown)
                lhs, rhs = (float(page_value(side, env)) for side in step.equation)
                assert _close(lhs, rhs), (template_id, step.relation, lhs, rhs)


@pytest.mark.parametrize("template_id", ORDER)
def test_no_page_shows_a_form_the_textbook_would_not(template_id: str,
                                                     variants: dict[str, list[ProblemVariant]]) -> None:
    forbidden = {
        "a reciprocal sum (the impulse form)": re.compile(r"(?:^|[\s(+])1/(?!\d)"),
        "atan2": re.compile(r"atan2"),
        "a double sign": re.compile(r"-\(-|- \(-|\+ \(-"),
        "a root of a square and a zero": re.compile(r"\^2 \+ 0\^2|(?<![\w.])0\^2 \+"),  # 6.0^2 is no zero
        "r + r": re.compile(r"(?<![\^\w])([A-Za-z]\w*) \+ \1\b"),
    }
    for variant in variants[template_id]:
        for step in worked(BANK[template_id], variant).steps:
            for part in (step.equation or "", *step.chain, str(step.relation)):
                for what, pattern in forbidden.items():
                    assert pattern.search(part) is None, (template_id, what, part)


TWO_MOVING = ["billiards", "car-collision", "head-on", "head-on-approach", "oblique-moving-spheres", "oblique-spheres",
              "offset-spheres", "package-bounce", "ramp-strike", "three-balls"]


@pytest.mark.parametrize("template_id", [t for t in TWO_MOVING if t in BANK])
def test_two_bodies_that_both_move_are_worked_with_momentum_and_restitution_solved_together(template_id: str) -> None:
    """Sample Problem 3/30: (a) momentum along n, (b) the restitution equation, then their simultaneous
    solution; no impulse step."""
    relations = [str(step.relation) for step in worked_form(BANK[template_id]).steps]
    assert any("conservation of momentum" in r for r in relations), template_id
    assert any("coefficient of restitution" in r for r in relations), template_id
    assert not any("impulse along n" in r or "impulse in the impact" in r for r in relations), (template_id, relations)


TOGETHER = [t for t in ORDER if any("move on together" in step.relation for step in compiled_for(BANK[t]).steps)]
"""Every shipped template with a plastic impact (the bodies move on together)."""


@pytest.mark.parametrize("template_id", TOGETHER)
def test_a_plastic_impact_opens_with_momentum_and_finds_the_impulse_from_it(template_id: str) -> None:
    """The cars move on together: m_A v_A + m_B v_B = (m_A + m_B) v′, then J = m_B (v′ − v_B) on B; no impulse
    form before the momentum balance."""
    steps = textbook_route(BANK[template_id], compiled_for(BANK[template_id])).steps
    balance = next(index for index, step in enumerate(steps) if "move on together" in step.relation)
    assert not any(step.relation.startswith("impulse along n") for step in steps), template_id
    impulses = [step for step in steps if step.unknown == "J"]
    for step in impulses:
        assert steps.index(step) > balance and step.relation.startswith("impulse-momentum for "), str(step)


def test_couplings_impulse_is_the_change_of_car_bs_momentum() -> None:
    steps = {s.unknown: s for s in textbook_route(BANK["coupling"], compiled_for(BANK["coupling"])).steps}
    assert "coupling" in TOGETHER and to_text(steps["J"].solved) == "m_B*(v_common - v_B)"
    assert steps["J"].relation == "impulse-momentum for B along n"


def test_a_fall_from_rest_is_the_root_of_2h_over_g_not_a_quadratic() -> None:
    steps = {s.unknown: s for s in textbook_route(BANK["shell-landing"], compiled_for(BANK["shell-landing"])).steps}
    assert to_text(steps["t_fall"].solved) == "sqrt(2*H/g)"
    assert "±" not in steps["t_fall"].relation and "0²" not in steps["t_fall"].relation
    # A's velocity after, with the mass it shares with the reduced mass cancelled: v_x − u m_B/(m_A + m_B) = 0
    assert to_text(steps["u_rel"].equation[1]) == "v_x - u_rel*m_B/(m_A + m_B)"
    assert to_text(steps["u_rel"].solved) == "v_x*(m_A + m_B)/m_B"


@pytest.mark.parametrize("template_id", ORDER)
def test_no_equation_is_labelled_in_two_blocks(template_id: str) -> None:
    """A block's equations are labelled once (billiards-inverse's momentum and restitution are the numeric block's
    (b) and (c), and their solution follows from it, not from a block of their own)."""
    steps = worked_form(BANK[template_id]).steps
    labelled = [str(member.relation) for index, step in enumerate(steps) if step.block and step.unknown == step.block[0]
                for member in steps[index:index + len(step.block)]]
    assert len(labelled) == len(set(labelled)), (template_id, labelled)


@pytest.mark.parametrize("template_id", ["pile-driver", "head-on-inverse", "ramp-strike-inverse"])
def test_a_velocity_after_from_the_others_is_conservation_of_momentum(template_id: str) -> None:
    """Sample Problem 3/28 (a): 800(6.26) + 0 = 800(−1.401) + 2400 v_p′, no impulse on the page but an impulse
    asked, after the momentum balance (pile-driver's, issue 27: the pile's change of momentum)."""
    steps = worked_form(BANK[template_id]).steps
    relations = [str(step.relation) for step in steps]
    asked = {getattr(spec.value, "name", None) for spec in BANK[template_id].answers.values()}
    assert any("conservation of momentum" in r for r in relations), relations
    impulses = [index for index, step in enumerate(steps) if "impulse-momentum" in str(step.relation)]
    assert all(steps[index].unknown in asked for index in impulses), relations
    momentum = next(i for i, r in enumerate(relations) if "conservation of momentum" in r)
    assert all(index > momentum for index in impulses), relations


@pytest.mark.parametrize(("template_id", "shown"), [("drop-rebound", 'e = sqrt(h_"rebound"/h_"drop")'),
                                                    ("two-rebounds", "e = sqrt(h_2/h_1)")])
def test_a_bounce_measured_by_its_heights_gives_e_as_the_root_of_their_ratio(template_id: str, shown: str) -> None:
    """Problem 3/251: e = v′/v = √(h′/h)."""
    steps = {step.unknown: step for step in worked_form(BANK[template_id]).steps if step.unknown == "e"}
    assert f"e = {steps['e'].solved_math}" == shown


def test_the_pile_drivers_momentum_balance_is_the_textbooks_with_its_numbers() -> None:
    """Sample Problem 3/28 (a): m_r v_r + 0 = m_r v_r′ + m_p v_p′ gives v_p′ = 2.55 m/s for 800 kg, 2400 kg, a drop of
    2 m and a rebound of 0.1 m (the textbook's answer, to its three figures)."""
    template = BANK["pile-driver"]
    printed = {"m_ram": "800", "m_pile": "2400", "h_drop": "2", "h_rebound": "0.1"}
    variant = ProblemVariant("1", template.id, "3/28", {n: float(v) for n, v in printed.items()}, printed, ())
    steps = {step.chain[0]: step for step in worked(template, variant).steps if step.chain}
    assert steps['v_"pile"'].equation == 'm_"ram" v_"ram" = m_"ram" v\'_"ram" + m_"pile" v_"pile"'
    assert steps['v_"pile"'].chain[-1].startswith("2.55")
    assert steps["e"].chain[-1].startswith("0.63")
    assert steps["J"].chain[1] == 'm_"pile" v_"pile"' and steps["J"].chain[-1].startswith("6132")


@pytest.mark.parametrize("template_id", ORDER)
def test_an_answer_in_a_unit_other_than_si_is_converted_in_a_step(template_id: str,
                                                                  variants: dict[str, list[ProblemVariant]]) -> None:
    template = BANK[template_id]
    variant = variants[template_id][0]
    steps = {step.chain[0]: step for step in worked(template, variant).steps if step.chain}
    for spec in template.answers.values():
        if not isinstance(spec.value, Sym) or spec.unit.text in ("", "deg") or spec.unit.to_si == 1.0:
            continue
        step = steps[typst_math(spec.value)]
        assert step.chain[-1].endswith(f'"{spec.unit.text}"'), (template_id, spec.name, step.chain)


@pytest.mark.parametrize("template_id", ORDER)
def test_an_answer_asked_as_an_expression_of_steps_is_a_step(template_id: str,
                                                            variants: dict[str, list[ProblemVariant]]) -> None:
    """Issue 32: two-rebounds' answer cell showed (E_lost,1 + E_lost,2)/T_0, which no step computed."""
    template = BANK[template_id]
    reader = reader_names(template, compiled_for(template))
    shown = {step.chain[0] for step in worked(template, variants[template_id][0]).steps if step.chain}
    for spec in template.answers.values():
        if isinstance(spec.value, Sym) or spec.symbolic:
            continue
        assert typst_math(readable(spec.value, reader)) in shown, (template_id, spec.name)


def test_a_symbolic_answer_is_derived_to_the_keys_expression(variants: dict[str, list[ProblemVariant]]) -> None:
    """Problem 3/255: the page solves momentum and restitution for v_A′ and v_B′ in terms of p and v; with e = 0.1
    that form is the book's answer at any p and v, and with a variant's e it is the key's answer, which the step
    then writes before the numbers go in."""
    template = BANK["car-collision"]
    forms = {step.unknown: step.solved for step in worked_form(template).steps}
    rng = np.random.default_rng(255)
    points = {"p": rng.uniform(0.1, 5, 16), "v": rng.uniform(-10, 10, 16), "m": rng.uniform(0.5, 5, 16)}
    textbook = {"vA_after": "v*(1 - 0.1*p)/(1 + p)", "vB_after": "1.1*v/(1 + p)"}  # the book's answers
    for quantity, answer in textbook.items():
        page = substitute(forms[quantity], {"e": Num(0.1)})
        assert np.allclose(evaluate(page, points), evaluate(parse(answer), points), rtol=1e-12)
    for variant in variants["car-collision"]:
        steps = {step.chain[0]: step for step in worked(template, variant).steps if step.chain}
        for part in variant.answers:
            spec = template.answers[part.name]
            if not spec.symbolic:
                continue
            assert isinstance(spec.value, Sym) and isinstance(part.value, str)
            page = substitute(forms[spec.value.name], {"e": Num(float(variant.printed["e"]))})
            assert np.allclose(evaluate(page, points), evaluate(parse(part.value), points), rtol=1e-12)
            assert answer_math(part.value, "") in steps[typst_math(spec.value)].chain


def test_billiards_finds_the_angle_from_its_sine_and_its_speeds_by_name() -> None:
    """θ = sin⁻¹(b/(2r)); the angle between the cue ball's velocities is cos⁻¹ of their dot product over the
    speeds, the speeds by their names; the object ball's speed is its one component's size."""
    steps = {step.unknown: step.solved_math for step in worked_form(BANK["billiards"]).steps}
    assert steps["theta"] == "sin^(-1)(b/(2 r))"
    assert steps["angle_cue"].startswith("cos^(-1)(") and steps["angle_cue"].endswith('/(v v_"cue"))')
    assert steps["v_obj"] == "abs(v'_(\"obj\", n))"


def test_the_contact_sheet_shows_a_worked_solution_of_every_effect_the_bank_uses() -> None:
    """docs/contact_sheet.py tiles one worked solution per effect (docs/images/worked-by-effect.png): a template
    with a new effect is listed there too."""
    import importlib.util
    from pathlib import Path

    path = Path(__file__).parent.parent / "docs" / "contact_sheet.py"
    spec = importlib.util.spec_from_file_location("contact_sheet", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    shown = {stage.effect for template in module.CHOSEN for stage in BANK[template].scene.stages}
    assert {stage.effect for template in BANK.values() for stage in template.scene.stages} <= shown


def test_an_angle_whose_inverse_is_not_the_principal_value_is_shown_with_the_kernels_atan2() -> None:
    """tan⁻¹(v_t/v_n) is the wreck's direction only while v_n > 0: with car B driving the other way (a draw no
    shipped range makes, written by hand), the page falls back to the kernel's atan2, and its value stays the
    kernel's (an obtuse angle)."""
    template = BANK["intersection-crash"]
    printed = {"m_A": "1500", "m_B": "1200", "v_A": "50", "v_B": "-60"}
    variant = ProblemVariant("1", template.id, "by hand", {n: float(v) for n, v in printed.items()}, printed, ())
    steps = {step.chain[0]: step for step in worked(template, variant).steps if step.chain}
    assert steps["theta"].chain[1].startswith('op("atan2")')
    kernel = _kernel_values(template, variant)["theta"]
    assert kernel > math.pi / 2 and steps["theta"].chain[-1] == f"{math.degrees(kernel):.1f} degree"  # 4 figures


@pytest.mark.parametrize("template_id", ["head-on", "pile-driver", "billiards"])
def test_the_route_gives_the_kernels_values_whichever_way_the_scene_is_written(template_id: str) -> None:
    """Bodies and stages listed in reverse and each impact's two bodies swapped (its n turned round): the page
    still works momentum and restitution, and each of its forms still gives the kernels' value."""
    from pathlib import Path

    import yaml

    from grader.bank.template import parse_template
    from grader.render.preview import example_printed
    from grader.solve.solver import compile_template
    from tests.scene_edits import reversed_scene

    template = BANK[template_id]
    turned = parse_template(reversed_scene(yaml.safe_load(Path(template.where).read_text())),
                            f"test:{template_id}:reversed", template_id)
    compiled = compile_template(turned)
    printed = example_printed(turned)
    variant = ProblemVariant("1", turned.id, "reversed", {n: float(v) for n, v in printed.items()}, printed, ())
    kernel = chain_values(compiled, {**si_parameters(turned, variant), **{s: 1.0 for s in turned.symbols}})
    route = textbook_route(turned, compiled)
    env = {**kernel, **{s.unknown: float(page_value(s.solved, kernel)) for s in route.extra}}
    assert any("conservation of momentum" in step.relation for step in route.steps), template_id
    for step in route.steps:
        if step.unknown in kernel:
            assert _close(float(page_value(step.solved, env)), kernel[step.unknown]), (template_id, step.unknown)
        lhs, rhs = (float(page_value(side, env)) for side in step.equation)
        assert _close(lhs, rhs), (template_id, step.relation)


ENERGY = [t for t in ORDER if any(step.relation == "energy lost in the impact" for step in compiled_for(BANK[t]).steps)]
"""Every shipped template that finds the energy lost in an impact."""


@pytest.mark.parametrize("template_id", ENERGY)
def test_the_energy_lost_is_t_before_less_t_after_with_the_velocities_after_on_the_page(template_id: str) -> None:
    """Sample Problems 3/28–3/30: T = ½ m_A v_A² + ½ m_B v_B², T′ from the velocities after already found, then
    ΔE = T − T′ (the kernel's stable form stays the kernel's)."""
    steps = textbook_route(BANK[template_id], compiled_for(BANK[template_id])).steps
    order = [step.unknown for step in steps]
    for lost in [s for s in steps if s.relation == "energy lost in the impact"]:
        before, after = (side.name for side in lost.solved.args)  # type: ignore[union-attr]
        assert lost.solved.op == "sub", (template_id, to_text(lost.solved))  # type: ignore[union-attr]
        found = steps[order.index(after)]
        assert found.relation == "kinetic energy just after the impact"
        assert order.index(before) < order.index(lost.unknown)
        for velocity in names(found.solved) - set(BANK[template_id].parameters) - set(BANK[template_id].symbols):
            assert order.index(velocity) < order.index(after), (template_id, velocity)


def test_a_plastic_impacts_t_after_is_half_the_masses_together_times_the_common_speed_squared() -> None:
    steps = {s.unknown: s for s in textbook_route(BANK["coupling"], compiled_for(BANK["coupling"])).steps}
    assert to_text(steps["T_after"].solved) == "(m_A + m_B)*v_common**2/2"
    assert to_text(steps["E_lost"].solved) == "T - T_after"


def test_an_oblique_impacts_t_after_adds_the_components_squared() -> None:
    steps = {s.unknown: s for s in textbook_route(BANK["oblique-spheres"], compiled_for(BANK["oblique-spheres"])).steps}
    # sphere 2 leaves along n (its t-velocity is 0, never written 0²)
    assert to_text(steps["T_after"].solved) == "m1*(v1_n_after**2 + v1_t_after**2)/2 + m2*v2_n_after**2/2"
