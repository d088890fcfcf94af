"""Contact sheets: one shipped template per effect of the catalogue, its worked solution as the answer key
prints it for the demo roster's first student, tiled into ``docs/images/worked-by-effect.png``; and every
shipped template's problem as the student's sheet prints it (statement, figure, blanks), tiled into
``docs/images/sheets-by-template.png``.

An instructor reads them as a key and a set of sheets: every effect's route (momentum and restitution solved
together, ``e = √(h′/h)``, ``tan⁻¹`` of components, unit conversions as steps) and every figure, each on one
page. Redo them when the key or the sheets change their look::

    .venv/bin/python docs/contact_sheet.py            # writes both images
    .venv/bin/python docs/contact_sheet.py --only worked --out /tmp/sheet.png --columns 3

Each template is an assignment of its own (one problem, one student), compiled by Typst to PNG; a page is cut
below its last line of ink and the pages are tiled left to right, each titled by the effects it shows.
"""

from __future__ import annotations

import argparse
import dataclasses
import io
from pathlib import Path

CHOSEN = ("head-on", "oblique-spheres", "billiards", "car-collision", "pile-driver", "drop-rebound",
          "ball-plate", "successive-bounces", "ballistic-pendulum", "package-bounce", "ramp-strike",
          "intersection-crash", "gun-recoil", "wall-impulse", "wall-throw", "incline-slide", "skid")
"""The templates shown, in order: together they take every effect of the catalogue the bank uses."""


def _pages(template_id: str, ppi: int, key: bool = True) -> list[bytes]:
    from grader.assign.assignment import ProblemSpec, load_assignment, load_roster
    from grader.assign.variants import generate
    from grader.bank.template import load_bank
    from grader.base.resources import sample_dir
    from grader.render.documents import Documents, key_source, student_source
    from grader.render.typeset import compile_typst

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

    from grader.bank.template import load_bank

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


def main() -> None:
    from grader.bank.template import load_bank

    images = Path(__file__).parent / "images"
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", choices=("worked", "sheets"), help="write one of the two images")
    parser.add_argument("--out", type=Path, help="where to write it (with --only)")
    parser.add_argument("--columns", type=int, default=3)
    parser.add_argument("--ppi", type=int, default=80)
    arguments = parser.parse_args()
    if arguments.only in (None, "worked"):
        out = arguments.out if arguments.only else None
        contact_sheet(out or images / "worked-by-effect.png", arguments.columns, arguments.ppi)
        print(out or images / "worked-by-effect.png")
    if arguments.only in (None, "sheets"):
        out = arguments.out if arguments.only else None
        contact_sheet(out or images / "sheets-by-template.png", arguments.columns + 1, arguments.ppi,
                      tuple(sorted(load_bank())), key=False)
        print(out or images / "sheets-by-template.png")


if __name__ == "__main__":
    main()
