"""Submissions read from LMS and Google Forms exports: one answer per (student, label), every data
row accounted for (an answer used, or a problem saying why not; caveats may accompany either)."""

from __future__ import annotations

import os
import tempfile
from collections import Counter
from datetime import UTC, datetime, timedelta, timezone
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from grader.base.errors import GraderError
from grader.base.inputs import read_csv
from grader.grade.submissions import Answer, RowProblem, StudentRef, Submissions, read_submissions
from grader.grade.timestamps import read_timestamp

NOW = datetime(2030, 1, 1, tzinfo=UTC)  # the run's time: the files' timestamps, in 2026, are before it
STUDENTS = [StudentRef("00123", "Ann.Lee@uni.edu"), StudentRef("456", "bob@uni.edu"), StudentRef("789", "cy@uni.edu")]
LABELS = ["1a", "1b", "2"]


def write(folder: Path, name: str, content: str | bytes) -> Path:
    path = folder / name
    if isinstance(content, str):
        path.write_bytes(content.encode("utf-8"))
    else:
        path.write_bytes(content)
    return path


def read(*paths: Path, fmt: str = "auto") -> Submissions:
    result = read_submissions(list(paths), STUDENTS, LABELS, fmt, now=NOW)  # type: ignore[arg-type]
    assert_accounted(result, {str(p): {row.line for row in read_csv(p, exports=True).rows} for p in paths})
    return result


def assert_accounted(result: Submissions, lines: dict[str, set[int]]) -> None:
    """Each data line is the line of one or more answers, or of exactly one problem that is not a
    caveat, never both; nothing is reported for a line that holds no data row."""
    answered = {(a.file, a.line) for a in result.answers}
    refused = Counter((p.file, p.line) for p in result.problems if not p.caveat)
    for file, numbers in lines.items():
        for line in numbers:
            place = (file, line)
            assert (place in answered) != (refused[place] == 1), (place, result)
            assert refused[place] <= 1, (place, result)
    reported = answered | {(p.file, p.line) for p in result.problems}
    assert reported <= {(f, n) for f, numbers in lines.items() for n in numbers}
    winners = Counter((a.student_id, a.label) for a in result.answers)
    assert max(winners.values(), default=1) == 1, "one answer per (student, label)"


def summary(result: Submissions) -> tuple[list[tuple[int, str, str, str]], list[tuple[int, str, str]]]:
    return ([(a.line, a.student_id, a.label, a.text) for a in result.answers],
            [(p.line, p.label, p.reason) for p in result.problems])


def test_long_file_one_answer_per_row_with_blank_lines_crlf_and_quoted_newlines(tmp_path: Path) -> None:
    """Line numbers count the header as 1 and blank lines too; a quoted cell over two lines keeps the
    row's first line; an empty long answer is an answer "" (a blank submitted)."""
    path = write(tmp_path, "long.csv", '\r\nStudent_ID,Label,Answer\r\n00123,1a,"6.26\r\nm/s"\r\n\r\n'
                                       '00123,1b,\r\n456,2,"1,5"\r\n')
    result = read(path)
    assert summary(result) == ([(3, "00123", "1a", "6.26\r\nm/s"), (6, "00123", "1b", ""), (7, "456", "2", "1,5")],
                               [])
    assert {a.delimiter for a in result.answers} == {","} and result.answers[0].file == str(path)


def test_wide_file_empty_cells_are_missing_answers_not_problems(tmp_path: Path) -> None:
    path = write(tmp_path, "wide.csv", "id;1a;1b;2\n00123;6,26;;\n456;;;\n789;1;2;3\n")
    result = read(path)
    assert summary(result)[0] == [(2, "00123", "1a", "6,26"), (4, "789", "1a", "1"), (4, "789", "1b", "2"),
                                  (4, "789", "2", "3")]
    assert summary(result)[1] == [(3, "", "no answers in this row")]
    assert result.answers[0].delimiter == ";"


def test_the_delimiter_is_sniffed_outside_quotes(tmp_path: Path) -> None:
    path = write(tmp_path, "semi.csv", 'id;"1a. speed, m/s"\n456;6,26\n')
    assert [(a.text, a.delimiter) for a in read(path).answers] == [("6,26", ";")]


def test_google_forms_headers_timestamps_and_ignored_columns(tmp_path: Path) -> None:
    path = write(tmp_path, "form.csv",
                 'Timestamp,Email Address,Student ID,"1a. Speed of the pile, in m/s",1b (m),2: energy lost,Name\n'
                 "12/4/2026 23:59:07,ann.lee@uni.edu,00123,6.26,0.5,12,Ann\n"
                 "12/4/2026 10:00:00,ann.lee@uni.edu,00123,6.3,0.4,11,Ann\n")
    result = read(path)
    assert summary(result)[0] == [(2, "00123", "1a", "6.26"), (2, "00123", "1b", "0.5"), (2, "00123", "2", "12")]
    assert summary(result)[1] == [(3, "", "superseded by " + str(path) + " line 2 (submitted later)")]
    assert result.answers[0].timestamp == datetime(2026, 12, 4, 23, 59, 7, tzinfo=UTC)  # in the zone given (UTC)
    assert result.ignored_columns == ("Email Address", "Name")  # an id column exists: the email is not used


@pytest.mark.parametrize(("header", "label"), [
    ("1a", "1a"), ("1A", "1a"), ("1a (m/s)", "1a"), ("1a. speed of the pile", "1a"), ("1a: v", "1a"),
    ("1a) v", "1a"), ("1ab", "1ab"), ("1ab (m)", "1ab"), ("11a", "11a"), ("1a-b", None), ("21a", None),
])
def test_a_wide_column_belongs_to_its_label_and_no_other(header: str, label: str | None) -> None:
    from grader.grade.columns import label_of
    assert label_of(header, ["1a", "1ab", "11a"]) == label


def test_email_only_files_match_the_keys_emails_ignoring_case(tmp_path: Path) -> None:
    path = write(tmp_path, "emails.csv", "Email Address,1a\nANN.LEE@uni.edu,1\nnobody@uni.edu,2\n")
    assert summary(read(path)) == ([(2, "00123", "1a", "1")],
                                   [(3, "", "unknown student email 'nobody@uni.edu' (not in the answer key)")])


def test_leading_zeros_eaten_by_a_spreadsheet_are_restored_and_said(tmp_path: Path) -> None:
    path = write(tmp_path, "zeros.csv", "sid,part,response\n123,1a,1\n0456,1a,2\n00789,1a,3\n")
    result = read(path)
    assert summary(result)[0] == [(2, "00123", "1a", "1"), (3, "456", "1a", "2"), (4, "789", "1a", "3")]
    assert [(p.line, p.reason, p.caveat) for p in result.problems] == [
        (2, "leading zeros restored: 123 -> 00123", True), (3, "leading zeros restored: 0456 -> 456", True),
        (4, "leading zeros restored: 00789 -> 789", True)]


def test_an_email_typed_in_the_id_column_is_matched_by_email_and_said(tmp_path: Path) -> None:
    """Issue 28: a student who typed their email for their id scored 0 as an unknown student, though
    ``grader check --student`` takes an email."""
    path = write(tmp_path, "a.csv", "student_id,label,answer\n ann.lee@UNI.edu ,1a,1\n456,1a,2\nno@uni.edu,1a,3\n")
    result = read(path)
    assert summary(result)[0] == [(2, "00123", "1a", "1"), (3, "456", "1a", "2")]
    assert [(p.line, p.reason, p.caveat) for p in result.problems] == [
        (2, "an email in the id column, matched by email: ann.lee@UNI.edu -> 00123", True),
        (4, "unknown student 'no@uni.edu' (not in the answer key)", False)]
    assert result.notes == ("1 row names its student by email in the id column: matched by email (see problems.csv)",)


def test_ids_are_text(tmp_path: Path) -> None:
    path = write(tmp_path, "a.csv", "id,1a\n00123,1\n")
    assert read_submissions([path], [StudentRef("00123", ""), StudentRef("123", "")], ["1a"]).answers[0].student_id \
        == "00123"
    result = read_submissions([path], [StudentRef("123", ""), StudentRef("0123", "")], ["1a"])
    assert [p.reason for p in result.problems] == [
        "student '00123' is ambiguous: with its leading zeros restored it could be 0123 or 123; write the id in full"]


def test_an_answer_over_the_cell_limit_is_kept_to_be_found_too_long_not_missing(tmp_path: Path) -> None:
    """Issue 22: a 1,204-character answer was dropped with the row, and the part said "no answer was submitted"."""
    long_answer = "6.26" + " +0" * 400
    path = write(tmp_path, "a.csv", f"id,label,answer\n456,1a,{long_answer}\n456,1b,2\n{'9' * 1001},1a,1\n")
    result = read(path)
    assert summary(result)[0] == [(2, "456", "1a", long_answer), (3, "456", "1b", "2")]
    assert [(p.line, p.reason) for p in result.problems] == [(4, "a cell of 1,001 characters; expected at most 1000")]


def test_duplicates_with_timestamps_across_two_files_the_latest_wins(tmp_path: Path) -> None:
    first = write(tmp_path, "a.csv", "student_id,label,answer,submitted at\n"
                                     "00123,1a,late,2026-12-04T23:59:07Z\n00123,1b,x,2026-12-04 10:00\n")
    second = write(tmp_path, "b.csv", "student_id,label,answer,submitted at\n"
                                      "00123,1a,early,2026-12-05 00:30:00+02:00\n00123,1b,y,2026-12-04 11:00\n")
    result = read(first, second)
    assert summary(result)[0] == [(2, "00123", "1a", "late"), (3, "00123", "1b", "y")]
    assert summary(result)[1] == [(3, "1b", f"superseded by {second} line 3 (submitted later)"),
                                  (2, "1a", f"superseded by {first} line 2 (submitted later)")]
    assert result.notes == ("some timestamps have a time zone and some do not: those without were taken as UTC "
                            "(the assignment's zone) to compare them",)


def test_duplicates_without_timestamps_the_last_row_wins_in_file_then_argument_order(tmp_path: Path) -> None:
    first = write(tmp_path, "a.csv", "id,1a,1b\n456,1,1\n456,2,2\n")
    second = write(tmp_path, "b.csv", "id,1a\n456,3\n")
    result = read(first, second)
    assert summary(result)[0] == [(2, "456", "1a", "3")]
    why = f"superseded by {second} line 2 (no timestamps: the last row wins)"
    assert [(p.file, p.line, p.reason) for p in result.problems] == [(str(first), 2, why), (str(first), 3, why)]


def test_a_long_row_replaces_one_answer_of_a_wide_submission_as_a_caveat(tmp_path: Path) -> None:
    wide = write(tmp_path, "w.csv", "id,1a,1b\n456,1,1\n")
    long = write(tmp_path, "l.csv", "id,label,answer\n456,1a,9\n")
    result = read(wide, long)
    assert summary(result)[0] == [(2, "456", "1b", "1"), (2, "456", "1a", "9")]
    assert [(p.file, p.label, p.caveat) for p in result.problems] == [(str(wide), "1a", True)]


def test_an_unreadable_timestamp_is_a_caveat_and_the_row_has_none(tmp_path: Path) -> None:
    path = write(tmp_path, "t.csv", "id,label,answer,timestamp\n456,1a,1,yesterday\n456,1a,2,2026-01-01\n")
    result = read(path)
    assert summary(result)[0] == [(3, "456", "1a", "2")]
    assert [(p.line, p.caveat, p.reason[:22]) for p in result.problems] == [
        (2, False, "superseded by " + str(path)[:8]), (2, True, "timestamp 'yesterday' ")]
    assert "not every row has a timestamp: the last row wins" in result.problems[0].reason


@pytest.mark.parametrize(("text", "when"), [
    ("2026-12-04 23:59:07", datetime(2026, 12, 4, 23, 59, 7)),
    ("2026-12-04T23:59:07Z", datetime(2026, 12, 4, 23, 59, 7, tzinfo=UTC)),
    ("2026-12-04 23:59:07 UTC", datetime(2026, 12, 4, 23, 59, 7, tzinfo=UTC)),
    ("2026-12-04T23:59:07.5+01:00", datetime(2026, 12, 4, 23, 59, 7, 500000, tzinfo=timezone(timedelta(hours=1)))),
    ("12/4/2026 23:59:07", datetime(2026, 12, 4, 23, 59, 7)),
    ("12/4/2026 11:59:07 PM", datetime(2026, 12, 4, 23, 59, 7)),
    ("12/4/2026 12:05 AM", datetime(2026, 12, 4, 0, 5)),
    ("12/4/2026 23:59:07 GMT-5", datetime(2026, 12, 4, 23, 59, 7, tzinfo=timezone(timedelta(hours=-5)))),
    ("", None),
])
def test_timestamp_formats(text: str, when: datetime | None) -> None:
    assert read_timestamp(text) == when


@pytest.mark.parametrize("text", ["yesterday", "13/45/2026 10:00", "2026-02-30", "12/4/26 10:00"])
def test_timestamps_that_do_not_read_say_so(text: str) -> None:
    assert "not understood" in str(read_timestamp(text))


def test_utf16_with_bom_tab_delimited_as_excel_saves_unicode_text(tmp_path: Path) -> None:
    path = write(tmp_path, "excel.txt", "ID\t1a\t1b\r\n00123\t6,26\tZoë\r\n".encode("utf-16"))
    result = read(path)
    assert summary(result)[0] == [(2, "00123", "1a", "6,26"), (2, "00123", "1b", "Zoë")]
    assert result.answers[0].delimiter == "\t" and result.notes == ()


def test_a_clean_cp1252_file_is_read_and_noted(tmp_path: Path) -> None:
    path = write(tmp_path, "legacy.csv", "id;Name;1a\n456;José Muñoz;6,26 m·s\n".encode("cp1252"))
    result = read(path)
    assert summary(result)[0] == [(2, "456", "1a", "6,26 m·s")]
    assert len(result.notes) == 1 and "Windows-1252" in result.notes[0]


def test_lone_cr_line_ends_are_line_ends_not_a_refused_file(tmp_path: Path) -> None:
    """Excel for Mac's "CSV (Macintosh)" ends lines with CR alone; a file edited on two systems mixes
    them. Both were refused with the csv module's "new-line character seen in unquoted field"."""
    path = write(tmp_path, "mac.csv", "id,1a\r00123,6.26\r456,1\r\n789,2\n")
    assert summary(read(path))[0] == [(2, "00123", "1a", "6.26"), (3, "456", "1a", "1"), (4, "789", "1a", "2")]


def test_a_byte_order_mark_inside_a_file_does_not_stick_to_an_id(tmp_path: Path) -> None:
    """Two exports pasted together: the second one's BOM made its first id unknown ('\\ufeff456')."""
    path = write(tmp_path, "pasted.csv", "\ufeffid,1a\n00123,6.26\n\ufeff456,1\n")
    assert summary(read(path)) == ([(2, "00123", "1a", "6.26"), (3, "456", "1a", "1")], [])


@pytest.mark.parametrize("encoding", ["utf-16-le", "utf-16-be"])
def test_utf16_without_a_byte_order_mark_is_refused_as_such(tmp_path: Path, encoding: str) -> None:
    """It was refused for "the byte 0xb0" at the first °, far into the file, or as binary data."""
    path = write(tmp_path, "u.csv", "id,1a\n456,30°\n".encode(encoding))
    with pytest.raises(GraderError, match=f"{encoding.upper().replace('-LE', 'LE').replace('-BE', 'BE')} text "
                                          "without a byte-order mark; expected UTF-8, or UTF-16"):
        read_submissions([path], STUDENTS, LABELS)


def test_a_file_name_that_is_not_utf8_is_written_escaped(tmp_path: Path) -> None:
    """details.csv and problems.csv name the file; a name with the byte 0xff stopped the run with a
    UnicodeEncodeError when they were written."""
    path = write(tmp_path, os.fsdecode(b"answers-\xff.csv"), "id,1a\n999,1\n")
    assert [p.file for p in read_submissions([path], STUDENTS, LABELS).problems] == [
        str(tmp_path / "answers-\\xff.csv")]


@pytest.mark.parametrize(("content", "offset"), [
    (b"id,1a\n456,1\n\x89PNG\r\n\x1a\n\x00\x00", 12),  # binary: control bytes, not clean cp1252
    ("id,1a\n456,é\n".encode() + b"\xe9", 13),  # UTF-8 with one stray byte: a mix, not cp1252
    (b"PK\x03\x04\x14\x00\x06\x00\x08\x00\x00\x00!\x00\xb5", 14),  # an .xlsx
])
def test_files_in_no_supported_encoding_are_refused_with_the_byte_offset(tmp_path: Path, content: bytes,
                                                                         offset: int) -> None:
    path = write(tmp_path, "bad.csv", content)
    with pytest.raises(GraderError, match=f"byte offset {offset} .*expected UTF-8 or UTF-16 text"):
        read_submissions([path], STUDENTS, LABELS)


def test_canvas_rows_are_listed_as_not_student_rows_never_graded(tmp_path: Path) -> None:
    path = write(tmp_path, "canvas.csv",
                 "Student,ID,SIS User ID,SIS Login ID,Section,1a (m/s),1b\n"
                 "    Points Possible,,,,,5,5\n"
                 "    Manual Posting,,,,,Manual Posting,\n"
                 '"Student, Test",999,,abc,S1,1,2\n'
                 "Ann,55,00123,ann,S1,6.26,\n")
    result = read(path)
    assert summary(result) == ([(5, "00123", "1a", "6.26")], [
        (2, "", "not a student row (Canvas' 'Points Possible' row)"),
        (3, "", "not a student row (Canvas' 'Manual Posting' row)"),
        (4, "", "not a student row (Canvas' test student)")])
    assert result.ignored_columns == ("Student", "ID", "SIS Login ID", "Section")  # SIS User ID names students


def test_unknown_students_and_labels_are_row_problems(tmp_path: Path) -> None:
    path = write(tmp_path, "u.csv", "username,question,value\n999,1a,1\n456,3c,2\n,1a,3\n456,1A,4\n")
    assert summary(read(path)) == ([(5, "456", "1a", "4")], [
        (2, "1a", "unknown student '999' (not in the answer key)"),
        (3, "3c", "unknown label '3c' (expected one of 1a, 1b, 2)"), (4, "1a", "no student given")])


def test_a_row_with_too_many_cells_is_a_row_problem_and_a_huge_answer_is_kept_to_be_graded(tmp_path: Path) -> None:
    path = write(tmp_path, "r.csv", f"id,1a\n456,1,extra\n789,{'9' * 1001}\n00123,5\n")
    result = read(path)
    assert summary(result)[0] == [(3, "789", "1a", "9" * 1001), (4, "00123", "1a", "5")]
    assert [(p.line, p.reason[:20]) for p in result.problems if not p.caveat] == [(2, "3 cells, but the hea")]


def test_a_cell_beyond_the_csv_modules_limit_is_not_a_refused_file(tmp_path: Path) -> None:
    """A 10 MB cell (an essay pasted in a form) refused the whole file, saying "a cell longer than 1000
    characters" although cells of 1,001 to 131,072 characters were row problems. An answer that long is
    now graded (invalid, too long: issue 22); an id that long is a row problem."""
    path = write(tmp_path, "r.csv", f'id,1a\n789,"{"9" * (10 << 20)}"\n00123,5\n"{"9" * (10 << 20)}",1\n')
    result = read(path)
    assert [(a.line, a.student_id, len(a.text)) for a in result.answers] == [(2, "789", 10 << 20), (3, "00123", 1)]
    assert [(p.line, p.reason) for p in result.problems] == [(4, "a cell of 10,485,760 characters; expected at most "
                                                                 "1000")]


def test_a_quote_left_open_is_refused_at_the_line_it_opens(tmp_path: Path) -> None:
    """It was reported at the last line of the file, which the open quote ran to."""
    path = write(tmp_path, "q.csv", 'id,1a\n456,"1\n' + "789,2\n" * 50)
    with pytest.raises(GraderError, match=r"q\.csv: line 2: unexpected end of data"):
        read(path)


@pytest.mark.parametrize(("header", "fmt"), [("name,section\n", "auto"), ("id,label,answer\n", "wide"),
                                             ("id,1a\n", "long"), ("1a,1b\n", "auto")])
def test_a_file_without_a_recognisable_header_is_refused_saying_what_was_expected(tmp_path: Path, header: str,
                                                                                  fmt: str) -> None:
    path = write(tmp_path, "h.csv", header + "x,y\n")
    with pytest.raises(GraderError, match=r"line 1: no recognisable header; expected a long file .*student_id, "
                                          r"label, answer.* or a wide file"):
        read(path, fmt=fmt)


def test_a_header_of_100000_unknown_columns_is_refused_in_a_short_message(tmp_path: Path) -> None:
    """The message listed every column: 789 kB on one line."""
    path = write(tmp_path, "h.csv", "id," + ",".join(f"c{i}" for i in range(100_000)) + "\n1,2\n")
    with pytest.raises(GraderError, match="no recognisable header") as refused:
        read(path)
    assert len(str(refused.value)) < 800


@pytest.mark.parametrize("twice", ["a.csv", "./a.csv"])
def test_a_file_given_twice_is_refused(tmp_path: Path, twice: str) -> None:
    """Each of its rows was listed as "superseded by" itself (the file and line it is on)."""
    path = write(tmp_path, "a.csv", "id,1a\n456,1\n")
    with pytest.raises(GraderError, match="expected each submissions file once"):
        read_submissions([path, tmp_path / twice], STUDENTS, LABELS)


def test_two_columns_for_one_label_are_refused(tmp_path: Path) -> None:
    path = write(tmp_path, "two.csv", "id,1a. speed,1a (m/s)\n456,1,2\n")
    with pytest.raises(GraderError, match="both answer 1a; expected one column per label"):
        read(path)


def test_answers_and_problems_are_frozen() -> None:
    answer = Answer("a.csv", 2, "456", "1a", "1", ",", None)
    with pytest.raises(AttributeError):
        answer.text = "2"  # type: ignore[misc]
    assert RowProblem("a.csv", 2, "456", "", "why").caveat is False


# --- the accounting property, on random files ------------------------------------------------------

IDS = ["00123", "123", "456", "0456", "789", "999", ""]
CELLS = st.sampled_from(["1", "6,26", "", "0.5 m", 'say "hi"', "two\nlines", "a;b"])
STAMPS = st.sampled_from(["", "2026-12-04 23:59:07", "2026-12-04T23:59:07Z", "12/4/2026 10:00:00", "soon",
                          "2026-12-03T01:00:00+05:00"])
ROWS = st.lists(st.tuples(st.sampled_from(IDS), st.sampled_from([*LABELS, "3c"]), CELLS, STAMPS, st.booleans(),
                          st.lists(CELLS, min_size=3, max_size=3)), max_size=12)


def _quoted(cell: str, delimiter: str) -> str:
    special = any(c in cell for c in (delimiter, '"', "\n"))
    return '"' + cell.replace('"', '""') + '"' if special else cell


def _file(rows: list[tuple[str, str, str, str, bool, list[str]]], wide: bool, delimiter: str,
          stamped: bool) -> tuple[str, set[int]]:
    """A random file's text and the lines its data rows start on (counted here, not by the reader)."""
    header = ["student_id", *LABELS] if wide else ["student_id", "label", "answer"]
    header += ["timestamp"] if stamped else []
    lines, data_lines = [delimiter.join(header)], set()
    for who, label, answer, stamp, blank_before, cells in rows:
        if blank_before:
            lines.append("")
        cells_out = [who, *cells] if wide else [who, label, answer]
        cells_out += [stamp] if stamped else []
        if not any(c.strip() for c in cells_out):
            continue  # an empty row is a blank line
        data_lines.add(len(lines) + 1)
        lines.append(delimiter.join(_quoted(c, delimiter) for c in cells_out))
        lines[-1:] = lines[-1].split("\n")  # a quoted newline: the row spans lines
    return "\n".join(lines) + "\n", data_lines


@settings(max_examples=60, deadline=None)
@given(files=st.lists(st.tuples(ROWS, st.booleans(), st.sampled_from([",", ";", "\t"]), st.booleans()),
                      min_size=1, max_size=3))
def test_every_data_line_is_accounted_for_exactly_once(
        files: list[tuple[list[tuple[str, str, str, str, bool, list[str]]], bool, str, bool]]) -> None:
    with tempfile.TemporaryDirectory() as folder:
        paths, lines = [], {}
        for index, (rows, wide, delimiter, stamped) in enumerate(files):
            text, data_lines = _file(rows, wide, delimiter, stamped)
            path = write(Path(folder), f"f{index}.csv", text)
            paths.append(path)
            lines[str(path)] = data_lines
        result = read_submissions(paths, STUDENTS, LABELS, now=NOW)
        assert_accounted(result, lines)
        if not any(wide or stamped for _, wide, _, stamped in files):  # long, no timestamps: the last row wins
            last = {}
            for rows, *_ in files:
                for who, label, answer, *_ in rows:
                    student = {"00123": "00123", "123": "00123", "456": "456", "0456": "456", "789": "789"}.get(who)
                    if student and label in LABELS:
                        last[student, label] = answer
            assert {(a.student_id, a.label): a.text for a in result.answers} == last
