"""``grader demo``: the whole job on the shipped sample, as an instructor trying the tool would run it.

It generates the sample assignment for the sample roster (:mod:`grader.render.generate`), plays the
class (``submissions.csv``: answers as students type them, :mod:`grader.assign.sample_answers`) and
grades them into ``grades/`` as ``grader grade --feedback`` would (:func:`grader.grade.run.grade_into`), each
student's graded sheet in ``grades/feedback/``. All of it
is one output folder (:func:`grader.base.files.output_folder`): a failure leaves nothing behind, and
``--force`` replaces a previous demo whole. ``grades/`` has a manifest of its own, so that
``grader grade --key DIR/key.json DIR/submissions.csv --out DIR/grades --force`` can grade again.
"""

from __future__ import annotations

import shutil
import time
from collections.abc import Mapping
from dataclasses import dataclass
from datetime import timedelta
from pathlib import Path

from grader.assign.sample_answers import due_time, sample_answers, submissions_csv
from grader.bank.template import Template
from grader.base.files import output_folder, write_atomic
from grader.base.resources import sample_dir
from grader.grade.run import GradeSummary, grade_into
from grader.handback import FOLDER, feedback_writer
from grader.render.generate import Job, Summary, load_inputs, write_outputs

SUBMISSIONS, GRADES, KEY, FEEDBACK = "submissions.csv", "grades", "key.json", FOLDER


@dataclass(frozen=True)
class DemoSummary:
    """What the demo generated, and how its simulated submissions graded."""

    generated: Summary
    graded: GradeSummary


def demo(out: Path, bank: Mapping[str, Template], jobs: int = 1, force: bool = False,
         font_dirs: tuple[Path, ...] = ()) -> DemoSummary:
    """Generate, simulate and grade into ``out``; the assignment and roster it used are copied there too."""
    started = time.perf_counter()
    samples = sample_dir()
    job = Job(samples / "assignment.yaml", samples / "roster.csv", out, jobs=jobs, force=force, font_dirs=font_dirs)
    assignment, roster = load_inputs(job, bank)
    with output_folder(out, command="grader demo", inputs=(job.assignment, job.roster), force=force) as staging:
        for source in (job.assignment, job.roster):
            shutil.copyfile(source, staging / source.name)
        generation, _ = write_outputs(job, assignment, roster, bank, staging)
        write_atomic(staging / SUBMISSIONS, submissions_csv(sample_answers(assignment, generation, bank)))
        # Graded as at a day after the due date, by which the simulated class submitted, its late resubmission
        # (within 12 hours) included: no row is after the run's time.
        graded = grade_into(staging / GRADES, staging / KEY, [staging / SUBMISSIONS], out / GRADES,
                            [str(out / SUBMISSIONS)], bank, now=due_time(assignment.due) + timedelta(days=1),
                            feedback=feedback_writer("pdf", bank, font_dirs))
        files = sum(path.is_file() for path in staging.rglob("*"))
    generated = Summary(out, len(roster), len(assignment.problems), generation.collisions, files,
                        time.perf_counter() - started)
    return DemoSummary(generated, graded)
