"""``grader grade --feedback``: each student's graded sheet handed back, written beside the grades
(``feedback/ID.pdf`` or ``.html``, and ``feedback/index.csv``).

Grading (:mod:`grader.grade`) and typesetting (:mod:`grader.render`) are peers that import neither
each other; this joins them: the run's verdicts become each student's record
(:func:`grader.grade.feedback_rows.returned`), the key's variants are read back with the templates it
was made from, and :func:`grader.render.feedback.write_feedback` writes the files into the grading run's
output folder, so they share its manifest, its atomic move into place and its ``--force`` rule.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

from grader.bank.template import Template
from grader.grade.feedback_rows import key_generation, key_templates, returned
from grader.grade.grading import Graded
from grader.render.feedback import FOLDER, Format, write_feedback
from grader.render.generate import progress_bar

__all__ = ["FOLDER", "feedback_writer"]


def feedback_writer(fmt: Format = "pdf", bank: Path | Mapping[str, Template] | None = None,
                    font_dirs: Sequence[Path] = ()) -> Callable[[Graded, Path], list[Path]]:
    """What a grading run calls with its verdicts and the folder it writes, to add the feedback files;
    ``bank``: where the key's templates are (a folder, or templates; by default the shipped bank)."""

    def write(graded: Graded, folder: Path) -> list[Path]:
        templates = key_templates(graded.key, bank)
        assignment, generation = key_generation(graded.key, templates)
        with progress_bar(len(generation.students), "feedback") as advance:  # a bar on a terminal only
            return write_feedback(assignment, generation, templates, returned(graded), folder, fmt, font_dirs,
                                  advance)

    return write
