"""``canvas.csv`` as Canvas' gradebook import reads it (issue 31): Canvas exports are built as its exporter
writes them, ``grader grade`` writes ``canvas.csv`` on them, and the file is uploaded to a model of Canvas'
importer and upload page (``tests/canvas_model.py``, whose docstring quotes the canvas-lms lines it
follows). The expected grades are read off the fixtures: the key's parts are 1a (4 points) and 1b (6
points), answered right or not at all."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest

from grader.cli import main
from tests.canvas_model import Assignment, Course, Layout, Student, export, import_file

TITLE = "@Home Lab 7: Impact"  # starts with @: a spreadsheet's formula, Canvas' plain title
# (key id, name, email, answers: 1a right is 4 points, 1b right is 6)
KEY = [
    ("00123", "Jane Doe", "jane.doe@uni.edu", {"1a": "6.26", "1b": "0.5"}),  # 10, by SIS User ID
    ("2026174", "Priya Raman", "priya.raman@uni.edu", {"1a": "6.26"}),  # 4, by name: no SIS id, username login
    ("-2026175", "Eve Adams", "+eve@uni.edu", {"1b": "0.5"}),  # 6, by SIS User ID starting with -
    ("=1+1", "Ana Ruiz", "ana.ruiz@uni.edu", {"1a": "6.26", "1b": "0.5"}),  # 10, by SIS User ID starting with =
    ("s2004", "Omar Haddad", "omar.haddad@uni.edu", {}),  # nothing; Canvas has 8 for him
    ("s2005", "Sam Lee", "sam.lee@uni.edu", {"1a": "6.26"}),  # excused in Canvas
    ("s2006", "Kim Park", "kim.park@uni.edu", {}),  # nothing; no grade in Canvas
    ("s2007", "Noah Kim", "noah.kim@uni.edu", {"1a": "6.26"}),  # not assigned in Canvas (N/A)
]


def course(posting: str = "", points: float = 10.0) -> Course:
    """The Canvas course of the key's students, and one not in the key (Sam Stone, 7.5)."""
    return Course([
        Student(101, "Jane Doe", "Doe, Jane", "00123", "jdoe"),
        Student(102, "Priya Raman", "Raman, Priya", None, "praman"),
        Student(103, "Eve Adams", "Adams, Eve", "-2026175", "+eve@uni.edu", integration_id="@int-3"),
        Student(104, "Ana Ruiz", "Ruiz, Ana", "=1+1", "aruiz"),
        Student(105, "Omar Haddad", "Haddad, Omar", "s2004", "ohaddad", grade=8.0),
        Student(106, "Sam Lee", "Lee, Sam", "s2005", "slee", grade="EX"),
        Student(107, "Kim Park", "Park, Kim", "s2006", "kpark"),
        Student(108, "Noah Kim", "Kim, Noah", "s2007", "nkim", assigned=False),
        Student(109, "Sam Stone", "Stone, Sam", "s9999", "sstone", grade=7.5),
    ], [Assignment(555, TITLE, points, posting=posting), Assignment(556, "Quiz 1", 5.0)])


def key_document(students: list[tuple[str, str, str, dict[str, str]]]) -> dict[str, object]:
    tolerance = {"mode": "rtol", "rtol": 0.01, "atol": 0}
    parts = {"speed": ("1a", 6.26, 4), "ratio": ("1b", 0.5, 6)}
    answers = {name: {"value": value, "unit": "", "label": label, "points": points, "tolerance": tolerance}
               for name, (label, value, points) in parts.items()}
    return {"schema": "grader-key", "version": 2, "assignment": {"title": TITLE},
            "problems": [{"key": "1", "title": "Drop", "answers": [
                {"name": name, "label": label, "unit": "", "points": points}
                for name, (label, _, points) in parts.items()]}],
            "students": [{"id": sid, "name": name, "email": email, "section": "1",
                          "problems": [{"key": "1", "answers": answers}]} for sid, name, email, _ in students]}


@pytest.fixture
def folder(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.chdir(tmp_path)
    write_key(tmp_path, KEY)
    return tmp_path


def write_key(folder: Path, students: list[tuple[str, str, str, dict[str, str]]]) -> None:
    (folder / "key.json").write_text(json.dumps(key_document(students)), encoding="utf-8")
    with open(folder / "answers.csv", "w", encoding="utf-8", newline="") as stream:
        writer = csv.writer(stream)
        writer.writerow(["student_id", "label", "answer"])
        writer.writerows([sid, label, text] for sid, _, _, answers in students for label, text in answers.items())


def grade(capsys: pytest.CaptureFixture[str], *extra: str) -> tuple[int, list[str], str]:
    """Exit code, notes and stderr of ``grader grade`` into ``g``."""
    code = main(["grade", "--key", "key.json", "answers.csv", "--out", "g", "--json", *extra])
    captured = capsys.readouterr()
    return code, json.loads(captured.out)["notes"] if code in (0, 3) else [], captured.err


def table(path: Path) -> list[list[str]]:
    with open(path, encoding="utf-8", newline="") as stream:
        return list(csv.reader(stream))


LAYOUTS = {
    "Student, ID, SIS User ID, SIS Login ID, Section": Layout(),
    "LastName, FirstName": Layout(first_last=True),
    "Integration ID and Root Account": Layout(integration_id=True, root_account=True),
    "; with decimal commas": Layout(decimal_comma=True),
}


@pytest.mark.parametrize("layout", LAYOUTS.values(), ids=LAYOUTS.keys())
def test_canvas_imports_each_key_score_to_its_student_and_changes_nothing_else(
        folder: Path, capsys: pytest.CaptureFixture[str], layout: Layout) -> None:
    """Uploaded to Canvas, ``canvas.csv`` updates assignment 555 (``parse_assignments``: the id of
    ``Title (id)``) and posts exactly the key's scores: Jane, Eve and Ana by SIS User ID (``-2026175`` and
    ``=1+1`` written as they are: ``process_student`` looks them up as exact hash keys), Priya by name
    (no SIS id, a username login: ``s.name == name || s.sortable_name == name``), Kim's 0 (no grade in
    Canvas); Omar's 8 (he submitted nothing), Sam's EX, Noah's N/A and the stranger's 7.50 are left as
    Canvas has them. No row is new to Canvas, the points possible do not change, and no BOM precedes
    ``LastName`` (``row[0] == "LastName"``)."""
    Path("export.csv").write_text(export(course(), layout), encoding="utf-8")
    code, notes, err = grade(capsys, "--canvas", "export.csv")
    assert code == 0, err
    written = Path("g/canvas.csv").read_text(encoding="utf-8")
    uploaded = import_file(written, course())
    assert (uploaded.assignment, uploaded.unknown, uploaded.points_changed) == (555, [], False)
    assert uploaded.posted == {101: "10", 102: "4", 103: "6", 104: "10", 107: "0"}
    assert not written.startswith("\ufeff")
    assert "export.csv: of the key's students who submitted nothing, 1 got 0 (the export shows no grade for them), " \
           "1 kept the grade the export shows (--missing zero writes 0)" in notes


def test_a_student_matched_by_name_is_one_caveat_not_two_contradicting_rows(
        folder: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Priya has no SIS User ID and the login ``praman``: she was "not in the key" and "not in the export"
    at once, and her score never reached Canvas. Now one caveat says the match was by name; Sam Stone, whom
    the key lacks, is the only Canvas student not in the key; Sam Lee's EX and Noah's N/A are said."""
    Path("export.csv").write_text(export(course(), Layout()), encoding="utf-8")
    assert grade(capsys, "--canvas", "export.csv")[0] == 0
    problems = {(row[1], row[2]): row[4] for row in table(Path("g/problems.csv"))[1:]}
    assert problems == {
        ("4", "2026174"): "matched by name, 'Raman, Priya' is the key's Priya Raman: no ID, SIS User ID or SIS Login "
                          "ID of the row is the key's; check it is the same student",
        ("8", "s2005"): "excused (EX) in Canvas: EX kept, the key's score not written",
        ("10", "s2007"): "N/A in Canvas: the assignment is not assigned to this student, and Canvas ignores a score "
                         "for them: N/A kept, the key's score not written",
        ("11", "s9999"): "Canvas student 'Stone, Sam' is not in the key (by ID, SIS User ID, SIS Login ID or a name "
                         "of one key student): no score written, the export's cell kept",
    }


def test_a_name_two_key_students_share_matches_nobody(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                      capsys: pytest.CaptureFixture[str]) -> None:
    """Canvas takes the first student of a name; grader matches by name only a name of one key student, and
    says why a row was not matched, and on which line the missing key students' name is."""
    monkeypatch.chdir(tmp_path)
    write_key(tmp_path, [("00123", "Jane Doe", "jane.doe@uni.edu", {"1a": "6.26"}),
                         ("s1", "Li Wei", "li1@uni.edu", {"1a": "6.26"}), ("s2", "Li Wei", "li2@uni.edu", {})])
    Path("export.csv").write_text('Student,ID,SIS User ID,SIS Login ID,Section,@Home Lab 7: Impact (555)\n'
                                  '"Doe, Jane",101,00123,jdoe,S1,\n"Wei, Li",102,,lwei,S1,3.00\n', encoding="utf-8")
    assert grade(capsys, "--canvas", "export.csv")[0] == 0
    assert table(Path("g/canvas.csv"))[2:] == [["Doe, Jane", "101", "00123", "jdoe", "S1", "4"],
                                               ["Wei, Li", "102", "", "lwei", "S1", "3"]]
    reasons = [row[4] for row in table(Path("g/problems.csv"))[1:]]
    assert reasons[0].startswith("Canvas student 'Wei, Li' is not in the key (by ID, SIS User ID, SIS Login ID or "
                                 "a name of one key student); its name is 2 key students' (s1, s2), so it is not "
                                 "matched by name")
    assert [reason.split(": ")[0] for reason in reasons[1:]] == [
        "in the key but not in the Canvas export (by ID, SIS User ID, SIS Login ID or a name of one key student); "
        "line 3 has their name, not matched by it (see that line)"] * 2


@pytest.mark.parametrize(("missing", "posted", "said"), [
    ("zero", {105: "0", 107: "0"}, "2 got 0 (--missing zero)"),  # Omar's 8 replaced; Sam's EX never
    ("blank", {}, "1 kept the grade the export shows, 1 got no score (--missing blank)"),
])
def test_missing_zero_or_blank_is_the_instructors_choice_and_ex_is_never_overwritten(
        folder: Path, capsys: pytest.CaptureFixture[str], missing: str, posted: dict[int, str], said: str) -> None:
    """``--missing``: 0 for who submitted nothing, or the export's own cell; ``EX`` is kept either way."""
    Path("export.csv").write_text(export(course(), Layout()), encoding="utf-8")
    code, notes, err = grade(capsys, "--canvas", "export.csv", "--missing", missing)
    assert code == 0, err
    uploaded = import_file(Path("g/canvas.csv").read_text(encoding="utf-8"), course())
    assert uploaded.posted == {101: "10", 102: "4", 103: "6", 104: "10", **posted}
    assert f"export.csv: of the key's students who submitted nothing, {said}" in notes


@pytest.mark.parametrize(("missing", "posted"), [(None, {105: "0", 106: "4", 107: "0"}),
                                                 ("blank", {105: "", 106: "4"})])
def test_without_an_export_the_note_says_how_canvas_will_match_and_recommends_canvas(
        folder: Path, capsys: pytest.CaptureFixture[str], missing: str | None, posted: dict[int, str]) -> None:
    """Without an export Canvas finds the assignment among published ones by its exact title (``a.title ==
    name_and_id``): ``@Home Lab 7: Impact`` unguarded is assignment 555, not a new one. Students are found
    by SIS User ID, then login, then name (Priya). Who submitted nothing gets 0, which replaces Omar's 8 and
    Sam's EX, as the note says (or, ``--missing blank``, an empty cell that removes Omar's 8)."""
    code, notes, err = grade(capsys, *(["--missing", missing] if missing else []))
    assert code == 0, err
    uploaded = import_file(Path("g/canvas.csv").read_text(encoding="utf-8"), course())
    assert (uploaded.assignment, uploaded.unknown) == (555, [])
    assert uploaded.posted == {101: "10", 102: "4", 103: "6", 104: "10", **posted}
    assert ("canvas.csv, made without a Canvas export: Canvas updates only a published assignment titled exactly "
            "'@Home Lab 7: Impact' (else it creates one), and finds students by SIS User ID (the key's ids), SIS "
            "Login ID (emails), then name; to update the assignment by its id and keep grades Canvas has, grade with "
            "--canvas EXPORT.csv (Canvas: Grades > Export)") in notes
    assert any(note.startswith("canvas.csv: 2 students submitted nothing and got ") for note in notes)


def test_points_possible_are_the_exports_own_and_a_difference_is_noted(
        folder: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Canvas has 20 points possible, the key 10: writing 10 would mark the assignment as changed
    (``process_pp``), which the upload page never saves. canvas.csv keeps 20, and a note says so."""
    Path("export.csv").write_text(export(course(points=20.0), Layout(decimal_comma=True)), encoding="utf-8")
    code, notes, err = grade(capsys, "--canvas", "export.csv")
    assert code == 0, err
    assert table(Path("g/canvas.csv"))[1] == ["Points Possible", "", "", "", "", "20"]
    assert not import_file(Path("g/canvas.csv").read_text(encoding="utf-8"), course(points=20.0)).points_changed
    assert ("export.csv: Canvas gives '@Home Lab 7: Impact (555)' 20 points possible, the key's students can earn 10: "
            "canvas.csv keeps Canvas' 20; change the assignment's points in Canvas, or the scores read as a fraction "
            "of 20") in notes


def test_scores_hidden_from_instructors_keep_the_exports_cells_and_are_said(
        folder: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Anonymous grades not yet posted: the exporter writes ``Manual Posting (scores hidden from instructors)``
    and N/A for everyone, and the importer refuses grades (``gradeable?``). canvas.csv keeps every cell."""
    hidden = course(posting="Manual Posting (scores hidden from instructors)")
    Path("export.csv").write_text(export(hidden, Layout()), encoding="utf-8")
    code, notes, err = grade(capsys, "--canvas", "export.csv")
    assert code == 0, err
    assert {row[-1] for row in table(Path("g/canvas.csv"))[2:]} == {"N/A"}
    assert import_file(Path("g/canvas.csv").read_text(encoding="utf-8"), hidden).posted == {}
    assert any("hides '@Home Lab 7: Impact (555)''s scores from instructors" in note for note in notes)


def test_plain_manual_posting_is_only_a_row_to_skip(folder: Path, capsys: pytest.CaptureFixture[str]) -> None:
    posted = course(posting="Manual Posting")
    Path("export.csv").write_text(export(posted, Layout()), encoding="utf-8")
    assert grade(capsys, "--canvas", "export.csv")[0] == 0
    uploaded = import_file(Path("g/canvas.csv").read_text(encoding="utf-8"), posted)
    assert uploaded.posted == {101: "10", 102: "4", 103: "6", 104: "10", 107: "0"}


def test_a_decimal_comma_score_kept_from_the_export_is_a_plain_number(
        folder: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """``decimal_comma_to_period`` reads ``7,50`` as 7.50: canvas.csv writes 7.5, not the export's text."""
    Path("export.csv").write_text(export(course(), Layout(decimal_comma=True)), encoding="utf-8")
    assert grade(capsys, "--canvas", "export.csv")[0] == 0
    rows = {row[2]: row[-1] for row in table(Path("g/canvas.csv"))[2:]}
    assert (rows["s9999"], rows["s2004"], rows["s2005"], rows["s2007"]) == ("7.5", "8", "EX", "N/A")


@pytest.mark.parametrize(("text", "message"), [
    (b"Student,ID,SIS Login ID,Section,X (1)\n\"Doe, Jane\",1,jdoe,S1,\x00\n", "line 2: expected text, got a NUL"),
    (b"Student,ID,ID,SIS Login ID,Section\n", "line 1: the column 'ID' appears twice"),
    (b"Student,ID,SIS Login ID,Section,X (1)\n\"Doe, Jane,1,jdoe,S1,\n", "line 2: unexpected end of data"),
    ("Student,ID,SIS Login ID,Section\n".encode("utf-16-le"), "UTF-16LE text without a byte-order mark"),
    (b"Student,ID,SIS Login ID,Section," + b"x" * 2000 + b"\n", "line 1: a cell of 2,000 characters"),
    (b"Student,ID,SIS Login ID,Section\n    Points Possible,,,\n", "no student rows"),
    (b"\xff\xfe\x00", "export.csv: byte offset 2: expected UTF-16 text after the UTF-16 byte-order mark"),
    (b"Student,ID,SIS Login ID,Section\n;;;,,,\n", "export.csv: no student rows"),  # Canvas skips ;;;,,,
])
def test_a_malformed_export_exits_2_with_a_clear_message(folder: Path, capsys: pytest.CaptureFixture[str],
                                                         text: bytes, message: str) -> None:
    Path("export.csv").write_bytes(text)
    code, _, err = grade(capsys, "--canvas", "export.csv")
    assert code == 2 and message in err and "Traceback" not in err, err
    assert not Path("g").exists()


def test_a_key_of_canvas_ids_matches_by_id_first(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                 capsys: pytest.CaptureFixture[str]) -> None:
    """``process_student`` looks a row up by ``ID`` before anything else: a roster of Canvas ids matches
    by it, whatever the SIS columns say (here another key student's SIS User ID, on a later row)."""
    monkeypatch.chdir(tmp_path)
    write_key(tmp_path, [("101", "Jane Doe", "jane.doe@uni.edu", {"1a": "6.26"}),
                         ("102", "Li Wei", "li.wei@uni.edu", {"1b": "0.5"})])
    Path("export.csv").write_text('Student,ID,SIS User ID,SIS Login ID,Section,@Home Lab 7: Impact (555)\n'
                                  '"Doe, Jane",101,102,jdoe,S1,\n"Wei, Li",102,,lwei,S1,\n', encoding="utf-8")
    assert grade(capsys, "--canvas", "export.csv")[0] == 0
    assert [row[-1] for row in table(Path("g/canvas.csv"))[2:]] == ["4", "6"]
    assert table(Path("g/problems.csv"))[1:] == []
