"""The shipped bank's compiled forms come with the package and are current, so a first run on a new machine
pays for sympy only for an instructor's own templates (``grader.solve.ship``)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from grader.bank.template import Template
from grader.base import caching
from grader.solve import ship
from grader.solve.alternatives import Alternatives
from grader.solve.cache import KINDS, SHIPPED, entry_name
from grader.solve.compiled import Compiled
from grader.solve.routes import Routes

ROOT = Path(__file__).resolve().parent.parent
READERS = {"": Compiled.from_json, "-alternatives": Alternatives.from_json, "-routes": Routes.from_json}


def test_the_package_carries_an_entry_of_each_kind_for_every_shipped_template_and_no_other(
        bank: dict[str, Template]) -> None:
    """Every entry today's source looks up is there, and nothing else is: else run the build command."""
    expected, present = ship.expected_names(bank.values()), ship.present_names()
    assert expected == present, (f"the shipped compiled forms are stale: run `{ship.BUILD_COMMAND}` "
                                 f"(missing {sorted(expected - present)}, stale {sorted(present - expected)})")


@pytest.mark.parametrize("kind", KINDS)
def test_each_shipped_entry_reads_back_as_its_own_template(bank: dict[str, Template], kind: str) -> None:
    """Sealed under its name, readable, and made from that very template file."""
    for template in bank.values():
        stored = caching.read_entry(SHIPPED / entry_name(template, kind), shipped=True)
        assert stored is not None, template.id
        kept = READERS[kind](stored)
        assert (kept.template_id, kept.source_hash) == (template.id, template.source_hash)


def test_a_first_solve_on_a_new_machine_imports_no_sympy(tmp_path: Path) -> None:
    """An empty cache folder: the answers come from the shipped form, with no compiling."""
    script = ("import sys; from grader.cli import main; "
              "code = main(['solve', 'pile-driver', '--set', 'm_ram=800', '--set', 'm_pile=2400', '--set', "
              "'h_drop=2', '--set', 'h_rebound=0.1', '--json']); print('sympy' in sys.modules); sys.exit(code)")
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, cwd=tmp_path,
                            env={"GRADER_CACHE_DIR": str(tmp_path / "cache"), "PATH": "/usr/bin:/bin",
                                 "PYTHONPATH": str(ROOT)}, timeout=120, check=True)
    answers, sympy_loaded = result.stdout.splitlines()
    assert json.loads(answers)["answers"]["v_pile"]["value"] == pytest.approx(2.555, abs=5e-4)  # Sample Problem 3/28
    assert sympy_loaded == "False"
    assert not list((tmp_path / "cache").glob("pile-driver-*"))  # nothing compiled, so nothing kept


def test_an_entry_made_from_other_source_is_not_found(bank: dict[str, Template]) -> None:
    """The name carries the template's hash: another file's bytes look up another name."""
    template = bank["drop-rebound"]
    other = bank["pile-driver"]
    assert entry_name(template, "") != entry_name(other, "")
    assert entry_name(template, "").startswith("drop-rebound-")


@pytest.mark.slow
@pytest.mark.parametrize("kind", KINDS)
def test_shipped_entries_are_what_the_solver_compiles_today(bank: dict[str, Template], kind: str) -> None:
    """Compiled afresh with sympy, every template gives exactly what the package carries."""
    compile_now = ship.compilers()[kind]
    for template in bank.values():
        stored = caching.read_entry(SHIPPED / entry_name(template, kind), shipped=True)
        assert stored == json.loads(json.dumps(compile_now(template).to_json())), template.id


def test_an_instructors_own_template_derives_its_diagnosis_chains_when_grading_first_needs_them(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    """Generating compiles what the key needs and no more; the first grading says, on stderr, that it derives the
    chains of errors carried forward and of mistakes (seconds of sympy), and a second grading reads them kept."""
    from grader.base.resources import bank_dir
    from grader.cli import main

    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("GRADER_CACHE_DIR", str(tmp_path / "cache"))
    mine = tmp_path / "mine"
    mine.mkdir()
    text = (bank_dir() / "drop-rebound.yaml").read_text(encoding="utf-8")
    (mine / "my-drop.yaml").write_text(text.replace("id: drop-rebound", "id: my-drop"), encoding="utf-8")
    Path("a.yaml").write_text("title: HW\ncourse: C\nseed: s\nproblems:\n  - template: my-drop\n", encoding="utf-8")
    Path("r.csv").write_text("id,name,email,section\n1,Ann,a@x.org,A\n", encoding="utf-8")
    assert main(["generate", "a.yaml", "--roster", "r.csv", "--out", "out", "--no-pdf", "--bank", str(mine)]) == 0
    assert "deriving" not in capsys.readouterr().err
    assert not list((tmp_path / "cache").glob("my-drop-*-alternatives.json"))
    Path("s.csv").write_text("student_id,label,answer\n1,1a,0.5\n", encoding="utf-8")
    for run, out in ((1, "g1"), (2, "g2")):
        code = main(["grade", "s.csv", "--key", "out/key.json", "--out", out, "--bank", str(mine)])
        err = capsys.readouterr().err
        assert code in (0, 3), err
        said = "grader: deriving the chains of errors carried forward and of mistakes for my-drop"
        assert (said in err) == (run == 1), err
    assert list((tmp_path / "cache").glob("my-drop-*-alternatives.json"))
