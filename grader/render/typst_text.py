"""Typst source built safely: :class:`Typ` marks trusted source (generated here, or the instructor's), and
:func:`string` and :func:`text` turn any other text into a literal that Typst shows and never interprets.

>>> str(text("$x$ #1"))
'#"$x$ #1";'
>>> print(string('say "hi"'))
"say \\"hi\\""
"""

from __future__ import annotations


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
