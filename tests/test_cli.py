"""The command line: outputs, exit codes (0 ok, 2 bad input, 3 rows refused) and messages."""

from __future__ import annotations

import ast
import json
import os
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
    assert set(record["answers"]) == {"v_pile", "e", "loss_pct", "energy_lost", "impulse"}
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
    ["simulate", "--help"], ["demo", "--help"], ["effects"], ["effects", "--help"],
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


def _imported(argv: list[str], modules: tuple[str, ...], env: dict[str, str] | None = None) -> list[str]:
    """Which of ``modules`` a run of ``grader ARGV``, in a process of its own, imported."""
    import subprocess
    import sys

    code = ("import sys\nfrom grader.cli import main\ntry:\n    main(sys.argv[1:])\nexcept SystemExit:\n    pass\n"
            f"print(sorted(m for m in {modules!r} if m in sys.modules), file=sys.stderr)")
    result = subprocess.run([sys.executable, "-c", code, *argv], capture_output=True, text=True, timeout=60,
                            check=True, env=env)
    return list(ast.literal_eval(result.stderr.strip().splitlines()[-1]))


@pytest.mark.parametrize("argv", [["list"], ["list", "--json"]], ids=" ".join)
def test_a_cold_list_imports_no_heavy_library_and_a_warm_one_reads_no_template(argv: list[str],
                                                                              tmp_path: Path) -> None:
    """The first `grader list` with an empty cache reads the bank (numpy and PyYAML, none of the heavy
    libraries); the second takes the listing from the cache: no YAML read, no numpy, no physics."""
    env = {**os.environ, "GRADER_CACHE_DIR": str(tmp_path / "cache")}
    assert _imported(argv, HEAVY, env) == []
    assert _imported(argv, ("yaml", "numpy", "grader.physics", "grader.bank.template"), env) == []


def test_a_warm_solve_reads_no_yaml(compiled: dict[str, Any]) -> None:
    """A second `grader solve` reads what the template's YAML reads as from the cache (no PyYAML), and
    imports nothing only some commands need."""
    argv = ["solve", "pile-driver", *PILE]
    _imported(argv, ())
    assert _imported(argv, ("yaml", "csv", "difflib", "shutil", "grader.physics.integrate",
                            "grader.solve.routes", "grader.solve.alternatives", *HEAVY)) == []


def test_list_groups_the_bank_by_topic(capsys: pytest.CaptureFixture[str]) -> None:
    """A heading per topic, in the order of the list (direct, oblique, drops and rebounds, impact and a swing,
    impact and sliding, impact with flight: each topic the bank has); each template under its own."""
    from grader.bank.template import TOPICS, load_bank

    code, out, _ = run(capsys, "list")
    headings = [line for line in out.splitlines() if line and not line.startswith(" ")]
    present = {template.topic for template in load_bank().values()}
    assert code == 0 and headings == [f"{topic[0].upper()}{topic[1:]}" for topic in TOPICS if topic in present]
    assert headings[:3] == ["Direct impact", "Oblique impact", "Drops and rebounds"] and len(headings) == 6
    under, heading = {}, ""
    for line in out.splitlines()[2:]:
        heading = line if not line.startswith(" ") else heading
        if line.startswith("  "):
            under[line.split()[0]] = heading.lower()
    assert under == {t.id: t.topic for t in load_bank().values()}
    _, out, _ = run(capsys, "list", "--json")
    records = [json.loads(line) for line in out.splitlines()]
    assert {r["id"]: r["topic"] for r in records} == under
    assert [r["topic"] for r in records] == sorted((r["topic"] for r in records), key=TOPICS.index)


def test_list_shows_the_bank_whatever_its_cache_entry_says(capsys: pytest.CaptureFixture[str], tmp_path: Path,
                                                          monkeypatch: pytest.MonkeyPatch) -> None:
    """A listing entry (sealed as grader seals them) with a topic outside the list stopped `grader list` with a
    traceback; one with a row no template file has listed it."""
    from grader.base import caching

    monkeypatch.setenv("GRADER_CACHE_DIR", str(tmp_path))
    _, fresh, _ = run(capsys, "list")
    (entry,) = tmp_path.glob("bank-*.json")
    kept = caching.read_entry(entry)
    kept["templates"][0]["topic"] = "no such topic"
    kept["templates"].append({**kept["templates"][1], "id": "ghost", "title": "\x1b[31mghost"})
    caching.write_entry(entry, kept)
    assert run(capsys, "list") == (0, fresh, "")


def test_show_prints_the_statement_with_the_example_numbers_and_their_answers(
        capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "show", "pile-driver")
    assert code == 0
    text = " ".join(out.split())
    assert "The 800-kg ram of a pile driver is released from rest 2.00 m above the top of a 2400-kg pile." in text
    assert "bounces back up 0.10 m." in text
    assert "v_pile 2.555 m/s e 0.63148 loss_pct 45.093 %" in text
    _, out, _ = run(capsys, "show", "pile-driver", "--json")
    record = json.loads(out)
    assert record["example"] == {"m_ram": "800", "m_pile": "2400", "h_drop": "2.00", "h_rebound": "0.10"}
    assert record["topic"] == "drops and rebounds" and "2400-kg pile" in record["statement"]
    assert record["example_answers"]["e"]["value"] == pytest.approx(0.63148, rel=1e-5)


def test_show_shows_escape_sequences_in_a_template_as_text(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    """A template's descriptions reach the terminal as text: an escape sequence in one (YAML has them in
    double quotes) is shown as its escape, never acted on (a colour, a cleared screen)."""
    folder = _own_bank(tmp_path, "bank", "escapes", "description: height the ball bounces back up to",
                       'description: "height the ball bounces back up to\\e[2J"')
    code, out, _ = run(capsys, "show", "escapes", "--bank", str(folder))
    assert code == 0 and "\x1b" not in out
    assert "height the ball bounces back up to\\x1b[2J" in out


def _own_bank(tmp_path: Path, name: str, template_id: str, old: str = "", new: str = "") -> Path:
    """A folder with drop-rebound copied as ``template_id`` (``old`` replaced by ``new``)."""
    from grader.base.resources import bank_dir

    folder = tmp_path / name
    folder.mkdir()
    text = (bank_dir() / "drop-rebound.yaml").read_text(encoding="utf-8").replace("id: drop-rebound",
                                                                                 f"id: {template_id}")
    (folder / f"{template_id}.yaml").write_text(text.replace(old, new), encoding="utf-8")
    return folder


@pytest.mark.parametrize("title", ["Ball\\rdropped", "Ball\\u2028dropped", "\\e[2J\\e[31mBall"],
                         ids=["return", "line separator", "escape sequence"])
def test_list_refuses_a_title_a_terminal_would_act_on(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                      title: str) -> None:
    """A title with a line break of any kind stopped `grader list` with a traceback (its table had more lines than
    templates); an escape sequence was printed for the terminal to act on."""
    mine = _own_bank(tmp_path, "mine", "my-drop", "title: Ball dropped onto a rigid floor", f'title: "{title}"')
    code, out, err = run(capsys, "--bank", str(mine), "--no-shipped-bank", "list")
    assert code == 2 and not out
    assert "my-drop.yaml: title: expected one line of text without control characters" in err


@pytest.mark.parametrize("command", [
    ["list"], ["show", "my-drop"], ["solve", "my-drop", "--set", "h_drop=2100", "--set", "h_rebound=1100"],
    ["simulate", "my-drop", "--set", "h_drop=2100", "--set", "h_rebound=1100"], ["check-bank", "--no-shipped-bank"],
])
def test_every_command_reads_repeated_banks_before_or_after_its_name(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], command: list[str]) -> None:
    mine, more = _own_bank(tmp_path, "mine", "my-drop"), _own_bank(tmp_path, "more", "my-other-drop")
    code, out, err = run(capsys, "--bank", str(mine), command[0], "--bank", str(more), *command[1:])
    assert code == 0, err
    assert "my-drop" in out
    if command == ["list"]:
        assert "my-other-drop" in out and "pile-driver" in out


@pytest.mark.parametrize("command", [["list"], ["show", "drop-rebound"], ["demo", "--out", "demo-out"],
                                     ["generate", "a.yaml", "--roster", "r.csv", "--out", "out"]])
def test_a_template_id_in_two_banks_is_refused_by_every_command(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], command: list[str], workdir: str) -> None:
    """Exit 2 before any work, naming both files; nothing is written (check-bank reports it as one template's
    failure: tests/test_bankcheck.py)."""
    from grader.base.resources import bank_dir

    copy = _own_bank(tmp_path, "copy", "drop-rebound")
    code, out, err = run(capsys, command[0], "--bank", str(copy), *command[1:])
    assert code == 2 and not out
    assert f"two templates have the id 'drop-rebound': {bank_dir() / 'drop-rebound.yaml'} and " \
           f"{copy / 'drop-rebound.yaml'}" in err
    assert not (Path(workdir) / "demo-out").exists() and not (Path(workdir) / "out").exists()


def test_the_compile_cache_keeps_same_id_templates_of_two_folders_apart(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The cache is keyed by the template's content: a colleague's drop-rebound with g = 32.2 ft/s^2 is not
    answered from the shipped one's compiled form, nor the other way round."""
    from grader.solve.cache import SHIPPED, cache_dir

    theirs = _own_bank(tmp_path, "theirs", "drop-rebound", "gravity: 9.81 m/s^2", "gravity: 9.80 m/s^2")
    theirs_text = (theirs / "drop-rebound.yaml").read_text(encoding="utf-8").replace(
        "loss_fraction: f_loss", "loss_fraction: f_loss\n  - {effect: rise, body: ball, speed: v_impact, "
        "height: h_apex}").replace("answers:\n", "answers:\n  h_apex: {value: h_apex, unit: m}\n")
    (theirs / "drop-rebound.yaml").write_text(theirs_text, encoding="utf-8")
    answers = {}
    for name, argv in (("ours", []), ("theirs", ["--no-shipped-bank", "--bank", str(theirs)]), ("ours again", [])):
        code, out, err = run(capsys, *argv, "solve", "drop-rebound", "--set", "h_drop=2100", "--set",
                             "h_rebound=1100", "--json")
        assert code == 0, err
        answers[name] = json.loads(out)["answers"]
    assert set(answers["ours"]) == set(answers["ours again"]) == {"e", "loss_pct"}
    assert answers["theirs"]["h_apex"]["value"] == pytest.approx(2.1)
    kept = {path.name for folder in (cache_dir(), SHIPPED) for path in folder.glob("drop-rebound-*.json")}
    assert len({name for name in kept if not name.endswith(("-alternatives.json", "-routes.json"))}) >= 2


def test_generate_draws_an_instructors_template_beside_the_shipped_ones(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], workdir: str) -> None:
    """An assignment naming a template of the instructor's own folder and a shipped one."""
    mine = _own_bank(tmp_path, "mine", "my-drop", "Before a game", "Before the final")
    Path("a.yaml").write_text("title: HW\ncourse: C\nseed: s\nproblems:\n  - template: my-drop\n"
                              "  - template: pile-driver\n", encoding="utf-8")
    Path("r.csv").write_text("id,name,email,section\n1,Ann,a@x.org,A\n", encoding="utf-8")
    code, _, err = run(capsys, "generate", "a.yaml", "--roster", "r.csv", "--out", "out", "--no-pdf",
                       "--bank", str(mine))
    assert code == 0, err
    key = json.loads(Path("out/key.json").read_text(encoding="utf-8"))
    assert [p["template"] for p in key["problems"]] == ["my-drop", "pile-driver"]
