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

import re
from collections.abc import Iterator, Mapping
from functools import lru_cache
from typing import Any

import jinja2
import jinja2.nodes as nodes
import jinja2.sandbox
from jinja2.exceptions import SecurityError

MAX_OUTPUT = 20_000  # characters a filled-in statement may have
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


# --- Typst --------------------------------------------------------------------------------------

# Typst functions and keywords that read files or packages, and the two ways to reach them by name.
_FILE_ACCESS = ("read", "image", "json", "csv", "yaml", "toml", "xml", "cbor", "plugin", "include", "import",
                "eval", "std")
_ANY_FILE_ACCESS = re.compile("|".join(_FILE_ACCESS))
_WORD = re.compile(r"[A-Za-z_][A-Za-z0-9_-]*")
_MATH_WORD = re.compile(r"[A-Za-z]+")
_KEYWORDS = {"let", "set", "show", "if", "else", "for", "while", "import", "include", "context", "return"}
_CLOSE = {"(": ")", "[": "]", "{": "}"}


# The only Typst code a statement may hold: emphasis and the like on a content block, a space of a
# fixed length, a line break, a named symbol. Anything else (#for, #range, #let, #datetime, a code
# block) could loop for ever, exhaust memory, or print something other than the same for everyone.
_ALLOWED_CODE = re.compile(r"#(?:(?:emph|strong|sub|super|underline|overline|smallcaps|highlight)(?=\[)"
                           r"|[hv]\(\s*-?\d+(?:\.\d+)?\s*(?:pt|mm|cm|in|em)\s*\)"
                           r"|linebreak\(\)|sym(?:\.[A-Za-z]+)+)")


def typst_refusal(source: str) -> str | None:
    """Why a statement's Typst is refused (it reads files, or holds code that is not markup), or None.

    >>> typst_refusal('#read("x")')
    'a Typst call that reads files: read("x")'
    >>> typst_refusal("#range(10**9).len()")  # doctest: +ELLIPSIS
    'Typst code that is not markup: #range(10**9).len() (allowed: #emph[..], ...)'
    """
    reading = typst_file_access(source)
    if reading is not None:
        return f"a Typst call that reads files: {reading}"
    code = typst_code(source)
    if code is not None:
        return (f"Typst code that is not markup: {code} (allowed: #emph[..], #strong[..], #h(1em), #v(1em), "
                "#linebreak(), #sym.name)")
    return None


def typst_code(source: str) -> str | None:
    """The first piece of Typst code in ``source`` that is not plain markup, or None.

    >>> typst_code("Find #emph[both] speeds #h(1em) and $v_A'$ #sym.arrow.r done")
    >>> typst_code("#for i in range(10) [x]"), typst_code("#emph[a].text")
    ('#for i in range(10) [x]', '#emph[a].text')
    """
    text = _without_jinja(source)
    for hash_ in _unescaped_hashes(text):
        allowed = _ALLOWED_CODE.match(text, hash_)
        end = allowed.end() if allowed else hash_ + 1
        if allowed and text.startswith("[", end):
            end = _balanced(text, end)
        if allowed is None or (end < len(text) and text[end] in ".([{"):
            return text[hash_:min(_expression_end(text, hash_ + 1), hash_ + 40)]
    return None


def _without_jinja(source: str) -> str:
    return re.sub(r"\{\{.*?\}\}|\{%.*?%\}|\{#.*?#\}", "", source, flags=re.DOTALL) if "{" in source else source


def _unescaped_hashes(text: str) -> Iterator[int]:
    return (m.start() for m in re.finditer(r"(?<!\\)#", text))


def typst_file_access(source: str) -> str | None:
    """The first piece of Typst code in ``source`` that reads files (``read("x")``, ``import ...``),
    or None. Jinja2 tags are removed first, so a name split across tags is still seen whole."""
    text = _without_jinja(source)
    if not _ANY_FILE_ACCESS.search(text):
        return None
    # Math calls functions by name too: $ read("x") $ is a call.
    spans = [(_WORD, span) for span in _code_spans(text)] + [(_MATH_WORD, span) for span in _math_spans(text)]
    hits = [word for pattern, (start, end) in spans for word in pattern.finditer(text, start, end)
            if word.group() in _FILE_ACCESS]
    if not hits:
        return None
    first = min(hits, key=lambda word: word.start())
    return text[first.start():min(_expression_end(text, first.start()), first.start() + 40)]


def _math_spans(text: str) -> Iterator[tuple[int, int]]:
    dollars = [m.start() for m in re.finditer(r"(?<!\\)\$", text)]
    yield from zip(dollars[::2], [*dollars[1::2], len(text)], strict=False)


def _code_spans(text: str) -> Iterator[tuple[int, int]]:
    """Where Typst code is: from each unescaped ``#`` to the end of its expression (a keyword's
    statement runs to the end of the line); brackets inside are code too (conservatively)."""
    index = 0
    while (hash_ := text.find("#", index)) != -1:
        if hash_ > 0 and text[hash_ - 1] == "\\":
            index = hash_ + 1
            continue
        end = _expression_end(text, hash_ + 1)
        yield hash_ + 1, end
        index = max(end, hash_ + 1)


def _expression_end(text: str, index: int) -> int:
    word = _WORD.match(text, index)
    if word and word.group() in _KEYWORDS:
        position = word.end()
        while position < len(text) and text[position] != "\n":
            position = _balanced(text, position) if text[position] in _CLOSE else position + 1
        return position
    position = word.end() if word else index
    while position < len(text):
        if text[position] in _CLOSE:
            position = _balanced(text, position)
        elif text[position] == "." and (field := _WORD.match(text, position + 1)):
            position = field.end()
        else:
            break
    return position


def _balanced(text: str, index: int) -> int:
    """The position after the bracket that closes the one at ``index`` (or the end of the text)."""
    stack, position = [_CLOSE[text[index]]], index + 1
    while position < len(text) and stack:
        char = text[position]
        if char == '"':
            position = _string_end(text, position)
            continue
        if char in _CLOSE:
            stack.append(_CLOSE[char])
        elif char == stack[-1]:
            stack.pop()
        position += 1
    return position


def _string_end(text: str, index: int) -> int:
    position = index + 1
    while position < len(text) and text[position] != '"':
        position += 2 if text[position] == "\\" else 1
    return position + 1
