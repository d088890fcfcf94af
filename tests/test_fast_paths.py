"""The column-at-a-time paths of grading and its reports give the bytes the cell-at-a-time rules give.

Each fast path is held against the rule it stands for, written here a cell at a time with the public pieces
(``safe_cell``, ``visible``, ``number_cell``, ``number_text``, the CSV writer, ``read_number``, ``is_correct``,
``errors``, :meth:`_Words.sentence`), on crafted inputs: every verdict kind, units, blanks, late work, and
hostile text (formula starters, their full-width forms, control characters, bidi marks, quotes, commas, line
breaks).
"""

from __future__ import annotations

import math
import random
from collections.abc import Sequence

import numpy as np
import pytest

from grader.base.errors import visible
from grader.base.spreadsheet import (
    csv_columns_text,
    csv_text,
    number_cell,
    number_cells,
    quoted_cell,
    safe_cell,
    safe_cells,
)
from grader.grade.canvas_file import CanvasFile
from grader.grade.cells import (
    _DECIMAL,
    _DEGREES_MINUTES,
    CellNumber,
    _clean,
    _read_number,
    _refuse_formula,
    _split_unit,
    _usual_split,
    _without_prefix,
    read_number,
)
from grader.grade.compare import (
    _difference,
    _period,
    _Words,
    errors,
    feedback,
    is_correct,
    number_text,
    number_texts,
)
from grader.grade.details_file import (
    DETAILS_HEADER,
    details_csv,
    report_cell,
    report_columns,
    report_pieces,
)
from grader.grade.grading import Graded, LateWork, Row, _grade_column
from grader.grade.integrity import Integrity, Match, Pair
from grader.grade.key import Key, KeyPart, KeyProblem, KeyStudent
from grader.grade.latest import Answer
from grader.grade.report import INTEGRITY_HEADER, canvas_csv, integrity_csv
from grader.model.tolerance import Tolerance

HOSTILE = ["=1+1", "+1", "-1+1", "@SUM(A1)", "\uff1dHYPERLINK(1)", "\ufe62x", "'quoted", "\tx", "\rx", "\nx",
           "a\x1b[31mred", "v\u202e2", "\u2066iso", 'say "hi"', "6,26", "two\nlines", "cr\rhere", "-0.369",
           "-1.5e-07", "", " ", "é ü", "\x00nul", "a,\"b\",\nc", "\xa0nbsp", "-", "=", "'", "=SUM(A1,B1)",
           "-6,26", "'say \"hi\"", "@a,\"b\""]


def error_rule(value: float | None) -> str:
    return "" if value is None else number_text(value)


def details_rule(graded: Graded) -> str:
    """details.csv a row at a time, each cell by its rule, through the CSV writer."""
    late = graded.late
    rows: list[Sequence[object]] = [DETAILS_HEADER]
    for index, student in enumerate(graded.key.students):
        for label in graded.key.labels:
            row = graded.columns[label][index]
            minutes = late.minutes[label][index] if late else None
            share = late.shares[label][index] if late else None
            rows.append((safe_cell(student.id), safe_cell(label),
                         "" if row.submitted is None else safe_cell(visible(row.submitted)), report_cell(row.verdict),
                         report_cell(row.credit), report_cell(row.points), report_cell(row.credit * row.points),
                         safe_cell(row.expected), safe_cell(visible(row.parsed)), report_cell(row.unit),
                         error_rule(row.abs_error), error_rule(row.rel_error), report_cell(row.tolerance),
                         safe_cell(visible(row.feedback)), report_cell(row.diagnosis), safe_cell(visible(row.source)),
                         report_cell(minutes), report_cell(share or 0.0)))
    return csv_text(rows)


KINDS = [("correct", 1.0), ("ecf", 0.5), ("mistake", 0.25), ("incorrect", 0.0), ("invalid", 0.0), ("missing", 0.0)]


def crafted_class(students: int, late: bool, seed: int = 7) -> Graded:
    """A class whose rows take every verdict kind and hostile text in every text field."""
    rng = random.Random(seed)
    labels = ("1a", "=1b", "1,c")
    tolerance = {"mode": "rtol", "rtol": 0.01, "atol": 0.0}
    people = [KeyStudent(rng.choice([f"s{index}", f"=s{index}", f"-{index}", f"s\n{index}"]), "", "", "1",
                         {label: KeyPart("1", f"x{label}", label, 1.5, "m/s", 2.0, tolerance, None, {})
                          for label in labels}) for index in range(students)]
    key = Key("key.json", 2, "HW", True, (KeyProblem("1", "Drop", labels),), tuple(people))

    def row() -> Row:
        kind, credit = rng.choice(KINDS)
        number = rng.choice([None, 0.0, -0.0, 1.5, -2.25e-7, 123456789.0, 1e300, 3.0000000000000004])
        return Row(None if kind == "missing" else rng.choice([*HOSTILE, "1.5", "-1.5 m/s"]), kind, credit,
                   rng.choice([1.0, 2.0, 0.5]), rng.choice(["1.5", "-1.5", "=x", "undefined (no value)"]),
                   rng.choice(["", "1.5", "-1.5", *HOSTILE]), rng.choice(["m/s", "", "=u", "°"]), number,
                   None if number is None else abs(number) / 3, rng.choice(["±1 %", "±1 %, widened", "=t"]),
                   rng.choice([*HOSTILE, "1.5 m/s is 0.1 % below 1.5015 m/s; within ±1 % is accepted"]),
                   rng.choice(["", "ecf:1a", "impact.e_squared", "=d"]), rng.choice(["a.csv:2", "=a.csv:3", "b\x1b:4"]))

    columns = {label: [row() for _ in people] for label in labels}
    work = None
    if late:
        work = LateWork({label: [rng.choice([None, 0, 5, 1440]) for _ in people] for label in labels},
                        {label: [rng.choice([0.0, 0.25, 1.0 / 3]) for _ in people] for label in labels}, {})
    return Graded(key, columns, (), (), (), late=work)


@pytest.mark.parametrize(("students", "late", "piece"),
                         [(40, False, 2000), (40, True, 7), (13, True, 1), (0, False, 3)])
def test_details_csv_is_the_cell_at_a_time_rule(students: int, late: bool, piece: int) -> None:
    graded = crafted_class(students, late)
    assert "".join(details_csv(graded, piece)) == details_rule(graded)


def integrity_rule(graded: Graded, integrity: Integrity) -> str:
    """integrity.csv a row at a time, each cell a report's cell, through the CSV writer."""
    students, flagged = graded.key.students, set(integrity.flagged)
    rows: list[Sequence[object]] = [INTEGRITY_HEADER]
    for match in integrity.matches:
        row, pair = graded.columns[match.label][match.student], integrity.pair(match.student, match.partner)
        figures: list[object] = [None] * 8 if pair is None else [
            len(pair.labels), " ".join(pair.labels), pair.wrong, pair.closest,
            number_cell(pair.closeness, 3) if math.isfinite(pair.closeness) else None, number_cell(pair.chance, 3),
            number_cell(pair.corrected, 3), "yes" if pair in flagged else "no"]
        rows.append([students[match.student].id, match.label, row.submitted, row.parsed,
                     students[match.partner].id, number_text(match.value), match.matches, *figures])
    return csv_text([[report_cell(value) for value in row] for row in rows])


@pytest.mark.parametrize(("students", "piece"), [(40, 10_000), (40, 7), (13, 1), (0, 3)])
def test_integrity_csv_is_the_cell_at_a_time_rule(students: int, piece: int) -> None:
    """Hostile ids, labels and answers; pairs flagged and not, unread closeness, and matches whose pair is not
    listed; figures repeated and not."""
    graded, rng = crafted_class(students, late=False), random.Random(5)
    labels = graded.key.labels
    pairs = {}
    for _ in range(students * 2):
        student, partner = rng.randrange(students), rng.randrange(students)
        pairs[student, partner] = Pair(student, partner, tuple(rng.sample(labels, rng.randint(1, len(labels)))),
                                       rng.randint(1, 3), rng.choice([1e-9, 0.0123456, 0.5, 1.0, -0.0]),
                                       rng.choice([2.5e-7, 0.049999, 1.0, 0.0]), rng.randint(0, 3),
                                       rng.choice([math.inf, 0.0, 1.5, 12345.678, 999.6]))
    unlisted = [(rng.randrange(students), rng.randrange(students)) for _ in range(students // 4)]
    matches = tuple(Match(student, rng.choice(labels), partner, rng.choice([1.5, -0.0, -2.25e-7, 1e300, 0.1 + 0.2]),
                          rng.randint(1, 9)) for student, partner in [*pairs, *unlisted])
    for match in matches:  # a match is a wrong answer's, as the check lists them (what was read is kept of those)
        column = graded.columns[match.label]
        column[match.student] = column[match.student]._replace(verdict="incorrect", credit=0.0)  # type: ignore[index]
    integrity = Integrity.of(matches, tuple(pairs.values()), 100, 0.05, 10, 5)
    assert (integrity.flagged and len(integrity.flagged) < len(pairs)) or not students
    assert "".join(integrity_csv(graded, integrity, piece)) == integrity_rule(graded, integrity)


@pytest.mark.parametrize("figures", [1, 3, 6, 12, 15, 17])
def test_number_cells_are_number_cell_of_each(figures: int) -> None:
    """Every magnitude float64 has, signs, zeros, subnormals, whole numbers, and values that round up to a
    power of ten (999.5 to 3 figures is 1000)."""
    rng = random.Random(figures)
    values = [rng.uniform(-10, 10) * 10.0 ** rng.randint(-320, 300) for _ in range(3000)]
    values += [0.0, -0.0, 5e-324, -5e-324, 2.2250738585072014e-308, 2.225073858507201e-308, 1e-299,
               1.0, 2.0**53, 1e15, 1e16, 999.5, 9.9995, 0.099995, 1e-4, 9.9996e-5,
               123456.0, 0.1 + 0.2, 1.7976931348623157e308, *(float(n) for n in range(-20, 1200, 7))]
    assert number_cells(values, figures) == [number_cell(value, figures) for value in values]


def test_number_texts_are_number_text_of_each() -> None:
    rng = random.Random(2)
    values = [rng.uniform(-10, 10) * 10.0 ** rng.randint(-320, 300) for _ in range(3000)] + [0.0, -0.0, 5e-324]
    assert number_texts(values) == [number_text(value) for value in values]


@pytest.mark.parametrize(("students", "piece", "width"), [(60, 10_000, 5), (60, 7, 5), (5, 1, 1), (0, 3, 5), (9, 4, 0)])
def test_canvas_csv_is_the_cell_at_a_time_rule(students: int, piece: int, width: int) -> None:
    """Hostile names and ids written exactly (no guard), scores of every type, an export's kept text."""
    rng = random.Random(students + width)
    identities = [tuple(rng.choice([*HOSTILE, "Ana", "2026001"]) for _ in range(width)) for _ in range(students)]
    cells = [rng.choice([None, 0.0, -0.0, 17.5, 1e16, 0.1 + 0.2, "EX", "N/A", "=1", "a,b"]) for _ in range(students)]
    made = CanvasFile(tuple(f"c{index}" for index in range(width)), "@Home, Lab", 12.0, identities, cells, (), ())
    exact = [[*made.columns, made.title], ["Points Possible", *[""] * (width - 1), made.points],
             *([*identity, cell] for identity, cell in zip(identities, cells, strict=True))]
    expected = csv_text([["" if v is None else number_cell(v) if isinstance(v, float) else str(v) for v in row]
                         for row in exact])
    assert "".join(canvas_csv(made, piece)) == expected


def test_quoted_cell_is_the_csv_writers_cell() -> None:
    for cell in [*HOSTILE, "a", "±1 %, widened", '"', "a\r\nb"]:
        assert f"{quoted_cell(cell)},x\n" == csv_text([[cell, "x"]])


def test_report_pieces_are_the_cell_at_a_time_rule() -> None:
    """Mixed columns (text, numbers, None) and rows of another length, in pieces of a few rows."""
    rng = random.Random(3)
    values: list[object] = [*HOSTILE, None, 0, 7, 2.0, -0.0, 0.1 + 0.2, 1e20, "yes"]
    rows: list[Sequence[object]] = [[rng.choice(values) for _ in range(5)] for _ in range(60)]
    rows += [["only", "three", None], [1, 2.5, "x", "y", "z"], ["a", "b", "c", "d", "e"]]
    rows.append([rng.choice(HOSTILE) for _ in range(5)])
    expected = csv_text([[report_cell(value) for value in row] for row in rows])
    for piece in (1, 4, 1000):
        assert "".join(report_pieces(rows, piece)) == expected


def test_report_columns_are_the_cell_at_a_time_rule() -> None:
    """grades.csv's columns: text, numbers of one type, and mixed, as the rows they make."""
    rng = random.Random(4)
    values: list[object] = [*HOSTILE, None, 0, 7, 2.0, -0.0, 0.1 + 0.2, 1e20, "yes"]
    columns = [[rng.choice(HOSTILE) for _ in range(50)], [rng.choice([0.5, None, -0.0, 1e16]) for _ in range(50)],
               [rng.choice([None, 5, 0]) for _ in range(50)], [rng.choice(values) for _ in range(50)]]
    rows = zip(*columns, strict=True)
    assert report_columns(columns) == csv_text([[report_cell(value) for value in row] for row in rows])
    assert report_columns([[], []]) == ""


@pytest.mark.parametrize("cells", [
    [0.0, -0.0, 1.0, 1.0, 0.1 + 0.2, 0.3, None, 1e16, 2.0**60, -0.0, 3.4149999999999996, None],  # floats
    [0, 1, 2**60, None, 1, 0, 7],  # ints
    [1, True, 1.0, 0, False, -0.0, 2**60, 2.0**60],  # bools and ints and floats equal to one another
    [None, None, None]])
def test_a_column_of_repeated_numbers_is_the_cell_at_a_time_rule(cells: list[object]) -> None:
    """A column of numbers of one type is formatted once per value: equal values (0.0 and -0.0) give one text,
    and values equal across types (True, 1, 1.0; 2**60 and 2.0**60) keep each its own."""
    rows = [[cell, "x"] for cell in cells * 3]
    expected = csv_text([[report_cell(value) for value in row] for row in rows])
    for piece in (2, 1000):
        assert "".join(report_pieces(rows, piece)) == expected


def test_columns_are_written_as_the_csv_writer_writes_rows() -> None:
    rng = random.Random(11)
    alphabet = ["a", ",", '"', "\n", "\r", "=", " ", "é", "\x00", "'", "\u202e"]
    for _ in range(500):
        width, height = rng.randint(2, 4), rng.randint(0, 4)
        columns = [["".join(rng.choice(alphabet) for _ in range(rng.randint(0, 4))) for _ in range(height)]
                   for _ in range(width)]
        assert csv_columns_text(columns) == csv_text(list(zip(*columns, strict=True)))
    assert csv_columns_text([["", "x"]]) == csv_text([[""], ["x"]])  # one column: a row of one empty cell is ""


def test_safe_cells_is_safe_cell_of_each() -> None:
    texts = [*HOSTILE, "Ana", "1.5", "-0.5 m/s is 3 % above"]
    assert safe_cells(texts) == [safe_cell(text) for text in texts]
    assert safe_cells(["Ana", "Bo"]) == ["Ana", "Bo"]


SENTENCE_CASES = [Tolerance(), Tolerance(rtol=0.05), Tolerance(atol=0.5), Tolerance(rtol=0, atol=0.5),
                  Tolerance("sigfigs", digits=3), Tolerance("decimals", digits=2)]


@pytest.mark.parametrize("tolerance", SENTENCE_CASES)
@pytest.mark.parametrize("angle", [None, "deg"])
def test_feedback_sentences_are_each_sentence(tolerance: Tolerance, angle: str | None) -> None:
    """The percentage sentences written for a column are :meth:`_Words.sentence`'s, word for word."""
    rng = np.random.default_rng(5)
    key = np.concatenate([rng.normal(0, 10, 60), [0.0, -0.0, 1e-300, 1e300, 6.26, 6.26, 350.0, math.inf, math.nan]])
    submitted = np.concatenate([key[:60] * rng.choice([1.0, 1.004, 0.98, -1.0, 1 + 1e-16], 60),
                                [0.0, 1.0, 5e-301, 1.7e308, 6.3226, 6.26, -10.0, 1.0, 2.0]])
    right = is_correct(submitted, key, tolerance, angle_unit=angle)
    typed: list[str | None] = [None] * len(key)
    typed[3] = "17.0 mph"
    unit = "m/s" if angle is None else angle
    words = _Words(tolerance, unit, _period(angle))
    with np.errstate(all="ignore"):
        distances = _difference(submitted, key, words.period)
    expected = [words.sentence(s, t, d, ok, text) for s, t, d, ok, text in
                zip(submitted.tolist(), key.tolist(), distances.tolist(), right.tolist(), typed, strict=True)]
    fresh = _Words(tolerance, unit, _period(angle))  # its own cache of the numbers said
    assert fresh.sentences(submitted, key, distances, right, typed) == expected


NUMBER_TEXTS = ["1.5", "1.49", "1,5", "-1.5", "150 cm/s", "1.5 m/s", "5.4 km/h", "1.5 kg", "abc", "", "=1+1",
                "1.5e0", "3/2", "1.5\x1b", "1.5 or 1.6", "  1.5  ", "0", "1e400", "-0"]


def test_a_column_grades_each_cell_as_its_rule_says() -> None:
    """_grade_column (texts read once per distinct text, rows built a field at a time) against each cell
    graded on its own by the public rules: the number read, the verdict, errors and sentence, the source."""
    tolerance = {"mode": "rtol", "rtol": 0.01, "atol": 0.0}
    wide = {"mode": "rtol", "rtol": 0.05, "atol": 0.0}
    parts = [KeyPart("1", "v", "1a", value, "m/s", 2.0, rule, None, {})
             for value in (1.5, -1.5, 1.52) for rule in (tolerance, wide)]
    cells = [(parts[index % len(parts)], None if text is None else
              Answer("a.csv", index + 2, f"s{index}", "1a", text, ";" if index % 3 else ",", None))
             for index, text in enumerate([*NUMBER_TEXTS, *NUMBER_TEXTS[::-1], None])]
    key = Key("key.json", 2, "HW", True, (KeyProblem("1", "Drop", ("1a",)),), ())
    column = _grade_column([part for part, _ in cells], [answer for _, answer in cells], key)
    for (part, answer), row in zip(cells, column.rows, strict=True):
        assert row.points == part.points and row.unit == "m/s" and row.diagnosis == ""
        if answer is None:
            assert (row.submitted, row.verdict, row.source) == (None, "missing", "")
            continue
        assert row.source == f"a.csv:{answer.line}" and row.submitted == answer.text
        read = read_number(answer.text, "m/s", delimiter=answer.delimiter, names=("v", "1a"))
        if not isinstance(read, CellNumber):
            assert row.verdict in ("missing", "invalid", "incorrect") and row.abs_error is None
            continue
        rule, value = Tolerance.from_json(part.tolerance), float(part.value)  # type: ignore[arg-type]  # numbers
        right = bool(is_correct(read.value, value, rule))
        absolute, relative = errors(read.value, value)
        typed = None if read.unit_given in (None, "m/s") else " ".join(answer.text.split())
        said = _Words(rule, "m/s", None).sentence(read.value, value, read.value - value, right, typed)
        if typed is None:
            assert said == feedback(read.value, value, "m/s", rule, right)
        assert row == Row(answer.text, "correct" if right else "incorrect", 1.0 if right else 0.0, 2.0,
                          number_text(value), number_text(read.value), "m/s", float(absolute), float(relative),
                          rule.explained(), said, "", row.source)


def test_a_plain_decimal_is_read_as_every_step_reads_it() -> None:
    """read_number's shortcut for ``6.26`` and ``-0.369`` gives what the full reading gives, whatever the
    file's delimiter, the unit and the names (a label ``1`` before ``1.5`` is no prefix)."""
    rng = random.Random(17)
    texts = ["0", "-0", "0.0", "007", "1.5", "-1.5", "1" * 15, "9" * 15 + "." + "9" * 15, "0.000000000000001",
             "1.000", "-0.369", "123456789012345.5"]
    texts += [("-" if rng.random() < 0.3 else "") + str(rng.randint(0, 10 ** rng.randint(1, 15)))
              + ("." + str(rng.randint(0, 10 ** rng.randint(1, 15))) if rng.random() < 0.8 else "") for _ in range(300)]
    for text in texts:
        assert _DECIMAL.fullmatch(text), text
        for delimiter, unit, names in ((",", "m/s", ("v", "1a")), (";", "", ("1", "1")),
                                       ("\t", "deg", ("theta", "2b"))):
            assert read_number(text, unit, delimiter=delimiter, names=names) == _read_number(
                text, unit, delimiter, True, names), text
    for text in ("1,5", "1.5e3", " 1.5", "+1.5", "1.", ".5", "1.5 m", "1" * 16):
        assert not _DECIMAL.fullmatch(text)


UNIT_WORDS = ["m/s", "cm/s", "ft/s", "km/h", "N·s", "kJ", "%", "°", "deg", "rad", "e", "E", "x", "per", "pi", "m/",
              "/s", "·m", "%%", "°C", "xyz", "lb", "mph", "s", "m" * 30, "kg·m/s", "a", "EM", "em"]


def test_a_number_and_unit_is_split_as_every_step_splits_it() -> None:
    """read_number's shortcut for ``9.9 cm/s`` (a plain decimal, a space or none, a unit of letters, ``/``, ``·``,
    ``%`` and ``°``) splits it where every step (cleaned, a name taken off, no formula, no minutes, the unit
    looked for) splits it, whatever the names; and it is taken for the usual answers."""
    rng = random.Random(29)
    numbers = ["0", "-0", "9.9", "-12.5", "007", "1" * 15, "9" * 15 + "." + "9" * 15, "1.", ".5", "1e3", "+2", "1,5"]
    texts = [number + space + word for number in numbers for space in ("", " ", "  ") for word in UNIT_WORDS]
    texts += [f"{rng.uniform(-1e3, 1e3):.{rng.randint(0, 6)}f}{rng.choice(['', ' '])}{rng.choice(UNIT_WORDS)}"
              for _ in range(300)]
    split = 0
    for text in texts:
        found = _usual_split(text)
        if found is None:
            continue
        split += 1
        for names in (("v", "1a"), ("1", "1"), ("e", "9"), ("m", "-")):
            cleaned = _without_prefix(_clean(text), names)  # type: ignore[arg-type]  # a str: nothing to refuse
            _refuse_formula(cleaned, names)
            assert cleaned == text and not _DEGREES_MINUTES.fullmatch(cleaned), text
            assert _split_unit(cleaned) == found, text
    assert split > 300
    for usual in ("9.9 cm/s", "-12.5 %", "45.2 deg", "3.1 N·s", "7 kJ", "25.0 ft/s", "12°", "5.5m/s"):
        assert _usual_split(usual) is not None, usual
