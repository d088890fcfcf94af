"""What a template's ``statement`` may contain, and the one place it is filled in.

Templates may come from colleagues, so a statement is untrusted twice over:

* as **Jinja2** it may only fill in values: text and ``{{ name }}`` (with a few harmless filters).
  Loops, conditions, arithmetic, ``set``, macros, calls, attribute and item access are refused when
  the template loads, and every statement renders in Jinja2's ``ImmutableSandboxedEnvironment``
  with arithmetic checked before it runs and the output capped, so even a statement that skipped
  the load-time check can neither run code nor take long;
* as **Typst** it may only be text and math, with a handful of markup calls (``#emph[..]``,
  ``#h(1em)``, ``#sym.arrow``): code that reads files (``read``, ``image``, ``import``, packages,
  ``eval``, ``std``) or could loop or vary (``#for``, ``#range``, ``#datetime``) is refused.
  (The compiler's root is an empty private folder too, so nothing outside could be read anyway.)

>>> fill_statement("Dropped from {{ h }} mm", {"h": "2100"})
'Dropped from 2100 mm'
>>> fill_statement("{{ h * 3 }}", {"h": "2.50"})
Traceback (most recent call last):
...
grader.bank.statement.StatementRefused: arithmetic (values are filled in as printed text; ...
>>> typst_file_access('See #read("secret.txt") here')
'read("secret.txt")'
>>> typst_file_access("Find $v_A'$ #h(1em) and read the figure") is None
True
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from functools import lru_cache
from typing import Any

import jinja2
import jinja2.nodes as nodes
import jinja2.sandbox
from jinja2.exceptions import SecurityError

# The Typst rules live beside the plain-statement reader, which needs no Jinja2 (loading a template
# must not import it); they are imported here for the modules that fill statements in.
from grader.bank.markup import MAX_OUTPUT, typst_code, typst_file_access, typst_refusal

__all__ = ["MAX_OUTPUT", "StatementRefused", "check_jinja", "fill_statement", "typst_code", "typst_file_access",
           "typst_refusal"]

MAX_VALUE = 10_000  # characters of a string, digits of a number, inside a statement
FILTERS = ("abs", "round", "int", "float", "string", "lower", "upper", "title", "capitalize", "trim", "default")

# Jinja2 nodes a statement may use: text, values and filters. Parameters are filled in as the text
# printed on the page ("2.50"), so arithmetic or comparisons on them would work on text
# ({{ h * 3 }} repeats it): values a statement needs are computed in the template, not here.
_ALLOWED: dict[type[nodes.Node], str] = {
    nodes.Template: "", nodes.Output: "", nodes.TemplateData: "", nodes.Name: "", nodes.Const: "",
    nodes.Filter: "", nodes.Concat: "",
}
_ARITHMETIC = "arithmetic (values are filled in as printed text; compute what the page shows in the template)"
_CONDITION = "a condition (a statement shows the same text to every student)"
_REFUSED: dict[type[nodes.Node], str] = {
    nodes.For: "a for loop", nodes.Macro: "a macro", nodes.CallBlock: "a call block", nodes.Call: "a call",
    nodes.Getattr: "attribute access (.name)", nodes.Getitem: "item access ([...])", nodes.Assign: "a set",
    nodes.AssignBlock: "a set block", nodes.Include: "an include", nodes.Import: "an import",
    nodes.FromImport: "an import", nodes.Extends: "an extends", nodes.FilterBlock: "a filter block",
    nodes.With: "a with block", nodes.Block: "a block",
    **dict.fromkeys((nodes.Add, nodes.Sub, nodes.Mul, nodes.Div, nodes.FloorDiv, nodes.Mod, nodes.Pow, nodes.Neg,
                     nodes.Pos), _ARITHMETIC),
    **dict.fromkeys((nodes.If, nodes.CondExpr, nodes.Compare, nodes.And, nodes.Or, nodes.Not), _CONDITION),
}


class StatementRefused(Exception):  # noqa: N818 (a reason, turned into a TemplateError by the caller)
    """A statement that is not allowed; the message says what was found."""


class _BoundedSandbox(jinja2.sandbox.ImmutableSandboxedEnvironment):
    """The sandbox, with ``* ** % + //`` checked before they run, so no value grows past MAX_VALUE."""

    intercepted_binops = frozenset({"*", "**", "%", "+", "//"})

    def call_binop(self, context: Any, operator: str, left: Any, right: Any) -> Any:
        if operator == "%" and isinstance(left, str):
            raise StatementRefused("string formatting with %")
        if operator == "**" and _digits(left) * min(abs(_number(right)), 10**6) > MAX_VALUE * 4:
            raise StatementRefused(f"a value of more than {MAX_VALUE} characters or digits")
        if operator == "*" and (isinstance(left, str | list | tuple) or isinstance(right, str | list | tuple)):
            size = len(left) if isinstance(left, str | list | tuple) else len(right)
            count = right if isinstance(left, str | list | tuple) else left
            if size * max(0, _number(count)) > MAX_VALUE:
                raise StatementRefused(f"a value of more than {MAX_VALUE} characters or digits")
        result = super().call_binop(context, operator, left, right)
        if _size(result) > MAX_VALUE:
            raise StatementRefused(f"a value of more than {MAX_VALUE} characters or digits")
        return result


def _number(value: Any) -> int:
    return int(value) if isinstance(value, int | float) and value == value and abs(value) < 1e18 else 10**18


def _digits(value: Any) -> int:
    return max(1, int(abs(value)).bit_length() // 3) if isinstance(value, int | float) and abs(value) < 1e300 else 1


def _size(value: Any) -> int:
    if isinstance(value, int):
        return len(str(abs(value))) if value.bit_length() < MAX_VALUE * 4 else MAX_VALUE + 1
    return len(value) if isinstance(value, str | list | tuple) else 0


@lru_cache(maxsize=1)
def _environment() -> jinja2.Environment:
    # Typst, not HTML: no autoescape (the values filled in are printed numbers and symbol names).
    environment = _BoundedSandbox(undefined=jinja2.StrictUndefined, autoescape=False)
    environment.globals.clear()
    environment.filters = {name: environment.filters[name] for name in FILTERS}
    environment.tests = {name: environment.tests[name] for name in ("defined", "number", "string")}
    return environment


def check_jinja(source: str) -> jinja2.nodes.Template:
    """The statement's syntax tree, if it only fills in values; else :class:`StatementRefused`
    naming the first construct that is not allowed (``jinja2.TemplateSyntaxError`` passes through)."""
    try:
        syntax = _environment().parse(source)
        every_node = list(_walk(syntax))
    except RecursionError:
        raise StatementRefused("expressions nested too deeply to read (a statement only fills in values)") from None
    for node in every_node:
        if type(node) not in _ALLOWED:
            found = _REFUSED.get(type(node), f"a {type(node).__name__} expression")
            raise StatementRefused(f"{found} (a statement only fills in values: text and {{{{ name }}}})")
        if isinstance(node, nodes.Filter) and node.name not in FILTERS:
            raise StatementRefused(f"the filter '{node.name}' (allowed: {', '.join(FILTERS)})")
    return syntax


def _walk(node: nodes.Node) -> Iterator[nodes.Node]:
    yield node
    for child in node.iter_child_nodes():
        yield from _walk(child)


@lru_cache(maxsize=64)
def _compiled(source: str) -> jinja2.Template:
    check_jinja(source)
    return _environment().from_string(source)


def fill_statement(source: str, values: Mapping[str, Any]) -> str:
    """The statement with the values filled in, in the bounded sandbox; :class:`StatementRefused`
    for anything not allowed or that fails (``jinja2.TemplateSyntaxError`` passes through)."""
    try:
        pieces, length = [], 0
        for piece in _compiled(source).generate(dict(values)):
            length += len(piece)
            if length > MAX_OUTPUT:
                raise StatementRefused(f"more than {MAX_OUTPUT} characters of output")
            pieces.append(piece)
    except SecurityError as error:
        raise StatementRefused(f"something the sandbox forbids ({error})") from None
    except jinja2.TemplateError as error:
        raise StatementRefused(f"a statement that cannot be filled in ({error})") from None
    except (TypeError, ValueError, ArithmeticError, MemoryError, RecursionError) as error:
        raise StatementRefused(f"a statement that cannot be filled in ({type(error).__name__}: {error})") from None
    return "".join(pieces).strip()
