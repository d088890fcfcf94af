"""Plain statements are filled in without Jinja2, exactly as Jinja2 fills them; the rest goes to Jinja2."""

from __future__ import annotations

import subprocess
import sys

import pytest

from grader.bank.markup import plain_fill
from grader.bank.statement import fill_statement
from grader.bank.template import Template

VALUES = {"h": "1", "h_drop": "1", "g": "1", "m": "m", "none": "1", "self": "1", "loop": "1"}


@pytest.mark.parametrize("source", [
    "Dropped from {{ h }} m.", "{{h}}{{ h_drop }}", "{{\n  h\t}} and {{ m }}", "no placeholders at all",
    "braces { and } and }} alone", "{ {{ h }} }", "a}}b{{ h }}", "  {{ h }}  ", "$v_A' = {{ m }}$ #emph[x]",
])
def test_plain_statements_are_filled_as_jinja2_fills_them(source: str) -> None:
    """Text and {{ name }}: the same text as the sandboxed Jinja2 fill."""
    filled = plain_fill(source, VALUES)
    assert filled is not None
    assert filled == fill_statement(source, VALUES)


@pytest.mark.parametrize("source", [
    "{{ h * 3 }}", "{{ h | upper }}", "{% if h %}x{% endif %}", "{# note #} {{ h }}", "{{{ h }}", "{{ h }}}}{{",
    "{{ unknown }}", "{{ none }}", "{{ self }}", "{{ loop }}", "{{- h }}", "{{ h -}}", "line\r\nbreak {{ h }}",
    "{{ h.real }}", "{{ h['x'] }}", "{{ 'text' }}", "x" * 20_001,
])
def test_anything_else_is_left_to_jinja2(source: str) -> None:
    """Filters, tags, comments, whitespace control, names Jinja2 reads otherwise, unknown names,
    carriage returns (Jinja2 rewrites them) and over-long text: None, so Jinja2 decides."""
    assert plain_fill(source, VALUES) is None


def test_every_shipped_statement_is_plain(bank: dict[str, Template]) -> None:
    """The shipped bank loads without Jinja2, and fills as Jinja2 fills it."""
    for template in bank.values():
        values = {**dict.fromkeys([*template.parameters, "g"], "1"), **{n: n for n in template.symbols}}
        assert plain_fill(template.statement, values) == fill_statement(template.statement, values), template.id
    code = "import sys; from grader.bank.template import load_bank; load_bank(); print('jinja2' in sys.modules)"
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60, check=True)
    assert result.stdout.strip() == "False"
