"""``grader effects``: the catalogue of effects with their faces side by side, and docs/effects.md, which is
generated from the same data and must not drift from it."""

from __future__ import annotations

import ast
import importlib
import json
import re
from pathlib import Path
from typing import Any

import pytest

from grader.cli import main
from grader.model.quantities import words as dimension_words
from grader.physics.effects import CATALOGUE
from grader.render.figures import STAGE_FIGURES
from grader.render.reference import EXAMPLES, GENERATED_BY

PAGE = Path(__file__).resolve().parent.parent / "docs" / "effects.md"
SHEET_KEYS = {"name", "summary", "fields", "examples", "force_law", "simulated", "mistakes", "routes", "figure"}
FIELD_KEYS = {"name", "meaning", "kind", "dimension", "required", "default"}


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def strict_json(text: str) -> Any:
    """JSON as a strict reader takes it: NaN and Infinity are refused."""
    def refuse(constant: str) -> None:
        raise ValueError(f"not strict JSON: {constant}")

    return json.loads(text, parse_constant=refuse)


def declared_mistake_ids(module: str) -> set[str]:
    """The mistake ids an effect module's source writes (``"impact.e_squared"``), read from its text, not
    from the code under test."""
    path = importlib.import_module(module).__file__
    assert path is not None
    tree = ast.parse(Path(path).read_text(encoding="utf-8"))
    return {node.value for node in ast.walk(tree) if isinstance(node, ast.Constant) and isinstance(node.value, str)
            and re.fullmatch(r"[a-z]+\.[a-z_]+", node.value)}


def test_docs_effects_md_is_current(capsys: pytest.CaptureFixture[str]) -> None:
    """docs/effects.md is what `grader effects --markdown` prints today, and says so on its first line."""
    code, out, err = run(capsys, "effects", "--markdown")
    assert code == 0, err
    written = PAGE.read_text(encoding="utf-8") if PAGE.exists() else ""
    assert out == written, f"docs/effects.md is stale: run {GENERATED_BY}"
    assert written.startswith("<!--") and GENERATED_BY in written.splitlines()[0]


def test_the_page_links_only_to_its_own_headings() -> None:
    """MkDocs --strict: every link is to an effect's heading on the page, none to a file."""
    text = PAGE.read_text(encoding="utf-8")
    headings = set(re.findall(r"^## (\S+)$", text, re.MULTILINE))
    links = re.findall(r"\]\(([^)]*)\)", text)
    assert headings == set(CATALOGUE)
    assert links and all(link.startswith("#") and link[1:] in headings for link in links), links


@pytest.mark.parametrize("name", sorted(CATALOGUE))
def test_every_effect_is_listed_with_its_summary(name: str, capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "effects")
    line = next(line for line in out.splitlines() if line.split()[:1] == [name])
    assert CATALOGUE[name].summary in line
    assert code == 0


@pytest.mark.parametrize("name", sorted(CATALOGUE))
def test_every_field_appears_with_its_dimension(name: str, capsys: pytest.CaptureFixture[str]) -> None:
    """`grader effects NAME` shows each field, and with its dimension in words where it has one; --json too."""
    _, out, _ = run(capsys, "effects", name)
    _, as_json, _ = run(capsys, "effects", name, "--json")
    fields = {row["name"]: row for row in strict_json(as_json)["fields"]}
    for spec in CATALOGUE[name].fields:
        line = next((line for line in out.splitlines() if line.split()[:1] == [spec.name]), "")
        assert line, f"{name}: field {spec.name} not shown"
        if spec.dimension is not None:
            words = dimension_words(spec.dimension)
            assert words in " ".join(out.split()), f"{name}: {spec.name} without {words}"
            assert fields[spec.name]["dimension"] == words
        assert fields[spec.name]["required"] is spec.required


@pytest.mark.parametrize("argv, expected", [
    (["effects", "--json"], list),
    (["effects", "impact", "--json"], dict),
], ids=["every effect", "one effect"])
def test_json_is_strict_and_has_the_keys(argv: list[str], expected: type, capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(capsys, *argv)
    assert code == 0, err
    found = strict_json(out)
    assert isinstance(found, expected)
    sheets = found if isinstance(found, list) else [found]
    assert [s["name"] for s in sheets] == (sorted(CATALOGUE) if expected is list else ["impact"])
    for sheet in sheets:
        assert set(sheet) == SHEET_KEYS
        assert all(set(row) == FIELD_KEYS for row in sheet["fields"])
        assert sheet["examples"] and all(example["relations"] for example in sheet["examples"])


@pytest.mark.parametrize("name, suggestion", [("impct", "did you mean impact"), ("collision", None),
                                              ("Swing", "did you mean swing")])
def test_an_unknown_effect_exits_2_naming_the_choices(name: str, suggestion: str | None,
                                                       capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(capsys, "effects", name)
    assert code == 2 and out == ""
    assert f"unknown effect '{name}'" in err
    assert all(effect in err for effect in CATALOGUE)
    assert suggestion is None or suggestion in err


def test_impact_shows_the_restitution_relation_and_its_mistakes(capsys: pytest.CaptureFixture[str]) -> None:
    """The textbook's definition, e = separation/approach along n, and every mistake id impact.py declares."""
    _, out, _ = run(capsys, "effects", "impact")
    assert "coefficient of restitution: separation over approach along n" in out
    assert "e = (v_B - v_A)/(u_A - u_B)" in out
    assert "m_A*u_A + m_B*u_B = (m_A + m_B)*v" in out  # conservation of momentum, moving on together
    ids = declared_mistake_ids("grader.physics.effects.impact")
    assert {"impact.e_squared", "impact.rebound_sign"} <= ids
    assert all(id_ in out for id_ in ids)


@pytest.mark.parametrize("module", sorted({effect.relations.__module__ for effect in CATALOGUE.values()}))
def test_every_mistake_a_module_declares_is_shown(module: str, capsys: pytest.CaptureFixture[str]) -> None:
    """The examples reach every mistake, those of a scene in feet, a height in mm, a fixed surface, an
    oblique impact and a flight to the ground included."""
    shown = ""
    for name, effect in CATALOGUE.items():
        if effect.relations.__module__ == module:
            shown += run(capsys, "effects", name)[1]
    missing = sorted(id_ for id_ in declared_mistake_ids(module) if id_ not in shown)
    assert not missing, f"{module}: mistakes no example of the reference reaches: {missing}"


@pytest.mark.parametrize("name", sorted(CATALOGUE))
def test_every_effect_has_examples_a_force_law_and_a_figure(name: str) -> None:
    """A new effect is refused here until the reference can show it whole."""
    assert EXAMPLES.get(name), f"add representative stages of {name} to grader.render.reference.EXAMPLES"
    assert STAGE_FIGURES.get(name), f"say how a {name} stage is drawn in grader.render.figures.STAGE_FIGURES"
    assert CATALOGUE[name].force_law.strip()


def test_swing_shows_its_stable_form_and_force_law(capsys: pytest.CaptureFixture[str]) -> None:
    """The half-angle form the kernels use, and the pendulum the simulation integrates."""
    _, out, _ = run(capsys, "effects", "swing")
    assert "v = sqrt(2*g*L*(1 - cos(theta)))" in out
    assert "v = 2*sqrt(g*L)*sin(theta/2)" in out
    assert "Force law in simulation: a pendulum" in out
