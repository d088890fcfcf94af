"""Template loading: every mistake is refused with `file: key: expected …, got …`."""

from __future__ import annotations

import copy
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
import yaml

from grader.bank.template import load_bank, load_template, parse_template
from grader.base.errors import GraderError, TemplateError
from grader.base.resources import bank_dir
from grader.solve.solver import compile_template

BASE = yaml.safe_load((bank_dir() / "drop-rebound.yaml").read_text(encoding="utf-8"))


def mutated(change: Callable[[dict[str, Any]], Any]) -> dict[str, Any]:
    raw = copy.deepcopy(BASE)
    change(raw)
    return raw


def set_in(path: str, value: Any) -> Callable[[dict[str, Any]], None]:
    def change(raw: dict[str, Any]) -> None:
        *parents, last = path.split("/")
        node: Any = raw
        for part in parents:
            node = node[int(part)] if part.isdigit() else node[part]
        node[int(last) if last.isdigit() else last] = value
    return change


INVALID = [
    ("domain", set_in("parameters/h_drop/domain", "[1 2]"), "parameters.h_drop.domain: expected an interval"),
    ("domain-order", set_in("parameters/h_drop/domain", "[3, 1]"), "expected an interval with low < high"),
    ("unit", set_in("parameters/h_drop/unit", "furlongs"), "parameters.h_drop.unit: expected a unit"),
    ("sample-outside", set_in("parameters/h_rebound/sample", {"uniform": [-5, 10]}),
     "parameters.h_rebound.sample.uniform: expected values inside the domain [0, inf), got -5"),
    ("sample-kind", set_in("parameters/h_drop/sample", {"normal": [1, 2]}),
     "parameters.h_drop.sample: expected one of"),
    ("precision-both", set_in("parameters/h_drop/sig_figs", 3), "expected exactly one of decimals or sig_figs"),
    ("effect", set_in("stages/0/effect", "teleport"),
     "stages[0].effect: expected one of angle_between, "),
    ("field", set_in("stages/0/colour", "red"), "stages[0]: expected only the fields of 'free_fall'"),
    ("missing-field", lambda raw: raw["stages"][0].pop("height"), "stages[0].height: expected a value"),
    ("body", set_in("stages/0/body", "bat"), "stages[0].body: expected one of the bodies (ball, floor)"),
    ("fixed-first", set_in("stages/1/bodies", ["floor", "ball"]), "expected the first body to be movable"),
    ("expression", set_in("stages/0/height", "__import__('os')"), "'__import__' is not an allowed function"),
    ("answer-name", set_in("answers/e/value", "e_typo"), "answers.e.value: expected names of the scene's quantities"),
    ("constraint", set_in("constraints/0/require", "h_rebound <= height"), "constraints[0].require: expected an"),
    ("constraint-not-comparison", set_in("constraints/0/require", "h_rebound"), "expected a comparison"),
    ("statement", set_in("statement", "Dropped from {{ height }} mm"), "statement: expected only parameters"),
    ("statement-syntax", set_in("statement", "Dropped from {{ h_drop mm"), "statement: expected a valid Jinja2"),
    ("id", set_in("id", "Drop Rebound"), "id: expected lower-case letters"),
    ("version", set_in("version", "one"), "version: expected a whole number"),
    ("gravity", set_in("gravity", "9.81 m/s"), "gravity: expected a positive acceleration"),
    ("top-key", set_in("colour", "red"), "colour: expected only the keys"),
    ("reserved", set_in("parameters/g", BASE["parameters"]["h_drop"]),
     "expected a name of letters, digits and _, not g"),
    ("mass", set_in("bodies/ball/mass", "m_unknown"), "bodies.ball.mass: expected parameters or symbols only"),
    ("body-spec", set_in("bodies/floor", {"fixed": True, "mass": "m"}), "either a mass or fixed: true"),
    ("radius", set_in("bodies/ball/radius", "r_unknown"), "bodies.ball.radius: expected parameters or symbols only"),
    ("radius-dimension", set_in("bodies/ball/radius", "m"),
     "bodies.ball.radius: expected a length (check the parameters' units), got 'm', which is a mass"),
    ("shape", set_in("bodies/ball/shape", "cube"),
     "bodies.ball.shape: expected one of block, sphere, particle, got 'cube'"),
    ("shape-with-radius", lambda raw: raw["bodies"]["ball"].update({"radius": "h_drop", "shape": "block"}),
     "bodies.ball.shape: expected sphere for a body with a radius (or leave shape out), got 'block'"),
    ("spheres", set_in("stages/0", {"effect": "impact_geometry", "bodies": ["ball", "floor"], "offset": "h_drop",
                                    "angle": "theta"}),
     "stages[0].bodies: expected two spheres: bodies with a radius (bodies.NAME.radius), got ball, floor without one"),
    ("vector", set_in("stages/0", {"effect": "angle_between", "first": "v", "second": {"n": "a", "t": "b"},
                                   "angle": "theta"}), "stages[0].first: expected {n: EXPR, t: EXPR}, got 'v'"),
    ("fixed-after", set_in("stages/1/after", {"ball": "v_after", "floor": "w"}),
     "stages[1].after.floor: expected no velocity after the impact for a fixed body (it keeps the velocity given"),
    ("tolerance", set_in("answers/e/tolerance", {"rtol": -1}), "answers.e.tolerance.rtol: expected a number from 0"),
    ("title-escape", set_in("title", "\x1b[2J\x1b[31mBall"),
     "title: expected one line of text without control characters, got '\\x1b[2J\\x1b[31mBall'"),
    ("title-return", set_in("title", "Ball\rdropped"), r"title: expected one line of text without control"),
    ("title-line-separator", set_in("title", "Ball\u2028dropped"), r"got 'Ball\u2028dropped'"),
    ("answer-key", lambda raw: raw["answers"].update({"e\x1b[31m\r": raw["answers"].pop("e")}),
     r"answers: expected names of letters, digits and _, got 'e\x1b[31m\r'"),
    ("answer-key-newline", lambda raw: raw["answers"].update({"e\n": raw["answers"].pop("e")}),
     r"answers: expected names of letters, digits and _, got 'e\n'"),
]


@pytest.mark.parametrize(("change", "message"), [(c, m) for _, c, m in INVALID], ids=[i for i, _, _ in INVALID])
def test_invalid_template_is_refused_with_where_and_what(change: Callable[[dict[str, Any]], Any],
                                                         message: str) -> None:
    """The message names the file and the key, and says what was expected."""
    with pytest.raises(TemplateError) as error:
        parse_template(mutated(change), "bank/drop-rebound.yaml", "hash", "drop-rebound")
    assert str(error.value).startswith("bank/drop-rebound.yaml: ")
    assert message in str(error.value)


def test_shipped_template_passes_validation_unchanged() -> None:
    """The base of the table above is itself valid (so each row tests one mistake)."""
    assert parse_template(mutated(lambda raw: None), "x.yaml", "hash", "drop-rebound").id == "drop-rebound"


def test_answer_the_scene_cannot_determine_is_refused_at_compile_time() -> None:
    """A scene without the rebound stage cannot give e: the message names what is missing."""
    raw = mutated(lambda raw: raw["stages"].pop(2))
    raw.pop("constraints")
    template = parse_template(raw, "x.yaml", "hash")
    with pytest.raises(TemplateError, match=r"answers.e: expected an answer the scene determines .* nothing fixes"):
        compile_template(template)


def test_numeric_answer_that_depends_on_a_symbol_is_refused() -> None:
    """An answer still in terms of the ball's mass m has no number: say so."""
    raw = mutated(set_in("answers/e", {"value": "m*e", "unit": "kg"}))
    with pytest.raises(TemplateError, match=r"answers.e: expected a number once the parameters are given, .* on m"):
        compile_template(parse_template(raw, "x.yaml", "hash"))


def test_file_level_problems_name_the_file(tmp_path: Path) -> None:
    """Bad YAML, a non-mapping, an id that is not the file name, duplicate ids."""
    cases = {"broken.yaml": "id: [unclosed", "list.yaml": "- a\n- b\n",
             "renamed.yaml": (bank_dir() / "drop-rebound.yaml").read_text(encoding="utf-8")}
    expected = {"broken.yaml": "expected valid YAML, got expected ',' or ']', but got '<stream end>' "
                               "(line 1, column 14)",
                "list.yaml": "(file): expected a mapping",
                "renamed.yaml": "id: expected the file name's stem 'renamed'"}
    for name, text in cases.items():
        (tmp_path / name).write_text(text, encoding="utf-8")
        with pytest.raises(GraderError) as error:
            load_template(tmp_path / name)
        assert str(error.value).startswith(str(tmp_path / name))
        assert expected[name] in str(error.value)


def test_missing_bank_folder_is_a_clear_error(tmp_path: Path) -> None:
    """Pointing --bank at nothing says which folder."""
    with pytest.raises(GraderError, match="problem bank folder not found"):
        load_bank(tmp_path / "nowhere")


def test_shipped_bank_has_the_five_seed_templates_with_their_names() -> None:
    """Ids, parameters and answers exactly as the foundation issue names them (issue 27 adds pile-driver's
    energy lost and impulse after them)."""
    bank = load_bank()
    expected = {
        "drop-rebound": (["h_drop", "h_rebound"], ["e", "loss_pct"]),
        "car-collision": (["p", "e"], ["vA", "vB", "vA_ratio", "vB_ratio"]),
        "pile-driver": (["m_ram", "m_pile", "h_drop", "h_rebound"], ["v_pile", "e", "loss_pct", "energy_lost",
                                                                    "impulse"]),
        "ball-plate": (["v", "theta", "e"], ["v_out", "theta_out"]),
        "oblique-spheres": (["v1", "theta", "e", "m1", "m2"], ["v1_out", "v2_out", "theta1_out", "loss_pct"]),
    }
    assert {t: (list(bank[t].parameters), list(bank[t].answers)) for t in expected} == expected


# --- topics ---------------------------------------------------------------------------------------

TOPIC_OF = {
    "car-collision": "direct impact", "coupling": "direct impact", "head-on": "direct impact",
    "head-on-inverse": "direct impact", "three-balls": "direct impact",
    "ball-plate": "oblique impact", "oblique-spheres": "oblique impact",
    "drop-rebound": "drops and rebounds", "moving-plate": "drops and rebounds", "pile-driver": "drops and rebounds",
    "two-rebounds": "drops and rebounds", "skid": "impact and sliding", "wall-throw": "impact with flight",
    # issue 27's (ramp-slide and incline-slide declare impact and sliding: a slope alone is no slide to the scene)
    "bullet-block-spring": "direct impact", "gun-recoil": "direct impact", "head-on-approach": "direct impact",
    "shell-explosion": "direct impact", "wall-impulse": "direct impact", "crash-reconstruction": "oblique impact",
    "intersection-crash": "oblique impact", "oblique-moving-spheres": "oblique impact",
    "cushion-stop": "drops and rebounds", "package-on-platform": "drops and rebounds", "spring-carts": "direct impact",
    "package-bounce": "drops and rebounds", "two-pendulums": "impact and a swing",
    "two-pendulums-inverse": "impact and a swing", "billiards-inverse": "oblique impact",
    "two-walls": "impact with flight", "shell-landing": "impact with flight",
}


@pytest.mark.parametrize(("template_id", "topic"), TOPIC_OF.items())
def test_each_template_has_its_topic_and_the_scene_would_give_the_same(template_id: str, topic: str) -> None:
    """The topic a shipped template declares is also what its scene says without the key (so a template
    written without one is grouped where it belongs)."""
    raw = yaml.safe_load((bank_dir() / f"{template_id}.yaml").read_text(encoding="utf-8"))
    assert load_bank()[template_id].topic == topic
    del raw["topic"]
    assert parse_template(raw, f"{template_id}.yaml", "hash", template_id).topic == topic


def test_a_topic_outside_the_list_is_refused_naming_the_choices() -> None:
    with pytest.raises(TemplateError, match=r"topic: expected one of direct impact, oblique impact, drops and "
                                            r"rebounds, impact and a swing, impact and sliding, impact with flight "
                                            r".*got 'impacts'"):
        parse_template(mutated(set_in("topic", "impacts")), "x.yaml", "hash")


def test_a_statement_that_fills_in_an_answer_is_refused_saying_so() -> None:
    with pytest.raises(TemplateError, match=r"statement: expected only parameters, symbols and g, got the answer "
                                            r"e, which the student finds"):
        parse_template(mutated(set_in("statement", "It bounces with e = {{ e }}.")), "x.yaml", "hash")


# --- several bank folders -------------------------------------------------------------------------

def own_folder(tmp_path: Path, name: str, template_id: str, change: Callable[[str], str] = lambda s: s) -> Path:
    """A folder holding a copy of drop-rebound under ``template_id``, its text passed through ``change``."""
    folder = tmp_path / name
    folder.mkdir()
    text = (bank_dir() / "drop-rebound.yaml").read_text(encoding="utf-8").replace(
        "id: drop-rebound", f"id: {template_id}")
    (folder / f"{template_id}.yaml").write_text(change(text), encoding="utf-8")
    return folder


def test_an_instructors_folder_sits_beside_the_shipped_bank(tmp_path: Path) -> None:
    from grader.bank.template import load_banks

    mine, more = own_folder(tmp_path, "mine", "my-drop"), own_folder(tmp_path, "more", "my-other-drop")
    bank = load_banks([mine, more])
    assert set(bank) == set(load_bank()) | {"my-drop", "my-other-drop"}
    assert bank["my-drop"].where == str(mine / "my-drop.yaml")
    assert set(load_banks([mine], shipped=False)) == {"my-drop"}
    assert set(load_banks([mine, mine / ".", bank_dir()])) == set(bank) - {"my-other-drop"}  # a folder counts once


def test_two_templates_with_one_id_are_refused_naming_both_files(tmp_path: Path) -> None:
    from grader.bank.template import load_banks

    mine, theirs = own_folder(tmp_path, "mine", "my-drop"), own_folder(tmp_path, "theirs", "my-drop")
    with pytest.raises(GraderError) as error:
        load_banks([mine, theirs])
    assert f"two templates have the id 'my-drop': {mine / 'my-drop.yaml'} and {theirs / 'my-drop.yaml'}" \
        in str(error.value)
    with pytest.raises(GraderError, match=f"id 'drop-rebound': {bank_dir() / 'drop-rebound.yaml'} and "):
        load_banks([own_folder(tmp_path, "copy", "drop-rebound")])


def test_no_bank_at_all_is_a_usage_error() -> None:
    from grader.bank.template import load_banks
    from grader.base.errors import UsageError

    with pytest.raises(UsageError, match=r"without the shipped bank .*give --bank DIR"):
        load_banks([], shipped=False)


def test_libyaml_and_pythons_parser_read_every_template_alike() -> None:
    """Templates are read with libyaml's parser where PyYAML has it (the bank is read on every command);
    PyYAML's own, all in Python, must give the same data (and gives the messages for broken files)."""
    import yaml

    from grader.base.yaml_loader import _Loader, _PyLoader

    if not yaml.__with_libyaml__:
        pytest.skip("PyYAML was built without libyaml here: both loaders are Python's")
    assert _Loader is not _PyLoader
    for path in sorted(bank_dir().glob("*.yaml")):
        text = path.read_text(encoding="utf-8")
        assert yaml.load(text, Loader=_Loader) == yaml.load(text, Loader=_PyLoader), path
