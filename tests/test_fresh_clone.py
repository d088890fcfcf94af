"""A fresh clone stands alone: cloned into an empty folder (nothing beside it), its whole suite collects and
the textbook's answers are reproduced there, reading nothing outside the repository."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent

pytestmark = pytest.mark.skipif(shutil.which("git") is None or not (ROOT / ".git").exists(),
                                reason="needs git and a checkout (the committed tree is what a clone holds)")


@pytest.fixture(scope="module")
def clone(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The committed repository cloned into a folder of its own, in an otherwise empty one."""
    alone = tmp_path_factory.mktemp("alone")
    subprocess.run(["git", "clone", "--quiet", "--no-hardlinks", str(ROOT), str(alone / "grader")], check=True,
                   capture_output=True, timeout=120)
    assert [p.name for p in alone.iterdir()] == ["grader"]
    return alone / "grader"


def _pytest(clone: Path, *arguments: str) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "GRADER_CACHE_DIR": str(clone.parent / "cache")}
    env.pop("PYTHONPATH", None)
    return subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", *arguments], cwd=clone,
                          env=env, capture_output=True, text=True, timeout=600)


@pytest.mark.slow  # 8 s: .ci/run itself runs the suite of a fresh clone
def test_the_whole_suite_of_a_fresh_clone_collects(clone: Path) -> None:
    """No test reads a file outside the repository while it is collected (the golden answers did)."""
    result = _pytest(clone, "--collect-only", "tests")
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    assert " tests collected" in result.stdout or " tests selected" in result.stdout


def test_the_textbooks_answers_are_reproduced_in_a_fresh_clone(clone: Path) -> None:
    """The golden test runs there and passes, against the clone's own code and data."""
    result = _pytest(clone, "tests/test_golden.py")
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    assert " passed" in result.stdout and "failed" not in result.stdout
