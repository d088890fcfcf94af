"""Does a submitted number match the key? Tolerance modes, angles, errors, and the sentence that says why.

Three modes, the last two exactly PrairieLearn's ``is_correct_scalar_sf`` / ``is_correct_scalar_dd``:

- ``rtol``: correct iff ``|s - t| <= atol + rtol*|t|`` (the default, ``rtol`` 1 %);
- ``sigfigs`` n: iff ``|s - t| < 0.51*10**(floor(log10|t|) - n + 1)`` (``t = 0``: ``0.51*10**(1 - n)``);
- ``decimals`` n: iff ``|s - t| < 0.51*10**-n``.

Every number is taken as the decimal it prints as (``repr``): ``6.3226`` is exactly 1 % above ``6.26``
and so is accepted at ``rtol`` 1 %, as a person checking by hand would decide. PrairieLearn evaluates
the same rules in float64; the two can differ only for a value within a rounding of the boundary.
Angles (``angle_unit`` ``"deg"`` or ``"rad"``) compare as directions: the difference is reduced to a
half turn either way, and the tolerance is computed from the key as stored.

>>> bool(is_correct(6.3226, 6.26, Tolerance()))
True
>>> is_correct([6.26, 6.27, 6.2651], 6.26, Tolerance("sigfigs", digits=3)).tolist()
[True, False, False]
>>> bool(is_correct(340.9, -19.1, Tolerance(), angle_unit="deg"))
True
>>> feedback(6.5, 6.26, "m/s", Tolerance(), False)
'6.5 m/s is 3.8 % above 6.26 m/s; only ±1 % is accepted'
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Iterator, Sequence
from fractions import Fraction

import numpy as np
from numpy.typing import ArrayLike

from grader.base.errors import shown
from grader.model.quantities import leading_exponent
from grader.model.tolerance import Tolerance, with_unit

LARGEST = float(np.finfo(np.float64).max)
"""What :func:`errors` reports for an error too large for float64 (and for input that is not finite)."""

_PERIOD = {"deg": 360.0, "rad": 2 * math.pi}
_PRAIRIELEARN_HALF = Fraction(51, 100)  # half a unit in the last place, and a little more


# ---- verdicts -------------------------------------------------------------------------------------

def is_correct(submitted: ArrayLike, expected: ArrayLike, tolerance: Tolerance, *,
               angle_unit: str | None = None) -> np.ndarray:
    """Element-wise verdicts (broadcast like numpy); input that is not finite is never correct.

    Symmetric in ``submitted`` and ``expected`` where the accepted band does not depend on the key:
    ``decimals`` mode, and ``rtol`` mode with ``rtol = 0``. Elsewhere the key sets the band's width.

    >>> is_correct([6.32, 6.33, float("nan")], 6.26, Tolerance()).tolist()
    [True, False, False]
    >>> is_correct(0.004, 0.0, Tolerance("decimals", digits=2)).item()
    True
    """
    period = _period(angle_unit)
    s, t, finite = _finite_pairs(submitted, expected)
    with np.errstate(all="ignore"):
        distance = np.abs(_difference(s, t, period))
        bound, unsure = _bound(t, tolerance)
        verdict = distance <= bound if tolerance.mode == "rtol" else distance < bound
        # Rounding in float64 cannot move a verdict unless the distance is this close to the bound;
        # there the exact rule decides.
        scale = np.maximum(np.maximum(bound, np.abs(s)), np.maximum(np.abs(t), period or 0.0))
        unsure |= ~(np.isfinite(distance) & np.isfinite(bound)) | (np.abs(distance - bound) <= 1e-9 * scale + 1e-300)
    verdict &= finite.ravel()
    for index in np.flatnonzero(unsure & finite.ravel()):
        verdict[index] = _exact_verdict(float(s[index]), float(t[index]), tolerance, angle_unit)
    return np.asarray(verdict.reshape(finite.shape), dtype=bool)


def accepted_distance(expected: ArrayLike, tolerance: Tolerance) -> np.ndarray:
    """How far from each key value an answer may be and be accepted, as float64 finds it: up to and including
    it in ``rtol`` mode, strictly less in ``sigfigs`` and ``decimals`` modes (:func:`is_correct` lets the
    exact rule decide within a rounding of it).

    >>> accepted_distance([6.26, -200.0], Tolerance()).tolist(), accepted_distance(6.26, Tolerance("sigfigs")).item()
    ([0.0626, 2.0], 0.0051)
    """
    return _bound(np.asarray(expected, dtype=float), tolerance)[0]


def _finite_pairs(submitted: ArrayLike, expected: ArrayLike) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Both broadcast and flattened, with 0 where either is not finite; and where both are (in shape)."""
    s, t = np.broadcast_arrays(np.asarray(submitted, dtype=float), np.asarray(expected, dtype=float))
    finite = np.isfinite(s) & np.isfinite(t)
    return np.where(finite, s, 0.0).ravel(), np.where(finite, t, 0.0).ravel(), finite


def errors(submitted: ArrayLike, expected: ArrayLike, *,
           angle_unit: str | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Absolute error ``|s - t|`` and relative error ``|s - t|/|t|``, element-wise, always finite.

    Choices, so that nothing NaN or infinite is returned: where the key is 0 the relative error is
    the absolute error (the error relative to one unit of the answer, as ``atol`` reads); an error
    beyond float64, and any input that is not finite, is reported as :data:`LARGEST`. For angles the
    error is the turn to the nearer direction.

    >>> absolute, relative = errors([6.5, 1.0, float("inf")], [6.26, 0.0, 1.0])
    >>> [round(x, 4) for x in absolute.tolist()], [round(x, 4) for x in relative.tolist()]
    ([0.24, 1.0, 1.7976931348623157e+308], [0.0383, 1.0, 1.7976931348623157e+308])
    >>> [e.tolist() for e in errors(359.0, 1.0, angle_unit="deg")]
    [2.0, 2.0]
    """
    period = _period(angle_unit)
    s, t, finite = _finite_pairs(submitted, expected)
    with np.errstate(all="ignore"):
        absolute = np.abs(_difference(s, t, period))
        relative = np.where(t == 0, absolute, absolute / np.where(t == 0, 1.0, np.abs(t)))
    usable = finite.ravel()
    absolute = np.where(usable & np.isfinite(absolute), absolute, LARGEST).reshape(finite.shape)
    relative = np.where(usable & np.isfinite(relative), relative, LARGEST).reshape(finite.shape)
    return absolute, relative


def distances(submitted: ArrayLike, expected: ArrayLike, *, angle_unit: str | None = None) -> np.ndarray:
    """:func:`errors`' absolute error alone, the same numbers without the relative error's work (the integrity
    check compares millions of pairs).

    >>> [round(x, 4) for x in distances([6.5, float("nan")], [6.26, 1.0]).tolist()]
    [0.24, 1.7976931348623157e+308]
    >>> distances(359.0, 1.0, angle_unit="deg").item()
    2.0
    """
    period = _period(angle_unit)
    with np.errstate(all="ignore"):
        absolute = np.abs(_difference(np.asarray(submitted, dtype=float), np.asarray(expected, dtype=float), period))
    return np.where(np.isfinite(absolute), absolute, LARGEST)


def _period(angle_unit: str | None) -> float | None:
    if angle_unit is not None and angle_unit not in _PERIOD:
        raise ValueError(f"angle_unit: expected 'deg', 'rad' or None, got {shown(angle_unit)}")
    return None if angle_unit is None else _PERIOD[angle_unit]


def _difference(s: np.ndarray, t: np.ndarray, period: float | None) -> np.ndarray:
    """``s - t``; for angles reduced to ``(-period/2, period/2]`` (each reduced first: ``fmod`` is exact)."""
    if period is None:
        return np.asarray(s - t)
    turn = np.fmod(s, period) - np.fmod(t, period)
    return np.asarray(turn - period * np.ceil((turn - period / 2) / period))


def _bound(t: np.ndarray, tolerance: Tolerance) -> tuple[np.ndarray, np.ndarray]:
    """The accepted distance from ``t`` in float64, and where float64 cannot be trusted to find it."""
    if tolerance.mode == "rtol":
        return tolerance.atol + tolerance.rtol * np.abs(t), np.zeros(t.shape, dtype=bool)
    if tolerance.mode == "decimals":
        return np.full(t.shape, 0.51 * 10.0 ** -tolerance.digits), np.zeros(t.shape, dtype=bool)
    magnitude = np.log10(np.where(t == 0, 1.0, np.abs(t)))
    # Near a power of ten log10 may round across it; far below 1e-290 the bound is subnormal.
    exponent = np.where(t == 0, 0.0, np.floor(magnitude)) - tolerance.digits + 1
    unsure = (np.abs(magnitude - np.round(magnitude)) < 1e-9) & (t != 0) | (exponent < -290)
    return 0.51 * np.power(10.0, np.maximum(exponent, -290)), unsure


def _exact_verdict(submitted: float, expected: float, tolerance: Tolerance, angle_unit: str | None) -> bool:
    """The rule in exact arithmetic on the numbers as they print.

    >>> _exact_verdict(6.3226, 6.26, Tolerance(), None), _exact_verdict(1e-320, 1e-320, Tolerance("sigfigs"), None)
    (True, True)
    """
    s, t = _decimal(submitted), _decimal(expected)
    distance = abs(s - t)
    if angle_unit is not None:
        period = _decimal(_PERIOD[angle_unit])  # 2π as it prints, like the numbers it reduces
        distance = abs((s - t) - period * math.ceil((s - t - period / 2) / period))
    if tolerance.mode == "rtol":
        return distance <= _decimal(tolerance.atol) + _decimal(tolerance.rtol) * abs(t)
    if tolerance.mode == "decimals":
        return distance < _PRAIRIELEARN_HALF * Fraction(10) ** -tolerance.digits
    return distance < _PRAIRIELEARN_HALF * Fraction(10) ** (leading_exponent(expected) - tolerance.digits + 1)


def _decimal(value: float) -> Fraction:
    return Fraction(repr(float(value)))


# ---- feedback ------------------------------------------------------------------------------------

def feedback(submitted: float, expected: float, unit: str, tolerance: Tolerance, correct: bool, *,
             angle_unit: str | None = None) -> str:
    """One sentence that explains the verdict ``correct`` to the student.

    >>> feedback(6.32, 6.26, "m/s", Tolerance(), True)
    '6.32 m/s is 0.96 % above 6.26 m/s; within ±1 % is accepted'
    >>> feedback(6.27, 6.26, "", Tolerance("sigfigs", digits=3), False)
    '6.27 does not match 6.26 to 3 significant figures (it is 0.01 above)'
    >>> feedback(340.9, -19.1, "deg", Tolerance(), True, angle_unit="deg")
    '340.9° is the same direction as -19.1°; within ±1 % is accepted'
    """
    return feedbacks([submitted], [expected], unit, tolerance, [correct], angle_unit=angle_unit)[0]


def feedbacks(submitted: ArrayLike, expected: ArrayLike, unit: str, tolerance: Tolerance, correct: ArrayLike, *,
              angle_unit: str | None = None, typed: Sequence[str | None] | None = None,
              expected_texts: Sequence[str] | None = None) -> list[str]:
    """:func:`feedback` for each element of equally long sequences (a class's answers to one part):
    the distances in one numpy pass, the words that do not depend on the numbers once. ``typed``: for an
    answer given in another unit, what the student wrote, said before its value in ``unit``;
    ``expected_texts``: the :func:`number_texts` of ``expected``, where the caller has them.

    >>> feedbacks([6.32, 6.5], [6.26, 6.26], "m/s", Tolerance(), [True, False])[1]
    '6.5 m/s is 3.8 % above 6.26 m/s; only ±1 % is accepted'
    >>> feedbacks([17 * 0.44704 / 0.3048], [24.95], "ft/s", Tolerance(), [True], typed=["17.0 mph"])[0]
    '17.0 mph = 24.9333 ft/s is 0.067 % below 24.95 ft/s; within ±1 % is accepted'
    """
    s, t = np.asarray(submitted, dtype=float).ravel(), np.asarray(expected, dtype=float).ravel()
    right = np.asarray(correct, dtype=bool).ravel()
    if not s.shape == t.shape == right.shape:
        raise ValueError(f"feedbacks: expected sequences of one length, got {s.size}, {t.size} and {right.size}")
    words = _Words(tolerance, unit or {"deg": "°", "rad": "rad"}.get(angle_unit or "", ""), _period(angle_unit))
    with np.errstate(all="ignore"):
        distances = _difference(s, t, words.period)
    return words.sentences(s, t, distances, right, typed if typed is not None else [None] * s.size, expected_texts)


class _Words:
    """The sentences of one tolerance and unit: what does not depend on the numbers, worked out once."""

    def __init__(self, tolerance: Tolerance, unit: str, period: float | None) -> None:
        self.tolerance, self.period = tolerance, period
        self.suffix = with_unit("", unit)  # what with_unit(text, unit) puts after text
        self.subjects: dict[float, str] = {}  # the numbers a class typed, with the unit: a few thousand
        self.clauses = {verdict: _clause(tolerance, unit, verdict) for verdict in (True, False)}
        self.to_digits = f" to {tolerance.describe()}"

    def sentences(self, s: np.ndarray, t: np.ndarray, distances: np.ndarray, right: np.ndarray,
                  typed: Sequence[str | None], expected_texts: Sequence[str] | None = None) -> list[str]:
        """:meth:`sentence` for each answer. Most of a class's say ``6.32 m/s is 0.96 % above 6.26 m/s; within
        ±1 % is accepted``: where the tolerance is a percentage alone, such a sentence is written here, its
        percentage worked out for the column in one numpy pass (as :meth:`_comparison` works it out, in
        float64) and each of its words a column at a time; any other answer is :meth:`sentence`'s.
        ``expected_texts``: the :func:`number_texts` of ``t``, where the caller has them."""
        tolerance, suffix, subjects = self.tolerance, self.suffix, self.subjects
        values, keys, gaps, verdicts = s.tolist(), t.tolist(), distances.tolist(), right.tolist()
        if self.period is not None or tolerance.mode != "rtol" or not tolerance.rtol or tolerance.atol:
            return list(map(self.sentence, values, keys, gaps, verdicts, typed))
        with np.errstate(all="ignore"):
            usual = np.isfinite(s) & np.isfinite(t) & (t != 0) & (distances != 0)
            percents = _percent_texts((np.abs(distances) / np.abs(t) * 100).tolist())
        usual &= np.array([text is None for text in typed], dtype=bool)
        key_texts = _key_texts(keys, number_texts(keys) if expected_texts is None else expected_texts)
        said = [subjects.get(value) or subjects.setdefault(value, _shown(value, full=True) + suffix)
                for value in values]
        clauses = [f"{suffix}{self.clauses[ok]}" for ok in (False, True)]
        sentences = [f"{subject} is {percent} % {'above' if gap > 0 else 'below'} {key}{clauses[ok]}"
                     for subject, percent, gap, key, ok in zip(said, percents, gaps, key_texts, verdicts, strict=True)]
        for index in np.flatnonzero(~usual).tolist():  # the others (a few): their sentences said in full
            sentences[index] = self.sentence(values[index], keys[index], gaps[index], verdicts[index], typed[index])
        return sentences

    def sentence(self, submitted: float, expected: float, distance: float, correct: bool,
                 typed: str | None = None) -> str:
        """The sentence for one answer; ``distance`` is ``_difference(submitted, expected)``; ``typed``: the
        student's text, for an answer given in another unit."""
        suffix, period = self.suffix, self.period
        if not math.isfinite(expected):
            return "this answer has no finite value in the key; please ask your instructor to check it"
        key = _shown(expected) + suffix
        if not math.isfinite(submitted):
            return f"{_shown(submitted)} is not a finite number, so it cannot match {key}"
        if typed is not None:
            subject = f"{typed} = {_shown(submitted)}{suffix}"
        else:
            subject = self.subjects.get(submitted) or self.subjects.setdefault(submitted, _shown(submitted, full=True)
                                                                               + suffix)
        if period is not None and abs((submitted - expected) - distance) > 1e-9 * period:
            # The student's direction, written within a half turn of the key.
            if distance == 0 and self.tolerance.mode == "rtol":
                return f"{subject} is the same direction as {key}{self.clauses[correct]}"
            subject = f"{subject} is the same direction as {_shown(expected + distance)}{suffix}, which"
        return f"{subject} {self._comparison(distance, expected, key, correct)}"

    def _comparison(self, distance: float, expected: float, key: str, correct: bool) -> str:
        """``is 1.2 % above 6.26 m/s; ...`` or ``matches 6.26 to 3 significant figures``."""
        tolerance, suffix = self.tolerance, self.suffix
        side = "above" if distance > 0 else "below"
        if tolerance.mode != "rtol":
            n = tolerance.digits
            key = _shown(expected, digits=n) if tolerance.mode == "sigfigs" else f"{expected + 0.0:.{n}f}"
            words = f"{key}{suffix}{self.to_digits}"
            if correct:
                return f"matches {words}"
            return f"does not match {words} (it is {_shown(abs(distance))}{suffix} {side})"
        if distance == 0:
            return f"equals {key}{self.clauses[correct]}"
        percent = f"{_percent(abs(distance) / abs(expected))} %" if expected else ""
        if tolerance.rtol and percent and not tolerance.atol:
            size = percent
        else:
            absolute = _shown(abs(distance)) + suffix
            size = f"{absolute} ({percent})" if tolerance.rtol and percent else absolute
        return f"is {size} {side} {key}{self.clauses[correct]}"


def _clause(tolerance: Tolerance, unit: str, correct: bool) -> str:
    return f"; {'within' if correct else 'only'} {tolerance.describe(unit)} is accepted"


def _shown(value: float, *, full: bool = False, digits: int = 6) -> str:
    """A number as a student reads it: ``6.26``, ``1.5e-7``; ``full`` keeps every digit (their own answer)."""
    value = float(value) + 0.0  # never -0
    if not math.isfinite(value):  # a distance between ±1e308 overflows: said in words, never "inf"
        return "more than 1.8e308" if value == math.inf else repr(value)
    text = repr(value) if full else f"{value:.{digits}g}"
    if "e" not in text:
        if not full and digits < 6:
            text = f"{value:#.{digits}g}".rstrip(".")  # keep the significant trailing zeros: 6.20
        return text[:-2] if text.endswith(".0") else text
    mantissa, _, power = text.partition("e")
    if mantissa.endswith(".0"):
        mantissa = mantissa[:-2]
    return f"{mantissa}e{int(power)}" if power else mantissa


def _key_texts(values: Sequence[float], texts: Sequence[str]) -> list[str]:
    """``_shown(value)`` of each value from its :func:`number_text`: the usual one (no exponent) is that text."""
    return [text if "e" not in text else _shown(value)  # %g never ends in ".0": nothing else to take off
            for value, text in zip(values, texts, strict=True)]


def number_text(value: float) -> str:
    """A number as a person reads it in a report: 6 significant figures, never ``-0``.

    >>> number_text(2.83138271), number_text(-0.0), number_text(1.5e-7)
    ('2.83138', '0', '1.5e-07')
    """
    return f"{float(value) + 0.0:{_FIGURES}}"


def number_texts(values: Sequence[float]) -> list[str]:
    """:func:`number_text` of each of a column of floats (without a call for each).

    >>> number_texts([2.83138271, -0.0, 1.5e-7])
    ['2.83138', '0', '1.5e-07']
    """
    return [f"{value + 0.0:{_FIGURES}}" for value in values]


_FIGURES = ".6g"  # how many significant figures a report shows


def _percent(ratio: float) -> str:
    return _percent_of(ratio * 100)


def _percent_texts(percents: Iterable[float]) -> Iterator[str]:
    """:func:`_percent_of` of each percentage, the usual ones (finite, no exponent) without a call; one at a time
    (each is let go once its sentence is written: a column of them would leave holes among the rows kept)."""
    return (f"{percent:.0f}" if 10 <= percent < 1e6 else text if percent < 10 and "e" not in (text := f"{percent:.2g}")
            else _percent_of(percent) for percent in percents)


def _percent_of(percent: float) -> str:
    """A percentage for people: whole from 10 %, else two significant figures."""
    if not math.isfinite(percent):
        return _shown(percent)
    if 10 <= percent < 1e6:
        return f"{percent:.0f}"
    text = f"{percent:.2g}"
    return text if "e" not in text else _shown(float(text))  # two figures print alike in _shown
