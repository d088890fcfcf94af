"""The sympy side of :mod:`grader.solve.alternatives`: a template's chain derived again under each
mistake its effects declare, and with each earlier answer as a known and a parameter freed.

Imported only when alternatives are compiled (the cache spares later runs the sympy import).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from fractions import Fraction
from typing import Any

import numpy as np
import sympy as sp

from grader.bank.template import Template
from grader.base.errors import SYMPY_FAILURES, TemplateError, unworkable
from grader.model.expr import Node, Num, Op, bottom_up, names
from grader.model.kernel import evaluate
from grader.physics.effects import CATALOGUE, Mistake, Relation
from grader.physics.symbolic import from_node, to_node
from grader.solve.alternatives import GIVEN, Alternative, Alternatives
from grader.solve.solver import _Compiler, _si_factor, _Solved, derive
from grader.solve.stable import numeric_order

_FAILURES = (TemplateError, *SYMPY_FAILURES)
"""What an alternative the solver cannot derive or compile may raise: it is left out when the error is
:func:`~grader.base.errors.unworkable`, and keeps its traceback otherwise (a bug of grader's)."""


def compile_alternatives(template: Template) -> Alternatives:
    """Derive and compile a template's alternatives (sympy; then cached, see
    :func:`grader.solve.cache.alternatives_for`). One that the solver cannot derive is left out."""
    compiler = AlternativeCompiler(template)
    found = [*compiler.mistakes(), *compiler.carried()]
    return Alternatives(template.id, template.source_hash,
                        {"g": float(template.scene.gravity.si)} if template.scene.gravity else {},
                        tuple(_without_repeats(found, template)))


def _without_repeats(found: Iterable[Alternative], template: Template) -> list[Alternative]:
    """Each answer's alternatives once: a tree met before for the same answer and kind is dropped."""
    seen: set[tuple[str, str, Node]] = set()
    kept = []
    for item in found:
        key = (item.answer, item.kind, item.value)
        if key not in seen and names(item.value) <= {*template.parameters, "g", GIVEN}:
            seen.add(key)
            kept.append(item)
    return kept


class AlternativeCompiler(_Compiler):
    """Compiles one template's alternatives; holds its own chain, composed, to compare them with."""

    def __init__(self, template: Template) -> None:
        super().__init__(template)
        self.stages = [CATALOGUE[stage.effect].relations(stage, self.ctx) for stage in template.scene.stages]
        self.main = _composed(derive(self.relations, self.inputs, self.inputs), {})
        self.numeric = [name for name, spec in template.answers.items() if not spec.symbolic]
        self.wanted = {name: from_node(template.answers[name].value, self.ctx.symbols) for name in self.numeric}
        self.right = {name: self._value(self.main, name) for name in self.numeric}
        self.points = _sample_points(template)

    def mistakes(self) -> list[Alternative]:
        """Every answer a declared mistake changes, mistake by mistake in the order the stages declare them."""
        found = []
        for id, (mistake, replaced) in self._declared().items():
            if mistake.unit is not None:
                scale = to_node(sp.sympify(mistake.scale))
                trees = {name: numeric_order(Op("mul", (scale, right))) for name, right in self.right.items()
                         if right is not None and self.template.answers[name].unit.text == mistake.unit}
            else:
                relations = [r for index, real in enumerate(self.stages) for r in replaced.get(index, real)]
                try:
                    composed = _composed(derive(relations, self.inputs, self.inputs), self.main)
                except _FAILURES as error:
                    if not unworkable(error):
                        raise
                    continue
                trees = {name: tree for name in self.numeric if (tree := self._value(composed, name)) is not None}
            # A constant tells nothing about what the student did (the loss of a "body" that sticks: 0).
            found += [Alternative(name, "mistake", id, mistake.says, tree) for name, tree in trees.items()
                      if names(tree) and self._differs(tree, self.right[name])]
        return found

    def carried(self) -> list[Alternative]:
        """For each answer, every chain from an earlier answer of the problem (in the answers' order) with
        each parameter that answer depends on freed (in the parameters' order)."""
        given = sp.Symbol(GIVEN, real=True)
        found = []
        for index, source in enumerate(self.numeric):
            right = self.right[source]
            if right is None:
                continue
            student = Relation(f"the student's {source}", given * _si_factor(self.template.answers[source].unit),
                               self.wanted[source])
            for parameter in (p for p in self.template.parameters if p in names(right)):
                knowns = (self.inputs - {self.ctx.symbols[parameter]}) | {given}
                try:
                    composed = _composed(derive([student, *self.relations], knowns, knowns, branches=True), self.main)
                except _FAILURES as error:
                    if not unworkable(error):
                        raise
                    continue
                for name in self.numeric[index + 1:]:
                    tree = self._value(composed, name, extra=(given,))
                    if tree is not None and GIVEN in names(tree):
                        found.append(Alternative(name, "ecf", source, parameter, tree))
        return found

    def _declared(self) -> dict[str, tuple[Mistake, dict[int, tuple[Relation, ...]]]]:
        """Each mistake once, in the order the stages declare them, with the stages it changes."""
        declared: dict[str, tuple[Mistake, dict[int, tuple[Relation, ...]]]] = {}
        for index, stage in enumerate(self.template.scene.stages):
            mistakes = CATALOGUE[stage.effect].mistakes
            for mistake in mistakes(stage, self.ctx) if mistakes is not None else ():
                declared.setdefault(mistake.id, (mistake, {}))[1][index] = mistake.relations
        return declared

    def _value(self, composed: Mapping[Any, Any], name: str, extra: Iterable[Any] = ()) -> Node | None:
        """An answer from a composed chain as a tree in its unit, or None where the chain does not reach it."""
        expr, extra = self.wanted[name], set(extra)
        if not expr.free_symbols <= set(composed) | self.inputs | extra:
            return None
        try:
            in_units = self._user_units(expr.xreplace(dict(composed))) / _si_factor(self.template.answers[name].unit)
            return _unclipped(self._tree(in_units, name, extra))
        except _FAILURES as error:
            if not unworkable(error):
                raise
            return None

    def _differs(self, tree: Node, right: Node | None) -> bool:
        """Whether an alternative can be told from the right answer: another tree, and another value at a
        sampled point (a mistake in a ratio of heights printed in mm changes the tree, not the value)."""
        if right is None:
            return True
        if tree == right:
            return False
        env = {**self.points, "g": float(self.template.scene.gravity.si) if self.template.scene.gravity else 9.81}
        with np.errstate(all="ignore"):
            mine, theirs = (np.broadcast_to(np.asarray(evaluate(t, env), dtype=float), (2,)) for t in (tree, right))
        comparable = np.isfinite(mine) & np.isfinite(theirs)
        apart = np.abs(mine - theirs) > 1e-9 * np.abs(theirs) + 1e-300
        return not comparable.any() or bool((apart & comparable).any())


def _unclipped(tree: Node) -> Node:
    """``Max(0, x)`` as ``x``: the scene's own answer takes a loss one rounding below 0 as 0, but a
    chain from a student's number keeps its sign (a loss that comes out negative is not 0).

    >>> from grader.model.expr import parse, to_text
    >>> to_text(_unclipped(parse("100*Max(0, h - r)/h")))
    '100*(h - r)/h'
    """
    return bottom_up(tree, lambda op: op.args[1] if op.op == "Max" and op.args[0] == Num(Fraction(0)) else op)


def _composed(chain: list[_Solved], main: Mapping[Any, Any]) -> dict[Any, Any]:
    """Each unknown of a chain over its knowns; a step known up to sign takes its sign in ``main``."""
    composed: dict[Any, Any] = {}
    for step in chain:
        value = step.numeric.doit().xreplace(composed)
        if step.branch and step.unknown in main:
            value = sp.sign(main[step.unknown]) * value
        composed[step.unknown] = value
    return composed


def _sample_points(template: Template) -> dict[str, np.ndarray]:
    """Two parameter sets inside the sampled ranges, away from their ends, each parameter at other
    fractions of its range (two masses drawn from one range must not come out equal)."""
    points = {}
    for index, (name, parameter) in enumerate(template.parameters.items()):
        low, high = parameter.sample.values[0], parameter.sample.values[-1]
        where = 0.1 + 0.8 * np.modf(np.array([0.31, 0.77]) + 0.618034 * index)[0]
        if parameter.sample.kind == "log_uniform":
            points[name] = np.exp(np.log(low) + where * (np.log(high) - np.log(low)))
        else:
            points[name] = low + where * (high - low)
        if parameter.integer:  # a count takes whole values, both inside its range
            points[name] = np.clip(np.round(points[name]), low, high)
    return points
