"""Late work: how late each answer that counts was, and what the key's late policy deducts for it
(:mod:`grader.assign.deadlines` holds the policy and its rules; Canvas' late policies are the reference).

An answer is late by its row's timestamp minus the student's due time (their extension, else the
assignment's). Deductions are of the points possible, per part: a part late by ``k`` intervals loses
``deduct × k`` of its points, a part past ``after`` all it scored; the student's late deductions together
never take their score below ``lowest`` of their points possible (a score already below it loses nothing),
so that when every part came in one submission the deduction is Canvas' (``deduct × k`` of the points
possible, floored). Where the floor holds the deduction back, each late part's share is cut in proportion.

>>> from grader.assign.deadlines import LatePolicy
>>> late = timedelta(days=1, minutes=1)  # two days: 20 % of the points possible, 20
>>> deductions(LatePolicy(Fraction(1, 10)), [(10.0, 10.0, late), (6.0, 10.0, late)])
(Fraction(4, 1), [Fraction(2, 1), Fraction(2, 1)])
>>> deductions(LatePolicy(Fraction(1, 10), lowest=Fraction(2, 5)), [(9.0, 10.0, late), (0.0, 10.0, late)])
(Fraction(1, 1), [Fraction(1, 2), Fraction(1, 2)])

(9 of 20 would lose 4; the floor, 40 % of 20, holds it at 8.)
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from datetime import datetime, timedelta
from fractions import Fraction

from grader.assign.deadlines import LatePolicy


def late_by(stamp: datetime | None, due: datetime | None) -> timedelta | None:
    """How late a row stamped ``stamp`` (aware) is for ``due``: none before it; None when either is unknown."""
    if stamp is None or due is None:
        return None
    return max(stamp - due, timedelta(0))


def minutes(late: timedelta | None) -> int | None:
    """Lateness in whole minutes, a partial minute counted whole (a second late is a minute late)."""
    return None if late is None else math.ceil(late / timedelta(minutes=1))


def part_deduction(policy: LatePolicy, score: float, points: float, late: timedelta | None) -> Fraction:
    """What a part of ``points`` scoring ``score``, ``late`` by so much, loses before the floor: all it
    scored past ``after``, else ``deduct`` of its points per interval late (used to compare attempts)."""
    if late is None:
        return Fraction(0)
    if policy.closed(late):
        return Fraction(score)
    return policy.deduct * policy.intervals(late) * Fraction(points)


def deductions(policy: LatePolicy, parts: Sequence[tuple[float, float, timedelta | None]]) -> tuple[
        Fraction, list[Fraction]]:
    """A student's deduction and each part's share, for ``parts`` of (score, points, lateness or None)."""
    possible = sum(Fraction(points) for _, points, _ in parts)
    closed = [late is not None and policy.closed(late) for _, _, late in parts]
    kept = sum(Fraction(score) for (score, _, _), shut in zip(parts, closed, strict=True) if not shut)
    wanted = [Fraction(0) if shut else part_deduction(policy, score, points, late)
              for (score, points, late), shut in zip(parts, closed, strict=True)]
    room = max(Fraction(0), kept - policy.lowest * possible)
    total = sum(wanted, Fraction(0))
    if total > room:
        wanted = [share * room / total for share in wanted]
        total = room
    shares = [Fraction(score) if shut else share
              for (score, _, _), shut, share in zip(parts, closed, wanted, strict=True)]
    return total + sum((share for share, shut in zip(shares, closed, strict=True) if shut), Fraction(0)), shares
