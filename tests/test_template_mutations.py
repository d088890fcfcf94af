"""Every shipped template mutated many ways (issue 24): a field deleted, renamed or misspelt, a body swapped,
an unknown name or a function in an expression, a velocity left out, a name misspelt so that two unknowns
stand where one fits, an effect's name misspelt, a unit of the wrong kind, a value of the wrong type. Each
is loaded, compiled and solved at its example as ``grader check-bank --bank DIR`` and ``grader solve`` do;
it works, or its message names the file and a field and is an author's message: no sympy class, no Python
exception, no function the template does not call.

The mutations are enumerated in a fixed order and a seeded sample runs by default (a few hundred, seconds);
``-m slow`` runs every one.
"""

from __future__ import annotations

import copy
import random
import re
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
import yaml

from grader.bank.template import Template, load_template, misspelt_as
from grader.base.errors import GraderError, TemplateError
from grader.base.resources import bank_dir
from grader.solve.compiled import Compiled
from grader.solve.evaluate import solve_one
from grader.solve.solver import compile_template

Place = tuple[str | int, ...]  # keys and indexes from the top of the template to a value

WRONG_TYPES: tuple[Any, ...] = ([1, 2], {"x": 1}, True, None, 2.5, "q_unknown")
OTHER_UNIT = {"kg": "m", "g": "m/s", "m/s": "s", "m": "kg", "mm": "N", "deg": "m", "": "m", "%": "kg",
              "ft": "lb", "s": "m", "lb": "ft/s", "ft/s": "lb"}

INTERNAL = re.compile(r"Boolean(?:True|False)|\bSymbol\b|\bDummy\b|\b(?:Add|Mul|Pow)\(|Piecewise|\b[A-Z]\w*Error\b|"
                      r"\b(?:Exception|Traceback)\b|object has no attribute|NoneType|\bsympy\b|\bnumpy\b|<class ")
"""What only grader's code or its libraries say: a sympy class, a Python exception, a repr of a class."""
FUNCTION = re.compile(r"\b(atan2|atan|asin|acos|acot|asinh|acosh|sqrt|Max|Min|Abs|abs|sign|log|exp|sin|cos|tan|"
                      r"sind|cosd|hypot|Heaviside|re|im|arg|floor|ceiling|LambertW|conjugate)\(")


def _places(value: Any, here: Place = ()) -> Iterator[tuple[Place, Any]]:
    """Every value below the top and where it sits, containers before what they hold."""
    items = value.items() if isinstance(value, dict) else enumerate(value) if isinstance(value, list) else ()
    for key, item in items:
        yield (*here, key), item
        yield from _places(item, (*here, key))


def _misspelt(text: str) -> list[str]:
    """Three misspellings: a character added, one dropped, the word reversed (or upper-cased)."""
    return [text + "_", text[:-1] if len(text) > 1 else text + "x", text[::-1] if len(text) > 2 else text.upper()]


Mutation = tuple[str, Callable[[dict[str, Any]], None]]  # what is done, and doing it to a copy
TEXT = {"title", "description", "statement"}  # prose: only deleted or given a value of another type


def mutations(raw: dict[str, Any]) -> Iterator[Mutation]:
    """Each mutation of one template's mapping: what is done, and a function doing it to a copy."""

    def at(place: Place, change: Callable[[Any, Any], None]) -> Callable[[dict[str, Any]], None]:
        def done(mutated: dict[str, Any]) -> None:
            parent = mutated
            for key in place[:-1]:
                parent = parent[key]
            change(parent, place[-1])
        return done

    def becomes(new: Any) -> Callable[[Any, Any], None]:
        return lambda parent, key: parent.__setitem__(key, new)

    for place, value in list(_places(raw)):
        where, key = ".".join(map(str, place)), place[-1]
        if isinstance(key, str):
            yield f"{where} deleted", at(place, lambda parent, key: parent.pop(key))
            for new in _misspelt(key)[:2]:
                yield f"{where} renamed {new}", at(place, lambda parent, key, new=new: parent.__setitem__(
                    new, parent.pop(key)))
        else:
            yield f"{where} dropped", at(place, lambda parent, key: parent.pop(key))
        if isinstance(value, list) and len(value) >= 2:
            yield f"{where} reversed", at(place, lambda parent, key: parent[key].reverse())
        if isinstance(value, str) and not TEXT & set(map(str, place)):
            for new in [*_misspelt(value), f"({value}) + zz", f"atan2({value}, 1)", f"sqrt({value})"]:
                yield f"{where} = {new!r}", at(place, becomes(new))
        if key == "unit" and isinstance(value, str):
            unit = OTHER_UNIT.get(value, "furlong")
            yield f"{where} = {unit!r}", at(place, becomes(unit))
        for wrong in WRONG_TYPES:
            if wrong != value:
                yield f"{where} = {wrong!r}", at(place, becomes(wrong))
    yield from _swapped_bodies(raw)


def _swapped_bodies(raw: dict[str, Any]) -> Iterator[Mutation]:
    """A stage's body replaced by another, and a velocity given to another body."""
    bodies = list(raw.get("bodies", {}))
    for index, stage in enumerate(raw.get("stages", [])):
        for key in ("body", "with"):
            for other in bodies:
                if key in stage and other != stage[key]:
                    yield (f"stages.{index}.{key} = {other}",
                           lambda mutated, index=index, key=key, other=other: mutated["stages"][index].__setitem__(
                               key, other))
        for key in ("before", "after"):
            given = stage.get(key)
            for body in given if isinstance(given, dict) else ():
                for other in [b for b in bodies if b not in given]:
                    def moved(mutated: dict[str, Any], index: int = index, key: str = key, body: str = body,
                              other: str = other) -> None:
                        velocities = mutated["stages"][index][key]
                        velocities[other] = velocities.pop(body)
                    yield f"stages.{index}.{key}.{body} given to {other}", moved


SHIPPED = {path.stem: yaml.safe_load(path.read_text(encoding="utf-8")) for path in sorted(bank_dir().glob("*.yaml"))}
MUTATIONS = [(template_id, what, change) for template_id, raw in SHIPPED.items() for what, change in mutations(raw)]
"""(template id, what is done, doing it) for every shipped template, in a fixed order."""


def problems(message: str, text: str, where: str | None) -> list[str]:
    """What is wrong with a message an author reads (``where``: the file it must name first, if any)."""
    wrong = []
    if where is not None and not re.match(rf"{re.escape(where)}: [\w\[\](){{}}., -]+: ", message):
        wrong.append("no file and field")
    wrong += [f"internal name {m.group()!r}" for m in INTERNAL.finditer(message)]
    wrong += [f"function {m.group(1)} the template does not call" for m in FUNCTION.finditer(message)
              if not re.search(rf"\b{m.group(1)}\(", text)]
    return wrong


def misspelling_unnamed(message: str, mutated: dict[str, Any], original: dict[str, Any]) -> list[str]:
    """A name the mutation brought in that misspells a parameter or symbol no stage uses any more (``e_`` for
    ``e``), reported as an answer nothing fixes rather than as the unknown name it is."""
    if "nothing fixes" not in message:
        return []
    given = {str(name) for key in ("parameters", "symbols") for name in mutated.get(key) or {}}
    stages = set(re.findall(r"[A-Za-z_]\w*", str([mutated.get("stages"), mutated.get("bodies")])))
    brought = stages - set(re.findall(r"[A-Za-z_]\w*", str([original.get("stages"), original.get("bodies")])))
    return [f"{name}, a misspelling of {close[0]}, reported as nothing fixes" for name in sorted(brought)
            if (close := misspelt_as(name, given - stages))]


def outcome(template_id: str, change: Callable[[dict[str, Any]], None], folder: Path) -> list[str]:
    """Load, compile and solve a mutated template at its example (a parameter without one at the low end of
    its sampling); what is wrong with the message it gets, if any (empty when it works or says it well)."""
    mutated = copy.deepcopy(SHIPPED[template_id])
    change(mutated)
    path = folder / f"{template_id}.yaml"
    text = yaml.safe_dump(mutated, sort_keys=False, allow_unicode=True)
    path.write_text(text, encoding="utf-8")
    try:
        template = load_template(path)
        compiled = _compiled(template, str(folder))
        values = {name: template.example.get(name, parameter.sample.values[0])
                  for name, parameter in template.parameters.items()}
        refused = solve_one(template, compiled, values).error
    except TemplateError as error:
        return problems(str(error), text, str(path)) + ([] if error.key else ["no field"]) + \
            misspelling_unnamed(str(error), mutated, SHIPPED[template_id])
    except GraderError as error:
        return problems(str(error), text, str(path))
    return problems(refused, text, None) if refused else []


_COMPILED: dict[tuple[str, str], Compiled | TemplateError] = {}


def _compiled(template: Template, folder: str) -> Compiled:
    """``compile_template``, once for all the mutations that change nothing it reads (a description, a sampling
    range, the statement, the example): the run's time goes to the mutations that change the physics."""
    parameters = {name: (p.unit, p.domain, p.integer) for name, p in template.parameters.items()}
    answers = {name: (a.value, a.unit, a.symbolic) for name, a in template.answers.items()}
    key = (folder, repr((template.id, template.scene, parameters, template.symbols, answers)))
    if key not in _COMPILED:
        try:
            _COMPILED[key] = compile_template(template)
        except TemplateError as error:
            _COMPILED[key] = error
    found = _COMPILED[key]
    if isinstance(found, TemplateError):
        raise found
    return found


SAMPLED = random.Random(24).sample(range(len(MUTATIONS)), 100)


def _check(indexes: list[int], folder: Path) -> None:
    found = {}
    for index in indexes:
        template_id, what, change = MUTATIONS[index]
        wrong = outcome(template_id, change, folder)
        if wrong:
            found[f"{template_id}: {what}"] = wrong
    assert not found, found


@pytest.mark.slow  # about 5 s of mutated templates loaded; each kind of mistake has its own test above
def test_a_sample_of_mutated_templates_is_told_what_to_change(tmp_path: Path) -> None:
    """100 mutations, a seeded sample of all of them."""
    _check(SAMPLED, tmp_path)


@pytest.mark.slow
@pytest.mark.parametrize("template_id", sorted(path.stem for path in bank_dir().glob("*.yaml")))
def test_every_mutation_of_a_template_is_told_what_to_change(template_id: str, tmp_path: Path) -> None:
    """Every mutation of one template (about a thousand)."""
    _check([index for index, (found, _, _) in enumerate(MUTATIONS) if found == template_id], tmp_path)


def _refusal(tmp_path: Path, template_id: str, old: str, new: str) -> str:
    """The message of a shipped template with ``old`` replaced by ``new``, loaded and compiled."""
    text = (bank_dir() / f"{template_id}.yaml").read_text(encoding="utf-8")
    assert old in text
    path = tmp_path / f"{template_id}.yaml"
    path.write_text(text.replace(old, new, 1), encoding="utf-8")
    with pytest.raises(TemplateError) as refused:
        compile_template(load_template(path))
    return str(refused.value).removeprefix(f"{path}: ")


def test_a_misspelt_restitution_is_an_unknown_name_not_an_answer_nothing_fixes(tmp_path: Path) -> None:
    assert _refusal(tmp_path, "head-on", "restitution: e", "restitution: e_") == (
        "stages[0].restitution: expected names of parameters, symbols or quantities the solver finds, got unknown "
        "name e_ (did you mean e?): the parameter e, which no stage uses")


def test_an_atan2_sympy_rewrites_as_atan_compiles(tmp_path: Path) -> None:
    """Every domain positive, sympy writes ``atan2(v_y, 1)`` as ``atan(v_y)``: it was "got atan(v_y) (atan)"."""
    text = (bank_dir() / "wall-throw.yaml").read_text(encoding="utf-8")
    path = tmp_path / "wall-throw.yaml"
    path.write_text(text.replace("end_vertical: v_y_hit", "end_vertical: atan2(v_y_hit, 1)", 1), encoding="utf-8")
    assert "atan2(v_y_hit, 1)" in path.read_text(encoding="utf-8")
    assert compile_template(load_template(path)).answers


def test_quantities_the_template_left_unnamed_are_named_by_their_stage_field(tmp_path: Path) -> None:
    """The ball's velocity after the impact left out: the equations left tie the impulse and that velocity, which
    the author never named; the message says where each belongs."""
    message = _refusal(tmp_path, "drop-rebound", "    after: {ball: v_after}\n", "")
    assert message.startswith("answers.e: expected an answer the scene determines from the parameters, got nothing "
                              "fixes e; the equations left tie J (stages[1].impulse, unnamed), e, v_ball_n_after "
                              "(stages[1].after.ball: ball's velocity after, unnamed) together"), message
