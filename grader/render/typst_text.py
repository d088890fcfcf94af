"""Typst source built safely: :class:`Typ` marks trusted source (generated here, or the instructor's), and
:func:`string` and :func:`text` turn any other text into a literal that Typst shows and never interprets.

>>> str(text("$x$ #1"))
'#"$x$ #1";'
>>> print(string('say "hi"'))
"say \\"hi\\""
>>> body_name("cart1"), body_name("ball_2"), body_name("A"), signed("-2.8")
('cart 1', 'ball 2', 'A', '−2.8')
"""

from __future__ import annotations

import re


class Typ(str):
    """Typst source we generated (or the instructor wrote): inserted into a document as is."""


def string(value: object) -> Typ:
    """A Typst string literal (for code and math): ``"..."`` with quotes and backslashes escaped."""
    body = str(value).replace("\\", "\\\\").replace('"', '\\"')
    body = body.replace("\n", "\\n").replace("\r", "\\r").replace("\t", "\\t")
    return Typ(f'"{body}"')


def text(value: object) -> Typ:
    """Text shown literally in markup: an embedded string literal, ended by ``;`` so that nothing
    after it (a dot, a bracket) can continue the expression."""
    return Typ(f"#{string(value)};")


def body_name(body: str) -> str:
    """A body's name as a page prints it: the scene's id with a space before a number that ends it and
    for an underscore (``cart1`` is cart 1, as the statement says), else as it is."""
    return re.sub(r"(?<=[A-Za-z])(?=\d+$)", " ", body).replace("_", " ")


def signed(printed: str) -> str:
    """A printed number with a minus sign, not a hyphen, before it (as Typst prints one in math)."""
    return "\u2212" + printed[1:] if printed.startswith("-") else printed
