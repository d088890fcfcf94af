"""Shared fixtures: the bank, compiled templates, a private compile cache for the run, the demo's output, and the
sample assignment's variants and key (made once a session: several test files read the same class)."""

from __future__ import annotations

import os
import tempfile
from collections.abc import Iterator
from datetime import UTC, datetime
from pathlib import Path

import pytest

# Tests never read or write the user's cache; the first compile of each template happens here.
os.environ["GRADER_CACHE_DIR"] = tempfile.mkdtemp(prefix="grader-test-cache-")

from grader.assign.assignment import load_assignment, load_roster
from grader.assign.variants import Generation, generate
from grader.bank.template import Template, load_bank
from grader.base.resources import sample_dir
from grader.solve.cache import compiled_for
from grader.solve.compiled import Compiled
from tests.demo_output import DemoRun, run_demo


@pytest.fixture(autouse=True)
def _graded_as_at_2030(monkeypatch: pytest.MonkeyPatch) -> None:
    """Grading runs as at 2030: the suite's submissions are stamped December 2026, after the time some of it
    was written (a timestamp after the run's time is a caveat; the tests of that caveat give their own time)."""
    monkeypatch.setattr("grader.grade.timestamps.clock", lambda: datetime(2030, 1, 1, tzinfo=UTC))


@pytest.fixture(scope="session")
def bank() -> dict[str, Template]:
    """The shipped problem bank."""
    return load_bank()


@pytest.fixture(scope="session")
def compiled(bank: dict[str, Template]) -> dict[str, Compiled]:
    """Every shipped template, compiled once per test session."""
    return {template_id: compiled_for(template) for template_id, template in bank.items()}


@pytest.fixture
def workdir(tmp_path: pytest.TempPathFactory) -> Iterator[str]:
    """A temporary current folder."""
    old = os.getcwd()
    os.chdir(tmp_path)  # type: ignore[arg-type]
    yield str(tmp_path)
    os.chdir(old)


@pytest.fixture(scope="session")
def demo_run(tmp_path_factory: pytest.TempPathFactory) -> DemoRun:
    """The demo, run once per test session (PDFs included); tests that change its output work on a copy."""
    return run_demo(tmp_path_factory.mktemp("demo"))


@pytest.fixture(scope="session")
def sample_generation(bank: dict[str, Template]) -> Generation:
    """The sample assignment's variants for the sample roster (30 students), made in process once a session."""
    assignment = load_assignment(sample_dir() / "assignment.yaml")
    return generate(assignment, load_roster(sample_dir() / "roster.csv"), bank)


@pytest.fixture(scope="session")
def sample_key(demo_run: DemoRun) -> Path:
    """The sample assignment's key.json for the sample roster, as the demo wrote it: the same bytes as
    ``grader generate`` writes for them (``--no-pdf`` or not). Read it; a test that changes it works on a copy."""
    assert demo_run.code == 0, demo_run.stderr
    return demo_run.out / "key.json"
