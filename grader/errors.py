"""One error family for everything a user can fix.

The CLI catches :class:`GraderError`, prints its message and exits with code 2;
any other exception is a bug and keeps its traceback.

>>> raise TemplateError("bank/x.yaml", "parameters.e.domain", "an interval like '[0, 1]'", "'[1, 0]'")
Traceback (most recent call last):
...
grader.errors.TemplateError: bank/x.yaml: parameters.e.domain: expected an interval like '[0, 1]', got '[1, 0]'
"""

from __future__ import annotations


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
