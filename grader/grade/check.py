"""``grader check``: one answer graded exactly as ``grader grade`` grades it.

Against a part of a key (``--key``, ``--student``, ``--label``), or against a value or expression
given on the command line or in a JSON line, with its unit, tolerance and symbols. The verdict comes
from :func:`grader.grade.grading.grade_part`, the function ``grader grade`` uses for every cell.

>>> result = check("626 cm/s", expectation(6.26, unit="m/s"))
>>> result["verdict"], result["parsed"], result["tolerance"]
('correct', 6.26, '±1 %')
>>> check("6.4", expectation(6.26, unit="m/s", tolerance={"mode": "sigfigs", "digits": 2}))["feedback"]
'6.4 m/s does not match 6.3 m/s to 2 significant figures (it is 0.14 m/s above)'
>>> check("0.1p v", expectation("v*p/10", symbols=["p", "v"]))["verdict"]
'correct'
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from grader.base.errors import GraderError, UsageError, shown
from grader.base.inputs import CELL_CHARS, decode_text, read_input
from grader.grade.diagnosis import Physics
from grader.grade.grading import Request, Verdict, grade_part, grade_parts
from grader.grade.key import Key, KeyPart
from grader.grade.notation import ReadError, tree_of, value_of
from grader.grade.submissions import Answer, find_label
from grader.model.expr import CONSTANTS, FUNCTIONS, names, to_text
from grader.model.quantities import parse_unit, split_quantity
from grader.model.tolerance import SYMBOL_RANGE, Tolerance

_GIVEN = Key(where="the command line", version=2, title="grader check", numeric_expressions=True,
             problems=(), students=())
"""The context of an answer checked against a given value: arithmetic allowed, as by default."""

FIELDS = ("verdict", "credit", "parsed", "expected", "unit", "abs_error", "rel_error", "tolerance", "tolerance_reason",
          "feedback", "diagnosis")
"""The fields of a result, in order (``--json`` and ``--batch``): ``tolerance`` is the figure that decided
(``±2.7 %``), ``tolerance_reason`` why the key widened it (``""`` when it is as configured)."""

_BATCH_FIELDS = {"submitted", "expected", "unit", "tolerance", "symbols", "domains", "student", "label"}


@dataclass(frozen=True)
class Expectation:
    """What an answer is checked against: a part, and the key it belongs to (for the assignment's
    grading settings and the seed of symbolic comparisons); for a part of a key, the student's id and
    what diagnoses mistakes (:func:`grader.grade.diagnosis.physics_for`)."""

    part: KeyPart
    key: Key
    student: str = ""
    physics: Physics | None = None


@dataclass(frozen=True)
class Asked:
    """What ``grader check`` is asked, as its command line gives it: an answer against a key's part (``key``,
    ``student``, ``label``), or against a given value (``expected``, ``unit``, a tolerance, ``symbols``,
    ``domains``), or ``batch``, a file of JSON lines (``-``: standard input)."""

    answer: str | None = None
    key: Path | None = None
    student: str | None = None
    label: str | None = None
    expected: str | None = None
    unit: str | None = None
    rtol: float | None = None
    atol: float | None = None
    sigfigs: int | None = None
    decimals: int | None = None
    symbols: str | None = None
    domains: tuple[str, ...] = ()
    batch: Path | None = None

    def refuse_a_mix(self) -> None:
        """The two ways to call ``grader check``, and ``--batch``; a mix of them is refused with the reason."""
        given = [f"--{name}" for name in ("expected", "unit", "rtol", "atol", "sigfigs", "decimals", "symbols")
                 if getattr(self, name) is not None] + (["--domain"] if self.domains else [])
        chosen = [f"--{name}" for name in ("student", "label") if getattr(self, name) is not None]
        if self.batch is not None:
            if self.answer is not None or given or chosen:
                raise UsageError("--batch takes every answer and expectation from its lines; give it alone "
                                 "(with --key when the lines name a student and label)")
            return
        if self.answer is None:
            raise UsageError("expected the answer to check, e.g. grader check \"6.3 m/s\" --expected 6.26 --unit m/s")
        modes = [flag for flag in ("--sigfigs", "--decimals") if flag in given]
        if len(modes) > 1 or (modes and {"--rtol", "--atol"} & set(given)):
            raise UsageError(f"{' and '.join(modes + sorted({'--rtol', '--atol'} & set(given)))}: choose one "
                             "tolerance mode (--rtol/--atol, --sigfigs or --decimals)")
        if self.key is not None:
            if given:
                raise UsageError(f"{', '.join(given)}: with --key the expected answer, unit and tolerance come from "
                                 "the key")
            if len(chosen) < 2:
                raise UsageError("--key needs --student ID and --label LABEL (the part as printed, e.g. 1a)")
        elif chosen or self.expected is None:
            raise UsageError("expected --expected VALUE (and --unit), or --key with --student and --label")

    def against(self, key: Key | None, physics: Physics | None) -> Expectation:
        """What the answer is checked against: the part of ``key`` (read from :attr:`key`), or the given value."""
        if key is not None:
            assert self.student is not None and self.label is not None  # refuse_a_mix saw to it
            return from_key(key, self.student, self.label, physics)
        assert self.expected is not None  # refuse_a_mix saw to it
        tolerance: dict[str, Any] = {name: getattr(self, name) for name in ("rtol", "atol")
                                     if getattr(self, name) is not None}
        for mode in ("sigfigs", "decimals"):
            if getattr(self, mode) is not None:
                tolerance = {"mode": mode, "digits": getattr(self, mode)}
        symbols = None if self.symbols is None else [s.strip() for s in self.symbols.split(",")]
        expected, unit = expected_quantity(self.expected, self.unit)
        return expectation(expected, unit=unit, tolerance=tolerance, symbols=symbols, domains=domains(self.domains))


def expected_quantity(text: str, unit: str | None) -> tuple[float | str, str]:
    """``--expected``: a number (``6.26``, or ``6.26 m/s`` when ``--unit`` is not given) or an expression.

    >>> expected_quantity("6.26 m/s", None), expected_quantity("2v", None), expected_quantity("6.26", "m/s")
    ((6.26, 'm/s'), ('2v', ''), (6.26, 'm/s'))
    """
    quantity = split_quantity(text)
    if quantity is None:
        return text, unit or ""  # an expression
    value, written = quantity
    if written:
        try:
            parse_unit(written)
        except GraderError:
            return text, unit or ""  # 2v: an expression
        if unit is not None and unit.strip() != written:
            raise UsageError(f"--expected {text} and --unit {unit}: give the unit once")
        return value, written
    return value, unit or ""


BATCH_BYTES = 1 << 30
"""The most ``--batch`` reads (1 GiB): 100,000 lines are a few MB."""


def batch_lines(path: Path) -> list[str]:
    """The lines of ``--batch FILE`` (``-``: standard input), read within :data:`BATCH_BYTES`."""
    data = read_input(path, BATCH_BYTES)
    if data is None:
        raise UsageError("--batch -: standard input is closed; send the lines to it, or give --batch FILE.jsonl")
    return decode_text(data, Path("standard input") if str(path) == "-" else path).splitlines()


def json_blocks(lines: Sequence[str], key: Key | None, physics: Physics | None) -> Iterator[tuple[str, int]]:
    """The results of :func:`batch` as lines of JSON (:func:`json_line`), a block of :data:`BATCH_CHUNK` lines at
    a time (written a block at a time, not a line at a time), each with how many of its lines are errors."""
    block: list[str] = []
    failed = 0
    for found in batch(lines, key, physics):
        failed += "error" in found
        block.append(json_line(found))
        if len(block) == BATCH_CHUNK:
            yield "\n".join(block), failed
            block, failed = [], 0
    if block:
        yield "\n".join(block), failed


def json_line(found: dict[str, Any]) -> str:
    r"""A result as one line of strict JSON, UTF-8 as it is (``±1 %``), except lone surrogates (input
    echoed in an error: a JSON ``\ud800``, a file name that is not UTF-8), which no UTF-8 output can
    write: they keep their ``\u`` escape.

    >>> json_line({"error": "unit: cannot read unit '\ud800'", "tolerance": "±1 %"})
    '{"error": "unit: cannot read unit \'\\ud800\'", "tolerance": "±1 %"}'
    """
    text = json.dumps(found, ensure_ascii=False, allow_nan=False)
    return _SURROGATE.sub(lambda m: f"\\u{ord(m.group()):04x}", text)


_SURROGATE = re.compile("[\ud800-\udfff]")


def from_key(key: Key, student: str, label: str, physics: Physics | None = None) -> Expectation:
    """The part ``label`` of the key's student ``student`` (an id, or an email as in the roster); with
    ``physics``, a wrong number is diagnosed as ``grader grade`` diagnoses it."""
    student = student.strip()
    at = key.positions.get(student)
    found = [key.students[at]] if at is not None else \
        [s for s in key.students if s.email and s.email.lower() == student.lower()]
    if not found:
        unpadded = [s.id for s in key.students if s.id.lstrip("0") == student.lstrip("0")]
        hint = f"; did you mean {unpadded[0]}?" if len(unpadded) == 1 else ""
        if len(unpadded) > 1:
            hint = f"; with leading zeros it could be {' or '.join(sorted(unpadded))}: give the id in full"
        raise UsageError(f"{key.where}: no student {shown(student)} (by id or email){hint}")
    parts = found[0].parts
    named = find_label(label, key.labels)  # as grade reads a label cell: " 1A " is 1a
    if named is None:
        raise UsageError(f"{key.where}: no part {shown(label)}; the parts are {', '.join(key.labels)}")
    return Expectation(parts[named], key, found[0].id, physics)


def expectation(expected: float | str | None, *, unit: str = "", tolerance: Mapping[str, Any] | None = None,
                symbols: Sequence[str] | None = None,
                domains: Mapping[str, tuple[float, float]] | None = None) -> Expectation:
    """A part made from given values: a number, an expression (symbolic), or None (no value exists).

    ``expected`` as text is a number or arithmetic (``sqrt(2*9.81*2)``) unless it has names: then it is
    an expression in ``symbols`` (default: the names it uses), each drawn from ``domains`` or [1, 10].
    """
    try:
        parse_unit(unit)  # the units a key can hold: a typing error is refused here, not blamed on the student
    except GraderError as error:
        raise UsageError(f"unit: {error}") from None
    rule = Tolerance.from_json({} if tolerance is None else tolerance)
    value, ranges = _expected(expected, symbols, domains or {})
    return Expectation(KeyPart(problem="", name="", label="answer", value=value, unit=unit, points=1.0,
                               tolerance={"mode": rule.mode, **rule.to_json()},
                               undefined=None if value is not None else "given as undefined", symbols=ranges),
                       _GIVEN)


def _expected(expected: float | str | None, symbols: Sequence[str] | None,
              domains: Mapping[str, tuple[float, float]]) -> tuple[float | str | None,
                                                                   dict[str, tuple[float, float]]]:
    if expected is None or (isinstance(expected, float | int) and not isinstance(expected, bool)):
        if symbols or domains:
            raise UsageError("symbols and domains are for an expected expression, not a number")
        return None if expected is None else _finite("expected", expected), {}
    if not isinstance(expected, str):
        raise UsageError(f"expected: expected a number, an expression or null, got {shown(expected)}")
    if symbols is not None and not all(isinstance(name, str) and name.isidentifier() for name in symbols):
        raise UsageError(f"symbols: expected names like p, v, got {shown(list(symbols))}")
    try:
        tree = tree_of(expected, tuple(symbols) if symbols is not None else _names_in(expected))
    except (ReadError, GraderError) as error:
        raise UsageError(f"expected {shown(expected)}: {error}") from None
    used = sorted(names(tree))
    if not used:
        if domains:
            raise UsageError("domains are for an expected expression, not a number")
        try:
            return value_of(tree) + 0.0, {}  # never -0
        except ReadError as error:
            raise UsageError(f"expected {shown(expected)}: {error}") from None
    listed = list(symbols) if symbols is not None else used
    unknown = sorted(set(domains) - set(listed))
    if unknown:
        raise UsageError(f"a domain for {', '.join(unknown)}, which the expression's symbols "
                         f"({', '.join(listed)}) do not include")
    return to_text(tree), {name: domains.get(name, SYMBOL_RANGE) for name in listed}


def _names_in(text: str) -> tuple[str, ...]:
    """The names an expected expression uses, as its symbols when none are given (``2v`` uses v); ``inf``
    and ``nan`` are no names but numbers, refused as not finite."""
    words = set(re.findall(r"[A-Za-z_]\w*", text[:CELL_CHARS])) - set(FUNCTIONS) - set(CONSTANTS)
    return tuple(sorted(word for word in words if word.lower() not in _NOT_FINITE))


_NOT_FINITE = ("inf", "infinity", "nan")


def domain(text: str) -> tuple[str, tuple[float, float]]:
    """``p=0.1:10`` as a name and its range (a command-line ``--domain``).

    >>> domain("p=0.1:10")
    ('p', (0.1, 10.0))
    """
    name, _, bounds = text.partition("=")
    low, _, high = bounds.partition(":")
    try:
        return name.strip(), _range(name.strip(), [float(low), float(high)])
    except ValueError:
        raise UsageError(f"--domain {shown(text)}: expected NAME=LOW:HIGH, like p=0.1:10") from None


def _range(name: str, bounds: Any) -> tuple[float, float]:
    """Where a symbol is drawn: LOW < HIGH, both finite and their span too (points are drawn across it)."""
    if not name.isidentifier():
        raise UsageError(f"domain: expected a name like p, got {shown(name)}")
    problem = UsageError(f"domain of {name}: expected two finite numbers LOW < HIGH, got {shown(bounds)}")
    if not (isinstance(bounds, list) and len(bounds) == 2
            and all(isinstance(b, float | int) and not isinstance(b, bool) for b in bounds)):
        raise problem
    try:
        low, high = _finite("", bounds[0]), _finite("", bounds[1])
    except UsageError:
        raise problem from None
    if not (low < high and math.isfinite(high - low)):
        raise problem
    return low, high


def _finite(field: str, number: float) -> float:
    """A number of a request as a float, finite (an integer of 400 digits is not), never -0."""
    try:
        value = float(number) + 0.0
    except OverflowError:
        value = math.inf
    if not math.isfinite(value):
        raise UsageError(f"{field}: expected a finite number, got {shown(number)}")
    return value


def check(submitted: str, against: Expectation) -> dict[str, Any]:
    """Grade one answer; the result has the fields of :data:`FIELDS`."""
    answer = Answer("the command line", 0, "", against.part.label, submitted, ",", None)
    return result(grade_part(against.part, against.student, answer, against.key, against.physics), against.part)


def result(verdict: Verdict, part: KeyPart) -> dict[str, Any]:
    """A verdict as the JSON object ``grader check`` prints: numbers as numbers, absent ones as null."""
    parsed: float | str | None = verdict.parsed or None
    if parsed is not None and not part.symbolic:
        parsed = float(parsed)
    # Grading's words are Tolerance.explained's, "figure: reason"; a symbolic answer's ("equal expressions")
    # use no tolerance.
    reason = "" if part.symbolic else str(part.tolerance.get("reason", ""))
    figure = verdict.tolerance.removesuffix(f": {reason}") if reason else verdict.tolerance
    return {"verdict": verdict.verdict, "credit": verdict.credit, "parsed": parsed, "expected": part.value,
            "unit": part.unit, "abs_error": verdict.abs_error, "rel_error": verdict.rel_error,
            "tolerance": figure, "tolerance_reason": reason, "feedback": verdict.feedback,
            "diagnosis": verdict.diagnosis}


def batch(lines: Sequence[str], key: Key | None, physics: Physics | None = None) -> Iterator[dict[str, Any]]:
    """One result per line that is not blank, in order; a line that cannot be checked gives
    ``{"line": n, "error": reason}`` and the others go on. ``physics`` diagnoses the key's parts. Lines are
    read one by one and graded :data:`BATCH_CHUNK` at a time, a part's answers together, as ``grader grade``
    grades a column."""
    for start in range(0, len(lines), BATCH_CHUNK):
        yield from _chunk(lines[start:start + BATCH_CHUNK], start, key, physics)


BATCH_CHUNK = 4096
"""Lines of ``--batch`` graded together: enough that the per-call work of grading is spread thin."""


def _chunk(lines: Sequence[str], start: int, key: Key | None, physics: Physics | None) -> Iterator[dict[str, Any]]:
    results: list[dict[str, Any] | None] = [None] * len(lines)
    asked: list[tuple[int, Expectation]] = []
    requests: list[Request] = []
    for offset, line in enumerate(lines):
        if not line.strip():
            continue
        try:
            submitted, against = _line(line, key, physics)
        except GraderError as error:
            results[offset] = {"line": start + offset + 1, "error": str(error)}
            continue
        asked.append((offset, against))
        requests.append(Request(against.part, against.student,
                                Answer("the command line", 0, "", against.part.label, submitted, ",", None)))
    given = [index for index, (_, against) in enumerate(asked) if against.key is _GIVEN]
    mine = [index for index, (_, against) in enumerate(asked) if against.key is not _GIVEN]
    for indices, context, found in ((given, _GIVEN, None), (mine, key, physics)):
        if not indices or context is None:
            continue
        verdicts = grade_parts([requests[index] for index in indices], context, found)
        for index, verdict in zip(indices, verdicts, strict=True):
            offset, against = asked[index]
            results[offset] = result(verdict, against.part)
    yield from (found_result for found_result in results if found_result is not None)


def _line(line: str, key: Key | None, physics: Physics | None) -> tuple[str, Expectation]:
    """What a line of ``--batch`` asks: the answer, and what it is checked against."""
    try:
        item = json.loads(line, parse_constant=_refuse_constant, object_pairs_hook=_once_each)
    except _TwiceError as error:
        raise UsageError(str(error)) from None
    except ValueError as error:
        raise UsageError(f"expected a JSON object, got invalid JSON ({error})") from None
    except RecursionError as error:  # nested deeper than Python reads
        raise UsageError(str(error)) from None
    if not isinstance(item, dict):
        raise UsageError(f"expected a JSON object, got {shown(item)}")
    extra = sorted(str(name) for name in item if name not in _BATCH_FIELDS)
    if extra:
        raise UsageError(f"unknown field {shown(', '.join(extra))[1:-1]}; expected {', '.join(sorted(_BATCH_FIELDS))}")
    submitted = item.get("submitted")
    if isinstance(submitted, float | int) and not isinstance(submitted, bool):
        submitted = repr(submitted)
    if not isinstance(submitted, str):
        raise UsageError(f"submitted: expected the answer as text, got {shown(submitted)}")
    if "student" in item or "label" in item:
        if key is None:
            raise UsageError("student and label need --key")
        return submitted, from_key(key, _text(item, "student"), _text(item, "label"), physics)
    if "expected" not in item:
        raise UsageError("expected: missing (a number, an expression or null)" +
                         ("; or give student and label" if key is not None else ""))
    symbols = item.get("symbols")
    if symbols is not None and not (isinstance(symbols, list) and all(isinstance(s, str) for s in symbols)):
        raise UsageError(f"symbols: expected a list of names like [\"p\", \"v\"], got {shown(symbols)}")
    ranges = item.get("domains", {})
    if not isinstance(ranges, dict):
        raise UsageError(f"domains: expected an object like {{\"p\": [0.1, 10]}}, got {shown(ranges)}")
    unit = item.get("unit", "")
    if not isinstance(unit, str):
        raise UsageError(f"unit: expected text like \"m/s\", got {shown(unit)}")
    against = expectation(item["expected"], unit=unit, tolerance=item.get("tolerance"), symbols=symbols,
                          domains={str(name): _range(str(name), bounds) for name, bounds in ranges.items()})
    return submitted, against


def _text(item: Mapping[str, Any], name: str) -> str:
    value = item.get(name)
    if not isinstance(value, str):
        raise UsageError(f"{name}: expected text, got {shown(value)}")
    return value


class _TwiceError(ValueError):
    """A JSON object with a name given twice (JSON's rule, the last one wins, would drop the first)."""


def _once_each(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    """A JSON object's pairs as a dict, each name given once.

    >>> _once_each([("expected", 1), ("expected", 2)])
    Traceback (most recent call last):
    ...
    grader.grade.check._TwiceError: the field 'expected' appears twice; expected each field once (the last would win)
    """
    item = dict(pairs)
    if len(item) != len(pairs):
        twice = next(name for index, (name, _) in enumerate(pairs) if any(name == n for n, _ in pairs[:index]))
        raise _TwiceError(f"the field {shown(twice)} appears twice; expected each field once (the last would win)")
    return item


def domains(texts: Sequence[str]) -> dict[str, tuple[float, float]]:
    """Command-line ``--domain``s by name, each name given once (the last would silently win).

    >>> domains(["p=0.1:10", "v=1:5"])
    {'p': (0.1, 10.0), 'v': (1.0, 5.0)}
    >>> domains(["p=0.1:10", "p=1:2"])
    Traceback (most recent call last):
    ...
    grader.base.errors.UsageError: --domain p=1:2: p's domain is already given (--domain p=0.1:10); give each name once
    """
    found: dict[str, tuple[float, float]] = {}
    given: dict[str, str] = {}
    for text in texts:
        name, bounds = domain(text)
        if name in found:
            raise UsageError(f"--domain {text}: {name}'s domain is already given (--domain {given[name]}); give each "
                             "name once")
        found[name], given[name] = bounds, text
    return found


def _refuse_constant(name: str) -> float:
    raise ValueError(f"{name} is not a number JSON allows")
