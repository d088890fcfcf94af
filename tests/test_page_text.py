"""Nothing internal on the page (issue 32): the text of every shipped template's student sheet and worked
solution, generated for two students and extracted from the PDFs, holds none of the forms an instructor
reading the key found: an internal identifier (an answer's, a quantity's or a body's name as the
template spells it), "along n" in a problem on one line (n is never defined there), a hyphen for a
minus sign, ``L(1 − cos θ)`` for a swing to θ_max, a unit split across lines, ``1/4 p`` for ``p/4``, a double
space in a page's header; and no problem's worked solution titles two steps alike."""

from __future__ import annotations

import dataclasses
import re
from collections import Counter

import pytest
from pypdf import PdfReader

from grader.assign.assignment import ProblemSpec, load_assignment, load_roster
from grader.bank.template import Template, load_bank
from grader.base.resources import sample_dir
from grader.render.typst_text import body_name
from grader.render.worked import worked_form
from grader.solve.cache import compiled_for

BANK = load_bank()
ORDER = sorted(BANK)  # problem k of the generated assignment is ORDER[k - 1]


@pytest.fixture(scope="module")
def pages(tmp_path_factory: pytest.TempPathFactory) -> dict[str, list[str]]:
    """Each PDF's pages as text: two students' sheets and the answer key of an assignment of one problem
    per shipped template."""
    from grader.assign.variants import generate
    from grader.render.pdfs import render_all

    assignment = load_assignment(sample_dir() / "assignment.yaml")
    problems = tuple(ProblemSpec(str(k), template, {"*": 1.0}, {}, {}, {}) for k, template in enumerate(ORDER, 1))
    assignment = dataclasses.replace(assignment, problems=problems)
    generation = generate(assignment, load_roster(sample_dir() / "roster.csv")[:2], BANK)
    out = tmp_path_factory.mktemp("page-text")
    render_all(assignment, generation, BANK, out, jobs=2)
    files = [*sorted((out / "students").glob("*.pdf")), out / "answer-key.pdf"]
    return {path.name: [page.extract_text() or "" for page in PdfReader(path).pages] for path in files}


def _sections(pages: dict[str, list[str]]) -> dict[str, str]:
    """Each template's text: its problem on every sheet and its worked solutions in the key."""
    found: dict[str, list[str]] = {template: [] for template in ORDER}
    for document in pages.values():
        whole = "\n".join(document)
        parts = re.split(r"(?m)^Problem (\d+)(?::| )", whole)
        for number, body in zip(parts[1::2], parts[2::2], strict=True):
            found[ORDER[int(number) - 1]].append(body)
    return {template: "\n".join(bodies) for template, bodies in found.items()}


def _internal_names(template: Template) -> set[str]:
    """The names only the template knows: its answers', its quantities' and its bodies' as written in
    it, where the page would print them otherwise (``loss_pct``, ``v_common``, ``cart1``)."""
    quantities = {*template.answers, *template.parameters, *(s.unknown for s in compiled_for(template).steps)}
    bodies = {body for body in template.scene.bodies if body_name(body) != body}
    return {q for q in quantities if "_" in q or re.fullmatch(r"[A-Za-z]{2,}\d+", q)} | bodies


def _one_dimensional(template: Template) -> bool:
    return not any(stage.is_oblique or stage.effect == "velocity" for stage in template.scene.stages)


FORBIDDEN = {
    "a hyphen for a minus sign": re.compile(r"(?:^|[\s(=,:])-\s?(?:\d|[\U0001D400-\U0001D7FF])"),
    "L(1 − cos θ) for a swing to θ_max": re.compile(r"cos θ\)"),
    "a unit split across lines": re.compile(r"\b(?:m|ft|km|N)/\s*\n\s*(?:s|h)\b|\b(?:m|ft|km)/ s\b"),
    "a number and its unit on two lines": re.compile(r"\d\s*\n\s*(?:m|ft|km)/(?:s|h)\b"),
    "an identifier's underscore": re.compile(r"[A-Za-z0-9]_[A-Za-z0-9{]"),
    "a subscript of internal words": re.compile(r"\d,\s*between"),
    "a fraction's number before a name (1/4 p for p/4)": re.compile(
        r"(?<![\d.,])1 (?:[3-9]|[1-9]\d+) ?[\U0001D44E-\U0001D467\U0001D6FC-\U0001D71B]"),
    "dt for the contact time Δt": re.compile(r"(?<![A-Za-z])dt(?![A-Za-z])"),
}


@pytest.mark.parametrize("template_id", ORDER)
def test_no_internal_name_or_wrong_sign_on_a_templates_pages(template_id: str, pages: dict[str, list[str]]) -> None:
    section = _sections(pages)[template_id]
    assert section.strip(), f"{template_id}: no text found for its problem"
    for what, form in FORBIDDEN.items():
        found = form.search(section)
        assert found is None, (template_id, what, section[max(0, found.start() - 80):found.end() + 80])
    for internal in _internal_names(BANK[template_id]):
        found = re.search(rf"(?<![\w\u2032']){re.escape(internal)}(?!\w)", section)
        assert found is None, (template_id, internal, section[max(0, found.start() - 80):found.end() + 80])
    if _one_dimensional(BANK[template_id]):
        assert "along n" not in section, (template_id, "along n in a problem on one line")


def test_no_page_header_or_footer_has_a_double_space(pages: dict[str, list[str]]) -> None:
    for document, texts in pages.items():
        for number, page in enumerate(texts, 1):
            lines = page.strip().splitlines()
            header = lines[:2] if number == 1 or document != "answer-key.pdf" else []  # the key's pages have none
            for line in (*header, *lines[-2:]):
                assert "  " not in line.strip(), (document, number, line)


@pytest.mark.parametrize("template_id", ORDER)
def test_no_two_steps_of_a_worked_solution_have_one_title(template_id: str) -> None:
    titles = Counter(str(step.relation) for step in worked_form(BANK[template_id]).steps)
    assert [title for title, count in titles.items() if count > 1] == [], template_id


def test_the_issues_ballistic_pendulum_says_what_v_is_where_it_first_computes_it() -> None:
    """Issue 32: the first step computed `V` from the swing, and only the impact's step after it said what
    V is. The swing's step now names it: the speed at the lowest point."""
    first = worked_form(BANK["ballistic-pendulum"]).steps[0]
    assert first.unknown == "V"
    assert "$V$" in str(first.relation) and "speed at the lowest point" in str(first.relation)


def test_a_part_answered_by_an_expression_has_no_numeric_tolerance_in_the_key(pages: dict[str, list[str]]) -> None:
    """Issue 32: car-collision's expression answers said "±1 %" in the key, a tolerance grading never applies to
    an expression (it is marked right when it is the key's expression). Each of its expression parts reads
    "equal expressions" in its row, as details.csv says, and its numeric parts keep their tolerance."""
    number = ORDER.index("car-collision") + 1
    key = "\n".join(pages["answer-key.pdf"])
    rows = re.findall(rf"(?m)^{number}([a-d]) .*?(equal expressions|±\d+ %)$", key)
    expressions = {name for name, spec in BANK["car-collision"].answers.items() if spec.symbolic}
    assert len(expressions) == 2 and rows, rows
    assert {label for label, tolerance in rows if tolerance == "equal expressions"} == {"a", "b"}, rows
    assert {label for label, tolerance in rows if tolerance != "equal expressions"} == {"c", "d"}, rows
