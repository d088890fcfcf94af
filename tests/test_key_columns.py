"""key.columns.npz, the sidecar of key.json that grading reads in its place (issue 29): the key it gives is
the key key.json gives, the reports graded with it are byte for byte those graded without it, and a sidecar
that is missing, made from another key.json, or damaged is passed over."""

from __future__ import annotations

import json
import shutil
import zipfile
from dataclasses import replace
from pathlib import Path

import pytest

from grader.assign.assignment import load_assignment, load_roster
from grader.assign.key_columns import read_key_columns, sidecar, write_key_columns
from grader.assign.sample_answers import sample_answers, submissions_csv
from grader.assign.variants import generate
from grader.bank.template import load_bank
from grader.base.resources import sample_dir
from grader.cli import main
from grader.grade.key import KeyPart, load_key
from grader.grade.run import run

# The sample's five problems (units, a symbolic problem, errors carried forward and diagnosed mistakes in the
# simulated answers), with a late policy and a student's extension.
LATE = 'late: {grace: "15 min", deduct: "10 %", per: day, lowest: "40 %", after: "7 days"}\n'


@pytest.fixture(scope="module")
def graded_class(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A generated class (key.json and its sidecar) and the sample's simulated submissions."""
    folder = tmp_path_factory.mktemp("class")
    text = (sample_dir() / "assignment.yaml").read_text(encoding="utf-8")
    (folder / "assignment.yaml").write_text(text.replace('due: "2026-12-04 23:59"\n',
                                                         'due: "2026-12-04 23:59"\n' + LATE), encoding="utf-8")
    roster = (sample_dir() / "roster.csv").read_text(encoding="utf-8").splitlines()
    header = roster[0] + ",due"
    rows = [line + ("," if index else ",2026-12-06 12:00") for index, line in enumerate(roster[1:])]
    (folder / "roster.csv").write_text("\n".join([header, *rows]) + "\n", encoding="utf-8")
    assert main(["generate", str(folder / "assignment.yaml"), "--roster", str(folder / "roster.csv"), "--out",
                 str(folder / "hw"), "--no-pdf"]) == 0
    bank = load_bank()
    assignment = load_assignment(folder / "assignment.yaml")
    generation = generate(assignment, load_roster(folder / "roster.csv"), bank)
    (folder / "answers.csv").write_text(submissions_csv(sample_answers(assignment, generation, bank)),
                                        encoding="utf-8")
    return folder


def _outputs(folder: Path) -> dict[str, bytes]:
    return {path.name: path.read_bytes() for path in sorted(folder.iterdir())}


def test_generate_writes_a_sidecar_that_gives_the_key_key_json_gives(graded_class: Path, tmp_path: Path) -> None:
    key = graded_class / "hw" / "key.json"
    assert sidecar(key).is_file()
    alone = tmp_path / "key.json"
    shutil.copyfile(key, alone)  # no sidecar beside it: read from the JSON
    from_json, from_columns = load_key(alone), load_key(key)
    assert from_columns == replace(from_json, where=str(key))
    assert from_columns.late is not None and any(student.due for student in from_columns.students)
    assert any(part.symbolic for part in from_columns.students[0].parts.values())
    assert [s.parameters for s in from_columns.students] == [s.parameters for s in from_json.students]


def test_a_label_of_every_student_at_once_is_each_students_part(graded_class: Path, tmp_path: Path) -> None:
    """Key.part_column (the sidecar's table, made together) gives each student's own part, symbolic ones and
    points as key.json gives them, and Key.part_entries each entry of them; a student's possible points are the
    sum over their parts, in order."""
    key = graded_class / "hw" / "key.json"
    alone = tmp_path / "key.json"
    shutil.copyfile(key, alone)
    from_json, from_columns = load_key(alone), load_key(key)
    for label in from_columns.labels:
        assert from_columns.part_column(label) == [s.parts[label] for s in from_json.students], label
        assert from_json.part_column(label) == [s.parts[label] for s in from_columns.students], label
        for field in KeyPart._fields:
            assert from_columns.part_entries(label, field) == [getattr(s.parts[label], field)
                                                               for s in from_json.students], (label, field)
    assert [s.possible for s in from_columns.students] == [sum(p.points for p in s.parts.values())
                                                           for s in from_json.students]
    first = from_columns.students[0].parts
    assert list(first) == list(from_json.students[0].parts) and len(first) == len(from_json.students[0].parts)
    assert "no such label" not in first and next(iter(first)) in first


def test_grading_with_the_sidecar_is_byte_identical_to_grading_without(graded_class: Path) -> None:
    key, answers = graded_class / "hw" / "key.json", graded_class / "answers.csv"
    with_columns = run(key, [answers], graded_class / "with")
    plain = graded_class / "plain"
    plain.mkdir()
    shutil.copyfile(key, plain / "key.json")
    without = run(plain / "key.json", [answers], graded_class / "without")
    assert with_columns.verdicts == without.verdicts
    assert {"ecf", "mistake", "incorrect", "invalid", "missing"} <= {k for k, n in with_columns.verdicts.items() if n}
    mine, theirs = _outputs(graded_class / "with"), _outputs(graded_class / "without")
    assert mine.keys() == theirs.keys()
    for name in mine:
        if name != ".grader-manifest.json":  # names the key's path
            assert mine[name] == theirs[name], name


def _grade_all(folder: Path, key: Path, answers: Path, name: str) -> dict[str, bytes]:
    run(key, [answers], folder / name)
    return {k: v for k, v in _outputs(folder / name).items() if k != ".grader-manifest.json"}


def test_a_missing_stale_or_damaged_sidecar_is_passed_over(graded_class: Path, tmp_path: Path) -> None:
    answers = graded_class / "answers.csv"
    key = tmp_path / "key.json"
    shutil.copyfile(graded_class / "hw" / "key.json", key)
    assert write_key_columns(key)
    expected = _grade_all(tmp_path, key, answers, "fresh")
    good = sidecar(key).read_bytes()
    # Stale: key.json edited after the sidecar was written (a student's answer changed). The sidecar is not
    # used: the grades follow the edited key.
    raw = json.loads(key.read_text(encoding="utf-8"))
    student = raw["students"][0]
    answer = next(iter(student["problems"][0]["answers"].values()))
    answer["value"] = answer["value"] * 3
    edited = tmp_path / "edited.json"
    edited.write_text(json.dumps(raw), encoding="utf-8")
    assert read_key_columns(edited) is None
    shutil.copyfile(key, tmp_path / "stale.json")
    sidecar(tmp_path / "edited.json").write_bytes(good)  # the old key's sidecar beside the edited key
    assert read_key_columns(edited) is None
    sidecar(tmp_path / "edited.json").unlink()
    reference = _grade_all(tmp_path, edited, answers, "edited-alone")
    sidecar(tmp_path / "edited.json").write_bytes(good)
    assert _grade_all(tmp_path, edited, answers, "edited-stale") == reference
    assert load_key(edited).students[0].parts[answer["label"]].value == answer["value"]
    # Damaged: cut short, bytes flipped inside an array, not a zip at all, an empty file; or missing.
    middle = len(good) // 2
    flipped = good[:middle] + bytes([good[middle] ^ 0xFF]) + good[middle + 1:]
    for number, damaged in enumerate((good[:middle], flipped, b"not a zip", b"", None)):
        if damaged is None:
            sidecar(key).unlink()
        else:
            sidecar(key).write_bytes(damaged)
        assert read_key_columns(key) is None
        assert _grade_all(tmp_path, key, answers, f"damaged-{number}") == expected


def test_a_sidecar_altered_consistently_with_its_zip_is_refused_unless_its_hash_matches(tmp_path: Path) -> None:
    """The hash ties a sidecar to one key.json: a sidecar rewritten whole (its zip sound) for another key is
    passed over too."""
    key = tmp_path / "key.json"
    document = {"schema": "grader-key", "version": 2, "assignment": {"title": "HW"},
                "problems": [{"key": "1", "answers": [{"name": "e", "label": "1a", "unit": "", "points": 2}]}],
                "students": [{"id": "007", "problems": [{"key": "1", "answers": {"e": {
                    "value": 0.7, "unit": "", "label": "1a", "points": 2,
                    "tolerance": {"mode": "rtol", "rtol": 0.01, "atol": 0}}}}]}]}
    key.write_text(json.dumps(document), encoding="utf-8")
    assert write_key_columns(key)
    first = sidecar(key).read_bytes()
    document["students"][0]["problems"][0]["answers"]["e"]["value"] = 0.8
    key.write_text(json.dumps(document), encoding="utf-8")
    sidecar(key).write_bytes(first)
    assert load_key(key).students[0].parts["1a"].value == 0.8
    with zipfile.ZipFile(sidecar(key)) as archive:
        assert sorted(archive.namelist()) == ["code.npy", "meta.npy", "params.npy", "points.npy", "shape.npy",
                                              "value.npy"]


@pytest.mark.parametrize(("change", "why"), [
    (lambda s: s["problems"][0]["answers"]["e"].update(value=True), "a value that is no number"),
    (lambda s: s["problems"][0].update(params={"h": "tall"}), "a parameter that is no number"),
    (lambda s: s["problems"][0].update(key=1), "a problem key that is no text"),
    (lambda s: s["problems"][0]["answers"]["e"].update(points=10**400), "points beyond float64"),
])
def test_a_key_not_shaped_as_generate_writes_it_gets_no_sidecar(tmp_path: Path, change: object, why: str) -> None:
    key = tmp_path / "key.json"
    student = {"id": "007", "problems": [{"key": "1", "answers": {"e": {
        "value": 0.7, "unit": "", "label": "1a", "points": 2, "tolerance": {"mode": "rtol", "rtol": 0.01}}}}]}
    change(student)  # type: ignore[operator]
    key.write_text(json.dumps({"schema": "grader-key", "version": 2, "students": [student]}), encoding="utf-8")
    sidecar(key).write_bytes(b"an old one")
    assert not write_key_columns(key), why
    assert not sidecar(key).exists()


def test_a_key_the_json_reader_refuses_is_refused_with_its_message_despite_a_sidecar(tmp_path: Path) -> None:
    """A sidecar is made from a key grading would refuse (a unit no key holds): grading refuses it as before."""
    key = tmp_path / "key.json"
    student = {"id": "007", "problems": [{"key": "1", "answers": {"e": {
        "value": 0.7, "unit": "furlongs", "label": "1a", "points": 2, "tolerance": {"mode": "rtol", "rtol": 0.01}}}}]}
    key.write_text(json.dumps({"schema": "grader-key", "version": 2, "assignment": {"title": "HW"},
                               "problems": [{"key": "1", "answers": [{"name": "e", "label": "1a"}]}],
                               "students": [student]}), encoding="utf-8")
    assert write_key_columns(key)
    with pytest.raises(Exception, match="furlongs") as found:
        load_key(key)
    sidecar(key).unlink()
    with pytest.raises(Exception, match="furlongs") as again:
        load_key(key)
    assert str(found.value) == str(again.value)


def test_generating_twice_gives_the_same_sidecar(tmp_path: Path) -> None:
    key = tmp_path / "key.json"
    key.write_text(json.dumps({"schema": "grader-key", "version": 2, "students": []}), encoding="utf-8")
    assert write_key_columns(key)
    first = sidecar(key).read_bytes()
    assert write_key_columns(key)
    assert sidecar(key).read_bytes() == first


def test_a_sidecar_compressed_or_larger_than_its_key_is_passed_over_unread(tmp_path: Path) -> None:
    """A zip whose members unpack to more than the file (a zip bomb), or a file bigger than its key's
    columns could be, is no sidecar grader wrote: key.json is read."""
    key = tmp_path / "key.json"
    key.write_text(json.dumps({"schema": "grader-key", "version": 2, "students": []}), encoding="utf-8")
    assert write_key_columns(key)
    with zipfile.ZipFile(sidecar(key)) as archive:
        members = {name: archive.read(name) for name in archive.namelist()}
    assert read_key_columns(key) is not None
    with zipfile.ZipFile(sidecar(key), "w", zipfile.ZIP_DEFLATED) as archive:
        for name, content in members.items():
            archive.writestr(name, content)
    assert read_key_columns(key) is None
    sidecar(key).write_bytes(b"\0" * (len(key.read_bytes()) + (1 << 16) + 1))
    assert read_key_columns(key) is None


def test_a_key_laid_out_a_student_a_line_is_read_a_line_at_a_time_to_the_same_sidecar(
        graded_class: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """grader generate's layout is read line by line (a big class's key is never held whole); the same key
    written on one line is decoded whole; both give the same sidecar, but for the hash of the bytes."""
    import grader.assign.key_columns as key_columns

    key = tmp_path / "key.json"
    shutil.copyfile(graded_class / "hw" / "key.json", key)
    whole = []
    decode_text = key_columns.decode_text
    monkeypatch.setattr(key_columns, "decode_text", lambda *given: whole.append(1) or decode_text(*given))
    assert write_key_columns(key) and not whole
    by_line = read_key_columns(key)
    compact = tmp_path / "compact.json"
    compact.write_text(json.dumps(json.loads(key.read_text(encoding="utf-8")), ensure_ascii=False), encoding="utf-8")
    assert write_key_columns(compact) and whole
    decoded = read_key_columns(compact)
    assert by_line is not None and decoded is not None
    for name in ("header", "ids", "names", "emails", "sections", "dues", "shapes", "texts", "tolerances"):
        assert getattr(by_line, name) == getattr(decoded, name), name
    for name in ("shape", "value", "points", "code", "params"):
        assert getattr(by_line, name).tobytes() == getattr(decoded, name).tobytes(), name


def test_the_sidecar_is_an_output_like_any_other_for_the_manifest(tmp_path: Path,
                                                                   capsys: pytest.CaptureFixture[str]) -> None:
    """Listed in the manifest: altered by hand, generate --force refuses to replace the folder, naming it."""
    out = tmp_path / "hw"
    arguments = ["generate", str(sample_dir() / "assignment.yaml"), "--roster", str(sample_dir() / "roster.csv"),
                 "--out", str(out), "--no-pdf"]
    assert main(arguments) == 0
    assert "key.columns.npz" in json.loads((out / ".grader-manifest.json").read_text(encoding="utf-8"))["files"]
    sidecar(out / "key.json").write_bytes(b"edited")
    capsys.readouterr()
    assert main([*arguments, "--force"]) == 2
    assert "key.columns.npz (changed since grader wrote it)" in capsys.readouterr().err


def test_a_key_over_the_limit_with_its_sidecar_is_graded_the_same(graded_class: Path, tmp_path: Path,
                                                                   monkeypatch: pytest.MonkeyPatch) -> None:
    """KEY_BYTES bounds only key.json read whole (issue 29): with its sidecar a larger key is hashed a piece at a
    time and graded, to the bytes a key within the limit gives. The limit is made small, not the file large."""
    import grader.grade.key as key_module

    key, answers = graded_class / "hw" / "key.json", graded_class / "answers.csv"
    expected = _grade_all(tmp_path, key, answers, "within")
    monkeypatch.setattr(key_module, "KEY_BYTES", key.stat().st_size - 1)
    assert _grade_all(tmp_path, key, answers, "over") == expected


@pytest.mark.parametrize("sidecar_is", ["missing", "stale"])
def test_a_key_over_the_limit_without_a_sidecar_made_from_it_is_refused_with_the_way_out(
        graded_class: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str],
        sidecar_is: str) -> None:
    import grader.grade.key as key_module

    key = tmp_path / "key.json"
    shutil.copyfile(graded_class / "hw" / "key.json", key)
    if sidecar_is == "stale":  # made from the key before a byte was added to it
        shutil.copyfile(sidecar(graded_class / "hw" / "key.json"), sidecar(key))
        with open(key, "a", encoding="utf-8") as stream:
            stream.write("\n")
    monkeypatch.setattr(key_module, "KEY_BYTES", 1000)
    assert main(["grade", "--key", str(key), str(graded_class / "answers.csv"), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert f"{key}: {key.stat().st_size:,} bytes, more than the 1,000 a key.json is read whole within" in err
    assert "regenerate the key with grader generate, which writes key.columns.npz beside it" in err
    assert not (tmp_path / "out").exists()


def test_a_submissions_file_over_the_limit_is_refused_and_graded_split_in_two_files(
        graded_class: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    """The submissions' limit (its text is held whole while read) names the way out: the rows split over files
    under it, read in turn, give the same grades. The limit is made small, not the file large."""
    import grader.grade.submissions as submissions

    key, answers = graded_class / "hw" / "key.json", graded_class / "answers.csv"
    expected = _grade_all(tmp_path, key, answers, "whole")
    monkeypatch.setattr(submissions, "SUBMISSIONS_BYTES", answers.stat().st_size - 1)
    assert main(["grade", "--key", str(key), str(answers), "--out", str(tmp_path / "refused")]) == 2
    err = capsys.readouterr().err
    assert f"{answers}: {answers.stat().st_size:,} bytes, more than the {answers.stat().st_size - 1:,} a " \
           "submissions file is read within; split its rows into files under that size" in err
    assert not (tmp_path / "refused").exists()
    header, *rows = answers.read_text(encoding="utf-8").splitlines(keepends=True)
    halves = [tmp_path / "first.csv", tmp_path / "second.csv"]
    halves[0].write_text(header + "".join(rows[:len(rows) // 2]), encoding="utf-8")
    halves[1].write_text(header + "".join(rows[len(rows) // 2:]), encoding="utf-8")
    run(key, halves, tmp_path / "split")
    assert (tmp_path / "split" / "grades.csv").read_bytes() == expected["grades.csv"]


def test_points_of_minus_zero_and_zero_read_from_the_sidecar_as_from_key_json(tmp_path: Path) -> None:
    """The sidecar's parts are grouped by their entries' bits (-0.0 apart from 0.0), then shaped as key.json's
    reader shapes them, where equal points are one: the first found."""
    def student(number: int, points: float) -> dict[str, object]:
        return {"id": f"s{number}", "problems": [{"key": "1", "answers": {"e": {
            "value": 0.7, "unit": "", "label": "1a", "points": points, "tolerance": {"mode": "rtol", "rtol": 0.01,
                                                                                       "atol": 0}}}}]}

    for order in ((-0.0, 0.0, -0.0), (0.0, -0.0, 0.0)):
        folder = tmp_path / str(order[0])
        folder.mkdir()
        key = folder / "key.json"
        key.write_text(json.dumps({"schema": "grader-key", "version": 2, "assignment": {"title": "HW"},
                                   "problems": [{"key": "1", "answers": [{"name": "e", "label": "1a", "unit": "",
                                                                           "points": 2}]}],
                                   "students": [student(n, p) for n, p in enumerate(order)]}), encoding="utf-8")
        assert write_key_columns(key)
        alone = folder / "alone" / "key.json"
        alone.parent.mkdir()
        shutil.copyfile(key, alone)
        from_json, from_columns = load_key(alone), load_key(key)
        assert from_columns == replace(from_json, where=str(key))
        signs = [str(s.parts["1a"].points) for s in from_columns.students]
        assert signs == [str(order[0])] * 3  # the first found, for all three
