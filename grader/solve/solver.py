"""From a scene and what is known, a chain of steps (one equation, one unknown each), compiled
into expression trees over the parameters that the numpy kernels evaluate.

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
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

import sympy as sp

from grader.bank.template import Template
from grader.base.errors import SYMPY_FAILURES, TemplateError, unworkable
from grader.model.expr import names
from grader.model.quantities import Unit
from grader.physics.effects import CATALOGUE, Relation
from grader.physics.symbolic import INNER as _INNER
from grader.physics.symbolic import Context, cosd, from_node, sind, to_node
from grader.solve.compiled import Check, Compiled, CompiledAnswer, Step, Undefined
from grader.solve.stable import numeric_order, stabilize


@dataclass(frozen=True)
class _Solved:
    unknown: Any
    relation: Relation
    display: Any
    numeric: Any
    branch: bool = False  # the magnitude only: the sign is the one the unknown has in the scene's own solution


def derive(relations: list[Relation], knowns: Iterable[Any], given: Iterable[Any],
           branches: bool = False) -> list[_Solved]:
    """Solve relations one unknown at a time, earliest relation first, as far as they go.

    ``given`` are the knowns that are inputs (not derived): a stable form that asks for its
    symbols to be given is used only then. With ``branches``, a relation may also give an unknown
    known only up to sign (a step marked ``branch``), where no other relation gives it.
    """
    known, given_set = set(knowns), set(given)
    used: set[int] = set()
    chain: list[_Solved] = []
    while True:
        step = _next_step(relations, known, given_set, used) or (
            _next_branch(relations, known, used) if branches else None)
        if step is None:
            return chain
        chain.append(step)
        known.add(step.unknown)


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
        if "g" in self.ctx.symbols:
            self.inputs.add(self.ctx.symbols["g"])

    def compile(self) -> Compiled:
        chain = derive(self.relations, self.inputs, self.inputs)
        wanted = {name: from_node(spec.value, self.ctx.symbols) for name, spec in self.template.answers.items()}
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
            composed[solved.unknown] = solved.numeric.doit().xreplace(composed)
        answers = {name: self._answer(name, expr, chain, composed) for name, expr in wanted.items()}
        checks = self._checks(composed)
        self._check_every_parameter_used(chain, wanted.values(), checks)
        return Compiled(
            template_id=self.template.id, source_hash=self.template.source_hash,
            parameters=tuple(self.template.parameters),
            constants={"g": float(self.template.scene.gravity.si)} if self.template.scene.gravity else {},
            steps=tuple(self._step(s) for s in chain), checks=checks, answers=answers)

    def _check_every_parameter_used(self, chain: list[_Solved], wanted: Iterable[Any],
                                    checks: Iterable[Check]) -> None:
        """A parameter no step, answer or check uses is printed but ignored: the scene is over-determined
        (a constant fixes what it would decide) or it asks nothing that depends on it."""
        used = {str(s) for s in set().union(*(sp.sympify(w).free_symbols for w in wanted))}
        for solved in chain:
            used |= {str(s) for s in solved.display.free_symbols | solved.numeric.free_symbols}
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
                "and the solver takes one equation and one unknown at a time: give one of them as a parameter")

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
        return Step(solved.unknown.name, solved.relation.label,
                    (to_node(solved.relation.lhs), to_node(solved.relation.rhs)), to_node(for_reader(solved.display)))

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
        allowed = {self.ctx.symbols[p] for p in self.template.parameters} | {self.ctx.symbols.get("g"), *extra}
        stable = stabilize(expr, self.degree_angles)
        if stable.free_symbols - allowed:
            stable = stabilize(sp.cancel(stable), self.degree_angles)
        stray = stable.free_symbols - allowed
        if stray:
            raise TemplateError(self.template.where, f"answers.{name}", "a number once the parameters are given",
                                f"an expression that still depends on {', '.join(sorted(map(str, stray)))}")
        return numeric_order(to_node(stable))

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

    def _checks(self, composed: Mapping[Any, Any]) -> tuple[Check, ...]:
        known = self.inputs | set(composed)
        checks = []
        for relation in self.relations:
            for condition in relation.requires:
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
        difference = stabilize(holds.lhs - holds.rhs, self.degree_angles)
        # Against zero, a positive factor changes nothing: 381*v*x/1250 > 0 is x > 0.
        kept = [f for f in sp.Mul.make_args(difference) if not f.is_positive]
        return numeric_order(to_node(type(holds)(sp.Mul(*kept), 0)))


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
