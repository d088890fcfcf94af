"""The solution routes a student follows to each answer, and how far rounding along them moves it.

A student writes values down along a route, each rounded to the figures the sheet asks for, and
gives the answer to three. For every numeric answer the routes are: the worked solution's, as the page
prints it (each value the page computes, in its order, from the form it prints:
:func:`~grader.solve.textbook_steps.textbook_route`; the solver's chain where the page solves a value it
needs numerically); the textbook's other routes that the effects declare (an impact's energies: ``T`` and
``T′`` written down, then ``(T − T′)/T``), the page's values but those the route finds its own way, and
only for an answer that needs one of them (a route that writes down what the page does is the page's: the
worked solution finds an impact's energy lost as ``T − T′`` wherever the velocities after are on it); and,
for an answer whose square is a ratio of the parameters, that ratio written down first (``e`` from
``√(h_rebound/h_drop)``). A percentage comes from the fraction the route writes down. Printed
parameters are used as printed, never rounded again; a value that is only copied (``v_t′ = v_t``)
or a number is not written down again.

The bound is first order, vectorised over a class: ``Σ |∂answer/∂q_i| · h_i`` over the values
``q_i`` written down, with ``h_i`` half a unit in the ``N``-th significant figure of ``q_i`` as the
route computes it (parameters in the template's units, derived values in SI, angles derived in
radians). The slopes are sympy's (:mod:`grader.solve.derived_routes`), once per template,
cached and compiled into one :class:`~grader.model.kernel.Kernel` like the answers. Where first order
may be poor (a bound large enough to widen a tolerance, or not finite) the route is also evaluated
directly with every value moved by its half unit in the direction that moves the answer most, both
ways, and the larger figure is kept.

>>> import numpy as np
>>> from grader.bank.template import load_bank
>>> from grader.solve.cache import routes_for
>>> routes = routes_for(load_bank()["oblique-spheres"])
>>> for route in routes.for_answer("loss_pct"):
...     print(route.id, " ".join(route.names))
chain v1_n v1_t v1_n_after v2_n_after T T_after E_lost f_loss
>>> params = {"v1": np.array([6.0]), "theta": np.array([30.0]), "e": np.array([0.6]), "m1": np.array([1.0]),
...           "m2": np.array([1.0])}
>>> moves = rounding_bounds(routes, params, 4)["loss_pct"]
>>> routes.items[moves.route[0]].id, round(float(moves.bound[0]), 3)
('chain', 0.089)
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np

from grader.model.expr import Node, from_json, to_json
from grader.model.kernel import Kernel, evaluate
from grader.model.quantities import half_unit
from grader.solve.compiled import PerAnswer


@dataclass(frozen=True)
class Route:
    """One route to one answer. ``names`` are the values written down, in order; ``steps`` give each
    over the parameters (template units), ``g``, the template's symbols and the earlier names;
    ``value`` gives the answer (its unit) over the same and all names. ``composed`` gives each name
    over the parameters alone, and ``slopes`` each ``∂answer/∂name`` (later names recomputed from it)."""

    answer: str
    id: str
    says: str
    names: tuple[str, ...]
    steps: tuple[Node, ...]
    value: Node
    composed: tuple[Node, ...]
    slopes: tuple[Node, ...]


@dataclass(frozen=True)
class Routes(PerAnswer[Route]):
    """A template's routes, every answer's in order (the worked solution's chain first); ``symbols`` are
    the template's symbols (a route's values over one are never written down; evaluated at 1)."""

    symbols: tuple[str, ...] = ()

    @cached_property
    def kernel(self) -> Kernel:
        """Every value written down and every slope of every route, compiled once:
        ``("q", route, i)`` and ``("slope", route, i)``."""
        trees: dict[Any, Node] = {}
        for index, route in enumerate(self.items):
            for step, (value, slope) in enumerate(zip(route.composed, route.slopes, strict=True)):
                trees["q", index, step] = value
                trees["slope", index, step] = slope
        return Kernel(trees, self.constants)

    def to_json(self) -> dict[str, Any]:
        """A JSON-ready dictionary."""
        return {"template": self.template_id, "source_hash": self.source_hash, "constants": dict(self.constants),
                "symbols": list(self.symbols),
                "items": [{"answer": r.answer, "id": r.id, "says": r.says, "names": list(r.names),
                           "steps": [to_json(s) for s in r.steps], "value": to_json(r.value),
                           "composed": [to_json(c) for c in r.composed], "slopes": [to_json(s) for s in r.slopes]}
                          for r in self.items]}

    @classmethod
    def from_json(cls, data: Mapping[str, Any]) -> Routes:
        """Inverse of :meth:`to_json`."""
        return cls(data["template"], data["source_hash"], dict(data["constants"]),
                   tuple(Route(r["answer"], r["id"], r["says"], tuple(r["names"]),
                               tuple(from_json(s) for s in r["steps"]), from_json(r["value"]),
                               tuple(from_json(c) for c in r["composed"]), tuple(from_json(s) for s in r["slopes"]))
                         for r in data["items"]), tuple(data["symbols"]))


@dataclass(frozen=True)
class Moves:
    """How far rounding the values written down can move one answer, per parameter set: ``bound``
    (in the answer's unit; the largest over its routes, NaN where none could be bounded), ``route``
    (the index in :attr:`Routes.items` of the route that moves it most, -1 if none) and ``shares``
    (for each route, each value's part of that route's bound)."""

    bound: np.ndarray
    route: np.ndarray
    shares: Mapping[int, np.ndarray]


def rounding_bounds(routes: Routes, params: Mapping[str, Any], figures: int,
                    check: Callable[[str, np.ndarray], np.ndarray] | None = None) -> dict[str, Moves]:
    """For every answer with routes, how far rounding each value written down to ``figures`` significant
    figures moves it (first order), per parameter set (columns of ``params``, template units).

    ``check(answer, bound)`` picks the rows where first order is not trusted (by default, where the bound
    is not finite): there each route is also evaluated directly with its values moved by their half units
    (:func:`moved_route`), and the larger figure kept.
    """
    size = len(next(iter(params.values()))) if params else 0
    env = {**{name: np.asarray(column, dtype=float) for name, column in params.items()},
           **{name: np.ones(size) for name in routes.symbols}}
    with np.errstate(all="ignore"):
        trees: Mapping[Any, Any] = routes.kernel({name: env[name] for name in routes.kernel.inputs})

    def column(kind: str, index: int, step: int) -> np.ndarray:
        return np.broadcast_to(np.asarray(trees[kind, index, step], dtype=np.float64), (size,))

    by_answer: dict[str, list[int]] = {}
    for index, route in enumerate(routes.items):
        by_answer.setdefault(route.answer, []).append(index)
    result = {}
    for answer, indices in by_answer.items():
        shares, halves = {}, {}
        with np.errstate(all="ignore"):
            for index in indices:
                steps = range(len(routes.items[index].names))
                halves[index] = [half_unit(column("q", index, i), figures) for i in steps]
                shares[index] = np.array([np.abs(column("slope", index, i)) * halves[index][i]
                                          for i in steps]).reshape(len(steps), size)
        table = np.array([shares[index].sum(axis=0) for index in indices])
        doubtful = ~np.isfinite(table).all(axis=0)
        if check is not None:
            doubtful |= check(answer, table.max(axis=0))
        rows = np.flatnonzero(doubtful)
        if rows.size:
            subset = {name: values[rows] for name, values in env.items()}
            for position, index in enumerate(indices):
                moves = [np.sign(column("slope", index, i)[rows]) * half[rows] for i, half in enumerate(halves[index])]
                exact = walk_route(routes, routes.items[index], subset)
                direct = np.fmax(*(np.abs(moved_route(routes, routes.items[index], subset, sign, moves, exact))
                                   for sign in (1.0, -1.0)))
                table[position, rows] = np.fmax(table[position, rows], direct)
        with np.errstate(invalid="ignore"):
            bound = table.max(axis=0)  # NaN where a route could not be bounded either way
        best = np.array(indices)[np.argmax(np.where(np.isnan(table), -np.inf, table), axis=0)]
        result[answer] = Moves(bound, np.where(np.isfinite(bound), best, -1), shares)
    return result


def moved_route(routes: Routes, route: Route, env: Mapping[str, np.ndarray], sign: float,
                moves: list[np.ndarray], exact: np.ndarray | None = None) -> np.ndarray:
    """How far the answer moves along ``route`` when each value written down is moved by ``sign`` times
    its ``moves`` (a half unit, signed the way its slope moves the answer up), each moved value used by
    the later steps; ``exact``: the answer along the route unmoved, when the caller has it."""
    if exact is None:
        exact = walk_route(routes, route, env)
    moved = walk_route(routes, route, env, lambda step, value: value + sign * moves[step])
    difference: np.ndarray = moved - exact
    return difference


def walk_route(routes: Routes, route: Route, env: Mapping[str, np.ndarray],
               written: Callable[[int, np.ndarray], np.ndarray] | None = None) -> np.ndarray:
    """The answer along a route, each value written down passed through ``written(step, value)`` first
    (rounded, or moved; None: kept exact). ``env`` holds the parameters as printed."""
    values: dict[str, Any] = {**routes.constants, **env}
    size = len(next(iter(env.values()))) if env else 0
    for name in routes.symbols:
        values.setdefault(name, np.ones(size))
    with np.errstate(all="ignore"):
        for step, (name, tree) in enumerate(zip(route.names, route.steps, strict=True)):
            value = np.broadcast_to(np.asarray(evaluate(tree, values), dtype=float), (size,))
            values[name] = value if written is None else written(step, value)
        answer: np.ndarray = np.broadcast_to(np.asarray(evaluate(route.value, values), dtype=float), (size,))
        return answer
