"""The demo's output as the tests share it (the ``demo_run`` fixture of conftest)."""

from __future__ import annotations

import os
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


@dataclass(frozen=True)
class DemoRun:
    """A ``grader demo --out grader-demo`` run in a folder of its own (``cwd``)."""

    cwd: Path
    code: int
    stdout: str
    stderr: str

    @property
    def out(self) -> Path:
        """The demo's output folder."""
        return self.cwd / "grader-demo"


def run_demo(cwd: Path) -> DemoRun:
    """Run the demo as a user does, from the folder that will hold ``grader-demo``, so that the files it
    names are named as the README shows them."""
    result = subprocess.run([sys.executable, "-m", "grader", "demo", "--out", "grader-demo"], cwd=cwd,
                            capture_output=True, text=True, timeout=300,
                            env={**os.environ, "PYTHONPATH": str(ROOT)})
    return DemoRun(cwd, result.returncode, result.stdout, result.stderr)
