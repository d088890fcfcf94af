"""What a student answers who carries an earlier answer forward, or who makes a named mistake:
chains derived from the scene like the template's own, compiled once per template (the cache keeps
them beside the compiled form) and evaluated for a whole class at once.

- **Error carried forward**: for an answer B after an answer A of the same problem, A becomes a known
  and one parameter A depends on is freed, each in turn (which one the student effectively got wrong
  is not known); B follows from that chain. A component found from a speed takes the sign it has in
  the scene's own solution.
- **Mistakes**: each effect declares the mistakes students make with it, as the relations such a
  student writes (:class:`grader.physics.effects.Mistake`); the chain is derived again with them, in
  every stage that declares the mistake, or, for a mistake of units, the right answer is read in the
  other unit. A mistake that changes no answer is left out.

>>> from grader.bank.template import load_bank
>>> from grader.model.expr import to_text
>>> from grader.solve.cache import alternatives_for
>>> found = alternatives_for(load_bank()["drop-rebound"])
>>> [a.id for a in found.for_answer("e") if a.kind == "mistake"]
['flight.two_gh', 'impact.rebound_sign', 'impact.e_squared', 'impact.e_inverse', 'impact.fixed_as_equal_mass']
>>> [(a.id, a.says, to_text(a.value)) for a in found.for_answer("loss_pct") if a.kind == "ecf"][-1]
('e', 'h_rebound', '100*((_given + 1)*(1 - _given))')
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from grader.model.expr import Node, from_json, to_json
from grader.model.kernel import evaluate
from grader.solve.compiled import PerAnswer

GIVEN = "_given"
"""The name of the earlier answer in an ECF tree, in that answer's unit (no parameter can be named so)."""


PLAUSIBLE = 3.0
"""How far from the right value an earlier answer may be and still carry forward (a factor, either way)."""


def carries_forward(given: ArrayLike, right: ArrayLike) -> np.ndarray:
    """Whether an earlier answer is plausible enough to carry forward, element-wise: a number of the right
    value's sign within a factor of :data:`PLAUSIBLE` of it (a nonsense answer must not make later parts
    trivial).

    >>> carries_forward([2.71, -2.71, 100.0, 0.8, float("nan")], 2.55).tolist()
    [True, False, False, False, False]
    """
    with np.errstate(all="ignore"):
        mine, theirs = np.abs(np.asarray(given, dtype=float)), np.abs(np.asarray(right, dtype=float))
        same_sign = np.sign(given) == np.sign(right)
        return np.asarray(same_sign & (theirs > 0) & (mine <= PLAUSIBLE * theirs) & (PLAUSIBLE * mine >= theirs))


@dataclass(frozen=True)
class Alternative:
    """Another value an answer may take: ``kind`` ``"ecf"`` (``id``: the earlier answer carried forward,
    ``says``: the parameter freed) or ``"mistake"`` (``id``: the mistake's, ``says``: what the student
    did, completing "your answer matches ..."). ``value`` is a tree over the parameters in the template's
    units, ``g`` and, for ECF, :data:`GIVEN`; it is in the answer's unit."""

    answer: str
    kind: str
    id: str
    says: str
    value: Node


@dataclass(frozen=True)
class Alternatives(PerAnswer[Alternative]):
    """A template's alternatives, ECF and mistakes, each in the order they are tried (an answer's: mistakes
    in the effects' order, ECF in the answers' order)."""

    def to_json(self) -> dict[str, Any]:
        """A JSON-ready dictionary."""
        return {"template": self.template_id, "source_hash": self.source_hash, "constants": dict(self.constants),
                "items": [{"answer": a.answer, "kind": a.kind, "id": a.id, "says": a.says, "value": to_json(a.value)}
                          for a in self.items]}

    @classmethod
    def from_json(cls, data: Mapping[str, Any]) -> Alternatives:
        """Inverse of :meth:`to_json`."""
        return cls(data["template"], data["source_hash"], dict(data["constants"]),
                   tuple(Alternative(a["answer"], a["kind"], a["id"], a["says"], from_json(a["value"]))
                         for a in data["items"]))


def values(alternatives: Alternatives, alternative: Alternative, params: Mapping[str, np.ndarray],
           given: np.ndarray | None = None) -> np.ndarray:
    """The alternative for each parameter set (columns of ``params``, in the template's units), with
    the earlier answer ``given`` for ECF; NaN where it is not a finite number.

    >>> from grader.bank.template import load_bank
    >>> from grader.solve.cache import alternatives_for
    >>> found = alternatives_for(load_bank()["drop-rebound"])
    >>> squared = next(a for a in found.for_answer("e") if a.id == "impact.e_squared")
    >>> values(found, squared, {"h_drop": np.array([2100.0]), "h_rebound": np.array([1100.0])}).round(4).tolist()
    [0.8507]
    """
    env: dict[str, Any] = {**params, **alternatives.constants}
    if given is not None:
        env[GIVEN] = given
    size = len(next(iter(params.values()))) if params else (0 if given is None else len(given))
    with np.errstate(all="ignore"):
        result = np.broadcast_to(np.asarray(evaluate(alternative.value, env), dtype=float), (size,))
    return np.where(np.isfinite(result), result, np.nan)
