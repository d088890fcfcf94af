"""The class report (``report.html``): what it counts, what it lists, that every text from the key,
roster or submissions is shown as text, that a big class makes a page of bounded size, and that grading
never imports matplotlib (the figures are SVG text; ``test_report_plots.py`` checks what they draw). The
browser opens it in ``test_report_browser.py``."""

from __future__ import annotations

import dataclasses
import html
import json
import re
import subprocess
import sys
from collections.abc import Sequence
from html.parser import HTMLParser
from pathlib import Path

import pytest

from grader.grade import class_summary
from grader.grade.class_report import INVALID_STUDENTS, class_report
from grader.grade.class_summary import summarize
from grader.grade.grading import Graded, Row
from grader.grade.key import Key, KeyPart, KeyProblem, KeyStudent, load_key
from grader.grade.row_problems import RowProblem
from tests.demo_output import DemoRun

TOLERANCE = {"mode": "rtol", "rtol": 0.01, "atol": 0.0}
FEEDBACK = {"correct": "right", "incorrect": "wrong", "invalid": "could not read this answer: cannot read it",
            "missing": "no answer was submitted", "ecf": "right for your 1a", "mistake": "e² used for e"}
CREDIT = {"correct": 1.0, "ecf": 1.0}


def make_class(verdicts: dict[str, Sequence[str]], params: Sequence[dict[str, float]] | None = None,
               names: Sequence[str] | None = None, typed: str = "1.5", title: str = "HW 7",
               problem_title: str = "Drop", diagnoses: dict[str, Sequence[str]] | None = None) -> Graded:
    """One problem (key ``1``) whose parts are ``verdicts``' labels, a student per verdict; each student's
    printed parameters ``params``; ``diagnoses``: each row's diagnosis (default none)."""
    labels = tuple(verdicts)
    count = len(next(iter(verdicts.values())))
    students = []
    for index in range(count):
        printed = (params or [{}] * count)[index]
        parts = {label: KeyPart("1", f"answer_{label}", label, 1.5, "m/s", 2.0, TOLERANCE, None, {})
                 for label in labels}
        students.append(KeyStudent(f"s{index:05d}", (names or [f"Student {index}"] * count)[index], "", "L01", parts,
                                   tuple(("1", name) for name in printed), tuple(printed.values())))
    key = Key("key.json", 2, title, True, (KeyProblem("1", problem_title, labels),), tuple(students))
    columns = {}
    for label, kinds in verdicts.items():
        rows = []
        for index, kind in enumerate(kinds):
            submitted = None if kind == "missing" else typed
            diagnosis = diagnoses[label][index] if diagnoses is not None else ""
            rows.append(Row(submitted, kind, CREDIT.get(kind, 0.0), 2.0, "1.5", "", "m/s", None, None, "±1 %",
                            FEEDBACK.get(kind, kind), diagnosis, "a.csv:2"))
        columns[label] = rows
    return Graded(key, columns, (), (), ())


class Page(HTMLParser):
    """A page's tags, attributes and text, as a browser's parser reads them."""

    def __init__(self, text: str) -> None:
        super().__init__(convert_charrefs=True)
        self.tags: set[str] = set()
        self.attributes: list[tuple[str, str]] = []
        self.text: list[str] = []
        self.feed(text)

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        self.tags.add(tag)
        self.attributes += [(name, value or "") for name, value in attrs]

    def handle_data(self, data: str) -> None:
        self.text.append(data)


# Every element the page and its SVG figures use; nothing that runs, loads or links away.
ALLOWED_TAGS = {"html", "head", "meta", "title", "style", "body", "main", "header", "h1", "h2", "h3", "p", "div", "b",
                "span", "nav", "a", "table", "tbody", "tr", "th", "td", "small", "code", "i", "ul", "li",
                "svg", "path", "text", "rect", "circle"}


def test_every_verdict_kind_is_counted_even_when_nobody_got_it() -> None:
    graded = make_class({"1a": ["correct", "correct", "incorrect", "missing"],
                         "1b": ["correct", "invalid", "missing", "missing"]})
    summary = summarize(graded)
    assert summary.kinds == ("correct", "ecf", "mistake", "incorrect", "invalid", "missing")
    assert [part.counts for part in summary.parts] == [
        {"correct": 2, "ecf": 0, "mistake": 0, "incorrect": 1, "invalid": 0, "missing": 1},
        {"correct": 1, "ecf": 0, "mistake": 0, "incorrect": 0, "invalid": 1, "missing": 2}]
    assert summary.percent.tolist() == [100.0, 50.0, 0.0, 0.0]
    assert summary.submitted == 3
    assert [part.mean_credit for part in summary.parts] == [0.5, 0.25]
    headers = re.findall(r"</span>(\w+)</th>", class_report(graded))
    assert headers == ["correct", "ecf", "mistake", "incorrect", "invalid", "missing"]


def test_ecf_and_mistake_take_their_places_once_grading_has_them(monkeypatch: pytest.MonkeyPatch) -> None:
    """The merge with ECF and diagnosed mistakes: VERDICTS gains the kinds, the report shows them in the
    issue's order, with nothing else changed here."""
    monkeypatch.setattr(class_summary, "VERDICTS", ("correct", "ecf", "mistake", "incorrect", "invalid", "missing"))
    graded = make_class({"1a": ["mistake", "correct", "ecf", "missing"]})
    summary = summarize(graded)
    assert summary.kinds == ("correct", "ecf", "mistake", "incorrect", "invalid", "missing")
    assert summary.parts[0].counts == {"correct": 1, "ecf": 1, "mistake": 1, "incorrect": 0, "invalid": 0,
                                       "missing": 1}
    assert summary.parts[0].mean_credit == 0.5  # ecf earns credit 1 here
    assert re.findall(r"</span>(\w+)</th>", class_report(graded)) == list(summary.kinds)


def test_a_kind_verdicts_does_not_name_is_still_counted_after_the_others() -> None:
    summary = summarize(make_class({"1a": ["correct", "late"]}))
    assert summary.kinds[-1] == "late" and summary.parts[0].counts["late"] == 1


def test_no_diagnosis_means_no_mistakes_listed() -> None:
    graded = make_class({"1a": ["incorrect", "ecf"]}, diagnoses={"1a": ["", "ecf:1a"]})
    assert graded.columns["1a"][0].diagnosis == ""
    assert summarize(graded).parts[0].mistakes == ()
    assert "No answer was matched to a diagnosed mistake." in class_report(graded)


def test_diagnosed_mistakes_are_listed_most_frequent_first(monkeypatch: pytest.MonkeyPatch) -> None:
    """Each part lists its top diagnosed mistakes and counts."""
    found = ["e_squared"] * 4 + ["one_over_e"] * 2 + ["sign", "a", "b", "c"]
    graded = make_class({"1a": ["mistake"] * len(found) + ["correct"]}, diagnoses={"1a": [*found, ""]})
    part = summarize(graded).parts[0]
    assert part.mistakes == (("e_squared", 4), ("one_over_e", 2), ("a", 1), ("b", 1), ("c", 1))
    assert part.diagnosed == 10
    page = class_report(graded)
    assert "<code>e_squared</code></td><td class=\"n\">4</td>" in page
    assert "1a: 10 diagnosed in all" in page  # 9 of them listed


def test_diagnosed_mistakes_are_said_in_words_with_their_ids() -> None:
    """Issue 28: the report showed only ids (energy.kept_as_lost); it says each as the effect's list does."""
    graded = make_class({"1a": ["mistake", "mistake", "correct"]}, diagnoses={"1a": ["energy.kept_as_lost"] * 2 + [""]})
    words = "the energy kept (T') reported as the energy lost"
    graded = dataclasses.replace(graded, mistakes={("1a", "energy.kept_as_lost"): words})
    page = class_report(graded)
    assert f"<td>{html.escape(words)} <small class=\"muted\"><code>energy.kept_as_lost</code></small></td>" in page


def test_the_demo_report_says_its_mistakes_in_words_and_its_axes_units(demo_run: DemoRun) -> None:
    """Grading fills in each mistake's words from the templates' effects; each panel's axis names its
    parameter's unit, which the key records."""
    page = (demo_run.out / "grades" / "report.html").read_text(encoding="utf-8")
    assert "using e² instead of e <small class=\"muted\"><code>impact.e_squared</code></small>" in page
    assert "h_drop (mm)" in page  # a panel's axis, as SVG text
    assert load_key(demo_run.out / "key.json").problems[0].units == {"h_drop": "mm", "h_rebound": "mm"}


def test_the_rows_not_graded_are_named_with_their_reasons() -> None:
    """Issue 28: "1 submitted rows were not graded" named nobody; the first few are named, with the reason."""
    problems = tuple(RowProblem("a.csv", line, who, label, reason) for line, who, label, reason in [
        (4, "ann@x.edu", "", "unknown student 'ann@x.edu' (not in the answer key)"),
        (9, "s00001", "7z", "unknown label '7z' (expected one of 1a)"),
        *((10 + n, f"x{n}", "", f"unknown student 'x{n}' (not in the answer key)") for n in range(5))])
    graded = make_class({"1a": ["correct", "correct"]})
    one = class_report(dataclasses.replace(graded, problems=problems[:1]))
    assert ("1 submitted row was not graded (see problems.csv): unknown student &#x27;ann@x.edu&#x27; (not in the "
            "answer key) (a.csv line 4)</p>") in one
    many = class_report(dataclasses.replace(graded, problems=(
        *problems, RowProblem("a.csv", 0, "", "", "3 more rows …", rows=3))))
    assert ("10 submitted rows were not graded (see problems.csv): unknown student &#x27;ann@x.edu&#x27; (not in "
            "the answer key) (a.csv line 4); s00001: unknown label &#x27;7z&#x27; (expected one of 1a) (a.csv line 9)"
            ) in many
    assert "x2" in many and "x3" not in many and "; 5 more</p>" in many


HOSTILE = ["<script>alert(1)</script>", 'x" onerror="alert(1)', "<img src=x onerror=alert(1)>",
           "</title><svg onload=alert(1)>", "$\\alpha$ & ']]>"]


@pytest.mark.parametrize("hostile", HOSTILE)
def test_text_from_the_key_roster_and_submissions_is_shown_as_text(hostile: str) -> None:
    """A roster name, a title, a label, a parameter and a typed answer that look like markup stay text:
    the page holds only the report's own elements, no event attributes, no links away."""
    graded = make_class({hostile: ["invalid", "correct", "correct"]},
                        params=[{hostile: 1.0}, {hostile: 2.0}, {hostile: 3.0}],
                        names=[hostile] * 3, typed=hostile, title=hostile, problem_title=hostile)
    page = Page(class_report(graded))
    assert page.tags <= ALLOWED_TAGS, page.tags - ALLOWED_TAGS
    assert not [name for name, _ in page.attributes if name.startswith("on")]
    assert not [value for name, value in page.attributes if name in ("href", "src") and not value.startswith("#")]
    text = "".join(page.text)
    assert text.count(hostile) >= 4  # title, heading, name, typed answer (and the figures' labels)


def test_the_page_loads_nothing_and_runs_nothing() -> None:
    page = class_report(make_class({"1a": ["correct", "incorrect"]}))
    assert "default-src 'none'" in page
    assert not re.search(r"<script|<link|<img|<iframe|url\((?!#)|@import|https?://(?!www\.w3\.org)", page)


def test_a_hard_corner_of_the_parameter_space_is_listed() -> None:
    """Students with e above 0.8 all got it wrong: that range is listed, the rest of the class is not."""
    values = [0.05 * i for i in range(1, 20)] * 3  # 57 students, e from 0.05 to 0.95
    kinds = ["incorrect" if e > 0.8 else "correct" for e in values]
    page = class_report(make_class({"1a": kinds}, params=[{"e": e, "h": 1.0} for e in values]))
    corners = re.findall(r"<li><span class=\"hard\">Problem 1</span>, <code>(\w+)</code> ([^:]*): (.*?)</li>", page)
    assert corners and all(name == "e" for name, _, _ in corners)
    low, _, high = corners[0][1].partition(" to ")
    assert float(low) >= 0.6 and float(high) == 0.95
    assert "h = 1" in page  # the same for everyone: said, not drawn


def test_an_even_class_has_no_hard_corner() -> None:
    values = [0.05 * i for i in range(1, 20)] * 3
    kinds = ["correct" if i % 4 else "incorrect" for i in range(len(values))]
    page = class_report(make_class({"1a": kinds}, params=[{"e": e} for e in values]))
    assert "No range of any parameter scored clearly below its problem." in page


@pytest.mark.parametrize("values", [
    [2.0 + 0.1 * i for i in range(19)] + [1.6e308],  # one student's parameter at 1.6e308 (issue 22)
    [2.0 + 0.1 * i for i in range(18)] + [-1.6e308, 1.6e308],  # a span beyond float64: the bins overflowed too
    [1e307 * i for i in range(1, 18)],  # all of them huge: matplotlib's ticks overflow from about 1e308
], ids=["one-at-1.6e308", "span-beyond-float64", "all-near-the-limit"])
def test_a_parameter_too_large_to_draw_is_left_out_with_a_note_not_a_traceback(values: list[float]) -> None:
    """A key with a parameter near float64's limit crashed drawing the report (matplotlib's ``arange:
    cannot compute length``); the panel is left out, the page says so, and the others are still drawn."""
    kinds = ["correct" if i % 3 else "incorrect" for i in range(len(values))]
    params = [{"h": value, "e": 0.1 * (index % 7)} for index, value in enumerate(values)]
    page = class_report(make_class({"1a": kinds}, params=params))
    assert "not drawn, with values beyond ±1e+300 (too large for a figure&#x27;s axis; check the key): h (" in page
    assert page.count("<svg") == 3  # the histogram, the verdicts and e's panel


def test_parameters_up_to_the_drawing_limit_are_drawn() -> None:
    """The limit is not drawn too narrowly: ±1e300 and subnormal values still make a figure."""
    values = [-1e300, 1e300, 5e-324, 1e-300] * 3
    page = class_report(make_class({"1a": ["correct", "incorrect"] * 6}, params=[{"h": v} for v in values]))
    assert "not drawn" not in page and page.count("<svg") == 3


def test_a_key_without_parameters_still_reports() -> None:
    page = class_report(make_class({"1a": ["correct", "incorrect"]}))
    assert "the key holds no parameters for this problem" in page


def test_a_key_without_students_still_reports() -> None:
    graded = make_class({"1a": ["correct"]})
    empty = Graded(Key("key.json", 2, "HW", True, graded.key.problems, ()), {"1a": []}, (), (), ())
    assert "<h2 id=\"scores\">Scores</h2>" in class_report(empty)


def test_the_unreadable_answers_are_listed_for_the_first_students_and_counted_for_all() -> None:
    count = INVALID_STUDENTS + 70
    graded = make_class({"1a": ["invalid"] * count, "1b": ["correct"] * (count - 1) + ["invalid"]},
                        typed="x" * 500)
    summary = summarize(graded)
    assert summary.invalid_students == count and len(summary.invalid) == INVALID_STUDENTS
    assert [student.id for student, _ in summary.invalid] == [f"s{i:05d}" for i in range(INVALID_STUDENTS)]
    page = class_report(graded)
    assert f"{count} students have answers that could not be read" in page
    assert f"The first {INVALID_STUDENTS} are listed; 70 students more" in page
    assert "x" * 59 + "…" in page and "x" * 60 not in page  # a long answer is cut; details.csv has it


def test_a_class_of_20000_makes_a_page_of_bounded_size() -> None:
    """Aggregates are drawn, not students: the page does not grow with the class."""
    count = 20_000
    kinds = ["correct", "incorrect", "invalid", "missing", "correct"] * (count // 5)
    params = [{"e": round(0.1 + 0.8 * ((i * 7919) % count) / count, 2), "v": float(i % 50)} for i in range(count)]
    graded = make_class({"1a": kinds, "1b": kinds[::-1]}, params=params)
    page = class_report(graded)
    assert len(page) < 400_000
    assert page.count("<tr><td>s") <= 2 * INVALID_STUDENTS  # the unreadable answers' rows


def test_the_key_keeps_each_students_printed_parameters(demo_run: DemoRun) -> None:
    document = json.loads((demo_run.out / "key.json").read_text(encoding="utf-8"))
    key = load_key(demo_run.out / "key.json")
    for raw, student in zip(document["students"], key.students, strict=True):
        for problem in raw["problems"]:
            assert student.params(problem["key"]) == problem["params"]
    assert len({id(student.parameters) for student in key.students}) == 1  # the class shares one layout


def test_the_demo_report_shows_every_section_and_every_part(demo_run: DemoRun) -> None:
    page = (demo_run.out / "grades" / "report.html").read_text(encoding="utf-8")
    for section in ("scores", "parts", "mistakes", "difficulty", "invalid", "tolerances", "integrity"):
        assert f"<h2 id=\"{section}\">" in page
    key = load_key(demo_run.out / "key.json")
    assert all(f"<tr><td>{label}</td>" in page for label in key.labels)
    assert page.count("<svg ") == 2 + len(key.problems)
    assert "Lena Svensson" in page and "about 48" in page  # the demo's unreadable answer


def test_grading_a_class_never_imports_matplotlib(demo_run: DemoRun, tmp_path: Path) -> None:
    """Issue 29: importing matplotlib and drawing with it was three quarters of grading the demo's class;
    the report's figures are written as SVG text, so a whole grading run (every report) never imports it."""
    code = ("import sys; from grader.cli import main; main(sys.argv[1:]); "
            "print(any(name.partition('.')[0] == 'matplotlib' for name in sys.modules))")
    result = subprocess.run([sys.executable, "-c", code, "grade", "--key", str(demo_run.out / "key.json"),
                             str(demo_run.out / "submissions.csv"), "--out", str(tmp_path / "grades")],
                            capture_output=True, text=True, timeout=120, check=True,
                            cwd=Path(__file__).resolve().parent.parent)
    assert result.stdout.split()[-1] == "False"
    assert (tmp_path / "grades" / "report.html").stat().st_size > 10_000
