"""Late work: how late each answer that counts was, and what the key's late policy deducts for it
(:mod:`grader.assign.deadlines` holds the policy and its rules; Canvas' late policies are the reference).

An answer is late by its row's timestamp minus the student's due time (their extension, else the
assignment's). Deductions are of the points possible, per part: a part late by ``k`` intervals loses
``deduct × k`` of its points, a part past ``after`` all it scored; the student's late deductions together
never take their score below ``lowest`` of their points possible (a score already below it loses nothing),
so that when every part came in one submission the deduction is Canvas' (``deduct × k`` of the points
possible, floored). Where the floor holds the deduction back, each late part's share is cut in proportion.

>>> from grader.assign.deadlines import LatePolicy
>>> late = intervals(LatePolicy(Fraction(1, 10)), timedelta(days=1, minutes=1))  # two days: 20 % of 20 points
>>> deductions(LatePolicy(Fraction(1, 10)), ((10.0, 10.0, late), (6.0, 10.0, late)))
(Fraction(4, 1), (Fraction(2, 1), Fraction(2, 1)))
>>> deductions(LatePolicy(Fraction(1, 10), lowest=Fraction(2, 5)), ((9.0, 10.0, late), (0.0, 10.0, late)))
(Fraction(1, 1), (Fraction(1, 2), Fraction(1, 2)))

(9 of 20 would lose 4; the floor, 40 % of 20, holds it at 8.)
"""

from __future__ import annotations

import math
from datetime import datetime, timedelta
from fractions import Fraction
from functools import lru_cache

from grader.assign.deadlines import LatePolicy

CLOSED = -1
"""The intervals of an answer past the policy's ``after``: it earns nothing."""


def late_by(stamp: datetime | None, due: datetime | None) -> timedelta | None:
    """How late a row stamped ``stamp`` (aware) is for ``due``: none before it; None when either is unknown."""
    if stamp is None or due is None:
        return None
    return max(stamp - due, timedelta(0))


def minutes(late: timedelta | None) -> int | None:
    """Lateness in whole minutes, a partial minute counted whole (a second late is a minute late)."""
    return None if late is None else math.ceil(late / timedelta(minutes=1))


def intervals(policy: LatePolicy, late: timedelta | None) -> int:
    """The intervals an answer ``late`` by so much is charged for: 0 when on time (or not known),
    :data:`CLOSED` past ``after``."""
    if late is None:
        return 0
    return CLOSED if policy.closed(late) else policy.intervals(late)


def part_deduction(policy: LatePolicy, score: float, points: float, charged: int) -> Fraction:
    """What a part of ``points`` scoring ``score``, charged for ``charged`` intervals, loses before the
    floor: all it scored when :data:`CLOSED`, else ``deduct`` of its points per interval (used as is to
    compare a student's attempts at one part)."""
    if charged == CLOSED:
        return Fraction(score)
    return policy.deduct * charged * Fraction(points)


@lru_cache(maxsize=4096)  # a class's students repeat a few patterns of scores and intervals
def deductions(policy: LatePolicy, parts: tuple[tuple[float, float, int], ...]) -> tuple[
        Fraction, tuple[Fraction, ...]]:
    """A student's deduction and each part's share, for ``parts`` of (score, points, intervals charged)."""
    possible = sum(Fraction(points) for _, points, _ in parts)
    kept = sum(Fraction(score) for score, _, charged in parts if charged != CLOSED)
    wanted = [Fraction(0) if charged == CLOSED else part_deduction(policy, score, points, charged)
              for score, points, charged in parts]
    room = max(Fraction(0), kept - policy.lowest * possible)
    total = sum(wanted, Fraction(0))
    if total > room:
        wanted = [share * room / total for share in wanted]
        total = room
    shares = tuple(Fraction(score) if charged == CLOSED else share
                   for (score, _, charged), share in zip(parts, wanted, strict=True))
    return total + sum((Fraction(score) for score, _, charged in parts if charged == CLOSED), Fraction(0)), shares
