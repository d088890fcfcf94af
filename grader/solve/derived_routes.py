"""The sympy side of :mod:`grader.solve.routes`: each answer's routes derived from the scene, and the
slope of the answer in each value written down along them.

The worked solution's route is the one the page prints (:func:`grader.solve.textbook_steps.textbook_route`): the
values a student copies from it are the ones the page computes, in its order (head-on's velocities after from
momentum and restitution, then the impulse from one of them), each from the form the page writes. Where the page
solves a block numerically, the route is the solver's chain, as the page's numeric block is.

Imported only when routes are compiled (the cache spares later runs the sympy import).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace
from typing import Any

import sympy as sp

from grader.bank.template import Template
from grader.base.errors import TemplateError, unworkable
from grader.model.expr import Node
from grader.physics.effects import CATALOGUE
from grader.physics.symbolic import INNER, cosd, from_node, hypot, sind, to_node
from grader.solve.compiled import Compiled, Step
from grader.solve.derived import _FAILURES
from grader.solve.page_forms import kernel_form
from grader.solve.routes import Route, Routes
from grader.solve.solver import _Compiler, _needed, _si_factor, _Solved, compile_template, derive
from grader.solve.stable import numeric_order
from grader.solve.textbook_steps import textbook_route

RATIO = "ratio"
"""The name of the ratio a square-root route writes down first (no step of a chain is named so)."""


def compile_routes(template: Template, compiled: Compiled | None = None) -> Routes:
    """Derive and compile a template's routes (sympy; then cached, see :func:`grader.solve.cache.routes_for`);
    ``compiled``: the template's compiled form, if the caller has it (else it is compiled here). A route the solver
    cannot derive or differentiate is left out; the worked solution's never is."""
    compiler = RouteCompiler(template, compiled or compile_template(template))
    return Routes(template.id, template.source_hash,
                  {"g": float(template.scene.gravity.si)} if template.scene.gravity else {},
                  tuple(compiler.routes()), tuple(template.symbols))


class RouteCompiler(_Compiler):
    """Compiles one template's routes."""

    def __init__(self, template: Template, compiled: Compiled) -> None:
        super().__init__(template)
        self.compiled = compiled
        self.printed = textbook_route(template, compiled)
        self.kernel_forms = {step.unknown: step.solved for step in compiled.steps}
        self.stages = [CATALOGUE[stage.effect].relations(stage, self.ctx) for stage in template.scene.stages]
        self.numeric = [name for name, spec in template.answers.items() if not spec.symbolic]

    def chains(self) -> list[tuple[str, str, list[_Solved]]]:
        """The worked solution's chain, then one per route an effect declares, with its stage's relations
        changed as the route writes them."""
        found = [("chain", "the worked solution", derive(self.relations, self.inputs, self.inputs))]
        for index, stage in enumerate(self.template.scene.stages):
            declared = CATALOGUE[stage.effect].routes
            for route in declared(stage, self.ctx) if declared is not None else ():
                relations = [r for at, real in enumerate(self.stages)
                             for r in (route.relations if at == index else real)]
                try:
                    found.append((route.id, route.says, derive(relations, self.inputs, self.inputs)))
                except _FAILURES as error:
                    if not unworkable(error):
                        raise
                    continue
        return found

    def routes(self) -> list[Route]:
        """Every numeric answer's routes, each once (a route that writes down the same values the same way
        as an earlier one is left out)."""
        chains = self.chains()
        found = []
        for name in self.numeric:
            seen: set[tuple[tuple[str, ...], str]] = set()
            for id, says, chain in chains:
                try:
                    route = self._route(name, id, says, chain)
                except _FAILURES as error:
                    if id == "chain" or not unworkable(error):
                        raise
                    continue
                if route is not None and (route.names, str(route.steps)) not in seen:
                    seen.add((route.names, str(route.steps)))
                    found.append(route)
            try:
                ratio = self._ratio_route(name, chains[0][2])
            except _FAILURES as error:
                if not unworkable(error):
                    raise
                ratio = None
            if ratio is not None:
                found.append(ratio)
        return found

    def _unit(self, name: str) -> Any:
        return _si_factor(self.template.answers[name].unit)

    def _written(self, name: str, chain: list[_Solved]) -> tuple[list[tuple[Any, Any]], Any] | None:
        """The values a route to ``name`` writes down (each over the inputs and earlier values, template
        units in) and the answer over them, or None where the chain does not reach it. A step that only
        copies a value or is a number writes nothing new down."""
        wanted = from_node(self.template.answers[name].value, self.ctx.symbols)
        known = self.inputs | {s.unknown for s in chain}
        if not wanted.free_symbols <= known:
            return None
        alias: dict[Any, Any] = {}
        steps = []
        symbols = {self.ctx.symbols[symbol] for symbol in self.template.symbols}
        for solved in _needed(chain, [wanted]):
            expr = solved.display.doit().xreplace(alias)
            # A value over a symbol (a mass m not given) is worked with as a symbol, never a number written down.
            if expr.is_Symbol or expr.is_number or (-expr).is_Symbol or expr.free_symbols & symbols:
                alias[solved.unknown] = expr
                continue
            steps.append((solved.unknown, self._user_units(expr)))
        return steps, self._user_units(wanted.xreplace(alias)) / self._unit(name)

    def _changed(self, chain: list[_Solved]) -> dict[str, _Solved]:
        """The steps of a declared route's chain found from the relations the route changes, by unknown."""
        real = {(r.label, r.lhs, r.rhs) for relations in self.stages for r in relations}
        return {str(s.unknown): s for s in chain if (s.relation.label, s.relation.lhs, s.relation.rhs) not in real}

    def _printed(self, name: str, route: list[_Solved] | None = None) -> tuple[list[tuple[Any, Any]], Any] | None:
        """The values the worked solution's page writes down on its way to ``name``, in its order, each from the
        form it prints (template units in), and the answer over them; with a declared ``route``'s chain, the values
        found from the relations it changes as it finds them instead (and those the page never writes, as it
        finds them), and only if the answer needs one of them. None where the page solves a value it needs
        numerically, or does not reach the answer. An angle the page writes ``tan⁻¹(y/x)`` is the kernel's
        ``atan2(y, x)``: the same values written down, and the angle where ``x < 0`` too."""
        symbols = dict(self.ctx.symbols)
        wanted = from_node(self.template.answers[name].value, symbols)
        changed = self._changed(route) if route is not None else {}
        forms: dict[str, Any] = {}
        numeric = set()
        for step in self.printed.steps:
            if step.unknown in forms:
                continue
            if step.numeric:  # a root(...) tree: the route cannot be written down to it
                numeric.add(step.unknown)
                forms[step.unknown] = sp.S.Zero
                continue
            form = self.kernel_forms[step.unknown] if step.unknown in self.printed.positive else step.solved
            forms[step.unknown] = from_node(kernel_form(form), symbols)
        if route is not None:  # the route's own values, and those the page never writes (T′), as a page writes them
            own = self._as_printed(route)
            for solved in route:
                unknown = str(solved.unknown)
                if unknown in changed or unknown not in forms:
                    forms.pop(unknown, None)
                    forms[unknown] = own.get(unknown, solved.display.doit())
        inputs = {str(symbol) for symbol in self.inputs}
        needed: set[str] = set()
        frontier = {str(symbol) for symbol in wanted.free_symbols} - inputs
        while frontier:
            quantity = frontier.pop()
            if quantity not in forms or quantity in numeric:
                return None
            needed.add(quantity)
            frontier |= {str(symbol) for symbol in forms[quantity].free_symbols} - inputs - needed
        if route is not None and not needed & set(changed):
            return None
        alias: dict[Any, Any] = {}
        steps = []
        valueless = {self.ctx.symbols[symbol] for symbol in self.template.symbols}
        for unknown in _in_order([n for n in forms if n in needed], forms):
            expr = forms[unknown].xreplace(alias)
            symbol = symbols.setdefault(unknown, sp.Symbol(unknown, real=True))
            # as on the chain: a copy, a number or a multiple of a symbol without value is not written down
            if expr.is_Symbol or expr.is_number or (-expr).is_Symbol or expr.free_symbols & valueless:
                alias[symbol] = expr
                continue
            steps.append((symbol, self._user_units(expr)))
        return steps, self._user_units(wanted.xreplace(alias)) / self._unit(name)

    def _as_printed(self, chain: list[_Solved]) -> dict[str, Any]:
        """A declared route's values as a page would write them (:func:`textbook_route` over its chain: a velocity
        after from momentum and restitution, not from the impulse form), over the inputs and earlier values (SI);
        empty where its chain has a form a page cannot take."""
        try:
            steps = tuple(Step(str(s.unknown), s.relation.label,
                               (to_node(sp.sympify(s.relation.lhs)), to_node(sp.sympify(s.relation.rhs))),
                               to_node(sp.sympify(s.display.doit())), tuple(str(b) for b in s.block)) for s in chain)
        except _FAILURES as error:
            if not unworkable(error):
                raise
            return {}
        page = textbook_route(self.template, replace(self.compiled, steps=steps))
        kernel = {step.unknown: step.solved for step in steps}
        symbols = dict(self.ctx.symbols)
        return {step.unknown: from_node(kernel_form(kernel[step.unknown] if step.unknown in page.positive
                                                    else step.solved), symbols) for step in page.steps}

    def _route(self, name: str, id: str, says: str, chain: list[_Solved]) -> Route | None:
        if id == "chain":
            written = self._printed(name) or self._written(name, chain)
        else:  # a declared route counts for an answer that needs a value it finds its own way
            written = self._printed(name, chain)
            if written is None and {str(s.unknown) for s in _needed(chain, [self._wanted(name)])} \
                    & set(self._changed(chain)):
                written = self._written(name, chain)
        if written is None:
            return None
        steps, answer = written
        return self._compiled(name, id, says, steps, answer)

    def _wanted(self, name: str) -> Any:
        return from_node(self.template.answers[name].value, self.ctx.symbols)

    def _ratio_route(self, name: str, chain: list[_Solved]) -> Route | None:
        """``e`` from ``√(h_rebound/h_drop)``: for an answer with a square root whose square is a rational
        function of the parameters, that ratio written down, then its root."""
        written = self._written(name, chain)
        if written is None:
            return None
        steps, answer = written
        composed = answer.xreplace(_composition(steps))
        parameters = [self.ctx.symbols[p] for p in self.template.parameters]
        if composed.is_rational_function(*parameters):  # nothing to take a root of
            return None
        square = sp.powsimp(composed**2, force=True)
        if not square.is_rational_function(*parameters):  # before expanding: a sum of roots squared can
            return None  # take sympy's polynomial gcd half a minute to cancel (pile-driver's e)
        square = sp.cancel(sp.powsimp(sp.expand(square), force=True))
        if not (square.free_symbols <= set(parameters) and square.is_rational_function(*parameters)
                and not square.is_Symbol and composed.is_nonnegative):
            return None
        ratio = sp.Symbol(RATIO, positive=True)
        return self._compiled(name, "ratio", f"{name} = √({sp.sstr(square)})",
                              [(ratio, square)], sp.sqrt(ratio))

    def _compiled(self, name: str, id: str, says: str, steps: list[tuple[Any, Any]], answer: Any) -> Route:
        """A route with the slope of the answer in each value written down, later values recomputed."""
        slopes: list[Any] = [None] * len(steps)
        outcome = _smooth(answer)
        for index in reversed(range(len(steps))):
            symbol, expr = steps[index]
            slopes[index] = outcome.diff(symbol)
            outcome = outcome.xreplace({symbol: _smooth(expr)})
        composition = _composition(steps)
        composed = [expr.xreplace(composition) for _, expr in steps]
        slope_trees = [_tree(slope.xreplace({s: _smooth(c) for (s, _), c in zip(steps, composed, strict=True)})
                             .replace(sp.DiracDelta, lambda *args: 0)) for slope in slopes]
        return Route(name, id, says, tuple(str(s) for s, _ in steps), tuple(_tree(e) for _, e in steps), _tree(answer),
                     tuple(_tree(c) for c in composed), tuple(slope_trees))


def _in_order(quantities: list[str], forms: Mapping[str, Any]) -> list[str]:
    """``quantities`` in their order, each moved after those its form uses (a value a declared route finds its own
    way comes after the page's values it is found from)."""
    done: list[str] = []
    waiting = list(quantities)
    while waiting:
        ready = next(q for q in waiting
                     if not {str(s) for s in forms[q].free_symbols} & (set(waiting) - {q}))
        waiting.remove(ready)
        done.append(ready)
    return done


def _composition(steps: list[tuple[Any, Any]]) -> dict[Any, Any]:
    """Each value written down over the parameters alone."""
    composed: dict[Any, Any] = {}
    for symbol, expr in steps:
        composed[symbol] = expr.xreplace(composed)
    return composed


def _smooth(expr: Any) -> Any:
    """A form sympy differentiates: ``hypot``, ``sind``, ``cosd`` written out; ``Max(0, x)`` as ``x``
    (a route does not clip what it computes)."""
    return sp.sympify(expr).replace(hypot, lambda x, y: sp.sqrt(x**2 + y**2)).replace(
        sind, lambda x: sp.sin(x * sp.pi / 180)).replace(cosd, lambda x: sp.cos(x * sp.pi / 180)).replace(
        lambda e: isinstance(e, sp.Max) and len(e.args) == 2 and sp.S.Zero in e.args,
        lambda e: next(a for a in e.args if a != 0))


def _tree(expr: Any) -> Node:
    if sp.sympify(expr).has(sp.Derivative, sp.Subs, sp.Heaviside, sp.DiracDelta, sp.zoo, sp.nan, sp.oo):
        raise TemplateError(INNER, str(expr), "a numeric form (no derivative, step or infinity)")
    return numeric_order(to_node(sp.sympify(expr)))
