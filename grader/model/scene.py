"""A template's physical scene: bodies and a sequence of stages, each an effect of the catalogue.

Data types only, frozen; :mod:`grader.bank.scene_parser` reads them from YAML and validates each
stage against its effect's field schema.

>>> from grader.model.expr import parse
>>> stage = Stage(0, "free_fall", {"body": "ball", "height": parse("h")}, {"height": "h"}, frozenset({"h", "v"}))
>>> scene = Scene("demo.yaml", {"ball": Body("ball", parse("m"))}, (stage,), gravity=None)
>>> stage.text("height"), sorted(scene.names())
('h', ['h', 'm', 'v'])
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from grader.model.expr import Node, names

SHAPES = ("block", "sphere", "particle")
"""How a figure may draw a body: a block (a rectangle), a sphere (a circle), a particle (a small dot)."""


@dataclass(frozen=True)
class Body:
    """A body: its mass expression, or ``None`` for a fixed surface (infinite mass), the radius of
    a sphere where the scene's geometry needs one (``None``: a point body), and the shape its figures draw
    (one of :data:`SHAPES`; ``None``: each panel's own, a block in a line of impacts or on a cord)."""

    name: str
    mass: Node | None
    radius: Node | None = None
    shape: str | None = None


@dataclass(frozen=True)
class Velocity:
    """A body's velocity in an impact: n component, and t component for an oblique impact."""

    n: Node | None
    t: Node | None = None


@dataclass(frozen=True)
class Stage:
    """One stage: an effect and its fields, parsed; ``source`` keeps the YAML text of each field and
    ``quantities`` every quantity name its fields use (the parser knows which fields hold them)."""

    index: int
    effect: str
    fields: Mapping[str, Any]
    source: Mapping[str, str]
    quantities: frozenset[str]

    def text(self, key: str) -> str:
        """The field as the template wrote it."""
        return self.source.get(key, "")

    @property
    def is_oblique(self) -> bool:
        """Whether any velocity of this stage has a t component."""
        return any(v.t is not None for when in ("before", "after")
                   for v in self.fields.get(when, {}).values())


@dataclass(frozen=True)
class Gravity:
    """``g`` in SI, and as the template wrote it."""

    si: Any  # Fraction
    text: str


@dataclass(frozen=True)
class Scene:
    """Bodies and stages; ``where`` names the file for messages."""

    where: str
    bodies: Mapping[str, Body]
    stages: tuple[Stage, ...]
    gravity: Gravity | None

    def names(self) -> set[str]:
        """Every name the scene's expressions use."""
        used: set[str] = set()
        for body in self.bodies.values():
            for part in (body.mass, body.radius):
                used |= names(part) if part is not None else set()
        for stage in self.stages:
            used |= stage.quantities
        return used
