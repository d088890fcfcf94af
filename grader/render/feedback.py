"""Each student's graded sheet, handed back: ``feedback/ID.pdf`` (or ``ID.html``) and ``feedback/index.csv``.

A student's file shows their sheet's header and total, then per problem their numbers, the figure and each
part marked (what they typed, what it was read as, the verdict with its credit, the sentence that explains
it, the expected value within its tolerance, the late deduction), then the worked solutions of their own
variants exactly as the answer key has them (``templates/solutions.typ.j2``, the key's own), on pages of the
key's margins. It is one Typst document, a compile a student: every page has the footer of the student's
file (their name and id, "page k of n" of that file), and the PDF keeps its tags for screen readers. A
student who sent nothing gets the same, saying that no answers were received.

Only that student's record (:class:`~grader.assign.returned.Returned`) and their own variants go into a
file: nothing of another student, and none of the run's notes for the instructor. Sources are made from
``templates/feedback.typ.j2`` as the other documents are (every value shown as text unless marked as Typst
source), compiled with the fixed timestamp: two runs write the same bytes.

The HTML page is one self-contained file, as the class report is: no script, nothing loaded (its content
security policy allows only its own inline style), every text escaped; the figures and the worked solutions
are inline SVG typeset by Typst.
"""

from __future__ import annotations

import concurrent.futures
import html
from collections import deque
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

from grader.assign.assignment import Assignment
from grader.assign.returned import MarkedPart, Returned
from grader.assign.variants import Generation
from grader.bank.template import Template
from grader.base.errors import visible
from grader.base.files import write_atomic
from grader.base.spreadsheet import csv_text, number_cell, safe_cell
from grader.render.documents import PAPER, Documents, KeyPerson, assignment_view, document_environment, file_names
from grader.render.joining import without_false_suspects
from grader.render.typeset import compile_typst, font_paths, one_pdf, release_memory
from grader.render.typst_text import Typ, string

FOLDER, INDEX = "feedback", "index.csv"
Format = Literal["pdf", "html"]
RELEASE_EVERY = 8  # students between letting Typst's memo go: memory stays flat over a class
JOBS, AHEAD = 2, 3  # students typeset at once (on 2 cores), and whose sources may wait for a thread

VERDICT_WORDS = {"correct": "correct", "ecf": "correct for your earlier answer (error carried forward)",
                 "mistake": "a common mistake", "incorrect": "incorrect", "invalid": "could not be read",
                 "missing": "not answered"}


@dataclass(frozen=True)
class MarkView:
    """A marked part as the template shows it."""

    kind: str
    label: str
    description: str
    verdict: str
    credit: str
    typed: Typ
    typed_text: str | None  # as the student typed it (None: nothing came)
    read: str
    said: str
    expected: str
    tolerance: str
    late: str


@dataclass(frozen=True)
class ProblemView:
    """A problem of the graded sheet: its score, the student's numbers, the figure, the marked parts."""

    key: str
    title: str
    score: str
    given: Typ
    figure: Typ
    parts: tuple[MarkView, ...]


@dataclass(frozen=True)
class SheetView:
    """The graded sheet's header, total and problems."""

    name: str
    id: str
    section: str
    total: str
    late: str
    submitted: bool
    problems: tuple[ProblemView, ...]


def _points(value: float) -> str:
    return number_cell(value, 6)


def _credit(part: MarkedPart) -> str:
    return f"{_points(part.score)} of {_points(part.points)} point{'' if part.points == 1 else 's'}"


def _late(back: Returned) -> str:
    """How late the student's answers came, and what the late policy took, in a sentence (empty: on time).

    >>> _late(Returned(0, "7", "Ana", "", "", (), "2 h 5 min", 1.5, 10.0, 12.0))
    'Your answers came 2 h 5 min late: the late policy took 1.5 points.'
    """
    if not back.late:
        return ""
    taken = f": the late policy took {_points(back.deduction)} point{'' if back.deduction == 1 else 's'}"
    return f"Your answers came {back.late} late{taken if back.deduction else ''}."


class Feedback:
    """The feedback files of one graded class."""

    def __init__(self, assignment: Assignment, generation: Generation, bank: Mapping[str, Template],
                 fonts: tuple[str, ...] = ()) -> None:
        self.documents, self.fonts = Documents(assignment, generation, bank), fonts

    def view(self, back: Returned, person: KeyPerson) -> SheetView:
        """What the graded sheet shows for one student (``person``: their section of the key)."""
        variants = self.documents.generation.students[back.index].problems
        marks = {part.label: part for part in back.parts}
        problems = []
        for number, (variant, worked) in enumerate(zip(variants, person.problems, strict=True)):
            parts = [marks[answer.label] for answer in variant.answers]
            views = tuple(self._mark(part, answer.description) for part, answer in zip(parts, variant.answers,
                                                                                     strict=True))
            score = f"{_points(sum(p.score for p in parts))} of {_points(sum(p.points for p in parts))} points"
            problems.append(ProblemView(variant.key, worked.title, score, worked.given,
                                        self.documents.figure(back.index, number), views))
        total = f"{_points(back.total)} of {_points(back.possible)} points"
        return SheetView(back.name, back.id, back.section, total, _late(back), back.submitted, tuple(problems))

    @staticmethod
    def _mark(part: MarkedPart, description: str) -> MarkView:
        shown = part.typed if part.typed is not None and part.typed.strip() else None  # a blank cell: nothing
        typed = Typ("#text(fill: luma(90))[nothing]") if shown is None else \
            Typ(f'#text(font: "DejaVu Sans Mono", size: 8.5pt, {string(shown)})')
        late = f"late: the late policy took {_points(part.deduction)} of its points" if part.deduction else ""
        return MarkView(part.verdict, part.label, description, VERDICT_WORDS.get(part.verdict, part.verdict),
                        _credit(part), typed, shown, part.read_as if shown is not None else "", part.feedback,
                        part.expected, part.tolerance, late)

    def submit(self, back: Returned, fmt: Format,
               pool: concurrent.futures.Executor) -> concurrent.futures.Future[bytes | str]:
        """Make the student's Typst source here and typeset it in ``pool``: the future is the file's content.

        The PDF is one document, the marked pages then the worked solutions, so every page has the student's
        footer and the file's own page numbers; the HTML page's figures and worked solutions are one document."""
        person = self.documents.person(back.index)
        view = self.view(back, person)
        assignment = self.documents.assignment
        typeset: concurrent.futures.Future[bytes | str]
        if fmt == "pdf":
            source = document_environment().get_template("feedback.typ.j2").render(
                assignment=assignment_view(assignment), sheet=view, person=person, paper=PAPER,
                document_title=f"{assignment.title}: {back.name}, graded", begin=False)
            typeset = pool.submit(_pdf, source, self.fonts)
        else:
            source = document_environment().get_template("feedback-figures.typ.j2").render(
                assignment=assignment_view(assignment), problems=view.problems, person=person, paper=PAPER,
                begin=True)
            typeset = pool.submit(_page, assignment, view, source, self.fonts)
        self.documents.forget([back.index])  # what was built for this student: memory stays flat
        return typeset


def write_feedback(assignment: Assignment, generation: Generation, bank: Mapping[str, Template],
                   returned: Sequence[Returned], folder: Path, fmt: Format = "pdf", font_dirs: Sequence[Path] = (),
                   progress: Callable[[int], None] | None = None) -> list[Path]:
    """Write ``folder/feedback/<file name>.pdf`` (or ``.html``) per student of ``returned`` (file names as
    the students' sheets have them, :func:`~grader.render.documents.file_names`), then ``index.csv``;
    returns the paths written. Students' files are typeset ``JOBS`` at a time while this thread makes the
    next sources (Typst lets go of the GIL); at most ``AHEAD`` wait, so memory does not grow with the class."""
    out = folder / FOLDER
    out.mkdir(parents=True, exist_ok=True)
    feedback = Feedback(assignment, generation, bank, font_paths(tuple(font_dirs)))
    names = file_names([back.id for back in returned])
    written: list[Path] = []
    waiting: deque[tuple[Path, concurrent.futures.Future[bytes | str]]] = deque()

    def write_next() -> None:
        target, typeset = waiting.popleft()
        write_atomic(target, typeset.result())
        written.append(target)
        if len(written) % RELEASE_EVERY == 0:
            release_memory()
        if progress:
            progress(1)

    pool = concurrent.futures.ThreadPoolExecutor(max_workers=JOBS)
    try:
        for back, name in zip(returned, names, strict=True):
            waiting.append((out / f"{name}.{fmt}", feedback.submit(back, fmt, pool)))
            if len(waiting) > AHEAD:
                write_next()
        while waiting:
            write_next()
    finally:
        pool.shutdown(wait=True, cancel_futures=True)  # on an error, what has not started is not typeset
    rows: list[list[object]] = [["id", "name", "email", "file", "total"]]
    rows += [[safe_cell(visible(b.id)), safe_cell(visible(b.name)), safe_cell(visible(b.email)), safe_cell(path.name),
              number_cell(b.total)]
             for b, path in zip(returned, written, strict=True)]
    write_atomic(out / INDEX, csv_text(rows))
    return [*written, out / INDEX]


def _pdf(source: str, fonts: tuple[str, ...]) -> bytes:
    """A student's PDF, with its tags for screen readers."""
    return without_false_suspects(one_pdf(compile_typst(source, fonts=fonts)))


def _page(assignment: Assignment, view: SheetView, source: str, fonts: tuple[str, ...]) -> str:
    """A student's HTML page: ``source`` (a page per problem's figure, then the worked solutions) typeset as SVG."""
    pages = _svg_pages(source, fonts)
    return _html(assignment, view, pages[:len(view.problems)], pages[len(view.problems):])


# --- HTML ---------------------------------------------------------------------------------------

_STYLE = """
:root { --ink: #222; --muted: #5f6b7a; --line: #dde2ea; --soft: #f5f7fa; --accent: #1f4e99; --good: #1b5e20;
        --bad: #b71c1c; --odd: #e65100; }
* { box-sizing: border-box; }
body { margin: 0; color: var(--ink); background: #fff;
       font: 15px/1.45 system-ui, -apple-system, "Segoe UI", Roboto, "DejaVu Sans", sans-serif; }
main { max-width: 900px; margin: 0 auto; padding: 24px 28px 48px; }
header { border-bottom: 3px solid var(--accent); padding-bottom: 10px; margin-bottom: 8px; }
h1 { font-size: 24px; margin: 0 0 4px; }
h2 { font-size: 19px; margin: 28px 0 6px; padding-top: 6px; border-top: 1px solid var(--line); }
.muted { color: var(--muted); }
.total { font-size: 18px; font-weight: 600; margin: 10px 0; }
.notice { background: var(--soft); border: 1px solid var(--line); border-radius: 6px; padding: 8px 12px; }
.late { color: var(--bad); }
table { border-collapse: collapse; margin: 8px 0; font-size: 14px; width: 100%; }
th, td { text-align: left; padding: 4px 8px; border-bottom: 1px solid var(--line); vertical-align: top; }
th { background: var(--soft); font-weight: 600; }
code { background: var(--soft); padding: 0 3px; border-radius: 3px; word-break: break-all; }
.correct, .ecf { color: var(--good); font-weight: 600; }
.mistake, .incorrect { color: var(--bad); font-weight: 600; }
.invalid { color: var(--odd); font-weight: 600; }
.missing { color: var(--muted); font-weight: 600; }
figure { margin: 8px 0; }
svg { max-width: 100%; height: auto; display: block; }
.page { border: 1px solid var(--line); margin: 12px 0; }
"""


def _e(value: object) -> str:
    """Text as HTML shows it, quotes included (the class report's rule)."""
    return html.escape(str(value), quote=True)


def _svg_pages(source: str, fonts: tuple[str, ...]) -> list[str]:
    """A source typeset as SVG, a page each."""
    result = compile_typst(source, "svg", fonts=fonts)
    pages = [result] if isinstance(result, bytes) else result
    return [page.decode("utf-8") for page in pages]


def _html(assignment: Assignment, view: SheetView, figures: Sequence[str], worked: Sequence[str]) -> str:
    title = f"{assignment.title}: {view.name}, graded"
    head = [f"<header>\n<h1>{_e(assignment.title)}</h1>\n<p class=\"muted\">{_e(assignment.course)}"
            + (f" · due {_e(assignment.due)}" if assignment.due else "") + "</p>\n"
            f"<p>{_e(view.name)} <span class=\"muted\">({_e(view.id)}"
            + (f", section {_e(view.section)}" if view.section else "") + ")</span></p>\n</header>",
            f"<p class=\"total\">Total: {_e(view.total)}</p>"]
    if view.late:
        head.append(f"<p class=\"late\">{_e(view.late)}</p>")
    if not view.submitted:
        head.append("<p class=\"notice\"><strong>No answers were received.</strong> Each part below shows what was "
                    "expected; your worked solutions follow.</p>")
    figures, worked = _shared_glyphs([*figures, *worked], len(figures))
    body = [*head, *(_problem_html(problem, figure) for problem, figure in zip(view.problems, figures, strict=True))]
    body.append("<h2 id=\"worked\">Your worked solutions</h2>\n" +
                "\n".join(f"<div class=\"page\" role=\"img\" aria-label=\"worked solutions, page {n}\">{svg}</div>"
                          for n, svg in enumerate(worked, start=1)))
    return ("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
            "<meta http-equiv=\"Content-Security-Policy\" content=\"default-src 'none'; style-src 'unsafe-inline'\">\n"
            "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
            f"<title>{_e(title)}</title>\n<style>{_STYLE}</style>\n</head>\n<body>\n<main>\n" + "\n".join(body)
            + "\n</main>\n</body>\n</html>\n")


_SYMBOL_OPEN, _SYMBOL_CLOSE = '<symbol id="', "</symbol>"


def _shared_glyphs(pages: Sequence[str], split: int) -> tuple[list[str], list[str]]:
    """The SVG pages with each glyph defined once in the page: Typst names a glyph's ``<symbol>`` by a hash of
    it, and a page uses a symbol by its id anywhere in the document, so a later definition that is the same
    text is dropped (a third of the size of the worked solutions); the pages are split again at ``split``.

    Found by plain search, not a pattern: Typst writes ``<symbol id="…" …>…</symbol>`` and nothing else
    named so, and a pattern took longer over the 2 MB of a student's pages than the page took to build.

    >>> glyph = '<symbol id="g1"><path d="M 0 0"/></symbol>'
    >>> _shared_glyphs(['<use href="#g1"/><defs>' + glyph + '</defs>', '<defs>' + glyph + '</defs>'], 1)
    (['<use href="#g1"/><defs><symbol id="g1"><path d="M 0 0"/></symbol></defs>'], ['<defs></defs>'])
    """
    seen: dict[str, str] = {}
    kept = []
    for page in pages:
        pieces = page.split(_SYMBOL_OPEN)
        out = [pieces[0]]
        for piece in pieces[1:]:
            end = piece.find(_SYMBOL_CLOSE) + len(_SYMBOL_CLOSE)
            name, whole = piece[:piece.find('"')], piece[:end]
            if name in seen and seen[name] == whole:
                out.append(piece[end:])  # defined before, the same: dropped
            else:
                seen.setdefault(name, whole)
                out.append(_SYMBOL_OPEN + piece)
        kept.append("".join(out))
    return kept[:split], kept[split:]


def _problem_html(problem: ProblemView, figure: str) -> str:
    rows = "\n".join(_mark_html(mark) for mark in problem.parts)
    return (f"<h2>Problem {_e(problem.key)}: {_e(problem.title)} <span class=\"muted\">— {_e(problem.score)}"
            f"</span></h2>\n<figure role=\"img\" aria-label=\"figure of problem {_e(problem.key)}\">{figure}</figure>\n"
            "<table>\n<tr><th>Part</th><th>Asked</th><th>You typed</th><th>Verdict</th><th>Why</th>"
            f"<th>Expected</th></tr>\n{rows}\n</table>")


def _mark_html(mark: MarkView) -> str:
    read = f"<br><span class=\"muted\">read as</span> {_e(mark.read)}" if mark.read else ""
    late = f"<br><span class=\"late\">{_e(mark.late)}</span>" if mark.late else ""
    return (f"<tr><th>{_e(mark.label)}</th><td>{_e(mark.description)}</td><td>{_typed(mark)}{read}</td>"
            f"<td><span class=\"{_e(mark.kind)}\">{_e(mark.verdict)}</span><br>{_e(mark.credit)}</td>"
            f"<td>{_e(mark.said)}{late}</td>"
            f"<td>{_e(mark.expected)}<br><span class=\"muted\">accepted {_e(mark.tolerance)}</span></td></tr>")


def _typed(mark: MarkView) -> str:
    """What was typed, or that nothing was."""
    return "<span class=\"muted\">nothing</span>" if mark.typed_text is None else f"<code>{_e(mark.typed_text)}</code>"
