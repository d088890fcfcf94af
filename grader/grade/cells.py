"""What a student typed in one cell, as a value: a number in the expected unit, or an expression.

Student text is never run. Numbers are read by regular expressions; arithmetic and symbolic answers
by our own tokenizer (which writes out the multiplications students leave implicit) and then
:func:`grader.model.expr.parse` (Python's ``ast`` with an allow-list); units by
:mod:`grader.model.quantities.units` (the templates' grammar and table, with the words students type).

>>> read_number("6.26 m/s", "m/s")
CellNumber(value=6.26, unit_given='m/s')
>>> read_number("v_pile = 6,26", "m/s", delimiter=";", names=["v_pile"])
CellNumber(value=6.26, unit_given=None)
>>> read_number("1,234", "m")
CellInvalid(reason="'1,234' could be 1234 or 1.234; write it without the comma")
>>> read_number("12 kg", "m/s")
CellWrongUnit(reason='expected a speed (m/s), got a mass (kg)')
>>> read_expression("v(1 - 0.1p)", ["p", "v"]).text
'v*(1 - 0.1*p)'
>>> read_expression("2m", ["p", "v"])
CellInvalid(reason='unknown name m; use p and v')
"""

from __future__ import annotations

import functools
import math
import re
from collections.abc import Sequence
from dataclasses import dataclass

from grader.base.inputs import CELL_CHARS
from grader.grade.notation import ReadError, check_powers, cut, listed, tree_of, uses_a_name, value_of
from grader.model.expr import Node, to_text
from grader.model.quantities import MAX_POWER, UnitMismatchError, UnknownUnitError, unit_factor, unit_factors


@dataclass(frozen=True)
class CellBlank:
    """Nothing typed (empty or only spaces)."""


@dataclass(frozen=True)
class CellInvalid:
    """Text that cannot be read; ``reason`` is for the student."""

    reason: str


@dataclass(frozen=True)
class CellWrongUnit:
    """A number with a unit of another dimension than the answer's."""

    reason: str


@dataclass(frozen=True)
class CellNumber:
    """A finite number in the answer's unit; ``unit_given`` is the unit text the student typed (None: none)."""

    value: float
    unit_given: str | None


@dataclass(frozen=True)
class CellExpression:
    """A symbolic answer and its normalised text."""

    tree: Node
    text: str


_NONZERO_DIGIT = re.compile("[1-9]")
_SPACES = str.maketrans({"\u00a0": " ", "\u2009": " ", "\u202f": " ", "\u2007": " ", "\t": " ", "\n": " ",
                         "\r": " ", "\u2212": "-", "\u200b": None, "\ufeff": None})
_SUPERSCRIPTS = str.maketrans("⁰¹²³⁴⁵⁶⁷⁸⁹⁻⁺", "0123456789-+")
_SUPERSCRIPT_RUN = re.compile("[⁰¹²³⁴⁵⁶⁷⁸⁹⁻⁺]+")
_UNDEFINED = frozenset({"", "undefined", "none", "n/a", "-", "no direction"})

_NUM = r"(?>\d+(?:\.\d*)?|\.\d+)"  # atomic: no backtracking on long runs of digits
# A plain decimal as most answers are typed: no spaces, unit, exponent or comma, digits few enough to be finite.
_DECIMAL = re.compile(r"-?[0-9]{1,15}(?:\.[0-9]{1,15})?")
_PLAIN = re.compile(rf"(?P<sign>[-+]?)\s*(?P<digits>{_NUM}(?>[eE][-+]?\d+)?)")
_SCIENTIFIC = re.compile(rf"(?P<sign>[-+]?)\s*(?P<mantissa>{_NUM})\s*[×xX*·]\s*10\s*(?:\^|\*\*)\s*"
                         r"(?P<open>\(?)\s*(?P<exponent>[-+]?\d+)\s*(?P<close>\)?)")
_FRACTION = re.compile(rf"(?P<sign>[-+]?)\s*(?P<top>{_NUM})\s*/\s*(?P<bottom>{_NUM})")
_TWO_NUMBERS = re.compile(rf"{_NUM}(?:\s*(?:[,;–]|\bor\b|\band\b|\bto\b)\s*|\s+){_NUM}", re.IGNORECASE)
_GROUPED = re.compile(r"(?<![\d.,])\d{1,3}(?: \d{3})+(?!\d)")
_COMMA_NUMBER = re.compile(r"(?<![\w.,])(?P<groups>\d+(?:,\d+)+)(?P<fraction>\.\d*)?(?![\d,])")
_CALL = re.compile(r"[A-Za-z_]\w*\s*\(")
_DEGREES_MINUTES = re.compile(rf"(?P<sign>[-+]?)\s*(?P<degrees>{_NUM})\s*°\s*(?P<minutes>{_NUM})\s*['′’]"
                              rf"(?:\s*(?P<seconds>{_NUM})\s*(?:\"|″|''|′′|”))?")
_POWERED_WORD = re.compile(r"(?<=[\d.)\s])(?P<word>[A-Za-zµμ]+)\s*(?:\^|\*\*)\s*(?P<power>[-+]?\d+)$")
_ASSIGNMENT = re.compile(r"(?P<word>[A-Za-z_][\w']*)\s*=")
_NUMBER_UNIT = re.compile(r"-?[0-9]{1,15}(?:\.[0-9]{1,15})? ?(?P<unit>[A-Za-z%°][A-Za-z%°/·]*)")
_WHOLE = 41  # a text this long or shorter is looked at whole for where its unit starts


def read_number(text: str, unit: str, *, delimiter: str = ",", numeric_expressions: bool = True,
                names: Sequence[str] = ()) -> CellBlank | CellInvalid | CellWrongUnit | CellNumber:
    """Read a numeric answer and convert it into ``unit``, the answer's unit as printed on the sheet.

    ``delimiter`` is the CSV file's: a decimal comma is read in a ``;`` or tab file, and in a comma file
    wherever it cannot be a thousands separator. ``names`` are the answer's name and label, so that
    ``v_pile = 6.26`` reads as 6.26. Arithmetic is evaluated unless ``numeric_expressions`` is False.

    >>> read_number("≈ 6.26×10^3", "m").value, round(read_number("sqrt(2*9.81*2)", "m/s").value, 4)
    (6260.0, 6.2642)
    >>> read_number("30°", "rad").value == math.pi / 6, read_number("50 %", "").value
    (True, 0.5)
    >>> read_number("6.2 or 6.3", "m")
    CellInvalid(reason='two numbers (6.2 or 6.3); give one answer')
    """
    if _DECIMAL.fullmatch(text):  # the usual answer (6.26, -0.369): what the steps below read it as, at once
        return CellNumber(float(text) + 0.0, None)
    return _read_number(text, unit, delimiter, numeric_expressions, names)


def _read_number(text: str, unit: str, delimiter: str, numeric_expressions: bool,
                 names: Sequence[str]) -> CellBlank | CellInvalid | CellWrongUnit | CellNumber:
    """:func:`read_number`, every step (the usual number and unit, ``9.9 cm/s``, told apart at once)."""
    try:
        found = _usual_split(text) or _split(text, unit, names)
        if not isinstance(found, tuple):
            return found
        number_text, unit_text = found
        value = _readvalue_of(number_text, delimiter, numeric_expressions)
        if unit_text:
            value *= unit_factor(unit_text, unit)
            if not math.isfinite(value):
                raise ReadError(f"{cut(number_text, 40)} {unit_text} is too large a number in {unit or 'units'}")
    except (ReadError, UnknownUnitError) as problem:
        return CellInvalid(str(problem))
    except UnitMismatchError as problem:
        return CellWrongUnit(str(problem))
    return CellNumber(value + 0.0, unit_text or None)


def _split(text: str, unit: str, names: Sequence[str]) -> tuple[str, str] | CellBlank | CellInvalid | CellNumber:
    """The number and the unit typed (:func:`_split_unit`) after the text is cleaned and any ``NAME =`` taken
    off; or what the cell is without them (blank, unreadable, degrees and minutes). Raises ReadError,
    UnknownUnitError or UnitMismatchError where the text says why it is not a number."""
    cleaned = _clean(text)
    if not isinstance(cleaned, str):
        return cleaned
    cleaned = _without_prefix(cleaned, names)
    _refuse_formula(cleaned, names)
    if angle := _DEGREES_MINUTES.fullmatch(cleaned):
        return CellNumber(_degrees(angle) * unit_factor("deg", unit) + 0.0, "°")
    return _split_unit(cleaned)


def _usual_split(text: str) -> tuple[str, str] | None:
    """:func:`_split` of the usual number and unit (``9.9 cm/s``, ``-12.5 %``), without its steps; None for any
    other text. Such a text is a plain decimal, one space or none, and a unit of letters, ``/``, ``·``, ``%`` and
    ``°`` (no digit, space, power or quote): cleaning leaves it as it is, it has no ``=`` for a name before it
    and no minutes, and :func:`_split_unit`, which looks at the whole of a text this short, splits it where
    the unit starts when the rest is a unit (else it looks on: that text takes every step).

    >>> _usual_split("9.9 cm/s"), _usual_split("-12.5%"), _usual_split("2 e"), _usual_split("1.5e3 m")
    (('9.9', 'cm/s'), ('-12.5', '%'), None, None)
    """
    match = _NUMBER_UNIT.fullmatch(text) if len(text) <= _WHOLE else None
    if match is None or not _is_unit(match["unit"]):
        return None
    return text[:match.start("unit")].rstrip(), match["unit"]


@functools.lru_cache(maxsize=1024)
def _is_unit(text: str) -> bool:
    """Whether ``text`` reads as a unit (a class types a few)."""
    return unit_factors(text) is not None


def read_expression(text: str, symbols: Sequence[str], *,
                    delimiter: str = ",") -> CellBlank | CellInvalid | CellExpression:
    """Read a symbolic answer in ``symbols``: implicit products (``2v``, ``v(1 + p)``), ``^`` or ``**``,
    the functions of :data:`grader.model.expr.FUNCTIONS`. Decimal commas are refused whatever the
    file's ``delimiter`` (a comma separates a function's arguments).

    >>> read_expression("(1+p)(1-p) v^2", ["p", "v"]).text
    '(1 + p)*(1 - p)*v**2'
    >>> read_expression("0.5", ["p", "v"])
    CellInvalid(reason='a number; expected an expression in p and v')
    """
    cleaned = _clean(text)
    if not isinstance(cleaned, str):
        return cleaned
    try:
        _refuse_formula(cleaned, ())
        tree = tree_of(cleaned, tuple(symbols))
        if not uses_a_name(tree):
            raise ReadError(f"a number; expected an expression in {listed(symbols)}")
        text = to_text(tree)
        if "**" in text:  # only a power prints as '**': most answers have none to check
            check_powers(tree)
    except ReadError as problem:
        return CellInvalid(str(problem))
    return CellExpression(tree, text)


def undefined_word(text: str) -> bool:
    """Whether a cell says "no value": blank, ``undefined``, ``none``, ``n/a``, ``-``, ``no direction``.

    >>> undefined_word(" N/A "), undefined_word("No  direction"), undefined_word("0")
    (True, True, False)
    """
    if len(text) > 100:
        return False
    return " ".join(text.translate(_SPACES).split()).lower() in _UNDEFINED


def _clean(text: str) -> str | CellBlank | CellInvalid:
    """Length checked first, spaces and minus signs unified, control characters refused, superscript
    powers written out (``10⁻³`` is ``10^-3``)."""
    if len(text) > CELL_CHARS:
        return CellInvalid(f"{len(text):,} characters; an answer has at most {CELL_CHARS:,}")
    text = text.translate(_SPACES)
    if not text.isprintable():
        text = "".join(" " if char.isspace() else char for char in text)
        bad = next((char for char in text if not char.isprintable() and char != " "), None)
        if bad is not None:
            return CellInvalid(f"contains an invisible control character (U+{ord(bad):04X}); type the answer again")
    text = text.strip()
    if not text:
        return CellBlank()
    return _SUPERSCRIPT_RUN.sub(lambda run: "^" + run.group().translate(_SUPERSCRIPTS), text)


def _without_prefix(text: str, names: Sequence[str]) -> str:
    """Drop a leading ``NAME =`` (the answer's name or label) and ``≈`` or ``~``."""
    lowered = text.lower()
    for name in names:
        if name and lowered.startswith(name.lower()):
            rest = text[len(name):].lstrip()
            if rest[:1] in ("=", "≈"):
                text = rest[1:]
                break
    return text.lstrip(" ≈~")


def _refuse_formula(text: str, names: Sequence[str]) -> None:
    if not text:
        raise ReadError("no value after the '='")
    if text[0] in "=@":
        raise ReadError(f"starts with '{text[0]}' like a spreadsheet formula; type the value itself")
    assignment = _ASSIGNMENT.match(text)
    if assignment:
        shown_name = next(filter(None, names), "")  # grader check's part has no name, only its label
        hint = f" (or write {shown_name} = ...)" if shown_name else ""
        raise ReadError(f"starts with '{assignment['word']} ='; give only the value{hint}")


def _split_unit(text: str) -> tuple[str, str]:
    """The number and the unit after it: the first word from which the rest is a unit, after a number."""
    _powered_unit(text[-60:])
    for start in range(max(1, len(text) + 1 - _WHOLE), len(text)):
        char, before = text[start], text[start - 1]
        if not (char.isalpha() or char in "°%") or before.isalpha() or before == "_":
            continue
        head = text[:start].rstrip()
        if head and (head[-1].isdigit() or head[-1] in ".)") and unit_factors(text[start:]) is not None:
            return head, text[start:].strip()
    return text, ""


def _degrees(angle: re.Match[str]) -> float:
    """``55°30'`` (and ``55°30'15"``) in degrees; minutes and seconds below 60."""
    minutes, seconds = float(angle["minutes"]), float(angle["seconds"] or 0)
    if minutes >= 60 or seconds >= 60:
        raise ReadError(f"{angle.group()}: minutes and seconds of an angle are below 60")
    degrees = float(angle["degrees"]) + minutes / 60 + seconds / 3600
    return -degrees if angle["sign"] == "-" else degrees


def _powered_unit(text: str) -> None:
    """Refuse, saying why, a unit with a power beyond :data:`MAX_POWER` (``1.66 m^99999``)."""
    powered = _POWERED_WORD.search(text)
    if powered and abs(int(powered["power"])) > MAX_POWER and unit_factors(powered["word"]) is not None:
        raise ReadError(f"the power {cut(powered['power'], 12)} of the unit {powered['word']} is beyond the limit: "
                        f"units are read with powers up to {MAX_POWER}")


def _readvalue_of(text: str, delimiter: str, numeric_expressions: bool) -> float:
    text = _GROUPED.sub(lambda group: group.group().replace(" ", ""), text)
    text = _decimal_commas(text, delimiter)
    if plain := _PLAIN.fullmatch(text):
        return _finite(float(plain["sign"] + plain["digits"]), text)
    if (scientific := _SCIENTIFIC.fullmatch(text)) and bool(scientific["open"]) == bool(scientific["close"]):
        return _finite(float(f"{scientific['sign']}{scientific['mantissa']}e{scientific['exponent']}"), text)
    if fraction := _FRACTION.fullmatch(text):
        if float(fraction["bottom"]) == 0:
            raise ReadError(f"{text} divides by zero")
        return _finite(float(fraction["sign"] + "1") * float(fraction["top"]) / float(fraction["bottom"]), text)
    two = None if _CALL.search(text) else _TWO_NUMBERS.search(text)
    if two:
        raise ReadError(f"two numbers ({cut(two.group(), 40)}); give one answer")
    if not numeric_expressions:
        raise ReadError(f"cannot read '{cut(text, 40)}' as a number; give the number itself, without arithmetic")
    return value_of(tree_of(text, ()))


def _decimal_commas(text: str, delimiter: str) -> str:
    """``6,26`` is 6.26; ``1,234,567`` and ``1,234.5`` are thousands; ``1,234`` in a comma file is ambiguous.
    Commas between a function's arguments (``hypot(3, 4)``) are left alone."""
    if "," not in text or _CALL.search(text):
        return text
    pieces, end = [], 0
    for match in _COMMA_NUMBER.finditer(text):
        groups, fraction = match["groups"].split(","), match["fraction"] or ""
        thousands = len(groups[0]) <= 3 and all(len(group) == 3 for group in groups[1:])
        if fraction or len(groups) > 2:
            if not thousands:
                raise ReadError(f"cannot read '{match.group()}': commas and points do not group digits by three")
            number = "".join(groups) + fraction
        elif thousands and delimiter == "," and not groups[0].startswith("0"):
            raise ReadError(f"'{match.group()}' could be {''.join(groups)} or {'.'.join(groups)}; "
                              "write it without the comma")
        else:
            number = ".".join(groups)
        pieces += [text[end:match.start()], number]
        end = match.end()
    return "".join([*pieces, text[end:]])


def _finite(value: float, text: str) -> float:
    if not math.isfinite(value):
        raise ReadError(f"{cut(text, 40)} is too large for a number (beyond about 1.8e308)")
    if value == 0 and _NONZERO_DIGIT.search(text.lower().partition("e")[0].partition("×")[0].partition("x")[0]):
        raise ReadError(f"{cut(text, 40)} is too small for a number (below about 5e-324 it would be read as 0); "
                        "write 0 if you mean 0")
    return value


def typed_place(text: str) -> tuple[float, float] | None:
    """What a plain or scientific number as typed shows: its value (before any unit) and the place value of
    its last digit; None for anything else (arithmetic, a fraction, degrees and minutes, a name before it).
    The integrity check (:mod:`grader.grade.integrity`) reads how close an answer can claim to be from it.

    >>> typed_place("3.41 m/s"), typed_place("6.26×10^3"), typed_place("1,50"), typed_place("341")
    ((3.41, 0.01), (6260.0, 10.0), (1.5, 0.01), (341.0, 1.0))
    >>> typed_place("2.5e-3"), typed_place("sqrt(2)")
    ((0.0025, 0.0001), None)
    """
    cleaned = _clean(text)
    if not isinstance(cleaned, str):
        return None
    try:
        number = _decimal_commas(_GROUPED.sub(lambda group: group.group().replace(" ", ""),
                                              _split_unit(cleaned.lstrip(" ≈~"))[0]), ";")
    except ReadError:
        return None
    if plain := _PLAIN.fullmatch(number):
        sign, (mantissa, _, exponent) = plain["sign"], plain["digits"].lower().partition("e")
    elif scientific := _SCIENTIFIC.fullmatch(number):
        sign, mantissa, exponent = scientific["sign"], scientific["mantissa"], scientific["exponent"]
    else:
        return None
    if len(exponent) > 5:  # beyond any float's exponent
        return None
    power = int(exponent or 0) - len(mantissa.partition(".")[2])
    value = float(f"{sign}{mantissa}e{exponent or 0}")
    return (value, float(f"1e{power}")) if math.isfinite(value) else None
