"""A regular (non-editable) install finds the shipped bank: wheel -> fresh venv -> grader from elsewhere."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import venv
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


@pytest.mark.slow
def test_wheel_installed_in_a_fresh_venv_runs_from_another_folder(tmp_path: Path) -> None:
    """Build the wheel, install it (with its dependencies) into a new venv, run `grader list`,
    `grader solve` and `grader demo` from an unrelated folder: the problem bank, the sample data and
    the document templates must come from the wheel."""
    # Built from a clean copy: setuptools reuses a checkout's build/ folder, whose stale files would
    # hide a package missing from pyproject's list.
    source = tmp_path / "source"
    shutil.copytree(ROOT, source, ignore=shutil.ignore_patterns(".git", ".venv", "build", "dist", "*.egg-info",
                                                                 "__pycache__", "artifacts", ".*_cache"))
    wheels = tmp_path / "wheels"
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--quiet", "-w", str(wheels), str(source)],
                   check=True, capture_output=True, timeout=300)
    wheel = next(wheels.glob("grader-*.whl"))
    shipped = set(zipfile.ZipFile(wheel).namelist())
    sources = {p.relative_to(ROOT).as_posix() for p in (ROOT / "grader").rglob("*.py")}
    assert sources <= shipped, f"modules missing from the wheel (pyproject packages?): {sorted(sources - shipped)}"
    compiled = {p.relative_to(ROOT).as_posix() for p in (ROOT / "grader" / "solve" / "shipped").glob("*.json")}
    assert compiled and compiled <= shipped, "the shipped bank's compiled forms must be in the wheel"
    environment = tmp_path / "venv"
    venv.create(environment, with_pip=True)
    python = environment / "bin" / "python"
    subprocess.run([str(python), "-m", "pip", "install", "--quiet", str(wheel)], check=True, capture_output=True,
                   timeout=600)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    env = {**os.environ, "GRADER_CACHE_DIR": str(tmp_path / "cache")}
    env.pop("PYTHONPATH", None)
    listing = subprocess.run([str(environment / "bin" / "grader"), "list"], cwd=elsewhere, env=env,
                             capture_output=True, text=True, timeout=120)
    assert listing.returncode == 0, listing.stderr
    assert "pile-driver" in listing.stdout and "oblique-spheres" in listing.stdout
    location = subprocess.run([str(python), "-c", "import grader.base.resources as r; print(r.bank_dir())"],
                              cwd=elsewhere, env=env, capture_output=True, text=True, timeout=60)
    assert str(environment) in location.stdout, "the bank must be found inside the installed package"
    solved = subprocess.run([str(python), "-m", "grader", "solve", "drop-rebound", "--set", "h_drop=2100",
                             "--set", "h_rebound=1100", "--json"], cwd=elsewhere, env=env, capture_output=True,
                            text=True, timeout=120)
    assert json.loads(solved.stdout)["answers"]["e"]["value"] == pytest.approx(0.7237, abs=1e-4)
    # The demo needs the shipped sample data and the Typst templates too.
    demo = subprocess.run([str(environment / "bin" / "grader"), "demo", "--out", "demo"], cwd=elsewhere, env=env,
                          capture_output=True, text=True, timeout=300)
    assert demo.returncode == 0, demo.stderr
    assert (elsewhere / "demo" / "answer-key.pdf").stat().st_size > 10_000
    assert (elsewhere / "demo" / "grades" / "details.csv").read_text(encoding="utf-8").count("\n") == 30 * 15 + 1
    assert len(list((elsewhere / "demo" / "students").glob("*.pdf"))) == 30
    assert (elsewhere / "demo" / "assignment.yaml").is_file() and (elsewhere / "demo" / "roster.csv").is_file()
    # Everything the demo compiles comes with the wheel: the cache holds no compiled template
    assert not [p.name for p in (tmp_path / "cache").glob("*.json") if not p.name.startswith(("yaml-", "bank-"))]
