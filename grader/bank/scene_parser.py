"""Reads a template's scene from YAML: bodies, and stages validated against each effect's field schema.

>>> scene = parse_scene({"bodies": {"ball": {"mass": "m"}, "floor": {"fixed": True}},
...     "stages": [{"effect": "free_fall", "body": "ball", "height": "h", "speed": "v"}]},
...     "demo.yaml", gravity=None)
>>> scene.stages[0].text("height"), sorted(scene.names())
('h', ['h', 'm', 'v'])
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from grader.bank.folders import NAME
from grader.base.errors import ExpressionError, TemplateError, shown
from grader.model.expr import Node, names, parse
from grader.model.scene import SHAPES, Body, Gravity, Scene, Stage, Velocity
from grader.physics.effects import CATALOGUE, Effect, Field


def parse_scene(raw: Mapping[str, Any], where: str, gravity: Gravity | None) -> Scene:
    """Read ``bodies`` and ``stages`` from a template's YAML mapping."""
    bodies = _parse_bodies(raw.get("bodies"), where)
    stages_raw = raw.get("stages")
    if not isinstance(stages_raw, list) or not stages_raw:
        raise TemplateError(where, "stages", "a non-empty list of stages", shown(stages_raw))
    stages = tuple(_parse_stage(item, index, where, bodies) for index, item in enumerate(stages_raw))
    return Scene(where, bodies, stages, gravity)


def _parse_bodies(raw: Any, where: str) -> dict[str, Body]:
    if not isinstance(raw, Mapping) or not raw:
        raise TemplateError(where, "bodies", "a mapping of body names to {mass: ...} or {fixed: true}", shown(raw))
    bodies = {}
    for name, spec in raw.items():
        key = f"bodies.{name}"
        if not NAME.match(str(name)):
            raise TemplateError(where, key, "a name of letters, digits and _", shown(name))
        if not isinstance(spec, Mapping) or set(spec) - {"mass", "fixed", "radius", "shape"}:
            raise TemplateError(where, key, "{mass: EXPR} or {fixed: true}, and optionally radius: EXPR and "
                                f"shape: {'|'.join(SHAPES)}", shown(spec))
        radius = _expr(spec["radius"], where, f"{key}.radius") if "radius" in spec else None
        shape = _shape(spec, radius, where, key)
        if spec.get("fixed") is True:
            if "mass" in spec:
                raise TemplateError(where, key, "either a mass or fixed: true, not both", shown(spec))
            bodies[name] = Body(name, None, radius, shape)
        elif "mass" in spec:
            bodies[name] = Body(name, _expr(spec["mass"], where, f"{key}.mass"), radius, shape)
        else:
            raise TemplateError(where, key, "a mass or fixed: true", shown(spec))
    return bodies


def _shape(spec: Mapping[str, Any], radius: Node | None, where: str, key: str) -> str | None:
    """A body's ``shape``: one of :data:`SHAPES`; a body with a radius is a sphere."""
    if "shape" not in spec:
        return None
    shape = spec["shape"]
    if shape not in SHAPES:
        raise TemplateError(where, f"{key}.shape", f"one of {', '.join(SHAPES)}", shown(shape))
    if radius is not None and shape != "sphere":
        raise TemplateError(where, f"{key}.shape", "sphere for a body with a radius (or leave shape out)",
                            shown(shape))
    return str(shape)


def _parse_stage(raw: Any, index: int, where: str, bodies: Mapping[str, Body]) -> Stage:
    key = f"stages[{index}]"
    if not isinstance(raw, Mapping) or "effect" not in raw:
        raise TemplateError(where, key, "a mapping with an 'effect' key", shown(raw))
    effect = CATALOGUE.get(raw["effect"]) if isinstance(raw["effect"], str) else None
    if effect is None:
        raise TemplateError(where, f"{key}.effect", f"one of {', '.join(sorted(CATALOGUE))}", shown(raw["effect"]))
    allowed = {f.name for f in effect.fields} | {"effect"}
    unknown = set(raw) - allowed
    if unknown:
        raise TemplateError(where, f"{key}", f"only the fields of '{effect.name}' ({', '.join(sorted(allowed))})",
                            f"unknown field(s) {', '.join(sorted(map(str, unknown)))}")
    fields: dict[str, Any] = {}
    source: dict[str, str] = {}
    for spec in effect.fields:
        if spec.name not in raw:
            if spec.required:
                raise TemplateError(where, f"{key}.{spec.name}", f"a value ({spec.doc})", "nothing")
            continue
        fields[spec.name] = _parse_field(spec, raw[spec.name], where, f"{key}.{spec.name}", bodies)
        source[spec.name] = str(raw[spec.name])
    stage = Stage(index, effect.name, fields, source, frozenset(_quantities(effect, fields)))
    if "bodies" in fields and bodies[fields["bodies"][0]].mass is None:
        raise TemplateError(where, f"{key}.bodies", "the first body to be movable (list the fixed one second)",
                            shown(list(fields["bodies"])))
    return stage


def _parse_field(spec: Field, value: Any, where: str, key: str, bodies: Mapping[str, Body]) -> Any:
    if spec.kind == "body":
        if not isinstance(value, str) or value not in bodies:
            raise TemplateError(where, key, f"one of the bodies ({', '.join(bodies)})", shown(value))
        return value
    if spec.kind in ("bodies", "spheres"):
        if not (isinstance(value, list) and len(value) == 2 and all(isinstance(v, str) and v in bodies for v in value)
                and value[0] != value[1]):
            raise TemplateError(where, key, f"two different bodies from ({', '.join(bodies)})", shown(value))
        flat = [v for v in value if bodies[v].radius is None]
        if spec.kind == "spheres" and flat:
            raise TemplateError(where, key, "two spheres: bodies with a radius (bodies.NAME.radius)",
                                f"{', '.join(flat)} without one")
        return tuple(value)
    if spec.kind == "vector":
        if not isinstance(value, Mapping) or set(value) != {"n", "t"}:
            raise TemplateError(where, key, "{n: EXPR, t: EXPR}", shown(value))
        return Velocity(_expr(value["n"], where, f"{key}.n"), _expr(value["t"], where, f"{key}.t"))
    if spec.kind == "name":
        if not (isinstance(value, str) and NAME.match(value)):
            raise TemplateError(where, key, "a quantity name of letters, digits and _", shown(value))
        return value
    if spec.kind.startswith("choice:"):
        options = spec.kind.split(":", 1)[1].split("|")
        if value not in options:
            raise TemplateError(where, key, f"one of {', '.join(options)}", shown(value))
        return value
    if spec.kind == "flag":
        if not isinstance(value, bool):
            raise TemplateError(where, key, "true or false", shown(value))
        return value
    if spec.kind == "velocities":
        return _parse_velocities(value, where, key, bodies)
    return _expr(value, where, key)


def _parse_velocities(value: Any, where: str, key: str, bodies: Mapping[str, Body]) -> dict[str, Velocity]:
    if not isinstance(value, Mapping):
        raise TemplateError(where, key, "a mapping of body name to velocity", shown(value))
    result = {}
    for body, given in value.items():
        if body not in bodies:
            raise TemplateError(where, f"{key}.{body}", f"one of the bodies ({', '.join(bodies)})", shown(body))
        if bodies[body].mass is None and not key.endswith(".before"):
            # A fixed surface (infinite mass) may move at a constant velocity, which no impact changes.
            raise TemplateError(where, f"{key}.{body}", "no velocity after the impact for a fixed body (it keeps "
                                "the velocity given under 'before', or stays at rest)", shown(given))
        if isinstance(given, Mapping):
            if set(given) - {"n", "t"} or "n" not in given:
                raise TemplateError(where, f"{key}.{body}", "{n: EXPR, t: EXPR}", shown(given))
            t = _expr(given["t"], where, f"{key}.{body}.t") if "t" in given else None
            result[body] = Velocity(_expr(given["n"], where, f"{key}.{body}.n"), t)
        else:
            result[body] = Velocity(_expr(given, where, f"{key}.{body}"))
    return result


def _expr(value: Any, where: str, key: str) -> Node:
    if isinstance(value, bool) or not isinstance(value, (str, int, float)):
        raise TemplateError(where, key, "an expression (text or number)", shown(value))
    try:
        return parse(str(value))
    except ExpressionError as error:
        raise TemplateError(where, key, "a valid expression", f"{shown(value)} ({error})") from None


def _quantities(effect: Effect, fields: Mapping[str, Any]) -> set[str]:
    used: set[str] = set()
    for spec in effect.fields:
        value = fields.get(spec.name)
        if value is None or spec.kind in ("body", "bodies", "spheres", "flag") or spec.kind.startswith("choice:"):
            continue
        if spec.kind == "name":
            used.add(value)
        elif spec.kind in ("velocities", "vector"):
            for velocity in (value.values() if spec.kind == "velocities" else [value]):
                for part in (velocity.n, velocity.t):
                    used |= names(part) if part is not None else set()
        else:
            used |= names(value)
    return used
