"""Deadlines and late work: an assignment's due time in its zone, per-student extensions, and the late
policy (Canvas' late policies, with Gradescope's grace and late due date), read from the assignment and
written into the key, where grading reads them back with the same rules.

The policy, as an assignment writes it::

    due: "2026-12-04 23:59"
    timezone: America/Chicago
    late: {grace: "15 min", deduct: "10 %", per: day, lowest: "40 %", after: "7 days"}

A submission is late by its timestamp minus its due time. Within ``grace`` it is on time; otherwise it is
late by a number of ``per`` intervals, a partial interval counted whole (as Canvas counts), and loses
``deduct`` of the points possible per interval, never below ``lowest`` of the points possible (a score
already below it loses nothing); past ``after`` it earns no credit.

>>> policy = late_from({"deduct": "10 %", "lowest": "40 %", "after": "7 days"}, "a.yaml")
>>> policy.intervals(timedelta(days=1, minutes=1)), policy.deduct * policy.intervals(timedelta(days=1, minutes=1))
(2, Fraction(1, 5))
>>> late_from({"deduct": "10 %", "per": "week"}, "a.yaml")
Traceback (most recent call last):
...
grader.base.errors.TemplateError: a.yaml: late.per: expected day or hour, got 'week'
"""

from __future__ import annotations

import difflib
import math
import re
import zoneinfo
from collections.abc import Mapping
from dataclasses import dataclass
from datetime import datetime, timedelta
from decimal import Decimal
from fractions import Fraction
from functools import lru_cache
from typing import Any

from grader.base.errors import TemplateError, refuse_unknown_fields, shown

DEFAULT_ZONE = "UTC"
PER = {"day": timedelta(days=1), "hour": timedelta(hours=1)}
LATE_FIELDS = {"grace": 'a duration such as "15 min" (on time within it; default none)',
               "deduct": 'a percentage such as "10 %" of the points possible, per interval late',
               "per": "day or hour (the interval; default day)",
               "lowest": 'a percentage such as "40 %" of the points possible (default "0 %")',
               "after": 'a duration such as "7 days" past which late work earns nothing (default never)'}
"""The fields of ``late`` (in an assignment, and in the key that copies it) and what each takes."""

_DURATION = re.compile(r"(?P<number>\d+(?:\.\d+)?)\s*(?P<unit>[a-z]+)", re.I)
_UNITS = {"s": 1, "sec": 1, "second": 1, "min": 60, "minute": 60, "h": 3600, "hr": 3600, "hour": 3600,
          "d": 86400, "day": 86400, "week": 604800}
_PERCENT = re.compile(r"(?P<number>\d+(?:\.\d+)?)\s*%")
_RELATIVE = re.compile(r"\+\s*(?P<rest>.+)")
_DATE = re.compile(r"\d{4}-\d{2}-\d{2}")


@dataclass(frozen=True)
class LatePolicy:
    """How late work is credited: ``grace`` (on time within it), ``deduct`` (a fraction of the points
    possible per ``per`` interval late), ``lowest`` (the fraction of the points possible below which no
    deduction takes a score), ``after`` (no credit past it; None: never)."""

    deduct: Fraction
    grace: timedelta = timedelta(0)
    per: str = "day"
    lowest: Fraction = Fraction(0)
    after: timedelta | None = None

    def intervals(self, late_by: timedelta) -> int:
        """The intervals late: 0 within the grace, else the lateness in ``per`` intervals, a partial one
        counted whole.

        >>> policy = LatePolicy(Fraction(1, 10), grace=timedelta(minutes=15))
        >>> [policy.intervals(timedelta(minutes=m)) for m in (0, 15, 16, 1440, 1441)]
        [0, 0, 1, 1, 2]
        """
        if late_by <= self.grace:
            return 0
        return math.ceil(late_by / PER[self.per])

    def closed(self, late_by: timedelta) -> bool:
        """Whether work this late earns no credit (past ``after``)."""
        return self.after is not None and late_by > self.after

    def to_json(self) -> dict[str, str]:
        """The policy as an assignment writes it, which :func:`late_from` reads back."""
        data = {"grace": _duration_text(self.grace), "deduct": _percent_text(self.deduct), "per": self.per,
                "lowest": _percent_text(self.lowest)}
        if self.after is not None:
            data["after"] = _duration_text(self.after)
        return data


def late_from(raw: Any, where: str, field: str = "late") -> LatePolicy:
    """The ``late`` mapping of an assignment (or, as ``field``, of a key), checked: an unknown field is
    refused with the nearest known one, a value that does not read with what it takes."""
    if not isinstance(raw, Mapping):
        raise TemplateError(where, field, "a mapping {" + ", ".join(LATE_FIELDS) + "}", shown(raw))
    refuse_unknown_fields(raw, LATE_FIELDS, where, field)
    if "deduct" not in raw:
        raise TemplateError(where, f"{field}.deduct", LATE_FIELDS["deduct"], "none")
    per = raw.get("per", "day")
    if per not in PER:
        raise TemplateError(where, f"{field}.per", "day or hour", shown(per))
    after = None if raw.get("after") is None else _duration(raw["after"], where, f"{field}.after")
    policy = LatePolicy(_percent(raw["deduct"], where, f"{field}.deduct"),
                        _duration(raw.get("grace", "0 min"), where, f"{field}.grace"), per,
                        _percent(raw.get("lowest", "0 %"), where, f"{field}.lowest"), after)
    if after is not None and after < policy.grace:
        raise TemplateError(where, f"{field}.after", f"a duration no shorter than the grace "
                            f"({_duration_text(policy.grace)})", shown(raw["after"]))
    return policy


def duration(text: str) -> timedelta | None:
    """A duration as people write one (``15 min``, ``7 days``, ``2 hours 30 min``), or None.

    >>> duration("2 hours 30 min"), duration("7 days"), duration("soon")
    (datetime.timedelta(seconds=9000), datetime.timedelta(days=7), None)
    """
    text = text.strip()
    pieces = list(_DURATION.finditer(text))
    if not pieces or "".join(p.group(0) for p in pieces).replace(" ", "") != text.replace(" ", ""):
        return None
    seconds = Fraction(0)
    for piece in pieces:
        unit = piece["unit"].lower()
        unit = unit[:-1] if unit.endswith("s") and unit[:-1] in _UNITS else unit
        if unit not in _UNITS:
            return None
        seconds += Fraction(piece["number"]) * _UNITS[unit]
    return timedelta(microseconds=round(seconds * 10**6)) if seconds < 10**9 else None  # 30 years: beyond any term


def _duration(value: Any, where: str, field: str) -> timedelta:
    found = duration(value) if isinstance(value, str) else None
    if found is None:
        raise TemplateError(where, field, 'a duration such as "15 min", "2 hours" or "7 days"', shown(value))
    return found


def _percent(value: Any, where: str, field: str) -> Fraction:
    match = _PERCENT.fullmatch(value.strip()) if isinstance(value, str) else None
    if match is None or Fraction(match["number"]) > 100:
        raise TemplateError(where, field, 'a percentage from "0 %" to "100 %" (of the points possible)',
                            shown(value))
    return Fraction(match["number"]) / 100


def _percent_text(value: Fraction) -> str:
    """A percentage written back exactly (it was read from a decimal, so it ends).

    >>> _percent_text(Fraction("0.3333333")), _percent_text(Fraction(1, 10))
    ('33.33333 %', '10 %')
    """
    percent = Decimal(value.numerator * 100) / Decimal(value.denominator)
    return f"{percent.normalize():f} %"


def _duration_text(value: timedelta) -> str:
    """A duration written back exactly, in the largest unit that divides it.

    >>> _duration_text(timedelta(days=7)), _duration_text(timedelta(minutes=90)), _duration_text(timedelta(0))
    ('7 days', '90 min', '0 min')
    """
    microseconds = value // timedelta(microseconds=1)
    for name, size in (("days", 86400), ("hours", 3600), ("min", 60)) if microseconds else (("min", 60),):
        if microseconds % (size * 10**6) == 0:
            return f"{microseconds // (size * 10**6)} {name}"
    return f"{Decimal(microseconds).scaleb(-6).normalize():f} s"


@lru_cache(maxsize=64)
def zone(name: str) -> zoneinfo.ZoneInfo:
    """The IANA zone ``name`` (``America/Chicago``); raises ``KeyError`` when there is none."""
    try:
        return zoneinfo.ZoneInfo(name)
    except (ValueError, zoneinfo.ZoneInfoNotFoundError):
        raise KeyError(name) from None


def zone_from(value: Any, where: str, field: str = "timezone") -> zoneinfo.ZoneInfo:
    """An assignment's (or a key's) ``timezone``, checked: an unknown zone is refused with the nearest."""
    try:
        if isinstance(value, str):
            return zone(value.strip())
    except KeyError:
        pass
    close = difflib.get_close_matches(str(value), sorted(zoneinfo.available_timezones()), n=1, cutoff=0.6)
    hint = f" (did you mean {close[0]}?)" if close else ""
    raise TemplateError(where, field, f"an IANA time zone such as America/Chicago or UTC{hint}", shown(value))


def local_time(text: str, where_zone: zoneinfo.ZoneInfo) -> datetime | None:
    """A date-time as a due date is written (``2026-12-04 23:59``, ISO 8601, with or without seconds or an
    offset; a date alone is due at 23:59, Canvas' default), in ``where_zone`` when it gives no offset; None
    when ``text`` is no date-time.

    >>> local_time("2026-12-04", zone("America/Chicago")).isoformat()
    '2026-12-04T23:59:00-06:00'
    >>> local_time("Friday", zone("UTC")) is None
    True
    """
    text = text.strip()
    if not _DATE.match(text):
        return None
    try:
        when = datetime.fromisoformat(text)
    except ValueError:
        return None
    if len(text) == 10:
        when = when.replace(hour=23, minute=59)
    return when if when.tzinfo is not None else when.replace(tzinfo=where_zone)


def extension(text: str) -> timedelta | str | None:
    """A roster's ``due`` cell read: a duration after the assignment's due time (``+2 days``), the text of
    a date-time (checked: it reads), or None when empty; raises ``ValueError`` when it is neither."""
    text = text.strip()
    if not text:
        return None
    relative = _RELATIVE.fullmatch(text)
    if relative:
        later = duration(relative["rest"])
        if later is None:
            raise ValueError(f"{shown(text)} is not a duration after the due time such as +2 days")
        return later
    if local_time(text, zoneinfo.ZoneInfo("UTC")) is None:
        raise ValueError(f"{shown(text)} is neither a date-time such as 2026-12-06 23:59 nor a delay such as "
                         "+2 days")
    return text


def student_due(text: str, due: datetime | None, where_zone: zoneinfo.ZoneInfo) -> datetime | None:
    """A student's due time: their roster ``due`` (a date-time in the assignment's zone, or a delay after
    ``due``), or None when they have none; raises ``ValueError`` for a delay without a due time."""
    found = extension(text)
    if found is None:
        return None
    if isinstance(found, timedelta):
        if due is None:
            raise ValueError(f"{shown(text.strip())} is a delay, but the assignment's due is no date-time")
        return due + found
    return local_time(found, where_zone)
