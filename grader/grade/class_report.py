"""``report.html``: the class report, one self-contained page an instructor opens in a browser.

It shows the score histogram; per part the share of each verdict kind, the most frequent diagnosed
mistakes and the tolerance used; per problem the score against each printed parameter, so that a
corner of the parameter space that was unfair stands out (and is listed); and the students with
answers that could not be read. The figures are inline SVG (:mod:`grader.grade.report_plots`); the
page loads nothing (no script, no font, no network: its content security policy allows none), and
every text from the key, the roster or the submissions is escaped. Two runs on the same inputs write
the same bytes.

>>> from grader.grade.key import Key, KeyPart, KeyProblem, KeyStudent
>>> part = KeyPart("1", "e", "1a", 0.5, "", 2.0, {"mode": "rtol", "rtol": 0.01, "atol": 0.0}, None, {})
>>> key = Key("key.json", 2, "HW <1>", True, (KeyProblem("1", "Drop", ("1a",)),),
...           (KeyStudent("s1", "<script>alert(1)</script>", "", "1", {"1a": part}),))
>>> from grader.grade.grading import Row
>>> row = Row("x", "invalid", 0.0, 2.0, "0.5", "", "", None, None, "±1 %", "could not read this answer: x", "", "a:2")
>>> page = class_report(Graded(key, {"1a": [row]}, (), (), ()))
>>> "&lt;script&gt;alert(1)&lt;/script&gt;" in page, "<script" in page, "HW &lt;1&gt;" in page
(True, False, True)
"""

from __future__ import annotations

import html

import numpy as np

from grader.base.errors import visible
from grader.grade.class_grades import ClassGrades, classwide, lateness
from grader.grade.class_summary import (
    DRAWN_UP_TO,
    HARD_DROP,
    INVALID_STUDENTS,
    ClassSummary,
    PartSummary,
    ProblemSummary,
    summarize,
)
from grader.grade.grading import Graded
from grader.grade.integrity import Integrity, check
from grader.model.tolerance import Widening

REPORT = "report.html"
SHOWN_CHARS = 60  # of a typed answer shown in the report; details.csv has it whole

_STYLE = """
:root { --ink: #222; --muted: #5f6b7a; --line: #dde2ea; --soft: #f5f7fa; --accent: #1f4e99; --warn: #c62828; }
* { box-sizing: border-box; }
body { margin: 0; color: var(--ink); background: #fff;
       font: 15px/1.45 system-ui, -apple-system, "Segoe UI", Roboto, "DejaVu Sans", sans-serif; }
main { max-width: 1040px; margin: 0 auto; padding: 24px 28px 48px; }
header { border-bottom: 3px solid var(--accent); padding-bottom: 12px; margin-bottom: 8px; }
h1 { font-size: 26px; margin: 0 0 4px; }
h2 { font-size: 20px; margin: 30px 0 8px; padding-top: 6px; border-top: 1px solid var(--line); }
h3 { font-size: 16px; margin: 20px 0 4px; }
p { margin: 6px 0; }
.muted, .note { color: var(--muted); }
.note { font-size: 13px; }
nav { font-size: 14px; margin: 10px 0 0; }
nav a { color: var(--accent); text-decoration: none; margin-right: 14px; }
.stats { display: flex; flex-wrap: wrap; gap: 10px; margin: 14px 0 4px; }
.stat { background: var(--soft); border: 1px solid var(--line); border-radius: 6px; padding: 6px 12px;
        min-width: 112px; }
.stat b { display: block; font-size: 20px; }
.stat span { color: var(--muted); font-size: 12px; }
table { border-collapse: collapse; margin: 8px 0; font-size: 13.5px; width: 100%; }
th, td { text-align: left; padding: 4px 8px; border-bottom: 1px solid var(--line); vertical-align: top; }
th { background: var(--soft); font-weight: 600; white-space: nowrap; }
td.n, th.n { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
td.n small { color: var(--muted); }
td code, li code { background: var(--soft); padding: 0 3px; border-radius: 3px; word-break: break-all; }
.chip { display: inline-block; width: 10px; height: 10px; border-radius: 2px; margin-right: 4px; }
.hard { color: var(--warn); font-weight: 600; }
svg { max-width: 100%; height: auto; display: block; }
ul.corners li { margin: 2px 0; }
"""


FLAGGED_SHOWN = 50  # flagged pairs listed in the report; integrity.csv has every one


def class_report(graded: Graded | ClassGrades, integrity: Integrity | None = None) -> str:
    """The page, for a grading run (``integrity``: its integrity check, worked out here if not given)."""
    graded = classwide(graded)
    summary = summarize(graded)
    figures = _figures(summary)
    title = f"{summary.key.title}: class report"
    body = "\n".join([_header(summary), _late(graded), _scores(summary, figures), _parts(summary, figures),
                      _mistakes(summary), _difficulty(summary, figures), _invalid(summary), _tolerances(summary),
                      _integrity(graded, check(graded) if integrity is None else integrity)])
    return ("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
            "<meta http-equiv=\"Content-Security-Policy\" content=\"default-src 'none'; style-src 'unsafe-inline'\">\n"
            "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
            f"<title>{_e(title)}</title>\n<style>{_STYLE}</style>\n</head>\n<body>\n<main>\n{body}\n</main>\n"
            "</body>\n</html>\n")


def _e(text: object) -> str:
    """Text as HTML shows it, quotes included (it may go into an attribute)."""
    return html.escape(str(text), quote=True)


def _header(summary: ClassSummary) -> str:
    key, percent = summary.key, summary.percent
    stats = [("students", f"{len(key.students):,}"), ("submitted", f"{summary.submitted:,}"),
             ("parts", f"{len(summary.parts)}"), ("points possible", _number(key.possible))]
    if len(percent):
        stats += [("mean score", _percent(float(percent.mean()))),
                  ("median score", _percent(float(np.median(percent))))]
    notes = [*_not_graded(summary), *summary.notes]
    sections = [("scores", "Scores"), ("parts", "Parts"), ("mistakes", "Diagnosed mistakes"),
                ("difficulty", "Difficulty per variant"), ("invalid", "Unreadable answers"),
                ("tolerances", "Tolerances"), ("integrity", "Another student's numbers")]
    return (f"<header>\n<h1>{_e(key.title)}</h1>\n<p class=\"muted\">Class report: how the class did, part by "
            "part and variant by variant</p>\n<div class=\"stats\">"
            + "".join(f"<div class=\"stat\"><b>{_e(value)}</b><span>{_e(name)}</span></div>" for name, value in stats)
            + "</div>\n" + "".join(f"<p class=\"note\">{_e(note)}</p>\n" for note in notes)
            + "<nav>" + "".join(f"<a href=\"#{anchor}\">{name}</a>" for anchor, name in sections)
            + "</nav>\n</header>")


def _not_graded(summary: ClassSummary) -> list[str]:
    """``2 submitted rows were not graded (see problems.csv): unknown student 'ann@x' (not in the answer key)
    (a.csv line 4); 456: unknown label '7z' (…) (a.csv line 9)``: the first few, each with its reason."""
    count, shown = summary.rows_not_graded, summary.not_graded
    if not count:
        return []
    rows = "row was" if count == 1 else "rows were"
    named = "; ".join(f"{_who(p.student_id, p.reason)}{visible(p.reason)} ({visible(p.file)} line {p.line})"
                      for p in shown)
    more = f"; {count - len(shown):,} more" if count > len(shown) else ""
    return [f"{count:,} submitted {rows} not graded (see problems.csv)" + (f": {named}{more}" if named else "")]


def _who(student_id: str, reason: str) -> str:
    """``456: ``, naming the student of a row not graded, where its reason does not already."""
    return f"{visible(student_id)}: " if student_id and student_id not in reason else ""


def _late(graded: ClassGrades) -> str:
    """How many students submitted late, by how much, and what the late policy took (nothing without a
    due time in the key)."""
    key = graded.key
    if key.deadline is None and not any(student.due for student in key.students):
        return ""
    late = sorted(minutes for minutes in lateness(graded) if minutes)
    if not late:
        return "<p class=\"note\">Late work: nobody's answers that count came in after their due time.</p>"
    lost = [points for points in graded.deductions.values() if points]
    policy = (f"; {_students(len(lost))} lost points for it ({_number(sum(lost))} in all)" if key.late is not None
              else "; without a late policy, late work is graded as on time")
    return (f"<p class=\"note\">Late work: {_students(len(late))} had answers that count come in after their due "
            f"time, by {_e(_lateness(late[len(late) // 2]))} (the median) and up to {_e(_lateness(late[-1]))}"
            f"{policy}; details.csv has each answer's minutes late and deduction.</p>")


def _lateness(minutes: int) -> str:
    """Minutes late in words.

    >>> _lateness(1441), _lateness(59)
    ('1 d 0 h 1 min', '59 min')
    """
    days, rest = divmod(minutes, 1440)
    hours, left = divmod(rest, 60)
    return f"{days} d {hours} h {left} min" if days else f"{hours} h {left} min" if hours else f"{left} min"


def _figures(summary: ClassSummary) -> dict[str, str]:
    """The page's figures by name: the scores' histogram, the verdicts' bars, each drawn problem's difficulty."""
    from grader.grade.report_plots import difficulty, score_histogram, verdict_bars

    figures = {"histogram": score_histogram(summary), "verdicts": verdict_bars(summary)}
    for number, problem in enumerate(summary.problems, 1):
        if problem.drawn and problem.attempted.any():
            figures[f"problem-{number}"] = difficulty(problem)
    return figures


def _scores(summary: ClassSummary, figures: dict[str, str]) -> str:
    percent = summary.percent
    below = int((percent < 50).sum())
    return (f"<h2 id=\"scores\">Scores</h2>\n<p>Each student's score as a share of the points they could earn; "
            f"{below:,} of {len(percent):,} scored under 50 %.</p>\n{figures['histogram']}")


def _parts(summary: ClassSummary, figures: dict[str, str]) -> str:
    from grader.grade.report_plots import color

    kinds = summary.kinds
    head = ("<tr><th>part</th><th>answer</th><th class=\"n\">mean score</th>"
            + "".join(f"<th class=\"n\"><span class=\"chip\" style=\"background:{color(kind, kinds)}\"></span>"
                      f"{_e(kind)}</th>" for kind in kinds) + "</tr>")
    rows = []
    for part in summary.parts:
        shares = "".join(f"<td class=\"n\">{_share(part.counts[kind], part.students)}</td>" for kind in kinds)
        rows.append(f"<tr><td>{_e(part.label)}</td><td>{_answer(part)}</td>"
                    f"<td class=\"n\">{_percent(100 * part.mean_credit)}</td>{shares}</tr>")
    return (f"<h2 id=\"parts\">Parts</h2>\n<p>What share of the class got each verdict, part by part (every "
            f"student of the key counts: a part not answered is <i>missing</i>).</p>\n{figures['verdicts']}\n"
            f"<table>\n{head}\n" + "\n".join(rows) + "\n</table>")


def _mistakes(summary: ClassSummary) -> str:
    rows = [f"<tr><td>{_e(part.label)}</td><td>{_mistake(part, mistake)}</td><td class=\"n\">{count:,}</td>"
            f"<td class=\"n\">{_percent(100 * count / part.students)}</td></tr>"
            for part in summary.parts for mistake, count in part.mistakes]
    text = "<h2 id=\"mistakes\">Diagnosed mistakes</h2>\n"
    if not rows:
        return text + "<p>No answer was matched to a diagnosed mistake.</p>"
    more = [part for part in summary.parts if part.diagnosed > sum(count for _, count in part.mistakes)]
    return (text + "<p>The most frequent typical mistakes that wrong answers matched, part by part (as each "
            "effect's list of mistakes says them, with the id details.csv gives), with how many students made "
            "each.</p>\n<table>\n<tr><th>part</th><th>mistake</th><th class=\"n\">students</th>"
            "<th class=\"n\">of the class</th></tr>\n" + "\n".join(rows) + "\n</table>"
            + "".join(f"\n<p class=\"note\">{_e(part.label)}: {part.diagnosed:,} diagnosed in all (see details.csv)</p>"
                      for part in more))


def _mistake(part: PartSummary, mistake: str) -> str:
    """A diagnosed mistake in words (as the effect's list says it), with its id as details.csv names it."""
    says = part.says.get(mistake)
    code = f"<code>{_e(mistake)}</code>"
    return code if says is None else f"{_e(says)} <small class=\"muted\">{code}</small>"


def _difficulty(summary: ClassSummary, figures: dict[str, str]) -> str:
    corners = [(problem, parameter, part) for problem in summary.problems
               for parameter, part in problem.hard_corners()]
    text = ["<h2 id=\"difficulty\">Difficulty per variant</h2>\n<p>Each problem's score against each parameter "
            "printed on the students' sheets, over the students who answered at least one of its parts: blue, "
            "the mean score of the students in each range of the parameter (bars: its standard error); dashed, "
            "the problem's mean; grey, each student. A range whose mean is at least "
            f"{100 * HARD_DROP:.0f} points below the problem's, by more than twice its standard error, is red "
            "and listed here: those variants may have been harder than the others.</p>"]
    if corners:
        text.append("<ul class=\"corners\">" + "".join(
            f"<li><span class=\"hard\">Problem {_e(problem.key)}</span>, <code>{_e(parameter.name)}</code> "
            f"{_e(_range(part.low, part.high, parameter.unit))}: {_students(part.students)} scored "
            f"{_percent(100 * part.mean)} (the problem: {_percent(100 * problem.mean)})</li>"
            for problem, parameter, part in corners)
            + "</ul>")
    else:
        text.append("<p>No range of any parameter scored clearly below its problem.</p>")
    text += [_problem(problem, figures.get(f"problem-{number}", ""))
             for number, problem in enumerate(summary.problems, 1)]
    return "\n".join(text)


def _problem(problem: ProblemSummary, figure: str) -> str:
    attempted = int(problem.attempted.sum())
    head = (f"<h3>Problem {_e(problem.key)}: {_e(problem.title)}</h3>\n<p class=\"muted\">parts "
            f"{_e(', '.join(problem.labels))}; {_students(attempted)} answered, mean score "
            f"{_percent(100 * problem.mean)}</p>")
    varied = problem.drawn
    fixed = [f"{p.name} = {_range(p.bins[0].low, p.bins[0].high, p.unit)}" for p in problem.parameters
             if len(p.bins) == 1]
    beyond = [f"{p.name} ({_range(p.bins[0].low, p.bins[-1].high, p.unit)})" for p in problem.parameters
              if len(p.bins) > 1 and not p.drawable]
    notes = []
    if fixed:
        notes.append("the same for everyone: " + ", ".join(fixed))
    if beyond:
        notes.append(f"not drawn, with values beyond ±{DRAWN_UP_TO:.0e} (too large for a figure's axis; check the "
                     "key): " + ", ".join(beyond))
    if not problem.parameters:
        notes.append("the key holds no parameters for this problem")
    elif not varied and not beyond and attempted:
        notes.append("no parameter varies among the students who answered")
    return "\n".join([head, figure, *(f"<p class=\"note\">{_e(note)}</p>" for note in notes)])


def _invalid(summary: ClassSummary) -> str:
    count = summary.invalid_students
    text = [f"<h2 id=\"invalid\">Unreadable answers</h2>\n<p>{_students(count)} "
            f"{'has answers' if count == 1 else 'have answers'} that could not be read (verdict <i>invalid</i>): "
            "they score 0 for those parts, and may deserve a look.</p>"]
    if summary.invalid:
        rows = [f"<tr><td>{_e(student.id)}</td><td>{_e(student.name)}</td><td>{_e(student.section)}</td>"
                f"<td>{_e(cell.label)}</td><td><code>{_e(_cut(cell.submitted))}</code></td><td>{_e(cell.reason)}</td>"
                "</tr>" for student, cells in summary.invalid for cell in cells]
        text.append("<table>\n<tr><th>student</th><th>name</th><th>section</th><th>part</th><th>typed</th>"
                    "<th>why it could not be read</th></tr>\n" + "\n".join(rows) + "\n</table>")
    if summary.invalid_students > len(summary.invalid):
        text.append(f"<p class=\"note\">The first {INVALID_STUDENTS} are listed; "
                    f"{_students(summary.invalid_students - len(summary.invalid))} more: "
                    "details.csv lists every one (verdict invalid).</p>")
    return "\n".join(text)


def _tolerances(summary: ClassSummary) -> str:
    rows = [f"<tr><td>{_e(part.label)}</td><td>{_answer(part)}</td>"
            f"<td class=\"n\">{_e(' or '.join(_number(p) for p in part.points))}</td>"
            f"<td>{_tolerance_words(part)}</td><td>{_widened(part.widened, part.unit)}</td></tr>"
            for part in summary.parts]
    widened = sum(part.widened.variants for part in summary.parts if part.widened)
    how_many = f"{widened:,} answers in all" if widened else "none was"
    return ("<h2 id=\"tolerances\">Tolerances</h2>\n<p>How each part was compared to the key (a symbolic answer: "
            "by value at random points), and what it was worth. Where rounding as the sheet asks, along a "
            "textbook's route, can move a student's answer by more than the tolerance, the key widened that "
            f"student's tolerance: {how_many}.</p>\n<table>\n<tr><th>part</th><th>answer</th>"
            "<th class=\"n\">points</th><th>tolerance</th><th>for rounding</th></tr>\n"
            + "\n".join(rows) + "\n</table>")


def _integrity(graded: ClassGrades, integrity: Integrity) -> str:
    """The pairs of students whose wrong answers match each other's numbers too often to be chance."""
    students, flagged = graded.key.students, np.flatnonzero(integrity.ranked.flagged(integrity.threshold))
    text = ["<h2 id=\"integrity\">Answers from another student's variant</h2>\n<p>Every student has their own "
            "numbers, so a wrong answer that another student's key accepts (same part, within that student's "
            "tolerance; not a diagnosed mistake of the student's own) is worth a look. "
            f"{integrity.matched:,} of {integrity.wrong:,} wrong answers match some other student's value "
            "(integrity.csv lists them). A pair is flagged here when the chance of so many matches by accident, "
            f"corrected for the {integrity.examined:,} pairs examined, is at most "
            f"{_e(f'{integrity.threshold:g}')} (the assignment's <code>grading.integrity_threshold</code>; "
            "docs/grading.md says how it is estimated). This is evidence to look at, not proof, and it changes "
            "no grade.</p>"]
    if not len(flagged):
        text.append("<p>No pair of students is flagged.</p>")
        return "\n".join(text)
    rows = [f"<tr><td>{_e(students[p.student].id)}</td><td>{_e(students[p.student].name)}</td>"
            f"<td>{_e(students[p.partner].id)}</td><td>{_e(students[p.partner].name)}</td>"
            f"<td>{_e(', '.join(p.labels))}</td><td class=\"n\">{len(p.labels)} of {p.wrong}</td>"
            f"<td class=\"n\">{_e(f'{p.chance:.2g}')}</td><td class=\"n\">{_e(f'{p.corrected:.2g}')}</td></tr>"
            for p in integrity.ranked.records(flagged[:FLAGGED_SHOWN])]
    text.append("<table>\n<tr><th>student</th><th>name</th><th>answers match the key of</th><th>name</th>"
                "<th>parts</th><th class=\"n\">of the wrong parts</th><th class=\"n\">chance</th>"
                "<th class=\"n\">corrected</th></tr>\n" + "\n".join(rows) + "\n</table>")
    if len(flagged) > FLAGGED_SHOWN:
        text.append(f"<p class=\"note\">The first {FLAGGED_SHOWN} are listed; {len(flagged) - FLAGGED_SHOWN:,} "
                    "more: integrity.csv has each (flagged yes).</p>")
    return "\n".join(text)


def _tolerance_words(part: PartSummary) -> str:
    tolerances = part.tolerances
    if len(tolerances) == 1 and not part.widened:
        return _e(tolerances[0][0])
    return "; ".join(f"{_e(words)} <small class=\"muted\">({count:,} of {part.students:,})</small>"
                     for words, count in tolerances)


def _widened(widened: Widening | None, unit: str) -> str:
    """How many students' tolerance was widened, and the widest with its reason."""
    if widened is None:
        return "<small>–</small>"
    return (f"{_e(widened.describe('student', unit))} <small class=\"muted\">(the widest: "
            f"{_e(widened.widest.reason)})</small>")


def _answer(part: PartSummary) -> str:
    unit = f" <span class=\"muted\">({_e(part.unit)})</span>" if part.unit else ""
    return f"<code>{_e(part.name)}</code>{unit}"


def _students(count: int) -> str:
    return f"{count:,} student" if count == 1 else f"{count:,} students"


def _share(count: int, total: int) -> str:
    if not count:
        return "<small>–</small>"
    return f"{_percent(100 * count / total)} <small>({count:,})</small>"


def _percent(value: float) -> str:
    """A percentage as the report shows it.

    >>> _percent(93.333), _percent(0.2), _percent(100.0)
    ('93 %', '0.2 %', '100 %')
    """
    return f"{value:.1f} %" if 0 < abs(value) < 1 else f"{value:.0f} %"


def _number(value: float) -> str:
    return f"{value:g}"


def _range(low: float, high: float, unit: str = "") -> str:
    """``1500 to 1800 mm``, or one value."""
    text = f"{low:.4g}" if low == high else f"{low:.4g} to {high:.4g}"
    return f"{text} {unit}" if unit else text


def _cut(text: str) -> str:
    return text if len(text) <= SHOWN_CHARS else text[:SHOWN_CHARS - 1] + "…"
