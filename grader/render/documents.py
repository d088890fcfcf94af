"""What the PDFs show, as Typst sources: a sheet per student, the instructor's key in parts
(:mod:`grader.render.pdfs` compiles and joins them).

Sources are made from the Jinja2 templates in ``templates/`` (``student.typ.j2``, ``key.typ.j2``,
with ``figures.typ`` and ``preamble.typ`` inlined, so each source stands alone) and compiled with
the ``typst`` package using only its embedded fonts and a fixed timestamp: two runs give
byte-identical PDFs.

Text from the roster and the assignment (names, ids, titles, descriptions) is never interpreted:
every ``{{ }}`` of a document template is shown as a Typst string literal unless this module
marked the value as Typst source (:class:`~grader.render.worked.Typ`). A template's ``statement`` is
instructor-written Typst markup (text and math only, checked) and is inserted as markup, with the
printed values filled in by a bounded Jinja2 sandbox (:mod:`grader.bank.statement`). Typst compiles
in an empty private root (:mod:`grader.render.typeset`), so no document can read a file.

>>> safe_file_name("2026100"), safe_file_name("a/b c")
('2026100', 'a_b_c-0af99a6091')
"""

from __future__ import annotations

import hashlib
import re
from collections import Counter
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Any

import jinja2

from grader.assign.asked import restated
from grader.assign.assignment import Assignment, Student
from grader.assign.fair import display_name
from grader.assign.variants import AnswerPart, Generation, ProblemVariant, tolerance
from grader.bank.markup import paragraphs
from grader.bank.template import Template, filled_statement
from grader.base.errors import GraderError
from grader.base.resources import templates_dir
from grader.model.tolerance import EQUAL_EXPRESSIONS, Tolerance, widening
from grader.render.figures import figure
from grader.render.typeset import compile_typst, font_paths
from grader.render.typst_math import math, name
from grader.render.typst_text import Typ, signed, string, text
from grader.render.worked import Worked, WorkedForm, WorkedStep, answer_math, relation_markup, worked, worked_form
from grader.solve.cache import compiled_for
from grader.solve.compiled import Compiled

PAPER = "us-letter"
_SAFE = re.compile(r"[A-Za-z0-9_-][A-Za-z0-9._-]*")  # not starting with "." (a hidden file)


# --- file names ---------------------------------------------------------------------------------

def safe_file_name(student_id: str) -> str:
    """The file name (without ``.pdf``) for a student id.

    An id made only of ASCII letters, digits, ``.``, ``_`` and ``-`` (at most 120 characters, not
    starting with ``.``, which would hide the file) is kept as it is. Any other id becomes its safe
    characters, runs of others replaced by ``_`` (at most 60), then ``-`` and the first 10 hex digits
    of the SHA-256 of the id (UTF-8), so two different ids never share a name.

    >>> safe_file_name("s-001"), safe_file_name(".grader-manifest.json").startswith("grader-manifest.json-")
    ('s-001', True)
    """
    if _SAFE.fullmatch(student_id) and len(student_id) <= 120:
        return student_id
    cleaned = re.sub(r"[^A-Za-z0-9._-]+", "_", student_id)[:60].strip("._") or "student"
    return f"{cleaned}-{hashlib.sha256(student_id.encode('utf-8')).hexdigest()[:10]}"


def file_names(student_ids: Sequence[str]) -> list[str]:
    """:func:`safe_file_name` of each id; ids whose names differ only in case (one file on macOS and
    Windows) all take the hash suffix too, so no PDF overwrites another.

    >>> file_names(["AB1", "ab1", "x"])
    ['AB1-2d2c442062', 'ab1-ca5ba87c93', 'x']
    """
    names = [safe_file_name(i) for i in student_ids]
    folded = Counter(n.casefold() for n in names)
    return [f"{n}-{hashlib.sha256(i.encode('utf-8')).hexdigest()[:10]}" if folded[n.casefold()] > 1 else n
            for n, i in zip(names, student_ids, strict=True)]


# --- views: what the templates show -------------------------------------------------------------

@dataclass(frozen=True)
class Blank:
    """An answer blank: label as the submission CSV expects it, what to give, unit, points."""

    label: str
    description: str
    unit: str
    points: str


@dataclass(frozen=True)
class ProblemSheet:
    """One problem on a student's sheet."""

    key: str
    title: str
    points: str
    statement: Typ
    figure: Typ
    blanks: tuple[Blank, ...]


@dataclass(frozen=True)
class Sheet:
    """A student's sheet."""

    name: str
    id: str
    section: str
    problems: tuple[ProblemSheet, ...]


NO_NOTE = Typ("")


@dataclass(frozen=True)
class KeyAnswer:
    """An answer in the key: where it comes from and its value (math), or why it has none."""

    label: str
    description: str
    value: Typ
    points: str
    tolerance: str
    widened: Typ = NO_NOTE  # a widened tolerance, with why (what honest rounding needs): a note under the answers


@dataclass(frozen=True)
class KeyStep:
    """A worked step, as markup ready for the key."""

    relation: Typ
    equation: Typ
    chain: Typ
    note: Typ


@dataclass(frozen=True)
class KeyProblem:
    """One student's problem in the key: given values, notes, steps, answers."""

    key: str
    title: str
    seed: str
    given: Typ
    notes: tuple[Typ, ...]
    steps: tuple[KeyStep, ...]
    answers: tuple[KeyAnswer, ...]

    @property
    def tolerance_width(self) -> Typ:
        """The width of the answers' tolerance column: its longest text (or heading), half an em a
        character (a little more than Libertinus takes).

        >>> KeyProblem("1", "", "", Typ(""), (), (), (KeyAnswer("1a", "", Typ(""), "2", "±1 %"),)).tolerance_width
        '4.5em'
        """
        return Typ(f"{0.5 * max(len('Tolerance'), *(len(a.tolerance) for a in self.answers)):g}em")


@dataclass(frozen=True)
class KeyPerson:
    """A student's section of the key; ``title`` is its heading (and its line in the contents)."""

    name: str
    id: str
    section: str
    title: Typ
    problems: tuple[KeyProblem, ...]


@dataclass(frozen=True)
class Glance:
    """One problem's answers for some students, as a table: a part of the overview. ``part`` names
    it in the footer; ``continued``: the rest of a table begun in the part before."""

    title: Typ
    part: str
    continued: bool
    header: tuple[Typ, ...]
    rows: tuple[tuple[Typ, ...], ...]


@dataclass(frozen=True)
class Cover:
    """The key's first part: the problems with their points and tolerances, and the contents, each
    entry with its page counted from the first page after the cover."""

    count: str
    summary: tuple[CoverProblem, ...]
    contents: tuple[tuple[Typ, int], ...]


@dataclass(frozen=True)
class CoverProblem:
    """A problem on the key's cover: its parts (label, quantity, unit, points, the tolerance configured)
    and, for each part some students' tolerances were widened for, the part's label and how
    (:meth:`~grader.model.tolerance.Widening.describe`)."""

    key: str
    title: str
    parts: tuple[tuple[str, str, str, str, str], ...]
    widened: tuple[tuple[str, str], ...]


def _math(source: str) -> Typ:
    return Typ(f"${source}$") if source else Typ("")


def _points(points: float) -> str:
    return f"{points:g} point{'' if points == 1 else 's'}"


def _unit_text(unit: str) -> str:
    return {"deg": "degrees", "": "(no unit)"}.get(unit, unit.replace("^2", "²").replace("^3", "³").replace("*", "·"))


class Documents:
    """Builds the views of one generation, computing each variant's worked solution once."""

    def __init__(self, assignment: Assignment, generation: Generation, bank: Mapping[str, Template]) -> None:
        self.assignment, self.generation, self.bank = assignment, generation, bank
        self.compiled: dict[str, Compiled] = {}
        self.forms: dict[str, WorkedForm] = {}
        self.worked: dict[tuple[int, int], Worked] = {}
        self.sheets: dict[int, Sheet] = {}

    def forget(self, indices: Iterable[int]) -> None:
        """Drop what was built for these students (their documents are made): memory stays flat."""
        for index in indices:
            self.sheets.pop(index, None)
            for problem in range(len(self.generation.students[index].problems)):
                self.worked.pop((index, problem), None)

    def _compiled(self, template: Template) -> Compiled:
        if template.id not in self.compiled:
            self.compiled[template.id] = compiled_for(template)
        return self.compiled[template.id]

    def solution(self, student: int, problem: int) -> Worked:
        """The worked solution of one student's problem."""
        if (student, problem) not in self.worked:
            variant = self.generation.students[student].problems[problem]
            template = self.bank[variant.template]
            if template.id not in self.forms:
                self.forms[template.id] = worked_form(template, self._compiled(template))
            self.worked[(student, problem)] = worked(template, variant, self._compiled(template),
                                                     self.forms[template.id])
        return self.worked[(student, problem)]

    def sheet(self, index: int) -> Sheet:
        """A student's sheet."""
        if index not in self.sheets:
            entry = self.generation.students[index]
            problems = tuple(self._problem_sheet(index, p, v) for p, v in enumerate(entry.problems))
            student = entry.student
            self.sheets[index] = Sheet(student.name, student.id, student.section, problems)
        return self.sheets[index]

    def _problem_sheet(self, student: int, problem: int, variant: ProblemVariant) -> ProblemSheet:
        template = self.bank[variant.template]
        blanks = tuple(Blank(part.label, part.description, self._blank_unit(template, part),
                             _points(part.points)) for part in variant.answers)
        return ProblemSheet(variant.key, template.title, _points(sum(p.points for p in variant.answers)),
                            statement(template, variant), self.figure(student, problem), blanks)

    def figure(self, student: int, problem: int) -> Typ:
        """The figure of one student's problem, to the scale of their numbers."""
        variant = self.generation.students[student].problems[problem]
        return figure(self.bank[variant.template], variant, self.solution(student, problem).values)

    @staticmethod
    def _blank_unit(template: Template, part: AnswerPart) -> str:
        symbolic = template.answers[part.name].symbolic
        if symbolic:
            unit = f" ({_unit_text(part.unit)})" if part.unit else ""
            return f"an expression in {' and '.join(symbolic)}{unit}"
        return _unit_text(part.unit)

    def person(self, index: int) -> KeyPerson:
        """A student's section of the key."""
        entry = self.generation.students[index]
        problems = tuple(self._key_problem(self.solution(index, p), v) for p, v in enumerate(entry.problems))
        student = entry.student
        return KeyPerson(student.name, student.id, student.section, person_title(student), problems)

    def _key_problem(self, solution: Worked, variant: ProblemVariant) -> KeyProblem:
        template = self.bank[variant.template]
        given = Typ(", ".join(f"${g}$" for g in solution.given))
        steps = tuple(_key_step(s) for s in solution.steps)
        answers = tuple(_key_answer(template, part, self._compiled(template)) for part in variant.answers)
        return KeyProblem(variant.key, template.title, variant.variant_seed, given, solution.notes, steps, answers)

    def glance(self, position: int, indices: Sequence[int], part: str, continued: bool) -> Glance:
        """The table of one problem's numbers and answers for the listed students."""
        spec = self.assignment.problems[position]
        template = self.bank[spec.template]
        first = self.generation.students[indices[0]].problems[position]
        header = [Typ("ID"), Typ("Student")]
        header += [_math(_given_header(n, p.unit.text)) for n, p in template.parameters.items()]
        header += [Typ(f"*{part.label}*" + (f" {text(_unit_text(part.unit))}" if part.unit else ""))
                   for part in first.answers]
        rows = []
        for index in indices:
            entry = self.generation.students[index]
            variant = entry.problems[position]
            cells = [text(entry.student.id), text(entry.student.name)]
            cells += [text(signed(variant.printed[n])) for n in template.parameters]
            cells += [_glance_value(part) for part in variant.answers]
            rows.append(tuple(cells))
        return Glance(self.glance_title(position), part, continued, tuple(header), tuple(rows))

    def glance_title(self, position: int) -> Typ:
        """The heading of a problem's table of answers at a glance."""
        spec = self.assignment.problems[position]
        return Typ(f"Answers at a glance, problem {text(spec.key)}: {text(self.bank[spec.template].title)}")


def person_title(student: Student) -> Typ:
    """A student's heading in the key, and their line in its contents: name, then id and section.

    >>> person_title(Student("7", "Ana", "", ""))
    '#"Ana"; #h(0.4em) #text(weight: "regular")[(#"7";)]'
    """
    section = f", section {text(student.section)}" if student.section else ""
    return Typ(f'{text(student.name)} #h(0.4em) #text(weight: "regular")[({text(student.id)}){section}]')


def _given_header(parameter: str, unit: str) -> str:
    shown = {"deg": "degree", "": ""}.get(unit, f"thin ({string(unit)})")
    return f"{name(parameter)} {shown}".strip()


def _glance_value(part: AnswerPart) -> Typ:
    if part.value is None:
        return text("undefined")
    return _math(answer_math(part.value, ""))


def _key_step(step: WorkedStep) -> KeyStep:
    # A block's equation, labelled (a), (b), has no chain: its values come with the block's solution.
    chain = "" if not step.chain else f"$display({step.chain[0]} = {step.chain[1]})$" + "".join(
        f" $display(= {part})$" for part in step.chain[2:])
    return KeyStep(step.relation, _math(f"display({step.equation})" if step.equation else ""), Typ(chain), step.note)


def _key_answer(template: Template, part: AnswerPart, compiled: Compiled) -> KeyAnswer:
    source = math(template.answers[part.name].value)
    if part.value is None:
        value = Typ(f"${source}$ {text('undefined: ' + (part.undefined or 'no value'))}")
    else:
        value = _math(f"display({source} = {answer_math(part.value, part.unit)})")
    figure, reason = _tolerance_shown(part, part.tolerance), part.tolerance.reason
    return KeyAnswer(part.label, part.description, value, f"{part.points:g}",
                     f"{figure} (widened)" if reason else figure, _widened(template, part, figure, reason, compiled))


def _tolerance_shown(part: AnswerPart, configured: Tolerance) -> str:
    """A part's tolerance as the key prints it: an expression is marked right when it is the key's expression
    (:func:`grader.grade.equivalence.equivalent`: equal at sampled points to 1e-6, else exactly), whatever the
    part's numeric tolerance."""
    return EQUAL_EXPRESSIONS if isinstance(part.value, str) else configured.describe(part.unit)


def _widened(template: Template, part: AnswerPart, figure: str, reason: str, compiled: Compiled) -> Typ:
    """Why a part's tolerance was widened, its quantities as math and the answer itself as "it"
    (``rounding v_common and T ... moves loss_pct`` named what only the template knows)."""
    if not reason:
        return NO_NOTE
    quantities = {*template.parameters, *(step.unknown for step in compiled.steps)}
    said = re.sub(rf"\bmoves {re.escape(part.name)}\b", "moves it", reason)
    # The reason writes a velocity after as ``v_obj_n′`` (assign/fair.py): the page prints the quantity, v′_(obj, n)
    said = re.sub(r"\b(\w+)\u2032", lambda found: found.group(1) + "_after"
                  if found.group(1) + "_after" in quantities else found.group(0), said)
    for quantity in quantities:  # the reason's v2_n′ is the quantity v2_n_after, which the markup knows
        if display_name(quantity) != quantity:
            said = re.sub(rf"(?<!\w){re.escape(display_name(quantity))}", quantity, said)
    return Typ(text(f"widened to {figure}: ") + relation_markup(said, quantities))


# --- statements ---------------------------------------------------------------------------------

_UNIT = re.compile(r"(?<![\w/.])((?:[-−]?\d+(?:\.\d+)? )?[A-Za-z]{1,3}/[A-Za-z]{1,3}²?)(?![\w/])")


def statement(template: Template, variant: ProblemVariant) -> Typ:
    """The template's statement (instructor-written Typst markup, text and math only) with the
    variant's printed values; a unit in its text (``m/s``), and the number before it, kept on one line (a
    box ended by ``;``: a semicolon after the unit would end the box's code and be lost). When the assignment
    asks only some of the template's answers, its question is restated for those (:mod:`grader.assign.asked`)."""
    filled = filled_statement(template, variant.printed)
    if [part.name for part in variant.answers] != list(template.answers):
        filled = restated(filled, [part.description for part in variant.answers]) or filled
    parts = filled.split("$")
    return Typ("$".join(_UNIT.sub(r"#box[\1];", part) if index % 2 == 0 else part
                        for index, part in enumerate(parts)))


# --- documents ----------------------------------------------------------------------------------

def _finalize(value: Any) -> Any:
    """Every ``{{ }}`` of a document template: shown as text unless marked as Typst source."""
    return value if isinstance(value, Typ) else text("" if value is None else value)


@lru_cache(maxsize=1)
def document_environment() -> jinja2.Environment:
    """The Jinja2 environment of the document templates in ``templates/`` (sheets, key, feedback): every
    ``{{ }}`` shown as Typst text unless marked as Typst source (:class:`~grader.render.typst_text.Typ`)."""
    # Not HTML, so no autoescape: _finalize shows every value as a Typst string instead.
    environment = jinja2.Environment(
        loader=jinja2.FileSystemLoader(str(templates_dir())), undefined=jinja2.StrictUndefined,
        finalize=_finalize, trim_blocks=True, lstrip_blocks=True, keep_trailing_newline=True,
        auto_reload=False, autoescape=False)  # noqa: S701 (the templates are the package's: no file checks a render)
    environment.filters["str"] = string
    environment.filters["int"] = lambda value: Typ(str(int(value)))
    environment.filters["bool"] = lambda value: Typ("true" if value else "false")
    return environment


def assignment_view(assignment: Assignment) -> dict[str, Any]:
    """What a document template shows of the assignment: title, course, due date, instructions, the rounding
    rule and the widest tolerance."""
    return {"title": assignment.title, "course": assignment.course, "due": assignment.due,
            "instructions": paragraphs(assignment.instructions), "rounding": assignment.grading.rounding_rule,
            "widest": Tolerance(rtol=assignment.grading.max_tolerance).describe()}


def student_source(documents: Documents, indices: Iterable[int]) -> str:
    """The Typst source of the sheets of the listed students (roster positions), in order."""
    sheets = [documents.sheet(i) for i in indices]
    title = documents.assignment.title + (f": {sheets[0].name}" if len(sheets) == 1 else ": class")
    return document_environment().get_template("student.typ.j2").render(
        assignment=assignment_view(documents.assignment), sheets=sheets, paper=PAPER, document_title=title)


def key_source(documents: Documents, *, cover: Cover | None = None, glances: Sequence[Glance] = (),
               people: Sequence[int] = (), numbers: int = 0) -> str:
    """The Typst source of a part of the answer key: the cover, tables of answers at a glance, the
    worked solutions of the listed students (roster positions), or any of them in this order; with
    ``numbers``, that many pages of the key's page numbers alone (stamped on the joined key's pages)."""
    assignment = documents.assignment
    return document_environment().get_template("key.typ.j2").render(
        assignment=assignment_view(assignment), paper=PAPER, cover=cover, glances=glances, numbers=numbers,
        people=[(i + 1, documents.person(i)) for i in people], document_title=f"{assignment.title}: answer key")


def cover(documents: Documents, contents: Sequence[tuple[Typ, int]]) -> Cover:
    """The key's cover for the whole class, with these contents."""
    students = documents.generation.students
    summary = []
    for position, (spec, first) in enumerate(zip(documents.assignment.problems, students[0].problems, strict=False)):
        template = documents.bank[first.template]
        parts, widened = [], []
        for number, answer in enumerate(first.answers):
            configured = tolerance(spec, template, answer.name)
            parts.append((answer.label, answer.description, _unit_text(answer.unit), f"{answer.points:g}",
                          _tolerance_shown(answer, configured)))
            found = widening((s.problems[position].answers[number].tolerance, 1) for s in students)
            if found is not None:
                widened.append((answer.label, found.describe("student", answer.unit)))
        summary.append(CoverProblem(first.key, template.title, tuple(parts), tuple(widened)))
    count = len(students)
    return Cover(f"{count} student{'' if count == 1 else 's'}", tuple(summary), tuple(contents))


def check_statements(assignment: Assignment, generation: Generation, bank: Mapping[str, Template],
                     fonts: tuple[str, ...] = ()) -> None:
    """Typeset each problem's statement (and the template's own figure, if it has one) alone once, so
    that one Typst cannot read is reported with its template's file, not as a failure of a whole document."""
    if not generation.students:
        return
    for variant in generation.students[0].problems:
        template = bank[variant.template]
        try:
            compile_typst(f"#set page(width: 12cm, height: auto)\n{statement(template, variant)}\n", fonts=fonts)
        except GraderError as error:
            raise GraderError(f"{template.where}: statement: {error}") from None
        if template.figure.kind == "file":  # the author's own figure, alone: its errors name its template
            try:
                compile_typst(f"#set page(width: auto, height: auto)\n#{figure(template, variant, {})}\n",
                              fonts=fonts)
            except GraderError as error:
                raise GraderError(f"{template.where}: figure: {error}") from None


def sources(assignment: Assignment, generation: Generation, bank: Mapping[str, Template],
            indices: Sequence[int]) -> tuple[str, str]:
    """The Typst sources of the listed students' sheets (statements, figures) and of their answer key
    (worked solutions, without the class overview)."""
    documents = Documents(assignment, generation, bank)
    return student_source(documents, indices), key_source(documents, people=indices)


def render_page_png(assignment: Assignment, generation: Generation, bank: Mapping[str, Template],
                    student_index: int, *, key: bool = False, page: int = 0, ppi: int = 110,
                    font_dirs: Sequence[Path] = ()) -> bytes:
    """One page of a student's sheet as PNG, or with ``key`` of that student's worked solutions in
    the answer key (without the class overview)."""
    documents = Documents(assignment, generation, bank)
    source = key_source(documents, people=[student_index]) if key else student_source(documents, [student_index])
    pages = compile_typst(source, "png", ppi, fonts=font_paths(tuple(font_dirs)))
    pages = [pages] if isinstance(pages, bytes) else pages
    if not 0 <= page < len(pages):
        raise GraderError(f"page {page} does not exist: the document has {len(pages)} page(s)")
    return pages[page]
