"""The README's examples are true: each ``$ grader ...`` line prints what the README shows."""

from __future__ import annotations

import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
README = (ROOT / "README.md").read_text(encoding="utf-8")


def _console_examples() -> list[tuple[str, str]]:
    examples = []
    for block in re.findall(r"```console\n(.*?)```", README, flags=re.S):
        for chunk in re.split(r"^\$ ", block, flags=re.M)[1:]:
            command, _, output = chunk.partition("\n")
            examples.append((command, output))
    return examples


@pytest.mark.parametrize(("command", "expected"), _console_examples(), ids=lambda value: value[:50])
def test_readme_console_example_prints_what_the_readme_shows(command: str, expected: str) -> None:
    """Running the command gives the README's output, line for line."""
    words = shlex.split(command)
    assert words[0] == "grader"
    result = subprocess.run([sys.executable, "-m", "grader", *words[1:]], capture_output=True, text=True,
                            cwd=ROOT, timeout=120)
    assert _matches(result.stdout.rstrip(), expected.rstrip()), (result.stdout, result.stderr)


def _matches(got: str, expected: str) -> bool:
    """Line for line; ``...`` in the README stands for text that changes from run to run (timings)."""
    got_lines, expected_lines = got.splitlines(), expected.splitlines()
    if len(got_lines) != len(expected_lines):
        return False
    for line, pattern in zip(got_lines, expected_lines, strict=True):
        regex = ".*?".join(re.escape(part) for part in pattern.split("..."))
        if not re.fullmatch(regex, line):
            return False
    return True


def test_readme_opens_with_the_install_command_that_ci_runs() -> None:
    """CI installs exactly as the README tells a new user, and runs the README's test command."""
    first_block = re.search(r"```sh\n(.*?)```", README, flags=re.S)
    assert first_block is not None
    install = re.search(r"pip install -e '\.\[test\]'", first_block.group(1))
    assert install is not None
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8")
    assert "pip install -e '.[test]'" in ci
    assert ".venv/bin/python -m pytest -q" in README
    assert ".venv/bin/python -m pytest -q" in ci


def test_readme_has_console_examples() -> None:
    """The parametrized README test above is not vacuous."""
    assert len(_console_examples()) >= 5
