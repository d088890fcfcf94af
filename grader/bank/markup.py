"""What a statement's Typst may contain, and statements that are plain text and ``{{ name }}``.

Both read text with regular expressions only: loading a template checks its statement without
importing Jinja2 when the statement is plain (as every shipped one is), which keeps ``grader list``
and ``grader solve`` quick to start; anything else is read by Jinja2 in :mod:`grader.bank.statement`.

>>> plain_fill("Dropped from {{ h }} mm, {{g}} m/s^2.", {"h": "2100", "g": "9.81"})
'Dropped from 2100 mm, 9.81 m/s^2.'
>>> plain_fill("{{ h * 3 }}", {"h": "1"}) is None  # not plain: Jinja2 reads it (and refuses it)
True
"""

from __future__ import annotations

import keyword
import re
from collections.abc import Iterator, Mapping

MAX_OUTPUT = 20_000  # characters a filled-in statement may have

# --- plain statements ---------------------------------------------------------------------------

# Where Jinja2's lexer (default settings) leaves text: at {{, {% and {#. It also turns \r\n into \n.
_JINJA = re.compile(r"\{[{%#]|\r")
_PLACEHOLDER = re.compile(r"\{\{\s*([A-Za-z_][A-Za-z0-9_]*)\s*\}\}")
# Names Jinja2 reads as something other than a value from the context.
_SPECIAL = {*keyword.kwlist, "true", "false", "none", "self", "loop", "caller", "varargs", "kwargs", "super"}


def paragraphs(text: str) -> list[str]:
    """Text split at blank lines, each paragraph on one line."""
    return [" ".join(p.split()) for p in re.split(r"\n\s*\n", text) if p.strip()]


def plain_fill(source: str, values: Mapping[str, str]) -> str | None:
    """``source`` filled in as :func:`grader.bank.statement.fill_statement` fills it, when it is
    text and ``{{ name }}`` of names in ``values`` only; None for anything else (Jinja2 reads it).

    The filled text is never longer than ``source`` when every value is shorter than its
    placeholder, so a statement within ``MAX_OUTPUT`` needs no check of the output's length.
    """
    if len(source) > MAX_OUTPUT or any(len(value) > 4 + len(name) for name, value in values.items()):
        return None
    pieces, position = [], 0
    while (start := _JINJA.search(source, position)) is not None:
        placeholder = _PLACEHOLDER.match(source, start.start())
        if placeholder is None or placeholder.group(1) not in values or placeholder.group(1) in _SPECIAL:
            return None
        pieces += [source[position:start.start()], values[placeholder.group(1)]]
        position = placeholder.end()
    pieces.append(source[position:])
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
