"""grader uses only the public names of the libraries it stands on: a private name (``_negative_number_matcher``
of an argparse parser, ``_units`` of a pint quantity) changes or vanishes in any release without notice.

The check reads grader's source with ``ast`` and finds, in each module, what it can see is a library's: a name
imported from one (``import numpy as np``, ``from sympy import Symbol``), a class derived from a library's class,
a name assigned from any of these (``parser = argparse.ArgumentParser()``, then ``checking =
commands.add_parser(...)``), and ``self`` in such a class. Reading an attribute of those whose name starts with one
underscore (not a ``__dunder__``) is a failure, unless the class itself defines that name."""

from __future__ import annotations

import ast
from collections.abc import Iterator
from pathlib import Path

import pytest

import grader

LIBRARIES = ("argparse", "jinja2", "matplotlib", "mpmath", "numpy", "pint", "scipy", "sympy", "typst", "yaml")
PACKAGE = Path(grader.__file__).parent


def _private(name: str) -> bool:
    return name.startswith("_") and not (name.startswith("__") and name.endswith("__"))


def _root(node: ast.AST) -> str | None:
    """The name an expression starts from: ``np`` for ``np.linalg.norm(x).T``, None for a literal."""
    while isinstance(node, ast.Attribute | ast.Call | ast.Subscript):
        node = node.func if isinstance(node, ast.Call) else node.value
    return node.id if isinstance(node, ast.Name) else None


def _library_names(tree: ast.Module) -> set[str]:
    """The names of a module that are a library's: imported from one, a class derived from one, or assigned from
    one (to a fixed point)."""
    names: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names |= {(alias.asname or alias.name).split(".")[0] for alias in node.names
                      if alias.name.split(".")[0] in LIBRARIES}
        elif isinstance(node, ast.ImportFrom) and node.module and node.module.split(".")[0] in LIBRARIES:
            names |= {alias.asname or alias.name for alias in node.names}
    assignments = [node for node in ast.walk(tree) if isinstance(node, ast.Assign)]
    classes = [node for node in ast.walk(tree) if isinstance(node, ast.ClassDef)]
    while True:
        more = ({target.id for node in assignments if _root(node.value) in names
                 for target in node.targets if isinstance(target, ast.Name)}
                | {cls.name for cls in classes if any(_root(base) in names for base in cls.bases)}) - names
        if not more:
            return names
        names |= more


def _uses(source: str) -> Iterator[tuple[int, str]]:
    """Each private name of a library object that the module ``source`` reads, with its line."""
    tree = ast.parse(source)
    library = _library_names(tree)
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and _private(node.attr) and _root(node.value) in library:
            yield node.lineno, ast.unparse(node)
    for cls in ast.walk(tree):
        if isinstance(cls, ast.ClassDef) and any(_root(base) in library for base in cls.bases):
            own = {node.name for node in ast.walk(cls) if isinstance(node, ast.FunctionDef)} | {
                node.attr for node in ast.walk(cls) if isinstance(node, ast.Attribute)
                and isinstance(node.ctx, ast.Store)} | {
                target.id for node in ast.walk(cls) if isinstance(node, ast.Assign | ast.AnnAssign)
                for target in (node.targets if isinstance(node, ast.Assign) else [node.target])
                if isinstance(target, ast.Name)}
            yield from ((node.lineno, ast.unparse(node)) for node in ast.walk(cls)
                        if isinstance(node, ast.Attribute) and _private(node.attr)
                        and isinstance(node.value, ast.Name) and node.value.id == "self" and node.attr not in own)


def test_grader_reads_no_private_name_of_a_library() -> None:
    found = [f"{path.relative_to(PACKAGE.parent)}:{line}: {use}" for path in sorted(PACKAGE.rglob("*.py"))
             for line, use in _uses(path.read_text(encoding="utf-8"))]
    assert not found, "private names of libraries:\n" + "\n".join(found)


@pytest.mark.parametrize(("source", "found"), [
    ("import argparse\nclass P(argparse.ArgumentParser):\n    pass\nparser = P()\nsub = parser.add_subparsers()\n"
     "check = sub.add_parser('check')\ncheck._negative_number_matcher = None\n", True),
    ("import pint\ndef f(q):\n    return pint.Quantity(q)._units\n", True),
    ("from argparse import ArgumentParser\nclass P(ArgumentParser):\n    def f(self):\n"
     "        return self._option_string_actions\n", True),
    ("from argparse import ArgumentParser\nclass P(ArgumentParser):\n    def f(self):\n"
     "        self._mine = 1\n        return self._mine, self.__class__\n", False),
    ("import numpy as np\nclass Ours:\n    def f(self):\n        return self._cache, np.float64.__name__\n", False),
], ids=["argparse-matcher", "pint-units", "subclass-reads-private", "subclass-own-private", "ours"])
def test_the_check_finds_a_private_name_of_a_library(source: str, found: bool) -> None:
    assert bool(list(_uses(source))) is found
