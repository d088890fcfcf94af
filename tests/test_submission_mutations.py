"""`grader grade` on submission files mutated by Hypothesis (issue 22, "Done when"): rows dropped, repeated
and reordered, cells replaced by what students and spreadsheets produce (blank, huge, formulas, NaN, numbers
beyond float64, angles in degrees and minutes, markup, control characters), headers renamed or repeated,
timestamps odd or in the future, other delimiters, a byte-order mark, bytes that are not UTF-8. Whatever the
file holds, grading grades it (exit 0 or 3) or refuses it (exit 2) with one line: never a traceback, never a
changed input, nothing left behind when refused. (Memory: tests/test_grading_bounds.py measures whole runs
against the stated bound; tracing every example here would make it ten times slower.)
"""

from __future__ import annotations

import tracemalloc
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from tests.test_key_mutations import grade_or_refuse, sample

__all__ = ["sample"]  # the key of three students and their answers, as the key mutations use them

ODD_CELLS = st.sampled_from([
    "", " ", "=1+1", "＝HYPERLINK(\"x\")", "@SUM(A1)", "nan", "NaN m/s", "inf", "-inf", "1e-400", "1e400",
    "1.6e308", "55°30'", "6,26", "6.26 m/s", "626 cm/s", "1/0", "0/0", "x" * 1001, "2" * 400,
    "sqrt(-1)", "v*(1 - 0.1*p)/(p + 1)", "Max(0, p)", "<script>alert(1)</script>", "\x1b[2J", "\u202e1.0",
    "1;2", "\"unclosed", "1a", "2026-12-04 23:59", "9" * 5000,
])
ODD_TIMES = st.sampled_from(["2026-12-04 23:59", "2099-01-01 00:00", "1970-01-01", "yesterday", "", "9999-99-99",
                             "2026-12-04T23:59:00+14:00", "2026-12-05 00:14"])


def _mutate(lines: list[str], data: st.DataObject) -> list[str]:
    """One change to the file's lines (the header is line 0)."""
    body = len(lines) - 1
    kind = data.draw(st.sampled_from(["drop", "repeat", "swap", "cell", "header", "time", "junk", "delimiter"]),
                     label="change")
    event(kind)
    at = data.draw(st.integers(1, max(body, 1)), label="row")
    if kind == "drop" and body:
        return lines[:at] + lines[at + 1:]
    if kind == "repeat" and body:
        return lines[:at] + [lines[at]] * data.draw(st.integers(2, 50), label="times") + lines[at + 1:]
    if kind == "swap" and body > 1:
        other = data.draw(st.integers(1, body), label="other")
        lines = list(lines)
        lines[at], lines[other] = lines[other], lines[at]
        return lines
    if kind == "cell" and body:
        cells = lines[at].split(",")
        cells[data.draw(st.integers(0, len(cells) - 1), label="column")] = data.draw(ODD_CELLS)
        return [*lines[:at], ",".join(cells), *lines[at + 1:]]
    if kind == "header":
        header = data.draw(st.sampled_from(["student_id,label,answer,answer", "id,label,answer", "student_id,1a,1b",
                                            "", "\ufeffstudent_id,label,answer", "a,b,c",
                                            "student_id,label,answer,timestamp"]), label="header")
        return [header, *lines[1:]]
    if kind == "time":
        lines = [lines[0] + ",timestamp"] + [f"{line},{data.draw(ODD_TIMES)}" for line in lines[1:]]
        return lines
    if kind == "junk":
        return [*lines[:at], data.draw(st.text(max_size=40), label="junk"), *lines[at:]]
    return [line.replace(",", data.draw(st.sampled_from([";", "\t", "|"]), label="delimiter")) for line in lines]


FEW = settings(max_examples=6, deadline=None, suppress_health_check=[HealthCheck.too_slow])
MANY = settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])


@FEW
@given(data=st.data(), not_utf8=st.booleans())
def test_grading_mutated_submissions_grades_or_refuses_them_and_never_crashes(
        sample: tuple[dict[str, Any], str], data: st.DataObject, not_utf8: bool) -> None:
    """Exit 0, 2 or 3; on 2 one line on stderr and no --out; inputs unchanged (a dozen files: each grading
    draws the class report, about a second)."""
    _grade_mutated(sample, data, not_utf8)


@pytest.mark.slow
@MANY
@given(data=st.data(), not_utf8=st.booleans())
def test_grading_many_mutated_submissions_never_crashes(sample: tuple[dict[str, Any], str], data: st.DataObject,
                                                       not_utf8: bool) -> None:
    """The same property over 300 files."""
    _grade_mutated(sample, data, not_utf8)


def _grade_mutated(sample: tuple[dict[str, Any], str], data: st.DataObject, not_utf8: bool) -> None:
    document, submissions = sample
    lines = submissions.splitlines()
    for _ in range(data.draw(st.integers(1, 4), label="changes")):
        lines = _mutate(lines, data)
    text = ("\n".join(lines) + "\n").encode("utf-8", "surrogatepass")
    if not_utf8:
        text = text.replace(b"1a", b"1\xe9a", 1)
    grade_or_refuse(document, text)


def test_reading_a_small_key_takes_memory_for_what_it_holds_not_for_the_limit(tmp_path: Path) -> None:
    """A file was read with ``read(limit + 1)``: 1 GiB asked of the allocator for a key of a few kB (untouched,
    so not resident, but refused under a memory limit such as ``ulimit -v``)."""
    from grader.base.inputs import read_bytes
    from grader.grade.key import KEY_BYTES

    small = tmp_path / "key.json"
    small.write_bytes(b"{}" * 1000)
    tracemalloc.start()
    try:
        assert read_bytes(small, KEY_BYTES) == b"{}" * 1000
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 1 << 20, peak
