r"""A statement's text, checked without Jinja2: its Typst (text and math only, no file access, no
code but a few markup calls), and the common case of a statement that is plain text with
``{{ name }}`` placeholders, filled in here exactly as Jinja2 would fill it.

``grader list`` loads every template and checks every statement; most statements are plain, so
it never pays for importing Jinja2 (:mod:`grader.bank.statement` handles the rest).

>>> sorted(plain_names("Dropped from {{ h }} mm onto {{h2}} mm"))
['h', 'h2']
>>> plain_names("{{ h * 3 }}") is None, plain_names("{% for x in y %}") is None
(True, True)
>>> plain_fill("Dropped from {{ h }} mm.\n", {"h": "2100"})
'Dropped from 2100 mm.'
>>> typst_file_access('See #read("secret.txt") here')
'read("secret.txt")'
>>> typst_file_access("Find $v_A'$ #h(1em) and read the figure") is None
True
"""

from __future__ import annotations

import re
from collections.abc import Iterator, Mapping
from typing import Any

MAX_OUTPUT = 20_000  # characters a filled-in statement may have

# A placeholder of the plain form; Jinja2's literals (none, true, ...) are not names.
_PLACEHOLDER = re.compile(r"\{\{\s*([A-Za-z_][A-Za-z0-9_]*)\s*\}\}")
_LITERALS = {"none", "None", "true", "True", "false", "False"}


class StatementRefused(Exception):  # noqa: N818 (a reason, turned into a TemplateError by the caller)
    """A statement that is not allowed; the message says what was found."""


def plain_names(source: str) -> set[str] | None:
    """The names of a statement that is plain text and ``{{ name }}`` placeholders, or None when it
    holds anything else Jinja2 would read (a filter, a tag, a comment, ``{{{``)."""
    found = list(_PLACEHOLDER.finditer(source))
    if any(m.group(1) in _LITERALS or source[m.start() - 1:m.start()] == "{" for m in found):
        return None
    rest = _PLACEHOLDER.sub("\x00", source)
    if "{{" in rest or "{%" in rest or "{#" in rest:
        return None
    return {m.group(1) for m in found}


def plain_fill(source: str, values: Mapping[str, Any]) -> str | None:
    """A plain statement (see :func:`plain_names`) with the values filled in, as Jinja2 would (the
    text around them unchanged, then stripped), or None for a statement that is not plain.
    :class:`StatementRefused` for a name without a value or an output over ``MAX_OUTPUT``."""
    used = plain_names(source)
    if used is None:
        return None
    missing = sorted(used - set(values))
    if missing:
        raise StatementRefused(f"a statement that cannot be filled in ('{missing[0]}' is undefined)")
    filled = _PLACEHOLDER.sub(lambda m: str(values[m.group(1)]), source)
    if len(filled) > MAX_OUTPUT:
        raise StatementRefused(f"more than {MAX_OUTPUT} characters of output")
    return filled.strip()


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
