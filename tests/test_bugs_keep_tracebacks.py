"""A bug in grader keeps its traceback: only what a user's input can cause becomes a user's error (a
``GraderError``, exit 2), a note, or a cache miss (docs/design.md, "Anything else is a bug"). Each test
injects a ``TypeError`` where the code used to catch every exception, and checks that it propagates, while
the input that was always refused is still refused with the same words."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any, NoReturn

import pytest
import sympy as sp

from grader.bank.template import load_bank
from grader.base.errors import GraderError, TemplateError, unworkable
from grader.grade import check, diagnosis, key
from grader.grade.diagnosis import physics_for
from grader.grade.key import load_key
from grader.solve import cache as solve_cache
from grader.solve import solver
from grader.solve.compiled import Compiled
from tests.test_diagnosis import BALL, student_key


def _bug(*args: Any, **kwargs: Any) -> NoReturn:
    raise TypeError("a bug in grader")


def _sympy_refuses(*args: Any, **kwargs: Any) -> NoReturn:
    sp.Symbol("x") < sp.I  # noqa: B015 (sympy raises TypeError: an invalid comparison of complex numbers)
    raise AssertionError("sympy compared a complex number")


def test_unworkable_tells_sympy_refusing_a_relation_from_a_bug() -> None:
    with pytest.raises(TypeError) as refused:
        _sympy_refuses()
    assert unworkable(refused.value) and not unworkable(TypeError("a bug in grader"))
    assert unworkable(ZeroDivisionError()) and unworkable(TemplateError("x.yaml", "k", "y"))


# --- the solver -------------------------------------------------------------------------------------

def test_a_bug_in_the_solver_is_not_blamed_on_the_template(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(solver._Compiler, "compile", _bug)
    with pytest.raises(TypeError, match="a bug in grader"):
        solver.compile_template(load_bank()["drop-rebound"])


def test_sympy_refusing_a_templates_relation_is_the_templates_error(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(solver._Compiler, "compile", _sympy_refuses)
    template = load_bank()["drop-rebound"]
    with pytest.raises(TemplateError) as refused:
        solver.compile_template(template)
    assert str(refused.value).startswith(f"{template.where}: stages or answers: expected expressions the solver "
                                         "can work with (real, finite, solvable one unknown at a time), got "
                                         "expressions the algebra cannot work with")


# --- the key ---------------------------------------------------------------------------------------

KEY = {"schema": "grader-key", "version": 1, "assignment": {"title": "HW"},
       "problems": [{"key": "1", "title": "Drop", "answers": [{"name": "e", "label": "1a", "unit": "", "points": 2}]}],
       "students": [{"id": "007", "name": "Ana", "email": "a@x", "section": "1", "problems": [
           {"key": "1", "answers": {"e": {"value": 0.7, "unit": "", "label": "1a", "points": 2,
                                          "tolerance": {"rtol": 0.01, "atol": 0}}}}]}]}


def _key_file(tmp_path: Path, document: Any) -> Path:
    path = tmp_path / "key.json"
    path.write_text(json.dumps(document), encoding="utf-8")
    return path


def test_a_bug_while_reading_a_key_is_not_a_bad_key(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    assert load_key(_key_file(tmp_path, KEY)).students[0].parts["1a"].value == 0.7
    monkeypatch.setattr(key, "_part", _bug)
    with pytest.raises(TypeError, match="a bug in grader"):
        load_key(_key_file(tmp_path, KEY))


@pytest.mark.parametrize(("damage", "said"), [
    (lambda d: d["students"][0]["problems"][0]["answers"]["e"].pop("value"), "answer e: no entry 'value'"),
    (lambda d: d.update(students=5), "students: expected a list, got 5"),
    (lambda d: d["students"].append("Bo"), "a student: expected an object, got 'Bo'"),
    (lambda d: d.pop("assignment"), "the key: no entry 'assignment'"),
    (lambda d: d["problems"][0]["answers"][0].update(symbols={"v": ["1", 2]}), "symbols.v: expected [LOW, HIGH]"),
    (lambda d: d["students"][0]["problems"][0]["answers"]["e"].update(tolerance=[0.01]),
     "answer e: tolerance: expected an object, got [0.01]"),
], ids=["no-value", "students-a-number", "student-a-text", "no-assignment", "range-of-text", "tolerance-a-list"])
def test_a_key_missing_an_entry_or_of_another_type_is_still_refused(tmp_path: Path, damage: Any, said: str) -> None:
    document = json.loads(json.dumps(KEY))
    damage(document)
    path = _key_file(tmp_path, document)
    with pytest.raises(GraderError) as refused:
        load_key(path)
    assert str(refused.value).startswith(f"{path}: ") and said in str(refused.value)
    assert str(refused.value).endswith("regenerate it with grader generate") or \
        str(refused.value).endswith("regenerate the key with grader generate")


# --- diagnosis ---------------------------------------------------------------------------------------

def test_a_bug_while_deriving_the_alternatives_stops_grading(monkeypatch: pytest.MonkeyPatch) -> None:
    template = load_bank()["drop-rebound"]
    the_key = student_key(template, BALL)
    monkeypatch.setattr(diagnosis, "alternatives_for", _bug)
    with pytest.raises(TypeError, match="a bug in grader"):
        physics_for(the_key, {template.id: template})


def test_a_template_sympy_cannot_work_with_is_a_note_and_grading_goes_on(monkeypatch: pytest.MonkeyPatch) -> None:
    template = load_bank()["drop-rebound"]
    the_key = student_key(template, BALL)
    monkeypatch.setattr(diagnosis, "alternatives_for", _sympy_refuses)
    physics = physics_for(the_key, {template.id: template})
    assert physics.problems == {} and "template drop-rebound could not be compiled (TypeError: " in physics.notes[0]


# --- a student's expression shown identical ---------------------------------------------------------------

def test_a_bug_while_showing_an_expression_identical_is_not_a_verdict(monkeypatch: pytest.MonkeyPatch) -> None:
    from grader.grade import identity
    from grader.model.expr import parse

    domains = (("v", (1.0, 10.0)),)
    assert identity.identical(parse("2*v"), parse("v + v"), domains)
    monkeypatch.setattr(identity, "_sympy", _sympy_refuses)
    assert not identity.identical(parse("2*v"), parse("v + v"), domains)  # sympy could not: not shown identical
    monkeypatch.setattr(identity, "_sympy", _bug)
    with pytest.raises(TypeError, match="a bug in grader"):
        identity.identical(parse("2*v"), parse("v + v"), domains)


# --- grader check --batch ---------------------------------------------------------------------------

def test_a_bug_while_checking_a_batch_line_is_not_an_error_line(monkeypatch: pytest.MonkeyPatch) -> None:
    lines = ["[" * 100_000 + "]" * 100_000, '{"submitted": "1", "expected": 1, "tolerance": {"rtol": "x"}}']
    assert [found["error"] for found in check.batch(lines, None)] == [
        "maximum recursion depth exceeded while decoding a JSON array from a unicode string",
        "tolerance.rtol: expected a number from 0 to 1e300, got 'x'"]
    monkeypatch.setattr(check, "expectation", _bug)
    with pytest.raises(TypeError, match="a bug in grader"):
        list(check.batch(lines[1:], None))


# --- the cache -----------------------------------------------------------------------------------------

def test_a_bug_reading_a_cache_entry_is_not_a_silent_recompile(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """An entry of the right shape that the reader fails on: a regression, not a damaged entry."""
    monkeypatch.setenv("GRADER_CACHE_DIR", str(tmp_path / "cache"))
    template = load_bank()["drop-rebound"]
    solve_cache.compiled_for(template)  # read from the shipped entries
    monkeypatch.setattr(Compiled, "from_json", _bug)
    with pytest.raises(TypeError, match="a bug in grader"):
        solve_cache.compiled_for(template)
