"""Submission timestamps as LMSs and Google Forms write them: ISO 8601 (``2026-12-04 23:59:07``,
``2026-12-04T23:59:07Z``, ``... UTC``) and Google Forms' ``12/4/2026 23:59:07`` (month first, optional
``AM``/``PM``), each with or without a zone; times without a zone are compared as UTC.

>>> read_timestamp("12/4/2026 11:59:07 PM"), read_timestamp("2026-12-04T23:59:07Z")
(datetime.datetime(2026, 12, 4, 23, 59, 7), datetime.datetime(2026, 12, 4, 23, 59, 7, tzinfo=datetime.timezone.utc))
"""

from __future__ import annotations

import re
from datetime import UTC, datetime, timedelta, timezone

from grader.base.errors import shown

_ZONE = r"(?:\s*(?P<zone>Z|UTC|GMT|(?:UTC|GMT)?\s*(?P<sign>[+-])(?P<zh>\d{1,2})(?::?(?P<zm>\d{2}))?))?"
_ISO = re.compile(r"(?P<base>\d{4}-\d{2}-\d{2}(?:[T ]\d{1,2}:\d{2}(?::\d{2}(?:[.,]\d+)?)?)?)" + _ZONE, re.I)
_FORMS = re.compile(r"(?P<month>\d{1,2})/(?P<day>\d{1,2})/(?P<year>\d{4})(?:[T ]+(?P<hour>\d{1,2}):(?P<minute>\d{2})"
                    r"(?::(?P<second>\d{2})(?:\.\d+)?)?(?:\s*(?P<half>AM|PM))?)?" + _ZONE, re.I)


def read_timestamp(text: str) -> datetime | str | None:
    """A timestamp cell read: the time, ``None`` when empty, or why it does not read (a caveat)."""
    text = text.strip()
    if not text:
        return None
    try:
        iso, forms = _ISO.fullmatch(text), _FORMS.fullmatch(text)
        if iso:
            when = datetime.fromisoformat(iso["base"].replace(",", "."))
        elif forms:
            hour = int(forms["hour"] or 0)
            if forms["half"]:
                hour = hour % 12 + (12 if forms["half"].upper() == "PM" else 0)
            when = datetime(int(forms["year"]), int(forms["month"]), int(forms["day"]), hour,
                            int(forms["minute"] or 0), int(forms["second"] or 0))
        else:
            raise ValueError(text)
        return _zoned(when, iso or forms)
    except (ValueError, OverflowError):
        return (f"timestamp {shown(text)} not understood (expected ISO 8601 like 2026-12-04 23:59:07 or "
                "12/4/2026 23:59:07); the row is taken as having none")


def _zoned(when: datetime, match: re.Match[str] | None) -> datetime:
    if match is None or match["zone"] is None:
        return when
    if match["sign"] is None:
        return when.replace(tzinfo=UTC)
    offset = timedelta(hours=int(match["zh"]), minutes=int(match["zm"] or 0))
    return when.replace(tzinfo=timezone(-offset if match["sign"] == "-" else offset))


def instant(when: datetime | None) -> datetime:
    """``when`` comparable with any other: without a zone, taken as UTC."""
    when = when or datetime.min
    return when if when.tzinfo is not None else when.replace(tzinfo=UTC)


def clock() -> datetime:
    """The run's own time, in UTC: a timestamp after it is a caveat. (One place to read the clock: the test
    suite, whose files are stamped in December 2026, sets it.)"""
    return datetime.now(UTC)
