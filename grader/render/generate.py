"""``grader generate`` and ``grader demo``: an assignment and a roster become a key and PDFs.

Everything is written into a work folder beside the output and moved into place at the end, with a
manifest of what was written (:func:`grader.files.output_folder`): a failed run leaves nothing behind,
a previous output stays untouched, and ``--force`` replaces only what an earlier run wrote.
"""

from __future__ import annotations

import gc
import shutil
import sys
import time
from collections.abc import Callable, Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from grader.assign.assignment import Assignment, check_against_bank, load_assignment, load_roster
from grader.assign.keyfile import key_csv, key_document, key_json
from grader.assign.variants import Generation, generate
from grader.bank.template import Template
from grader.files import output_folder, write_atomic
from grader.resources import sample_dir


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


def run(job: Job, bank: Mapping[str, Template], extra: Mapping[str, Path] | None = None) -> Summary:
    """Generate into ``job.out``; ``extra`` files (name -> source) are copied in too (the demo's inputs)."""
    started = time.perf_counter()
    assignment = load_assignment(job.assignment)
    roster = load_roster(job.roster)
    check_against_bank(assignment, bank)
    if job.pdf:
        from grader.render.typeset import font_paths

        font_paths(job.font_dirs)  # refuses a --font-dir that is not a folder before any work
    with output_folder(job.out, command="grader generate", inputs=(job.assignment, job.roster),
                       force=job.force) as staging, _frozen_for_the_run():
        with _collector_paused():
            generation = generate(assignment, roster, bank)
            written = _write_key(assignment, generation, bank, staging)
        for name, source in (extra or {}).items():
            shutil.copyfile(source, staging / name)
        if job.pdf:
            written += _write_pdfs(job, assignment, generation, bank, staging)
    return Summary(job.out, len(roster), len(assignment.problems), generation.collisions, written,
                   time.perf_counter() - started)


@contextmanager
def _collector_paused() -> Iterator[None]:
    """Python's cyclic garbage collector off while the variants and the key are made: they are
    trees without cycles (reference counting frees them), and each pass of the collector walked
    the whole growing heap again, so that time grew faster than the class. What exists at the
    end (the variants, kept for the PDFs) is frozen out of later passes (:func:`_frozen_for_the_run`)."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        gc.freeze()
        if enabled:
            gc.enable()


@contextmanager
def _frozen_for_the_run() -> Iterator[None]:
    """What exists now (modules, the bank) is left out of the collector's passes until the run ends."""
    gc.freeze()
    try:
        yield
    finally:
        gc.unfreeze()


def demo(out: Path, bank: Mapping[str, Template], jobs: int = 1, force: bool = False,
         font_dirs: tuple[Path, ...] = ()) -> Summary:
    """The whole job on the shipped sample; the assignment and roster it used are written beside it."""
    samples = sample_dir()
    job = Job(samples / "assignment.yaml", samples / "roster.csv", out, jobs=jobs, force=force, font_dirs=font_dirs)
    return run(job, bank, {"assignment.yaml": samples / "assignment.yaml", "roster.csv": samples / "roster.csv"})


def _write_key(assignment: Assignment, generation: Generation, bank: Mapping[str, Template], staging: Path) -> int:
    write_atomic(staging / "key.json", key_json(key_document(assignment, generation, bank)))
    write_atomic(staging / "key.csv", key_csv(generation))
    return 2


def _write_pdfs(job: Job, assignment: Assignment, generation: Generation, bank: Mapping[str, Template],
                staging: Path) -> int:
    from grader.render.pdfs import render_all
    from grader.render.typeset import font_paths, missing_glyph_warnings

    people = [(s.student.id, s.student.name) for s in generation.students]
    for warning in missing_glyph_warnings(people, font_paths(job.font_dirs)):
        print(warning, file=sys.stderr)
    with _progress(len(generation.students) + 2, "PDFs") as advance:
        return len(render_all(assignment, generation, bank, staging, jobs=job.jobs, keep_source=job.keep_source,
                              progress=advance, font_dirs=job.font_dirs))


@contextmanager
def _progress(total: int, label: str) -> Iterator[Callable[[int], None]]:
    """A progress bar on stderr when it is a terminal; silent otherwise."""
    if not sys.stderr.isatty():
        yield lambda _: None
        return
    from tqdm import tqdm

    with tqdm(total=total, desc=label, unit="doc", file=sys.stderr, leave=False) as bar:
        yield bar.update
