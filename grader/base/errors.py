"""One error family for everything a user can fix.

The CLI catches :class:`GraderError`, prints its message and exits with code 2;
any other exception is a bug and keeps its traceback.

>>> raise TemplateError("bank/x.yaml", "parameters.e.domain", "an interval like '[0, 1]'", "'[1, 0]'")
Traceback (most recent call last):
...
grader.base.errors.TemplateError: bank/x.yaml: parameters.e.domain: expected an interval like '[0, 1]', got '[1, 0]'
"""

from __future__ import annotations

import re
import reprlib
from collections.abc import Iterable, Mapping, Sequence
from typing import Any

_SHOWN = reprlib.Repr()  # keyword arguments need Python 3.12
_SHOWN.maxlevel, _SHOWN.maxstring, _SHOWN.maxother, _SHOWN.maxlong = 3, 60, 60, 40
_SHOWN.maxdict = _SHOWN.maxlist = _SHOWN.maxtuple = _SHOWN.maxset = _SHOWN.maxfrozenset = 6


def shown(value: Any, limit: int = 80) -> str:
    """``repr`` of input for a message, cut to ``limit`` characters; bounded work whatever its size
    (never ``repr`` an untrusted structure whole).

    >>> shown(list(range(100)))
    '[0, 1, 2, 3, 4, 5, ...]'
    >>> len(shown("x" * 500)), len(shown({"title": "x" * 10**6}))
    (60, 71)
    """
    text = _SHOWN.repr(value)
    return text if len(text) <= limit else text[:limit - 3] + "..."


CONTROL = re.compile(r"[\x00-\x1f\x7f-\x9f\u202a-\u202e\u2066-\u2069]")
"""Characters a terminal or a spreadsheet acts on instead of showing: C0 and C1 controls (escape
sequences, line breaks) and the bidirectional overrides that reorder what follows them."""


def visible(text: str) -> str:
    r"""``text`` with each character of :data:`CONTROL` written as its escape, for a report a person
    reads: what a student typed is shown, never acted on.

    >>> visible("6.26\x1b[31m m/s"), visible("v\u202e2"), visible("6,3 m/s")
    ('6.26\\x1b[31m m/s', 'v\\u202e2', '6,3 m/s')
    """
    return text if text.isprintable() else CONTROL.sub(lambda m: repr(m.group())[1:-1], text)


def some(names: Sequence[str], most: int = 10) -> str:
    """Names for a message, at most ``most`` of them, each cut to 40 characters.

    >>> some([f"c{i}" for i in range(25)], 3)
    'c0, c1, c2 and 22 more'
    """
    listed = ", ".join(shown(name, 40)[1:-1] for name in names[:most])
    return listed + (f" and {len(names) - most:,} more" if len(names) > most else "")


def raised_in(error: BaseException, *packages: str) -> bool:
    """Whether ``error`` was raised by the code of one of ``packages`` (its traceback's last frame is theirs):
    a library refusing what it was given, as against a bug in the code that called it.

    >>> try:
    ...     import json; json.loads("{")
    ... except ValueError as error:
    ...     raised_in(error, "json"), raised_in(error, "grader"), raised_in(ValueError("made, not raised"), "json")
    (True, False, False)
    """
    trace = error.__traceback__
    if trace is None:
        return False
    while trace.tb_next is not None:
        trace = trace.tb_next
    return str(trace.tb_frame.f_globals.get("__name__", "")).split(".")[0] in packages


SYMPY_FAILURES = (ArithmeticError, NotImplementedError, RecursionError, TypeError, ValueError, AttributeError)
"""What working with sympy may raise besides a :class:`GraderError`; only an error :func:`unworkable` says so
is the template's (or the expression's), the rest are bugs."""


def unworkable(error: BaseException) -> bool:
    """Whether ``error`` says that sympy cannot work with a template's relations or values (or a student's
    expression), not that grader has a bug: a :class:`GraderError`, arithmetic that fails on the values, what
    sympy cannot do (``NotImplementedError``), nesting deeper than Python goes; a ``TypeError``, ``ValueError``
    or ``AttributeError`` only when sympy (or mpmath, which it computes with) raised it, its way of refusing an
    expression it cannot work with.

    >>> unworkable(ZeroDivisionError()), unworkable(TypeError("raised by grader, not sympy"))
    (True, False)
    """
    if isinstance(error, (GraderError, ArithmeticError, NotImplementedError, RecursionError)):
        return True
    return isinstance(error, (TypeError, ValueError, AttributeError)) and raised_in(error, "sympy", "mpmath")


def close_matches(name: str, choices: Iterable[str]) -> list[str]:
    """Up to three of ``choices`` that look like ``name`` (a misspelt id), closest first, for a "did you mean".

    >>> close_matches("drop-rebond", ["drop-rebound", "head-on", "two-rebounds"])
    ['drop-rebound', 'two-rebounds']
    """
    import difflib

    return difflib.get_close_matches(name, list(choices), n=3, cutoff=0.5)


def refuse_unknown_fields(raw: Mapping[Any, Any], known: Iterable[str], where: str, field: str) -> None:
    """Refuse the first entry of the mapping ``raw`` (the ``field`` of file ``where``) whose name is not one of
    ``known``, with the nearest known name (``grading.max_tolerence``: did you mean max_tolerance?)."""
    import difflib

    names = list(known)
    for name in raw:
        if name not in names:
            close = difflib.get_close_matches(str(name), names, n=1, cutoff=0.6)
            hint = f" (did you mean {close[0]}?)" if close else ""
            raise TemplateError(where, f"{field}.{name if isinstance(name, str) else shown(name, 40)}",
                                f"one of {', '.join(names)}{hint}", "an unknown field")


class GraderError(Exception):
    """Base of every error caused by input a user can correct (exit code 2)."""


class TemplateError(GraderError):
    """A problem template that does not load, validate or solve.

    The message names the file, the key inside it, what was expected and what came.
    """

    def __init__(self, where: str, key: str, expected: str, got: str | None = None) -> None:
        self.where, self.key, self.expected, self.got = where, key, expected, got
        message = f"{where}: {key}: expected {expected}"
        if got is not None:
            message += f", got {got}"
        super().__init__(message)


class UsageError(GraderError):
    """A command-line request that cannot be carried out as given."""


class ExpressionError(GraderError):
    """Text that is not an allowed expression; the message says why."""
