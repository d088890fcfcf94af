"""``grader grade``: a key and submission files become grades, details, problems and a Canvas import.

Inputs are read and checked first; the outputs are written into a work folder beside ``--out`` and
moved into place at the end (:func:`grader.files.output_folder`), so an unusable input or a failure
leaves nothing behind and a previous output untouched.
"""

from __future__ import annotations

import gc
import time
from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

from grader.files import output_folder
from grader.grade.grading import counts, grade
from grader.grade.key import load_key
from grader.grade.report import write_reports
from grader.grade.submissions import StudentRef, read_submissions


@dataclass(frozen=True)
class GradeSummary:
    """What a run produced, for the one-line summary and ``--json``."""

    out: Path
    students: int
    submitted: int  # students with at least one answer
    parts: int
    rows_not_graded: int
    verdicts: Mapping[str, int]
    ignored_columns: tuple[str, ...]
    notes: tuple[str, ...]
    seconds: float

    def to_json(self) -> dict[str, object]:
        """The ``--json`` summary object."""
        return {"out": str(self.out), "students": self.students, "submitted": self.submitted, "parts": self.parts,
                "rows_not_graded": self.rows_not_graded, "verdicts": dict(self.verdicts),
                "ignored_columns": list(self.ignored_columns), "notes": list(self.notes)}


def run(key_path: Path, paths: Sequence[Path], out: Path, fmt: Literal["auto", "long", "wide"] = "auto",
        force: bool = False) -> GradeSummary:
    """Grade the submission files against the key into ``out``."""
    started = time.perf_counter()
    with _collector_paused():
        key = load_key(key_path)
        submissions = read_submissions(paths, [StudentRef(s.id, s.email) for s in key.students], key.labels, fmt)
        graded = grade(key, submissions)
        with output_folder(out, command="grader grade", inputs=(key_path, *paths), force=force) as staging:
            write_reports(graded, staging)
    answered = {answer.student_id for answer in submissions.answers}
    return GradeSummary(out, len(key.students), len(answered), len(key.students) * len(key.labels),
                        sum(not problem.caveat for problem in graded.problems), counts(graded),
                        submissions.ignored_columns, submissions.notes, time.perf_counter() - started)


@contextmanager
def _collector_paused() -> Iterator[None]:
    """Python's cycle collector paused while a run builds its objects: a big class makes millions
    (keys, rows, verdicts) and no cycles worth collecting, and each collection walks all of them
    (with it, reading 1.1 million answers took twice as long). At the end what the run made counts
    as old (``freeze`` then ``unfreeze`` moves it to the oldest generation), or the first collection
    after it would walk it all once more."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        gc.freeze()
        gc.unfreeze()
        if enabled:
            gc.enable()
