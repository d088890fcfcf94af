"""`grader solve --batch`: cells read a column at a time and JSON lines made a block at a time give
the text that reading and writing one row at a time gives, messages and exit codes included."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from grader.bank.template import Template
from grader.base.errors import GraderError
from grader.base.inputs import read_csv, read_csv_columns
from grader.cli import main
from grader.solve.batch import read_value, record
from grader.solve.compiled import Compiled
from grader.solve.evaluate import solve_batch

# Rows of every kind: plain numbers, units, spaces, signs and exponents, unusable cells, values out of
# the domain or beyond float64, too many and too few cells, refused by a constraint or the physics,
# undefined answers (ball-plate head-on with e = 0), and symbolic answers (car-collision).
CASES = {
    "drop-rebound": "h_drop;h_rebound\n2100;1100\n1000;1200\n2,1\n-5;1\n2000;2000\n2.1 m; 110 cm\n1e400;1\n"
                    "+2.1e3;-0\n2100;1100;9\n2100\n 2100 ; 1100 \n2100;1100;\n2100;11 kg\n",
    "ball-plate": "v,theta,e\n50,90,0\n50,30,0.5\n40,45,0.9\n50,-30,0.5\n1e-150,30,0.5\n1e170,89.999,1\n50,deg,1\n",
    "car-collision": "p,e\n0.5,0.1\n1e-12,1\n3,0\n2,2\n0.5,1e-05\n",
    "pile-driver": "m_ram,m_pile,h_drop,h_rebound\n800,2400,2,0.1\n800,2.4Mg,200cm,0.1\n1,1e12,2,0.1\n800,2400,2,3\n",
    "oblique-spheres": "v1,theta,e,m1,m2\n10,30,0.5,1,2\n10,0,1,1,1e12\n10,90,0.5,1,1\n",
}


def row_by_row(template: Template, compiled: Compiled, path: Path) -> tuple[list[str], int]:
    """The JSON lines and exit code as the batch was first answered: each cell through read_value, each
    row a Solution, each line one json.dumps."""
    table = read_csv(path)
    columns: dict[str, list[float]] = {name: [] for name in template.parameters}
    errors: list[str | None] = []
    for row in table.rows:
        reason = row.problem
        for name, parameter in template.parameters.items():
            try:
                columns[name].append(read_value(row.cells[name], parameter, f"line {row.line}, {name}"))
            except GraderError as problem:
                columns[name].append(float("nan"))
                reason = reason or str(problem)
        errors.append(reason)
    lines, refused = [], False
    for index, solution in enumerate(solve_batch(template, compiled, columns)):
        error = errors[index] or solution.error
        refused |= error is not None
        params: Any = table.rows[index].cells if errors[index] else solution.params
        lines.append(json.dumps(record(template, params, solution.answers if error is None else None, error,
                                       index + 1), allow_nan=False))
    return lines, 3 if refused else 0


@pytest.mark.parametrize("template_id", sorted(CASES))
def test_batch_json_is_the_text_of_one_row_at_a_time(template_id: str, bank: dict[str, Template],
                                                     compiled: dict[str, Compiled], tmp_path: Path,
                                                     capsys: pytest.CaptureFixture[str]) -> None:
    """Byte for byte, with the exit code (3: some rows refused)."""
    path = tmp_path / "rows.csv"
    path.write_text(CASES[template_id], encoding="utf-8")
    expected, expected_code = row_by_row(bank[template_id], compiled[template_id], path)
    code = main(["solve", template_id, "--batch", str(path), "--json"])
    assert capsys.readouterr().out.splitlines() == expected
    assert code == expected_code


def test_a_batch_longer_than_one_block_keeps_its_order(bank: dict[str, Template], compiled: dict[str, Compiled],
                                                       tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Rows past the first block of lines, with refused rows among them, in order."""
    path = tmp_path / "rows.csv"
    rows = [f"{2000 + i % 500};{(i * 7) % 2600}" for i in range(40_000)]
    path.write_text("h_drop;h_rebound\n" + "\n".join(rows) + "\n", encoding="utf-8")
    expected, expected_code = row_by_row(bank["drop-rebound"], compiled["drop-rebound"], path)
    code = main(["solve", "drop-rebound", "--batch", str(path), "--json"])
    assert capsys.readouterr().out.splitlines() == expected
    assert code == expected_code == 3


def test_a_bad_cell_names_its_line_and_column(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Among plain numbers, the one cell that is not a value of its parameter is named."""
    path = tmp_path / "rows.csv"
    path.write_text("h_drop,h_rebound\n" + "2100,1100\n" * 5 + "2100,tall\n", encoding="utf-8")
    code = main(["solve", "drop-rebound", "--batch", str(path), "--json"])
    last = json.loads(capsys.readouterr().out.splitlines()[-1])
    assert code == 3
    assert last["error"] == "line 7, h_rebound: expected a finite number in mm, got 'tall'"
    assert last["params"] == {"h_drop": "2100", "h_rebound": "tall"}


@pytest.mark.parametrize("content", [
    "a,b\n1,2\n\n3\n4,5,6\n  ,  \n7,,\n", "a;b\n\"1;5\";2\n", "a,b\n" + "x" * 1001 + ",1\n1,\"unclosed\n",
    "a,b\n1,2\n1,\"unclosed\n", "a\n1\n2\n",
], ids=["ragged", "quoted", "long-cell-first", "unclosed-quote", "one-column"])
def test_csv_columns_hold_what_csv_rows_hold(tmp_path: Path, content: str) -> None:
    """read_csv_columns: the cells, lines and row problems of read_csv, or the same error."""
    path = tmp_path / "t.csv"
    path.write_text(content, encoding="utf-8")
    try:
        table = read_csv(path)
    except GraderError as error:
        with pytest.raises(type(error)) as raised:
            read_csv_columns(path)
        assert str(raised.value) == str(error)
        return
    columns = read_csv_columns(path)
    assert columns.header == table.header
    assert columns.lines == [row.line for row in table.rows]
    assert columns.problems == [row.problem for row in table.rows]
    assert columns.columns == {name: [row.cells[name] for row in table.rows] for name in table.header}
