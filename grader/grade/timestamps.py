"""Submission timestamps as LMSs and forms write them: ISO 8601 (``2026-12-04 23:59:07``,
``2026-12-04T23:59:07Z``, ``... UTC``, Canvas' reports), Google Forms' and Microsoft Forms' (Excel's)
``12/4/2026 23:59:07`` (month first, optional ``AM``/``PM``; a two-digit year is refused, as ambiguous), and
the dates Canvas shows (``Dec 4, 2026 11:59pm``, ``Dec 4, 2026 at 11:59 PM``), each with or without a zone;
a time without a zone is in the assignment's zone (the grader reads it so: :func:`in_zone`).

>>> read_timestamp("12/4/2026 11:59:07 PM"), read_timestamp("2026-12-04T23:59:07Z")
(datetime.datetime(2026, 12, 4, 23, 59, 7), datetime.datetime(2026, 12, 4, 23, 59, 7, tzinfo=datetime.timezone.utc))
>>> read_timestamp("Dec 4, 2026 at 11:59pm"), read_timestamp("December 4 2026 23:59 -0600").isoformat()
(datetime.datetime(2026, 12, 4, 23, 59), '2026-12-04T23:59:00-06:00')
"""

from __future__ import annotations

import re
from datetime import UTC, datetime, timedelta, timezone, tzinfo

from grader.base.errors import shown

_ZONE = r"(?:\s*(?P<zone>Z|UTC|GMT|(?:UTC|GMT)?\s*(?P<sign>[+-])(?P<zh>\d{1,2})(?::?(?P<zm>\d{2}))?))?"
_ISO = re.compile(r"(?P<base>\d{4}-\d{2}-\d{2}(?:[T ]\d{1,2}:\d{2}(?::\d{2}(?:[.,]\d+)?)?)?)" + _ZONE, re.I)
_CLOCK = r"(?P<hour>\d{1,2}):(?P<minute>\d{2})(?::(?P<second>\d{2})(?:\.\d+)?)?(?:\s*(?P<half>AM|PM))?"
_FORMS = re.compile(r"(?P<month>\d{1,2})/(?P<day>\d{1,2})/(?P<year>\d{4})(?:[T ]+" + _CLOCK + ")?" + _ZONE, re.I)
_MONTHS = ("jan", "feb", "mar", "apr", "may", "jun", "jul", "aug", "sep", "oct", "nov", "dec")
_NAMED = re.compile(r"(?P<name>[a-z]{3})[a-z]*\.?\s+(?P<day>\d{1,2}),?\s+(?P<year>\d{4})(?:,?\s+(?:at\s+)?"
                    + _CLOCK + ")?" + _ZONE, re.I)


def read_timestamp(text: str) -> datetime | str | None:
    """A timestamp cell read: the time, ``None`` when empty, or why it does not read (a caveat)."""
    text = text.strip()
    if not text:
        return None
    try:
        iso, forms, named = _ISO.fullmatch(text), _FORMS.fullmatch(text), _NAMED.fullmatch(text)
        if iso:
            return _zoned(datetime.fromisoformat(iso["base"].replace(",", ".")), iso)
        if forms:
            return _zoned(_clock(forms, int(forms["year"]), int(forms["month"])), forms)
        if named and named["name"].lower() in _MONTHS:
            return _zoned(_clock(named, int(named["year"]), _MONTHS.index(named["name"].lower()) + 1), named)
        raise ValueError(text)
    except (ValueError, OverflowError):
        return (f"timestamp {shown(text)} not understood (expected ISO 8601 like 2026-12-04 23:59:07, "
                "12/4/2026 23:59:07 or Dec 4, 2026 11:59pm); the row is taken as having none, so how late it "
                "was is not known")


def _clock(match: re.Match[str], year: int, month: int) -> datetime:
    """The date and time of a match of the month-first or named-month forms."""
    hour = int(match["hour"] or 0)
    if match["half"]:
        hour = hour % 12 + (12 if match["half"].upper() == "PM" else 0)
    return datetime(year, month, int(match["day"]), hour, int(match["minute"] or 0), int(match["second"] or 0))


def _zoned(when: datetime, match: re.Match[str] | None) -> datetime:
    if match is None or match["zone"] is None:
        return when
    if match["sign"] is None:
        return when.replace(tzinfo=UTC)
    offset = timedelta(hours=int(match["zh"]), minutes=int(match["zm"] or 0))
    return when.replace(tzinfo=timezone(-offset if match["sign"] == "-" else offset))


def in_zone(when: datetime, zone: tzinfo) -> datetime:
    """``when`` as an instant: a time without a zone is in ``zone`` (the assignment's)."""
    return when if when.tzinfo is not None else when.replace(tzinfo=zone)


def instant(when: datetime | None) -> datetime:
    """``when`` comparable with any other: without a zone, taken as UTC."""
    when = when or datetime.min
    return when if when.tzinfo is not None else when.replace(tzinfo=UTC)


def clock() -> datetime:
    """The run's own time, in UTC: a timestamp after it is a caveat. (One place to read the clock: the test
    suite, whose files are stamped in December 2026, sets it.)"""
    return datetime.now(UTC)
