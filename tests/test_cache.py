"""grader.solve.cache: compiled templates, their alternatives and routes kept on disk. An entry is used only for
the template it was made from; one that cannot be read as such is compiled again, never a crash or another
answer."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from grader.bank.template import Template, load_bank
from grader.base import caching
from grader.solve import cache as solve_cache
from grader.solve.evaluate import solve_one


@pytest.fixture
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """An empty cache folder of this test's own, and no shipped entries: every template is compiled into it."""
    folder = tmp_path / "cache"
    monkeypatch.setenv("GRADER_CACHE_DIR", str(folder))
    monkeypatch.setattr(solve_cache, "SHIPPED", tmp_path / "none shipped")
    return folder


DROP = {"h_drop": 2100.0, "h_rebound": 1100.0}


def _entry(cache: Path, template_id: str, kind: str = "") -> Path:
    (path,) = [path for path in cache.glob(f"{template_id}-*{kind}.json")
               if kind or not path.name.endswith(("-alternatives.json", "-routes.json"))]
    return path


def _answers(template: Template) -> dict[str, float]:
    solution = solve_one(template, solve_cache.compiled_for(template), DROP)
    assert solution.answers is not None, solution.error
    return {name: answer.value for name, answer in solution.answers.items()}


def _numeric(tree: Any) -> Callable[[Any], Any]:
    def change(entry: Any) -> Any:
        entry["answers"]["e"]["numeric"] = tree
        return entry
    return change


def _deep(entry: Any) -> str:
    """The entry as JSON text, the answer's tree nested 5,000 deep (deeper than json.dumps writes)."""
    import json

    entry["answers"]["e"]["numeric"] = "DEEP"
    return json.dumps(entry).replace('"DEEP"', '["neg", ' * 5000 + '"h_drop"' + "]" * 5000)


def _write(entry: Path, data: Any) -> None:
    """Keep ``data`` (or JSON text) at ``entry`` as grader keeps entries."""
    if isinstance(data, str):
        entry.write_bytes(caching.seal(entry.name, data.encode()))
    else:
        caching.write_entry(entry, data)


BROKEN = {
    "an unknown operation": _numeric(["__import__", "h_drop"]), "too few arguments": _numeric(["div", "h_drop"]),
    "a zero denominator": _numeric({"q": [1, 0]}), "a number as text": _numeric({"f": "1e5"}),
    "a NaN": _numeric({"f": float("nan")}), "a boolean": _numeric({"q": [True, 1]}), "an empty tree": _numeric([]),
    "nested 5,000 deep": _deep, "answers as a list": lambda entry: {**entry, "answers": []},
    "another format": lambda entry: {**entry, "format": 99}, "no steps": lambda entry: {**entry, "steps": None},
}


@pytest.mark.parametrize("damage", BROKEN.values(), ids=BROKEN.keys())
def test_an_entry_that_is_no_compiled_template_is_compiled_again(cache: Path, damage: Callable[[Any], Any]) -> None:
    """Sealed as grader seals entries: an unknown operation stopped `grader solve` with a KeyError when the kernel
    was built, a zero denominator with a ZeroDivisionError, answers as a list with an AttributeError, a NaN with
    an exit 2 naming no file; a number as text was taken as the answer."""
    template = load_bank()["drop-rebound"]
    right = _answers(template)
    entry = _entry(cache, "drop-rebound")
    good = caching.read_entry(entry)
    _write(entry, damage(caching.read_entry(entry)))
    assert _answers(template) == right
    assert caching.read_entry(entry) == good  # written again


def test_another_templates_entry_under_this_ones_name_is_compiled_again(cache: Path) -> None:
    """pile-driver's compiled form under drop-rebound's name: `grader solve drop-rebound` stopped with a KeyError
    (a parameter drop-rebound has not)."""
    bank = load_bank()
    right = _answers(bank["drop-rebound"])
    solve_cache.compiled_for(bank["pile-driver"])
    caching.write_entry(_entry(cache, "drop-rebound"), caching.read_entry(_entry(cache, "pile-driver")))
    assert _answers(bank["drop-rebound"]) == right


def test_another_version_of_the_template_under_its_name_is_compiled_again(cache: Path, tmp_path: Path) -> None:
    """The same id, other bytes (the loss asked for as a half): its compiled form is not this one's."""
    from grader.bank.template import load_template

    moon = tmp_path / "drop-rebound.yaml"
    shipped = load_bank()["drop-rebound"]
    moon.write_text(Path(shipped.where).read_text(encoding="utf-8").replace("value: f_loss", "value: f_loss/2"),
                    encoding="utf-8")
    right = _answers(shipped)
    ours = _entry(cache, "drop-rebound")
    solve_cache.compiled_for(load_template(moon))
    (theirs,) = set(cache.glob("drop-rebound-*.json")) - {ours}
    caching.write_entry(ours, caching.read_entry(theirs))
    assert _answers(shipped) == right


@pytest.mark.slow  # compiles two templates' chains again: about 3 s each
@pytest.mark.parametrize("kind", ["-alternatives", "-routes"])
def test_another_templates_alternatives_or_routes_are_compiled_again(cache: Path, kind: str) -> None:
    bank = load_bank()
    read = {"-alternatives": solve_cache.alternatives_for, "-routes": solve_cache.routes_for}[kind]
    right = read(bank["drop-rebound"])
    read(bank["pile-driver"])
    caching.write_entry(_entry(cache, "drop-rebound", kind), caching.read_entry(_entry(cache, "pile-driver", kind)))
    assert read(bank["drop-rebound"]) == right


@pytest.mark.parametrize("damage", [BROKEN["an unknown operation"], BROKEN["a NaN"], BROKEN["another format"]],
                         ids=["an unknown operation", "a NaN", "another format"])
def test_a_damaged_shipped_entry_is_compiled_again(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                  damage: Callable[[Any], Any]) -> None:
    """The package's own entries are read as the cache's are: one that is no compiled template is not used."""
    import shutil

    shipped = tmp_path / "shipped"
    shutil.copytree(solve_cache.SHIPPED, shipped)
    monkeypatch.setattr(solve_cache, "SHIPPED", shipped)
    monkeypatch.setenv("GRADER_CACHE_DIR", str(tmp_path / "cache"))
    template = load_bank()["drop-rebound"]
    right = _answers(template)
    entry = shipped / solve_cache.entry_name(template, "")
    _write(entry, damage(caching.read_entry(entry, shipped=True)))
    assert _answers(template) == right
    assert [path.name for path in (tmp_path / "cache").glob("drop-rebound-*.json")] == [entry.name]  # compiled
