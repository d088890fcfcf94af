"""Grading stays inside its bounds on any accepted input (issue 22): work linear in the key's size, the
output folder checked before any grading, memory within the bound docs/grading.md states, however many
rows a submissions file holds. Each case is named after what broke."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from grader.cli import main
from grader.grade.key import Key, KeyStudent, load_key


class _CountedName(tuple[str, str]):
    """A parameter's (problem key, name) that counts how often it is compared with another."""

    compared = 0

    def __eq__(self, other: object) -> bool:
        _CountedName.compared += 1
        return tuple.__eq__(self, other)  # type: ignore[operator, no-any-return]

    __hash__ = tuple.__hash__


def test_a_keys_parameter_columns_take_work_linear_in_its_names_not_one_search_per_name() -> None:
    """``Key.parameter_columns`` searched the list of names for each name (``names.index``): quadratic,
    20,000 names took 7 s and 50,000 over 30 s. Counted instead of timed: 2,000 names were compared
    about 2 million times; now a few times each at most."""
    names = tuple(_CountedName(("1", f"p{index}")) for index in range(2000))
    student = KeyStudent("1", "", "", "", {}, names, tuple(map(float, range(2000))))
    _CountedName.compared = 0
    columns = Key("key.json", 2, "HW", True, (), (student,)).parameter_columns
    assert _CountedName.compared < 10 * len(names)
    assert [columns[name][0] for name in names] == list(range(2000))


def test_a_key_with_20000_parameter_names_loads_and_reads_its_columns(tmp_path: Path) -> None:
    """The key of the report: one student, 20,000 printed parameters (7 s before, now milliseconds)."""
    params = {f"p{index}": float(index) for index in range(20_000)}
    answer = {"value": 1.0, "unit": "", "label": "1a", "points": 1, "tolerance": {"rtol": 0.01, "atol": 0}}
    path = tmp_path / "key.json"
    path.write_text(json.dumps({
        "schema": "grader-key", "version": 2, "assignment": {"title": "HW"},
        "problems": [{"key": "1", "title": "P", "answers": [{"name": "x", "label": "1a", "unit": "", "points": 1}]}],
        "students": [{"id": "1", "name": "", "email": "", "section": "",
                      "problems": [{"key": "1", "answers": {"x": answer}, "params": params}]}]}))
    columns = load_key(path).parameter_columns
    assert len(columns) == 20_000 and columns["1", "p19999"][0] == 19_999.0


def test_an_out_folder_that_will_be_refused_is_refused_before_anything_is_read_or_graded(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    """``--out`` was checked only when the reports were written, after the whole grading run: a folder of
    someone else's files was refused after a minute of grading a big file. Now nothing is read first."""
    import grader.grade.run

    def must_not_run(*_: object, **__: object) -> None:
        raise AssertionError("read or graded before --out was checked")

    for name in ("load_key", "read_submissions", "grade", "read_export"):
        monkeypatch.setattr(grader.grade.run, name, must_not_run)
    out = tmp_path / "theirs"
    out.mkdir()
    (out / "thesis.tex").write_text("not grader's")
    submissions = tmp_path / "big.csv"
    submissions.write_text("student_id,label,answer\n" + "x,1a,1\n" * 100_000)
    code = main(["grade", "--key", str(tmp_path / "key.json"), str(submissions), "--out", str(out)])
    assert code == 2 and "theirs" in capsys.readouterr().err
    assert [p.name for p in out.iterdir()] == ["thesis.tex"]
