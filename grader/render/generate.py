"""``grader generate`` and ``grader demo``: an assignment and a roster become a key and PDFs.

Everything is written into a temporary folder beside the output and moved into place at the end,
so a failed run leaves nothing behind and a previous output stays untouched.
"""

from __future__ import annotations

import os
import shutil
import sys
import tempfile
import time
from collections.abc import Callable, Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from grader.assign.assignment import Assignment, check_against_bank, load_assignment, load_roster
from grader.assign.keyfile import key_csv, key_document, key_json
from grader.assign.variants import Generation, generate
from grader.bank.template import Template
from grader.errors import GraderError
from grader.files import usual_mode, write_atomic
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
    _check_output(job.out, job.force)
    if job.pdf:
        from grader.render.typeset import font_paths

        font_paths(job.font_dirs)  # refuses a --font-dir that is not a folder before any work
    generation = generate(assignment, roster, bank)
    with _staging(job.out) as staging:
        for name, source in (extra or {}).items():
            shutil.copyfile(source, staging / name)
        written = _write(job, assignment, generation, bank, staging)
    return Summary(job.out, len(roster), len(assignment.problems), generation.collisions, written,
                   time.perf_counter() - started)


def demo(out: Path, bank: Mapping[str, Template], jobs: int = 1, force: bool = False,
         font_dirs: tuple[Path, ...] = ()) -> Summary:
    """The whole job on the shipped sample; the assignment and roster it used are written beside it."""
    samples = sample_dir()
    job = Job(samples / "assignment.yaml", samples / "roster.csv", out, jobs=jobs, force=force, font_dirs=font_dirs)
    return run(job, bank, {"assignment.yaml": samples / "assignment.yaml", "roster.csv": samples / "roster.csv"})


def _check_output(out: Path, force: bool) -> None:
    if out.exists() and not out.is_dir():
        raise GraderError(f"{out}: exists and is not a folder; choose another --out")
    if out.is_dir() and any(out.iterdir()) and not force:
        raise GraderError(f"{out}: the output folder exists and is not empty; choose another --out, or --force to "
                          "replace it")


@contextmanager
def _staging(out: Path) -> Iterator[Path]:
    out.parent.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(prefix=f".{out.name}.", suffix=".partial", dir=out.parent))
    usual_mode(staging, folder=True)
    try:
        yield staging
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise
    if out.exists():
        retired = Path(tempfile.mkdtemp(prefix=f".{out.name}.", suffix=".old", dir=out.parent))
        os.replace(out, retired / "previous")
        os.replace(staging, out)
        shutil.rmtree(retired, ignore_errors=True)
    else:
        os.replace(staging, out)


def _write(job: Job, assignment: Assignment, generation: Generation, bank: Mapping[str, Template],
           staging: Path) -> int:
    write_atomic(staging / "key.json", key_json(key_document(assignment, generation, bank)))
    write_atomic(staging / "key.csv", key_csv(generation))
    written = 2
    if job.pdf:
        from grader.render.documents import render_all
        from grader.render.typeset import font_paths, missing_glyph_warnings


        people = [(s.student.id, s.student.name) for s in generation.students]
        for warning in missing_glyph_warnings(people, font_paths(job.font_dirs)):
            print(warning, file=sys.stderr)
        with _progress(len(generation.students) + 2, "PDFs") as advance:
            written += len(render_all(assignment, generation, bank, staging, jobs=job.jobs,
                                      keep_source=job.keep_source, progress=advance,
                                      font_dirs=job.font_dirs))
    return written


@contextmanager
def _progress(total: int, label: str) -> Iterator[Callable[[int], None]]:
    """A progress bar on stderr when it is a terminal; silent otherwise."""
    if not sys.stderr.isatty():
        yield lambda _: None
        return
    from tqdm import tqdm

    with tqdm(total=total, desc=label, unit="doc", file=sys.stderr, leave=False) as bar:
        yield bar.update
