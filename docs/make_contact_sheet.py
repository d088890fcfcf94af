"""The contact sheet of figures: every shipped template's figure, the test bank's scenes written for issue
26 (``tests/data/figures``) and issue 25's trial templates of the new effects (``tests/data``), each at its
example's values as a sheet prints them, titled with its template and the effects its panels draw. It ends
with the effects of the catalogue that no figure on it draws (none, when every effect's panel is shown).

Run: ``python docs/make_contact_sheet.py [--out docs/images/figures.png] [--ppi 110] [--only ID,ID]``;
``--only`` draws just those templates (to look at a few closely, at a higher ``--ppi``).
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from grader.assign.variants import ProblemVariant  # noqa: E402
from grader.bank.template import Template, load_bank, load_template  # noqa: E402
from grader.base.resources import templates_dir  # noqa: E402
from grader.physics.effects import CATALOGUE  # noqa: E402
from grader.render.figures import figure_record  # noqa: E402
from grader.render.panels import ANNOTATIONS, PANELS  # noqa: E402
from grader.render.preview import example_printed  # noqa: E402
from grader.render.typeset import compile_typst  # noqa: E402
from grader.render.typst_text import string  # noqa: E402
from grader.render.worked import chain_values, si_parameters  # noqa: E402
from grader.solve.cache import compiled_for  # noqa: E402

DATA = ROOT / "tests" / "data"
TRIALS = ("bullet-spring", "package-platform", "ramp-and-floor", "incline-up-and-back", "intersection",
          "intersection-reconstruction", "explosion", "recoil", "ball-wall-impulse", "cushion", "oblique-both-moving")
"""Issue 25's trial templates of the new effects (as ``tests/test_figures.py`` lists them)."""


def sections() -> list[tuple[str, list[Template]]]:
    """The templates on the sheet, by where they come from."""
    shipped = load_bank()
    written = [load_template(path) for path in sorted((DATA / "figures").glob("*.yaml"))]
    trials = [load_template(DATA / f"{name}.yaml") for name in TRIALS]
    return [(f"Shipped templates ({len(shipped)})", [shipped[key] for key in sorted(shipped)]),
            (f"Test-bank scenes written for issue 26, tests/data/figures ({len(written)})", written),
            (f"Trial templates of the new effects, tests/data ({len(trials)})", trials)]


def example_figure(template: Template) -> tuple[str, list[str]]:
    """The template's figure at its example's values (Typst, code mode) and the effects its panels draw."""
    printed = example_printed(template)
    variant = ProblemVariant("1", template.id, "example", {n: float(v) for n, v in printed.items()}, printed, ())
    given = {**si_parameters(template, variant), **dict.fromkeys(template.symbols, 1.0)}
    typst, record = figure_record(template, variant, chain_values(compiled_for(template), given))
    stages = template.scene.stages
    effects = [stages[i].effect for panel in record.panels for i in panel.stages if stages[i].effect not in ANNOTATIONS]
    return str(typst), list(dict.fromkeys(effects))


def source(chosen: Sequence[tuple[str, list[Template]]]) -> tuple[str, set[str]]:
    """The sheet as a Typst document, and the effects whose panels it shows."""
    shown: set[str] = set()
    parts = [(templates_dir() / "figures.typ").read_text(encoding="utf-8"),
             '#set page(width: 17cm, height: auto, margin: 0.8cm)',
             '#set text(font: "Libertinus Serif", size: 10.5pt)',
             "= Figures: every template's, at its example's values"]
    for heading, templates in chosen:
        if not templates:
            continue
        parts.append(f"== {heading}")
        for template in templates:
            typst, effects = example_figure(template)
            shown.update(effects)
            said = ", ".join(effects) or "no panel"
            parts.append(f"#block(breakable: false, above: 0.5cm, stroke: (top: 0.4pt + luma(190)), inset: "
                         f"(top: 0.25cm), grid(columns: (3.6cm, 1fr), column-gutter: 0.4cm, "
                         f"[#text(weight: \"bold\", {string(template.id)}) \\ #text(size: 8pt, fill: luma(90), "
                         f"{string(said)})], {typst}))")
    return "\n\n".join(parts) + "\n", shown


def _write_small(png: bytes, out: Path) -> None:
    """The page in 16 grays (the figures are black on white with gray fills): a quarter of the bytes."""
    import io

    from PIL import Image  # matplotlib's dependency

    Image.open(io.BytesIO(png)).convert("L").quantize(16).save(out, optimize=True)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("--out", type=Path, default=ROOT / "docs" / "images" / "figures.png")
    parser.add_argument("--ppi", type=float, default=110.0)
    parser.add_argument("--only", default="", help="comma-separated template ids: just these")
    arguments = parser.parse_args(argv)
    only = {name for name in arguments.only.split(",") if name}
    chosen = [(heading, [t for t in templates if not only or t.id in only]) for heading, templates in sections()]
    text, shown = source(chosen)
    if arguments.out.suffix == ".typ":
        arguments.out.write_text(text, encoding="utf-8")
        return 0
    pages = compile_typst(text, fmt="png", ppi=arguments.ppi)
    _write_small(pages[0] if isinstance(pages, list) else pages, arguments.out)
    drawn = set(PANELS) & set(CATALOGUE)
    if not only:
        print(f"{arguments.out}: {sum(len(t) for _, t in chosen)} figures; effects with a panel not shown: "
              f"{', '.join(sorted(drawn - shown)) or 'none'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
