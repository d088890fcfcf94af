"""A simulation beside the closed form: how far each simulated answer is from the solver's, and the record
``grader simulate --json`` prints (``grader check-bank`` and the tests measure agreement the same way).

The closed-form answers come from the solver, a stage of this one's rank: they are taken as objects with a
``value`` and an ``undefined`` reason (:class:`ClosedForm`), so this stage imports nothing of the solver.

>>> relative_difference(1.0000001, 1.0) < 1.1e-7, relative_difference(-2e-12, 0.0), relative_difference(0.0, -0.0)
(True, 2e-12, 0.0)
"""

from __future__ import annotations

import sys
from collections.abc import Mapping
from typing import Any, Protocol

from grader.physics.record import Options
from grader.simulate.walker import Simulation


class ClosedForm(Protocol):
    """An answer of the closed form: a number, an expression (a symbolic answer: not compared), or undefined."""

    @property
    def value(self) -> float | str | None: ...
    @property
    def undefined(self) -> str | None: ...


def relative_difference(simulated: float, exact: float) -> float:
    """``|simulated - exact| / |exact|``; where the exact value is 0, which no relative difference is measured
    against, the difference itself, ``|simulated|`` (in the answer's unit): a simulation that gives 1e-12 for an
    answer of 0 agrees to 1e-12, one that gives 0.5 does not. Capped at the largest float (1e300 against
    1e-10 overflows: "huge" is the truth), so that the record is finite JSON."""
    difference = abs(simulated - exact)
    return min(difference / abs(exact) if exact else difference, sys.float_info.max)


def comparison(result: Simulation, closed: Mapping[str, ClosedForm], options: Options) -> dict[str, Any]:
    """The record of a simulation beside the closed form ``closed`` (by answer), every -0 made 0: what was
    simulated and how, and for each answer its simulated and closed-form value, their relative difference
    (:func:`relative_difference`, None when either is undefined or the answer is an expression) and why
    either is undefined."""
    settings = options.settings
    rows = {}
    for name, simulated in result.answers.items():
        answer = closed.get(name)
        exact = answer.value if answer is not None and isinstance(answer.value, float) else None
        differs = None if exact is None or simulated is None else relative_difference(simulated, exact)
        why = {"simulated": result.undefined.get(name) if simulated is None else None,
               "closed_form": (answer.undefined or "undefined") if answer is not None and exact is None else None}
        rows[name] = {"simulated": simulated, "closed_form": exact, "rel_diff": differs,
                      "undefined": {k: v for k, v in why.items() if v is not None} or None}
    record = {"template": result.template, "params": result.params, "method": settings.method,
              "effects": list(result.effects), "steps": result.steps, "seconds": result.seconds, "answers": rows,
              "fitted": dict(result.fitted), "nominal": dict(result.nominal),
              "contacts": [{"impact": c.label, "e": c.e, "measured_e": c.measured_e, "zeta": c.zeta,
                            "duration": c.duration} for c in result.contacts],
              "notes": list(result.notes),
              "settings": {"steps_per_contact": settings.steps, "rtol": settings.rtol,
                           "contact_duration": options.contact_duration,
                           "weight_during_contact": options.weight_during_contact}}
    return _plain_numbers(record)  # type: ignore[no-any-return]


def _plain_numbers(value: Any) -> Any:
    """A simulation record with every -0 made 0; a number that is not finite is a bug (the
    simulator refuses what would produce one and reports undefined quantities as None)."""
    if isinstance(value, dict):
        return {key: _plain_numbers(item) for key, item in value.items()}
    if isinstance(value, list | tuple):
        return [_plain_numbers(item) for item in value]
    if isinstance(value, float):
        if value != value or value in (float("inf"), float("-inf")):
            raise ValueError(f"a simulation produced a number that is not finite: {value}")
        return value + 0.0
    return value
