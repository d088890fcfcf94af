"""A template's ``figure:``: what its sheets show beside the answer blanks.

- no ``figure`` key: the scene's panels in stage order (:mod:`grader.render.panels`);
- ``figure: none``: no figure;
- ``figure: {panels: [1, [2, 3]]}``: the panels chosen or merged, each a stage's number (from 1, in
  the order the stages are written) or a list of stages drawn in one panel; stages not listed are not
  drawn;
- ``figure: {file: my-figure.typ}`` (or ``.svg``), beside the template: the author's own figure, read
  once when the template loads, with ``{{ name }}`` of a parameter replaced by the variant's printed
  value (as statements are filled in). A ``.typ`` figure is Typst markup compiled in the same empty,
  private root as every document (no file, no package can be read); an ``.svg`` is embedded as an
  image.

>>> parse_figure("none", "t.yaml", 2, {"h"}).kind
'none'
>>> parse_figure({"panels": [1, [2]]}, "t.yaml", 2, {"h"}).panels
((0,), (1,))
>>> try:
...     parse_figure({"panel": [1]}, "t.yaml", 2, {"h"})
... except TemplateError as error:
...     print(error)
t.yaml: figure.panel: expected one of file, panels (did you mean panels?), got an unknown field
>>> try:
...     parse_figure({"panels": [1, [1, 2]]}, "t.yaml", 2, {"h"})
... except TemplateError as error:
...     print(error)
t.yaml: figure.panels, panel 2 of 2: expected each stage in one panel at most, got stage 1 again
"""

from __future__ import annotations

import re
from collections.abc import Collection, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from grader.base.errors import TemplateError, refuse_unknown_fields, shown

MAX_FILE = 256 * 1024  # bytes of a figure file
_PLACEHOLDER = re.compile(r"\{\{\s*([A-Za-z_][A-Za-z0-9_]*)\s*\}\}")
# What a .typ figure may not do: read or import files, include other sources, or change the page.
_REFUSED = re.compile(r"#?\b(import|include|read|image|json|yaml|toml|csv|xml|cbor|plugin|pagebreak|page)\b\s*[(\"]")


@dataclass(frozen=True)
class FigureSpec:
    """``kind``: ``scene`` (the panels of the scene's stages), ``none``, ``panels`` (the stages of each
    panel, indices from 0) or ``file`` (its ``source``, ``.typ`` or ``.svg`` as ``suffix``)."""

    kind: str = "scene"
    panels: tuple[tuple[int, ...], ...] = ()
    source: str = ""
    suffix: str = ""

    def filled(self, printed: Mapping[str, str]) -> str:
        """A file figure's source with each ``{{ name }}`` replaced by its printed value."""
        return _PLACEHOLDER.sub(lambda found: printed[found.group(1)], self.source)


SCENE_FIGURE = FigureSpec()
"""No ``figure`` key: the scene's panels."""


def parse_figure(raw: Any, where: str, stages: int, parameters: Collection[str]) -> FigureSpec:
    """The ``figure`` field of the template at ``where`` (a file's path), whose scene has ``stages``
    stages and these parameters."""
    if raw is None:
        return SCENE_FIGURE
    if raw == "none" or raw is False:
        return FigureSpec("none")
    if not isinstance(raw, Mapping):
        raise TemplateError(where, "figure", "none, {file: FILE.typ or FILE.svg} or {panels: [1, [2, 3]]}", shown(raw))
    refuse_unknown_fields(raw, ("file", "panels"), where, "figure")
    if len(raw) != 1:
        raise TemplateError(where, "figure", "one of file or panels", ", ".join(map(str, raw)) or "neither")
    if "panels" in raw:
        return FigureSpec("panels", panels=_panels(raw["panels"], where, stages))
    return _file(raw["file"], where, parameters)


def _panels(raw: Any, where: str, stages: int) -> tuple[tuple[int, ...], ...]:
    expected = f"a list of panels, each a stage's number (1 to {stages}) or a list of them"
    if not isinstance(raw, list) or not raw:
        raise TemplateError(where, "figure.panels", expected, shown(raw))
    panels: list[tuple[int, ...]] = []
    seen: set[int] = set()
    for number, item in enumerate(raw, start=1):
        members = item if isinstance(item, list) else [item]
        if not members or not all(isinstance(m, int) and not isinstance(m, bool) and 1 <= m <= stages
                                  for m in members):
            raise TemplateError(where, _panel_key(number, len(raw)), expected, shown(item))
        again = seen & set(members)
        if again:
            raise TemplateError(where, _panel_key(number, len(raw)), "each stage in one panel at most",
                                f"stage {min(again)} again")
        seen |= set(members)
        panels.append(tuple(sorted(m - 1 for m in members)))
    return tuple(panels)


def _panel_key(number: int, count: int) -> str:
    """Which panel, counted as the author counts them (from 1): ``figure.panels, panel 2 of 3``; never
    ``panels[1]``, which reads as an index from 0 to a programmer and as the first panel to an author."""
    return f"figure.panels, panel {number} of {count}"


def _file(raw: Any, where: str, parameters: Collection[str]) -> FigureSpec:
    if not isinstance(raw, str) or Path(raw).suffix not in (".typ", ".svg") or Path(raw).name != raw:
        raise TemplateError(where, "figure.file", "the name of a .typ or .svg file beside the template", shown(raw))
    path = Path(where).parent / raw
    try:
        data = path.read_bytes()[:MAX_FILE + 1]
        source = data.decode("utf-8")
    except (OSError, UnicodeDecodeError) as error:
        raise TemplateError(where, "figure.file", f"a UTF-8 file {path}", str(error)) from None
    if len(data) > MAX_FILE:
        raise TemplateError(where, "figure.file", f"a file of at most {MAX_FILE // 1024} KiB", "a larger one")
    for found in _PLACEHOLDER.finditer(source):
        if found.group(1) not in parameters:
            raise TemplateError(where, f"figure.file ({raw})", "{{ name }} of parameters only",
                                f"{{{{ {found.group(1)} }}}}")
    refused = _REFUSED.search(source) if raw.endswith(".typ") else None
    if refused is not None:
        raise TemplateError(where, f"figure.file ({raw})", "a drawing that reads no file and sets no page",
                            refused.group(0))
    return FigureSpec("file", source=source, suffix=Path(raw).suffix)
