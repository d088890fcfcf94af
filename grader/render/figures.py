"""Figures of a scene, to one variant's scale, as Typst drawing calls (see ``templates/figures.typ``).

A figure is the scene's panels in stage order, each effect drawing its own
(:mod:`grader.render.panels`): a template written tomorrow gets a true figure with no drawing code,
and nothing is matched against a list of known shapes. :data:`STAGE_FIGURES` says how each effect's
stage is drawn (``grader effects`` and docs/effects.md show it).
"""

from __future__ import annotations

from collections.abc import Mapping

from grader.assign.variants import ProblemVariant
from grader.bank.template import Template
from grader.render.panels import PANELS, FigureRecord, panels_figure
from grader.render.scene_view import SceneView
from grader.render.typst_text import Typ, string

STAGE_FIGURES: Mapping[str, str] = {
    **{name: kind.drawn for name, kind in PANELS.items()},
    "velocity": "not drawn on its own: its speed and angle label the velocity arrows of the impact's panel (oblique "
                "impacts) and a projectile's throw",
    "angle_between": "not drawn: no panel reads it",
    "impact_geometry": "in the panel of the oblique impact after it: the two spheres at contact, radii in their "
                       "ratio, the offset dimensioned and n at its angle to the path",
}
"""How a stage of each effect is drawn, one sentence each: a figure is the scene's panels in stage
order, a stage drawn in its own effect's panel or in the panel of the stage before it that claims it."""


def figure(template: Template, variant: ProblemVariant, values: Mapping[str, float]) -> Typ:
    """The figure of one variant's scene, as a Typst expression (code mode): its panels in stage order
    (:mod:`grader.render.panels`)."""
    return figure_record(template, variant, values)[0]


def figure_record(template: Template, variant: ProblemVariant,
                  values: Mapping[str, float]) -> tuple[Typ, FigureRecord]:
    """The figure and the record of what it drew (its panels, their stages and bodies): the scene's
    panels, the panels the template chose, none, or the template's own figure (``figure:``,
    :mod:`grader.bank.figure_field`)."""
    spec = template.figure
    if spec.kind == "none":
        return Typ("none"), FigureRecord(())
    if spec.kind == "file":
        filled = spec.filled(variant.printed)
        if spec.suffix == ".svg":
            return Typ(f"image(bytes({string(filled)}), format: \"svg\", width: 6cm)"), FigureRecord(())
        return Typ(f"box(width: 7.6cm, [\n{filled}\n])"), FigureRecord(())
    stages = template.scene.stages
    groups = [[stages[i] for i in panel] for panel in spec.panels] if spec.kind == "panels" else None
    return panels_figure(SceneView(template, variant, values), groups)
