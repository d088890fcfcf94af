"""The shipped bank's compiled forms, carried by the package so that a first run on a new machine pays for sympy
only for an instructor's own templates (:data:`grader.solve.cache.SHIPPED`).

``python -m grader.solve.ship`` compiles every template of the shipped bank afresh (its compiled form, its
alternatives, its routes: about a minute of sympy) and writes them under the names :func:`entry_name` gives,
removing the entries it finds there for source that is no more; ``--check`` only says what is missing or
stale (exit 1). Run it after changing the solver's source or a shipped template: ``tests/test_shipped.py``
fails until then, naming this command.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable, Iterable
from typing import Any

from grader.bank.template import Template, load_bank
from grader.base import caching
from grader.solve.cache import KINDS, SHIPPED, compiled_for, entry_name

BUILD_COMMAND = "python -m grader.solve.ship"


def expected_names(templates: Iterable[Template]) -> set[str]:
    """The entries the shipped bank's templates are looked up under, with today's source."""
    return {entry_name(template, kind) for template in templates for kind in KINDS}


def present_names() -> set[str]:
    """The entries the package carries."""
    return {path.name for path in SHIPPED.glob("*.json")}


def compilers() -> dict[str, Callable[[Template], Any]]:
    """What makes each kind of entry, with sympy, from nothing kept."""
    from grader.solve.derived import compile_alternatives
    from grader.solve.derived_routes import compile_routes
    from grader.solve.solver import compile_template

    # the routes follow the worked solution's page, made from the compiled form just written
    return {"": compile_template, "-alternatives": compile_alternatives,
            "-routes": lambda template: compile_routes(template, compiled_for(template))}


def build(templates: Iterable[Template]) -> tuple[int, int]:
    """Compile ``templates`` afresh into :data:`SHIPPED` and remove the entries no template of them is looked up
    under; the numbers written and removed."""
    templates = list(templates)
    SHIPPED.mkdir(parents=True, exist_ok=True)
    made = compilers()
    for template in templates:
        for kind, compile_now in made.items():
            name = entry_name(template, kind)
            caching.write_entry(SHIPPED / name, compile_now(template).to_json())
            print(f"  {name}", file=sys.stderr)
    stale = present_names() - expected_names(templates)
    for name in stale:
        (SHIPPED / name).unlink()
    return len(templates) * len(made), len(stale)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog=BUILD_COMMAND, description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("--check", action="store_true", help="only say whether the shipped entries are current")
    args = parser.parse_args(argv)
    bank = load_bank()
    if args.check:
        expected, present = expected_names(bank.values()), present_names()
        missing, extra = expected - present, present - expected
        for name in sorted(missing):
            print(f"missing: {name}")
        for name in sorted(extra):
            print(f"stale: {name}")
        return 1 if missing or extra else 0
    written, removed = build(bank.values())
    print(f"{written} entries written to {SHIPPED}, {removed} stale ones removed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
