"""One variant's scene as the figures see it: every quantity's value (SI, symbols at 1) and how to
label it, and the stages a figure is drawn from."""

from __future__ import annotations

import math as _m
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from grader.assign.variants import ProblemVariant
from grader.bank.template import Template
from grader.model.expr import Node, Op, Sym, names
from grader.model.kernel import evaluate
from grader.model.scene import Stage, Velocity
from grader.render.typst_math import math, name
from grader.render.typst_text import string


@dataclass(frozen=True)
class SceneView:
    """One variant's scene: values of every quantity (SI, symbols at 1) and how to label them."""

    template: Template
    variant: ProblemVariant
    values: Mapping[str, float]

    def value(self, node: Node | None) -> float:
        if node is None:
            return 0.0
        try:
            with np.errstate(all="ignore"):
                return float(evaluate(node, self.values))
        except KeyError:
            return _m.nan

    def given(self, node: Node) -> list[str]:
        """``h_drop = 1863 mm`` for a parameter, the name (or expression) otherwise."""
        if isinstance(node, Sym) and node.name in self.template.parameters:
            unit = self.template.parameters[node.name].unit.text
            printed = self.variant.printed[node.name]
            shown = " degree" if unit == "deg" else f" thin {string(unit)}" if unit else ""
            return [f"{name(node.name)} = {printed}{shown}"]
        return [math(node)]

    def moving(self, node: Node, along: tuple[float, float]) -> tuple[list[str], tuple[float, float]]:
        """The label of a velocity ``node`` (positive ``along`` a direction) drawn as an arrow the way it
        moves, and the direction in which the quantity the label names is positive: as :meth:`given`
        when the statement gives it positive, its magnitude when negative (``|v_B| = 5.2 km/h``: the
        arrow says which way); ``-u`` is labelled with ``u``, positive the other way."""
        if isinstance(node, Op) and node.op == "neg":
            node, along = node.args[0], (-along[0], -along[1])
        lines = self.given(node)
        if isinstance(node, Sym) and node.name in self.template.parameters and " = " in lines[0]:
            shown, value = lines[0].split(" = ", 1)
            if value.startswith(("-", "\u2212")):
                return [f"|{shown}| = {value[1:]}"], along
        return lines, along

    def is_given(self, node: Node) -> bool:
        """Whether the statement gives this quantity (only parameters and numbers in it): what is
        asked is never drawn to scale."""
        return names(node) <= set(self.template.parameters)

    def shape(self, body: str, default: str) -> str:
        """How a figure draws ``body``: the template's ``shape`` for it, else the panel's ``default``."""
        return self.template.scene.bodies[body].shape or default

    def mass_value(self, body: str) -> list[str]:
        """A body's mass as its printed value and unit (``1.5 kg``) when a parameter gives it."""
        mass = self.template.scene.bodies[body].mass
        if isinstance(mass, Sym) and mass.name in self.template.parameters:
            return [self.given(mass)[0].split(" = ", 1)[1]]
        return self.mass(body)

    def mass(self, body: str) -> list[str]:
        """A body's mass as given: ``m_1 = 1.5 kg``, or ``p m = 1.67 m``."""
        mass = self.template.scene.bodies[body].mass
        if mass is None:
            return []
        if isinstance(mass, Sym):
            return self.given(mass)
        printed = {n: self.variant.printed[n] for n in names(mass) if n in self.template.parameters}
        shown = math(mass)
        substituted = math(mass, printed)
        return [shown if substituted == shown else f"{shown} = {substituted}"]


def find_stage(stages: Sequence[Stage], effect: str, before: int | None = None, after: int | None = None,
           body: str | None = None) -> Stage | None:
    for stage in stages:
        if stage.effect != effect or (before is not None and stage.index >= before) or \
                (after is not None and stage.index <= after):
            continue
        if body is None or stage.fields.get("body") == body:
            return stage
    return None


def velocity_stage(stages: Sequence[Stage], velocity: Velocity | None) -> Stage | None:
    """The ``velocity`` stage that gives (or takes) the components of ``velocity``."""
    if velocity is None:
        return None
    wanted = set().union(*(names(part) for part in (velocity.n, velocity.t) if part is not None))
    for stage in stages:
        if stage.effect == "velocity" and (names(stage.fields["n"]) | names(stage.fields["t"])) & wanted:
            return stage
    return None
