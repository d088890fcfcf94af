"""The documentation is true: each ``$ grader ...`` line of README.md and docs/*.md prints what the page
shows, each Python example runs, each relative link reaches a file (and a heading), and the CLI reference
names every command and option the parser has."""

from __future__ import annotations

import argparse
import doctest
import re
import shlex
import subprocess
import sys
import unicodedata
from pathlib import Path

import pytest

from grader.cli import build_parser
from tests.documents import PAGES, ROOT, text

README = text(ROOT / "README.md")


def _console_examples() -> list[tuple[str, str, str]]:
    """(page, command, output) for every ``$ `` line of every ```console block, in page order."""
    examples = []
    for page in PAGES:
        for block in re.findall(r"```console\n(.*?)```", text(page), flags=re.S):
            for chunk in re.split(r"^\$ ", block, flags=re.M)[1:]:
                command, _, output = chunk.partition("\n")
                examples.append((page.name, command, output))
    return examples


@pytest.mark.parametrize(("page", "command", "expected"),
                         [pytest.param(*example, id=f"{example[0]}: {example[1][:60]}")
                          for example in _console_examples()])
def test_console_example_prints_what_the_page_shows(page: str, command: str, expected: str) -> None:
    """Running the command from the repository's folder gives the page's output, line for line: what it
    prints on standard output, then on standard error (an error message is an example too)."""
    words = shlex.split(command)
    assert words[0] == "grader", f"{page}: a console example runs grader, got {command!r}"
    result = subprocess.run([sys.executable, "-m", "grader", *words[1:]], capture_output=True, text=True,
                            cwd=ROOT, timeout=120)
    got = result.stdout.rstrip() + ("\n" + result.stderr.rstrip() if result.stderr.strip() else "")
    assert _matches(got.strip("\n"), expected.rstrip()), (page, result.stdout, result.stderr)


def _matches(got: str, expected: str) -> bool:
    """Line for line; ``...`` on a page stands for text that changes from run to run (timings)."""
    got_lines, expected_lines = got.splitlines(), expected.splitlines()
    if len(got_lines) != len(expected_lines):
        return False
    for line, pattern in zip(got_lines, expected_lines, strict=True):
        regex = ".*?".join(re.escape(part) for part in pattern.split("..."))
        if not re.fullmatch(regex, line):
            return False
    return True


def test_readme_opens_with_the_install_command_that_ci_runs() -> None:
    """CI installs exactly as the README tells a new user, and runs the README's test command."""
    first_block = re.search(r"```sh\n(.*?)```", README, flags=re.S)
    assert first_block is not None
    install = re.search(r"pip install -e '\.\[test\]'", first_block.group(1))
    assert install is not None
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8")
    assert "pip install -e '.[test]'" in ci
    assert ".venv/bin/python -m pytest -q" in README
    assert ".venv/bin/python -m pytest -q" in ci


def test_the_pages_have_console_examples() -> None:
    """The parametrized test above is not vacuous: the README and most pages show commands that run."""
    pages = {page for page, _, _ in _console_examples()}
    assert len(_console_examples()) >= 15
    assert {"README.md", "getting-started.md", "generating.md", "grading.md", "writing-templates.md"} <= pages


# --- Python examples: pytest's --doctest-glob runs README.md's; these are the pages' -----------------

@pytest.mark.parametrize("page", [p for p in PAGES if p.parent.name == "docs" and ">>> " in text(p)],
                         ids=lambda page: page.name)
def test_python_examples_of_a_page_run(page: Path) -> None:
    result = doctest.testfile(str(page), module_relative=False, optionflags=doctest.ELLIPSIS, report=True)
    assert result.attempted > 0 and result.failed == 0


# --- links ------------------------------------------------------------------------------------------

_LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)\)")


def _prose(markdown: str) -> str:
    """The page without its fenced blocks and code spans (a link shown as code is no link)."""
    return re.sub(r"`[^`\n]*`", "", re.sub(r"^```.*?^```", "", markdown, flags=re.S | re.M))


def _anchors(markdown: str) -> set[str]:
    """Each heading's anchor, as MkDocs makes it (and a code host, for headings of words and spaces)."""
    anchors = set()
    for heading in re.findall(r"^#{1,6} (.+)$", re.sub(r"^```.*?^```", "", markdown, flags=re.S | re.M), re.M):
        plain = unicodedata.normalize("NFKD", heading).encode("ascii", "ignore").decode()
        anchors.add(re.sub(r"[-\s]+", "-", re.sub(r"[^\w\s-]", "", plain).strip().lower()))
    return anchors


def _relative_links() -> list[tuple[Path, str]]:
    return [(page, target) for page in PAGES for target in _LINK.findall(_prose(text(page)))
            if not re.match(r"[a-z][a-z0-9+.-]*:", target)]


@pytest.mark.parametrize(("page", "target"), _relative_links(), ids=lambda value: getattr(value, "name", value))
def test_a_relative_link_reaches_a_file_and_its_heading(page: Path, target: str) -> None:
    path, _, anchor = target.partition("#")
    reached = (page.parent / path).resolve() if path else page
    assert reached.is_file(), f"{page.name}: {target} links to {reached}, which does not exist"
    assert reached.is_relative_to(ROOT), f"{page.name}: {target} leaves the repository"
    if anchor:
        assert reached.suffix == ".md" and anchor in _anchors(text(reached)), \
            f"{page.name}: {target}: no heading of {reached.name} has the anchor #{anchor}"


def test_the_pages_link_to_each_other() -> None:
    """The link test above is not vacuous, and every page of docs/ is reached from the README or another page."""
    linked = {(page.parent / target.partition("#")[0]).resolve() for page, target in _relative_links()}
    assert {page.resolve() for page in PAGES if page.parent.name == "docs"} <= linked


# --- the CLI reference ------------------------------------------------------------------------------

def _subcommands(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    actions = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    return dict(actions[0].choices) if actions else {}


def _options(parser: argparse.ArgumentParser) -> set[str]:
    """Every long option of a parser and of the subcommands under it, and the subcommands' names."""
    found = {o for a in parser._actions for o in a.option_strings if o.startswith("--") and o != "--help"}
    for name, sub in _subcommands(parser).items():
        found |= {name, *_options(sub)}
    return found


@pytest.mark.parametrize("command", sorted(_subcommands(build_parser())))
def test_the_cli_reference_describes_every_command_and_option(command: str) -> None:
    """docs/cli.md has a section ``## `grader COMMAND``` naming each of the command's options."""
    reference = text(ROOT / "docs" / "cli.md")
    heading = f"\n## `grader {command}"
    assert heading in reference, f"docs/cli.md: no section for grader {command}"
    section = reference.split(heading, 1)[1].split("\n## ", 1)[0]
    missing = sorted(o for o in _options(_subcommands(build_parser())[command]) if f"`{o}" not in section
                     and f" {o}" not in section)
    assert not missing, f"docs/cli.md: grader {command}'s section does not mention {', '.join(missing)}"


def test_the_cli_reference_describes_the_global_options() -> None:
    reference = text(ROOT / "docs" / "cli.md")
    options = {o for a in build_parser()._actions for o in a.option_strings if o.startswith("--") and o != "--help"}
    assert options and not sorted(o for o in options if f"`{o}" not in reference)


def test_every_page_the_code_cites_exists() -> None:
    """A comment or docstring that cites a page of docs/ (the design notes, say) cites a page that exists."""
    cited = {match for folder in ("grader", "tests", "benchmarks") for path in (ROOT / folder).rglob("*.py")
             for match in re.findall(r"docs/[\w-]+\.md", path.read_text(encoding="utf-8"))}
    assert "docs/design.md" in cited
    assert not sorted(page for page in cited if not (ROOT / page).is_file())
