"""Each student's graded sheet handed back (``grader grade --feedback``, and the demo's ``grades/feedback/``):
a file per student of the key and an index; in each, the student's own verdicts, sentences, expected values and
worked solutions, and nothing of anyone else's (every file is searched for every other student's id, name and
email); no notes meant for the instructor; the HTML page escapes what it shows, loads nothing, and a browser
draws it."""

from __future__ import annotations

import csv
import html
import json
import re
import shutil
import subprocess
import unicodedata
from collections.abc import Callable, Sequence
from pathlib import Path

import pytest

from grader.assign.assignment import load_assignment
from grader.assign.sample_answers import sample_answers, submissions_csv
from grader.bank.template import Template
from grader.base.resources import sample_dir
from grader.cli import main
from grader.render.generate import Job, load_inputs, write_outputs
from tests.demo_output import DemoRun

# What only the instructor sees: the key's cover, the rows' sources, integrity findings (integrity.csv).
INSTRUCTOR_ONLY = ("For the instructor only", "submissions.csv", "integrity", "problems.csv", "details.csv")


def pdf_text(path: Path) -> str:
    """A PDF's text, its runs of white space made one space and its characters composed (NFC)."""
    if shutil.which("pdftotext"):
        found = subprocess.run(["pdftotext", "-enc", "UTF-8", str(path), "-"], capture_output=True, check=True,
                               timeout=60).stdout.decode("utf-8")
    else:
        from pypdf import PdfReader

        found = " ".join(page.extract_text() for page in PdfReader(path).pages)
    return unicodedata.normalize("NFC", re.sub(r"\s+", " ", found))


def page_text(path: Path) -> str:
    """An HTML page's text as a reader sees it: tags dropped, entities read."""
    return unicodedata.normalize("NFC", html.unescape(re.sub(r"<[^>]*>", " ", path.read_text(encoding="utf-8"))))


def index_rows(folder: Path) -> list[dict[str, str]]:
    with open(folder / "index.csv", encoding="utf-8", newline="") as stream:
        return list(csv.DictReader(stream))


def roster(path: Path) -> list[dict[str, str]]:
    with open(path, encoding="utf-8", newline="") as stream:
        return list(csv.DictReader(stream))


def leaks(folder: Path, people: Sequence[dict[str, str]], read: Callable[[Path], str]) -> list[str]:
    """Every other student's id, name or email found in a student's file; each file must show its own name
    and id (so that finding nothing means something)."""
    found = []
    files = {row["id"]: folder / row["file"] for row in index_rows(folder)}
    for person in people:
        text = read(files[person["id"]])
        if person["name"] not in text or person["id"] not in text:
            found.append(f"{person['id']}: its own name or id is not in its file")
        for other in people:
            if other is not person:
                found += [f"{person['id']}: {other[field]}" for field in ("id", "name", "email")
                          if other[field] and unicodedata.normalize("NFC", other[field]) in text]
        found += [f"{person['id']}: {words}" for words in INSTRUCTOR_ONLY if words in text]
    return found


@pytest.fixture(scope="module")
def feedback(demo_run: DemoRun) -> Path:
    assert demo_run.code == 0, demo_run.stderr
    return demo_run.out / "grades" / "feedback"


def test_every_student_of_the_key_has_a_file_and_a_row_of_the_index(feedback: Path, demo_run: DemoRun) -> None:
    people = roster(demo_run.out / "roster.csv")
    rows = index_rows(feedback)
    assert list(rows[0]) == ["id", "name", "email", "file", "total"]
    assert [(r["id"], r["name"], r["email"]) for r in rows] == [(p["id"], p["name"], p["email"]) for p in people]
    assert sorted(p.name for p in feedback.iterdir()) == sorted([*(r["file"] for r in rows), "index.csv"])
    grades = {row["student_id"]: row["total"] for row in roster(demo_run.out / "grades" / "grades.csv")}
    assert {r["id"]: r["total"] for r in rows} == grades


def test_no_file_holds_anything_of_another_student_nor_the_instructors_notes(feedback: Path,
                                                                              demo_run: DemoRun) -> None:
    assert leaks(feedback, roster(demo_run.out / "roster.csv"), pdf_text) == []


def test_a_sheet_shows_what_was_typed_read_the_verdicts_sentences_and_the_worked_solutions(feedback: Path) -> None:
    """Yara Mansour (2026988) of the demo: 15 of 28; 3c right for her wrong 3a (error carried forward); 4b the
    angle in radians; then her worked solutions, as the answer key has them. Another student's 5d (oblique-spheres'
    loss) has its tolerance widened, with why."""
    text = pdf_text(feedback / "2026988.pdf")
    for shown in ("Total: 15 of 28 points", "Name Yara Mansour", "ID 2026988 Section L01",
                  "You typed 16.3 km/h read as 4.52778 m/s",
                  "velocity of the pile just after the impact incorrect · 0 of 2 points",
                  "correct for your earlier answer (error carried forward) · 2 of 2 points",
                  "right for your 3a = 2.12 m/s (error carried forward); with 3a = 2.54838 m/s, 3c is 39.3093 %",
                  "a common mistake · 0 of 2 points",
                  "your answer matches the angle in radians where degrees were asked",
                  "Expected 23.171° accepted ±1 %",
                  "Pile driver ram striking a pile", "Given:",
                  "not answered · 0 of 2 points You typed nothing the answer was blank"):  # her blank 3b
        assert shown in text, shown
    widened = "accepted ±1.1 %: rounding T to 4 figures along the worked solution moves loss_pct by up to 0.41 %"
    assert widened in pdf_text(feedback / "2026174.pdf")


def test_every_page_has_the_students_own_footer_the_worked_solutions_too(feedback: Path) -> None:
    """The worked solutions' pages are the student's file's, not the answer key's: each page of Ben O'Brien's file
    ends with his name and id and "page k of n" of that file."""
    from pypdf import PdfReader

    pages = [re.sub(r"\s+", " ", page.extract_text()) for page in PdfReader(feedback / "2026137.pdf").pages]
    assert len(pages) > 3 and any("Given:" in page for page in pages)
    for number, page in enumerate(pages, start=1):
        assert "Ben O'Brien (2026137) · Homework 7: Impact, graded" in page, number
        assert f"page {number} of {len(pages)}" in page, number
        assert "answer key" not in page, number


def test_each_part_is_described_as_the_students_sheet_describes_it(feedback: Path, demo_run: DemoRun,
                                                                    bank: dict[str, Template]) -> None:
    """What a part asks reads as on the sheet the student answered (car-collision's 2c, "car A's velocity ... as
    a fraction of v", printed on both as the template words it)."""
    key = json.loads((demo_run.out / "key.json").read_text(encoding="utf-8"))
    sheet, marked = pdf_text(demo_run.out / "students" / "2026137.pdf"), pdf_text(feedback / "2026137.pdf")
    problems = next(s for s in key["students"] if s["id"] == "2026137")["problems"]
    parts = [(answer["label"], bank[problem["template"]].answers[name].description)
             for problem in problems for name, answer in problem["answers"].items()]
    assert ("2c", "car A's velocity just after the impact as a fraction of v, for the given p") in parts
    for label, description in parts:
        assert description in sheet and description in marked, (label, description)


def test_who_submitted_nothing_gets_the_sheet_the_expected_values_and_the_worked_solutions(feedback: Path) -> None:
    absent = [row for row in index_rows(feedback) if "No answers were received" in pdf_text(feedback / row["file"])]
    assert [row["total"] for row in absent] == ["0"]
    text = pdf_text(feedback / absent[0]["file"])
    assert text.count("not answered · 0 of") == 15 and "You typed nothing" in text
    assert "Problem 5: Oblique impact of two spheres" in text and "Given:" in text


def test_the_late_resubmission_says_how_late(feedback: Path, demo_run: DemoRun) -> None:
    """Zoë Keller (2027025) resubmitted 1a 127 minutes after the due time; the demo has no late policy."""
    late = {row["student_id"]: row["late"] for row in roster(demo_run.out / "grades" / "grades.csv")
            if row["late"] not in ("", "0")}
    assert late == {"2027025": "127"}
    said = [row["id"] for row in index_rows(feedback) if "Your answers came" in pdf_text(feedback / row["file"])]
    assert said == ["2027025"]
    assert "Your answers came 2 h 7 min late." in pdf_text(feedback / "2027025.pdf")


@pytest.fixture(scope="module")
def hostile(demo_run: DemoRun, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The demo's key with a student named as markup, and a submission typing markup: graded to HTML pages."""
    folder = tmp_path_factory.mktemp("hostile")
    key = json.loads((demo_run.out / "key.json").read_text(encoding="utf-8"))
    key["students"][0]["name"] = '<script>alert(1)</script> <img src="https://x.invalid/a.png"> & "Ana"'
    (folder / "key.json").write_text(json.dumps(key), encoding="utf-8")
    first = key["students"][0]["id"]
    (folder / "answers.csv").write_text(
        f'student_id,label,answer\n{first},1a,"<b onclick=alert(1)>0.47</b>"\n{first},1b,77.5 %\n', encoding="utf-8")
    assert main(["grade", "--key", str(folder / "key.json"), str(folder / "answers.csv"), "--out",
                 str(folder / "grades"), "--feedback-format", "html"]) == 0
    return folder / "grades" / "feedback"


def test_the_html_page_escapes_what_it_shows_and_loads_nothing(hostile: Path) -> None:
    first = index_rows(hostile)[0]
    assert first["file"].endswith(".html")
    page = (hostile / first["file"]).read_text(encoding="utf-8")
    assert "&lt;script&gt;alert(1)&lt;/script&gt;" in page and "&lt;b onclick=alert(1)&gt;0.47&lt;/b&gt;" in page
    assert "<script" not in page and "onclick=alert" not in page.replace("&lt;b onclick=alert(1)&gt;", "")
    assert not re.search(r"""(src|href)\s*=\s*["']?(https?:|//|data:|file:)""", page)
    assert "<link" not in page and "@import" not in page and "url(" not in page
    assert "default-src 'none'" in page
    text = page_text(hostile / first["file"])
    assert "could not be read" in text or "incorrect" in text
    assert "No answers were received" in page_text(hostile / index_rows(hostile)[1]["file"])


def test_the_html_pages_hold_nothing_of_another_student(hostile: Path, demo_run: DemoRun) -> None:
    people = roster(demo_run.out / "roster.csv")
    people[0] = {**people[0], "name": '<script>alert(1)</script> <img src="https://x.invalid/a.png"> & "Ana"'}
    assert leaks(hostile, people, page_text) == []


def test_html_pages_are_the_same_bytes_when_graded_again(hostile: Path) -> None:
    before = {path.name: path.read_bytes() for path in hostile.iterdir()}
    folder = hostile.parent.parent
    assert main(["grade", "--key", str(folder / "key.json"), str(folder / "answers.csv"), "--out",
                 str(folder / "grades"), "--feedback-format", "html", "--force"]) == 0
    assert {path.name: path.read_bytes() for path in hostile.iterdir()} == before


def test_a_key_whose_template_cannot_be_found_is_refused_and_nothing_is_written(
        demo_run: DemoRun, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    key = json.loads((demo_run.out / "key.json").read_text(encoding="utf-8"))
    key["templates"]["drop-rebound"]["sha256"] = "0" * 64
    (tmp_path / "key.json").write_text(json.dumps(key), encoding="utf-8")
    assert main(["grade", "--key", str(tmp_path / "key.json"), str(demo_run.out / "submissions.csv"), "--out",
                 str(tmp_path / "grades"), "--feedback"]) == 2
    assert "problem 1: template drop-rebound in the problem bank has changed since the key was written" in \
        capsys.readouterr().err
    assert not (tmp_path / "grades").exists()


@pytest.mark.skipif(shutil.which("chromium") is None, reason="no chromium")
def test_a_browser_draws_the_html_page(hostile: Path, tmp_path: Path) -> None:
    """Headless Chromium opens a page offline and draws it: the screenshot is not blank."""
    page = hostile / index_rows(hostile)[2]["file"]
    shot = tmp_path / "page.png"
    subprocess.run(["chromium", "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
                    f"--user-data-dir={tmp_path / 'profile'}", "--window-size=1000,1400",
                    f"--screenshot={shot}", page.as_uri()], capture_output=True, timeout=120, check=False)
    from PIL import Image

    image = Image.open(shot).convert("L")
    assert image.size == (1000, 1400)
    low, high = image.getextrema()
    assert low < 100 and high > 200  # text on a white page
    dark = sum(image.histogram()[:128])
    assert dark > 2000


@pytest.mark.slow
def test_a_class_of_2000_gets_its_feedback_and_no_file_holds_another_students_anything(
        bank: dict[str, Template], tmp_path: Path) -> None:
    """2,000 students, generated, answering as the demo's class does, graded with --feedback (PDF): every file is
    searched for every other student's id, name and email (by their forms: ``00042x``, ``Given0042``,
    ``p0042@``), and each shows its own."""
    people = [{"id": f"{i:05d}x", "name": f"Given{i:04d} Family{i:04d}", "email": f"p{i:04d}@example.edu",
               "section": "L01"} for i in range(2000)]
    roster_path = tmp_path / "roster.csv"
    with open(roster_path, "w", encoding="utf-8", newline="") as stream:
        writer = csv.DictWriter(stream, ["id", "name", "email", "section"])
        writer.writeheader()
        writer.writerows(people)
    job = Job(sample_dir() / "assignment.yaml", roster_path, tmp_path / "hw", pdf=False)
    assignment, students = load_inputs(job, bank)
    (tmp_path / "hw").mkdir()
    generation, _ = write_outputs(job, assignment, students, bank, tmp_path / "hw")
    (tmp_path / "answers.csv").write_text(
        submissions_csv(sample_answers(load_assignment(job.assignment), generation, bank)), encoding="utf-8")
    assert main(["grade", "--key", str(tmp_path / "hw" / "key.json"), str(tmp_path / "answers.csv"), "--out",
                 str(tmp_path / "grades"), "--feedback"]) in (0, 3)
    folder = tmp_path / "grades" / "feedback"
    files = {row["id"]: folder / row["file"] for row in index_rows(folder)}
    assert list(files) == [p["id"] for p in people]
    forms = re.compile(r"\d{5}x|Given\d{4}|Family\d{4}|p\d{4}@example\.edu")
    for number, person in enumerate(people):
        text = pdf_text(files[person["id"]])
        own = {person["id"], f"Given{number:04d}", f"Family{number:04d}", person["email"]}
        assert {person["id"], f"Given{number:04d}"} <= set(forms.findall(text)), person["id"]
        assert set(forms.findall(text)) <= own, (person["id"], set(forms.findall(text)) - own)
        assert not any(words in text for words in INSTRUCTOR_ONLY), person["id"]
