"""From a scene and what is known, a chain of steps, compiled into expression trees over the parameters
that the numpy kernels evaluate.

A step is a block of the scene's equations in block-triangular order (docs/design.md, The solver): one
equation giving one unknown, as a student writes it, wherever the chain can go on so; where it cannot, the
smallest set of equations that fixes as many unknowns as it has (a 2x2 linear system: momentum and
restitution), solved together in closed form, with the root the scene's conditions select.

Sympy does the algebra once per template; :mod:`grader.solve.cache` keeps the result, so a later run
needs neither sympy nor this module.

>>> from grader.bank.template import load_bank
>>> compiled = compile_template(load_bank()["drop-rebound"])
>>> [step.unknown for step in compiled.steps]
['v_impact', 'T', 'v_after', 'e', 'E_lost', 'f_loss']
>>> from grader.model.expr import to_text
>>> to_text(compiled.answers["loss_pct"].numeric)
'100*Max(0, h_drop - h_rebound)/h_drop'
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Any

import sympy as sp

from grader.bank.template import Template
from grader.base.errors import SYMPY_FAILURES, TemplateError, shown, unworkable
from grader.model.expr import Node, Num, Op, names, substitute
from grader.model.quantities import Unit
from grader.model.roots import TOLERANCE_TEXT
from grader.physics.effects import CATALOGUE, Condition, Relation
from grader.physics.symbolic import INNER as _INNER
from grader.physics.symbolic import Context, cosd, from_node, sind, to_node
from grader.solve.compiled import Check, Compiled, CompiledAnswer, Step, Undefined
from grader.solve.stable import numeric_order, stabilize
from grader.solve.torn import identity, interval, root_node, roots_at


@dataclass(frozen=True)
class _Solved:
    unknown: Any
    relation: Relation
    display: Any
    numeric: Any
    branch: bool = False  # the magnitude only: the sign is the one the unknown has in the scene's own solution
    block: tuple[Any, ...] = ()  # the unknowns solved together with this one (empty: a step of one equation)
    requires: tuple[Condition, ...] = ()  # what the step needs of the values (a block: that it fixes its unknowns)
    residual: Any = None  # a numeric block's unknown: lhs - rhs of the equation that closes the block (else None)
    interval: tuple[float, float] = (0.0, 0.0)  # a numeric block's unknown: where its one root is looked for (SI)
    at_points: tuple[float, ...] = ()  # a numeric block's unknown: its root at each of derive's points (SI)


def derive(relations: list[Relation], knowns: Iterable[Any], given: Iterable[Any],
           branches: bool = False, wanted: Iterable[Any] = (), points: Sequence[Mapping[Any, float]] = (),
           numeric: bool = False) -> list[_Solved]:
    """Solve relations one unknown at a time, earliest relation first, as far as they go; then, while
    something in ``wanted`` is still unknown, the next block of equations solved together
    (:func:`next_block`), and one at a time again.

    ``given`` are the knowns that are inputs (not derived): a stable form that asks for its
    symbols to be given is used only then. With ``branches``, a relation may also give an unknown
    known only up to sign (a step marked ``branch``), where no other relation gives it. ``points`` (the
    inputs' values in SI at the template's example and at draws across its sampling) tell apart the roots
    of a block that the scene's conditions select only once the values are known (:func:`solve_block`).
    With ``numeric``, a block with no closed form is solved numerically (:func:`~grader.solve.torn.torn_block`).
    """
    known, given_set, targets = set(knowns), set(given), set().union(*(sp.sympify(w).free_symbols for w in wanted))
    used: set[int] = set()
    chain: list[_Solved] = []
    while True:
        step = _next_step(relations, known, given_set, used) or (
            _next_branch(relations, known, used) if branches else None)
        if step is not None:
            chain.append(step)
            known.add(step.unknown)
            continue
        if not targets - known:
            return chain
        block = next_block(relations, known, used, points, chain, targets)
        if block is None and numeric:
            torn = torn_block(relations, known, given_set, used, points, chain, targets)
            if isinstance(torn, str):
                raise TemplateError(_INNER, "stages", "a scene that tells its solutions apart", _two_solutions(torn))
            block = torn
        if block is None:
            return chain
        chain += block
        known |= {solved.unknown for solved in block}


def _next_step(relations: list[Relation], known: set[Any], given: set[Any], used: set[int]) -> _Solved | None:
    """The earliest relation that gives its one unknown (marked used), or None."""
    for index, relation in enumerate(relations):
        if index in used:
            continue
        unknowns = relation.symbols() - known
        if not unknowns:
            used.add(index)
            continue
        if len(unknowns) != 1:
            continue
        unknown = unknowns.pop()
        display = _solve(relation, unknown)
        if display is None:
            continue
        used.add(index)
        return _Solved(unknown, relation, display, _stable(relation, unknown, display, known, given))
    return None


def _next_branch(relations: list[Relation], known: set[Any], used: set[int]) -> _Solved | None:
    """The earliest relation that gives its one unknown up to sign (marked used), or None."""
    for index, relation in enumerate(relations):
        unknowns = relation.symbols() - known
        if index not in used and len(unknowns) == 1 and (unknown := unknowns.pop()) in relation.branches:
            used.add(index)
            return _Solved(unknown, relation, relation.branches[unknown], relation.branches[unknown], branch=True)
    return None


MAX_BLOCK = 4
"""The most equations solved together; a larger block is left unsolved (the template is refused)."""
MAX_DEGREE = 4
"""The highest Bezout number (the product of the equations' degrees) of a block solved in closed form:
linear systems, and quadratics or two coupled ones, whose roots sympy writes with square roots."""


def next_block(relations: list[Relation], known: set[Any], used: set[int],
               points: Sequence[Mapping[Any, float]] = (), chain: list[_Solved] | None = None,
               asked: set[Any] | None = None) -> list[_Solved] | None:
    """The first block of the open relations, in block-triangular order, that has one solution; its
    relations are marked used. None if there is none.

    The open relations (unused, with an unknown) are matched to their unknowns (a maximum bipartite
    matching, relations with fewer unknowns first, then in order); a relation then depends on the relations
    matched to its other unknowns, and the strongly connected components of that graph (Tarjan),
    dependencies first, are the blocks. A block is solvable when every unknown its equations hold is
    matched inside it. Such a block is solved together (:func:`solve_block`). One whose solutions nothing
    tells apart is refused, naming them, if no other block lets the chain go on.
    """
    unknowns_of = {index: relation.symbols() - known for index, relation in enumerate(relations)
                   if index not in used and relation.symbols() - known}
    # Relations with fewer unknowns are matched first: where the open relations fix more than they hold
    # (momentum, impulse and restitution say the same thing), the small closed blocks are the ones kept.
    open_relations = sorted(unknowns_of, key=lambda index: (len(unknowns_of[index]), index))
    owner = _matching(open_relations, unknowns_of)
    matched = {index: unknown for unknown, index in owner.items()}
    graph = {index: [owner[u] for u in sorted(unknowns_of[index], key=str) if u in owner and owner[u] != index]
             for index in open_relations if index in matched}
    ambiguous = []
    for component in strongly_connected(graph):
        members = sorted(component)
        unknowns = [matched[index] for index in members]
        if len(members) > MAX_BLOCK or set().union(*(unknowns_of[index] for index in members)) != set(unknowns):
            continue
        found = solve_block([relations[index] for index in members], unknowns, relations, known,
                            lambda: [(point, _values_at(point, chain or [], i)) for i, point in enumerate(points)],
                            asked)
        if isinstance(found, str):
            ambiguous.append(found)
        elif found is not None:
            used.update(members)
            return found
    if ambiguous:
        raise TemplateError(_INNER, "stages", "a scene that tells its solutions apart", _two_solutions(ambiguous[0]))
    return None


def _two_solutions(equations: str) -> str:
    """The refusal of a block with two admissible roots: ``equations`` (which, and the roots at a sampled
    point) after the field it is about, so the message reads file: field: expected ..., got ...."""
    return (f"{equations}: two physical solutions that nothing in it (a sign, a domain, a condition) tells apart: "
            "give the quantity that decides between them, or ask the question the other way round (a name no "
            "parameter, symbol or answer defines is an unknown the scene must find: check its spelling)")


def _matching(rows: list[int], columns_of: Mapping[int, set[Any]]) -> dict[Any, int]:
    """A maximum matching of rows to columns (augmenting paths, rows in order, columns by name): each
    matched column's row."""
    owner: dict[Any, int] = {}

    def augment(row: int, seen: set[Any]) -> bool:
        for column in sorted(columns_of[row], key=str):
            if column not in seen:
                seen.add(column)
                if column not in owner or augment(owner[column], seen):
                    owner[column] = row
                    return True
        return False

    for row in rows:
        augment(row, set())
    return owner


def strongly_connected(graph: Mapping[int, list[int]]) -> list[list[int]]:
    """The strongly connected components of ``graph`` (Tarjan), each after every component it reaches:
    with an edge from a relation to the relations it needs, dependencies come first.

    >>> strongly_connected({0: [1], 1: [0], 2: [0], 3: []})
    [[1, 0], [2], [3]]
    """
    index: dict[int, int] = {}
    low: dict[int, int] = {}
    stack: list[int] = []
    on_stack: set[int] = set()
    found: list[list[int]] = []

    def visit(node: int) -> None:
        index[node] = low[node] = len(index)
        stack.append(node)
        on_stack.add(node)
        for successor in graph.get(node, []):
            if successor not in index:
                visit(successor)
                low[node] = min(low[node], low[successor])
            elif successor in on_stack:
                low[node] = min(low[node], index[successor])
        if low[node] == index[node]:
            component = []
            while True:
                member = stack.pop()
                on_stack.discard(member)
                component.append(member)
                if member == node:
                    break
            found.append(component)

    for node in graph:
        if node not in index:
            visit(node)
    return found


def solve_block(block: list[Relation], unknowns: list[Any], relations: list[Relation], known: set[Any],
                values: Any = lambda: None, asked: set[Any] | None = None) -> list[_Solved] | str | None:
    """The one solution of ``block``'s equations for ``unknowns`` (``unknowns[i]`` shown beside ``block[i]``),
    as steps; None if they have no closed form here (not polynomial in the unknowns, or of a Bezout number
    above :data:`MAX_DEGREE`) or no admissible root; a sentence naming two roots if more than one is.

    A root is admissible when it is real, leaves no denominator of the equations zero, fits the unknowns'
    assumptions and breaks no condition of the scene's relations (``e >= 0``, the bodies approach) that
    sympy can decide. Where several remain, ``values()`` (the known quantities at the template's example and
    at draws across its sampling) decides: the root that alone is real and meets every condition at each of
    them where any does (:func:`_selected`); where two do at one point, or different roots at two, none is
    chosen, and the sentence names both at that point, for an unknown of ``asked`` whose roots differ if
    there is one.
    """
    asked = asked or set()
    numerators, denominators, degree = [], [], 1
    for relation in block:
        numerator, denominator = sp.fraction(sp.together(sp.sympify(relation.lhs) - sp.sympify(relation.rhs)))
        if not numerator.is_polynomial(*unknowns):
            return None
        degree *= max(1, sp.Poly(numerator, *unknowns).total_degree())
        numerators.append(numerator)
        denominators.append(denominator)
    if degree > MAX_DEGREE:
        return None
    conditions = [c.holds for relation in relations for c in relation.requires
                  if sp.sympify(c.holds).free_symbols & set(unknowns)
                  and sp.sympify(c.holds).free_symbols <= known | set(unknowns)]
    roots = [root for root in sp.solve(numerators, unknowns, dict=True, check=False, simplify=False)
             if set(root) == set(unknowns) and not any(v.free_symbols & set(unknowns) for v in root.values())
             and all(v.is_real is not False for v in root.values())
             and not any(d.xreplace(root).is_zero for d in denominators)
             and all(sp.sympify(c).xreplace(root) is not sp.false for c in conditions)]
    ambiguous_at: tuple[Mapping[Any, float], dict[Any, Any]] | None = None
    if len(roots) > 1:
        roots, ambiguous_at = _selected(roots, conditions, values())
    if not roots:
        return None
    if len(roots) > 1:
        labels = " and ".join(f"({chr(97 + i)}) {relation.label}" for i, relation in enumerate(block))
        differing = [u for u in unknowns if sp.expand(roots[0][u] - roots[1][u]) != 0] or unknowns
        first = next((u for u in differing if u in asked), differing[0])
        if ambiguous_at is not None:
            inputs, at = ambiguous_at
            one, other = (f"{first} = {float(sp.re(sp.N(root[first].xreplace(at)))):.6g}" for root in roots[:2])
            return f"the equations {labels}, which give {one} or {other} (SI) at {_where(inputs)}"
        one, other = (f"{first} = {shown(str(root[first]), 80)}" for root in roots[:2])
        return f"the equations {labels}, which give {one} or {other}"
    together = tuple(unknowns) if len(unknowns) > 1 else ()
    steps = [_Solved(unknown, relation, tidy := _as_written(roots[0][unknown]), tidy, block=together)
             for unknown, relation in zip(unknowns, block, strict=True)]
    return [replace(steps[0], requires=_determined(block, numerators, unknowns, roots[0])), *steps[1:]]


def _sides(relation: Relation) -> tuple[Any, Any]:
    """A relation's two sides as a residual takes them: its solved form where it has one (``theta =
    atan2(v_n, v_t)``, which keeps the quadrant that ``tan(theta) = v_n/v_t`` loses, and has no pole), else its
    equation."""
    for unknown, solved in relation.solutions.items():
        if unknown not in sp.sympify(solved).free_symbols:
            return sp.sympify(unknown), sp.sympify(solved).doit()
    return sp.sympify(relation.lhs), sp.sympify(relation.rhs)


def _as_written(root: Any) -> Any:
    """A block's root as a textbook writes it, the shorter of: factored (``m1 m2 (1 + e)(v2 - v1_out)/(e m2 -
    m1)``, whose difference of inputs is also formed first), or a quotient whose numerator is collected on the
    quantities it holds linearly and its denominator does not (``((1 + e) m2 v2 - (m1 + m2) v1_out)/(e m2 -
    m1)``).

    >>> m1, m2 = sp.symbols("m1 m2", positive=True)
    >>> e, v2, v1_out = sp.symbols("e v2 v1_out", real=True)
    >>> _as_written((m2*v2 + e*m2*v2 - m1*v1_out - m2*v1_out)/(e*m2 - m1))
    (m2*v2*(e + 1) + v1_out*(-m1 - m2))/(e*m2 - m1)
    """
    numerator, denominator = sp.fraction(sp.together(root))
    linear = sorted((symbol for symbol in numerator.free_symbols - denominator.free_symbols
                     if numerator.is_polynomial(symbol) and sp.degree(numerator, symbol) == 1), key=str)
    collected = sp.collect(sp.expand(numerator), linear, func=sp.factor) / sp.factor(denominator)
    factored = sp.factor(root)
    return factored if sp.count_ops(factored) <= sp.count_ops(collected) else collected


def _determined(block: list[Relation], numerators: list[Any], unknowns: list[Any],
                root: Mapping[Any, Any]) -> tuple[Condition, ...]:
    """That the block fixes its unknowns at the values drawn: its Jacobian's determinant at the root is not
    zero, to 1e-9 of the sum of its terms' sizes (where it vanishes, as for a cart of ``e`` times the
    other's mass whose rebound is the other's velocity, any velocity before fits: the draw is refused)."""
    determinant = sp.factor(sp.Matrix(numerators).jacobian(unknowns).det().xreplace(root))
    if determinant.is_nonzero:  # a sum of positive masses: the block fixes its unknowns at every draw
        return ()
    size = sp.Add(*[sp.Abs(term) for term in sp.Add.make_args(sp.expand(determinant))])
    labels = " and ".join(f"({chr(97 + i)}) {relation.label}" for i, relation in enumerate(block))
    return (Condition(sp.Gt(sp.Abs(determinant), size / 10**9),
                      f"the equations {labels} do not fix {', '.join(map(str, unknowns))} for these values: their "
                      f"determinant, {determinant}, is zero (to 1e-9 of its terms), so the scene has no single "
                      "solution here"),)


def _selected(roots: list[Mapping[Any, Any]], conditions: list[Any],
              points: list[tuple[Mapping[Any, float], dict[Any, Any]]]
              ) -> tuple[list[Mapping[Any, Any]], tuple[Mapping[Any, float], dict[Any, Any]] | None]:
    """The one root that is the only admissible one (:func:`_admissible`) at every point where any is, and
    None; or all the roots, with the first point (its inputs, and every value known there) that shows they
    are not told apart (two admissible there, or another root than at an earlier point). With no point
    deciding, all the roots and None."""
    chosen = None
    for point in points:
        admissible = [index for index, root in enumerate(roots) if _admissible(root, conditions, point[1])]
        if not admissible:
            continue
        if len(admissible) > 1 or (chosen is not None and admissible[0] != chosen):
            return roots, point
        chosen = admissible[0]
    return ([roots[chosen]], None) if chosen is not None else (roots, None)


def _where(inputs: Mapping[Any, float]) -> str:
    """A point's inputs in SI, as the refusal of a block names them: ``m1 = 2, v1 = 4``."""
    return ", ".join(f"{symbol} = {value:.6g}" for symbol, value in sorted(inputs.items(), key=lambda i: str(i[0])))


def _admissible(root: Mapping[Any, Any], conditions: list[Any], at: Mapping[Any, Any]) -> bool:
    """Whether a root is real and finite, and meets every condition, at the values ``at``."""
    values = {unknown: sp.N(value.xreplace(at)) for unknown, value in root.items()}
    if not all(v.is_finite and abs(sp.im(v)) <= 1e-12 * (1 + abs(sp.re(v))) for v in values.values()):
        return False
    real = {unknown: sp.re(value) for unknown, value in values.items()}
    return all(sp.sympify(c).xreplace({**at, **real}) is not sp.false for c in conditions)


def _values_at(point: Mapping[Any, float], chain: list[_Solved], index: int) -> dict[Any, Any]:
    """The inputs at ``point`` (derive's ``index``-th) and every quantity the chain has found so far, evaluated
    there (a numeric block's unknown: the root found there, if one was)."""
    values: dict[Any, Any] = {symbol: sp.Float(value) for symbol, value in point.items()}
    for solved in chain:
        if solved.residual is not None:
            values[solved.unknown] = sp.Float(solved.at_points[index]) if solved.at_points[index] == \
                solved.at_points[index] else sp.nan
            continue
        values[solved.unknown] = sp.N(solved.numeric.doit().xreplace(values))
    return values


def torn_block(relations: list[Relation], known: set[Any], given: set[Any], used: set[int],
               points: Sequence[Mapping[Any, float]], chain: list[_Solved], asked: set[Any]
               ) -> list[_Solved] | str | None:
    """A block with no closed form, torn as equation-based tools tear it: one of its unknowns taken as known
    (an asked one first), the others follow one equation at a time, until an equation is left with no unknown;
    that equation, a residual in the torn unknown alone, is solved numerically (:mod:`grader.model.roots`).
    Its steps: the torn unknown (with its residual, the interval its root is looked for in and its roots at
    ``points``), then the unknowns that follow from it. None if no unknown tears a block that has a root at
    some point; a sentence naming two roots if at some point two meet every condition (marked used: else)."""
    composed: dict[Any, Any] = {}
    for solved in chain:
        composed[solved.unknown] = solved.unknown if solved.residual is not None else \
            solved.numeric.doit().xreplace(composed)
    open_unknowns = {s for i, r in enumerate(relations) if i not in used for s in r.symbols() - known}
    for tear in sorted(open_unknowns, key=lambda s: (s not in asked, str(s))):
        trial, have, closing = set(used), known | {tear}, None
        inner: list[_Solved] = []
        while True:
            found = {tear} | {step.unknown for step in inner}
            closing = next((i for i, r in enumerate(relations)
                            if i not in trial and r.symbols() <= have and r.symbols() & found), None)
            if closing is None:
                step = _next_step(relations, have, given, trial)
                if step is None:
                    break
                inner.append(step)
                have.add(step.unknown)
                continue
            within = {**composed, tear: tear}
            for step in inner:
                within[step.unknown] = step.numeric.doit().xreplace(within)
            closes = relations[closing]
            lhs, rhs = _sides(closes)
            residual = lhs - rhs
            reduced = residual.xreplace(within)
            unknowns = {tear} | {step.unknown for step in inner}
            conditions = [c.holds for relation in relations for c in relation.requires
                          if sp.sympify(c.holds).free_symbols & unknowns and sp.sympify(c.holds).free_symbols <= have]
            low, high = interval(tear, reduced, conditions)
            if tear in reduced.free_symbols and not (points and identity(
                    lhs.xreplace(within), rhs.xreplace(within), tear, low, high, _values_at(points[0], chain, 0))):
                break
            trial.add(closing)  # an equation the torn unknown's steps already satisfy: it closes nothing
            closing = None
        if closing is None:
            continue
        block = [relations[closing]] + [step.relation for step in inner]
        found_at: list[float] = []
        for index, point in enumerate(points):
            at = _values_at(point, chain, index)
            admissible = [root for root in roots_at(reduced, tear, low, high, at)
                          if _admissible({tear: sp.Float(root), **{step.unknown: within[step.unknown].xreplace(
                              {tear: sp.Float(root)}) for step in inner}}, conditions, at)]
            if len(admissible) > 1:
                used.add(closing)
                labels = " and ".join(f"({chr(97 + i)}) {relation.label}" for i, relation in enumerate(block))
                one, other = (f"{tear} = {root:.6g}" for root in admissible[:2])
                return f"the equations {labels}, which give {one} or {other} (SI) at {_where(point)}"
            found_at.append(admissible[0] if admissible else float("nan"))
        if all(value != value for value in found_at):
            continue
        used.update(trial | {closing})
        head = _Solved(tear, relations[closing], tear, tear, block=tuple([tear, *(step.unknown for step in inner)]),
                       residual=residual, interval=(low, high), at_points=tuple(found_at))
        return [head, *inner]
    return None


def _solve(relation: Relation, unknown: Any) -> Any:
    if unknown in relation.solutions:
        return relation.solutions[unknown]
    if -unknown in relation.solutions:  # a quantity named with its sign turned (an upward v_out along a downward n)
        return -relation.solutions[-unknown]
    if not relation.general:
        return None
    # The side without the unknown is solved for as a whole, so sqrt(2*g*h) stays as the
    # effect wrote it (sympy would split it into sqrt(2)*sqrt(g)*sqrt(h)).
    lhs, rhs = sp.sympify(relation.lhs), sp.sympify(relation.rhs)
    if unknown in rhs.free_symbols and unknown not in lhs.free_symbols:
        lhs, rhs = rhs, lhs
    whole = sp.Dummy("whole", real=True) if unknown not in rhs.free_symbols else rhs
    roots = [r.xreplace({whole: rhs}) for r in sp.solve(sp.Eq(lhs, whole), unknown)]
    roots = [r for r in roots if r.is_real is not False]
    if len(roots) > 1:
        roots = [r for r in roots if all(
            c.holds.subs(unknown, r) is not sp.false for c in relation.requires)]
    return roots[0] if len(roots) == 1 else None


def _stable(relation: Relation, unknown: Any, display: Any, known: set[Any], given: set[Any]) -> Any:
    forms = [(1, form) for form in relation.stable.get(unknown, ())] + \
        [(-1, form) for form in relation.stable.get(-unknown, ())]
    for sign, form in forms:
        needs_given = set().union(*(sp.sympify(g).free_symbols for g in form.given)) if form.given else set()
        if sp.sympify(form.expr).free_symbols <= known and needs_given <= given:
            return sign * form.expr
    return display


class _Compiler:
    """Compiles one template; holds its context and the unit substitutions."""

    def __init__(self, template: Template) -> None:
        self.template = template
        self.ctx = Context(template.scene, units={name: p.unit for name, p in template.parameters.items()})
        for name, parameter in template.parameters.items():
            low = parameter.domain.low
            positive = low > 0 or (low == 0 and parameter.domain.low_open)
            assumptions = {"positive": True} if positive else {"nonnegative": True} if low >= 0 else {}
            if parameter.integer:
                assumptions["integer"] = True
            self.ctx.symbols[name] = sp.Symbol(name, real=True, **assumptions)
        for name in template.symbols:
            self.ctx.symbols[name] = sp.Symbol(name, positive=True)
        self.relations = [r for stage in template.scene.stages
                          for r in CATALOGUE[stage.effect].relations(stage, self.ctx)]
        self.degree_angles = [self.ctx.symbols[n] for n, p in template.parameters.items() if p.unit.pi_power]
        self.inputs = {self.ctx.symbols[n] for n in list(template.parameters) + list(template.symbols)}
        self.torn: set[Any] = set()  # the unknowns of numeric blocks, which trees may hold until _rooted
        self.roots: dict[str, Node] = {}  # their root(...) trees over the parameters in template units
        self.si_roots: dict[str, Node] = {}  # the same in SI, for the steps
        if "g" in self.ctx.symbols:
            self.inputs.add(self.ctx.symbols["g"])

    def compile(self) -> Compiled:
        wanted = {name: from_node(spec.value, self.ctx.symbols) for name, spec in self.template.answers.items()}
        chain = derive(self.relations, self.inputs, self.inputs, wanted=wanted.values(), points=self._points(),
                       numeric=True)
        known = self.inputs | {s.unknown for s in chain}
        for name, expr in wanted.items():
            missing = expr.free_symbols - known
            if missing:
                raise TemplateError(self.template.where, f"answers.{name}",
                                    "an answer the scene determines from the parameters",
                                    f"nothing fixes {', '.join(sorted(map(str, missing)))}{self._coupled(known)}")
        chain = _needed(chain, wanted.values())
        composed: dict[Any, Any] = {}
        for solved in chain:
            # doit(): display forms keep sqrt(2*g*h) whole; the numeric composition wants it evaluated.
            composed[solved.unknown] = solved.unknown if solved.residual is not None else \
                solved.numeric.doit().xreplace(composed)
        found = self._numeric_blocks(chain, composed)
        answers = {name: self._answer(name, expr, chain, composed) for name, expr in wanted.items()}
        checks = found + self._checks(composed, [c for solved in chain for c in solved.requires])
        self._check_every_parameter_used(chain, wanted.values(), checks)
        return Compiled(
            template_id=self.template.id, source_hash=self.template.source_hash,
            parameters=tuple(self.template.parameters),
            constants={"g": float(self.template.scene.gravity.si)} if self.template.scene.gravity else {},
            steps=tuple(self._step(s) for s in chain), checks=checks, answers=answers)

    def _numeric_blocks(self, chain: list[_Solved], composed: Mapping[Any, Any]) -> tuple[Check, ...]:
        """Each numeric block's unknown as its ``root(...)`` tree (template units; and SI for its step), which
        every tree with it takes in its place (:meth:`_tree`), and the check that a draw has its one root."""
        checks = []
        for solved in chain:
            if solved.residual is None:
                continue
            name, (low, high) = solved.unknown.name, solved.interval
            residual = solved.residual.xreplace(dict(composed))
            self.torn.add(solved.unknown)
            user = self._tree(self._user_units(residual), "(numeric block)", [solved.unknown])
            self.si_roots[name] = root_node(substitute(to_node(residual), self.si_roots), name, low, high)
            root = self.roots[name] = root_node(user, name, low, high)
            count = len(solved.block)
            labels = " and ".join(f"({chr(97 + i)})" for i in range(count))
            checks.append(Check(Op("ge", (root, Num(low))), (
                f"the equations {labels} do not fix {name} for these values: solved numerically (to "
                f"{TOLERANCE_TEXT}), they have no root, or more than one, for {name} between {low:.6g} and "
                f"{high:.6g} (SI)")))
        return tuple(checks)

    def _points(self, count: int = 8) -> list[dict[Any, float]]:
        """The inputs in SI (symbols without value at 1) at the template's example, if it gives every parameter,
        then at ``count`` points spread over the parameters' sampling (a fixed low-discrepancy sequence, so
        a template compiles the same every time): where a block's roots are told apart only by the values."""
        spread = []
        for k in range(1, count + 1):
            values = {}
            for j, (name, parameter) in enumerate(self.template.parameters.items()):
                fraction = (k * 0.6180339887498949 + j * 0.41421356237309503) % 1
                kind, ends = parameter.sample.kind, parameter.sample.values
                if kind == "choice":
                    value = ends[k % len(ends)]
                elif kind == "log_uniform":
                    value = ends[0] * (ends[1] / ends[0]) ** fraction
                else:
                    value = ends[0] + fraction * (ends[1] - ends[0])
                    value = round(value) if kind == "integers" else value
                values[name] = value
            spread.append(values)
        complete = not set(self.template.parameters) - set(self.template.example)
        example = [dict(self.template.example)] if complete else []
        points = []
        for values in example + spread:
            point = {self.ctx.symbols[name]: float(values[name]) * parameter.unit.to_si
                     for name, parameter in self.template.parameters.items()}
            point.update({self.ctx.symbols[name]: 1.0 for name in self.template.symbols})
            if self.template.scene.gravity is not None and "g" in self.ctx.symbols:
                point[self.ctx.symbols["g"]] = float(self.template.scene.gravity.si)
            points.append(point)
        return points

    def _check_every_parameter_used(self, chain: list[_Solved], wanted: Iterable[Any],
                                    checks: Iterable[Check]) -> None:
        """A parameter no step, answer or check uses is printed but ignored: the scene is over-determined
        (a constant fixes what it would decide) or it asks nothing that depends on it."""
        used = {str(s) for s in set().union(*(sp.sympify(w).free_symbols for w in wanted))}
        for solved in chain:
            used |= {str(s) for s in solved.display.free_symbols | solved.numeric.free_symbols}
            if solved.residual is not None:
                used |= {str(s) for s in solved.residual.free_symbols}
        for check in checks:
            used |= names(check.holds)
        for name in self.template.parameters:
            if name not in used:
                raise TemplateError(self.template.where, f"parameters.{name}", "a parameter the answers depend on",
                                    "one no step of the solution uses: the scene is over-determined (a constant or "
                                    "another parameter already fixes what it would decide) or no answer needs it; "
                                    "remove it, make it a symbol, or turn the constant into a parameter")

    def _coupled(self, known: set[Any]) -> str:
        """Why the chain stopped: the unknowns the unused equations still tie together."""
        left = [r.symbols() - known for r in self.relations if len(r.symbols() - known) > 1]
        # An equation with an unknown no other equation has only ties that one up: drop it, repeat.
        while True:
            counts: dict[Any, int] = {}
            for unknowns in left:
                for symbol in unknowns:
                    counts[symbol] = counts.get(symbol, 0) + 1
            core = [u for u in left if all(counts[s] > 1 for s in u)]
            if len(core) == len(left):
                break
            left = core
        tied = sorted({str(s) for unknowns in left for s in unknowns})
        if not tied:
            return "; no stage involves it"
        return (f"; the equations left tie {', '.join(map(self._named, tied))} together (two or more unknowns each) "
                f"and no set of them fixes as many unknowns as it has, in closed form (at most {MAX_BLOCK}, "
                "polynomial, of degree at most 4 together) or numerically (one unknown from which the others "
                "follow, with a root at the sampled values): give one of them as a parameter")

    def _named(self, name: str) -> str:
        """A quantity as a message names it: a name the template wrote as is; one the solver gave (the template
        left it unnamed: :meth:`Context.unused_name`, ``base`` or ``base_<stage>``) with the stage field it
        belongs to, e.g. ``J (stages[1].impulse, unnamed)``."""
        numbered = re.fullmatch(r"(\w+?)_(\d+)", name)
        base, index = (name, self.ctx.defaults[name]) if name in self.ctx.defaults else \
            (numbered.group(1), int(numbered.group(2))) if numbered else (name, None)
        if name in self.template.scene.names() or index is None or index >= len(self.template.scene.stages):
            return name
        stage = self.template.scene.stages[index]
        velocity = re.fullmatch(r"v_(\w+)_[nt]_after", base)
        if velocity is not None:
            return f"{name} (stages[{index}].after.{velocity.group(1)}: {velocity.group(1)}'s velocity after, unnamed)"
        field = next((f.name for f in CATALOGUE[stage.effect].fields if f.default == base), None)
        return f"{name} (stages[{index}].{field}, unnamed)" if field else name

    def _step(self, solved: _Solved) -> Step:
        solved_form = self.si_roots[solved.unknown.name] if solved.residual is not None else \
            to_node(for_reader(solved.display))
        return Step(solved.unknown.name, solved.relation.label,
                    (to_node(solved.relation.lhs), to_node(solved.relation.rhs)), solved_form,
                    tuple(unknown.name for unknown in solved.block), numeric=solved.residual is not None)

    def _answer(self, name: str, expr: Any, chain: list[_Solved], composed: Mapping[Any, Any]) -> CompiledAnswer:
        spec = self.template.answers[name]
        si = expr.xreplace(dict(composed))
        in_units = self._user_units(si) / _si_factor(spec.unit)
        undefined = tuple(
            Undefined(self._tree_condition(self._user_units(cond.xreplace(dict(composed)))), reason)
            for solved in _needed(chain, [expr]) for unknown, (cond, reason) in solved.relation.undefined.items()
            if unknown == solved.unknown)
        if spec.symbolic:
            return CompiledAnswer(name, spec.unit.text, None, to_node(_tidy(sp.factor(sp.simplify(in_units)))),
                                  undefined)
        return CompiledAnswer(name, spec.unit.text, self._tree(in_units, name), None, undefined)

    def _tree(self, expr: Any, name: str, extra: Iterable[Any] = ()) -> Any:
        """A numeric expression over parameters (and ``extra``) only, stabilised, as a tree."""
        allowed = {self.ctx.symbols[p] for p in self.template.parameters} | {self.ctx.symbols.get("g"), *extra,
                                                                              *self.torn}
        stable = stabilize(expr, self.degree_angles)
        if stable.free_symbols - allowed:
            stable = stabilize(sp.cancel(stable), self.degree_angles)
        stray = stable.free_symbols - allowed
        if stray:
            raise TemplateError(self.template.where, f"answers.{name}", "a number once the parameters are given",
                                f"an expression that still depends on {', '.join(sorted(map(str, stray)))}")
        return self._rooted(numeric_order(to_node(stable)))

    def _rooted(self, tree: Node) -> Node:
        """``tree`` with each numeric block's unknown replaced by its ``root(...)`` tree."""
        return substitute(tree, self.roots) if self.roots else tree

    def _user_units(self, expr: Any) -> Any:
        """Rewrite an SI expression over SI-valued names into one over values in template units."""
        scale = {}
        for name, unit in [(n, p.unit) for n, p in self.template.parameters.items()] + [
                (n, s.unit) for n, s in self.template.symbols.items()]:
            factor = _si_factor(unit)
            if factor != 1:
                scale[self.ctx.symbols[name]] = self.ctx.symbols[name] * factor
        converted = expr.xreplace(scale)
        # Angles given in degrees stay in degrees inside sine and cosine: sind(90 - x) is exact.
        converted = converted.replace(lambda e: isinstance(e, sp.sin), lambda e: sind(e.args[0] * 180 / sp.pi))
        return converted.replace(lambda e: isinstance(e, sp.cos), lambda e: cosd(e.args[0] * 180 / sp.pi))

    def _checks(self, composed: Mapping[Any, Any], steps: Iterable[Condition] = ()) -> tuple[Check, ...]:
        """``steps``' own conditions (a block's determinant), then those of the scene's relations, that the
        composed quantities decide, as checks over the parameters."""
        known = self.inputs | set(composed)
        checks = []
        # A block's own condition first: where it fails, the scene's conditions on its roots say nothing.
        for conditions in [tuple(steps), *(relation.requires for relation in self.relations)]:
            for condition in conditions:
                # A condition applies as soon as its own quantities are known, whatever else its relation has.
                if not sp.sympify(condition.holds).free_symbols <= known:
                    continue
                holds = self._user_units(sp.sympify(condition.holds).xreplace(dict(composed)))
                if holds is sp.true:
                    continue
                if holds is sp.false:
                    value = sp.sympify(condition.subject).xreplace(dict(composed)) if condition.subject else None
                    shown_value = str(value) if value is not None and value.is_number else "a constant"
                    raise TemplateError(self.template.where, "stages", "a scene that can hold",
                                        "a condition that never holds: "
                                        + condition.message.replace("{value}", shown_value))
                subject = None
                if condition.subject is not None and sp.sympify(condition.subject).free_symbols <= known:
                    subject = self._tree(self._user_units(sp.sympify(condition.subject).xreplace(dict(composed))),
                                         "(check)")
                if self._reduced(holds) is sp.true:  # its sides differ by positive factors only: it always holds
                    continue
                check = Check(self._tree_condition(holds), condition.message, subject)
                if check not in checks:
                    checks.append(check)
        return tuple(checks)

    def _tree_condition(self, holds: Any) -> Any:
        """A condition (an undefined answer's, a check's) as a tree; one sympy finds always true or always false
        (the angle of a velocity the template leaves out) is the template's error."""
        if holds in (sp.true, sp.false):
            raise TemplateError(_INNER, "stages or answers", "a condition that depends on the parameters",
                                f"one that is always {str(holds).lower()}")
        reduced = self._reduced(holds)
        if reduced in (sp.true, sp.false):
            raise TemplateError(_INNER, "stages or answers", "a condition that depends on the parameters",
                                f"one that is always {str(reduced).lower()}")
        return self._rooted(numeric_order(to_node(reduced)))

    def _reduced(self, holds: Any) -> Any:
        """A condition against zero without its positive factors (381*v*x/1250 > 0 is x > 0): sympy's true
        or false where only positive factors were left (x**2 + 1 > 0, found after a block is solved)."""
        difference = stabilize(holds.lhs - holds.rhs, self.degree_angles)
        kept = [f for f in sp.Mul.make_args(difference) if not f.is_positive]
        return type(holds)(sp.Mul(*kept), 0)


def for_reader(expr: Any) -> Any:
    """A solved form as a reader wants it: with no fraction inside a denominator (the impulse
    ``(1 + e)(v1 - v2)/(1/m1 + 1/m2)`` is ``m1 m2 (1 + e)(v1 - v2)/(m1 + m2)``). Order and signs are
    the printer's (:mod:`grader.render.readable`).

    >>> m1, m2, v = sp.symbols("m1 m2 v", positive=True)
    >>> for_reader(v / (1 / m1 + 1 / m2)), for_reader(v - v / m1)
    (m1*m2*v/(m1 + m2), v - v/m1)
    """
    compound = any(power.exp.is_negative and isinstance(power.base, sp.Add) and any(
        part.is_Pow and part.exp.is_negative for term in power.base.args for part in sp.Mul.make_args(term))
        for power in sp.sympify(expr).atoms(sp.Pow))
    return sp.factor(expr) if compound else expr


def _si_factor(unit: Unit) -> Any:
    """A unit's factor to SI as an exact sympy number (deg: pi/180), so conversions cancel exactly."""
    return sp.Rational(unit.factor.numerator, unit.factor.denominator) * sp.pi**unit.pi_power


def _needed(chain: list[_Solved], wanted: Iterable[Any]) -> list[_Solved]:
    """The steps the wanted expressions depend on, in chain order."""
    producer = {s.unknown: s for s in chain}
    needed: set[Any] = set()
    frontier = set().union(*(sp.sympify(w).free_symbols for w in wanted))
    while frontier:
        symbol = frontier.pop()
        if symbol in producer and symbol not in needed:
            needed.add(symbol)
            step = producer[symbol]
            frontier |= step.display.free_symbols | step.numeric.free_symbols
            if step.residual is not None:
                frontier |= step.residual.free_symbols
    return [s for s in chain if s.unknown in needed]


def _tidy(expr: Any) -> Any:
    """Write ``-v*(e*p - 1)/(p + 1)`` as ``v*(1 - e*p)/(p + 1)``."""
    if isinstance(expr, sp.Mul) and expr.could_extract_minus_sign():
        factors = list(sp.Mul.make_args(-expr))
        for index, factor in enumerate(factors):
            if isinstance(factor, sp.Add):
                factors[index] = sp.Add(*[-t for t in factor.args], evaluate=False)
                return sp.Mul(*factors, evaluate=False)
    return expr


def compile_template(template: Template) -> Compiled:
    """Derive and compile a template's answers (sympy; slow the first time, then cached).

    Templates come from colleagues: an expression sympy cannot handle (``h**h**h**h`` to solve for,
    ``1/0``, a constant beyond float64) is a :class:`TemplateError` naming the file, not a traceback; an
    exception that is not :func:`unworkable` is a bug of grader's and keeps its traceback.
    """
    try:
        return _Compiler(template).compile()
    except TemplateError as error:
        if error.where == _INNER:  # raised below the solver, which does not know the file
            raise TemplateError(template.where, error.key, error.expected, error.got) from None
        raise
    except SYMPY_FAILURES as error:
        if not unworkable(error):
            raise
        raise TemplateError(template.where, "stages or answers", "expressions the solver can work with (real, "
                            "finite, solvable one unknown at a time)", _failure_in_words(error)) from None


def _failure_in_words(error: BaseException) -> str:
    """What the algebra could not do, for an author (who wrote no Python and no sympy)."""
    if isinstance(error, ZeroDivisionError):
        return "a division by zero (a constant 0 where a quantity divides)"
    if isinstance(error, ArithmeticError):
        return "arithmetic beyond what a number can hold"
    if isinstance(error, RecursionError):
        return "expressions nested too deeply to work with"
    if isinstance(error, NotImplementedError):
        return "an equation the algebra cannot solve for its unknown: give that quantity as a parameter"
    return ("expressions the algebra cannot work with (a value or a comparison it cannot decide): check each "
            "stage's velocities before and after and the constants, e.g. a body left at rest that must move")
