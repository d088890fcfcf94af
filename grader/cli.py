"""The ``grader`` command: one subcommand per stage of the pipeline.

Exit codes: 0 ok; 1 runtime error (a bug: it keeps its traceback); 2 usage or invalid input;
3 finished, with some rows refused.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shlex
import signal
import sys
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from grader import __version__
from grader.base.errors import GraderError, UsageError, close_matches, some, visible

if TYPE_CHECKING:
    from grader.bank.listing import Listed
    from grader.bank.template import Parameter, Template

# Each command imports what it needs when it runs: `grader --help` and `grader list` do not pay for
# the solver, and nothing imports sympy, scipy, matplotlib, typst, jinja2 or pint unless its command
# needs it (a test checks this).

if TYPE_CHECKING:  # imported when used: `grader list` must not pay for numpy
    from grader.grade.run import GradeSummary

EXIT_OK, EXIT_USAGE, EXIT_REFUSED, EXIT_INTERRUPTED = 0, 2, 3, 130


class _HelpFormatter(argparse.HelpFormatter):
    """argparse's help formatter, as wide as the terminal as :func:`shutil.get_terminal_size` finds it, without
    importing shutil (and with it bz2 and lzma: argparse makes a formatter for each option it is given, and
    every command would pay for them)."""

    def __init__(self, prog: str, indent_increment: int = 2, max_help_position: int = 24,
                 width: int | None = None) -> None:
        super().__init__(prog, indent_increment, max_help_position, _columns() - 2 if width is None else width)


_NEGATIVE_NUMBER = re.compile(r"^-(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?$")
"""A negative number as argparse should take it for a value: ``-6.26``, ``-1e308``, ``-.5E-3``."""


class _Parser(argparse.ArgumentParser):
    """argparse's parser with :class:`_HelpFormatter`, its commands' parsers too. With ``negative_values``, a
    negative number in any form (``-6.3e2``, which argparse alone takes for an option) is a value: answers and
    expected values are often negative."""

    def __init__(self, *args: Any, negative_values: bool = False, **kwargs: Any) -> None:
        self.negative_values = negative_values
        self.options: dict[str, bool] = {}  # each option string: whether it takes a value
        kwargs.setdefault("formatter_class", _HelpFormatter)
        super().__init__(*args, **kwargs)

    def add_argument(self, *args: Any, **kwargs: Any) -> argparse.Action:
        action = super().add_argument(*args, **kwargs)
        self.options.update(dict.fromkeys(action.option_strings, action.nargs is None))
        return action

    def parse_known_args(self, args: Sequence[str] | None = None,  # type: ignore[override]
                         namespace: argparse.Namespace | None = None) -> tuple[argparse.Namespace, list[str]]:
        if self.negative_values and args is not None:
            args = self.values_given(list(args))
        return super().parse_known_args(args, namespace)

    def values_given(self, args: list[str]) -> list[str]:
        """``args`` with each negative number argparse would take for an option given as a value: joined to the
        option before it that takes one (``--expected -6.3e2`` as ``--expected=-6.3e2``, an option abbreviated
        as argparse allows), else, a positional value, after ``--`` at the end. Arguments that already hold a
        ``--`` are left as they are.

        >>> parser = _Parser(negative_values=True)
        >>> _ = parser.add_argument("answer", nargs="?"), parser.add_argument("--expected"), parser.add_argument(
        ...     "--json", action="store_true")
        >>> parser.values_given(["-6.3e0", "--json", "--exp", "-6.26e0", "--expected", "-6"])
        ['--json', '--exp=-6.26e0', '--expected=-6', '--', '-6.3e0']
        """
        if "--" in args:
            return args
        given: list[str] = []
        positional: list[str] = []
        for arg in args:
            if not _NEGATIVE_NUMBER.match(arg):
                given.append(arg)
            elif given and self._takes_value(given[-1]):
                given[-1] += f"={arg}"
            else:
                positional.append(arg)
        return given + (["--", *positional] if positional else [])

    def _takes_value(self, arg: str) -> bool:
        """Whether ``arg`` names one option that takes a value (argparse takes a long option's unique prefix)."""
        if arg in self.options:
            return self.options[arg]
        named = [option for option in self.options if option.startswith("--") and option.startswith(arg)]
        return arg.startswith("--") and "=" not in arg and len(named) == 1 and self.options[named[0]]


def _columns() -> int:
    """The terminal's width as :func:`shutil.get_terminal_size` finds it: ``$COLUMNS``, else standard output's
    terminal, else 80."""
    try:
        columns = int(os.environ.get("COLUMNS", ""))
    except ValueError:
        columns = 0
    if columns > 0:
        return columns
    try:
        return os.get_terminal_size(sys.__stdout__.fileno()).columns or 80  # type: ignore[union-attr]
    except (AttributeError, ValueError, OSError):  # no standard output, or not a terminal
        return 80


def build_parser() -> argparse.ArgumentParser:
    """The argument parser, with one subparser per command."""
    parser = _Parser(prog="grader", description="Impact-problem generator and auto-grader.")
    parser.add_argument("--version", action="version", version=f"grader {__version__}")
    _bank_options(parser, "_global")
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    listing = commands.add_parser("list", help="list the templates in the bank, by topic")
    _bank_options(listing)
    listing.add_argument("--json", action="store_true", help="one JSON object per template")

    show = commands.add_parser("show", help="one template: its statement with example numbers, scene, parameters, "
                                            "derived step chain")
    _bank_options(show)
    show.add_argument("template", metavar="ID")
    show.add_argument("--json", action="store_true", help="print JSON")

    solve = commands.add_parser("solve", help="answers for one parameter set or a CSV of them")
    _bank_options(solve)
    solve.add_argument("template", metavar="ID")
    given = solve.add_mutually_exclusive_group(required=True)
    given.add_argument("--set", action="append", metavar="NAME=VALUE", dest="assignments",
                       help="a parameter value in the template's unit, or with its own unit (2.1m)")
    given.add_argument("--batch", type=Path, metavar="FILE.csv", help="CSV with a header of parameter names")
    solve.add_argument("--json", action="store_true", help="JSON output (one object per line for --batch)")

    simulate = commands.add_parser("simulate", help="re-derive the answers in the time domain, beside the closed form")
    _bank_options(simulate)
    simulate.add_argument("template", metavar="ID")
    simulate.add_argument("--set", action="append", metavar="NAME=VALUE", dest="assignments", required=True,
                          help="a parameter value in the template's unit, or with its own unit")
    simulate.add_argument("--method", default="adaptive", help="euler, rk4 or adaptive (default)")
    step = simulate.add_mutually_exclusive_group()
    step.add_argument("--steps-per-contact", type=int, metavar="N",
                      help="fixed steps per contact (euler, rk4; a fall or rise takes N steps over its duration)")
    step.add_argument("--rtol", type=float, metavar="X", help="relative tolerance (adaptive; default 1e-10)")
    simulate.add_argument("--contact-duration", type=float, default=1e-3, metavar="S",
                          help="duration of a contact in seconds; sets the stiffness (default 0.001)")
    simulate.add_argument("--weight-during-contact", action="store_true",
                          help="let gravity act during contact too (the closed form neglects it)")
    simulate.add_argument("--json", action="store_true", help="print one JSON object")
    simulate.add_argument("--plot", type=Path, metavar="FILE.png", help="draw position, velocity and force")

    generate = commands.add_parser("generate", help="per-student variants, key and PDFs for an assignment")
    _bank_options(generate)
    generate.add_argument("assignment", type=Path, metavar="ASSIGNMENT.yaml")
    generate.add_argument("--roster", type=Path, required=True, metavar="ROSTER.csv",
                          help="columns id, name, email, section")
    generate.add_argument("--out", type=Path, required=True, metavar="DIR", help="output folder (new or empty)")
    _output_options(generate)
    generate.add_argument("--no-pdf", action="store_true", help="write key.json and key.csv only")
    generate.add_argument("--keep-source", action="store_true", help="also keep the Typst sources")

    grading = commands.add_parser("grade", help="grade CSV submissions against a key.json")
    grading.add_argument("submissions", type=Path, nargs="+", metavar="SUBMISSIONS.csv")
    grading.add_argument("--key", type=Path, required=True, metavar="DIR/key.json",
                         help="the key grader generate wrote")
    grading.add_argument("--out", type=Path, required=True, metavar="DIR", help="output folder (new or empty)")
    _bank_options(grading)  # the templates the key was made from: errors carried forward, diagnosed mistakes
    grading.add_argument("--format", choices=("auto", "long", "wide"), default="auto",
                         help="long: a row per answer (student, label, answer); wide: a row per submission, a "
                              "column per label; auto (default): told apart from the header")
    grading.add_argument("--canvas", type=Path, metavar="EXPORT.csv",
                         help="a Canvas gradebook export (Grades > Export): canvas.csv then has its students, names "
                              "and ids, and its 'Title (id)' column of the assignment")
    grading.add_argument("--missing", choices=("zero", "blank"),
                         help="what canvas.csv gives a student who submitted nothing: 0, or no score (the export's "
                              "cell, or an empty one); by default 0 unless the --canvas export shows a grade, kept")
    grading.add_argument("--feedback", action="store_true",
                         help="also write each student's graded sheet with their worked solutions: "
                              "DIR/feedback/ID.pdf, and DIR/feedback/index.csv (id, name, email, file, total)")
    grading.add_argument("--feedback-format", choices=("pdf", "html"), default=None,
                         help="pdf (default), or html: a self-contained page per student (implies --feedback)")
    grading.add_argument("--force", action="store_true",
                         help="replace an output folder an earlier run of this command wrote (as its "
                              ".grader-manifest.json says)")
    grading.add_argument("--json", action="store_true", help="print a summary object on stdout")

    checking = commands.add_parser(
        "check", help="grade one answer as grader grade would: against a key's part, or a given value",
        negative_values=True,
        description="Grade one answer: against a student's part of a key (--key, --student, --label), or against "
                    "--expected with --unit, a tolerance and, for an expression, --symbols and --domain. "
                    "--batch reads one JSON object a line and prints one result a line.")
    checking.add_argument("answer", nargs="?", metavar="ANSWER", help="what the student typed, e.g. \"6.3 m/s\"")
    checking.add_argument("--key", type=Path, metavar="DIR/key.json", help="the key grader generate wrote")
    checking.add_argument("--student", metavar="ID", help="a student id (or email) of the key")
    checking.add_argument("--label", metavar="LABEL", help="the part as printed on the sheet, e.g. 1a")
    checking.add_argument("--expected", metavar="VALUE", help="the right answer: a number, or an expression")
    checking.add_argument("--unit", metavar="UNIT", help="the expected answer's unit (default: none)")
    checking.add_argument("--rtol", type=float, metavar="X", help="relative tolerance (default 0.01)")
    checking.add_argument("--atol", type=float, metavar="X", help="absolute tolerance, in --unit (default 0)")
    checking.add_argument("--sigfigs", type=int, metavar="N", help="correct to N significant figures")
    checking.add_argument("--decimals", type=int, metavar="N", help="correct to N decimal places")
    checking.add_argument("--symbols", metavar="NAMES", help="an expression's names, e.g. p,v (default: those "
                                                                   "--expected uses)")
    checking.add_argument("--domain", action="append", default=[], metavar="NAME=LOW:HIGH", dest="domains",
                          help="where a symbol is sampled (repeatable; default 1:10)")
    _bank_options(checking)
    checking.add_argument("--json", action="store_true", help="print the result as one JSON object")
    checking.add_argument("--batch", type=Path, metavar="FILE.jsonl",
                          help="one JSON object a line: submitted, expected, unit, tolerance, symbols, domains "
                               "(or, with --key, submitted, student, label); - reads standard input")

    demo = commands.add_parser("demo", help="the whole job on shipped sample data (5 problems, 30 students)")
    _bank_options(demo)
    demo.add_argument("--out", type=Path, default=Path("grader-demo"), metavar="DIR",
                      help="output folder (default: ./grader-demo)")
    _output_options(demo)

    effects = commands.add_parser(
        "effects", help="the effects a scene is made of: fields, relations, stable forms, force law, mistakes, figure",
        description="Without NAME: every effect with its summary. With NAME: that effect in full: its fields, its "
                    "relations as a student writes them for representative stages, the stable forms the kernels "
                    "use, the force law the simulation integrates, the mistakes the grader diagnoses, other "
                    "routes, and how its figure is drawn today.")
    effects.add_argument("name", nargs="?", metavar="NAME", help="an effect, e.g. impact")
    effects_output = effects.add_mutually_exclusive_group()
    effects_output.add_argument("--json", action="store_true",
                                help="print JSON: one object for NAME, else a list of every effect's")
    effects_output.add_argument("--markdown", action="store_true",
                                help="print the Markdown page docs/effects.md is (NAME: that effect's section only)")

    checking_bank = commands.add_parser(
        "check-bank", help="check every template of a bank, for authors: loads, samples, solves, simulates, renders",
        description="Check every template: it loads; 200 sampled variants each solve or are refused by a "
                    "constraint; no answer of a valid draw sits near zero; the statement fills in; the simulation "
                    "agrees with the closed form on 4 variants; the figure and worked solution typeset. One line "
                    "per template; exit code 2 when any fails.")
    _bank_options(checking_bank)
    checking_bank.add_argument("--json", action="store_true", help="one JSON object per template")

    cache = commands.add_parser(
        "cache", help="where compiled templates are kept, and how much; 'clear' removes grader's entries",
        description="Compiled templates and what YAML files read as are kept in $GRADER_CACHE_DIR, else "
                    "$XDG_CACHE_HOME/grader, else ~/.cache/grader. 'grader cache' says where and how much; "
                    "'grader cache clear' removes grader's own entries there (nothing else in the folder).")
    cache.add_argument("action", nargs="?", choices=("info", "clear"), default="info",
                       help="info (default): where and how much; clear: remove grader's entries")
    cache.add_argument("--json", action="store_true", help="print one JSON object")
    return parser


def _bank_options(command: argparse.ArgumentParser, where: str = "") -> None:
    """``--bank DIR`` (repeatable) and ``--no-shipped-bank``, before or after the command's name
    (separate destinations: argparse would let a subcommand's defaults replace the main parser's)."""
    command.add_argument("--bank", type=Path, action="append", default=[], metavar="DIR", dest=f"banks{where}",
                         help="also use the templates in DIR (repeatable; the shipped bank is included)")
    command.add_argument("--no-shipped-bank", action="store_true", dest=f"no_shipped_bank{where}",
                         help="leave out the shipped templates (then give --bank DIR)")


def _output_options(command: argparse.ArgumentParser) -> None:
    command.add_argument("--jobs", type=int, default=1, metavar="N", help="render PDFs in N parallel jobs")
    command.add_argument("--force", action="store_true",
                         help="replace an output folder an earlier run of this command wrote (as its "
                              ".grader-manifest.json says)")
    command.add_argument("--font-dir", type=Path, action="append", default=[], metavar="DIR", dest="font_dirs",
                         help="also use the fonts in DIR (repeatable), e.g. for names in scripts the embedded "
                              "fonts and any installed Noto CJK / emoji fonts lack")


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit code.

    A file-system error (a full disk, a read-only folder, a name too long, a full or closed standard
    output) is one line naming the path and the reason, exit code 2; other exceptions are bugs and keep
    their traceback. A reader that stops early (``grader list | head -1``) ends the run quietly.
    """
    arguments = build_parser().parse_args(argv)
    if sys.stdout is None:  # started with standard output closed (`grader ... >&-`)
        return _error("standard output is closed; send the output to a file or a program")
    previous = _handle_sigterm()
    try:
        code = _COMMANDS[arguments.command](arguments)
        sys.stdout.flush()
        return code
    except GraderError as error:
        return _error(str(error))
    except KeyboardInterrupt:
        # Cleanup ran on the way out (work folders removed, the previous output kept).
        _error("interrupted; nothing was left half-written")
        return EXIT_INTERRUPTED
    except BrokenPipeError:
        _discard_stdout()
        return EXIT_OK
    except OSError as error:
        # Every file error of this package names its path (write_atomic and output_folder add it where
        # the operating system does not), so one that names none comes from writing standard output.
        if error.filename is None:
            _discard_stdout()
            return _error(f"cannot write to standard output ({error.strerror}); free some space, or send the "
                          "output to a file or program that takes it")
        from grader.base.files import describe_os_error

        return _error(describe_os_error(error))
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)


def _handle_sigterm() -> Any:
    """Handle SIGTERM with :func:`_terminated`; the handler it replaces, or None in a thread other than the
    main one (where Python sets none: tests run the CLI in threads)."""
    try:
        return signal.signal(signal.SIGTERM, _terminated)
    except ValueError:  # not the main thread
        return None


def _terminated(signum: int, frame: object) -> None:
    """SIGTERM (``kill``, ``timeout``) unwinds like Ctrl-C, so work folders are removed."""
    raise KeyboardInterrupt


def _error(message: str) -> int:
    print(f"grader: error: {_printable(message)}", file=sys.stderr)
    return EXIT_USAGE


def _printable(message: str) -> str:
    r"""One line, with no control character a terminal would act on (input is echoed in messages).

    >>> _printable("cannot read unit '\x1b[31mred'\nsecond line")
    "cannot read unit '\\x1b[31mred'; second line"
    """
    return visible("; ".join(message.strip().split("\n")))


def _discard_stdout() -> None:
    """Send what is still buffered for a stdout that fails to the null device, so that Python's own
    flush at exit does not fail again with a traceback."""
    try:
        null = os.open(os.devnull, os.O_WRONLY)
        os.dup2(null, sys.stdout.fileno())
        os.close(null)
    except (OSError, ValueError):  # a stdout with no file descriptor (tests capture it) needs nothing
        pass


def _bank(arguments: argparse.Namespace) -> dict[str, Template]:
    from grader.bank.template import load_banks

    return load_banks(*_bank_sources(arguments))


def _lazy_bank(arguments: argparse.Namespace) -> Mapping[str, Template]:
    """The banks as a mapping that reads a template when it is asked for (grading needs the few a key names)."""
    from grader.bank.template import Banks

    return Banks(*_bank_sources(arguments))


def _bank_sources(arguments: argparse.Namespace) -> tuple[list[Path], bool]:
    """The ``--bank`` folders (given before or after the command), and whether the shipped bank is in."""
    return ([*arguments.banks_global, *arguments.banks],
            not (arguments.no_shipped_bank_global or arguments.no_shipped_bank))


def _template(arguments: argparse.Namespace) -> Template:
    """The template the command names (:func:`grader.bank.template.find_template`)."""
    from grader.bank.template import find_template

    return find_template(arguments.template, *_bank_sources(arguments))


def _list(arguments: argparse.Namespace) -> int:
    from grader.bank.listing import listing

    by_topic = _by_topic(listing(*_bank_sources(arguments)))
    if arguments.json:
        for template in by_topic:
            print(json.dumps({"id": template.id, "title": template.title, "topic": template.topic,
                              "version": template.version, "file": template.where,
                              "parameters": list(template.parameters), "answers": list(template.answers)}))
        return EXIT_OK
    rows = [("  " + t.id, t.title, ", ".join(t.parameters), ", ".join(t.answers)) for t in by_topic]
    lines = _table(("  id", "title", "parameters", "answers"), rows).splitlines()
    output, topic = [lines[0], "  " + lines[1][2:]], None
    for template, line in zip(by_topic, lines[2:], strict=True):
        if template.topic != topic:
            topic = template.topic
            output.append(f"{topic[0].upper()}{topic[1:]}")
        output.append(line)
    print("\n".join(output))
    return EXIT_OK


def _by_topic(templates: Iterable[Listed]) -> list[Listed]:
    """Templates grouped by topic, in the order of :data:`TOPICS`, each group by id."""
    from grader.bank.folders import TOPICS

    return sorted(templates, key=lambda t: (TOPICS.index(t.topic), t.id))


def _show(arguments: argparse.Namespace) -> int:
    import textwrap

    from grader.model.expr import to_text
    from grader.model.roots import TOLERANCE_TEXT
    from grader.render.preview import example_printed, example_statement
    from grader.render.readable import readable
    from grader.render.worked import reader_names
    from grader.solve.cache import compiled_for
    from grader.solve.evaluate import solve_one

    template = _template(arguments)
    compiled = compiled_for(template)
    names = reader_names(template, compiled)
    printed = example_printed(template)
    example = solve_one(template, compiled, {n: float(v) for n, v in printed.items()})
    if arguments.json:
        print(json.dumps({
            "id": template.id, "title": template.title, "topic": template.topic, "version": template.version,
            "file": template.where, "statement": example_statement(template), "example": printed,
            "example_answers": None if example.answers is None else
            {name: value.to_json() for name, value in example.answers.items()},
            "parameters": {n: {"unit": p.unit.text, "domain": str(p.domain), "integer": p.integer,
                               "description": p.description} for n, p in template.parameters.items()},
            "answers": {n: {"unit": a.unit.text, "description": a.description, "symbolic": list(a.symbolic)}
                        for n, a in template.answers.items()},
            "steps": [{"unknown": s.unknown, "relation": s.relation, "solved": to_text(readable(s.solved, names))}
                      for s in compiled.steps]}))
        return EXIT_OK
    scene = template.scene
    lines = [f"{template.id} (version {template.version}): {template.title}",
             f"topic: {template.topic}; file: {template.where}", "", "Statement, with example numbers:"]
    for paragraph in example_statement(template).split("\n\n"):  # a paragraph's line breaks are spaces here
        lines += [*textwrap.wrap(" ".join(paragraph.split()), 100, initial_indent="  ", subsequent_indent="  "), ""]
    print("\n".join(map(visible, lines)))  # the template's text shown, an escape sequence in it never acted on
    print("Answers for these numbers:")
    _print_solution(template, example.params, example.answers, example.error, False, None)
    lines = ["", "Bodies:"]
    lines += [f"  {b.name}: {'fixed surface' if b.mass is None else 'mass ' + to_text(b.mass)}"
              + (f", radius {to_text(b.radius)}" if b.radius is not None else "") for b in scene.bodies.values()]
    lines += ["", "Stages:"]
    lines += [f"  {s.index + 1}. {s.effect}: " + ", ".join(f"{k}={v}" for k, v in s.source.items())
              for s in scene.stages]
    lines += ["", "Parameters:"]
    lines += [f"  {n:<10} {p.unit.text or '-':<6} {p.domain!s:<12} {p.description}"
              + (" (a whole number)" if p.integer else "") for n, p in template.parameters.items()]
    lines += ["", "Answers:"]
    lines += [f"  {n:<10} {a.unit.text or '-':<6} {a.description}" for n, a in template.answers.items()]
    lines += ["", "Step chain (one equation, one unknown):"]
    for number, step in enumerate(compiled.steps, 1):
        lhs, rhs, solved = (to_text(readable(side, names)) for side in (*step.equation, step.solved))
        lines += [f"  {number}. {step.relation}", f"       {lhs} = {rhs}", f"       => {step.unknown} = {solved}"]
        if step.block and step.unknown == step.block[0]:
            how = f" numerically (to {TOLERANCE_TEXT}, relative; the first step's root(...) is found by the kernel)" \
                if step.numeric else ""
            lines.insert(-3, f"  (steps {number}-{number + len(step.block) - 1}: these equations solved together{how} "
                             f"for {', '.join(step.block)})")
    print("\n".join(map(visible, lines)))
    return EXIT_OK


def _solve(arguments: argparse.Namespace) -> int:
    from grader.solve.batch import json_lines, read_assignments, read_batch
    from grader.solve.cache import compiled_for
    from grader.solve.evaluate import solve_batch, solve_columns, solve_one

    template = _template(arguments)
    if arguments.batch is not None:
        batch = read_batch(arguments.batch, template)
        compiled = compiled_for(template)
        if arguments.json:
            result = solve_columns(template, compiled, batch.columns)
            for lines in json_lines(template, compiled, batch, result):
                sys.stdout.write(lines)
            refused = any(e is not None or r is not None for e, r in zip(batch.errors, result.refusals, strict=True))
            return EXIT_REFUSED if refused else EXIT_OK
        refused = False
        for row, solution in enumerate(solve_batch(template, compiled, batch.columns)):
            error = batch.errors[row] or solution.error
            refused |= error is not None
            params = batch.cells(row) if batch.errors[row] else solution.params
            _print_solution(template, params, solution.answers if error is None else None, error, False, row + 1)
        return EXIT_REFUSED if refused else EXIT_OK
    params = read_assignments(arguments.assignments, template)
    solution = solve_one(template, compiled_for(template), params)
    _print_solution(template, solution.params, solution.answers, solution.error, arguments.json, None)
    return EXIT_REFUSED if solution.error else EXIT_OK


def _print_solution(template: Template, params: Any, answers: Any, error: str | None, as_json: bool,
                    row: int | None) -> None:
    if as_json:
        from grader.solve.batch import record

        print(json.dumps(record(template, params, answers, error, row), allow_nan=False))
        return
    heading = f"{template.id}" + (f", row {row}" if row is not None else "") + ": " + ", ".join(
        f"{name} = {_number(value)}{_unit(template.parameters[name])}" for name, value in params.items()
        if name in template.parameters and isinstance(value, float))
    print(heading)
    if error is not None:
        print(f"  refused: {error}")
        return
    for name, value in answers.items():
        unit = f" {value.unit}" if value.unit and isinstance(value.value, float) else ""
        shown = _number(value.value) if isinstance(value.value, float) else value.value
        print(f"  {name:<12} {'undefined (' + value.undefined + ')' if value.undefined else str(shown) + unit}")


def _number(value: float) -> str:
    return f"{value:.5g}" if value == value else "nan"


def _unit(parameter: Parameter) -> str:
    return f" {parameter.unit.text}" if parameter.unit.text else ""


def _table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    widths = [max(len(str(r[i])) for r in [header, *rows]) for i in range(len(header))]
    lines = ["  ".join(str(cell).ljust(width) for cell, width in zip(row, widths, strict=True)).rstrip()
             for row in [header, *rows]]
    lines.insert(1, "  ".join("-" * w for w in widths))
    return "\n".join(lines)


def _simulate(arguments: argparse.Namespace) -> int:
    from grader.physics.integrate import Settings
    from grader.physics.record import Options
    from grader.simulate.comparison import comparison
    from grader.simulate.walker import simulate
    from grader.solve.batch import read_assignments
    from grader.solve.cache import compiled_for
    from grader.solve.evaluate import solve_one

    template = _template(arguments)
    params = read_assignments(arguments.assignments, template)
    if arguments.method == "adaptive" and arguments.steps_per_contact is not None:
        raise UsageError("--steps-per-contact is for the fixed-step methods (euler, rk4); use --rtol with adaptive")
    if arguments.method != "adaptive" and arguments.rtol is not None:
        raise UsageError("--rtol is for the adaptive method; use --steps-per-contact with euler or rk4")
    settings = Settings(arguments.method,
                        100 if arguments.steps_per_contact is None else arguments.steps_per_contact,
                        1e-10 if arguments.rtol is None else arguments.rtol, dense=arguments.plot is not None)
    options = Options(settings, arguments.contact_duration, arguments.weight_during_contact)
    if arguments.plot is not None:
        from grader.simulate.plots import check_plot_target, plot_simulation

        check_plot_target(arguments.plot)  # before any work: nothing is written for a name we cannot write
    closed = solve_one(template, compiled_for(template), params)
    if closed.error is not None:
        _print_solution(template, closed.params, None, closed.error, arguments.json, None)
        return EXIT_REFUSED
    result = simulate(template, params, options)
    if arguments.plot is not None:
        plot_simulation(result, arguments.plot)
    record = comparison(result, closed.answers or {}, options)
    if arguments.json:
        print(json.dumps(record, allow_nan=False))
        return EXIT_OK
    _print_simulation(template, record)
    return EXIT_OK


def _print_simulation(template: Template, record: dict[str, Any]) -> None:
    method = record["method"] + (f" (rtol {record['settings']['rtol']:g})" if record["method"] == "adaptive"
                                 else f" ({record['settings']['steps_per_contact']} steps per contact)")
    print(f"{template.id}: " + ", ".join(f"{n} = {_number(v)}{_unit(template.parameters[n])}"
                                         for n, v in record["params"].items()))
    print(f"simulated: {', '.join(record['effects'])}; {method}; {record['steps']} steps in "
          f"{record['seconds'] * 1e3:.1f} ms")
    for contact in record["contacts"]:
        print(f"{contact['impact']}: Kelvin-Voigt contact of {contact['duration'] * 1e3:g} ms, zeta = "
              f"{contact['zeta']:.4f}, measured e = separation/approach = {contact['measured_e']:.10g}")
    for note in record["notes"]:
        print(note)
    from grader.model.expr import to_text

    restitutions = {to_text(s.fields["restitution"]) for s in template.scene.stages if s.effect == "impact"}
    for name, value in record["fitted"].items():
        found = f"contact law calibrated to {name}" if name in restitutions else name
        print(f"{name} not given: {found} = {value:.10g}, found so that the simulated outcome matches the given one")
    if record["nominal"]:
        print("symbols set to 1 for the simulation: " + ", ".join(record["nominal"]))
    print(_table(("answer", "simulated", "closed form", "rel. diff"), [
        (name, "undefined" if row["simulated"] is None else f"{row['simulated']:.10g}",
         "undefined" if row["closed_form"] is None else f"{row['closed_form']:.10g}",
         "-" if row["rel_diff"] is None else f"{row['rel_diff']:.2g}") for name, row in record["answers"].items()]))
    reasons = {why for row in record["answers"].values() for why in (row["undefined"] or {}).values()}
    for why in sorted(reasons):
        print(f"undefined: {why}")


def _generate(arguments: argparse.Namespace) -> int:
    from grader.render.generate import Job, run

    _check_jobs(arguments.jobs)
    job = Job(arguments.assignment, arguments.roster, arguments.out, pdf=not arguments.no_pdf,
              jobs=arguments.jobs, keep_source=arguments.keep_source, force=arguments.force,
              font_dirs=tuple(arguments.font_dirs))
    _print_summary(run(job, _bank(arguments)))
    return EXIT_OK


def _demo(arguments: argparse.Namespace) -> int:
    from grader.demo import FEEDBACK, GRADES, KEY, SUBMISSIONS, demo

    _check_jobs(arguments.jobs)
    summary = demo(arguments.out, _bank(arguments), jobs=arguments.jobs, force=arguments.force,
                   font_dirs=tuple(arguments.font_dirs))
    _print_summary(summary.generated)
    out = summary.generated.out
    print(f"{SUBMISSIONS} (simulated answers) graded: {_graded_line(summary.graded)}")
    print(f"Each student's graded sheet, with their worked solutions: {out / GRADES / FEEDBACK}")
    print(f"The assignment and roster it used are in {out}: edit them and run\n"
          f"  grader generate {_quoted(out / 'assignment.yaml')} --roster {_quoted(out / 'roster.csv')} --out OTHER\n"
          f"Grade the submissions again, or your own file, with\n"
          f"  grader grade --key {_quoted(out / KEY)} {_quoted(out / SUBMISSIONS)} --out {_quoted(out / GRADES)} "
          "--feedback --force")
    return EXIT_OK


def _quoted(path: Path) -> str:
    return shlex.quote(str(path))


def _check_jobs(jobs: int) -> None:
    if jobs < 1:
        raise UsageError(f"--jobs must be 1 or more, got {jobs}")


def _print_summary(summary: Any) -> None:
    collided = {key: n for key, n in summary.collisions.items() if n}
    print(f"{summary.students} students x {summary.problems} problems -> {summary.out} "
          f"({summary.files} files, {summary.seconds:.1f} s)")
    if collided:
        print("students sharing their numbers with another (the parameter space is small): " +
              ", ".join(f"problem {key}: {n}" for key, n in collided.items()))


def _grade(arguments: argparse.Namespace) -> int:
    from grader.grade.run import run as run_grading

    feedback = None
    if arguments.feedback or arguments.feedback_format:
        from grader.handback import FOLDER, feedback_writer

        feedback = feedback_writer(arguments.feedback_format or "pdf", _lazy_bank(arguments))
    summary = run_grading(arguments.key, arguments.submissions, arguments.out, arguments.format, arguments.force,
                          arguments.canvas, _lazy_bank(arguments), arguments.missing, feedback)
    print(_graded_line(summary), file=sys.stderr)
    if feedback is not None:
        print(f"each student's graded sheet -> {arguments.out / FOLDER} (index.csv lists them)", file=sys.stderr)
    if summary.ignored_columns:
        print(f"columns ignored: {some(list(summary.ignored_columns))}", file=sys.stderr)
    for note in summary.notes:
        print(f"note: {_printable(note)}", file=sys.stderr)
    if arguments.json:
        print(json.dumps(summary.to_json(), allow_nan=False))
    return EXIT_REFUSED if summary.rows_not_graded else EXIT_OK


def _graded_line(summary: GradeSummary) -> str:
    """``30 students (29 submitted), 450 parts graded (...); 1 row set aside (superseded or not a student),
    0 rows not graded (see problems.csv) -> OUT``."""
    verdicts = ", ".join(f"{n} {kind}" for kind, n in summary.verdicts.items() if n)
    aside = f"{_rows(summary.rows_set_aside)} set aside (superseded or not a student), " if summary.rows_set_aside \
        else ""
    return (f"{summary.students} students ({summary.submitted} submitted), {summary.parts} parts graded ({verdicts}); "
            f"{aside}{_rows(summary.rows_not_graded)} not graded (see problems.csv) -> {summary.out}")


def _rows(n: int) -> str:
    return f"{n} row{'' if n == 1 else 's'}"


def _check(arguments: argparse.Namespace) -> int:
    from grader.grade import check
    from grader.grade.diagnosis import physics_for
    from grader.grade.key import load_key

    asked = check.Asked(arguments.answer, arguments.key, arguments.student, arguments.label, arguments.expected,
                        arguments.unit, arguments.rtol, arguments.atol, arguments.sigfigs, arguments.decimals,
                        arguments.symbols, tuple(arguments.domains), arguments.batch)
    asked.refuse_a_mix()
    key = load_key(asked.key) if asked.key is not None else None
    physics = physics_for(key, _lazy_bank(arguments)) if key is not None else None
    if asked.batch is not None:
        failed = 0
        for block, errors in check.json_blocks(check.batch_lines(asked.batch), key, physics):
            print(block)
            failed += errors
        return EXIT_REFUSED if failed else EXIT_OK
    result = check.check(arguments.answer, asked.against(key, physics))
    if arguments.json:
        print(check.json_line(result))
    else:
        _print_check(result)
    return EXIT_OK


def _print_check(result: dict[str, Any]) -> None:
    def amount(value: object) -> str:
        return "" if value is None else f"{value:.6g} {result['unit']}".rstrip() if isinstance(value, float) \
            else str(value)

    rows = [("verdict", f"{result['verdict']} (credit {result['credit']:g})"), ("read as", amount(result["parsed"])),
            ("expected", "undefined" if result["expected"] is None else amount(result["expected"])),
            ("error", "" if result["abs_error"] is None else
             f"{amount(result['abs_error'])} ({min(100 * result['rel_error'], sys.float_info.max):.2g} %)"),
            ("tolerance", result["tolerance"] + (f" (widened: {result['tolerance_reason']})"
                                                 if result["tolerance_reason"] else "")),
            ("feedback", result["feedback"]), ("diagnosis", result["diagnosis"])]
    for name, text in rows:
        if text:
            print(f"{name:<10} {_printable(text)}")


def _effects(arguments: argparse.Namespace) -> int:
    """The catalogue of effects; listing it needs no sympy, an effect in full does (its relations)."""
    from grader.physics.effects import CATALOGUE

    names = sorted(CATALOGUE)
    if arguments.name is not None and arguments.name not in CATALOGUE:
        close = close_matches(arguments.name, names)
        hint = f" (did you mean {' or '.join(close)}?)" if close else ""
        raise UsageError(f"unknown effect '{arguments.name}'{hint}; the effects are {', '.join(names)}")
    if arguments.name is None and not (arguments.json or arguments.markdown):
        print(_table(("effect", "summary"), [(name, CATALOGUE[name].summary) for name in names]))
        return EXIT_OK
    from grader.render.reference import sheet
    from grader.render.reference_text import markdown, text

    sheets = [sheet(name) for name in ([arguments.name] if arguments.name is not None else names)]
    if arguments.json:
        found = [s.to_json() for s in sheets]
        print(json.dumps(found[0] if arguments.name is not None else found, allow_nan=False))
    elif arguments.markdown:
        print(markdown(sheets), end="")
    else:
        print(text(sheets[0]))
    return EXIT_OK


def _check_bank(arguments: argparse.Namespace) -> int:
    from grader.bank.folders import template_paths
    from grader.bankcheck import check_bank

    sources = _bank_sources(arguments)
    width = max(len(path.stem) for path in template_paths(*sources))
    failed = total = 0
    for report in check_bank(*sources):
        total += 1
        failed += report.problem is not None
        if arguments.json:
            print(json.dumps(report.to_json(), allow_nan=False), flush=True)
        else:
            verdict = f"ok    {report.checked} ({report.seconds:.1f} s)" if report.problem is None \
                else f"FAIL  {_printable(report.problem)}"
            print(f"{report.template:<{width}}  {verdict}", flush=True)
    if not arguments.json:
        print(f"{total} template{'' if total == 1 else 's'}: " +
              (f"{failed} failed" if failed else "all passed"))
    return EXIT_USAGE if failed else EXIT_OK


def _cache(arguments: argparse.Namespace) -> int:
    from grader.base import caching

    try:
        folder = caching.cache_dir()
    except RuntimeError:  # Path.home() found none
        raise UsageError("there is no home folder to keep a cache in; set GRADER_CACHE_DIR to a folder") from None
    if folder.exists() and not folder.is_dir():
        raise UsageError(f"the cache folder {folder} is a file, not a folder; set GRADER_CACHE_DIR to a folder")
    if arguments.action == "clear":
        removed, freed = caching.clear(folder)
        summary = {"folder": str(folder), "removed": removed, "bytes": freed}
        said = f"removed {removed} entries ({_size(freed)}) from {folder}"
    else:
        entries = caching.grader_entries(folder)
        size = sum(path.stat().st_size for path in entries)
        summary = {"folder": str(folder), "entries": len(entries), "bytes": size}
        said = f"{folder}: {len(entries)} entries, {_size(size)}"
    print(json.dumps(summary) if arguments.json else visible(said))
    return EXIT_OK


def _size(size: int) -> str:
    """A number of bytes as a person reads it.

    >>> _size(512), _size(20_480), _size(3_500_000)
    ('512 bytes', '20 KiB', '3.3 MiB')
    """
    if size < 1024:
        return f"{size} bytes"
    return f"{size / 1024:.0f} KiB" if size < 1024 * 1024 else f"{size / (1024 * 1024):.1f} MiB"


_COMMANDS = {"list": _list, "show": _show, "solve": _solve, "simulate": _simulate, "generate": _generate,
             "demo": _demo, "grade": _grade, "check": _check, "check-bank": _check_bank, "effects": _effects,
             "cache": _cache}
