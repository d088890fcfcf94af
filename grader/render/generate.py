"""``grader generate``: an assignment and a roster become a key and PDFs (``grader demo`` too, in
:mod:`grader.demo`).

Everything is written into a work folder beside the output and moved into place at the end, with a
manifest of what was written (:func:`grader.base.files.output_folder`): a failed run leaves nothing behind,
a previous output stays untouched, and ``--force`` replaces only what an earlier run of ``grader generate`` wrote.
"""

from __future__ import annotations

import gc
import sys
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from grader.assign.assignment import (
    Assignment,
    Student,
    check_against_bank,
    check_extensions,
    load_assignment,
    load_roster,
)
from grader.assign.key_columns import write_key_columns
from grader.assign.keyfile import write_key_files
from grader.assign.variants import ClassDraws, Generation, generate
from grader.bank.template import Template
from grader.base.files import output_folder
from grader.base.heap import collector_paused


@dataclass(frozen=True)
class Job:
    """What to generate, and how."""

    assignment: Path
    roster: Path
    out: Path
    pdf: bool = True
    jobs: int = 1
    keep_source: bool = False
    force: bool = False
    font_dirs: tuple[Path, ...] = ()


@dataclass(frozen=True)
class Summary:
    """What a run produced."""

    out: Path
    students: int
    problems: int
    collisions: Mapping[str, int]
    files: int
    seconds: float


def run(job: Job, bank: Mapping[str, Template]) -> Summary:
    """Generate into ``job.out``; without PDFs, the key is drawn and written a piece of the class at a time."""
    started = time.perf_counter()
    assignment, roster = load_inputs(job, bank)
    with output_folder(job.out, command="grader generate", inputs=(job.assignment, job.roster),
                       force=job.force) as staging:
        if job.pdf:
            generation, written = write_outputs(job, assignment, roster, bank, staging)
            collisions = generation.collisions
        else:
            collisions = write_key(job, assignment, roster, bank, staging)
            written = 2 + write_key_columns(staging / "key.json")  # the sidecar grading reads in its place
    return Summary(job.out, len(roster), len(assignment.problems), collisions, written,
                   time.perf_counter() - started)


def load_inputs(job: Job, bank: Mapping[str, Template]) -> tuple[Assignment, tuple[Student, ...]]:
    """The assignment and roster, checked against the bank (and the font folders), before any work."""
    assignment = load_assignment(job.assignment)
    roster = load_roster(job.roster)
    check_against_bank(assignment, bank)
    check_extensions(assignment, roster, job.roster)
    if job.pdf:
        from grader.render.typeset import font_paths

        font_paths(job.font_dirs)  # refuses a --font-dir that is not a folder before any work
    return assignment, roster


def write_outputs(job: Job, assignment: Assignment, roster: Sequence[Student], bank: Mapping[str, Template],
                  staging: Path) -> tuple[Generation, int]:
    """Generate the variants and write the key files and, unless ``job.pdf`` is off, the PDFs into
    ``staging``; returns the generation (all of it, in memory: the documents need it) and how many files were
    written."""
    with _frozen_for_the_run():
        with collector_paused(keep_frozen=True):
            generation = generate(assignment, roster, bank)
            write_key_files(staging, assignment, [generation.students], lambda: generation.collisions, bank, job.out)
        columns = write_key_columns(staging / "key.json")  # the sidecar grading reads in its place
        written = 2 + columns + (_write_pdfs(job, assignment, generation, bank, staging) if job.pdf else 0)
    return generation, written


def write_key(job: Job, assignment: Assignment, roster: Sequence[Student], bank: Mapping[str, Template],
              staging: Path) -> Mapping[str, int]:
    """Draw the class and write key.json and key.csv into ``staging`` a piece at a time (the same bytes as
    :func:`write_outputs` writes), holding one piece's variants at once; returns the collisions."""
    with collector_paused():  # a piece's objects are freed by reference counting; no cycles to collect
        draws = ClassDraws(assignment, roster, bank)
        write_key_files(staging, assignment, draws.chunks(), draws.collisions, bank, job.out)
    return draws.collisions()


def _write_pdfs(job: Job, assignment: Assignment, generation: Generation, bank: Mapping[str, Template],
                staging: Path) -> int:
    from grader.render.pdfs import render_all
    from grader.render.typeset import font_paths, missing_glyph_warnings

    people = [(s.student.id, s.student.name) for s in generation.students]
    for warning in missing_glyph_warnings(people, font_paths(job.font_dirs)):
        print(warning, file=sys.stderr)
    with progress_bar(len(generation.students) + 2, "PDFs") as advance:
        return len(render_all(assignment, generation, bank, staging, jobs=job.jobs, keep_source=job.keep_source,
                              progress=advance, font_dirs=job.font_dirs))


@contextmanager
def _frozen_for_the_run() -> Iterator[None]:
    """What exists now (modules, the bank) is left out of the collector's passes until the run ends."""
    gc.freeze()
    try:
        yield
    finally:
        gc.unfreeze()


@contextmanager
def progress_bar(total: int, label: str) -> Iterator[Callable[[int], None]]:
    """A progress bar on stderr when it is a terminal; silent otherwise."""
    if not sys.stderr.isatty():
        yield lambda _: None
        return
    from tqdm import tqdm

    with tqdm(total=total, desc=label, unit="doc", file=sys.stderr, leave=False) as bar:
        yield bar.update
