"""A compiled template: the step chain and the answer and check trees, JSON-serialisable.

This is what the cache stores and the kernels evaluate; it never needs sympy.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from functools import cached_property
from typing import Any, Generic, Protocol, TypeVar

from grader.model.expr import Node, from_json, to_json, to_text
from grader.model.kernel import Kernel

FORMAT = 1


class _OfAnswer(Protocol):
    @property
    def answer(self) -> str: ...


_Item = TypeVar("_Item", bound=_OfAnswer)


@dataclass(frozen=True)
class PerAnswer(Generic[_Item]):
    """What a template derives beside its compiled form, answer by answer (its alternatives, its
    routes): compiled with its constants, kept in the cache under its source hash."""

    template_id: str
    source_hash: str
    constants: Mapping[str, float]
    items: tuple[_Item, ...]

    def for_answer(self, name: str) -> tuple[_Item, ...]:
        """The items of one answer, in order."""
        return tuple(item for item in self.items if item.answer == name)


@dataclass(frozen=True)
class Step:
    """One step of the chain: from ``relation``'s equation ``lhs = rhs``, ``unknown = solved``. A step of a
    block of equations solved together names the block's unknowns in ``block``, in order (its steps follow
    one another, each with one of the block's equations); a step of one equation has none."""

    unknown: str
    relation: str
    equation: tuple[Node, Node]
    solved: Node
    block: tuple[str, ...] = ()
    numeric: bool = False  # solved numerically: ``solved`` is a ``root(...)`` tree (a block's first step)

    def __str__(self) -> str:
        lhs, rhs = (to_text(side) for side in self.equation)
        return f"{self.unknown} = {to_text(self.solved)}    [{self.relation}: {lhs} = {rhs}]"


@dataclass(frozen=True)
class Check:
    """A condition on the parameters (template units) that the physics needs."""

    holds: Node
    message: str
    subject: Node | None = None


@dataclass(frozen=True)
class Undefined:
    """When ``when`` holds, the answer has no value; ``reason`` says why."""

    when: Node
    reason: str


@dataclass(frozen=True)
class CompiledAnswer:
    """An answer as a numeric tree over the parameters, or a symbolic tree."""

    name: str
    unit: str
    numeric: Node | None
    symbolic: Node | None
    undefined: tuple[Undefined, ...] = ()


@dataclass(frozen=True)
class Compiled:
    """Everything the kernels need for one template."""

    template_id: str
    source_hash: str
    parameters: tuple[str, ...]
    constants: Mapping[str, float]
    steps: tuple[Step, ...]
    checks: tuple[Check, ...]
    answers: Mapping[str, CompiledAnswer]

    @cached_property
    def kernel(self) -> Kernel:
        """Every tree the solver evaluates per parameter set, compiled once (the first use builds it):
        ``("holds", i)`` and ``("subject", i)`` of each check, ``("undefined", name, i)`` of each
        answer's undefined conditions, and ``("answer", name)`` of each numeric answer."""
        trees: dict[Any, Node] = {}
        for index, check in enumerate(self.checks):
            trees["holds", index] = check.holds
            if check.subject is not None:
                trees["subject", index] = check.subject
        for name, answer in self.answers.items():
            for index, rule in enumerate(answer.undefined):
                trees["undefined", name, index] = rule.when
            if answer.numeric is not None:
                trees["answer", name] = answer.numeric
        return Kernel(trees, self.constants)

    def to_json(self) -> dict[str, Any]:
        """A JSON-ready dictionary."""
        def tree(node: Node | None) -> Any:
            return None if node is None else to_json(node)
        return {
            "format": FORMAT, "template": self.template_id, "source_hash": self.source_hash,
            "parameters": list(self.parameters), "constants": dict(self.constants),
            "steps": [{"unknown": s.unknown, "relation": s.relation,
                       "equation": [to_json(s.equation[0]), to_json(s.equation[1])],
                       "solved": to_json(s.solved)} | ({"block": list(s.block)} if s.block else {})
                      | ({"numeric": True} if s.numeric else {})
                      for s in self.steps],
            "checks": [{"holds": to_json(c.holds), "message": c.message, "subject": tree(c.subject)}
                       for c in self.checks],
            "answers": {name: {"unit": a.unit, "numeric": tree(a.numeric), "symbolic": tree(a.symbolic),
                               "undefined": [{"when": to_json(u.when), "reason": u.reason} for u in a.undefined]}
                        for name, a in self.answers.items()},
        }

    @classmethod
    def from_json(cls, data: Mapping[str, Any]) -> Compiled:
        """Inverse of :meth:`to_json` for data of the shape it writes; another format, an equation of other
        than two sides, or a tree :func:`~grader.model.expr.from_json` refuses, is a ``ValueError``."""
        def tree(value: Any) -> Node | None:
            return None if value is None else from_json(value)
        if data["format"] != FORMAT:
            raise ValueError(f"compiled in format {data['format']!r}, not {FORMAT}")
        return cls(
            template_id=data["template"], source_hash=data["source_hash"],
            parameters=tuple(data["parameters"]), constants=dict(data["constants"]),
            steps=tuple(Step(s["unknown"], s["relation"], _sides(s["equation"]), from_json(s["solved"]),
                             tuple(map(str, s.get("block", ()))), s.get("numeric") is True) for s in data["steps"]),
            checks=tuple(Check(from_json(c["holds"]), c["message"], tree(c["subject"])) for c in data["checks"]),
            answers={name: CompiledAnswer(name, a["unit"], tree(a["numeric"]), tree(a["symbolic"]),
                                          tuple(Undefined(from_json(u["when"]), u["reason"]) for u in a["undefined"]))
                     for name, a in data["answers"].items()},
        )


def _sides(equation: list[Any]) -> tuple[Node, Node]:
    """An equation's two sides as :meth:`Compiled.to_json` writes them; another number of sides is a ``ValueError``."""
    if len(equation) != 2:
        raise ValueError(f"an equation of {len(equation)} sides")
    return from_json(equation[0]), from_json(equation[1])
