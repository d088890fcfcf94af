"""The package's layering: one folder per pipeline stage, no import circles between files or folders.

Imports are read with ``ast`` from every file of ``grader/``, wherever they stand (module level,
inside a function, under ``TYPE_CHECKING``): a lazy or typing-only import is still a dependency.
"""

from __future__ import annotations

import ast
import shutil
from collections.abc import Iterable, Mapping
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parent.parent / "grader"

# The pipeline, bottom to top: a folder may import only folders of a lower rank. Stages of one rank
# are peers and import neither each other. The folder base (errors, files, inputs, caching, heap, resources,
# yaml_loader) and grader/__init__ sit below everything; cli, __main__, demo (which generates and grades) and
# bankcheck (which samples, solves, simulates and typesets) above everything.
RANKS = {"base": 0, "model": 1, "physics": 2, "bank": 3, "solve": 4, "simulate": 4, "assign": 5,
         "render": 6, "grade": 6, "cli": 7}
TOP_LEVEL = {"grader": "base", "grader.cli": "cli", "grader.__main__": "cli", "grader.demo": "cli",
             "grader.handback": "cli", "grader.bankcheck": "cli"}
MAX_TOP_LEVEL = 8
"""Modules at the top of ``grader/`` (``__init__`` and ``__main__`` counted): the rest stand in their stage."""


def module_files(package: Path) -> dict[str, Path]:
    """Every module of the package by dotted name (a package by its ``__init__.py``)."""
    modules = {}
    for path in sorted(package.rglob("*.py")):
        parts = list(path.relative_to(package.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        modules[".".join(parts)] = path
    return modules


def imports_of(module: str, path: Path, known: Iterable[str]) -> set[str]:
    """The grader modules a file imports: ``from a.b import c`` is ``a.b.c`` when that is a module,
    else ``a.b``. A name that is no module of grader is kept, for the stale-path test to report."""
    known = set(known)
    is_package = path.name == "__init__.py"
    found: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), str(path))):
        if isinstance(node, ast.Import):
            targets = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = _absolute(module, is_package, node.module, node.level)
            targets = [f"{base}.{alias.name}" if f"{base}.{alias.name}" in known else base for alias in node.names]
        else:
            continue
        for target in targets:
            if target == "grader" or target.startswith("grader."):
                found.add(target)
    found.discard(module)
    return found


def _absolute(module: str, is_package: bool, name: str | None, level: int) -> str:
    if level == 0:
        return name or ""
    parts = module.split(".")
    anchor = parts if is_package else parts[:-1]
    anchor = anchor[:len(anchor) - (level - 1)]
    return ".".join(anchor + ([name] if name else []))


def import_graph(package: Path) -> dict[str, set[str]]:
    """Module name -> the grader modules it imports."""
    modules = module_files(package)
    return {name: imports_of(name, path, modules) for name, path in modules.items()}


def find_cycle(graph: Mapping[str, Iterable[str]]) -> list[str] | None:
    """One cycle of the graph as a path that returns to its start, or None when there is none."""
    state: dict[str, int] = {}  # 1: on the current path, 2: done
    path: list[str] = []

    def visit(node: str) -> list[str] | None:
        state[node] = 1
        path.append(node)
        for target in sorted(graph.get(node, ())):
            if state.get(target) == 1:
                return [*path[path.index(target):], target]
            if target not in state and (cycle := visit(target)):
                return cycle
        path.pop()
        state[node] = 2
        return None

    for start in sorted(graph):
        if start not in state and (cycle := visit(start)):
            return cycle
    return None


def stage_of(module: str) -> str:
    """The pipeline stage a module belongs to: its folder under grader/, or base/cli for top-level files."""
    if module in TOP_LEVEL:
        return TOP_LEVEL[module]
    return module.split(".")[1]


def folder_graph(graph: Mapping[str, Iterable[str]]) -> dict[str, set[str]]:
    """Stage -> the other stages its files import."""
    folders: dict[str, set[str]] = {}
    for module, targets in graph.items():
        edges = folders.setdefault(stage_of(module), set())
        edges |= {stage_of(t) for t in targets} - {stage_of(module)}
    return folders


GRAPH = import_graph(PACKAGE)


def test_every_import_names_a_module_that_exists() -> None:
    """No import of an old module path survives a move (a lazy import would only fail when run)."""
    modules = module_files(PACKAGE)
    stale = sorted(f"{module} imports {target}" for module, targets in GRAPH.items() for target in targets
                   if target not in modules)
    assert not stale, "imports of modules that do not exist:\n" + "\n".join(stale)


def test_no_file_imports_itself_back() -> None:
    """No file imports a file that, directly or through others, imports it back."""
    cycle = find_cycle(GRAPH)
    assert cycle is None, "import circle: " + " -> ".join(cycle or [])


def test_no_folder_imports_itself_back() -> None:
    cycle = find_cycle(folder_graph(GRAPH))
    assert cycle is None, "folders import each other: " + " -> ".join(cycle or [])


def test_every_folder_imports_only_lower_stages() -> None:
    upward = sorted(f"{module} ({stage_of(module)}) imports {target} ({stage_of(target)})"
                    for module, targets in GRAPH.items() for target in targets
                    if stage_of(target) != stage_of(module)
                    and RANKS.get(stage_of(target), 99) >= RANKS.get(stage_of(module), 99))
    assert not upward, "imports that do not go down the pipeline:\n" + "\n".join(upward)


def test_every_module_has_a_place_in_the_pipeline() -> None:
    """A new folder or top-level file must be given a rank before it can be used."""
    unplaced = sorted(m for m in GRAPH if stage_of(m) not in RANKS)
    assert not unplaced, f"modules outside the pipeline order: {unplaced}; add their folder to RANKS"
    assert {stage_of(m) for m in GRAPH} == set(RANKS), "RANKS names a stage that has no module"


def test_the_top_level_holds_at_most_a_few_modules() -> None:
    """The bottom layer stands in its own folder, each stage in its own: the top holds the commands' entry points."""
    top = sorted(path.name for path in PACKAGE.glob("*.py"))
    assert len(top) <= MAX_TOP_LEVEL, f"{len(top)} modules at the top of grader/: {top}"
    assert {f"grader.{name.removesuffix('.py')}" for name in top} - {"grader.__init__"} <= set(TOP_LEVEL)


def test_no_two_modules_share_a_name() -> None:
    """A module's name says what it does: two files of one name in different stages (a drawing ``canvas`` and
    the LMS's, a simulation's ``run`` and grading's) read as one thing."""
    seen: dict[str, list[str]] = {}
    for name, path in module_files(PACKAGE).items():
        if path.name not in ("__init__.py", "__main__.py"):
            seen.setdefault(path.stem, []).append(name)
    shared = {stem: names for stem, names in seen.items() if len(names) > 1}
    assert not shared, f"modules sharing a name: {shared}"


def test_every_stage_package_says_what_it_does() -> None:
    for name, path in module_files(PACKAGE).items():
        if path.name == "__init__.py" and name.count(".") == 1:
            docstring = ast.get_docstring(ast.parse(path.read_text(encoding="utf-8")))
            assert docstring and len(docstring.splitlines()) == 2, f"{path}: wants a two-line docstring"


@pytest.mark.parametrize(("module", "added", "broken"), [
    ("grader.physics.effects.impact", "from grader.simulate.walker import simulate", "files"),
    ("grader.physics.effects.flight", "from grader.simulate import walker", "folders"),
    ("grader.model.expr", "from grader.bank.template import Template", "files"),
])
def test_the_walk_finds_an_added_circle(module: str, added: str, broken: str) -> None:
    """The checks above can fail: one import added against the grain makes a circle they report."""
    graph = {name: set(targets) for name, targets in GRAPH.items()}
    modules = module_files(PACKAGE)
    extra = ast.parse(added).body[0]
    assert isinstance(extra, ast.ImportFrom) and extra.module is not None
    for alias in extra.names:
        target = f"{extra.module}.{alias.name}"
        graph[module].add(target if target in modules else extra.module)
    if broken == "files":
        assert find_cycle(graph) is not None
    assert find_cycle(folder_graph(graph)) is not None


def test_an_effect_importing_the_simulator_breaks_the_layout_test(tmp_path: Path) -> None:
    """The issue's check, on a copy of the package: the effect gets ``from grader.simulate import simulate``."""
    copy = tmp_path / "grader"
    shutil.copytree(PACKAGE, copy, ignore=shutil.ignore_patterns("__pycache__"))
    effect = copy / "physics" / "effects" / "flight.py"
    effect.write_text(effect.read_text(encoding="utf-8") + "\nfrom grader.simulate import simulate\n",
                      encoding="utf-8")
    graph = import_graph(copy)
    assert "grader.simulate" in graph["grader.physics.effects.flight"]
    cycle = find_cycle(folder_graph(graph))
    assert cycle is not None and {"physics", "simulate"} <= set(cycle)


def test_the_cache_fingerprint_covers_everything_the_solver_imports() -> None:
    """Editing any file the solver depends on must recompile cached templates."""
    from grader.solve.cache import SOLVER_FOLDERS  # imported here: the walk itself must run on a broken tree

    needed: set[str] = set()
    todo = ["grader.solve.solver"]
    while todo:
        module = todo.pop()
        if module not in needed:
            needed.add(module)
            todo.extend(GRAPH[module])
    outside = sorted(m for m in needed if stage_of(m) not in (*SOLVER_FOLDERS, "base"))
    assert not outside, f"the solver imports modules the cache fingerprint does not read: {outside}"


def test_the_cache_fingerprint_changes_with_solver_source_only(tmp_path: Path) -> None:
    from grader.solve.cache import source_fingerprint

    copy = tmp_path / "grader"
    shutil.copytree(PACKAGE, copy, ignore=shutil.ignore_patterns("__pycache__"))
    before = source_fingerprint(copy)
    figures = copy / "render" / "figures.py"
    figures.write_text(figures.read_text(encoding="utf-8") + "\n# drawing only\n", encoding="utf-8")
    assert source_fingerprint(copy) == before
    effect = copy / "physics" / "effects" / "impact.py"
    effect.write_text(effect.read_text(encoding="utf-8") + "\n# physics\n", encoding="utf-8")
    assert source_fingerprint(copy) != before


def test_every_package_folder_is_in_the_wheel() -> None:
    """pyproject.toml lists the packages a wheel carries: a new folder left out installs without it (the
    editable install used in development would not notice; the slow wheel test would, much later)."""
    import tomllib

    listed = set(tomllib.loads((PACKAGE.parent / "pyproject.toml").read_text(encoding="utf-8"))
                 ["tool"]["setuptools"]["packages"])
    folders = {".".join(path.parent.relative_to(PACKAGE.parent).parts) for path in PACKAGE.rglob("__init__.py")}
    assert folders <= listed, f"package folders pyproject.toml does not list: {sorted(folders - listed)}"
