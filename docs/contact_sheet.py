"""The contact sheet of worked solutions: one shipped template per effect of the catalogue, its worked solution as
the answer key prints it for the demo roster's first student, tiled into ``docs/images/worked-by-effect.png``.

An instructor reads it as a key: every effect's route on one page (momentum and restitution solved together,
``e = √(h′/h)``, ``tan⁻¹`` of components, unit conversions as steps). Redo it when the key changes its look::

    .venv/bin/python docs/contact_sheet.py            # writes docs/images/worked-by-effect.png
    .venv/bin/python docs/contact_sheet.py --out /tmp/sheet.png --columns 3

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


def _pages(template_id: str, ppi: int) -> list[bytes]:
    from grader.assign.assignment import ProblemSpec, load_assignment, load_roster
    from grader.assign.variants import generate
    from grader.bank.template import load_bank
    from grader.base.resources import sample_dir
    from grader.render.documents import Documents, key_source
    from grader.render.typeset import compile_typst

    bank = load_bank()
    assignment = load_assignment(sample_dir() / "assignment.yaml")
    assignment = dataclasses.replace(assignment, problems=(ProblemSpec("1", template_id, {"*": 1.0}, {}, {}, {}),))
    generation = generate(assignment, load_roster(sample_dir() / "roster.csv")[:1], bank)
    pages = compile_typst(key_source(Documents(assignment, generation, bank), people=[0]), "png", ppi)
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


def contact_sheet(out: Path, columns: int, ppi: int) -> None:
    """Writes the tiled worked solutions of :data:`CHOSEN` to ``out``."""
    from PIL import Image, ImageDraw

    from grader.bank.template import load_bank

    bank = load_bank()
    tiles = []
    for template_id in CHOSEN:
        effects = sorted({stage.effect for stage in bank[template_id].scene.stages})
        for page in _pages(template_id, ppi)[:1]:
            tile = _inked(page)
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
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path(__file__).parent / "images" / "worked-by-effect.png")
    parser.add_argument("--columns", type=int, default=3)
    parser.add_argument("--ppi", type=int, default=80)
    arguments = parser.parse_args()
    contact_sheet(arguments.out, arguments.columns, arguments.ppi)
    print(arguments.out)


if __name__ == "__main__":
    main()
