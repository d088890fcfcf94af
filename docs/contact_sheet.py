"""Contact sheets, the pictures in ``docs/images`` an instructor reads to see the key and the sheets at a glance:

- ``figures.png``: every template's figure at its example's values as a sheet prints it, the shipped ones, the
  test bank's scenes written for issue 26 (``tests/data/figures``) and issue 25's trial templates of the new
  effects (``tests/data``), each titled with its template and the effects its panels draw;
- ``worked-by-effect.png``: one shipped template per effect of the catalogue, its worked solution as the answer
  key prints it for the demo roster's first student;
- ``sheets-by-template.png``: every shipped template's problem as the student's sheet prints it (statement,
  figure, blanks).

Every effect's route (momentum and restitution solved together, ``e = √(h′/h)``, ``tan⁻¹`` of components, unit
conversions as steps) and every figure, each on one page. Redo them when the key, the sheets or the figures
change their look::

    .venv/bin/python docs/contact_sheet.py            # writes all three images
    .venv/bin/python docs/contact_sheet.py --only figures --templates two-pendulums,incline-bounce --ppi 200 \
        --out /tmp/figures.png                          # a few figures, closely
    .venv/bin/python docs/contact_sheet.py --only worked --out /tmp/sheet.png --columns 3

For the worked solutions and the sheets, each template is an assignment of its own (one problem, one student),
compiled by Typst to PNG; a page is cut below its last line of ink and the pages are tiled left to right, each
titled by the effects it shows.
"""

from __future__ import annotations

import argparse
import dataclasses
import io
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


def figures_source(chosen: Sequence[tuple[str, list[Template]]]) -> tuple[str, set[str]]:
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


def figures_sheet(out: Path, ppi: float, only: set[str]) -> None:
    """Writes every template's figure (or those of ``only``), in sixteen grays (the figures are black on white
    with gray fills: a quarter of the bytes), to ``out``; a ``.typ`` ``out`` gets the Typst source."""
    from PIL import Image  # matplotlib's dependency

    chosen = [(heading, [t for t in templates if not only or t.id in only]) for heading, templates in sections()]
    text, shown = figures_source(chosen)
    if out.suffix == ".typ":
        out.write_text(text, encoding="utf-8")
        return
    pages = compile_typst(text, fmt="png", ppi=ppi)
    png = pages[0] if isinstance(pages, list) else pages
    Image.open(io.BytesIO(png)).convert("L").quantize(16).save(out, optimize=True)
    drawn = set(PANELS) & set(CATALOGUE)
    if not only:
        print(f"{out}: {sum(len(t) for _, t in chosen)} figures; effects with a panel not shown: "
              f"{', '.join(sorted(drawn - shown)) or 'none'}")


CHOSEN = ("head-on", "oblique-spheres", "billiards", "car-collision", "pile-driver", "drop-rebound",
          "ball-plate", "successive-bounces", "ballistic-pendulum", "package-bounce", "ramp-strike",
          "intersection-crash", "gun-recoil", "wall-impulse", "wall-throw", "incline-slide", "skid")
"""The templates shown, in order: together they take every effect of the catalogue the bank uses."""


def _pages(template_id: str, ppi: int, key: bool = True) -> list[bytes]:
    from grader.assign.assignment import ProblemSpec, load_assignment, load_roster
    from grader.assign.variants import generate
    from grader.base.resources import sample_dir
    from grader.render.documents import Documents, key_source, student_source

    bank = load_bank()
    assignment = load_assignment(sample_dir() / "assignment.yaml")
    assignment = dataclasses.replace(assignment, problems=(ProblemSpec("1", template_id, {"*": 1.0}, {}, {}, {}),))
    generation = generate(assignment, load_roster(sample_dir() / "roster.csv")[:1], bank)
    documents = Documents(assignment, generation, bank)
    source = key_source(documents, people=[0]) if key else student_source(documents, [0])
    pages = compile_typst(source, "png", ppi)
    return [pages] if isinstance(pages, bytes) else list(pages)


def _inked(page: bytes) -> object:
    """The page cut below its last line of ink, and its footer (the last 6 % of the page) left out."""
    from PIL import Image, ImageChops, ImageOps

    image = Image.open(io.BytesIO(page)).convert("RGB")
    body = image.crop((0, 0, image.width, int(image.height * 0.94)))
    box = ImageChops.difference(body, Image.new("RGB", body.size, "white")).getbbox()
    if box is None:
        return body
    return ImageOps.expand(body.crop((0, 0, body.width, min(body.height, box[3] + 12))), border=1, fill="#999999")


def contact_sheet(out: Path, columns: int, ppi: int, templates: tuple[str, ...] = CHOSEN, key: bool = True) -> None:
    """Writes the first page of each of ``templates``' worked solutions (``key``) or sheets, tiled, to ``out``."""
    from PIL import Image, ImageDraw

    bank = load_bank()
    tiles = []
    for template_id in templates:
        effects = sorted({stage.effect for stage in bank[template_id].scene.stages})
        tile = _inked(_pages(template_id, ppi, key)[0])
        titled = Image.new("RGB", (tile.width, tile.height + 28), "white")  # type: ignore[attr-defined]
        titled.paste(tile, (0, 28))  # type: ignore[arg-type]
        ImageDraw.Draw(titled).text((8, 6), f"{template_id}: {', '.join(effects)}", fill="black")
        tiles.append(titled)
    width = max(t.width for t in tiles)
    rows = [tiles[i:i + columns] for i in range(0, len(tiles), columns)]
    heights = [max(t.height for t in row) for row in rows]
    sheet = Image.new("RGB", (width * columns, sum(heights)), "white")
    top = 0
    for row, height in zip(rows, heights, strict=True):
        for index, tile in enumerate(row):
            sheet.paste(tile, (index * width, top))
        top += height
    out.parent.mkdir(parents=True, exist_ok=True)
    sheet.convert("L").quantize(16).save(out, optimize=True)  # grey text on white: 16 levels keep it sharp and small


def main(argv: Sequence[str] | None = None) -> int:
    images = ROOT / "docs" / "images"
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("--only", choices=("figures", "worked", "sheets"), help="write one of the three images")
    parser.add_argument("--out", type=Path, help="where to write it (with --only)")
    parser.add_argument("--templates", default="", help="figures: comma-separated template ids, just these")
    parser.add_argument("--columns", type=int, default=3)
    parser.add_argument("--ppi", type=int, help="pixels per inch (figures 110, the others 80)")
    arguments = parser.parse_args(argv)
    out = arguments.out if arguments.only else None
    if arguments.only in (None, "figures"):
        figures_sheet(out or images / "figures.png", arguments.ppi or 110,
                      {name for name in arguments.templates.split(",") if name})
    if arguments.only in (None, "worked"):
        contact_sheet(out or images / "worked-by-effect.png", arguments.columns, arguments.ppi or 80)
        print(out or images / "worked-by-effect.png")
    if arguments.only in (None, "sheets"):
        contact_sheet(out or images / "sheets-by-template.png", arguments.columns + 1, arguments.ppi or 80,
                      tuple(sorted(load_bank())), key=False)
        print(out or images / "sheets-by-template.png")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
