"""The command line: outputs, exit codes (0 ok, 2 bad input, 3 rows refused) and messages."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from grader.cli import main

PILE = ["--set", "m_ram=800", "--set", "m_pile=2400", "--set", "h_drop=2", "--set", "h_rebound=0.1"]


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def test_solve_json_has_the_documented_shape(capsys: pytest.CaptureFixture[str]) -> None:
    """--json prints one object with template, params and answers {value, unit}."""
    code, out, _ = run(capsys, "solve", "pile-driver", *PILE, "--json")
    record = json.loads(out)
    assert code == 0
    assert record["template"] == "pile-driver"
    assert record["params"] == {"m_ram": 800.0, "m_pile": 2400.0, "h_drop": 2.0, "h_rebound": 0.1}
    assert set(record["answers"]) == {"v_pile", "e", "loss_pct"}
    assert record["answers"]["v_pile"]["unit"] == "m/s"
    assert record["answers"]["e"]["value"] == pytest.approx(0.6315, abs=1e-4)


def test_values_with_their_own_units_are_converted(capsys: pytest.CaptureFixture[str]) -> None:
    """h_drop=200cm and m_pile=2.4Mg mean the same as 2 m and 2400 kg."""
    _, plain, _ = run(capsys, "solve", "pile-driver", *PILE, "--json")
    _, converted, _ = run(capsys, "solve", "pile-driver", "--set", "m_ram=800", "--set", "m_pile=2.4Mg",
                          "--set", "h_drop=200cm", "--set", "h_rebound=0.1", "--json")
    for name, answer in json.loads(plain)["answers"].items():
        assert json.loads(converted)["answers"][name]["value"] == pytest.approx(answer["value"], rel=1e-14)


@pytest.mark.parametrize(("argv", "message"), [
    (["solve", "pile-drivr", "--set", "m_ram=1"], "unknown template 'pile-drivr'; did you mean pile-driver?"),
    (["solve", "pile-driver", "--set", "m_ram=800"], "missing parameter(s) m_pile, h_drop, h_rebound"),
    (["solve", "pile-driver", *PILE, "--set", "mass=3"], "unknown parameter(s) mass"),
    (["solve", "pile-driver", "--set", "m_ram=heavy", *PILE[2:]],
     "--set m_ram: expected a finite number in kg, got 'heavy'"),
    (["solve", "pile-driver", "--set", "m_ram=800s", *PILE[2:]], "'s' cannot be converted to kg"),
    (["solve", "pile-driver", "--set", "m_ram", *PILE[2:]], "expected NAME=VALUE"),
    (["solve", "pile-driver", *PILE, "--set", "h_drop=3"], "h_drop is given twice"),
    (["show", "oblique"], "did you mean oblique-spheres?"),
    (["--bank", "/nonexistent/bank", "list"], "problem bank folder not found"),
], ids=["unknown-id", "missing", "unknown-name", "not-a-number", "wrong-unit", "no-equals", "twice",
        "show-unknown", "no-bank"])
def test_unusable_input_exits_2_with_a_message_naming_the_problem(
        capsys: pytest.CaptureFixture[str], argv: list[str], message: str) -> None:
    """Exit code 2, the message on stderr, nothing on stdout."""
    code, out, err = run(capsys, *argv)
    assert code == 2
    assert message in err
    assert out == ""


def test_usage_errors_exit_2(capsys: pytest.CaptureFixture[str]) -> None:
    """argparse's own errors (no command, unknown option) also exit 2."""
    for argv in ([], ["solve"], ["solve", "pile-driver", "--nope"]):
        with pytest.raises(SystemExit) as stop:
            main(argv)
        assert stop.value.code == 2
    capsys.readouterr()


def test_batch_answers_every_row_in_order_and_exits_3_when_some_are_refused(
        capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    """One JSON line per CSV row; refused rows carry the reason; the others are answered."""
    batch = tmp_path / "rows.csv"
    batch.write_text("\ufeffh_drop;h_rebound\n2100;1100\n1000;1200\n2,1\n-5;1\n2000;2000\n", encoding="utf-8")
    code, out, _ = run(capsys, "solve", "drop-rebound", "--batch", str(batch), "--json")
    records = [json.loads(line) for line in out.splitlines()]
    assert code == 3
    assert [r["row"] for r in records] == [1, 2, 3, 4, 5]
    assert records[0]["answers"]["e"]["value"] == pytest.approx(0.7237, abs=1e-4)
    assert "cannot bounce higher" in records[1]["error"]
    assert "expected a finite number in mm" in records[2]["error"]
    assert "outside its domain (0, inf)" in records[3]["error"]
    assert records[4]["answers"]["e"]["value"] == 1.0
    assert records[4]["answers"]["loss_pct"]["value"] == 0.0


def test_batch_without_refusals_exits_0(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    """A tab-separated file with good rows answers all of them."""
    batch = tmp_path / "rows.tsv"
    batch.write_text("v\ttheta\te\n50\t30\t0.5\n40\t45\t0.9\n", encoding="utf-8")
    code, out, _ = run(capsys, "solve", "ball-plate", "--batch", str(batch), "--json")
    assert code == 0
    assert len(out.splitlines()) == 2


@pytest.mark.parametrize(("content", "message"), [
    ("v,theta\n50,30\n", "missing parameter(s) e"),
    ("v,theta,e,spin\n50,30,0.5,1\n", "unknown parameter(s) spin"),
    ("", "empty file"),
], ids=["missing-column", "extra-column", "empty"])
def test_batch_with_wrong_columns_exits_2(capsys: pytest.CaptureFixture[str], tmp_path: Path,
                                          content: str, message: str) -> None:
    """A header that does not name the template's parameters is refused as a whole."""
    batch = tmp_path / "rows.csv"
    batch.write_text(content, encoding="utf-8")
    code, out, err = run(capsys, "solve", "ball-plate", "--batch", str(batch))
    assert (code, out) == (2, "")
    assert message in err


def test_missing_batch_file_exits_2(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    """A batch file that cannot be read is named in the message."""
    code, _, err = run(capsys, "solve", "ball-plate", "--batch", str(tmp_path / "none.csv"))
    assert code == 2
    assert "none.csv: cannot read" in err


def test_show_prints_scene_parameters_and_step_chain(capsys: pytest.CaptureFixture[str]) -> None:
    """grader show lists bodies, parameters with units and domains, and the derived steps."""
    code, out, _ = run(capsys, "show", "drop-rebound")
    assert code == 0
    for fragment in ("floor: fixed surface", "h_drop     mm     (0, inf)", "Step chain",
                     "=> e = -v_after/v_impact", "=> v_impact = sqrt(2*g*h_drop)"):
        assert fragment in out
    _, out, _ = run(capsys, "show", "drop-rebound", "--json")
    assert [step["unknown"] for step in json.loads(out)["steps"]][:3] == ["v_impact", "T", "v_after"]


def test_list_json_names_every_template(capsys: pytest.CaptureFixture[str]) -> None:
    """grader list --json: one object per template with its parameters and answers."""
    _, out, _ = run(capsys, "list", "--json")
    records = {json.loads(line)["id"]: json.loads(line) for line in out.splitlines()}
    assert records["car-collision"]["answers"] == ["vA", "vB", "vA_ratio", "vB_ratio"]


HEAVY = ("scipy", "sympy", "matplotlib", "typst", "jinja2", "pint")


@pytest.mark.parametrize("argv", [
    ["--help"], ["list"], ["list", "--json"], ["solve", "pile-driver", *PILE], ["solve", "car-collision", "--set",
                                                                            "p=0.5", "--set", "e=0.1", "--json"],
    ["show", "drop-rebound"], ["solve", "--help"], ["check", "--help"], ["grade", "--help"], ["generate", "--help"],
    ["simulate", "--help"], ["demo", "--help"],
], ids=lambda argv: " ".join(argv[:2]))
def test_commands_import_no_heavy_library_they_do_not_need(argv: list[str], compiled: dict[str, Any]) -> None:
    """`grader --help`, `list`, a warm `solve` or `show` (the compiled template is cached) and every
    command's --help import none of scipy, sympy, matplotlib, typst, jinja2, pint: importing scipy
    through the effects once tripled their start-up, and loading a template imported jinja2."""
    import subprocess
    import sys

    code = ("import sys\nfrom grader.cli import main\ntry:\n    main(sys.argv[1:])\nexcept SystemExit:\n    pass\n"
            f"print(sorted(m for m in {HEAVY!r} if m in sys.modules), file=sys.stderr)")
    result = subprocess.run([sys.executable, "-c", code, *argv], capture_output=True, text=True, timeout=60,
                            check=True)
    assert result.stderr.strip().splitlines()[-1] == "[]", result.stderr
