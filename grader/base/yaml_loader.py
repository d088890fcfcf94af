"""The bounded YAML loader :func:`grader.base.inputs.parse_yaml` reads templates and assignments with: PyYAML's
safe loader on YAML 1.2's core schema, refusing what could hang or exhaust memory before it does (aliases
that expand beyond a budget, nesting too deep) and what would be silently misread (duplicate keys, keys
that are not names, numbers beyond float64). Apart from :mod:`grader.base.inputs`, so that a run that finds
what a file reads as remembered imports no PyYAML.

>>> load_yaml("h: 1e308\\nlist: [1, 2]\\n", Path("a.yaml"))
{'h': 1e+308, 'list': [1, 2]}
>>> load_yaml("h: 1\\nh: 2\\n", Path("b.yaml"))
Traceback (most recent call last):
...
grader.base.errors.GraderError: b.yaml: line 2: the key 'h' appears twice (expected each key once)
"""

from __future__ import annotations

import math
import re
from collections.abc import Hashable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import yaml

from grader.base.errors import GraderError, shown

YAML_NODES = 100_000  # nodes after alias expansion
YAML_DEPTH = 64


# YAML 1.2's core schema, which every other reader of these files uses: `on`, `no`, `off`, `yes` and
# dates stay text (YAML 1.1 made a parameter named `on` the boolean true), `010` is ten, and `1e308`
# is a number.
_CORE = {
    "tag:yaml.org,2002:null": (r"^(?:~|null|Null|NULL|)$", [*"~nN", None]),  # None: the empty scalar
    "tag:yaml.org,2002:bool": (r"^(?:true|True|TRUE|false|False|FALSE)$", [*"tTfF"]),
    "tag:yaml.org,2002:int": (r"^(?:[-+]?[0-9]+|0o[0-7]+|0x[0-9a-fA-F]+)$", [*"-+0123456789"]),
    "tag:yaml.org,2002:float": (r"^(?:[-+]?(?:\.[0-9]+|[0-9]+(?:\.[0-9]*)?)(?:[eE][-+]?[0-9]+)?"
                                r"|[-+]?\.(?:inf|Inf|INF)|\.(?:nan|NaN|NAN))$", [*"-+0123456789."]),
}


if TYPE_CHECKING:
    _Mixin = yaml.SafeLoader  # what _Bounded's methods reach through super()
else:
    _Mixin = object


class _Bounded(_Mixin):
    """What our YAML loaders add to PyYAML's safe loader: YAML 1.2's core schema, and bounds on depth,
    expanded size, text keys each given once, finite numbers."""

    yaml_implicit_resolvers = {}  # noqa: RUF012  (PyYAML's own class attribute: filled with _CORE below)

    def __init__(self, stream: str) -> None:
        super().__init__(stream)
        self._depth = 0
        self._nodes = 0  # nodes composed: the document's size when it has no alias
        self._aliases = False

    def compose_node(self, parent: Any, index: Any) -> Any:
        self._depth += 1
        self._nodes += 1
        if self._depth > YAML_DEPTH:
            mark = self.peek_event().start_mark  # type: ignore[no-untyped-call]
            raise GraderError(f"line {mark.line + 1}: nested deeper than {YAML_DEPTH} levels; expected a "
                              "template-sized structure")
        if self.check_event(yaml.AliasEvent):
            self._aliases = True
        try:
            return super().compose_node(parent, index)
        finally:
            self._depth -= 1

    def get_single_node(self) -> Any:
        node = super().get_single_node()
        if node is not None and self._aliases:  # without one, the document is as large as it was written
            _check_expanded_size(node)
        elif node is not None and self._nodes > YAML_NODES:
            raise GraderError(f"line 1: holds more than {YAML_NODES:,} values; expected a template-sized structure")
        return node

    def construct_mapping(self, node: Any, deep: bool = False) -> dict[Hashable, Any]:
        seen: set[str] = set()
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=True)
            line = key_node.start_mark.line + 1
            if not isinstance(key, str):
                raise GraderError(f"line {line}: expected a key that is a name, got {shown(key)} (write a name, "
                                  "or quote it)")
            if key in seen:
                raise GraderError(f"line {line}: the key {shown(key)} appears twice (expected each key once)")
            seen.add(key)
        return super().construct_mapping(node, deep=deep)

    def construct_yaml_int(self, node: Any) -> int:
        text = str(self.construct_scalar(node))
        value = int(text, 16 if text.startswith("0x") else 8 if text.startswith("0o") else 10)
        _check_finite(value, node)
        return value

    def construct_yaml_float(self, node: Any) -> float:
        value: float = super().construct_yaml_float(node)
        _check_finite(value, node)
        return value


class _PyLoader(_Bounded, yaml.SafeLoader):
    """The bounded loader, all in Python: PyYAML's own scanner and parser, whose messages are clearer."""


def _fast_loader() -> type[_Bounded]:
    """The bounded loader with libyaml's scanner and parser, where PyYAML was built with it: eight times
    faster (the bank's templates are read on every command). The composer and all after it stay
    PyYAML's Python, so the bounds hold whichever parser reads the text."""
    try:
        from yaml._yaml import CParser
    except ImportError:  # PyYAML without libyaml
        return _PyLoader
    from yaml.composer import Composer
    from yaml.constructor import SafeConstructor
    from yaml.resolver import Resolver

    class SafeLoader(Composer, CParser, SafeConstructor, Resolver):
        def __init__(self, stream: str) -> None:
            CParser.__init__(self, stream)
            Composer.__init__(self)
            SafeConstructor.__init__(self)
            Resolver.__init__(self)

    return type("_Loader", (_Bounded, SafeLoader), {"__doc__": _fast_loader.__doc__})


_Loader = _fast_loader()
_LOADERS: tuple[type[_Bounded], ...] = tuple(dict.fromkeys((_Loader, _PyLoader)))  # one without libyaml
for _loader in _LOADERS:
    _loader.add_constructor("tag:yaml.org,2002:int", _Bounded.construct_yaml_int)
    _loader.add_constructor("tag:yaml.org,2002:float", _Bounded.construct_yaml_float)
    for _tag, (_pattern, _first) in _CORE.items():
        _loader.add_implicit_resolver(_tag, re.compile(_pattern), _first)


def _check_finite(value: float, node: Any) -> None:
    try:
        finite = math.isfinite(float(value))
    except OverflowError:
        finite = False
    if not finite:
        raise GraderError(f"line {node.start_mark.line + 1}: expected a finite number within float64 "
                          f"(about ±1.8e308), got {shown(node.value)}")


def _check_expanded_size(root: Any) -> None:
    """Count the nodes the document expands to, aliases included, without expanding it."""
    sizes: dict[int, int] = {}
    stack: list[tuple[Any, bool]] = [(root, False)]
    while stack:
        node, children_done = stack.pop()
        if id(node) in sizes:
            continue
        children = _children(node)
        if not children_done:
            stack.append((node, True))
            stack.extend((child, False) for child in children if id(child) not in sizes)
            continue
        size = 1 + sum(sizes.get(id(child), 0) for child in children)
        if size > YAML_NODES:
            raise GraderError(f"line {node.start_mark.line + 1}: expands to more than {YAML_NODES:,} values "
                              "through aliases (*name); expected a template-sized structure")
        sizes[id(node)] = size


def _children(node: Any) -> list[Any]:
    if isinstance(node, yaml.MappingNode):
        return [part for pair in node.value for part in pair]
    if isinstance(node, yaml.SequenceNode):
        return list(node.value)
    return []


def load_yaml(text: str, path: Path) -> Any:
    """YAML text read from ``path`` (for messages), with the bounds above."""
    try:
        try:
            return yaml.load(text, Loader=_Loader)  # noqa: S506  (_Loader is a bounded SafeLoader)
        except yaml.YAMLError as error:
            problem = _in_python(text, error)
    except GraderError as error:
        raise GraderError(f"{path}: {error}") from None
    raise GraderError(f"{path}: expected valid YAML, got {_yaml_problem(problem)}") from None


def _in_python(text: str, error: yaml.YAMLError) -> yaml.YAMLError:
    """What PyYAML's own parser says of text libyaml refused (``expected ',' or ']', but got '<stream end>'``
    where libyaml says ``did not find expected ',' or ']'``); ``error`` if it says nothing. Where one of our
    bounds holds the text back, its :class:`GraderError` is raised: libyaml's scanner looks ahead, and its
    own nesting limit (1,000 in libyaml 0.2.5) fires before our composer reaches :data:`YAML_DEPTH`."""
    if _Loader is _PyLoader:
        return error
    try:
        yaml.load(text, Loader=_PyLoader)  # noqa: S506  (_PyLoader is a bounded SafeLoader)
    except yaml.YAMLError as python_error:
        return python_error
    return error


def _yaml_problem(error: yaml.YAMLError) -> str:
    mark = getattr(error, "problem_mark", None)
    problem = getattr(error, "problem", None) or str(error).splitlines()[0]
    return f"{problem} (line {mark.line + 1}, column {mark.column + 1})" if mark else str(problem)
