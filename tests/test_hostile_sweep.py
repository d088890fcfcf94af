"""Cases from the hostile-input sweep of ``grader grade`` against the code before the column-at-a-time work
(b54e7cd): the ones its own tests did not yet hold, where a shortcut could have read a file differently.

- A number's text is read once per distinct text of a part, keyed by the file's delimiter too: ``1,234`` is
  ambiguous in a comma file (1234 or 1.234) and a decimal comma in a semicolon file.
- A plain file is read a piece of rows at a time: a file whose first rows are not plain and whose quote is
  left open is refused with the message the row-by-row reading gives.
"""

from __future__ import annotations

from pathlib import Path

import pytest

import grader.grade.submissions as submissions
from grader.base.errors import GraderError
from grader.grade.cells import CellInvalid, CellNumber, read_number
from grader.grade.grading import _grade_column
from grader.grade.key import Key, KeyPart, KeyProblem
from grader.grade.latest import Answer
from grader.grade.submissions import StudentRef, read_submissions


def test_a_text_is_read_with_its_own_files_delimiter() -> None:
    """The same texts from a comma file and a semicolon file, in either order: each cell's verdict is what
    read_number makes of it with its file's delimiter (the readings of a text are not shared across files)."""
    part = KeyPart("1", "v", "1a", 1.234, "m/s", 2.0, {"mode": "rtol", "rtol": 0.01, "atol": 0.0}, None, {})
    texts = ["1,234", "1,234", "12,345", "1,5", "1,234 m/s"]
    cells = [(part, Answer(name, line, f"s{line}", "1a", text, delimiter, None))
             for line, (name, delimiter, text) in enumerate(
                 [(name, delimiter, text) for text in texts for name, delimiter in (("a.csv", ","), ("b.csv", ";"))]
                 + [(name, delimiter, text) for text in texts for name, delimiter in (("b.csv", ";"), ("a.csv", ","))],
                 start=2)]
    key = Key("key.json", 2, "HW", True, (KeyProblem("1", "Drop", ("1a",)),), ())
    rows = _grade_column([part for part, _ in cells], [answer for _, answer in cells], key).rows
    for (_, answer), row in zip(cells, rows, strict=True):
        read = read_number(answer.text, "m/s", delimiter=answer.delimiter, names=("v", "1a"))
        if isinstance(read, CellInvalid):
            assert row.verdict == "invalid" and read.reason in row.feedback, answer
        else:
            assert isinstance(read, CellNumber)
            assert row.verdict != "invalid" and row.parsed == f"{read.value:.6g}", answer
    # The case itself: a comma file's 1,234 does not read, a semicolon file's is 1.234 (correct).
    assert [row.verdict for row in rows[:2]] == ["invalid", "correct"]
    assert [row.verdict for row in rows[10:12]] == ["correct", "invalid"]


STUDENTS = [StudentRef("007", "ana@x.edu"), StudentRef("042", "ben@x.edu")]


@pytest.mark.parametrize("early", ["007,1a\n", "007,1a,6.2,extra\n", "999,1a,6.2\n", "007,1a,6.2\n007,1a,6.3\n",
                                   "007,1a," + "9" * 1001 + "\n"])
@pytest.mark.parametrize("piece", [65536, 1])
def test_a_quote_left_open_after_rows_not_plain_is_refused_as_row_by_row(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, early: str, piece: int) -> None:
    """A row the plain reading does not take (too few or many cells, an unknown student, a label twice, a long
    cell), then a quote left open: the plain reading reads its whole piece before it looks, and the file is
    refused as the row-by-row reading refuses it, naming the line the quote opens on."""
    monkeypatch.setattr(submissions, "_PLAIN_PIECE", piece)
    path = tmp_path / "answers.csv"
    path.write_text(f"student_id,label,answer\n{early}042,1b,6.2\n042,1a,\"7\n", encoding="utf-8")
    with pytest.raises(GraderError) as fast:
        read_submissions([path], STUDENTS, ("1a", "1b"))
    monkeypatch.setattr(submissions, "_plain_answers", lambda *given: None)
    with pytest.raises(GraderError) as row_by_row:
        read_submissions([path], STUDENTS, ("1a", "1b"))
    assert str(fast.value) == str(row_by_row.value)
    assert f"line {2 + early.count(chr(10)) + 1}" in str(fast.value)
