"""Partial credit from the physics (issue 12): diagnosed mistakes, each on a hand-built case from a seed
problem (the expected values worked out here by hand, not by the solver), and error carried forward."""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import yaml

from grader.bank.template import Template, parse_template
from grader.base.resources import bank_dir
from grader.cli import main
from grader.grade.diagnosis import physics_for
from grader.grade.grading import Verdict, grade
from grader.grade.key import Key, KeyPart, KeyProblem, KeyStudent
from grader.grade.submissions import Answer, Submissions
from grader.solve.alternatives import Alternatives, values
from grader.solve.cache import alternatives_for, compiled_for
from grader.solve.evaluate import solve_one
from tests.demo_output import DemoRun
from tests.scenes import RAM_AND_PILE

G, G_US = 9.81, 32.2
SQRT = math.sqrt

# Sample Problem 3/28: the 800-kg ram falls 2 m onto the 2400-kg pile and rebounds 0.1 m.
PILE = {"m_ram": 800, "m_pile": 2400, "h_drop": 2, "h_rebound": 0.1}
V_RAM, V_BACK = SQRT(2 * G * 2), SQRT(2 * G * 0.1)
V_PILE = 800 * (V_RAM + V_BACK) / 2400
E_PILE = (V_PILE + V_BACK) / V_RAM
KEPT_PCT = 100 * (800 * V_BACK**2 + 2400 * V_PILE**2) / (800 * V_RAM**2)
# Sample Problem 3/29: the ball strikes the plate at 50 ft/s, 30 degrees from its surface, e = 0.5.
PLATE = {"v": 50, "theta": 30, "e": 0.5}
V_N, V_T = 50 * math.sin(math.radians(30)), 50 * math.cos(math.radians(30))
THETA_OUT = math.degrees(math.atan2(0.5 * V_N, V_T))
# Sample Problem 3/30: sphere 1 at 6 m/s, 30 degrees from the line of centres, strikes an equal sphere at rest.
SPHERES = {"v1": 6, "theta": 30, "e": 0.6, "m1": 1, "m2": 1}
# Problem 3/251: the basketball dropped from 2100 mm rebounds to 1100 mm.
BALL = {"h_drop": 2100, "h_rebound": 1100}
# Problem 3/255: car A strikes car B (p times its mass) at rest; e = 0.1.
CARS = {"p": 0.5, "e": 0.1}

MISTAKES = [
    # impact
    ("pile-driver", PILE, "v_pile", "impact.rebound_sign", 800 * (V_RAM - V_BACK) / 2400),
    ("ball-plate", PLATE, "theta_out", "impact.rebound_sign", -THETA_OUT),
    ("car-collision", CARS, "vA_ratio", "impact.rebound_sign", -(1 - 0.1 * 0.5) / 1.5),
    ("ball-plate", PLATE, "v_out", "impact.e_squared", math.hypot(0.5**2 * V_N, V_T)),
    ("drop-rebound", BALL, "e", "impact.e_squared", (1100 / 2100) ** 0.25),
    ("car-collision", CARS, "vA_ratio", "impact.e_squared", (1 - 0.1**2 * 0.5) / 1.5),
    ("ball-plate", PLATE, "v_out", "impact.e_inverse", math.hypot(V_N / 0.5, V_T)),
    ("pile-driver", PILE, "e", "impact.e_inverse", V_RAM / (V_PILE + V_BACK)),
    ("ball-plate", PLATE, "v_out", "impact.full_speed", math.hypot(0.5 * 50, V_T)),
    ("oblique-spheres", SPHERES, "v2_out", "impact.full_speed", (1 + 0.6) * 6 / 2),
    ("pile-driver", PILE, "v_pile", "impact.masses_swapped", 2400 * (V_RAM + V_BACK) / 800),
    ("car-collision", CARS, "vB_ratio", "impact.masses_swapped", 1.1 / (1 + 1 / 0.5)),
    ("ball-plate", PLATE, "theta_out", "impact.fixed_as_equal_mass",
     math.degrees(math.atan2(-V_N * (1 - 0.5) / 2, V_T))),  # the "plate" moves off; the ball follows it
    ("drop-rebound", BALL, "e", "impact.fixed_as_equal_mass", 1 + 2 * SQRT(1100 / 2100)),
    # flight
    ("pile-driver", PILE, "v_pile", "flight.sqrt_gh", 800 * (SQRT(G * 2) + SQRT(G * 0.1)) / 2400),
    ("drop-rebound", BALL, "e", "flight.two_gh", 1100 / 2100),  # e = h'/h
    ("pile-driver", PILE, "e", "flight.two_gh", (800 * (2 * G * 2.1) / 2400 + 2 * G * 0.1) / (2 * G * 2)),
    ("pile-driver", PILE, "v_pile", "flight.g_customary", 800 * (SQRT(2 * G_US * 2) + SQRT(2 * G_US * 0.1)) / 2400),
    # energy
    ("pile-driver", PILE, "loss_pct", "energy.kept_as_lost", KEPT_PCT),
    ("drop-rebound", BALL, "loss_pct", "energy.kept_as_lost", 100 * 1100 / 2100),
    ("pile-driver", PILE, "loss_pct", "energy.fraction_for_percent", (100 - KEPT_PCT) / 100),
    ("pile-driver", PILE, "loss_pct", "energy.wrong_sign", -(100 - KEPT_PCT)),
    # angles
    ("ball-plate", PLATE, "theta_out", "angle.other_axis", 90 - THETA_OUT),
    ("ball-plate", PLATE, "theta_out", "angle.radians", math.radians(THETA_OUT)),
]


def scene(height: str, gravity: str, speed: str) -> Template:
    text = RAM_AND_PILE.replace("HEIGHT", height).replace("GRAVITY", gravity).replace("SPEED", speed)
    return parse_template(yaml.safe_load(text), "ram-and-pile.yaml", f"ram-and-pile {height}")


IN_MM = scene("mm", "9.81 m/s^2", "m/s")
IN_FEET = scene("ft", "32.2 ft/s^2", "ft/s")
HAND_BUILT = [  # the same numbers in other units: the pile's speed with the mistake, by hand
    (IN_MM, {**PILE, "h_drop": 2000, "h_rebound": 100}, "v_pile", "flight.mm_as_m",
     800 * (SQRT(2 * G * 2000) + SQRT(2 * G * 100)) / 2400),
    (IN_FEET, PILE, "v_pile", "flight.g_metric", 800 * (SQRT(2 * G * 2) + SQRT(2 * G * 0.1)) / 2400),
]


def mistake_value(alternatives: Alternatives, params: Mapping[str, float], answer: str, mistake: str) -> float:
    found = [a for a in alternatives.for_answer(answer) if a.kind == "mistake" and a.id == mistake]
    assert len(found) == 1, [a.id for a in alternatives.for_answer(answer)]
    return float(values(alternatives, found[0], {k: np.array([float(v)]) for k, v in params.items()})[0])


@pytest.mark.parametrize(("template_id", "params", "answer", "mistake", "by_hand"), MISTAKES,
                         ids=[f"{m[3]}-{m[0]}-{m[2]}" for m in MISTAKES])
def test_a_mistake_gives_what_a_student_who_makes_it_answers(bank: dict[str, Template], template_id: str,
                                                             params: dict[str, float], answer: str, mistake: str,
                                                             by_hand: float) -> None:
    """The solver's chain under the mistake, against the seed problem worked by hand with the mistake; and
    that answer typed to 3 significant figures is graded ``mistake`` with the mistake's id."""
    template = bank[template_id]
    assert mistake_value(alternatives_for(template), params, answer, mistake) == pytest.approx(by_hand, rel=1e-9)
    verdict = graded_alone(template, params, answer, f"{by_hand:.3g}")
    assert (verdict.verdict, verdict.diagnosis, verdict.credit) == ("mistake", mistake, 0.0), verdict
    assert verdict.feedback.startswith("your answer matches ")


@pytest.mark.parametrize(("template", "params", "answer", "mistake", "by_hand"), HAND_BUILT,
                         ids=[m[3] for m in HAND_BUILT])
def test_a_mistake_of_units_in_a_problem_in_mm_or_in_feet(template: Template, params: dict[str, float], answer: str,
                                                          mistake: str, by_hand: float) -> None:
    assert mistake_value(alternatives_for(template), params, answer, mistake) == pytest.approx(by_hand, rel=1e-9)
    assert graded_alone(template, params, answer, f"{by_hand:.3g}").diagnosis == mistake


def test_each_system_has_only_the_other_systems_g(bank: dict[str, Template]) -> None:
    """A problem in feet may use 9.81, one in metres 32.2; a height in metres is not one in mm."""
    in_feet = {a.id for a in alternatives_for(IN_FEET).items}
    in_metres = {a.id for a in alternatives_for(bank["pile-driver"]).items}
    assert "flight.g_metric" in in_feet - in_metres and "flight.g_customary" in in_metres - in_feet
    assert "flight.mm_as_m" not in in_feet | in_metres


# --- one student, graded --------------------------------------------------------------------------

def student_key(template: Template, params: Mapping[str, float], ecf_credit: float = 1.0,
                mistake_credit: float = 0.0, tolerance: Mapping[str, object] | None = None) -> Key:
    """A key of one student (id s1) and one problem (labels 1a, 1b, ...), answers from the solver."""
    solution = solve_one(template, compiled_for(template), {k: float(v) for k, v in params.items()})
    assert solution.answers is not None, solution.error
    parts = {}
    for index, (name, found) in enumerate(solution.answers.items()):
        label = f"1{chr(ord('a') + index)}"
        parts[label] = KeyPart("1", name, label, found.value, found.unit, 1.0,
                               tolerance or {"mode": "rtol", "rtol": 0.01, "atol": 0.0}, found.undefined,
                               {"p": (0.3, 3.0), "v": (1.0, 10.0)} if isinstance(found.value, str) else {})
    return Key("test", 2, "Homework", True, (KeyProblem("1", template.title, tuple(parts), template.id),),
               (KeyStudent("s1", "Ana", "", "", parts, tuple(("1", name) for name in params),
                           tuple(float(value) for value in params.values())),), {template.id: template.source_hash},
               ecf_credit, mistake_credit)


def graded(key: Key, typed: Mapping[str, str], template: Template) -> dict[str, Verdict]:
    """The student's parts graded (``typed``: by label; the others left blank), by label."""
    answers = tuple(Answer("s.csv", line, "s1", label, text, ",", None)
                    for line, (label, text) in enumerate(typed.items(), start=2))
    result = grade(key, Submissions(answers, (), (), ()), physics_for(key, {template.id: template}))
    return {verdict.label: verdict for verdict in result.verdicts}


def graded_alone(template: Template, params: Mapping[str, float], answer: str, text: str) -> Verdict:
    key = student_key(template, params)
    label = next(label for label, part in key.students[0].parts.items() if part.name == answer)
    return graded(key, {label: text}, template)[label]


def test_the_first_mistake_in_the_effects_list_names_two_that_give_the_same_number(bank: dict[str, Template]) -> None:
    """With e = 0.5, e**2 = (1 - e)/2: using e**2, or taking the plate as a ball, gives 43.75 ft/s."""
    assert math.hypot(0.5**2 * V_N, V_T) == pytest.approx(math.hypot(V_N * (1 - 0.5) / 2, V_T))
    assert graded_alone(bank["ball-plate"], PLATE, "v_out", "43.75").diagnosis == "impact.e_squared"


def test_a_mistake_that_gives_the_right_answer_for_this_variant_is_not_diagnosed(bank: dict[str, Template]) -> None:
    """Equal masses: swapping them changes nothing, so 1.5 % off the right answer (within 1 % of "the masses
    swapped") is just wrong."""
    template = bank["oblique-spheres"]
    right = student_key(template, SPHERES).students[0].parts["1b"].value
    assert isinstance(right, float)
    assert mistake_value(alternatives_for(template), SPHERES, "v2_out", "impact.masses_swapped") == \
        pytest.approx(right)
    verdict = graded_alone(template, SPHERES, "v2_out", repr(right * 1.015))
    assert (verdict.verdict, verdict.diagnosis) == ("incorrect", "")


def test_a_bare_number_takes_the_sheets_unit(bank: dict[str, Template]) -> None:
    """0.281 for an angle in degrees is radians given for degrees; 0.281 rad is the right angle."""
    template = bank["ball-plate"]
    assert graded_alone(template, PLATE, "theta_out", "0.281").diagnosis == "angle.radians"
    assert graded_alone(template, PLATE, "theta_out", "0.281 rad").verdict == "correct"


def test_mistake_credit_is_the_assignments(bank: dict[str, Template]) -> None:
    template = bank["drop-rebound"]
    key = student_key(template, BALL, mistake_credit=0.25)
    verdict = graded(key, {"1a": "0.524"}, template)["1a"]
    assert (verdict.verdict, verdict.credit, verdict.score) == ("mistake", 0.25, 0.25)


# --- error carried forward ------------------------------------------------------------------------

def test_the_issues_example_the_rebound_angle_from_the_students_rebound_speed(bank: dict[str, Template]) -> None:
    """Ball-plate with the student's 1a = v_out: freeing e gives theta' = atan2(sqrt(v_out^2 - v_t^2), v_t)."""
    template = bank["ball-plate"]
    v_out = 47.0  # the key's 45.1
    carried = math.degrees(math.atan2(SQRT(v_out**2 - V_T**2), V_T))
    verdicts = graded(student_key(template, PLATE), {"1a": "47.0", "1b": f"{carried:.3g}"}, template)
    assert (verdicts["1a"].verdict, verdicts["1b"].verdict, verdicts["1b"].credit) == ("incorrect", "ecf", 1.0)
    assert verdicts["1b"].diagnosis == "ecf:1a"
    assert verdicts["1b"].feedback == ("right for your 1a = 47 ft/s (error carried forward); with 1a = 45.0694 ft/s, "
                                       "1b is 16.1021°")


def test_the_pile_drivers_e_from_the_students_speed_of_the_pile(bank: dict[str, Template]) -> None:
    """3a = 2.71 m/s (the key's 2.55): e = (2.71 + v_r')/v_r, whichever mass was taken wrong."""
    template = bank["pile-driver"]
    carried = (2.71 + V_BACK) / V_RAM
    verdicts = graded(student_key(template, PILE), {"1a": "2.71 m/s", "1b": f"{carried:.3g}"}, template)
    assert verdicts["1b"].verdict == "ecf"
    assert verdicts["1b"].feedback.startswith("right for your 1a = 2.71 m/s (error carried forward)")


@pytest.mark.parametrize(("first", "why"), [("100", "37 times the right value"), ("-2.71", "the wrong sign"),
                                            ("0.8", "less than a third of it"), ("fast", "unreadable"),
                                            ("2.71 m", "not a speed"), ("", "blank")])
def test_a_nonsense_first_answer_does_not_make_the_later_parts_trivial(bank: dict[str, Template], first: str,
                                                                       why: str) -> None:
    """Whatever follows from an implausible 1a is not credited: 1b worked from it is incorrect."""
    template = bank["pile-driver"]
    number = float(first.split()[0]) if first[:1].isdigit() or first[:1] == "-" else 2.71
    carried = (number + V_BACK) / V_RAM
    verdict = graded(student_key(template, PILE), {"1a": first, "1b": f"{carried:.3g}"}, template)["1b"]
    assert verdict.verdict in ("incorrect", "mistake") and verdict.credit == 0 and "carried" not in verdict.feedback


def test_ecf_credit_is_the_assignments_and_0_turns_it_off(bank: dict[str, Template]) -> None:
    template = bank["pile-driver"]
    typed = {"1a": "2.71", "1b": f"{(2.71 + V_BACK) / V_RAM:.3g}"}
    assert graded(student_key(template, PILE, ecf_credit=0.5), typed, template)["1b"].credit == 0.5
    assert graded(student_key(template, PILE, ecf_credit=0), typed, template)["1b"].verdict == "incorrect"


def test_an_error_carried_forward_comes_before_a_mistake_and_after_correct(bank: dict[str, Template]) -> None:
    """1a by v = 2gh (e = h'/h), 1b from it: 100 (1 - e^2) is also "v = 2gh" in 1b, but the error was 1a's."""
    template = bank["drop-rebound"]
    e = 1100 / 2100
    verdicts = graded(student_key(template, BALL), {"1a": f"{e:.3g}", "1b": f"{100 * (1 - e * e):.3g}"}, template)
    assert (verdicts["1a"].verdict, verdicts["1a"].diagnosis) == ("mistake", "flight.two_gh")
    assert (verdicts["1b"].verdict, verdicts["1b"].diagnosis) == ("ecf", "ecf:1a")
    right = graded(student_key(template, BALL), {"1a": f"{e:.3g}", "1b": "47.6"}, template)["1b"]
    assert right.verdict == "correct"


def test_an_earlier_answer_that_leaves_no_real_value_carries_nothing(bank: dict[str, Template]) -> None:
    """A rebound speed below the unchanged tangential 43.3 ft/s has no normal component: nothing matches, and
    nothing that is not a number is written."""
    template = bank["ball-plate"]
    verdict = graded(student_key(template, PLATE), {"1a": "40", "1b": "0"}, template)["1b"]
    assert verdict.verdict == "incorrect" and "nan" not in verdict.feedback.lower()


def test_a_class_of_several_tolerances_is_reconsidered_as_each_student_alone(bank: dict[str, Template]) -> None:
    """A part's wrong numbers fall into a group per tolerance, reconsidered together: each student's verdicts are
    the ones the student gets graded alone (an error carried forward, radians for degrees, a plain slip)."""
    template = bank["ball-plate"]
    carried = math.degrees(math.atan2(SQRT(47.0**2 - V_T**2), V_T))
    typed = [{"1a": "47.0", "1b": f"{carried:.3g}"}, {"1a": "45.1", "1b": "0.281"}, {"1a": "60", "1b": "20"},
             {"1a": "47.0", "1b": "0.281"}]
    tolerances = [{"mode": "rtol", "rtol": rtol, "atol": 0.0} for rtol in (0.01, 0.02, 0.03)]
    alone = [graded(student_key(template, PLATE, tolerance=tolerances[index % 3]), answers, template)
             for index, answers in enumerate(typed * 3)]
    keys = [student_key(template, PLATE, tolerance=tolerances[index % 3]) for index in range(len(alone))]
    students = tuple(replace(key.students[0], id=f"s{index}") for index, key in enumerate(keys))
    answers = tuple(Answer("s.csv", 2 + 2 * index + line, f"s{index}", label, text, ",", None)
                    for index, mine in enumerate(typed * 3) for line, (label, text) in enumerate(mine.items()))
    key = replace(keys[0], students=students)
    together = grade(key, Submissions(answers, (), (), ()), physics_for(key, {template.id: template}))
    by_student = {(verdict.student_id, verdict.label): verdict for verdict in together.verdicts}
    assert {verdict.verdict for verdicts in alone for verdict in verdicts.values()} >= {"ecf", "mistake", "incorrect"}
    for index, verdicts in enumerate(alone):
        for label, verdict in verdicts.items():
            mine = by_student[(f"s{index}", label)]
            assert (mine.verdict, mine.credit, mine.feedback, mine.diagnosis) == \
                (verdict.verdict, verdict.credit, verdict.feedback, verdict.diagnosis)


# --- where the template is not available ----------------------------------------------------------

def test_without_the_template_the_key_was_made_from_grading_goes_on_with_a_note(bank: dict[str, Template]) -> None:
    template = bank["drop-rebound"]
    key = student_key(template, BALL)
    changed = replace(template, source_hash="another file")
    for physics, reason in [(physics_for(key, {}), "is not in the problem bank"),
                            (physics_for(key, {template.id: changed}), "has changed since the key was written"),
                            (physics_for(replace(key, templates={}), {template.id: template}), "does not record")]:
        assert physics.problems == {} and len(physics.notes) == 1 and reason in physics.notes[0]
        answers = (Answer("s.csv", 2, "s1", "1a", "0.524", ",", None),)
        result = grade(key, Submissions(answers, (), (), ()), physics)
        assert result.verdicts[0].verdict == "incorrect" and result.notes == physics.notes


def test_a_key_finds_its_own_bank_folder_again_or_says_which_bank_to_give(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Issue 28: a key made from an instructor's own templates, graded without --bank, gave no error carried
    forward or diagnosis. The key records the folder (relative to itself) and grading finds it again, the
    key and the folder moved together too; a changed file is not used, and the note says which --bank."""
    course = tmp_path / "course"
    (course / "mybank").mkdir(parents=True)
    (course / "mybank" / "drop-rebound.yaml").write_bytes((bank_dir() / "drop-rebound.yaml").read_bytes())
    (course / "hw.yaml").write_text("title: HW\ncourse: C\nseed: s\nproblems:\n  - template: drop-rebound\n")
    (course / "roster.csv").write_text("id,name,email,section\n1,Ana,a@x.edu,1\n")
    assert main(["--no-shipped-bank", "--bank", str(course / "mybank"), "generate", str(course / "hw.yaml"),
                 "--roster", str(course / "roster.csv"), "--out", str(course / "hw7"), "--no-pdf"]) == 0
    document = json.loads((course / "hw7" / "key.json").read_text(encoding="utf-8"))
    assert document["templates"]["drop-rebound"]["bank"] == "../mybank"
    student = document["students"][0]["problems"][0]
    e = student["answers"]["e"]["value"]
    (tmp_path / "s.csv").write_text(f"student_id,label,answer\n1,1a,{e * e:.4g}\n", encoding="utf-8")
    (tmp_path / "empty").mkdir()
    moved = tmp_path / "moved"
    (course / "hw7" / "key.json").replace(course / "key.json")  # a key beside its bank: "../mybank" from hw7
    document["templates"]["drop-rebound"]["bank"] = "mybank"
    (course / "key.json").write_text(json.dumps(document), encoding="utf-8")
    course.rename(moved)

    def grade_it() -> tuple[str, str]:
        capsys.readouterr()
        main(["--no-shipped-bank", "--bank", str(tmp_path / "empty"), "grade", "--key", str(moved / "key.json"),
              str(tmp_path / "s.csv"), "--out", str(tmp_path / "g"), "--force"])
        details = (tmp_path / "g" / "details.csv").read_text(encoding="utf-8")
        return details.splitlines()[1], capsys.readouterr().err

    row, err = grade_it()
    assert ",mistake," in row and "note: problem" not in err
    (moved / "mybank" / "drop-rebound.yaml").write_text(
        (moved / "mybank" / "drop-rebound.yaml").read_text(encoding="utf-8") + "\n# edited\n", encoding="utf-8")
    row, err = grade_it()
    assert ",incorrect," in row
    assert (f"the key records that it came from {moved / 'mybank'}, and it has changed since: give grader grade "
            "--bank DIR, where DIR holds drop-rebound.yaml as it was when the key was written (SHA-256 ") in err


def test_a_key_from_the_shipped_bank_records_no_folder(demo_run: DemoRun) -> None:
    """The shipped bank is found without being told: the demo's key names no folder (and reads as before)."""
    document = json.loads((demo_run.out / "key.json").read_text(encoding="utf-8"))
    assert all("bank" not in entry for entry in document["templates"].values())


def test_grader_grade_with_a_bank_that_lacks_the_template_notes_it_and_grades(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], sample_key: Path) -> None:
    student = json.loads(sample_key.read_text(encoding="utf-8"))["students"][0]["id"]
    (tmp_path / "s.csv").write_text(f"student_id,label,answer\n{student},1a,0.1\n", encoding="utf-8")
    (tmp_path / "empty").mkdir()
    capsys.readouterr()
    assert main(["--no-shipped-bank", "--bank", str(tmp_path / "empty"), "grade", "--key", str(sample_key),
                 str(tmp_path / "s.csv"), "--out", str(tmp_path / "g")]) == 0
    err = capsys.readouterr().err
    assert err.count("note: problem ") == 5 and "is not in the problem bank" in err


def test_grader_check_json_shows_the_diagnosis(capsys: pytest.CaptureFixture[str], sample_key: Path) -> None:
    student = json.loads(sample_key.read_text(encoding="utf-8"))["students"][0]
    angle = student["problems"][3]["answers"]["theta_out"]
    capsys.readouterr()
    assert main(["check", "--key", str(sample_key), "--student", student["id"], "--label", angle["label"],
                 f"{math.radians(angle['value']):.3g}", "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert (result["verdict"], result["diagnosis"]) == ("mistake", "angle.radians")
    assert main(["check", "--key", str(sample_key), "--student", student["id"], "--label", angle["label"],
                 f"{math.radians(angle['value']):.3g}"]) == 0
    assert "\ndiagnosis  angle.radians\n" in capsys.readouterr().out


def test_the_cached_alternatives_are_the_compiled_ones(bank: dict[str, Template]) -> None:
    """Compiled again, a template's alternatives are the same, and read back from JSON equal."""
    from grader.solve.derived import compile_alternatives

    fresh = compile_alternatives(bank["drop-rebound"])
    assert fresh == alternatives_for(bank["drop-rebound"])
    assert Alternatives.from_json(json.loads(json.dumps(fresh.to_json()))) == fresh
    assert {a.kind for a in fresh.items} == {"ecf", "mistake"}
