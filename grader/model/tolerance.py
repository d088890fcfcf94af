"""How close an answer must be to the key: one tolerance, from the template to the verdict.

A template sets ``{rtol, atol}``; an assignment may override it per answer with ``{rtol, atol}``
(either alone keeps the other), ``{sigfigs: N}`` or ``{decimals: N}``; the key stores it in its JSON
form (``{"mode": "rtol", "rtol", "atol"}`` or ``{"mode": "sigfigs", "digits"}``, and key version 1's
bare ``{"rtol", "atol"}``); ``grader check --batch`` takes either form. The comparison rules live in
:mod:`grader.grade.compare`; this is the data and its words.

>>> Tolerance.from_json({"sigfigs": 3}) == Tolerance("sigfigs", digits=3)
True
>>> Tolerance.from_json({"atol": 0.05}, base=Tolerance(rtol=0.02)).describe("m/s")
'±2 % + 0.05 m/s'
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any, Literal

from grader.base.errors import GraderError, shown

Mode = Literal["rtol", "sigfigs", "decimals"]
MODES: tuple[Mode, ...] = ("rtol", "sigfigs", "decimals")
ANSWER_SIG_FIGS = 3
"""The significant figures the sheet asks answers to be given to (what rounding bounds assume)."""
MAX_REASON = 300
"""The longest reason a key may carry for a widened tolerance."""
MAX_DIGITS = 17
"""float64 carries 17 significant digits; more cannot be told apart."""

FORMS = "{rtol: X, atol: Y}, {sigfigs: N} or {decimals: N}"
"""The forms an instructor writes, for messages."""
SYMBOL_RANGE = (1.0, 10.0)
"""Where a symbolic answer's name with no sampled range (a symbol such as a speed v, or any name of a
version 1 key) is drawn to compare expressions, when the key is written and when it is read."""

EQUAL_EXPRESSIONS = "equal expressions"
"""The tolerance of a part answered by an expression, in words (details.csv, the answer key): it is right when
it is the key's expression (:func:`grader.grade.equivalence.equivalent`), whatever the numeric tolerance."""


class ToleranceError(GraderError, ValueError):
    """A tolerance that is not one of the accepted forms; ``field`` names the entry (``""``: the whole),
    ``got`` is what came, as shown in the message."""

    def __init__(self, field: str, expected: str, got: str) -> None:
        self.field, self.expected, self.got = field, expected, got
        super().__init__(f"tolerance{'.' + field if field else ''}: expected {expected}, got {got}")


@dataclass(frozen=True)
class Tolerance:
    """How close a submitted number must be to the key.

    ``rtol`` mode: ``|s - t| <= atol + rtol*|t|`` (``atol`` in the answer's unit); ``sigfigs`` and
    ``decimals`` modes: PrairieLearn's rules with ``digits`` figures or places. Values that do not apply
    to the mode must stay at their defaults, so two tolerances are equal exactly when they grade alike.

    >>> Tolerance().describe(), Tolerance(atol=0.05).describe("m/s"), Tolerance(rtol=0, atol=0.5).describe("deg")
    ('±1 %', '±1 % + 0.05 m/s', '±0.5°')
    >>> Tolerance("sigfigs", digits=3).describe(), Tolerance("decimals", digits=1).describe()
    ('3 significant figures', '1 decimal place')
    >>> Tolerance("sigfigs", digits=0)
    Traceback (most recent call last):
    ...
    grader.model.tolerance.ToleranceError: tolerance.digits: expected a whole number from 1 to 17, got 0
    """

    mode: Mode = "rtol"
    rtol: float = 0.01
    atol: float = 0.0
    digits: int = 3
    reason: str = field(default="", compare=False)
    """Why this tolerance is wider than the one configured (what honest rounding along a solution route
    needs), in words that follow the figure: ``rounding T and T′ to 4 figures moves loss_pct by up to
    1.3 %``; empty when it is as configured. It does not change how answers are graded."""

    def __post_init__(self) -> None:
        if self.mode not in MODES:
            raise ToleranceError("mode", "'rtol', 'sigfigs' or 'decimals'", shown(self.mode))
        for name in ("rtol", "atol"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0 <= value < 1e300:
                raise ToleranceError(name, "a number from 0 to 1e300", shown(value))
            object.__setattr__(self, name, float(value))
        lowest = 1 if self.mode == "sigfigs" else 0
        if isinstance(self.digits, bool) or not isinstance(self.digits, int) or not lowest <= self.digits <= MAX_DIGITS:
            raise ToleranceError("digits", f"a whole number from {lowest} to {MAX_DIGITS}", shown(self.digits))
        if self.mode == "rtol" and self.digits != 3:
            raise ToleranceError("digits", "no digits in rtol mode (digits count only for sigfigs and decimals)",
                                 shown(self.digits))
        if not isinstance(self.reason, str) or len(self.reason) > MAX_REASON:
            raise ToleranceError("reason", f"text of at most {MAX_REASON} characters", shown(self.reason)[:80])
        if self.mode != "rtol" and (self.rtol, self.atol) != (0.01, 0.0):
            raise ToleranceError("rtol", f"no rtol or atol in {self.mode} mode (they count only in rtol mode)",
                                 shown({"rtol": self.rtol, "atol": self.atol}))

    def describe(self, unit: str = "") -> str:
        """What is accepted, in words; ``atol`` is in the answer's ``unit``."""
        if self.mode != "rtol":
            noun = "significant figure" if self.mode == "sigfigs" else "decimal place"
            return f"{self.digits} {noun}" + ("" if self.digits == 1 else "s")
        relative = f"{_plain(self.rtol * 100)} %"
        if not self.atol:
            return f"±{relative}"
        absolute = with_unit(_plain(self.atol), unit)
        return f"±{relative} + {absolute}" if self.rtol else f"±{absolute}"

    def explained(self, unit: str = "") -> str:
        """:meth:`describe`, with the reason a widened tolerance carries.

        >>> Tolerance(rtol=0.027, reason="rounding T and T′ to 4 figures moves loss_pct by up to 1.3 %").explained()
        '±2.7 %: rounding T and T′ to 4 figures moves loss_pct by up to 1.3 %'
        >>> Tolerance().explained("m/s")
        '±1 %'
        """
        described = self.describe(unit)
        return f"{described}: {self.reason}" if self.reason else described

    @classmethod
    def from_json(cls, data: Any, *, base: Tolerance | None = None) -> Tolerance:
        """Read any written form: ``{"rtol", "atol"}`` (either may be left out: it comes from ``base``,
        else the default), ``{"sigfigs": N}``, ``{"decimals": N}``, or the key's ``{"mode", ...}``.

        >>> Tolerance.from_json({"mode": "decimals", "digits": 2}) == Tolerance("decimals", digits=2)
        True
        >>> Tolerance.from_json({"rtol": 0.02, "digits": 3})
        Traceback (most recent call last):
        ...
        grader.model.tolerance.ToleranceError: tolerance: expected only the keys atol, mode, reason, rtol in ...
        """
        if not isinstance(data, Mapping):
            raise ToleranceError("", f"a mapping like {FORMS}", shown(data))
        shorthand: list[Mode] = [mode for mode in ("sigfigs", "decimals") if mode in data]
        if shorthand:
            if len(data) != 1:
                raise ToleranceError("", f"{FORMS}, one of them", shown(dict(data)))
            return cls(shorthand[0], digits=data[shorthand[0]])
        mode = data.get("mode", "rtol")
        if mode not in MODES:
            raise ToleranceError("mode", "'rtol', 'sigfigs' or 'decimals'", shown(mode))
        allowed = ({"mode", "rtol", "atol"} if mode == "rtol" else {"mode", "digits"}) | {"reason"}
        extra = sorted(str(key) for key in data if key not in allowed)
        if extra:
            raise ToleranceError("", f"only the keys {', '.join(sorted(allowed))} in {mode} mode",
                                 shown(", ".join(extra))[1:-1])
        reason = data.get("reason", "")
        if mode != "rtol":
            return cls(mode, digits=data.get("digits", 3), reason=reason)
        start = base if base is not None and base.mode == "rtol" else cls()
        return cls(rtol=data.get("rtol", start.rtol), atol=data.get("atol", start.atol), reason=reason)

    def to_json(self) -> dict[str, Any]:
        """The key's form, with the mode named.

        >>> Tolerance().to_json(), Tolerance("decimals", digits=2).to_json()
        ({'mode': 'rtol', 'rtol': 0.01, 'atol': 0.0}, {'mode': 'decimals', 'digits': 2})
        """
        data: dict[str, Any] = ({"mode": "rtol", "rtol": self.rtol, "atol": self.atol} if self.mode == "rtol"
                                else {"mode": self.mode, "digits": self.digits})
        if self.reason:
            data["reason"] = self.reason
        return data


@dataclass(frozen=True)
class Widening:
    """How many of a part's variants got a tolerance widened for rounding, of how many, and the widest
    of them (with its reason): what the answer key's cover and the class report say of a part.

    >>> rule = Tolerance(rtol=0.027, reason="rounding T and T′ to 4 figures moves loss_pct by up to 1.3 %")
    >>> found = widening([(Tolerance(), 18), (rule, 2), (Tolerance(rtol=0.02, reason="..."), 10)])
    >>> found.describe("student"), found.widest.reason[:8]
    ('widened for 12 of 30 students, up to ±2.7 %', 'rounding')
    >>> widening([(Tolerance(), 30)]) is None
    True
    """

    variants: int
    of: int
    widest: Tolerance

    def describe(self, noun: str = "variant", unit: str = "") -> str:
        """In words: ``widened for 12 of 30 students, up to ±2.7 %``."""
        counted = f"{self.variants:,} of {self.of:,} {noun}" + ("" if self.of == 1 else "s")
        return f"widened for {counted}, up to {self.widest.describe(unit)}"


def widening(counted: Iterable[tuple[Tolerance, int]]) -> Widening | None:
    """The :class:`Widening` of a part whose variants have these tolerances (each with how many variants
    have it), or None when none is widened (none has a reason). The widest is the one with the largest
    ``rtol``, then ``atol``."""
    total, widened, widest = 0, 0, None
    for tolerance, count in counted:
        total += count
        if tolerance.reason:
            widened += count
            if widest is None or (tolerance.rtol, tolerance.atol) > (widest.rtol, widest.atol):
                widest = tolerance
    return None if widest is None else Widening(widened, total, widest)


def with_unit(text: str, unit: str) -> str:
    """A number's text with its unit: ``6.26 m/s``, ``30°``."""
    if unit in ("deg", "degree", "degrees", "°"):
        return f"{text}°"
    return f"{text} {unit}" if unit else text


def _plain(value: float) -> str:
    """A tolerance figure without float noise: ``0.07*100`` prints as ``7``."""
    mantissa, _, power = f"{value + 0.0:.12g}".partition("e")
    return f"{mantissa}e{int(power)}" if power else mantissa
