"""The usual submissions file (long, no timestamps, every row a known student's answer to a label, once)
is read without the rows' machinery (issue 29): what it reads is what the row-by-row reader reads, and any
other file is read row by row."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

import grader.grade.submissions as submissions
from grader.grade.answer_columns import AnswerColumns
from grader.grade.submissions import StudentRef, Submissions, read_submissions

STUDENTS = [StudentRef("007", "ana@x.edu"), StudentRef("042", "ben@x.edu"), StudentRef("100", "cy@x.edu")]
LABELS = ("1a", "1b", "2a")

PLAIN = {  # read as plain answers
    "usual": "student_id,label,answer\n007,1a,6.2\n007,1b,165 cm/s\n042,1a,\n042,2a,\"1,234\"\n100,1b,six\n",
    "byte-order mark, CRLF, spaces": "\ufeffstudent_id,label,answer\r\n 007 , 1a ,  6.2 m/s \r\n042,1b,=1+1\r\n",
    "semicolons and a decimal comma": "id;label;answer\n007;1a;6,2\n042;2a;\"6;2\"\n",
    "blank lines and a cell over two lines": "student_id,label,answer\n\n007,1a,\"6.2\n m/s\"\n\n\n042,1a,7\n",
    "other columns": "name,student_id,label,answer,note\nAna,007,1a,6.2,x\nBen,042,1b,7,\n",
    "rows of only delimiters or spaces": "student_id,label,answer\n007,1a,6.2\n,,\n   \n042,1b,7\n",
    "CRLF and quoted cells": "student_id,label,answer\r\n007,1a,\"1,5\"\r\n042,1b,\" 7 \"\r\n100,2a,\"\"\"x\"\"\"\r\n",
    "no line end at the end": "student_id,label,answer\n007,1a,6.2\n042,1b,7",
    "the longest cell, CRLF": "student_id,label,answer\r\n007,1a," + "9" * 1000 + "\r\n",
    "a header name over two lines": "student_id,label,answer,\"a\nnote\"\n007,1a,6.2,x\n042,1b,7,\n",
    # from the hostile-input sweep of grader grade (each read the same by both readers there too)
    "lone CRs (Excel for Mac), tabs": "student_id\tlabel\tanswer\r007\t1a\t6,2\r042\t1b\t165 cm/s\r100\t2a\t\"a\tb\"\r",
    "blank lines before the header, a byte-order mark mid file":
        "\n\r\n\ufeffstudent_id,label,answer\n007,1a,6.2\n\ufeff042,1b,7\n",
    "hostile answers": "student_id,label,answer\n007,1a,\"=1+1\"\n007,1b,\u202e6.2\x01\n007,2a,\uff11\uff12.\uff15\n"
                       "042,1a,\u0666\u066b\u0662\n042,1b,1e400\n042,2a,\"6\"\"2\"\n100,1a,-0\n"
                       "100,1b,\u00a06.2\u00a0 m / s\n",
    "a quote inside a cell": "student_id,label,answer\n007,1a,6\"2\n042,1b,55\u00b030'\n",
}
ROW_BY_ROW = {  # anything else: read row by row
    "twice": "student_id,label,answer\n007,1a,6.2\n007,1a,6.3\n",
    "unknown student": "student_id,label,answer\n007,1a,6.2\n999,1a,6.3\n",
    "leading zeros lost": "student_id,label,answer\n7,1a,6.2\n",
    "label in another case": "student_id,label,answer\n007,1A,6.2\n",
    "unknown label": "student_id,label,answer\n007,9z,6.2\n",
    "timestamps": "student_id,label,answer,timestamp\n007,1a,6.2,2026-12-01 10:00\n",
    "too many cells": "student_id,label,answer\n007,1a,6.2,extra\n",
    "too few cells": "student_id,label,answer\n007,1a\n",
    "by email": "email,label,answer\nana@x.edu,1a,6.2\n",
    "wide": "student_id,1a,1b\n007,6.2,7\n",
    "a long cell": "student_id,label,answer\n007,1a," + "9" * 5000 + "\n",
    "a cell one too long": "student_id,label,answer\n007,1a,\"" + "9" * 1001 + "\"\n",
    "no student": "student_id,label,answer\n,1a,6.2\n",
    "a student's row over two pieces' edge twice": "student_id,label,answer\r\n007,1a,1\r\n042,1a,2\r\n007,1a,3\r\n",
}


def _read(path: Path, attempts: str = "latest") -> Submissions:
    return read_submissions([path], STUDENTS, LABELS, attempts=attempts)


# Rows read a piece at a time: a piece of one row, where a student's label twice is in two pieces.
@pytest.mark.parametrize(("attempts", "piece"), [("latest", 65536), ("first", 65536), ("best", 65536), ("latest", 1)])
@pytest.mark.parametrize("name", [*PLAIN, *ROW_BY_ROW])
def test_the_plain_reading_reads_what_the_row_by_row_reading_reads(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                                   name: str, attempts: str, piece: int) -> None:
    monkeypatch.setattr(submissions, "_PLAIN_PIECE", piece)
    path = tmp_path / "answers.csv"
    path.write_bytes((PLAIN | ROW_BY_ROW)[name].encode("utf-8"))
    used = []
    plain_answers = submissions._plain_answers
    monkeypatch.setattr(submissions, "_plain_answers", lambda *given: used.append(plain_answers(*given)) or used[-1])
    fast = _read(path, attempts)
    assert (used[-1] is not None) == (name in PLAIN)
    monkeypatch.setattr(submissions, "_plain_answers", lambda *given: None)
    assert fast == _read(path, attempts)


def test_plain_answers_keep_their_lines_and_text(tmp_path: Path) -> None:
    path = tmp_path / "answers.csv"
    path.write_text(PLAIN["blank lines and a cell over two lines"], encoding="utf-8")
    assert [(a.line, a.student_id, a.label, a.text) for a in _read(path).answers] == [
        (3, "007", "1a", "6.2\n m/s"), (7, "042", "1a", "7")]


def test_a_quote_left_open_is_refused_naming_its_line_as_before(tmp_path: Path) -> None:
    path = tmp_path / "answers.csv"
    path.write_text('student_id,label,answer\n007,1a,6.2\n042,1a,"7\n', encoding="utf-8")
    with pytest.raises(Exception, match="line 3"):
        _read(path)


@pytest.mark.parametrize("text", ['student_id,label,answer\n007,1a,6.2\n042,1a,"6"2\n',
                                  'student_id,label,answer\r\n007,1a,"6"2\r\n042,1b,7\r\n'])
def test_a_quote_closed_mid_cell_is_refused_as_the_row_by_row_reading_refuses_it(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, text: str) -> None:
    path = tmp_path / "answers.csv"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(Exception) as plain:
        _read(path)
    monkeypatch.setattr(submissions, "_plain_answers", lambda *given: None)
    with pytest.raises(Exception) as row_by_row:
        _read(path)
    assert str(plain.value) == str(row_by_row.value) and "expected after '\"'" in str(plain.value)


SEVERAL = {  # several files: (files, whether all are read as plain answers)
    "plain files": (["student_id,label,answer\n007,1a,6.2\n042,1b,7\n", "id;label;answer\n100;2a;6,2\n007;1b;8\n",
                     "student_id,label,answer\r\n042,2a,x\r\n"], True),
    "a student's label in two files": (["student_id,label,answer\n007,1a,6.2\n", "student_id,label,answer\n007,1a,7\n"],
                                       False),
    "a plain file, then one with timestamps": (["student_id,label,answer\n007,1a,6.2\n042,1a,5\n",
                                                 "student_id,label,answer,timestamp\n007,1a,7,2026-12-01 10:00\n"],
                                                False),
    "a plain file between others": (["student_id,label,answer\n007,1a,6.2\n", "student_id,label,answer\n9,1a,1\n",
                                     "student_id,label,answer\n042,1b,7\n100,2a,1\n"], False),
}


@pytest.mark.parametrize("attempts", ["latest", "best"])
@pytest.mark.parametrize("name", SEVERAL)
def test_several_plain_files_are_read_as_the_row_by_row_reading_reads_them(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, name: str, attempts: str) -> None:
    """Each (student, label) once in all the files, and every file plain: read without the rows' machinery, the
    files' answers one after another; else every file is read row by row (the files before the first that is not
    plain read again)."""
    texts, plain = SEVERAL[name]
    paths = []
    for index, text in enumerate(texts):
        paths.append(tmp_path / f"answers-{index}.csv")
        paths[-1].write_bytes(text.encode("utf-8"))
    fast = read_submissions(paths, STUDENTS, LABELS, attempts=attempts)
    assert isinstance(fast.answers, AnswerColumns) == plain
    monkeypatch.setattr(submissions, "_plain_answers", lambda *given: None)
    slow = read_submissions(paths, STUDENTS, LABELS, attempts=attempts)
    assert fast == slow and list(fast.answers) == list(slow.answers) and fast.answers
    assert [answer.file for answer in fast.answers] == sorted(answer.file for answer in fast.answers)


@pytest.mark.skipif(not Path("/dev/fd").is_dir(), reason="no /dev/fd")
@pytest.mark.parametrize("pipe_first", [True, False])
def test_a_plain_pipe_before_a_file_that_is_not_plain_is_read_once(tmp_path: Path, pipe_first: bool) -> None:
    """``grader grade <(cat a.csv) b.csv``: a pipe cannot be read again when a later file turns out not plain.
    It was, and read empty: "empty file; expected a header line" (the row-by-row reading read it once)."""
    plain_text = "student_id,label,answer\n007,1a,6.2\n042,1b,7\n"
    stamped = tmp_path / "stamped.csv"
    stamped.write_text("student_id,label,answer,timestamp\n100,2a,5,2026-12-01 10:00\n", encoding="utf-8")
    read_end, write_end = os.pipe()
    os.write(write_end, plain_text.encode("utf-8"))  # well within a pipe's buffer
    os.close(write_end)
    try:
        pipe = Path(f"/dev/fd/{read_end}")
        got = read_submissions([pipe, stamped] if pipe_first else [stamped, pipe], STUDENTS, LABELS)
    finally:
        os.close(read_end)
    assert sorted((a.student_id, a.label, a.text) for a in got.answers) == [
        ("007", "1a", "6.2"), ("042", "1b", "7"), ("100", "2a", "5")]
