"""A template's statement as a student's sheet prints it, with the template's example numbers
(``grader show``).

>>> from grader.bank.template import load_bank
>>> template = load_bank()["drop-rebound"]
>>> example_printed(template)
{'h_drop': '2100', 'h_rebound': '1100'}
>>> example_statement(template).split(":")[1].split(",")[0]
' released from rest with its lowest point 2100 mm above the court'
"""

from __future__ import annotations

import math

from grader.bank.markup import paragraphs
from grader.bank.template import Parameter, Template, filled_statement
from grader.model.quantities import printed_text


def example_printed(template: Template) -> dict[str, str]:
    """Each parameter as the page prints it: the template's ``example`` value, else the middle of its
    sampling (the mean of a uniform range, the geometric mean of a log-uniform one, the first choice)."""
    return {name: printed_text(template.example.get(name, _middle(parameter)), parameter.decimals, parameter.sig_figs)
            for name, parameter in template.parameters.items()}


def _middle(parameter: Parameter) -> float:
    values = parameter.sample.values
    if parameter.sample.kind == "choice":
        return values[0]
    if parameter.sample.kind == "integers":
        return float(math.floor((values[0] + values[1]) / 2))
    return math.sqrt(values[0] * values[1]) if parameter.sample.kind == "log_uniform" else (values[0] + values[1]) / 2


def example_statement(template: Template) -> str:
    """The statement filled in with :func:`example_printed`, as a sheet shows it (Typst markup, one
    line per paragraph)."""
    return "\n\n".join(paragraphs(filled_statement(template, example_printed(template))))
