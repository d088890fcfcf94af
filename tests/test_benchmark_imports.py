"""The benchmark scripts are not run by the suite (they take minutes), so a name they import from grader
that moved would only show when someone reruns them (benchmarks/tolerance.py imported ``ANSWER_FIGURES``
from ``grader.solve.routes`` for a session after it moved). Every import they make, at the top or inside
a function, must name something that exists."""

from __future__ import annotations

import ast
import importlib
from pathlib import Path

import pytest

BENCHMARKS = Path(__file__).resolve().parent.parent / "benchmarks"
SCRIPTS = sorted(BENCHMARKS.glob("*.py"))


def _top_level_names(path: Path) -> set[str]:
    """What a module defines at its top level (functions, classes, assignments, imports)."""
    names: set[str] = set()
    for node in ast.parse(path.read_text(encoding="utf-8")).body:
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
            names.add(node.name)
        elif isinstance(node, ast.Assign):
            names.update(target.id for target in node.targets if isinstance(target, ast.Name))
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            names.add(node.target.id)
        elif isinstance(node, ast.Import | ast.ImportFrom):
            names.update((alias.asname or alias.name).split(".")[0] for alias in node.names)
    return names


def _imports(path: Path) -> list[tuple[int, str, str | None]]:
    """(line, module, name) of every import in a script; name None for ``import module``."""
    found: list[tuple[int, str, str | None]] = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found += [(node.lineno, alias.name, None) for alias in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            found += [(node.lineno, node.module, alias.name) for alias in node.names]
    return found


def test_there_are_benchmark_scripts_to_check() -> None:
    assert {"solve.py", "generate.py", "grade.py", "accuracy.py", "tolerance.py"} <= {p.name for p in SCRIPTS}


@pytest.mark.parametrize("script", SCRIPTS, ids=[p.stem for p in SCRIPTS])
def test_every_name_a_benchmark_imports_from_grader_or_its_neighbours_exists(script: Path) -> None:
    for line, module, name in _imports(script):
        where = f"{script.name}:{line}: {module}" + (f".{name}" if name else "")
        if module == "grader" or module.startswith("grader."):
            imported = importlib.import_module(module)
            assert name is None or hasattr(imported, name) or _is_module(f"{module}.{name}"), where
        elif (BENCHMARKS / f"{module}.py").exists():  # another benchmark script, imported by name
            assert name is None or name in _top_level_names(BENCHMARKS / f"{module}.py"), where


def _is_module(name: str) -> bool:
    try:
        importlib.import_module(name)
    except ModuleNotFoundError:
        return False
    return True


def test_the_check_finds_a_name_that_moved(tmp_path: Path) -> None:
    """The check itself: an import of a name grader does not have is caught."""
    script = tmp_path / "moved.py"
    script.write_text("def share():\n    from grader.solve.routes import ANSWER_FIGURES\n", encoding="utf-8")
    (line, module, name), = _imports(script)
    assert (line, module, name) == (2, "grader.solve.routes", "ANSWER_FIGURES")
    assert not hasattr(importlib.import_module(module), name)
