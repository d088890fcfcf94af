"""Answers from another student's variant (issue 28 part 3): a copied answer is found with its partner and
value, an honest class gives no pair, a student's own diagnosed mistake is not counted, the chance of the
matches by accident is the hand computation of docs/grading.md, and what integrity.csv and report.html show.
The benchmark (``benchmarks/integrity.py``) measures how often it is right on 200 simulated classes."""

from __future__ import annotations

import csv
import dataclasses
import io
import json
import math
import warnings
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import pytest

from grader.grade.class_report import class_report
from grader.grade.diagnosis import Physics
from grader.grade.grading import Graded, grade
from grader.grade.integrity import Integrity, Match, Pair, check
from grader.grade.integrity_chance import UNRELATED, Spread, class_density
from grader.grade.key import Key, KeyPart, KeyProblem, KeyStudent
from grader.grade.latest import Answer
from grader.grade.report import integrity_csv
from grader.grade.submissions import Submissions

TOLERANCE = {"mode": "rtol", "rtol": 0.01, "atol": 0.0}


def make_key(values: Sequence[Sequence[float]], threshold: float = 0.01) -> Key:
    """One problem whose parts 1a, 1b, ... have, for student ``s{i}``, the values ``values[i]``."""
    labels = tuple(f"1{chr(ord('a') + j)}" for j in range(len(values[0])))
    students = tuple(KeyStudent(f"s{i}", f"Student {i}", "", "1",
                                {label: KeyPart("1", f"x{j}", label, float(value), "m/s", 1.0, TOLERANCE, None, {})
                                 for j, (label, value) in enumerate(zip(labels, row, strict=True))})
                     for i, row in enumerate(values))
    return Key("key.json", 2, "HW", True, (KeyProblem("1", "Drop", labels),), students,
               integrity_threshold=threshold)


def graded(key: Key, typed: Mapping[tuple[str, str], str]) -> Graded:
    """The key graded against ``typed``, by (student id, label); no physics (nothing is diagnosed)."""
    answers = tuple(Answer("answers.csv", line, student, label, text, ",", None)
                    for line, ((student, label), text) in enumerate(typed.items(), 2))
    return grade(key, Submissions(answers, (), (), ()), Physics({}))


def own_answers(key: Key) -> dict[tuple[str, str], str]:
    """Every student's own values, as typed."""
    return {(s.id, label): f"{part.value:.4g}" for s in key.students for label, part in s.parts.items()}


def test_a_copied_answer_is_found_with_the_right_partner_and_value() -> None:
    # Eight students, three parts, values 2 % and more apart: student 0 types student 5's three answers.
    key = make_key([[1.0 + i, 10.0 + 2 * i, 100.0 + 5 * i] for i in range(8)])
    typed = own_answers(key) | {("s0", "1a"): "6", ("s0", "1b"): "20", ("s0", "1c"): "125"}
    result = check(graded(key, typed))
    assert [(m.student, m.label, m.partner, m.value, m.matches) for m in result.matches] == [
        (0, "1a", 5, 6.0, 1), (0, "1b", 5, 20.0, 1), (0, "1c", 5, 125.0, 1)]
    (pair,) = result.flagged
    assert (pair.student, pair.partner, pair.labels, pair.wrong) == (0, 5, ("1a", "1b", "1c"), 3)
    assert result.examined == 7  # one student with two or more wrong parts, against the 7 others


def test_an_honest_class_has_no_pair() -> None:
    # Wrong answers 20 % off the student's own value, where another student's value is at least 5 % away.
    key = make_key([[1.0 + i, 10.0 + 2 * i] for i in range(10)])
    typed = own_answers(key) | {(f"s{i}", "1a"): f"{(1.0 + i) * 1.2 + 0.5:.4g}" for i in range(0, 10, 2)}
    result = check(graded(key, typed))
    assert result.wrong == 5 and result.flagged == () and result.matched == 0 and result.matches == ()


def phi(x: float) -> float:
    return 0.5 * (1 + math.erf(x / math.sqrt(2)))


def kernel_mass(logs: Sequence[float], low: float, high: float) -> float:
    """A Gaussian kernel density's mass over ``[low, high]`` (of ``log |ratio|``), Silverman's bandwidth:
    0.9 min(standard deviation, interquartile range / 1.34) n^(-1/5)."""
    width = kernel_width(np.array(logs))
    return sum(phi((high - x) / width) - phi((low - x) / width) for x in logs) / len(logs)


def test_the_class_density_is_the_hand_computation() -> None:
    # Values 1 to 5, ±1 %: around 3 the √5 -> 3 nearest values each side span 1 to 5, 4 of the 4 other
    # students over a width of 4: 0.25 per unit, and the band 3 ± 0.03 holds p = 0.25 * 0.06 = 0.015; at the
    # edge, 1 ± 0.01: 3 of 4 over 1 to 4, 0.25 per unit, p = 0.005.
    values = np.array([1.0, 2.0, 3.0, 4.0, 5.0])
    found = class_density(values, 0.01 * values, np.arange(5), values)
    assert found[2] == pytest.approx(0.015, rel=1e-12) and found[0] == pytest.approx(0.005, rel=1e-12)


def test_the_spread_of_wrong_answers_is_a_kernel_density_of_their_ratios() -> None:
    """Per sign, the mass over a band of the Gaussian kernels at each answer's log |ratio| (the width from
    all answers, the mass divided by all of them), as an exact sum of normal distribution functions; the
    module bins the kernels on a grid, a fraction of their width apart."""
    rng = np.random.default_rng(5)
    own = rng.uniform(1, 10, 200)
    answers = own * rng.choice([0.8, 1.15, 2.0], 200) * rng.uniform(0.98, 1.02, 200)
    answers[:10] *= -1  # a sign wrong
    spread = Spread.of(answers, own, np.arange(200), 201)  # each answer a student's; student 200 gave none
    logs = np.log(np.abs(answers / own))
    for ratio in (0.8, 1.1, 2.0, 3.0, -2.0):
        low, high = sorted((ratio * 0.99, ratio * 1.01))
        mine = logs[10:] if ratio > 0 else logs[:10]
        width = kernel_width(logs)
        expected = sum(phi((math.log(abs(high if ratio > 0 else low)) - x) / width)
                       - phi((math.log(abs(low if ratio > 0 else high)) - x) / width) for x in mine) / len(logs)
        got = float(spread.chance(np.array([1.0]), np.array([low]), np.array([high]), np.array([200]))[0])
        assert got == pytest.approx(expected, abs=2e-3)


def kernel_width(logs: np.ndarray) -> float:
    """Silverman's rule of thumb, at least 0.01."""
    deviation = float(np.std(logs, ddof=1))
    quartile = float(np.percentile(logs, 75) - np.percentile(logs, 25))
    return max(0.01, 0.9 * min(deviation, quartile / 1.34) * len(logs) ** -0.2)


def test_the_chance_of_the_matches_by_accident_is_the_hand_computation() -> None:
    # Five students, values 1 to 5 in each of three parts, ±1 %; student 0 types student 2's value (3) in 1a
    # and 1b, and 100 in 1c; student 4 types 6 (a ratio of 1.2 to their own 5) in 1a and 1b. Per part, for
    # student 0's answers, p = (1 - u) * (the kernel mass of the other students' wrong log-ratios, student
    # 4's two ln 1.2, over the band's, ln 2.97 to ln 3.03, the kernel's width from all five answers) + u *
    # (the class density, 0.015 as above). Two or more matches among three parts with the same p:
    # 3 p^2 - 2 p^3. "3" typed shows its value to ±0.5, wider than the band (±0.03): no closeness to claim,
    # the whole band counts. Two students have two or more wrong parts: 2 * 4 pairs examined; and the pair
    # could have been counted with 2 or 3 matches: the chance with 2, plus at most that of 3 anywhere, p^3.
    key = make_key([[1.0 + i] * 3 for i in range(5)])
    typed = own_answers(key) | {("s0", "1a"): "3", ("s0", "1b"): "3", ("s0", "1c"): "100",
                                ("s4", "1a"): "6", ("s4", "1b"): "6"}
    result = check(graded(key, typed))
    logs = [math.log(3), math.log(3), math.log(100), math.log(1.2), math.log(1.2)]
    width = kernel_width(np.array(logs))
    related = sum(phi((math.log(3.03) - x) / width) - phi((math.log(2.97) - x) / width) for x in logs[3:]) / 2
    p = (1 - UNRELATED) * related + UNRELATED * 0.015
    assert related > 0.001  # the kernels of student 4's answers reach student 0's
    (pair,) = [pair for pair in result.pairs if (pair.student, pair.partner) == (0, 2)]
    assert pair.labels == ("1a", "1b") and pair.wrong == 3
    assert pair.chance == pytest.approx(3 * p**2 - 2 * p**3, rel=0.05)
    assert result.examined == 8 and pair.corrected == pytest.approx(8 * (pair.chance + p**3), rel=1e-4)


def test_a_students_own_answers_do_not_make_themselves_likely() -> None:
    # Student 0's wrong answers are the class's only ones: the chance that they are related to their own
    # values rests on nobody's, and only the unrelated kind is left: p = u * 0.015 (as above) for each part.
    key = make_key([[1.0 + i] * 3 for i in range(5)])
    typed = own_answers(key) | {("s0", "1a"): "3", ("s0", "1b"): "3", ("s0", "1c"): "100"}
    (pair,) = [pair for pair in check(graded(key, typed)).pairs if (pair.student, pair.partner) == (0, 2)]
    p = UNRELATED * 0.015
    assert pair.chance == pytest.approx(3 * p**2 - 2 * p**3, rel=1e-9)


def test_a_students_own_diagnosed_mistake_that_is_another_students_value_is_not_counted() -> None:
    key = make_key([[1.0 + i, 10.0 + 2 * i, 100.0 + 5 * i] for i in range(8)])
    typed = own_answers(key) | {("s0", "1a"): "6", ("s0", "1b"): "20", ("s0", "1c"): "125"}
    result = graded(key, typed)
    # The same answers, graded as diagnosed mistakes of student 0's own (as the physics would find them).
    columns = {label: list(rows) for label, rows in result.columns.items()}
    for label in ("1a", "1b", "1c"):
        columns[label][0] = columns[label][0]._replace(verdict="mistake", diagnosis="impact.masses_swapped")
    diagnosed = Graded(result.key, columns, (), (), (), numbers=result.numbers)
    found = check(diagnosed)
    assert found.wrong == 0 and found.matches == () and found.pairs == ()


def test_a_diagnosed_mistake_from_the_shipped_physics_is_not_counted(tmp_path: Path) -> None:
    """Through the real grading: a drop-rebound student who squares e (a diagnosed mistake) in a class where
    another student's e is that square."""
    from grader.base.resources import sample_dir
    from grader.cli import main
    from grader.grade.diagnosis import physics_for
    from grader.grade.key import load_key

    assert main(["generate", str(sample_dir() / "assignment.yaml"), "--roster", str(sample_dir() / "roster.csv"),
                 "--out", str(tmp_path / "hw"), "--no-pdf"]) == 0
    document = json.loads((tmp_path / "hw" / "key.json").read_text(encoding="utf-8"))
    students = document["students"]
    first, second = students[0]["problems"][0], students[1]["problems"][0]
    e = first["answers"]["e"]["value"]
    second["answers"]["e"]["value"] = e * e  # student 1's e is student 0's e squared
    (tmp_path / "edited.json").write_text(json.dumps(document), encoding="utf-8")
    key = load_key(tmp_path / "edited.json")
    label = first["answers"]["e"]["label"]
    typed = {(students[0]["id"], label): f"{e * e:.6g}"}
    answers = tuple(Answer("a.csv", 2, who, part, text, ",", None) for (who, part), text in typed.items())
    result = grade(key, Submissions(answers, (), (), ()), physics_for(key))
    assert result.columns[label][0].verdict == "mistake"
    assert check(result).matches == ()


def test_integrity_csv_guards_what_a_student_typed_and_names_the_partner() -> None:
    key = make_key([[1.0 + i, 10.0 + 2 * i, 100.0 + 5 * i] for i in range(8)])
    typed = own_answers(key) | {("s0", "1a"): "+6", ("s0", "1b"): "20", ("s0", "1c"): "125"}
    result = graded(key, typed)
    text = "".join(integrity_csv(result, check(result)))
    rows = list(csv.DictReader(io.StringIO(text)))
    assert [(r["student_id"], r["label"], r["submitted"], r["matches_id"], r["matches_value"]) for r in rows] == [
        ("s0", "1a", "'+6", "s5", "6"), ("s0", "1b", "20", "s5", "20"), ("s0", "1c", "125", "s5", "125")]
    assert {(r["pair_parts"], r["pair_labels"], r["wrong_parts"], r["close_parts"], r["closeness"], r["flagged"])
            for r in rows} == {("3", "1a 1b 1c", "3", "3", "0", "yes")}
    assert all(0 < float(r["chance"]) <= float(r["corrected_chance"]) <= 1 for r in rows)


def test_an_answer_matching_many_students_names_a_bounded_number() -> None:
    from grader.grade.integrity import LISTED

    key = make_key([[5.0 + 0.001 * i] for i in range(12)] + [[50.0]])
    typed = {("s12", "1a"): "5.005"}
    result = check(graded(key, typed))
    assert len(result.matches) == LISTED and {m.matches for m in result.matches} == {12}
    assert result.matches[0].partner == 5  # the nearest value first


def test_an_angle_matches_across_the_turn() -> None:
    students = [KeyStudent(f"s{i}", "", "", "1", {"1a": KeyPart("1", "theta", "1a", value, "deg", 1.0, TOLERANCE,
                                                                None, {})})
                for i, value in enumerate([10.0, 90.0, 359.5, 200.0])]
    key = Key("key.json", 2, "HW", True, (KeyProblem("1", "Spin", ("1a",)),), tuple(students))
    result = check(graded(key, {("s1", "1a"): "-0.5"}))
    assert [(m.student, m.partner) for m in result.matches] == [(1, 2)]


def test_the_report_lists_flagged_pairs_and_says_when_there_are_none() -> None:
    key = make_key([[1.0 + i, 10.0 + 2 * i, 100.0 + 5 * i] for i in range(8)])
    copied = graded(key, own_answers(key) | {("s0", "1a"): "6", ("s0", "1b"): "20", ("s0", "1c"): "125"})
    page = class_report(copied)
    assert "<h2 id=\"integrity\">" in page and "<td>s0</td><td>Student 0</td><td>s5</td><td>Student 5</td>" in page
    assert "3 of 3" in page
    honest = class_report(graded(key, own_answers(key)))
    assert "<h2 id=\"integrity\">" in honest and "No pair of students is flagged." in honest


def test_a_threshold_of_0_flags_nothing() -> None:
    key = make_key([[1.0 + i, 10.0 + 2 * i, 100.0 + 5 * i] for i in range(8)], threshold=0.0)
    result = check(graded(key, own_answers(key) | {("s0", "1a"): "6", ("s0", "1b"): "20", ("s0", "1c"): "125"}))
    assert result.flagged == () and len(result.pairs) == 1


def test_the_pair_search_agrees_with_a_comparison_of_every_pair(monkeypatch: pytest.MonkeyPatch) -> None:
    """The sort-and-join search finds exactly the pairs with two or more matched parts that comparing every
    student with every other finds (every such pair kept, whatever its chance)."""
    from grader.grade import integrity

    monkeypatch.setattr(integrity, "KEPT", 2.0)
    rng = np.random.default_rng(28)
    labels = ("1a", "1b", "1c", "1d", "1e")
    values = rng.uniform(1, 1.5, size=(80, len(labels)))
    key = make_key(values.tolist())
    typed = {(f"s{i}", label): f"{values[i, j] * (rng.uniform(0.7, 1.3) if rng.random() < 0.6 else 1):.6g}"
             for i in range(80) for j, label in enumerate(labels)}
    result = graded(key, typed)
    expected = {}
    for a in range(80):
        for b in range(80):
            matched = tuple(label for j, label in enumerate(labels)
                            if result.columns[label][a].verdict == "incorrect" and a != b
                            and abs(result.numbers[label][a] - values[b, j]) <= 0.01 * values[b, j]
                            and abs(values[b, j] - values[a, j]) > 0.01 * values[a, j])
            if len(matched) >= 2:
                expected[a, b] = matched
    assert len(expected) > 10  # the class has pairs to find
    assert {(p.student, p.partner): p.labels for p in check(result).pairs if len(p.labels) >= 2} == expected


def test_answers_counted_from_the_sorted_band_ends_count_as_those_tested_one_by_one(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """Slips of 10 % (counted from the ends) and of 1.5 % (near the student's own value, where bands that
    do not count as matches may hold them: tested one by one), in bands of ±1 % and, for every seventh
    student, ±3 %."""
    from grader.grade import integrity_search

    rng = np.random.default_rng(7)
    values = rng.uniform(1, 1.2, size=(200, 2))
    key = make_key(values.tolist())
    wide = {"mode": "rtol", "rtol": 0.03, "atol": 0.0}
    key = dataclasses.replace(key, students=tuple(
        dataclasses.replace(student, parts={label: part._replace(tolerance=wide) if i % 7 == 0 else part
                                            for label, part in student.parts.items()})
        for i, student in enumerate(key.students)))
    slips = {0: 1.1, 1: 1.015}
    typed = {(f"s{i}", label): f"{values[i, j] * slips.get(i % 3, 1):.6g}"
             for i in range(200) for j, label in enumerate(("1a", "1b"))}
    result = graded(key, typed)
    counted = [(m.student, m.label, m.matches) for m in check(result).matches]
    monkeypatch.setattr(integrity_search, "BY_ENDS", False)
    assert [(m.student, m.label, m.matches) for m in check(result).matches] == counted
    assert max(matches for _, _, matches in counted) > 5
    assert any(student % 3 == 1 for student, _, _ in counted)


def test_a_wrong_answer_near_the_float64_limit_makes_no_overflow() -> None:
    """1.6e308 typed for 0.47 (the mutated-submissions sweep): its ratio overflows, its logs do not."""
    from grader.grade.integrity_chance import Spread

    spread = Spread.of(np.array([1.6e308, 0.5, 0.45]), np.array([0.47, 0.47, 0.47]), np.arange(3), 3)
    assert np.isfinite(spread.start) and np.isfinite(spread.step)


def test_an_undefined_own_value_gives_a_chance_of_one_and_no_warning() -> None:
    """A part whose key value is null (undefined) for the owner: no ratio tells, so the chance is 1, and
    numpy says nothing on stderr (the hostile-input sweep saw 'All-NaN slice encountered' from grader grade)."""
    spread = Spread.of(np.array([0.5, 0.45, 2.0]), np.array([0.47, 0.47, 1.0]), np.arange(3), 4)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        got = spread.chance(np.array([np.nan, 0.0, 1.0]), np.array([0.4, 0.0, 0.4]), np.array([0.6, 0.0, 0.6]),
                            np.array([3, 3, 3]))
    assert got[:2].tolist() == [1.0, 1.0] and 0.0 <= got[2] <= 1.0


def slipping_class(seed: int) -> tuple[Key, np.ndarray, dict[tuple[str, str], str]]:
    """40 students, four parts with values 1 to 1.5 (each band ±1 % holds a number of about 2 others'
    values); 40 % of the answers slip by 6 to 30 % either way, typed to three figures as students do."""
    rng = np.random.default_rng(seed)
    values = rng.uniform(1, 1.5, size=(40, 4))
    typed = {}
    for i in range(40):
        for j, label in enumerate(("1a", "1b", "1c", "1d")):
            slip = rng.uniform(1.06, 1.3) ** rng.choice([-1, 1]) if rng.random() < 0.4 else 1.0
            typed[f"s{i}", label] = f"{values[i, j] * slip:.3g}"
    return make_key(values.tolist(), threshold=0.05), values, typed


def test_answers_copied_as_typed_are_found_among_slips_that_land_in_the_same_bands() -> None:
    """Five students each copy three answers of another, typed to four figures as that student typed them:
    within the typed rounding (±0.05 % of the value) of the other's value, in bands of ±1 % where the class's
    slips land too. Each pair is flagged; over the whole band (the model before the closeness was read) none of
    the five was (corrected chances 0.05 to 0.35)."""
    key, values, typed = slipping_class(3)
    for copier, source in [(2, 3), (4, 5), (8, 9), (14, 15), (22, 23)]:
        taken = {(f"s{copier}", label): f"{values[source, j]:.4g}" for j, label in enumerate(("1a", "1b", "1c"))}
        copied = typed | taken
        result = check(graded(key, copied))
        pair = result.pair(copier, source)
        assert pair is not None and pair in result.flagged, (copier, source, pair)


def test_an_honest_class_whose_slips_land_in_other_students_bands_has_no_pair() -> None:
    """The same kind of class with nobody copying, in five seeds: slips land anywhere in the bands they land in,
    so no closeness is claimed and no pair is flagged."""
    for seed in range(5):
        key, _, typed = slipping_class(seed)
        assert check(graded(key, typed)).flagged == ()


def test_the_band_narrows_to_the_closeness_of_the_least_close_match() -> None:
    # Values 1 to 5 in three parts, ±1 %; student 0 types 3.001 in 1a and 1b (student 2's value is 3, band
    # ±0.03) and 100 in 1c; nobody else is wrong, so only the unrelated kind is left (as above: u * 0.015 over
    # the whole band). The least close match is 0.001 / 0.03 of the band from its value; "3.001" shows its
    # value to ±0.0005, so each band narrows to (0.001 + 0.0005) / 0.03 = 0.05 of itself: p = u * 0.015 * 0.05
    # in 1a and 1b; "100" shows ±0.5, more than the band: q = u * 0.015 in 1c. Two or more of three:
    # p² + 2 p q (1 - p). One student with two or more wrong parts: 4 pairs examined; counted with 2 matches
    # or 3: plus the chance of 3 anywhere in the bands, q³.
    key = make_key([[1.0 + i] * 3 for i in range(5)])
    typed = own_answers(key) | {("s0", "1a"): "3.001", ("s0", "1b"): "3.001", ("s0", "1c"): "100"}
    result = check(graded(key, typed))
    p, q = UNRELATED * 0.015 * 0.05, UNRELATED * 0.015
    (pair,) = [pair for pair in result.pairs if (pair.student, pair.partner) == (0, 2)]
    assert pair.labels == ("1a", "1b") and pair.chance == pytest.approx(p**2 + 2 * p * q * (1 - p), rel=1e-9)
    assert pair.corrected == pytest.approx(4 * (pair.chance + q**3), rel=1e-9)


def test_a_coarsely_typed_answer_on_another_students_round_value_claims_no_closeness() -> None:
    """Student 0 types 3 and 4 where students 2 and 3 have exactly 3.0 and 4.0: a distance of 0, but "3" shows
    its value only to ±0.5, more than the band: the chance is the whole band's, as if the answers lay anywhere
    in it."""
    key = make_key([[1.0 + i, 1.0 + i] for i in range(5)])
    exact = check(graded(key, own_answers(key) | {("s0", "1a"): "3", ("s0", "1b"): "3"}))
    nearly = check(graded(key, own_answers(key) | {("s0", "1a"): "3.02", ("s0", "1b"): "3.02"}))
    (pair,) = [pair for pair in exact.pairs if (pair.student, pair.partner) == (0, 2)]
    (other,) = [pair for pair in nearly.pairs if (pair.student, pair.partner) == (0, 2)]
    assert pair.chance == pytest.approx((UNRELATED * 0.015) ** 2, rel=1e-9)
    assert other.chance > pair.chance * 0.4  # 3.02 is 2/3 of the band out, ±0.005: (0.667 + 0.167)² of it


@pytest.mark.parametrize(("text", "place"), [("3.41 m/s", (3.41, 0.01)), ("341 cm/s", (341.0, 1.0)),
                                             ("6.26×10^3", (6260.0, 10.0)), ("1,50", (1.5, 0.01)),
                                             ("-2.50E-3", (-0.0025, 1e-5)), ("≈ 7.", (7.0, 1.0))])
def test_the_place_of_the_last_typed_digit(text: str, place: tuple[float, float]) -> None:
    from grader.grade.cells import typed_place

    assert typed_place(text) == pytest.approx(place, rel=1e-12)


@pytest.mark.parametrize("text", ["sqrt(2)", "3/4", "55°30'", "v = 3", "", "1e99999"])
def test_a_typed_number_that_is_not_plain_shows_no_place(text: str) -> None:
    from grader.grade.cells import typed_place

    assert typed_place(text) is None


def test_a_flagged_pair_changes_no_grade_and_is_in_no_feedback_file(tmp_path: Path,
                                                                     monkeypatch: pytest.MonkeyPatch) -> None:
    """The demo's key for four students; the first student types their own values except the first parts of
    three problems (no earlier answer of theirs carries into them), which are the second student's, typed to
    four figures. integrity.csv flags the pair; every file of the run but integrity.csv and the report, each
    student's feedback page included, is the same bytes as when the check finds nothing."""
    from grader.base.resources import sample_dir
    from grader.cli import main
    from grader.grade import report
    from grader.grade.integrity import Integrity

    roster = (sample_dir() / "roster.csv").read_text(encoding="utf-8").splitlines()[:5]
    (tmp_path / "roster.csv").write_text("\n".join(roster) + "\n", encoding="utf-8")
    assert main(["generate", str(sample_dir() / "assignment.yaml"), "--roster", str(tmp_path / "roster.csv"),
                 "--out", str(tmp_path / "hw"), "--no-pdf"]) == 0
    document = json.loads((tmp_path / "hw" / "key.json").read_text(encoding="utf-8"))
    first, second = document["students"][:2]
    numeric = [(problem["answers"][name]["label"], answer, problem["answers"][name]["value"])
               for problem, other in zip(first["problems"], second["problems"], strict=True)
               for name, answer in problem["answers"].items()
               if isinstance(answer["value"], float) and isinstance(other["answers"][name]["value"], float)
               for answer in [other["answers"][name]]]
    rows = ["student_id,label,answer"]
    copied = [label for label, _, _ in numeric if label.endswith("a")][:3]
    for label, theirs, mine in numeric:
        rows.append(f"{first['id']},{label},{theirs['value'] if label in copied else mine:.4g}")
        rows.append(f"{second['id']},{label},{theirs['value']:.4g}")
    (tmp_path / "answers.csv").write_text("\n".join(rows) + "\n", encoding="utf-8")

    def graded_into(folder: str) -> dict[str, bytes]:
        assert main(["grade", "--key", str(tmp_path / "hw" / "key.json"), str(tmp_path / "answers.csv"), "--out",
                     str(tmp_path / folder), "--feedback-format", "html"]) == 0
        return {str(path.relative_to(tmp_path / folder)): path.read_bytes()
                for path in sorted((tmp_path / folder).rglob("*")) if path.is_file()}

    checked = graded_into("checked")
    flagged = [row for row in csv.DictReader(io.StringIO(checked["integrity.csv"].decode("utf-8")))
               if row["flagged"] == "yes"]
    assert {(row["student_id"], row["matches_id"]) for row in flagged} == {(first["id"], second["id"])}
    assert len(flagged) == 3
    monkeypatch.setattr(report, "check", lambda graded: Integrity.of((), (), 0, 0.05, 0, 0))
    unchecked = graded_into("unchecked")
    differ = sorted(name for name in checked if checked[name] != unchecked.get(name))
    assert set(differ) <= {"integrity.csv", "report.html", ".grader-manifest.json"}, differ
    assert any(name.startswith("feedback/") for name in checked)


def test_the_bound_on_how_few_matches_a_pair_needs_drops_no_pair_it_should_keep(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """The pairs kept (corrected chance under 1) are the same when every student's pairs are searched from
    two matches on: the bound on each part's chance (the least over the bands that may hold the answer,
    however close) is never above the chance worked out."""
    from grader.grade import integrity

    found = []
    for seed in range(3):
        key, values, typed = slipping_class(seed)
        copied = typed | {("s0", label): f"{values[1, j]:.4g}" for j, label in enumerate(("1a", "1b", "1c"))}
        found.append({(p.student, p.partner, p.labels, p.corrected) for p in check(graded(key, copied)).pairs
                      if len(p.labels) >= 2})
    monkeypatch.setattr(integrity, "_needed", lambda parts, answers, *_: np.full(len(answers.per_student), 2))
    for seed in range(3):
        key, values, typed = slipping_class(seed)
        copied = typed | {("s0", label): f"{values[1, j]:.4g}" for j, label in enumerate(("1a", "1b", "1c"))}
        assert {(p.student, p.partner, p.labels, p.corrected) for p in check(graded(key, copied)).pairs
                if len(p.labels) >= 2} == found[seed]
    assert sum(len(pairs) for pairs in found) >= 3


def test_a_copy_typed_as_its_source_typed_it_is_measured_from_what_the_source_typed() -> None:
    # Values 1.0004 to 5.0004, ±1 %; student 2 types 3.000 (right: 0.0004 off their 3.0004) and student 0 types
    # the same 3.000 in 1a and 1b, and 100 in 1c. Measured from what student 2 typed, with as many digits as
    # student 0's, the distance is 0: the band narrows to 3.000 ± 0.0005 (the half-unit), a width of 0.001, at
    # the class density of 0.25 per unit (as above): p = u * 0.25 * 0.001 (from student 2's value it would be
    # 0.8 half-units off: 3.000 ± 0.0009). "100": the whole band, q = u * 0.25 * 0.060008.
    key = make_key([[1.0004 + i] * 3 for i in range(5)])
    typed = {("s2", "1a"): "3.000", ("s2", "1b"): "3.000", ("s0", "1a"): "3.000", ("s0", "1b"): "3.000",
             ("s0", "1c"): "100"}
    (pair,) = [pair for pair in check(graded(key, typed)).pairs if (pair.student, pair.partner) == (0, 2)]
    p, q = UNRELATED * 0.25 * 0.001, UNRELATED * 0.25 * 0.060008
    assert pair.chance == pytest.approx(p**2 + 2 * p * q * (1 - p), rel=1e-6)
    assert (pair.closest, pair.closeness) == (2, 0.0)


@pytest.mark.parametrize("kept", [1.0, 2.0])
def test_the_pairs_worked_out_a_few_students_at_a_time_give_the_same_findings(
        monkeypatch: pytest.MonkeyPatch, kept: float) -> None:
    """The candidate pairs are worked out a block of students at a time (issue 29: memory bounded, whatever
    the class): blocks of one student, of a few, and the whole class in one find the same pairs, chances and
    listed matches, to the bit, in a class whose values lie close (every band overlaps dozens of others),
    whose students have from none to all parts wrong, two of them copying (one with 8 wrong parts, one with 5:
    a block of the second alone would sum its chances over fewer columns, which numpy adds in another order,
    and this class's figures show it), and whose student with the most wrong parts matches nobody (the first
    block searched finds no pair). ``kept`` 2: every pair is kept."""
    from grader.grade import integrity

    monkeypatch.setattr(integrity, "KEPT", kept)
    rng = np.random.default_rng(13)
    labels = tuple(f"1{letter}" for letter in "abcdefghij")  # up to 10 wrong parts: numpy sums 11 columns
    values = rng.uniform(1.0, 1.3, size=(150, len(labels)))
    key = make_key(values.tolist())
    slips = rng.uniform(0.0, 0.8, size=150)  # each student's share of wrong parts
    typed = {(f"s{i}", label): f"{values[i, j] * (rng.uniform(0.8, 1.2) if rng.random() < slips[i] else 1):.5g}"
             for i in range(150) for j, label in enumerate(labels)}
    typed |= {("s0", label): f"{values[1, j]:.5g}" for j, label in enumerate(labels[:8])}
    typed |= {("s2", label): f"{values[3 if j < 5 else 2, j]:.{3 + j % 3}g}" for j, label in enumerate(labels)}
    typed |= {("s4", label): f"{1000 * values[4, j]:.5g}" for j, label in enumerate(labels)}
    result = graded(key, typed)
    whole = check(result, block=10**9)
    assert len(whole.pairs) >= (100 if kept > 1 else 1) and whole.flagged  # the class has pairs to find
    for block in (1, 7, 500):
        found = check(result, block=block)
        assert found == whole
        assert "".join(integrity_csv(result, found)) == "".join(integrity_csv(result, whole))
    if kept == 1.0:
        return
    # Students laid out, candidates tested and the listed matches' pairs worked out a few at a time (the check's
    # memory bounded, issue 29): the same findings, every pair kept.
    from grader.grade import integrity_search

    monkeypatch.setattr(integrity, "ROWS", 7)
    monkeypatch.setattr(integrity, "FIGURED", 50)
    monkeypatch.setattr(integrity_search, "CHUNK", 97)
    found = check(result)
    assert found == whole
    assert "".join(integrity_csv(result, found)) == "".join(integrity_csv(result, whole))


def test_the_findings_kept_in_columns_read_back_as_the_records_they_were_made_from() -> None:
    """Matches and pairs are kept as columns (a million students' findings in a few hundred MiB, issue 29):
    read back, each is the record it was made from, signed zeros, infinities and labels in any order kept;
    a pair not listed is None, and the flagged pairs are those at most the threshold with two or more parts."""
    matches = (Match(3, "2b", 0, -0.0, 7), Match(0, "1a", 2, 1e300, 1), Match(3, "1a", 1, 2.5e-7, 2))
    pairs = (Pair(3, 0, ("2b", "1a"), 4, 1e-9, 0.01, 2, 0.0), Pair(0, 2, ("1a",), 1, 0.5, 1.0),
             Pair(3, 1, ("1a", "2b"), 4, -0.0, 0.0, 1, math.inf))
    found = Integrity.of(matches, pairs, 12, 0.05, 9, 3)
    assert found.matches == matches and found.pairs == pairs
    assert math.copysign(1.0, found.matches[0].value) == -1.0 and math.copysign(1.0, found.pairs[2].chance) == -1.0
    assert found.pair(3, 1) == pairs[2] and found.pair(1, 3) is None and found.pair(0, 0) is None
    assert found.flagged == (pairs[0], pairs[2])
    assert Integrity.of((), (), 0, 0.05, 0, 0).pair(0, 1) is None
