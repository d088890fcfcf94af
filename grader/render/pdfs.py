"""A class's PDFs: a sheet per student, the class file and the answer key, in memory that does not
grow with the class.

Typst keeps what it lays out in a process-wide memo cache, and the ``typst`` package lets an entry
go only after ten compiles have not used it. A document of the whole class kept all of its pages
there: the key (about four pages of worked solutions a student) took 1.9 GiB at 200 students. So
nothing is typeset whole. Each sheet is a document of its own; the key is typeset in parts (a few
students' worked solutions; a few hundred rows of a table of answers; the cover, last, with the
contents, once the other parts' pages are known); the class file and the key are their parts
joined one part at a time (:mod:`grader.render.joining`). Students go a few at a time, their
sheets then their part of the key, so the compiles that let a part's memo go are the next
students' sheets, and what was built for them (worked solutions) is dropped once used.
"""

from __future__ import annotations

import concurrent.futures
import itertools
import tempfile
from collections import deque
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from pathlib import Path

from grader.assign.assignment import Assignment
from grader.assign.variants import Generation
from grader.bank.template import Template
from grader.base.errors import GraderError
from grader.render.documents import (
    Documents,
    check_statements,
    cover,
    file_names,
    key_source,
    person_title,
    student_source,
)
from grader.render.joining import Part, join, read_part, without_false_suspects
from grader.render.typeset import compile_typst, font_paths, one_pdf, release_memory
from grader.render.typst_text import Typ

STUDENTS_PER_PART = 6  # of the key: about 15 pages, some 35 MiB of Typst's memo while it compiles
ROWS_PER_PART = 150  # of the tables of answers at a glance, which flow on: some three pages, some 45 MiB
AHEAD = 2  # groups of students whose sources may wait for a thread: bounds the memory they take


def render_all(assignment: Assignment, generation: Generation, bank: Mapping[str, Template], out: Path, *,
               jobs: int = 1, keep_source: bool = False, progress: Callable[[int], None] | None = None,
               font_dirs: Sequence[Path] = ()) -> list[Path]:
    """Write ``out/students/<file name>.pdf`` per student (names from
    :func:`~grader.render.documents.file_names`), ``out/class.pdf`` (every sheet, each student from
    a new page) and ``out/answer-key.pdf``; with ``keep_source`` also the Typst sources under
    ``out/source/`` (``students/<file name>.typ``, and ``answer-key/NNNN.typ``: the key's parts in
    the order they are joined, the cover first). Fonts: the embedded ones, Noto CJK and emoji where
    installed, and those in ``font_dirs`` (:func:`~grader.render.typeset.font_paths`).

    ``progress(1)`` is called as each of the ``len(students) + 2`` documents is written. Documents
    compile in ``jobs`` threads (Typst releases the GIL) while this thread makes their sources.
    Returns the paths written: students in roster order, the class file, the key, then the sources.
    """
    if not generation.students:
        raise GraderError("there are no students to make PDFs for")
    fonts = font_paths(tuple(font_dirs))
    check_statements(assignment, generation, bank, fonts)
    run = _Run(Documents(assignment, generation, bank), out, fonts, keep_source, progress or (lambda _: None))
    (out / "students").mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix=".answer-key-", dir=out) as scratch, _threads(jobs) as pool:
        return run.write(pool, Path(scratch))


@contextmanager
def _threads(jobs: int) -> Iterator[concurrent.futures.ThreadPoolExecutor]:
    """A pool of ``jobs`` threads; on an error, what has not started is cancelled."""
    pool = concurrent.futures.ThreadPoolExecutor(max_workers=max(1, jobs))
    try:
        yield pool
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def _ranges(count: int, size: int) -> list[range]:
    """``range(count)`` in pieces of ``size``.

    >>> _ranges(5, 2)
    [range(0, 2), range(2, 4), range(4, 5)]
    """
    return [range(start, min(count, start + size)) for start in range(0, count, size)]


def _table_parts(problems: int, students: int, rows: int) -> list[list[tuple[int, range]]]:
    """The tables of answers at a glance (a row a student, a table a problem) in parts of at most
    ``rows`` rows: each part a list of (problem position, students), a table split where a part is full.

    >>> _table_parts(3, 2, 5)
    [[(0, range(0, 2)), (1, range(0, 2)), (2, range(0, 1))], [(2, range(1, 2))]]
    """
    parts: list[list[tuple[int, range]]] = [[]]
    room = rows
    for position in range(problems):
        start = 0
        while start < students:
            if room == 0:
                parts.append([])
                room = rows
            stop = min(students, start + room)
            parts[-1].append((position, range(start, stop)))
            room -= stop - start
            start = stop
    return [part for part in parts if part]


def _typeset(source: str, path: Path, fonts: tuple[str, ...], tagged: bool = True) -> Path:
    path.write_bytes(without_false_suspects(one_pdf(compile_typst(source, tagged=tagged, fonts=fonts))))
    return path


def _typeset_part(source: str, path: Path, fonts: tuple[str, ...]) -> Part:
    return read_part(_typeset(source, path, fonts, tagged=False))


class _Run:
    """One class's PDFs: what to write, and what has been."""

    def __init__(self, documents: Documents, out: Path, fonts: tuple[str, ...], keep_source: bool,
                 progress: Callable[[int], None]) -> None:
        self.documents, self.out, self.fonts, self.progress = documents, out, fonts, progress
        students = documents.generation.students
        self.names = file_names([s.student.id for s in students])
        self.sheets = [out / "students" / f"{name}.pdf" for name in self.names]
        self.kept: list[Path] | None = [] if keep_source else None
        self.groups = _ranges(len(students), STUDENTS_PER_PART)
        self.tables = _table_parts(len(documents.assignment.problems), len(students), ROWS_PER_PART)

    def write(self, pool: concurrent.futures.ThreadPoolExecutor, scratch: Path) -> list[Path]:
        key_parts = self._submit(pool, scratch)
        join([read_part(path) for path in self.sheets], self.out / "class.pdf",
             title=f"{self.documents.assignment.title}: class", author=self.documents.assignment.course, lang="en")
        self.progress(1)
        parts = [future.result() for future in key_parts]
        release_memory(forget=True)  # nothing else compiles now; the cover's contents grow with the class
        contents = self._contents(parts)
        first = _typeset_part(self._keep(key_source(self.documents, cover=cover(self.documents, contents)), 0),
                              scratch / "0000.pdf", self.fonts)
        pages = first.pages + sum(part.pages for part in parts)
        numbers = _typeset_part(key_source(self.documents, numbers=pages), scratch / "numbers.pdf", self.fonts)
        join([first, *parts], self.out / "answer-key.pdf", title=f"{self.documents.assignment.title}: answer key",
             author=self.documents.assignment.course, lang="en", stamps=numbers)
        self.progress(1)
        return [*self.sheets, self.out / "class.pdf", self.out / "answer-key.pdf", *(self.kept or [])]

    def _submit(self, pool: concurrent.futures.ThreadPoolExecutor,
                scratch: Path) -> list[concurrent.futures.Future[Part]]:
        """Submit every sheet and part of the key but the cover, a group of students at a time,
        with a part of a table after each group while there are some (the group's sheets then let
        its memo go); returns the key's parts in the order they are joined, once every sheet is written."""
        parts: dict[int, concurrent.futures.Future[Part]] = {}
        sheets: list[concurrent.futures.Future[Path]] = []
        ahead: deque[concurrent.futures.Future[Part]] = deque()
        tables = iter(enumerate(self.tables, start=1))  # joined after the cover (0), before the students
        for number, group in enumerate(self.groups, start=len(self.tables) + 1):
            for index in group:
                source = self._keep(student_source(self.documents, [index]), self.names[index])
                sheets.append(pool.submit(_typeset, source, self.sheets[index], self.fonts))
            parts[number] = self._part(pool, scratch, number, key_source(self.documents, people=group))
            self.documents.forget(group)
            for table, pieces in itertools.islice(tables, 1):
                parts[table] = self._part(pool, scratch, table, self._table_source(pieces))
            ahead.append(parts[number])
            if len(ahead) > AHEAD:
                ahead.popleft().result()
                release_memory()
            sheets = self._report(sheets)
        for table, pieces in tables:
            parts[table] = self._part(pool, scratch, table, self._table_source(pieces))
        for future in concurrent.futures.as_completed(sheets):
            future.result()
            self.progress(1)
        return [parts[number] for number in sorted(parts)]

    def _part(self, pool: concurrent.futures.ThreadPoolExecutor, scratch: Path, number: int,
              source: str) -> concurrent.futures.Future[Part]:
        return pool.submit(_typeset_part, self._keep(source, number), scratch / f"{number:04d}.pdf", self.fonts)

    def _report(self, sheets: list[concurrent.futures.Future[Path]]) -> list[concurrent.futures.Future[Path]]:
        """Report the sheets written (raising the error of one that failed); returns the others."""
        waiting = []
        for future in sheets:
            if future.done():
                future.result()
                self.progress(1)
            else:
                waiting.append(future)
        return waiting

    def _table_source(self, pieces: Sequence[tuple[int, range]]) -> str:
        glances = []
        for position, rows in pieces:
            part = f"problem {self.documents.assignment.problems[position].key}"
            if len(rows) < len(self.documents.generation.students):
                part += f", students {rows.start + 1}–{rows.stop}" if len(rows) > 1 else f", student {rows.stop}"
            glances.append(self.documents.glance(position, rows, part, rows.start > 0))
        return key_source(self.documents, glances=glances)

    def _contents(self, parts: Sequence[Part]) -> list[tuple[Typ, int]]:
        """The cover's contents: each table's first part and each student, with the page it starts
        on, counted from the first page after the cover."""
        contents, later = [], 1
        students = self.documents.generation.students
        for pieces, part in zip(self.tables, parts[:len(self.tables)], strict=True):
            firsts = [position for position, rows in pieces if rows.start == 0]
            if len(part.bookmarks) != len(firsts):
                raise GraderError(f"a part of the answer key has {len(part.bookmarks)} tables' headings, "
                                  f"expected {len(firsts)}")
            contents += [(self.documents.glance_title(position), later + page)
                         for position, page in zip(firsts, part.bookmarks, strict=True)]
            later += part.pages
        for group, part in zip(self.groups, parts[len(self.tables):], strict=True):
            if len(part.bookmarks) != len(group):
                raise GraderError(f"a part of the answer key has {len(part.bookmarks)} students' headings, "
                                  f"expected {len(group)}")
            contents += [(person_title(students[i].student), later + page)
                         for i, page in zip(group, part.bookmarks, strict=True)]
            later += part.pages
        return contents

    def _keep(self, source: str, name: str | int) -> str:
        """Write a source under ``source/`` when they are kept; returns it."""
        if self.kept is not None:
            path = self.out / "source" / (f"answer-key/{name:04d}.typ" if isinstance(name, int) else
                                          f"students/{name}.typ")
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(source, encoding="utf-8")
            self.kept.append(path)
        return source
