"""A statement restated for some of its template's answers: what an assignment's ``parts:`` asks.

A statement sets the scene and ends with its question, a sentence that begins ``Find`` or ``Determine``
and names every answer of the template. When an assignment asks only some of them, that question (from
its first word to the end of the statement) is replaced by one built from the descriptions of the parts
asked, in the order the sheet prints them, so that the sheet never asks for a value it has no box for.
A statement whose question is worded otherwise ("How fast was car A going?") cannot be restated: the
assignment is refused and says so.

>>> restated("A ram falls 2 m onto a pile. Find the velocity of the pile and e.",
...          ["velocity of the pile", "car A's speed"])
"A ram falls 2 m onto a pile. Find the velocity of the pile and car A's speed."
>>> restated("How fast was car A going?", ["speed of car A"]) is None
True
"""

from __future__ import annotations

import re
from collections.abc import Sequence

# The question: "Find" or "Determine" opening a sentence (at the start, or after a sentence's end), to the
# end of the statement; the last such sentence, so that a scene mentioning "Find" earlier is kept.
_QUESTION = re.compile(r"(?:^|(?<=[.!?:]\s)|(?<=\n))(?:Find|Determine)\b", re.MULTILINE)


def question_start(statement: str) -> int | None:
    """Where the statement's question begins, or None when no sentence begins ``Find`` or ``Determine``.

    >>> question_start("Find the mass. Then it falls. Determine e.")
    30
    """
    start = None
    for found in _QUESTION.finditer(statement):  # the last one; one pass, whatever the statement's length
        start = found.start()
    return start


def restated(statement: str, descriptions: Sequence[str]) -> str | None:
    """``statement`` asking only for the answers described (each as the sheet describes it), or None when
    its question cannot be found."""
    start = question_start(statement)
    if start is None or not descriptions:
        return None
    named = [_markup_escaped(_with_article(d.strip())) for d in descriptions]
    listed = named[0] if len(named) == 1 else ", ".join(named[:-1]) + " and " + named[-1]
    return f"{statement[:start]}Find {listed}."


def _markup_escaped(description: str) -> str:
    r"""A description as literal text in the statement's Typst markup (a description is plain text).

    >>> _markup_escaped("v_A at *rest* #1")
    'v\\_A at \\*rest\\* \\#1'
    """
    return re.sub(r"([\\$#*_\[\]<>@`~=])", r"\\\1", description)


def _with_article(description: str) -> str:
    """``the speed of ...``; a possessive (``car A's speed``, ``B's speed``) takes none."""
    return description if "'s" in " ".join(description.split()[:2]) else f"the {description}"
