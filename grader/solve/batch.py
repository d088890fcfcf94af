"""Parameter values as users give them (``--set NAME=VALUE``, a CSV of parameter sets) and answers
as JSON lines.

A batch is read a column at a time: one pattern checks that every cell of a column is a plain
number (as nearly all are) and they are converted together; only a cell with a unit, or one that
is not a finite number, is read on its own by :func:`read_value`, whose message names its line and
column. Answers are written with one format per line and the numbers' text made a column at a time;
a refused row, or one with an undefined answer, is written by ``json.dumps`` from :func:`record`,
the one place the JSON object is laid out.

>>> from grader.bank.template import load_bank
>>> template = load_bank()["drop-rebound"]
>>> read_value("2.1 m", template.parameters["h_drop"], "--set h_drop")
2100.0
>>> read_value("2.1 kg", template.parameters["h_drop"], "--set h_drop")
Traceback (most recent call last):
...
grader.base.errors.GraderError: --set h_drop: 'kg' cannot be converted to mm
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from grader.bank.template import Parameter, Template
from grader.base.errors import GraderError, UsageError, shown, some
from grader.base.inputs import CsvColumns, read_csv_columns
from grader.model.quantities import MAX_TEXT, NUMBER, parse_unit, split_quantity
from grader.solve.compiled import Compiled
from grader.solve.evaluate import AnswerValue, Columns, answer_at

LINES_AT_ONCE = 1 << 14  # rows whose JSON lines are made together (bounds the memory for their text)


def read_value(text: str, parameter: Parameter, where: str) -> float:
    """A number in the parameter's unit, or with another unit of the same kind (``2.1 m``)."""
    quantity = split_quantity(text)
    expected = f"a finite number in {parameter.unit.text}" if parameter.unit.text else "a finite number"
    if quantity is None:
        raise GraderError(f"{where}: expected {expected}, got {shown(text.strip(), 40)}")
    number, unit_text = quantity
    if not unit_text:
        return number + 0.0  # -0 is 0
    try:
        unit = parse_unit(unit_text)
    except GraderError as error:
        raise GraderError(f"{where}: expected {expected}, got {shown(text.strip(), 40)} ({error})") from None
    if not unit.same_dimension(parameter.unit):
        raise GraderError(f"{where}: '{unit_text}' cannot be converted to {parameter.unit.text or 'a pure number'}")
    converted = number * unit.to_si / parameter.unit.to_si
    if not math.isfinite(converted):
        raise GraderError(f"{where}: expected {expected}, got {shown(text.strip(), 40)}")
    return converted + 0.0


def check_names(given: Sequence[str], template: Template, where: str) -> None:
    """Every parameter of the template given, and nothing else."""
    unknown = [n for n in given if n not in template.parameters]
    missing = [n for n in template.parameters if n not in given]
    problems = []
    if unknown:
        problems.append(f"unknown parameter(s) {some(unknown)}")
    if missing:
        problems.append(f"missing parameter(s) {some(missing)}")
    if problems:
        raise UsageError(f"{where}: {'; '.join(problems)} (template '{template.id}' takes "
                         f"{', '.join(template.parameters)})")


def read_assignments(assignments: Sequence[str], template: Template) -> dict[str, float]:
    """``--set NAME=VALUE`` options: one value for each parameter."""
    params: dict[str, float] = {}
    for text in assignments:
        name, sep, value = text.partition("=")
        name = name.strip()
        if not sep or not name:
            raise UsageError(f"--set {text}: expected NAME=VALUE, like h_drop=2.1")
        if name in params:
            raise UsageError(f"--set {text}: {name} is given twice")
        if name in template.parameters:
            params[name] = read_value(value, template.parameters[name], f"--set {name}")
        else:
            params[name] = float("nan")
    check_names(list(params), template, "--set")
    return params


@dataclass(frozen=True)
class Batch:
    """A CSV of parameter sets: a float64 column per parameter (NaN where a cell is unusable), the
    reason each row cannot be answered (None where it can), and the cells as written."""

    columns: Mapping[str, np.ndarray]
    errors: list[str | None]
    table: CsvColumns

    def cells(self, row: int) -> dict[str, str]:
        """A row's cells as written, by header name (what a row with an unusable cell shows)."""
        return {name: column[row] for name, column in self.table.columns.items()}


def read_batch(path: Path, template: Template) -> Batch:
    """A batch CSV whose header names the template's parameters; a row with a cell that is not a
    value of its parameter (or with more cells than the header) carries the reason."""
    table = read_csv_columns(path)
    check_names(table.header, template, str(path))
    if not table.lines:
        raise UsageError(f"{path}: no data rows; expected the header line, then one row of values per line")
    errors = list(table.problems)
    columns = {}
    for name, parameter in template.parameters.items():
        column, problems = _read_column(table.columns[name], parameter,
                                        lambda row, n=name: f"line {table.lines[row]}, {n}")
        for row, problem in problems.items():
            errors[row] = errors[row] or problem
        columns[name] = column
    return Batch(columns, errors, table)


def _read_column(cells: list[str], parameter: Parameter, where: Any) -> tuple[np.ndarray, dict[int, str]]:
    """A parameter's cells as float64 (NaN where a cell is unusable), and the reason by row."""
    if all(map(NUMBER.fullmatch, cells)) and max(map(len, cells)) <= MAX_TEXT:  # numbers only, as usual
        column = np.array(list(map(float, cells)))
    else:
        column = np.array([float(cell) if len(cell) <= MAX_TEXT and NUMBER.fullmatch(cell) else math.nan
                           for cell in cells])
    problems: dict[int, str] = {}
    for row in np.flatnonzero(~np.isfinite(column)).tolist():  # a unit, a mistake, or beyond float64
        try:
            column[row] = read_value(cells[row], parameter, where(row))
        except GraderError as problem:
            column[row] = math.nan
            problems[row] = str(problem)
    return column + 0.0, problems  # -0 is 0


def record(template: Template, params: Mapping[str, Any], answers: Mapping[str, AnswerValue] | None,
           error: str | None, row: int | None = None) -> dict[str, Any]:
    """The JSON object of one parameter set: ``{"template", "row" (in a batch), "params", "answers"}``,
    or ``"error"`` instead of ``"answers"`` where it was refused."""
    data: dict[str, Any] = {"template": template.id} if row is None else {"template": template.id, "row": row}
    data["params"] = dict(params)
    if error is None and answers is not None:
        data["answers"] = {name: value.to_json() for name, value in answers.items()}
    else:
        data["error"] = error
    return data


def json_lines(template: Template, compiled: Compiled, batch: Batch, result: Columns) -> Iterator[str]:
    """The batch's answers as JSON lines, in row order, a block of lines (each ending in a newline)
    at a time: the text of ``json.dumps(record(...))`` for each row."""
    line = _line_format(template, compiled)
    for start in range(0, len(result.refusals), LINES_AT_ONCE):
        rows = slice(start, start + LINES_AT_ONCE)
        numbers = [*result.params.values(), *result.values.values()]
        plain = _plain_rows(batch, result, rows, numbers)
        fields = [list(map(str, range(start + 1, start + 1 + len(plain))))]
        fields += [_texts(column[rows]) for column in result.params.values()]
        for name, answer in compiled.answers.items():
            fields.append(_texts(result.values[name][rows]) if answer.numeric is not None else
                          [json.dumps(answer_at(template, compiled, result, name, start + index)[0]) if ok else ""
                           for index, ok in enumerate(plain.tolist())])
        lines = list(map(line.__mod__, zip(*fields, strict=True)))
        for index in np.flatnonzero(~plain).tolist():
            lines[index] = _one_line(template, compiled, batch, result, start + index)
        yield "\n".join(lines) + "\n"


def _texts(column: np.ndarray) -> list[str]:
    """Each number's JSON text (``float.__repr__``, as ``json.dumps`` writes it; -0 as 0), made once per
    distinct number where a column repeats its numbers (values typed in a CSV mostly do)."""
    numbers = (column + 0.0).tolist()
    distinct = set(numbers)
    if 4 * len(distinct) > len(numbers) or not np.isfinite(column).all():  # NaN is no key: it is not equal to itself
        return list(map(float.__repr__, numbers))
    return list(map({number: repr(number) for number in distinct}.__getitem__, numbers))


def _plain_rows(batch: Batch, result: Columns, rows: slice, numbers: list[np.ndarray]) -> np.ndarray:
    """Which rows are answered with every answer defined (and, as the checks make sure, finite):
    their lines follow one format."""
    reasons = [batch.errors[rows], result.refusals[rows], *(missing[rows] for missing in result.undefined.values())]
    plain = np.fromiter((row.count(None) == len(reasons) for row in zip(*reasons, strict=True)), dtype=bool)
    for column in numbers:
        plain &= np.isfinite(column[rows])
    return plain


def _line_format(template: Template, compiled: Compiled) -> str:
    """The ``%``-format of an answered row's line: its row number, parameters' and answers' values."""
    def literal(value: str) -> str:
        return json.dumps(value).replace("%", "%%")
    params = ", ".join(f"{literal(name)}: %s" for name in template.parameters)
    answers = ", ".join(f'{literal(name)}: {{"value": %s, "unit": {literal(answer.unit)}}}'
                        for name, answer in compiled.answers.items())
    return f'{{"template": {literal(template.id)}, "row": %s, "params": {{{params}}}, "answers": {{{answers}}}}}'


def _one_line(template: Template, compiled: Compiled, batch: Batch, result: Columns, row: int) -> str:
    """A refused row, or one with an undefined answer (or, were it a bug, a number that is not finite)."""
    error = batch.errors[row] or result.refusals[row]
    if batch.errors[row] is not None:
        params: Mapping[str, Any] = batch.cells(row)
    else:
        params = {name: float(column[row]) for name, column in result.params.items()}
    answers = None
    if error is None:
        answers = {name: AnswerValue(name, answer.unit, *answer_at(template, compiled, result, name, row))
                   for name, answer in compiled.answers.items()}
    return json.dumps(record(template, params, answers, error, row + 1), allow_nan=False)
