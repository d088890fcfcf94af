"""PDFs: reproducible to the byte, every student's own numbers and labels, names shown literally,
worked solutions in the key, figures that fit; PNGs of each template's page in tests/artifacts/."""

from __future__ import annotations

import dataclasses
import io
import re
import struct
from pathlib import Path

import pytest
import yaml
from pypdf import PdfReader

from grader.assign.assignment import Assignment, ProblemSpec, Student, load_assignment, load_roster
from grader.assign.variants import AnswerPart, Generation, ProblemVariant, StudentVariants, generate
from grader.bank.template import Template, parse_template
from grader.base.errors import GraderError
from grader.base.resources import sample_dir
from grader.model.expr import parse
from grader.model.quantities import dimension_of, si_unit
from grader.render.documents import file_names, render_page_png, safe_file_name, statement
from grader.render.figures import figure
from grader.render.pdfs import render_all
from grader.render.typeset import compile_typst, font_paths, system_fonts, uncovered
from grader.render.typst_math import math
from grader.render.typst_text import Typ
from grader.render.worked import worked, worked_form
from grader.solve.cache import compiled_for
from grader.solve.evaluate import solve_one

ARTIFACTS = Path(__file__).parent / "artifacts"
TRICKY = "Farah #1 Haddad [TA's pick] $x$"


@pytest.fixture(scope="module")
def assignment() -> Assignment:
    return load_assignment(sample_dir() / "assignment.yaml")


@pytest.fixture(scope="module")
def generation(sample_generation: Generation) -> Generation:
    return sample_generation


@pytest.fixture(scope="module")
def few(generation: Generation) -> Generation:
    """Four students, the tricky name among them: enough for every check, quick to typeset."""
    return Generation(generation.students[3:7], generation.collisions)


@pytest.fixture(scope="module")
def others(assignment: Assignment, bank: dict[str, Template]) -> tuple[Assignment, Generation]:
    """One problem per template of the bank that the sample assignment does not use, six students."""
    used = {problem.template for problem in assignment.problems}
    problems = tuple(ProblemSpec(str(index + 1), template, {"*": 1.0}, {}, {}, {})
                     for index, template in enumerate(sorted(set(bank) - used)))
    extra = dataclasses.replace(assignment, problems=problems)
    return extra, generate(extra, load_roster(sample_dir() / "roster.csv")[:6], bank)


@pytest.fixture(scope="module")
def rendered(tmp_path_factory: pytest.TempPathFactory, assignment: Assignment, bank: dict[str, Template],
             few: Generation) -> tuple[Path, list[Path], list[int]]:
    out = tmp_path_factory.mktemp("render")
    progress: list[int] = []
    return out, render_all(assignment, few, bank, out, jobs=2, keep_source=True, progress=progress.append), progress


def pdf_text(path: Path) -> str:
    return "\n".join(page.extract_text() for page in PdfReader(path).pages)


def tricky_entry(generation: Generation) -> StudentVariants:
    return next(s for s in generation.students if s.student.name == TRICKY)


def test_render_all_writes_every_document_and_reports_progress(rendered: tuple[Path, list[Path], list[int]],
                                                                few: Generation) -> None:
    """One PDF per student, the class file, the key, the sources; progress once per document."""
    out, paths, progress = rendered
    students = [out / "students" / f"{s.student.id}.pdf" for s in few.students]
    assert paths[:len(students) + 2] == [*students, out / "class.pdf", out / "answer-key.pdf"]
    assert all(p.is_file() and p.read_bytes().startswith(b"%PDF-") for p in paths[:len(students) + 2])
    assert (out / "source" / "answer-key" / "0000.typ").is_file() and (out / "source" / "students").is_dir()
    assert sum(progress) == len(students) + 2


def test_two_renders_are_byte_identical(tmp_path: Path, rendered: tuple[Path, list[Path], list[int]],
                                        assignment: Assignment, bank: dict[str, Template], few: Generation) -> None:
    """Embedded fonts and a fixed timestamp: the same inputs give the same bytes, in one thread or two."""
    first, _, _ = rendered
    again = render_all(assignment, few, bank, tmp_path, jobs=1)
    for path in again:
        assert path.read_bytes() == (first / path.relative_to(tmp_path)).read_bytes(), path.name


def test_a_sheet_shows_the_students_name_id_numbers_and_answer_labels(
        rendered: tuple[Path, list[Path], list[int]], few: Generation) -> None:
    """Name and id in the header, every printed parameter value, every label the CSV expects."""
    out, _, _ = rendered
    for entry in few.students:
        text = pdf_text(out / "students" / f"{entry.student.id}.pdf")
        assert entry.student.name in text and entry.student.id in text
        for problem in entry.problems:
            for value in problem.printed.values():
                assert value in text, (problem.template, value)
            for part in problem.answers:
                assert part.label in text


def test_the_tricky_name_is_shown_literally_everywhere(rendered: tuple[Path, list[Path], list[int]],
                                                       few: Generation) -> None:
    """# [ ] ' and $ in a name are text: not a heading, a link, a smart quote or math."""
    out, _, _ = rendered
    entry = tricky_entry(few)
    for path in (out / "students" / f"{entry.student.id}.pdf", out / "class.pdf", out / "answer-key.pdf"):
        assert TRICKY in pdf_text(path), path.name


def test_the_class_file_starts_each_student_on_a_new_page(rendered: tuple[Path, list[Path], list[int]],
                                                          few: Generation) -> None:
    out, _, _ = rendered
    pages = [page.extract_text() for page in PdfReader(out / "class.pdf").pages]
    starts = [index for index, text in enumerate(pages) if text.lstrip().startswith("Homework 7")]
    assert len(starts) == len(few.students)
    for start, entry in zip(starts, few.students, strict=True):
        assert entry.student.id in pages[start]


def test_the_key_has_worked_steps_with_each_students_numbers(rendered: tuple[Path, list[Path], list[int]],
                                                             few: Generation) -> None:
    """Relation labels, substituted numbers (g, the printed values in SI), answers to 4 figures."""
    out, _, _ = rendered
    text = pdf_text(out / "answer-key.pdf")
    assert "conservation of energy, ball falls through" in text
    assert "conservation of momentum" in text and "9.81" in text
    entry = tricky_entry(few)
    drop = entry.problems[0]
    assert f"{float(drop.printed['h_drop']) / 1000:.3f}" in text  # mm shown converted to m
    assert f"{drop.answers[0].value:.4f}" in text  # e to 4 significant figures


def footers(reader: PdfReader) -> list[tuple[str, int, int]]:
    """Each page's footer: the section it names (its own, the left), and "page x of y" (stamped
    over it as the key's parts are joined, the last line)."""
    found = []
    for page in reader.pages:
        *_, left, right = page.extract_text().strip().splitlines()
        named = re.fullmatch(r"(.*) · answer key", left.strip())
        number = re.fullmatch(r"page (\d+) of (\d+)", right.strip())
        assert named is not None and number is not None, (left, right)
        found.append((named.group(1), int(number.group(1)), int(number.group(2))))
    return found


@pytest.mark.slow  # two threads typesetting parts of 2 students: about 5 s
def test_a_key_typeset_in_many_parts_numbers_its_pages_and_contents_rightly(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, assignment: Assignment, bank: dict[str, Template],
        few: Generation) -> None:
    """Parts of 2 students and tables of 3 rows: the pages are numbered 1..y through the whole key
    (issue 26: they were numbered per student, "page 1 of 2" in a file of 127), the contents give
    the page each student and table starts on, and the bookmarks point there too."""
    import grader.render.pdfs

    monkeypatch.setattr(grader.render.pdfs, "STUDENTS_PER_PART", 2)
    monkeypatch.setattr(grader.render.pdfs, "ROWS_PER_PART", 3)
    render_all(assignment, few, bank, tmp_path, jobs=2)
    reader = PdfReader(tmp_path / "answer-key.pdf")
    pages = footers(reader)
    assert [(number, count) for _, number, count in pages] == [(n, len(pages)) for n in range(1, len(pages) + 1)]
    texts = [page.extract_text() for page in reader.pages]
    covered = sum(1 for section, _, _ in pages if "class overview" in section)
    cover = "\n".join(texts[:covered])
    listed = {line.rsplit(maxsplit=1)[0]: int(line.split()[-1]) for line in cover.splitlines()
              if re.search(r"\(\d+\)|^Answers at a glance", line)}

    def first_page(words: str) -> int:
        return next(page for page in range(covered, len(texts)) if words in texts[page]) + 1

    for entry in few.students:
        shown = next(page for title, page in listed.items() if f"({entry.student.id})" in title)
        assert shown == first_page(f"({entry.student.id})"), entry.student.name
    for key in "12345":
        shown = next(page for title, page in listed.items() if title.startswith(f"Answers at a glance, problem {key}:"))
        assert shown == first_page(f"Answers at a glance, problem {key}:")
    assert sum("(continued)" in text for text in texts) >= 1  # a table goes on in the next part
    marks = [(o.title, reader.get_destination_page_number(o) + 1) for o in reader.outline if not isinstance(o, list)]
    assert sorted(page for _, page in marks) == sorted(listed.values())


def test_a_step_that_depends_on_a_cancelling_mass_is_shown_as_a_multiple_of_it(
        bank: dict[str, Template], few: Generation) -> None:
    """T = m v^2/2 in drop-rebound has no number of its own: it is shown as 'number times m'."""
    variant = few.students[0].problems[0]
    solution = worked(bank[variant.template], variant)
    energy = next(s for s in solution.steps if s.chain[0] == "T")
    assert energy.chain[-1].endswith(" m") and "in kg" in energy.note
    ratio = next(s for s in solution.steps if s.chain[0] == 'f_"loss"')
    assert not ratio.chain[-1].endswith("m") and not ratio.note


def test_one_worked_form_per_template_gives_every_variant_its_solution_from_scratch(
        bank: dict[str, Template], generation: Generation) -> None:
    """The documents make a template's step forms once (worked_form) and substitute each student's numbers:
    every student's solution is the one worked() makes on its own, numbers, notes and values alike."""
    forms = {}
    for entry in generation.students:
        for variant in entry.problems:
            template = bank[variant.template]
            form = forms.setdefault(template.id, worked_form(template))
            assert worked(template, variant, form=form) == worked(template, variant)
    assert len(forms) == 5


@pytest.mark.parametrize(("expression", "dimensions", "unit"), [
    ("sqrt(2*g*h)", {"g": (1, 0, -2, 0), "h": (1, 0, 0, 0)}, "m/s"),
    ("m*v*v/2", {"m": (0, 1, 0, 0), "v": (1, 0, -1, 0)}, "J"),
    ("v*(e + 1)/(1/m + 1/(m*p))", {"v": (1, 0, -1, 0), "m": (0, 1, 0, 0), "e": (0, 0, 0, 0), "p": (0, 0, 0, 0)},
     "N·s"),
    ("atan2(-a, b)", {"a": (1, 0, -1, 0), "b": (1, 0, -1, 0)}, "rad"),
    ("hypot(a, b)*cos(t)", {"a": (1, 0, -1, 0), "b": (1, 0, -1, 0), "t": (0, 0, 0, 1)}, "m/s"),
    ("Max(0, h - k)/h", {"h": (1, 0, 0, 0), "k": (1, 0, 0, 0)}, ""),
    ("m*v*h", {"m": (0, 2, 0, 0), "v": (1, 0, -1, 0), "h": (1, 0, 0, 0)}, "kg²·m²/s"),
])
def test_step_units_follow_from_the_parameters_units(expression: str, dimensions: dict[str, tuple[int, ...]],
                                                     unit: str) -> None:
    assert si_unit(dimension_of(parse(expression), dimensions, strict=False)) == unit


@pytest.mark.parametrize(("expression", "typst"), [
    ("sqrt(2*g*h_drop)", 'sqrt(2 g h_"drop")'),
    ("-v_after/v_impact", "(-v')/v_\"impact\""),
    ("m*v_impact*v_impact/2", '(m v_"impact"^2)/2'),
    ("hypot(v1_n_after, v1_t_after)", "sqrt(v'_(1, n)^2 + v'_(1, t)^2)"),
    ("atan2(-v_n_after, v_t_after)", "op(\"atan2\")(-v'_n, v'_t)"),
    ("vA_after - theta1_out", "v'_A - theta_(1, \"out\")"),
])
def test_expressions_become_typst_math(expression: str, typst: str) -> None:
    assert math(parse(expression)) == typst


@pytest.mark.parametrize(("student_id", "name"), [
    ("2026100", "2026100"), ("a.b_c-9", "a.b_c-9"),
    ("../../etc/passwd", "etc_passwd-" + safe_file_name("../../etc/passwd")[-10:]),
    ("Ünïcode id", "n_code_id-" + safe_file_name("Ünïcode id")[-10:]),
])
def test_student_ids_map_to_safe_file_names(student_id: str, name: str) -> None:
    assert safe_file_name(student_id) == name
    assert all(c.isascii() and (c.isalnum() or c in "._-") for c in safe_file_name(student_id))


def test_ids_that_differ_only_in_case_get_different_file_names() -> None:
    """On macOS and Windows 'A1.pdf' and 'a1.pdf' are one file: neither may overwrite the other."""
    names = file_names(["A1", "a1", "b2"])
    assert len({n.casefold() for n in names}) == 3 and names[2] == "b2"


def test_markup_in_names_and_ids_is_shown_literally(tmp_path: Path, assignment: Assignment,
                                                    bank: dict[str, Template], few: Generation) -> None:
    """Every Typst special character, a string-literal break-out attempt, an unsafe id."""
    name = 'Zed "quoted" \\ back #let x = 1; // not a comment *bold* _it_ <l> @r = h'
    student = Student("x/y z", name, "zed@example.edu", "L#1")
    odd = Generation((StudentVariants(student, few.students[0].problems),), few.collisions)
    paths = render_all(assignment, odd, bank, tmp_path)
    sheet = tmp_path / "students" / f"{safe_file_name('x/y z')}.pdf"
    assert sheet in paths
    text = pdf_text(sheet)
    assert name in text and "x/y z" in text and "L#1" in text


def test_an_undefined_answer_is_given_with_its_reason(tmp_path: Path, assignment: Assignment,
                                                      bank: dict[str, Template], few: Generation) -> None:
    """A ball that hits head-on with e = 0 stops: its rebound angle is undefined, step and answer."""
    template = bank["ball-plate"]
    solution = solve_one(template, compiled_for(template), {"v": 40.0, "theta": 90.0, "e": 0.0})
    assert solution.answers is not None
    parts = tuple(AnswerPart(a.name, f"4{'ab'[i]}", a.value, a.unit, 2.0, template.answers[a.name].tolerance,
                             template.answers[a.name].description, a.undefined)
                  for i, a in enumerate(solution.answers.values()))
    variant = ProblemVariant("4", template.id, "0" * 16, {"v": 40.0, "theta": 90.0, "e": 0.0},
                             {"v": "40", "theta": "90", "e": "0.00"}, parts)
    steps = worked(template, variant).steps
    assert "undefined" in steps[-1].note and "degree" not in steps[-1].chain[-1]
    single = dataclasses.replace(assignment, problems=(assignment.problems[3],))
    one = Generation((StudentVariants(few.students[0].student, (variant,)),), few.collisions)
    render_all(single, one, bank, tmp_path)
    assert "undefined: v_out is zero" in pdf_text(tmp_path / "answer-key.pdf").replace("\n", " ")


def test_a_statement_typst_cannot_read_is_reported_with_its_template(
        tmp_path: Path, assignment: Assignment, bank: dict[str, Template], few: Generation) -> None:
    broken = {**bank, "drop-rebound": dataclasses.replace(bank["drop-rebound"], statement="Unclosed $e = {{ h_drop }}")}
    with pytest.raises(GraderError, match=r"drop-rebound\.yaml: statement"):
        render_all(assignment, few, broken, tmp_path)


def png_size(data: bytes) -> tuple[int, int]:
    assert data.startswith(b"\x89PNG\r\n\x1a\n") and data[12:16] == b"IHDR"
    width, height = struct.unpack(">II", data[16:24])
    return width, height


@pytest.mark.parametrize("position", range(5))
def test_each_templates_page_renders_to_a_png(position: int, assignment: Assignment, few: Generation,
                                              bank: dict[str, Template]) -> None:
    """The header and one problem (statement, figure, blanks) on a letter page, written to
    tests/artifacts/<template>.png to look at."""
    single = dataclasses.replace(assignment, problems=(assignment.problems[position],))
    one = Generation(tuple(StudentVariants(s.student, (s.problems[position],)) for s in few.students), {})
    index = few.students.index(tricky_entry(few))
    png = render_page_png(single, one, bank, index, ppi=110)
    width, height = png_size(png)
    assert (width, height) == (935, 1210) and len(png) > 30_000
    ARTIFACTS.mkdir(exist_ok=True)
    (ARTIFACTS / f"{assignment.problems[position].template}.png").write_bytes(png)


def test_a_key_page_renders_to_a_png(assignment: Assignment, few: Generation, bank: dict[str, Template]) -> None:
    index = few.students.index(tricky_entry(few))
    for page in (0, 1):
        png = render_page_png(assignment, few, bank, index, key=True, page=page)
        assert png_size(png) == (935, 1210)
        ARTIFACTS.mkdir(exist_ok=True)
        (ARTIFACTS / f"answer-key-page-{page}.png").write_bytes(png)
    with pytest.raises(GraderError, match="page 99 does not exist"):
        render_page_png(assignment, few, bank, index, page=99)


def test_figures_fit_their_column(assignment: Assignment, generation: Generation, bank: dict[str, Template],
                                  others: tuple[Assignment, Generation]) -> None:
    """No figure of any student, of the sample's problems or the other templates', is wider than
    7.7 cm or taller than 8 cm; a strip of panels (a scene of several motions, two columns) keeps its two
    columns together within twice ``STRIP_WIDTH`` (a narrow panel leaves its room to the other column)
    and each panel within 8 cm."""
    from grader.render.panels import STRIP_WIDTH

    for entry in (*generation.students, *others[1].students):
        for variant in entry.problems:
            template = bank[variant.template]
            drawn = figure(template, variant, worked(template, variant).values)
            assert isinstance(drawn, Typ)
            strip = drawn.startswith("grid(")
            sizes = re.findall(r"fig-canvas\(([0-9.]+), ([0-9.]+),", drawn)
            assert sizes and (strip or drawn.startswith("fig-canvas(")), drawn[:80]
            widths = [float(w) for w, _ in sizes]
            if strip:
                columns = max(widths[0::2]) + max(widths[1::2], default=0.0)
                assert columns <= 2 * STRIP_WIDTH + 0.01, (variant.template, widths)
            else:
                assert widths[0] <= 7.7, (variant.template, widths)
            assert all(float(h) <= 8.0 for _, h in sizes), (variant.template, sizes)



WALL = """
id: wall
title: A puck strikes a wall head-on
version: 1
bodies: {puck: {mass: m}, wall: {fixed: true}}
symbols: {m: {unit: kg}}
parameters:
  v: {unit: m/s, domain: "(0, inf)", sample: {uniform: [1, 5]}, decimals: 1}
  e: {unit: "", domain: "[0, 1]", sample: {uniform: [0.2, 0.9]}, decimals: 2}
stages:
  - {effect: impact, bodies: [puck, wall], restitution: e, before: {puck: v}, after: {puck: v_after}}
answers:
  v_after: {value: v_after, unit: m/s}
statement: A puck at {{ v }} m/s strikes a wall; $e = {{ e }}$.
"""

FALL = """
id: fall
title: A stone falls
version: 1
gravity: 9.81 m/s^2
bodies: {stone: {mass: m}}
symbols: {m: {unit: kg}}
parameters:
  h: {unit: ft, domain: "(0, inf)", sample: {uniform: [1, 5]}, decimals: 1}
stages:
  - {effect: free_fall, body: stone, height: h, speed: v}
answers:
  v: {value: v, unit: ft/s}
statement: A stone falls {{ h }} ft from rest; g is {{ g }} m/s².
"""


COMPONENTS = """
id: components
title: Components of a velocity
version: 1
bodies: {ball: {mass: m}}
symbols: {m: {unit: kg}}
parameters:
  v: {unit: m/s, domain: "(0, inf)", sample: {uniform: [1, 5]}, decimals: 1}
  theta: {unit: deg, domain: "[0, 90]", sample: {uniform: [10, 80]}, decimals: 0}
stages:
  - {effect: velocity, speed: v, angle: theta, n: v_n, t: v_t}
answers:
  v_n: {value: v_n, unit: m/s}
statement: A ball moves at {{ v }} m/s, {{ theta }}° from the t axis.
"""


@pytest.mark.parametrize("source", [WALL, FALL, COMPONENTS], ids=["wall", "fall-only", "no-known-shape"])
def test_scenes_of_other_shapes_get_a_figure_and_a_worked_solution(source: str, tmp_path: Path,
                                                                   assignment: Assignment) -> None:
    """A direct impact on a fixed body (a wall); a fall without an impact (the ground); a scene of no
    known shape (its bodies in a row)."""
    raw = yaml.safe_load(source)
    template = parse_template(raw, f"test:{raw['id']}", f"hash-{raw['id']}")
    spec = ProblemSpec("1", template.id, {"*": 1.0}, {}, {}, {})
    one = dataclasses.replace(assignment, problems=(spec,))
    student = Student("s1", "Sam", "", "")
    generated = generate(one, (student,), {template.id: template})
    paths = render_all(one, generated, {template.id: template}, tmp_path)
    text = pdf_text(tmp_path / "students" / "s1.pdf")
    assert all(value in text for value in generated.students[0].problems[0].printed.values())
    assert "1a" in text and len(paths) == 3
    key = pdf_text(tmp_path / "answer-key.pdf")
    assert "conservation of energy" in key or "restitution" in key or "component along" in key
    png = render_page_png(one, generated, {template.id: template}, 0)
    ARTIFACTS.mkdir(exist_ok=True)
    (ARTIFACTS / f"extra-{template.id}.png").write_bytes(png)


def test_a_semicolon_or_a_dot_after_a_unit_stays_in_the_statement(assignment: Assignment) -> None:
    """A unit kept on one line is a box in code: a semicolon after it would end that code and be lost
    (wall-impulse's "at 23.8 m/s; the coefficient ..." printed without it)."""
    raw = yaml.safe_load(WALL)
    raw["statement"] = "A puck at {{ v }} m/s; it strikes a wall at {{ v }} m/s. Then $e = {{ e }}$."
    template = parse_template(raw, "test:wall", "hash-wall")
    spec = ProblemSpec("1", template.id, {"*": 1.0}, {}, {}, {})
    variant = generate(dataclasses.replace(assignment, problems=(spec,)), (Student("s1", "Sam", "", ""),),
                       {template.id: template}).students[0].problems[0]
    pdf = compile_typst(f"#set page(width: 20cm, height: auto)\n{statement(template, variant)}")
    assert isinstance(pdf, bytes)
    shown = " ".join(PdfReader(io.BytesIO(pdf)).pages[0].extract_text().split())
    v = variant.printed["v"]
    assert f"A puck at {v} m/s; it strikes a wall at {v} m/s. Then" in shown


# --- hardening: statements, the Typst root, fonts -------------------------------------------------

def test_a_statement_that_skipped_the_load_check_still_runs_no_code(bank: dict[str, Template],
                                                                   generation: Generation) -> None:
    """The sandbox itself refuses dunder access and sizes; statement() names the file and `statement`."""
    import jinja2.sandbox

    from grader.bank import statement as statements

    with pytest.raises(jinja2.sandbox.SecurityError):
        statements._environment().from_string("{{ ''.__class__.__mro__ }}").render()
    with pytest.raises(statements.StatementRefused, match="more than 10000"):
        statements._environment().from_string("{{ 'x' * 10**9 }}").render()
    variant = generation.students[0].problems[0]
    evil = dataclasses.replace(bank[variant.template], statement="{{ ''.__class__ }}")
    with pytest.raises(GraderError, match=r"\.yaml: statement: expected values filled in, not code, got attr"):
        statement(evil, variant)


def test_a_secret_file_in_the_working_folder_never_reaches_a_pdf(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, assignment: Assignment, bank: dict[str, Template],
        few: Generation) -> None:
    """Typst's root is an empty private folder: reading a file fails even when the text gets that far;
    a template asking for one is refused at load, and in rendering; no PDF holds the secret."""
    (tmp_path / "secret.txt").write_text("TOPSECRET", encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    for source in ('#read("secret.txt")', f'#read("{tmp_path / "secret.txt"}")', '#image("secret.txt")',
                   '#include "secret.txt"', '#import "@local/x:0.1.0"'):
        with pytest.raises(GraderError, match="Typst could not typeset"):
            compile_typst(source)
    raw = yaml.safe_load((Path(__file__).parents[1] / "problem_bank" / "drop-rebound.yaml").read_text("utf-8"))
    with pytest.raises(GraderError, match=r'x\.yaml: statement: expected text and math only, got a Typst call '
                                          r'that reads files: read\("secret\.txt"\)'):
        parse_template({**raw, "statement": '#read("secret.txt")'}, "x.yaml", "0", "drop-rebound")
    template = few.students[0].problems[0].template
    leaky = {**bank, template: dataclasses.replace(bank[template], statement='#read("secret.txt")')}
    with pytest.raises(GraderError, match="reads files"):
        render_all(assignment, few, leaky, tmp_path / "out")
    render_all(assignment, Generation(few.students[:1], few.collisions), bank, tmp_path / "ok")
    assert all("TOPSECRET" not in pdf_text(p) for p in (tmp_path / "ok").rglob("*.pdf"))


def dejavu_sans(folder: Path) -> Path:
    """A font folder holding only matplotlib's DejaVu Sans (which has Tifinagh; the embedded fonts do not)."""
    import matplotlib

    folder.mkdir()
    shipped = Path(matplotlib.get_data_path()) / "fonts" / "ttf" / "DejaVuSans.ttf"
    (folder / "DejaVuSans.ttf").write_bytes(shipped.read_bytes())
    return folder


def test_characters_no_font_has_are_found_and_font_dir_adds_fonts(tmp_path: Path) -> None:
    """Typst is asked which characters print as empty boxes; a font folder adds what it covers."""
    extra = str(dejavu_sans(tmp_path / "fonts"))
    assert uncovered(["Ωжé 李 𓀀 ⴰ"], ()) == {"李", "𓀀", "ⴰ"}
    assert uncovered(["Ωжé 李 𓀀 ⴰ"], (extra,)) == {"李", "𓀀"}


def test_a_name_no_font_has_is_warned_about_naming_the_student(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                              assignment: Assignment, bank: dict[str, Template],
                                                              few: Generation) -> None:
    """Without the font, a warning on stderr names the student; the PDFs are still written."""
    from grader.render.generate import Job, _write_pdfs

    entry = few.students[0]
    odd = Generation((dataclasses.replace(entry, student=dataclasses.replace(entry.student, name="Amun 𓀀")),),
                     few.collisions)
    job = Job(sample_dir() / "assignment.yaml", sample_dir() / "roster.csv", tmp_path)
    assert _write_pdfs(job, assignment, odd, bank, tmp_path) == 3
    err = capsys.readouterr().err
    assert f"warning: student {entry.student.id} (Amun 𓀀): no font has 𓀀 (U+13000)" in err


@pytest.mark.skipif(not any("CJK" in f.name for f in system_fonts()),
                    reason="no Noto CJK font installed (apt-get install fonts-noto-cjk); the embedded fonts lack CJK")
def test_cjk_and_hangul_names_print_with_the_system_noto_font(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                             assignment: Assignment, bank: dict[str, Template],
                                                             few: Generation) -> None:
    """With fonts-noto-cjk, 李华 and 김민준 are text in the PDF, not boxes, and nobody is warned about."""
    from grader.render.generate import Job, _write_pdfs

    entry = few.students[0]
    name = "李华 김민준"
    cjk = Generation((dataclasses.replace(entry, student=dataclasses.replace(entry.student, name=name)),),
                     few.collisions)
    _write_pdfs(Job(sample_dir() / "assignment.yaml", sample_dir() / "roster.csv", tmp_path), assignment, cjk, bank,
                tmp_path)
    assert "warning" not in capsys.readouterr().err
    assert name in pdf_text(tmp_path / "students" / f"{entry.student.id}.pdf")
    assert not uncovered([name], font_paths(()))


@pytest.mark.slow  # about 3 s of rendering to PNG
def test_other_templates_pages_render_to_pngs(others: tuple[Assignment, Generation],
                                              bank: dict[str, Template]) -> None:
    """Each template's page, and a page of the answer key, written to tests/artifacts/ to look at."""
    extra, generation = others
    ARTIFACTS.mkdir(exist_ok=True)
    for position, problem in enumerate(extra.problems):
        single = dataclasses.replace(extra, problems=(problem,))
        one = Generation(tuple(StudentVariants(s.student, (s.problems[position],)) for s in generation.students), {})
        png = render_page_png(single, one, bank, 0, ppi=110)
        assert png_size(png) == (935, 1210) and len(png) > 30_000
        (ARTIFACTS / f"{problem.template}.png").write_bytes(png)
    key = render_page_png(extra, generation, bank, 0, key=True)
    assert png_size(key) == (935, 1210)
    (ARTIFACTS / "answer-key-other-templates.png").write_bytes(key)


def _figure_of(assignment: Assignment, bank: dict[str, Template], template_id: str, fixed: dict[str, float]) -> str:
    spec = ProblemSpec("1", template_id, {"*": 1.0}, fixed, {}, {})
    # A grazing impact loses little, so rounding T and T′ moves its loss far: the cap on the tolerance
    # that allows for it would redraw the numbers this figure is about.
    one = dataclasses.replace(assignment, problems=(spec,),
                              grading=dataclasses.replace(assignment.grading, max_tolerance=0.5))
    variant = generate(one, (Student("s1", "Sam", "", ""),), bank).students[0].problems[0]
    return figure(bank[template_id], variant, worked(bank[template_id], variant).values)


@pytest.mark.parametrize("template_id, fixed", [
    ("moving-plate", {"h": 1.2, "u": 1.5}),  # the height the ball rises
    ("incline-bounce", {"h": 1.2, "beta": 30}),  # the angle of the rebound
])
def test_an_asked_height_or_angle_is_not_drawn_to_scale(assignment: Assignment, bank: dict[str, Template],
                                                        template_id: str, fixed: dict[str, float]) -> None:
    """Two variants that differ only in e (so in what is asked) get the same figure, which would otherwise
    give the answer away."""
    assert _figure_of(assignment, bank, template_id, {**fixed, "e": 0.5}) == \
        _figure_of(assignment, bank, template_id, {**fixed, "e": 0.9})


@pytest.mark.parametrize("template_id, fixed, sine", [
    ("billiards", {"v": 2, "r": 28.5, "b": 30, "e": 0.9}, 30 / 57),
    ("offset-spheres", {"m1": 2, "m2": 1, "r1": 40, "r2": 30, "v1": 5, "b": 35, "e": 0.6}, 0.5),
    ("offset-spheres", {"m1": 2, "m2": 1, "r1": 20, "r2": 50, "v1": 5, "b": 68, "e": 0.6}, 68 / 70),
])
def test_the_line_of_centres_is_drawn_at_the_variants_angle(assignment: Assignment, bank: dict[str, Template],
                                                            template_id: str, fixed: dict[str, float],
                                                            sine: float) -> None:
    """The two circles touch, and the line through their centres makes asin(b/(r1 + r2)) with the path
    (horizontal), to the figure's 0.01 cm."""
    drawn = _figure_of(assignment, bank, template_id, fixed)
    circles = re.findall(r"fig-circle\(\(([-0-9.]+), ([-0-9.]+)\), ([0-9.]+), w: 0.8pt, fill", drawn)
    (x1, y1, r1), (x2, y2, r2) = [tuple(map(float, found)) for found in circles]
    assert abs(((x2 - x1) ** 2 + (y2 - y1) ** 2) ** 0.5 - (r1 + r2)) < 0.02
    assert abs((y1 - y2) / (r1 + r2) - sine) < 0.02  # Typst's y points down


def test_a_given_is_printed_in_the_unit_it_was_given(bank: dict[str, Template], few: Generation) -> None:
    """Issue 26: a given `k = 651 N/m` was printed `= 651 kg/s²`. A unit of factor 1 that is not
    the SI name (here the ram's mass in N·s²/m) is shown as given, with no conversion; one of
    another factor (mm) is still converted."""
    raw = yaml.safe_load((Path(bank["pile-driver"].where)).read_text(encoding="utf-8"))
    raw["parameters"]["m_ram"]["unit"] = "N*s^2/m"
    template = parse_template(raw, "pile-driver (N*s^2/m)", "test")
    variant = next(v for s in few.students for v in s.problems if v.template == "pile-driver")
    given = worked(template, dataclasses.replace(variant, template=template.id)).given
    ram = next(line for line in given if line.startswith('m_"ram"'))
    assert "N" in ram and "kg" not in ram and ram.count("=") == 1, ram
    drop = worked(bank["drop-rebound"], few.students[0].problems[0]).given[0]
    assert '"mm"' in drop and drop.count("=") == 2, drop


def test_every_pdf_is_clean_for_pdfinfo_and_qpdf(rendered: tuple[Path, list[Path], list[int]]) -> None:
    """Issue 26: Typst's `/Suspects false` made poppler's pdfinfo warn "Suspects object is wrong type
    (boolean)" on every sheet. Every PDF written (sheets, class file, key) now reads without a word
    on stderr from pdfinfo, and `qpdf --check` finds nothing; a tool not installed is skipped."""
    import shutil
    import subprocess

    tools = [command for command in (["pdfinfo"], ["qpdf", "--check"]) if shutil.which(command[0])]
    if not tools:
        pytest.skip("neither pdfinfo (poppler-utils) nor qpdf is installed")
    _, paths, _ = rendered
    for path in (p for p in paths if p.suffix == ".pdf"):
        for command in tools:
            run = subprocess.run([*command, str(path)], capture_output=True, text=True, check=False)
            assert run.returncode == 0 and not run.stderr.strip(), (command, path.name, run.stderr)
            assert "warning" not in run.stdout.lower(), (command, path.name, run.stdout)


def test_a_contact_time_under_a_slash_or_a_power_is_one_group() -> None:
    """``Delta t`` is two atoms to Typst: ``|J|/Delta t`` would divide by Delta and multiply by t (seen on
    wall-impulse's key, F = |J_n|/Δ · t); grouped, Typst drops the parentheses of a fraction's denominator."""
    assert math(parse("abs(J)/dt")) == "abs(J)/(Delta t)"
    assert math(parse("dt^2")) == "(Delta t)^2"
    assert math(parse("F*dt")) == "F Delta t"  # a product needs no group
