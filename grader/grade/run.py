"""``grader grade``: a key and submission files become grades, details, problems and a Canvas import.

``--out`` is checked first (a folder that would be refused is refused before a minute of grading), then
the inputs are read and checked; the outputs are written into a work folder beside ``--out`` and moved
into place at the end (:func:`grader.base.files.output_folder`), so an unusable input or a failure leaves
nothing behind and a previous output untouched.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path
from typing import Literal

from grader.bank.template import Template
from grader.base.files import output_folder, write_manifest
from grader.base.heap import collector_paused
from grader.grade.canvas import CanvasExport, read_export
from grader.grade.canvas_file import CanvasFile, canvas_file
from grader.grade.class_grades import ClassGrades, answered, counts, final_scores, grade_class
from grader.grade.diagnosis import physics_for
from grader.grade.grading import PIECE, Graded
from grader.grade.key import Key, load_key
from grader.grade.report import write_details, write_reports
from grader.grade.submissions import StudentRef, Submissions, read_submissions

COMMAND = "grader grade"
Extra = Callable[[Graded, Path], object]  # more files a run writes from its verdicts (each student's feedback)


@dataclass(frozen=True)
class GradeSummary:
    """What a run produced, for the one-line summary and ``--json``."""

    out: Path
    students: int
    submitted: int  # students with at least one answer
    parts: int
    rows_not_graded: int  # answers not graded for a reason someone should look at (exit code 3)
    rows_set_aside: int  # superseded by a later submission, or rows that are no student's
    verdicts: Mapping[str, int]
    ignored_columns: tuple[str, ...]
    notes: tuple[str, ...]
    seconds: float

    def to_json(self) -> dict[str, object]:
        """The ``--json`` summary object."""
        return {"out": str(self.out), "students": self.students, "submitted": self.submitted, "parts": self.parts,
                "rows_not_graded": self.rows_not_graded, "rows_set_aside": self.rows_set_aside,
                "verdicts": dict(self.verdicts),
                "ignored_columns": list(self.ignored_columns), "notes": list(self.notes)}


def run(key_path: Path, paths: Sequence[Path], out: Path, fmt: Literal["auto", "long", "wide"] = "auto",
        force: bool = False, canvas: Path | None = None,
        bank: Path | Mapping[str, Template] | None = None, missing: str | None = None,
        feedback: Extra | None = None) -> GradeSummary:
    """Grade the submission files against the key into ``out``; ``canvas``: a Canvas gradebook export
    whose students, names and ids ``canvas.csv`` then carries; ``bank``: the templates the key was made
    from (a folder, or a mapping of templates; by default the shipped bank), for error carried forward
    and diagnosed mistakes; ``missing``: what ``canvas.csv`` gives a student who submitted nothing
    (:func:`grader.grade.canvas_file.canvas_file`); ``feedback``: called with the verdicts and the folder
    being written, to add each student's feedback files (:func:`grader.handback.feedback_writer`).

    ``rows_not_graded`` counts submission rows only: the export's mismatches are caveats (see
    :mod:`grader.grade.canvas`).
    """
    started = time.perf_counter()
    inputs = (key_path, *paths, *([canvas] if canvas is not None else []))
    # The output folder is claimed first: a folder that will be refused is refused before the inputs are
    # read and graded (which may take a minute), and a failure still leaves it as it was.
    with collector_paused(), output_folder(out, command=COMMAND, inputs=inputs, force=force) as staging:
        key = load_key(key_path)
        export = read_export(canvas, key) if canvas is not None else None
        graded = _graded(key, paths, fmt, (), bank, staging=staging, feedback=feedback)
        made = _canvas(graded, export, missing)
        write_reports(graded, staging, made)
    return _summary(graded, out, started, made)


def grade_into(folder: Path, key_path: Path, paths: Sequence[Path], out: Path, names: Sequence[str],
               bank: Path | Mapping[str, Template] | None = None, now: datetime | None = None,
               feedback: Extra | None = None) -> GradeSummary:
    """Grade into ``folder``, a part of an output folder still being written (the demo's ``grades/``), as
    ``grader grade --out out`` would, with the files named as in ``names`` (where they will be) and the
    manifest ``grader grade`` writes, so that ``grader grade --out out --force`` may replace it later;
    ``now``: the time the grading is as at (a timestamp after it is a caveat), by default the clock's;
    ``feedback``: as for :func:`run`."""
    started = time.perf_counter()
    with collector_paused():
        graded = _graded(load_key(key_path), paths, "auto", names, bank, now, folder, feedback)
        made = _canvas(graded, None, None)
        write_reports(graded, folder, made)
        write_manifest(folder, COMMAND)
    return _summary(graded, out, started, made)


def _graded(key: Key, paths: Sequence[Path], fmt: Literal["auto", "long", "wide"], names: Sequence[str],
            bank: Path | Mapping[str, Template] | None, now: datetime | None = None, staging: Path | None = None,
            feedback: Extra | None = None) -> ClassGrades:
    """The class graded a piece of students at a time (:func:`grade_class`), each piece's rows written to
    ``staging``'s details.csv (when given) and let go; with ``feedback``, the class is one piece (each student's
    files and their index are written from the verdicts at once)."""

    def read() -> Submissions:
        return read_submissions(paths, [StudentRef(s.id, s.email) for s in key.students], key.labels, fmt, names,
                                now=now, zone=key.zone, attempts=key.attempts)

    physics, size = physics_for(key, bank), PIECE if feedback is None else max(1, len(key.students))
    if staging is None:
        return grade_class(key, read, physics, size=size)
    with write_details(staging) as written:
        return grade_class(key, read, physics, written if feedback is None else
                           lambda graded: (written(graded), feedback(graded, staging)), size)


def _canvas(graded: ClassGrades, export: CanvasExport | None, missing: str | None) -> CanvasFile:
    """``canvas.csv`` of a run: who submitted anything is who has an answer to any part."""
    submitted = {student.id for student, gave in zip(graded.key.students, answered(graded).tolist(), strict=True)
                 if gave}
    return canvas_file(graded.key, final_scores(graded), submitted, export, missing)


def _summary(graded: ClassGrades, out: Path, started: float, canvas: CanvasFile) -> GradeSummary:
    students = len(graded.key.students)
    return GradeSummary(out, students, int(answered(graded).sum()), students * len(graded.columns),
                        sum(problem.rows for problem in graded.problems if problem.not_graded),
                        sum(problem.rows for problem in graded.problems if problem.routine), counts(graded),
                        graded.ignored_columns, (*graded.notes, *canvas.notes),
                        time.perf_counter() - started)
