"""`grader grade --canvas EXPORT.csv`: canvas.csv carries a Canvas gradebook export's students, names, ids
and `Title (id)` column, with the key's scores; every mismatch is a caveat in problems.csv; an unusable
export is refused before anything is written.

The key is written here by hand (5 students, parts 1a of 4 points and 1b of 6), so every expected cell
below is read off the fixtures, not computed by the code under test."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest

from grader.cli import main

EXPORT = Path("export.csv")  # relative, as a user types it: problems.csv names the file as given

# (id, name, email, answers given to 1a and 1b: correct 6.26 and 0.5, or nothing)
KEY_STUDENTS = [
    ("00123", "Jane Doe", "jane.doe@uni.edu", {"1a": "6.26", "1b": "0.5"}),  # 10 points; by SIS User ID
    ("s2002", "Li Wei", "li.wei@uni.edu", {"1a": "6.26"}),  # 4 points; by name (the login is in other case)
    ("s2003", "Ana Ruiz", "ana.ruiz@uni.edu", {}),  # 0 points; by name (the login is the email in other case)
    ("00126", "Eve Adams", "eve.adams@uni.edu", {"1b": "0.5"}),  # 6 points; SIS User ID lost its zeros
    ("s2004", "Omar Haddad", "omar.haddad@uni.edu", {"1a": "6.26"}),  # not in the export
]

EXPORT_TEXT = (
    "Student,ID,SIS User ID,SIS Login ID,Section,Homework 3 (12345),Quiz 1 (12346),Current Score,Final Score\n"
    "    Points Possible,,,,,10.00,5.00,(read only),(read only)\n"
    ",,,,,Manual Posting,,,\n"
    '"Doe, Jane",4321,00123,jdoe,Section 1,,4.00,80.00,80.00\n'
    '"Wei, Li",4322,,S2002,Section 1,,,,\n'
    '"Ruiz, Ana",4323,,Ana.Ruiz@UNI.edu,Section 2,,,,\n'
    '"=HYPERLINK(""http://x""), Eve",4325,126,eadams,Section 2,,,,\n'
    '"Stranger, Sam",4330,99999,sstranger,Section 2,7.50,,,\n'
    '"Student, Test",4399,,6f1e2d3c4b5a,Section 1,,,,\n'
)

CANVAS_HEADER = ["Student", "ID", "SIS User ID", "SIS Login ID", "Section", "Homework 3 (12345)"]
BY = "(by ID, SIS User ID, SIS Login ID or a name of one key student)"
NOT_IN_KEY = f"Canvas student 'Stranger, Sam' is not in the key {BY}: no score written, the export's cell kept"
NOT_IN_EXPORT = (f"in the key but not in the Canvas export {BY}: no score can be imported for them (dropped the "
                 "course, or enrolled under another id?)")


def by_name(name: str, key_name: str) -> str:
    return (f"matched by name, '{name}' is the key's {key_name}: no ID, SIS User ID or SIS Login ID of the row is "
            "the key's; check it is the same student")


def key_document() -> dict[str, object]:
    """Problem 1: 1a is 6.26 (4 points), 1b is 0.5 (6 points), for every student."""
    tolerance = {"mode": "rtol", "rtol": 0.01, "atol": 0}
    parts = {"speed": ("1a", 6.26, 4), "ratio": ("1b", 0.5, 6)}
    answers = {name: {"value": value, "unit": "", "label": label, "points": points, "tolerance": tolerance}
               for name, (label, value, points) in parts.items()}
    return {"schema": "grader-key", "version": 2, "assignment": {"title": "Homework 3"},
            "problems": [{"key": "1", "title": "Drop", "answers": [
                {"name": name, "label": label, "unit": "", "points": points}
                for name, (label, _, points) in parts.items()]}],
            "students": [{"id": sid, "name": name, "email": email, "section": "1",
                          "problems": [{"key": "1", "answers": answers}]} for sid, name, email, _ in KEY_STUDENTS]}


@pytest.fixture
def folder(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A current folder with key.json and answers.csv; the export is written by each test."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "key.json").write_text(json.dumps(key_document()), encoding="utf-8")
    rows = [f"{sid},{label},{text}" for sid, _, _, answers in KEY_STUDENTS for label, text in answers.items()]
    (tmp_path / "answers.csv").write_text("student_id,label,answer\n" + "\n".join(rows) + "\n", encoding="utf-8")
    return tmp_path


def grade(capsys: pytest.CaptureFixture[str], out: str = "g", *extra: str) -> tuple[int, str, str]:
    code = main(["grade", "--key", "key.json", "answers.csv", "--out", out, "--canvas", str(EXPORT), *extra])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def cells(path: Path) -> list[list[str]]:
    with open(path, encoding="utf-8", newline="") as stream:
        return list(csv.reader(stream))


@pytest.mark.parametrize("encoding", ["utf-8-sig", "utf-16"])  # Canvas writes a BOM; Excel's "Unicode text"
def test_canvas_csv_has_the_exports_students_ids_and_assignment_column(folder: Path, capsys: pytest.CaptureFixture[str],
                                                                       encoding: str) -> None:
    """Matched by SIS User ID, by an id whose zeros a spreadsheet ate, and by name where the login is the
    key's in another case (Canvas compares logins exactly); a name that is a formula is written exactly
    (Canvas matches on it); the Canvas student not in the key keeps the export's 7.50, as a plain number;
    the points-possible, manual-posting and test-student rows are not students."""
    EXPORT.write_bytes(EXPORT_TEXT.encode(encoding))
    code, out, err = grade(capsys, "g", "--json")
    assert code == 0, err  # caveats only: every submission row was graded
    assert cells(folder / "g" / "canvas.csv") == [
        CANVAS_HEADER,
        ["Points Possible", "", "", "", "", "10"],
        ["Doe, Jane", "4321", "00123", "jdoe", "Section 1", "10"],
        ["Wei, Li", "4322", "", "S2002", "Section 1", "4"],
        ["Ruiz, Ana", "4323", "", "Ana.Ruiz@UNI.edu", "Section 2", "0"],
        ["=HYPERLINK(\"http://x\"), Eve", "4325", "126", "eadams", "Section 2", "6"],
        ["Stranger, Sam", "4330", "99999", "sstranger", "Section 2", "7.5"],
    ]
    assert cells(folder / "g" / "problems.csv") == [
        ["file", "line", "student_id", "label", "reason"],
        ["export.csv", "5", "s2002", "", by_name("Wei, Li", "Li Wei")],
        ["export.csv", "6", "s2003", "", by_name("Ruiz, Ana", "Ana Ruiz")],
        ["export.csv", "7", "00126", "", "leading zeros restored: 126 -> 00126"],
        ["export.csv", "8", "99999", "", NOT_IN_KEY],
        ["export.csv", "", "s2004", "", NOT_IN_EXPORT],
    ]
    summary = json.loads(out)
    assert summary["rows_not_graded"] == 0
    assert "export.csv: 5 Canvas students, 4 matched to the key (2 by name); key students not in the export: 1 " \
           "(see problems.csv)" in summary["notes"]
    assert ("export.csv: of the key's students who submitted nothing, 1 got 0 (the export shows no grade for "
            "them)") in summary["notes"]
    assert "note: export.csv: 5 Canvas students" in err


def test_reruns_with_an_export_are_byte_identical(folder: Path, capsys: pytest.CaptureFixture[str]) -> None:
    EXPORT.write_text(EXPORT_TEXT, encoding="utf-8")
    assert grade(capsys, "g1")[0] == grade(capsys, "g2")[0] == 0
    for name in ("grades.csv", "details.csv", "problems.csv", "canvas.csv"):
        assert (folder / "g1" / name).read_bytes() == (folder / "g2" / name).read_bytes(), name


@pytest.mark.parametrize(("header", "written", "note"), [
    ("Quiz 1 (12346)", "Homework 3", "export.csv: no column 'Homework 3 (id)'; canvas.csv's column is titled "
                                     "'Homework 3': Canvas updates the published assignment of exactly that "
                                     "title, or creates one"),
    ("homework  3 (12345)", "homework  3 (12345)", "export.csv: the column 'homework  3 (12345)' taken as the key's "
                                                   "assignment 'Homework 3' (the titles differ in case or spacing)"),
    ("Homework 3 (12345)", "Homework 3 (12345)", "export.csv: Canvas gives 'Homework 3 (12345)' 20 points possible, "
                                                 "the key's students can earn 10: canvas.csv keeps Canvas' 20; change "
                                                 "the assignment's points in Canvas, or the scores read as a fraction "
                                                 "of 20"),
])
def test_the_assignment_column_and_its_points_are_noted_when_they_do_not_fit(
        folder: Path, capsys: pytest.CaptureFixture[str], header: str, written: str, note: str) -> None:
    EXPORT.write_text(f"Student,ID,SIS User ID,SIS Login ID,Section,{header}\n"
                      "    Points Possible,,,,,20.00\n"
                      '"Doe, Jane",4321,00123,jdoe,Section 1,\n'
                      '"Stranger, Sam",4330,99999,sstranger,Section 2,7.50\n', encoding="utf-8")
    code, out, err = grade(capsys, "g", "--json")
    assert code == 0, err
    assert note in json.loads(out)["notes"]
    rows = cells(folder / "g" / "canvas.csv")
    assert rows[0][-1] == written
    kept = "" if header.startswith("Quiz") else "7.5"  # no column of the assignment: no score to keep
    assert rows[2:] == [["Doe, Jane", "4321", "00123", "jdoe", "Section 1", "10"],
                        ["Stranger, Sam", "4330", "99999", "sstranger", "Section 2", kept]]


def test_an_excused_student_and_a_second_row_of_one_student_keep_the_exports_cells(
        folder: Path, capsys: pytest.CaptureFixture[str]) -> None:
    EXPORT.write_text("Student,ID,SIS User ID,SIS Login ID,Section,Homework 3 (12345)\n"
                      '"Doe, Jane",4321,00123,jdoe,Section 1,EX\n'
                      '"Wei, Li",4322,,s2002,Section 1,3.00\n'
                      '"Wei, Li",4388,,li.wei@uni.edu,Section 2,\n', encoding="utf-8")
    assert grade(capsys)[0] == 0
    assert [row[-1] for row in cells(folder / "g" / "canvas.csv")[2:]] == ["EX", "4", ""]
    reasons = [(row[1], row[2], row[4]) for row in cells(folder / "g" / "problems.csv")[1:3]]
    assert reasons == [("2", "00123", "excused (EX) in Canvas: EX kept, the key's score not written"),
                       ("4", "s2002", "names the key student s2002, as line 3 does: no score written, the export's "
                                      "cell kept")]


def test_scores_of_400_digits_are_kept_as_text_never_infinite(folder: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A kept score read as a float was infinite: writing canvas.csv stopped with a traceback; the points
    possible were noted as "inf"."""
    huge = "9" * 400
    EXPORT.write_text("Student,ID,SIS User ID,SIS Login ID,Section,Homework 3 (12345)\n"
                      f"    Points Possible,,,,,{huge}\n"
                      '"Doe, Jane",4321,00123,jdoe,Section 1,\n'
                      f'"Stranger, Sam",4330,99999,sstranger,Section 2,{huge}\n', encoding="utf-8")
    code, out, err = grade(capsys, "g", "--json")
    assert code == 0, err
    assert cells(folder / "g" / "canvas.csv")[-1][-1] == huge
    assert not any("inf" in note for note in json.loads(out)["notes"])


def test_a_row_with_more_cells_than_the_header_is_left_out_and_said_so(folder: Path,
                                                                      capsys: pytest.CaptureFixture[str]) -> None:
    EXPORT.write_text("Student;ID;SIS User ID;SIS Login ID;Section;Homework 3 (12345)\n"
                      '"Doe, Jane";4321;00123;jdoe;Section 1;\n'
                      '"Wei, Li";4322;;s2002;Section 1;3,50;extra\n'
                      '"Stranger; Sam";4330;99999;sstranger;Section 2;7,50\n', encoding="utf-8")
    assert grade(capsys)[0] == 0
    assert [row[0] for row in cells(folder / "g" / "canvas.csv")[2:]] == ["Doe, Jane", "Stranger; Sam"]
    assert cells(folder / "g" / "canvas.csv")[-1][-1] == "7.5"  # the decimal comma read as Canvas' import reads it
    assert cells(folder / "g" / "problems.csv")[1] == [
        "export.csv", "3", "s2002", "", "7 cells, but the header has 6 columns; expected one cell per column: left "
                                        "out of canvas.csv"]


@pytest.mark.parametrize(("header", "row"), [
    ("LastName,FirstName,ID,SIS Login ID,Section", "Doe,Jane,4321,jane.doe@uni.edu,Section 1"),
    ("Student,ID,SIS User ID,SIS Login ID,Integration ID,Root Account,Section",
     '"Doe, Jane",4321,00123,jdoe,int-9,uni.instructure.com,Section 1'),
])
def test_the_exports_own_student_columns_are_written_in_canvas_order(
        folder: Path, capsys: pytest.CaptureFixture[str], header: str, row: str) -> None:
    """Names as LastName and FirstName, no SIS User ID (a teacher without SIS rights), Integration ID and
    Root Account: Canvas' import reads these columns by position."""
    EXPORT.write_text(f"{header},Homework 3 (12345)\n{row},\n", encoding="utf-8")
    assert grade(capsys)[0] == 0
    assert cells(folder / "g" / "canvas.csv")[::2] == [f"{header},Homework 3 (12345)".split(","),
                                                      [*next(csv.reader([row])), "10"]]


@pytest.mark.parametrize(("text", "message"), [
    (None, "export.csv: cannot read"),
    ("student_id,label,answer\n00123,1a,6.26\n", "export.csv: line 1: expected a Canvas gradebook export (Grades > "
                                                 "Export) with the columns Student (or LastName and FirstName), ID, "
                                                 "SIS Login ID and Section; got the columns ['student_id', 'label', "
                                                 "'answer']"),
    ("Student,ID,SIS User ID,Section,Homework 3 (12345)\n", "expected a Canvas gradebook export"),
    ("Student,ID,SIS User ID,SIS Login ID,Section,Homework 3 (12345)\n    Points Possible,,,,,10\n",
     "export.csv: no student rows; expected a Canvas gradebook export"),
    ('Student,ID,SIS User ID,SIS Login ID,Section,Homework 3 (12345)\n"Roe, Al",7,555,aroe,S1,\n',
     "export.csv: none of its 1 students is in the key key.json (by ID, SIS User ID, SIS Login ID or a name of one "
     "key student); expected the Canvas gradebook export of this assignment's course"),
    ('Student,ID,SIS User ID,SIS Login ID,Section,Homework 3 (1),Homework 3 (2)\n"Doe, Jane",1,00123,jdoe,S1,,\n',
     "export.csv: line 1: the columns 'Homework 3 (1)' and 'Homework 3 (2)' both have the key's assignment title "
     "'Homework 3'; expected one"),
    ('Student,ID,SIS Login ID,Section\n"Doe, Jane,1,jdoe,S1\n', "export.csv: line 2: unexpected end of data"),
])
def test_an_unusable_export_exits_2_and_writes_nothing(folder: Path, capsys: pytest.CaptureFixture[str],
                                                       text: str | None, message: str) -> None:
    if text is not None:
        EXPORT.write_text(text, encoding="utf-8")
    code, out, err = grade(capsys)
    assert (code, out) == (2, "") and message in err, err
    assert not (folder / "g").exists()
