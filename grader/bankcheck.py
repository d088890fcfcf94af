"""``grader check-bank``: every template of a bank checked the way its author needs, one report each.

A template is checked in stages, and its report names the first that fails:

1. **load**: the file reads and validates (schema, names, dimensions, a statement that fills in only
   parameters, symbols and g), and no other template of the bank has its id;
2. **compile**: the solver derives every answer from the scene;
3. **draws**: ``DRAWS`` variants drawn as ``grader generate`` draws them (sampled, rounded as printed)
   are each answered or refused with a reason (a domain, a constraint, a physics check), never by an
   exception, and at least one is answered;
4. **degenerate draws**: no answered draw has an answer too close to zero to grade with a relative
   tolerance, or a derived ``e`` at 0 or 1 (``generate`` would have to draw it again); the draws whose
   tolerance, widened for rounding along a solution route, would pass the default
   ``grading.max_tolerance`` are counted (``generate`` draws those again too), and how many are widened;
5. **simulation**: the time-domain simulation agrees with the closed form to ``AGREEMENT`` on
   ``SIMULATED`` of those draws;
6. **typesetting**: one variant's sheet (statement, figure) and answer key (worked solution) compile.

Sits above every stage, like :mod:`grader.demo`: it samples (assign), solves (solve), simulates
(simulate) and typesets (render).
"""

from __future__ import annotations

import re
import time
from collections import Counter
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from grader.assign.assignment import Assignment, ProblemSpec, Student
from grader.assign.fair import Capped
from grader.assign.variants import MAX_DRAWS, ProblemDraws, generate, variant_generator
from grader.bank.folders import template_paths
from grader.bank.template import Template, load_template, same_id
from grader.base.errors import GraderError
from grader.model.expr import Sym
from grader.physics.integrate import Settings
from grader.physics.record import Options
from grader.render.documents import sources
from grader.render.typeset import compile_typst, font_paths
from grader.simulate.comparison import relative_difference
from grader.simulate.walker import simulate
from grader.solve.cache import compiled_for
from grader.solve.evaluate import Columns, solve_columns, solve_one

DRAWS = 200
SIMULATED = 4
AGREEMENT = 1e-6  # relative, as the test suite cross-checks every shipped template
SIMULATION = Options(Settings("adaptive", rtol=1e-10))
SEED = "check-bank"
# Some draws of a signed answer land near its zero crossing, and rounding to the printed precision makes
# exact zeros now and then (head-on's v2_out, two-rebounds' loss at h2 = h1): generate draws those again.
# A template fails when more of its draws are degenerate than this ...
MOST_DEGENERATE = 0.10
# ... or so many draws are refused or degenerate that generate's MAX_DRAWS draws could all fail for some
# student of a class of 2,000 with a chance above 1e-6 (2000 * 0.4**25 = 2e-7).
MOST_UNUSABLE = 0.40
# A cause of discarded draws (a constraint, an answer near zero, a rounding route past the cap) that discards at
# least this share of the draws is told what to change; a rarer one is only named.
ADVISED = 0.05
_NUMBER = re.compile(r"[-+]?\d+(?:\.\d+)?(?:e[-+]?\d+)?")


@dataclass(frozen=True)
class Report:
    """How one template fared: ``problem`` is None when every check passed, else the first failure."""

    template: str  # its id, or its file's stem when it does not load
    where: str
    problem: str | None
    checked: str  # what was checked, for a template that passed
    seconds: float

    def to_json(self) -> dict[str, Any]:
        """``{"template", "file", "ok", "problem", "checked", "seconds"}``."""
        return {"template": self.template, "file": self.where, "ok": self.problem is None,
                "problem": self.problem, "checked": self.checked, "seconds": round(self.seconds, 3)}


class _CheckError(Exception):
    """A check that failed; the message says which and why."""


def check_bank(folders: Sequence[Path] = (), shipped: bool = True, fonts: tuple[str, ...] = ()) -> Iterator[Report]:
    """A report per template file of the bank, in the order of the folders, then of the file names;
    a template that does not load, or repeats an id, is reported and the others are still checked."""
    seen: dict[str, Template] = {}
    for path in template_paths(folders, shipped):
        started = time.perf_counter()
        try:
            template = load_template(path)
        except GraderError as error:
            yield Report(path.stem, str(path), f"load: {error}", "", time.perf_counter() - started)
            continue
        if template.id in seen:
            yield Report(template.id, template.where, f"load: {same_id(seen[template.id], template)}", "",
                         time.perf_counter() - started)
            continue
        seen[template.id] = template
        yield check_template(template, fonts)


def check_template(template: Template, fonts: tuple[str, ...] = ()) -> Report:
    """Every check after loading (see the module's docstring) on one template."""
    started = time.perf_counter()
    try:
        checked = _Checks(template, fonts).run()
    except _CheckError as failure:
        return Report(template.id, template.where, str(failure), "", time.perf_counter() - started)
    return Report(template.id, template.where, None, checked, time.perf_counter() - started)


class _Checks:
    """The stages of one template's check, each reporting what it found."""

    def __init__(self, template: Template, fonts: tuple[str, ...]) -> None:
        self.template, self.fonts = template, fonts
        self.problem = ProblemSpec("1", template.id, {"*": 1.0}, {}, {}, {})
        self.assignment = Assignment(template.where, f"check-bank: {template.id}", "", SEED, "", "", (self.problem,))

    def run(self) -> str:
        _stage("compile", lambda: compiled_for(self.template))
        draws = _stage("draws", lambda: ProblemDraws(self.assignment, self.problem, self.template))
        rng, _ = variant_generator(SEED, self.template.id, "draws")
        rows = _stage("draws", lambda: [draws.draw_row(rng) for _ in range(DRAWS)])
        result = _stage("draws", lambda: solve_columns(self.template, draws.compiled, draws.table(rows)))
        usable = self._answered(rows, result, draws)
        worst = _stage("simulation", lambda: self._simulate(draws, [rows[i] for i in usable[:SIMULATED]]))
        _stage("typesetting", self._typeset)
        refused = sum(reason is not None for reason in result.refusals)
        discarded = f"; {DRAWS - len(usable)} of {DRAWS} draws discarded: {self.discarded}" if self.discarded else ""
        return (f"{DRAWS} draws: {len(usable)} usable, {refused} refused, {self.degenerate} degenerate, "
                f"{self.capped} past the ±{self.cap * 100:g} % tolerance cap ({self.widened} with a widened "
                f"tolerance); simulation within {worst:.0e} on {SIMULATED}; sheet and key typeset{discarded}")

    def _answered(self, rows: Sequence[dict[str, str]], result: Columns, draws: ProblemDraws) -> list[int]:
        """The rows answered and not degenerate; a failure when too few are (see ``MOST_DEGENERATE``)."""
        answered = [row for row, reason in enumerate(result.refusals) if reason is None]
        if not answered:
            reason, count = Counter(result.refusals).most_common(1)[0]
            raise _CheckError(f"draws: none of {DRAWS} sampled draws is answered; {count} are refused because {reason} "
                              "(check the sampling ranges against the constraints)")
        flaws = draws.degeneracies(result)
        degenerate = [row for row in answered if flaws[row] is not None]
        if len(degenerate) > MOST_DEGENERATE * len(answered):
            first = degenerate[0]
            raise _CheckError(f"degenerate draws: {len(degenerate)} of the {len(answered)} answered draws sit at a "
                              f"degenerate point, e.g. {flaws[first]} at {self._shown(rows[first])}; generate draws "
                              "them again, but a sampling that reaches where an answer vanishes this often should be "
                              f"narrowed (at most {MOST_DEGENERATE:.0%} of the draws may)")
        fair = _stage("tolerances", lambda: draws.fair(result))
        capped = [row for row in answered if flaws[row] is None and fair.flaws[row] is not None]
        usable = [row for row in answered if flaws[row] is None and fair.flaws[row] is None]
        self.cap, self.capped = self.assignment.grading.max_tolerance, len(capped)
        self.widened = sum(any(fair.tolerances[name][row].reason for name in fair.tolerances) for row in usable)
        self.discarded = self._explained([reason for reason in result.refusals if reason is not None],
                                         [str(flaws[row]) for row in degenerate],
                                         [cause for row in capped if (cause := fair.capped[row]) is not None])
        if len(usable) < (1 - MOST_UNUSABLE) * DRAWS:
            example = f", e.g. {fair.flaws[capped[0]]} at {self._shown(rows[capped[0]])}" if capped else ""
            raise _CheckError(f"draws: only {len(usable)} of {DRAWS} sampled draws are usable ({DRAWS - len(answered)} "
                              f"refused, {len(degenerate)} degenerate, {len(capped)} past the tolerance cap{example}); "
                              f"generate draws at most {MAX_DRAWS} times per student, so in a class of 2,000 some "
                              f"student would get no variant (at most {MOST_UNUSABLE:.0%} of the draws may be "
                              f"unusable): {self.discarded}")
        self.degenerate = len(degenerate)
        return usable

    def _explained(self, refusals: Sequence[str], flaws: Sequence[str], capped: Sequence[Capped]) -> str:
        """Why draws were discarded, one cause a clause, most first: what refused them or which answer sat at a
        degenerate point or passed the tolerance cap; a cause of at least ``ADVISED`` of the draws says what to
        change."""
        causes: list[tuple[int, str, str]] = []
        by_reason: dict[str, list[str]] = {}
        for reason in refusals:  # a physics check's reason holds the value: group without numbers
            by_reason.setdefault(_NUMBER.sub("#", reason), []).append(reason)
        for same in by_reason.values():
            causes.append((len(same), f"refused{'' if len(set(same)) == 1 else ', e.g.'} because {same[0]}",
                           "narrow the sampling to where it holds, or widen what the constraints allow"))
        for flaw, count in Counter(flaw.split(" = ")[0] for flaw in flaws).items():
            causes.append((count, f"with {flaw} too close to zero to grade with a relative tolerance",
                           "narrow the sampling away from where it vanishes, or give the answer an atol")
                          if flaw.startswith("answer ") else
                          (count, f"with {flaw} within 0.01 of 0 or 1",
                           "narrow the sampling away from e = 0 and e = 1"))
        groups: dict[tuple[str, str, str], list[float]] = {}
        for cause in capped:
            groups.setdefault((cause.answer, cause.route, cause.moved_by), []).append(cause.needed)
        for (answer, route, moved_by), needed in groups.items():
            causes.append((len(needed), f"with answer {answer}'s tolerance widened past the ±{self.cap * 100:g} % cap "
                           f"by rounding {moved_by} along {route} (typical ±{float(np.median(needed)) * 100:.2g} %)",
                           self._advice(answer, route)))
        return "; ".join(f"{count} {what}" + (f": {advice}" if count >= ADVISED * DRAWS else "")
                         for count, what, advice in sorted(causes, key=lambda cause: -cause[0]))

    def _advice(self, answer: str, route: str) -> str:
        """What to change for an answer that rounding moves past the cap."""
        general = "narrow the sampling toward variants that rounding moves less, or raise grading.max_tolerance"
        spec = self.template.answers[answer].value
        for stage in self.template.scene.stages:
            after = stage.fields.get("after") or {}
            shared = isinstance(spec, Sym) and len(after) == 2 and all(
                velocity.n == spec and velocity.t is None for velocity in after.values())
            if shared and route == "the worked solution":
                second = stage.fields["bodies"][1]
                return (f"list {second} first in stages[{stage.index}].bodies (the worked solution finds {answer}, "
                        f"shared by both bodies, from the first body's momentum, which cancels here), {general}")
        return general

    def _simulate(self, draws: ProblemDraws, rows: Sequence[dict[str, str]]) -> float:
        """The largest relative difference between simulated and closed-form answers."""
        worst = 0.0
        for row in rows:
            params = {name: float(value) for name, value in row.items()}
            closed = solve_one(self.template, draws.compiled, params)
            assert closed.answers is not None  # the row was answered above
            simulated = simulate(self.template, params, SIMULATION)
            for name, value in simulated.answers.items():
                exact = closed.answers[name].value
                if value is None or exact is None:
                    if (value is None) != (exact is None):
                        raise _CheckError(f"simulation: {name} = {_value(value)} simulated, {_value(exact)} in closed "
                                          f"form, at {self._shown(row)}")
                    continue
                assert isinstance(exact, float)
                differs = relative_difference(value, exact)
                if differs > AGREEMENT:
                    raise _CheckError(f"simulation: {name} = {value:.10g} simulated, {exact:.10g} in closed form "
                                      f"(relative difference {differs:.2g}, at most {AGREEMENT:g} allowed) at "
                                      f"{self._shown(row)}")
                worst = max(worst, differs)
        return worst

    def _typeset(self) -> None:
        student = Student("check-bank", "Check Bank", "", "")
        generation = generate(self.assignment, [student], {self.template.id: self.template})
        sheet, key = sources(self.assignment, generation, {self.template.id: self.template}, [0])
        fonts = self.fonts or font_paths()
        for what, source in (("the sheet (statement, figure)", sheet), ("the answer key (worked solution)", key)):
            try:
                compile_typst(source, tagged=False, fonts=fonts)
            except GraderError as error:
                raise _CheckError(f"typesetting {what}: {error}") from None

    def _shown(self, row: dict[str, str]) -> str:
        units = {name: p.unit.text for name, p in self.template.parameters.items()}
        return ", ".join(f"{name} = {value}" + (f" {units[name]}" if units[name] else "")
                         for name, value in row.items())


def _value(value: float | str | None) -> str:
    return "undefined" if value is None else f"{value:.10g}" if isinstance(value, float) else value


def _stage(name: str, work: Callable[[], Any]) -> Any:
    """``work()``; a refusal (GraderError) or an exception of any kind becomes a failure of stage ``name``."""
    try:
        return work()
    except _CheckError:
        raise
    except GraderError as error:
        raise _CheckError(f"{name}: {error}") from None
    except Exception as error:  # the author's template, or grader, has a bug: report it
        raise _CheckError(f"{name}: raised {type(error).__name__}: {error} (an exception, not a refusal with a reason: "
                          "a bug in the template or in grader)") from None
