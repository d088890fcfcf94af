"""The answer key's routes: the steps a textbook writes, where the solver's chain takes a stable route.

The kernels keep their stable forms (docs/design.md, Numerics): an impact in impulse form with inverse
masses, ``J = (1 + e) v/(1/m1 + 1/m2)``, angles from ``atan2``, magnitudes from ``hypot``. A student, and the
textbook, write the same physics another way, and the worked solution shows that way, each value still the
kernel's (``tests/test_textbook_steps.py`` evaluates every form on the page against the kernel's value to 1e-9):
two bodies that both move after an impact are worked with **conservation of momentum** and **the restitution
equation** as two labelled equations, then their simultaneous solution (Sample Problems 3/28 and 3/30), whichever
way round the scene lists them; a velocity after found from the other's is conservation of momentum alone (the
pile driver's ``v_p'``). The energy lost in an impact is ``T − T′``, with ``T′ = ½ m_A v′_A² + ½ m_B v′_B²`` from
the velocities after on the page (``½ (m_A + m_B) v′²`` for bodies that move on together; components squared and
added when oblique), where the kernel keeps its stable form ``m_A m_B (v_A − v_B)² (1 − e²)/(2 (m_A + m_B))``. The other
forms (``e = √(h′/h)``, inverse trigonometric functions, speeds by name, one
fraction for a reciprocal sum) are :mod:`grader.solve.page_forms`'.

The impacts are found by their relations' wording (:mod:`grader.physics.effects.impact`): "impulse along n in
the impact of A and B, with restitution e" and "impulse-momentum for A along n". An impact this module does not
recognise keeps the chain's steps.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from fractions import Fraction
from functools import partial
from typing import Any

from grader.bank.template import Template
from grader.model.expr import Node, Num, Op, Sym, names
from grader.model.scene import Stage, Velocity
from grader.solve.compiled import Compiled, Step
from grader.solve.page_forms import (
    bounce_heights,
    folded,
    inverse_trig,
    is_zero,
    magnitudes,
    one_fraction,
    product,
)

_IMPULSE = re.compile(r"impulse along n in the impact of (\S+) and (\S+), with restitution .+")
_MOMENTUM_OF = re.compile(r"impulse-momentum for (\S+) along n")
_TOGETHER = re.compile(r"conservation of momentum along n: (\S+) and (\S+) move on together")
_ZERO, _ONE = Num(Fraction(0)), Num(Fraction(1))


@dataclass(frozen=True)
class Route:
    """A template's worked solution as the page shows it: its ``steps`` (each a chain quantity or one of
    ``extra``, in the order a student writes them), and ``extra``, the quantities the route names that the
    kernels' chain never computes (the struck block's rebound, for a momentum balance), evaluated after it.
    ``positive`` names, per step, the quantity that must be positive at a variant for its form to hold
    (``tan⁻¹(y/x)`` is the angle only where ``x > 0``): elsewhere the page shows the kernel's form."""

    steps: tuple[Step, ...]
    extra: tuple[Step, ...] = ()
    positive: Mapping[str, Node] = field(default_factory=dict)


# --- building trees ------------------------------------------------------------------------------

def _add(*terms: Node | None) -> Node:
    kept = [t for t in terms if t is not None and not is_zero(t)]
    if not kept:
        return _ZERO
    total = kept[0]
    for term in kept[1:]:
        negative = isinstance(term, Op) and term.op == "neg"
        total = Op("sub", (total, term.args[0])) if isinstance(term, Op) and negative else Op("add", (total, term))
    return total


def _mul(*factors: Node) -> Node:
    if any(is_zero(f) for f in factors):
        return _ZERO
    return product([f for f in factors if f != _ONE])


def _neg(node: Node) -> Node:
    return node.args[0] if isinstance(node, Op) and node.op == "neg" else Op("neg", (node,))


def _div(numerator: Node, denominator: Node) -> Node:
    return numerator if denominator == _ONE else Op("div", (numerator, denominator))


def _sub(left: Node | None, right: Node | None) -> Node:
    if right is None or is_zero(right):
        return left if left is not None else _ZERO
    if left is None or is_zero(left):
        return _neg(right)
    return Op("sub", (left, right))


def _factors(node: Node) -> list[Node]:
    if isinstance(node, Op) and node.op == "mul":
        return _factors(node.args[0]) + _factors(node.args[1])
    return [node]


def _without_common(masses: tuple[Node, Node], valueless: set[str]) -> tuple[Node, Node]:
    """The two masses with the valueless factors they share taken out (``m`` and ``p m`` are 1 and ``p``),
    as a student cancels them."""
    first, second = (_factors(m) for m in masses)
    for factor in list(first):
        if isinstance(factor, Sym) and factor.name in valueless and factor in second:
            first.remove(factor)
            second.remove(factor)
    return _mul(*first) if first else _ONE, _mul(*second) if second else _ONE


# --- the impact: momentum and restitution ----------------------------------------------------------

@dataclass(frozen=True)
class _Pair:
    """An impact of two bodies that both move, as the momentum balance names it. Its velocities along n are
    expressions: a scene written the other way round has n turned, and names a velocity after ``-v1_out``."""

    first: str
    second: str
    masses: tuple[Node, Node]  # as the scene gives them
    cancelled: tuple[Node, Node]  # with the factors they share and that have no value taken out
    before: tuple[Node | None, Node | None]  # along n (None: at rest)
    after: tuple[Node, Node]  # along n: a name, or a name with its sign turned
    e: Node

    @property
    def after_names(self) -> tuple[str, str]:
        return (_named(self.after[0]) or "", _named(self.after[1]) or "")

    def momentum(self) -> tuple[Node, Node]:
        (m1, m2), (u1, u2), (a1, a2) = self.masses, self.before, self.after
        return (_add(_mul(m1, u1) if u1 is not None else None, _mul(m2, u2) if u2 is not None else None),
                _add(_mul(m1, a1), _mul(m2, a2)))

    def restitution(self) -> tuple[Node, Node]:
        (u1, u2), (a1, a2) = self.before, self.after
        return self.e, _div(_sub(a2, a1), _sub(u1 or _ZERO, u2))

    def relation(self) -> str:
        return f"conservation of momentum along n for {self.first} and {self.second}"

    def restitution_relation(self) -> str:
        return f"coefficient of restitution for {self.first} and {self.second}"

    def both_after(self) -> tuple[Node, Node]:
        """Simultaneous solution of the momentum and restitution equations for both velocities after, each
        solved for its name."""
        (m1, m2), (u1, u2), e = self.cancelled, self.before, self.e
        total = _add(m1, m2)
        if u2 is None and u1 is not None:  # the second at rest: v1' = v1 (m1 - e m2)/(m1 + m2)
            forms = (_div(_mul(u1, _sub(m1, _mul(e, m2))), total), _div(_mul(m1, u1, _add(_ONE, e)), total))
        else:
            momentum = _add(_mul(m1, u1) if u1 is not None else None, _mul(m2, u2) if u2 is not None else None)
            approach = _sub(u1 or _ZERO, u2)
            forms = (_div(_sub(momentum, _mul(e, m2, approach)), total),
                     _div(_add(momentum, _mul(e, m1, approach)), total))
        return _solved_for(self.after[0], forms[0]), _solved_for(self.after[1], forms[1])

    def one_after(self, known: int) -> Node:
        """The momentum balance solved for the name of the velocity after of the body other than ``known``."""
        other = 1 - known
        masses, before = self.cancelled, self.before
        if before[other] is None:
            form = _div(_mul(masses[known], _sub(before[known] or _ZERO, self.after[known])), masses[other])
        else:
            balance = _add(_mul(masses[0], before[0]) if before[0] is not None else None,
                           _mul(masses[1], before[1]) if before[1] is not None else None)
            form = _div(_sub(balance, _mul(masses[known], self.after[known])), masses[other])
        return _solved_for(self.after[other], form)

    def first_before(self) -> Node:
        """The momentum and restitution equations solved for the first body's velocity before, the second's
        after unknown too: ``v1 = ((m1 + m2) v1' - (1 + e) m2 v2)/(m1 - e m2)``."""
        (m1, m2), (u1, u2), e = self.cancelled, self.before, self.e
        given = _mul(_add(m1, m2), self.after[0])
        form = _div(_sub(given, _mul(_add(_ONE, e), m2, u2) if u2 is not None else None), _sub(m1, _mul(e, m2)))
        return _solved_for(u1 or _ZERO, form)

    def second_after_from_restitution(self) -> Node:
        """``v2' = v1' + e (v1 - v2)``, solved for the name of ``v2'``."""
        form = _add(self.after[0], _mul(self.e, _sub(self.before[0] or _ZERO, self.before[1])))
        return _solved_for(self.after[1], form)


def _named(node: Node | None) -> str | None:
    """The name in ``v`` or ``-v``."""
    if isinstance(node, Op) and node.op == "neg":
        node = node.args[0]
    return node.name if isinstance(node, Sym) else None


def _solved_for(expression: Node, form: Node) -> Node:
    """The name in ``expression`` (``v`` or ``-v``) from ``expression = form``."""
    return form if isinstance(expression, Sym) else _neg(form)


def _pair(template: Template, first: str, second: str) -> _Pair | None:
    """The impact of ``first`` and ``second`` that both move, if the scene has exactly one."""
    stages = [s for s in template.scene.stages if s.effect == "impact" and tuple(s.fields["bodies"]) == (first, second)]
    if len(stages) != 1:
        return None
    stage: Stage = stages[0]
    bodies = template.scene.bodies
    masses = (bodies[first].mass, bodies[second].mass)
    after = stage.fields.get("after", {})
    along = [after.get(b).n if isinstance(after.get(b), Velocity) else None for b in (first, second)]
    if masses[0] is None or masses[1] is None or along[0] is None or along[1] is None \
            or _named(along[0]) is None or _named(along[1]) is None:
        return None
    before = tuple(_along_n(stage.fields.get("before", {}).get(b)) for b in (first, second))
    valueless = set(template.symbols)
    return _Pair(first, second, (masses[0], masses[1]), _without_common((masses[0], masses[1]), valueless),
                 (before[0], before[1]), (along[0], along[1]), stage.fields["restitution"])


def _along_n(velocity: Any) -> Node | None:
    if isinstance(velocity, Velocity):
        return None if is_zero(velocity.n) else velocity.n
    return None if velocity is None or is_zero(velocity) else velocity


def _uses(step: Step, quantity: str) -> bool:
    return quantity in names(step.solved)


def _impacts(template: Template, compiled: Compiled, steps: list[Step], extra: list[Step]) -> list[Step]:
    """The impulse form of every impact of two moving bodies, as momentum and restitution."""
    answers = set().union(*(names(spec.value) for spec in template.answers.values()))
    # An impulse is the unknown of its impact's impulse relation, or of a body's impulse-momentum solved for it
    # (whose equation gives the body's velocity after: v' = v - J/m)
    for impulse in [s.unknown for s in steps if _IMPULSE.fullmatch(s.relation) or
                    (_MOMENTUM_OF.fullmatch(s.relation) and s.equation[0] != Sym(s.unknown))]:
        steps = _one_impact(template, steps, extra, impulse, answers) or steps
    return steps


def _one_impact(template: Template, steps: list[Step], extra: list[Step], impulse: str,
                answers: set[str]) -> list[Step] | None:
    """``steps`` with the impulse ``impulse`` of one impact worked out of them (None: they keep it, because a step
    or an answer other than the bodies' velocities uses it, or the impact is not one this module knows)."""
    defining = [s for s in steps if s.unknown == impulse]
    if len(defining) != 1:
        return None
    found = defining[0]
    bodies = _IMPULSE.fullmatch(found.relation)
    if bodies is None:  # found from one body's impulse-momentum; the impact step says which two
        labels = [_IMPULSE.fullmatch(s.relation) for s in steps if impulse in names(s.equation[0])]
        bodies = next((b for b in labels if b), None)
        if bodies is None:
            first_body = _MOMENTUM_OF.fullmatch(found.relation)
            return _momentum_only(template, steps, found, first_body.group(1) if first_body else "", impulse, answers,
                                  extra)
    pair = _pair(template, bodies.group(1), bodies.group(2))
    if pair is None:
        return None
    members = [s for s in steps if s.unknown in pair.after_names and _MOMENTUM_OF.fullmatch(s.relation)
               and impulse in names(s.equation[0]) | names(s.equation[1])]
    others = [s for s in steps if s is not found and s not in members]
    asked = impulse in answers
    if any(_uses(s, impulse) for s in others) or (asked and found.block):
        return None
    if found.block:
        return _first_before(steps, found, members, pair)
    if not members or any(m.block for m in members):
        return None
    block = pair.after_names
    momentum, restitution = pair.momentum(), pair.restitution()
    forms = pair.both_after()
    shown = [Step(block[0], pair.relation(), momentum, forms[0], block),
             Step(block[1], pair.restitution_relation(), restitution, forms[1], block)]
    if asked:  # the impulse asked: from the first body's change of momentum, once its velocity after is known
        change = _mul(pair.masses[0], _sub(pair.before[0] or _ZERO, pair.after[0]))
        shown.append(Step(impulse, f"impulse-momentum for {pair.first} along n", (Sym(impulse), change), change))
    chain = {s.unknown for s in steps}
    extra += [s for s in shown if s.unknown not in chain]
    index = steps.index(found)
    rest = [s for s in steps if s is not found and s not in members]
    return rest[:index] + shown + rest[index:]


def _momentum_only(template: Template, steps: list[Step], found: Step, body: str, impulse: str,
                   answers: set[str], extra: list[Step]) -> list[Step] | None:
    """A velocity after from the other body's: the impulse found from one body's momentum change and given to
    the other's is the momentum balance of the two, solved for one velocity; an impulse asked then follows as
    the change of momentum of the body it acts on (Sample Problem 3/28: the pile's, m_p v_p′)."""
    users = [s for s in steps if s is not found and _uses(s, impulse)]
    if len(users) != 1 or not _MOMENTUM_OF.fullmatch(users[0].relation):
        return None
    other = _MOMENTUM_OF.fullmatch(users[0].relation).group(1)  # type: ignore[union-attr]
    pair = _pair(template, body, other) or _pair(template, other, body)
    if pair is None or users[0].unknown not in pair.after_names:
        return None
    known = pair.after_names.index(users[0].unknown) ^ 1
    shown = [Step(users[0].unknown, pair.relation(), pair.momentum(), pair.one_after(known))]
    if impulse in answers:  # along n, from the first body to the second, as the impact's impulse is
        on = known ^ 1
        change = _mul(pair.masses[on], _sub(pair.after[on], pair.before[on] or _ZERO) if on else
                      _sub(pair.before[on] or _ZERO, pair.after[on]))
        name = pair.second if on else pair.first
        shown.append(Step(impulse, f"impulse-momentum for {name} along n", (Sym(impulse), change), change))
    chain = {s.unknown for s in steps}
    extra += [s for s in shown if s.unknown not in chain]
    index = steps.index(found)
    rest = [s for s in steps if s is not found and s is not users[0]]
    return [*rest[:index], *shown, *rest[index:]]


def _first_before(steps: list[Step], found: Step, members: list[Step], pair: _Pair) -> list[Step] | None:
    """A block that finds the first body's velocity before and the impulse, the second's velocity after then
    from the impulse: the momentum and restitution equations in the first's velocity before and the second's
    after."""
    block = [s for s in steps if s.block == found.block]
    first = _named(pair.before[0])
    if first is None or set(found.block) != {first, found.unknown}:
        return None
    after = [m for m in members if not m.block]
    if len(after) != 1 or after[0].unknown != pair.after_names[1]:
        return None
    unknowns = (first, pair.after_names[1])
    shown = [Step(unknowns[0], pair.relation(), pair.momentum(), pair.first_before(), unknowns),
             Step(unknowns[1], pair.restitution_relation(), pair.restitution(), pair.second_after_from_restitution(),
                  unknowns)]
    index = steps.index(block[0])
    rest = [s for s in steps if s not in block and s is not after[0]]
    return rest[:index] + shown + rest[index:]


def _plastic(template: Template, steps: list[Step]) -> list[Step]:
    """The impulse of a plastic impact (the bodies move on together) after the momentum balance, as the change of
    the second body's momentum, ``J = m_B (v′ − v_B)``, not the impulse form before it."""
    for found in [s for s in steps if _IMPULSE.fullmatch(s.relation)]:
        first, second = _IMPULSE.fullmatch(found.relation).groups()  # type: ignore[union-attr]
        stages = [s for s in template.scene.stages
                  if s.effect == "impact" and tuple(s.fields["bodies"]) == (first, second)]
        balance = [s for s in steps if (m := _TOGETHER.fullmatch(s.relation)) and {*m.groups()} == {first, second}]
        if len(stages) != 1 or len(balance) != 1 or template.scene.bodies[second].mass is None:
            continue
        after = stages[0].fields.get("after", {})
        common = _along_n(after.get(first))
        if _named(common) is None or common != _along_n(after.get(second)):
            continue
        at, to = steps.index(found), steps.index(balance[0])
        known = set(template.parameters) | set(template.symbols) | {"g"} | {s.unknown for s in steps[:to + 1]}
        change = _mul(template.scene.bodies[second].mass,  # type: ignore[arg-type]
                      _sub(common, _along_n(stages[0].fields.get("before", {}).get(second))))
        if at > to or any(_uses(s, found.unknown) for s in steps[at + 1:to + 1]) or not names(change) <= known:
            continue
        moved = Step(found.unknown, f"impulse-momentum for {second} along n", (Sym(found.unknown), change), change)
        steps = [*steps[:at], *steps[at + 1:to + 1], moved, *steps[to + 1:]]
    return steps


def _numeric_blocks(steps: list[Step]) -> list[Step]:
    """A block solved numerically is shown as its equations, its own step's and those of the steps after it, one per
    unknown (:mod:`grader.render.worked`). Where an impact's momentum and restitution follow it as a block of their
    own, with as many equations as the numeric block has besides its first, they are the numeric block's equations
    ((b) and (c)), and their unknowns follow from its solution, not from a second block of the same equations."""
    result = list(steps)
    for index, step in enumerate(result):
        pair = result[index + 1:index + len(step.block)]
        if not (step.numeric and pair and pair[0].block and not pair[0].numeric
                and pair[0].block == tuple(s.unknown for s in pair) and len(pair) == len(step.block) - 1):
            continue
        block = (step.unknown, *pair[0].block)
        result[index] = replace(step, block=block)
        for at, member in enumerate(pair, start=index + 1):
            result[at] = replace(member, block=block)
    return result


def textbook_route(template: Template, compiled: Compiled) -> Route:
    """The steps of ``template``'s worked solution as the page shows them (see the module's docstring)."""
    extra: list[Step] = []
    positive: dict[str, Node] = {}
    steps = _numeric_blocks(_plastic(template, _impacts(template, compiled, list(compiled.steps), extra)))
    steps = _energy(template, steps, extra)
    steps = bounce_heights(steps)
    steps = magnitudes(steps)
    steps = inverse_trig(steps, positive)
    steps = [one_fraction(s) for s in steps]
    return Route(tuple(folded(s) for s in steps), tuple(folded(s) for s in extra), positive)


_LOST = "energy lost in the impact"
_BEFORE = "kinetic energy just before the impact"
_AFTER = "kinetic energy just after the impact"
_TWO = Num(Fraction(2))


def _speed(node: Node | None) -> Node | None:
    """A velocity component as a speed is squared: ``v`` for ``−v``; None for none or zero."""
    if is_zero(node):
        return None
    return node.args[0] if isinstance(node, Op) and node.op == "neg" else node


def _kinetic(masses: list[Node], velocities: list[tuple[Node | None, ...]], zero: set[str]) -> Node | None:
    """``½ m_A v_A² + ½ m_B v_B²`` over the bodies that move (a velocity's components squared and added, ``v′² =
    v′_n² + v′_t²``), bodies with one velocity together as one, ``½ (m_A + m_B) v′²``; None where none moves."""
    grouped: list[tuple[list[Node], tuple[Node, ...]]] = []
    for mass, velocity in zip(masses, velocities, strict=True):
        parts = tuple(p for p in (_speed(c) for c in velocity)
                      if p is not None and not (isinstance(p, Sym) and p.name in zero))
        if not parts:
            continue
        same = next((group for group in grouped if group[1] == parts), None)
        if same is None:
            grouped.append(([mass], parts))
        else:
            same[0].append(mass)
    terms = []
    for group_masses, parts in grouped:
        mass = _add(*group_masses)
        squares = _add(*(Op("pow", (p, _TWO)) for p in parts))
        terms.append(_div(_mul(mass, squares), _TWO))
    return _add(*terms) if terms else None


def _components(stage: Stage, when: str, body: str) -> tuple[Node | None, ...]:
    """A body's velocity ``before`` or ``after`` an impact: ``(n, t)``, or ``(n,)`` as a number or a name alone."""
    velocity = stage.fields.get(when, {}).get(body)
    return (velocity.n, velocity.t) if isinstance(velocity, Velocity) else (velocity,)


def _energy(template: Template, steps: list[Step], extra: list[Step]) -> list[Step]:
    """The energy lost in an impact as a textbook finds it once the velocities after are on the page (Sample
    Problems 3/28–3/30): ``T = ½ m_A v_A² + ½ m_B v_B²``, ``T′`` likewise with the velocities after, then ``ΔE = T −
    T′``, where the kernel's stable form (``m_A m_B (v_A − v_B)² (1 − e²)/(2 (m_A + m_B))``) stays the kernel's.
    A velocity the page has not found by then keeps the kernel's form."""
    bodies = template.scene.bodies
    impacts = [s for s in template.scene.stages if s.effect == "impact"]
    for found in list(steps):
        if found.relation != _LOST or found.numeric:
            continue
        stages = [s for s in impacts if s.fields.get("energy_lost", "E_lost") == found.unknown]
        if len(stages) != 1:
            continue
        stage = stages[0]
        index = steps.index(found)
        taken = (set(template.parameters) | set(template.symbols) | set(template.scene.names())
                 | {s.unknown for s in steps} | {s.unknown for s in extra})
        known = set(template.parameters) | set(template.symbols) | {"g"} | {s.unknown for s in steps[:index]}
        zero = {s.unknown for s in steps if is_zero(s.solved)}
        movable = [b for b in stage.fields["bodies"] if bodies[b].mass is not None]
        masses = [bodies[b].mass for b in movable]

        components = partial(_components, stage)
        after = [components("after", b) for b in movable]
        if any(all(c is None for c in v) for v in after):
            continue  # a velocity after the scene does not name
        new: list[Step] = []
        for body, (_, tangent) in zip(movable, after, strict=True):
            # a t-velocity after the chain never needed: unchanged, as the page says for the other body's
            unchanged = _speed(components("before", body)[-1]) if len(components("before", body)) == 2 else None
            if isinstance(tangent, Sym) and tangent.name not in known and unchanged is not None \
                    and names(unchanged) <= known \
                    and tangent.name not in {s.unknown for s in (*steps, *extra)}:
                copy = components("before", body)[-1]
                new.append(Step(tangent.name, f"smooth surfaces: no impulse along t, so {body}'s t-velocity is "
                                "unchanged", (tangent, copy), copy))  # type: ignore[arg-type]
                known.add(tangent.name)
        before_form = _kinetic(masses, [components("before", b) for b in movable], zero)  # type: ignore[arg-type]
        after_form = _kinetic(masses, after, zero)  # type: ignore[arg-type]
        if before_form is None or after_form is None:
            continue
        # E_lost_2 = T_2 − T_after_2 (T₂ − T′₂ on the page), the second impact's
        suffix = found.unknown[len("E_lost"):] if found.unknown.startswith("E_lost") else f"_{stage.index}"
        before = stage.fields.get("energy_before", "T" + suffix)
        if before not in {s.unknown for s in steps[:index]}:
            if before in taken:
                continue
            new.append(Step(before, _BEFORE, (Sym(before), before_form), before_form))
        after_name = stage.fields.get("energy_after", "T_after" + suffix)
        if after_name in taken or not names(after_form) <= known | {before}:
            continue
        new.append(Step(after_name, _AFTER, (Sym(after_name), after_form), after_form))
        difference = _sub(Sym(before), Sym(after_name))
        extra += new
        steps = [*steps[:index], *new, replace(found, equation=(Sym(found.unknown), difference), solved=difference),
                 *steps[index + 1:]]
    return steps
