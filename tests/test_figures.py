"""Figures are the scene's panels in stage order (issue 26), checked against the scene through the
drawing's own record of what it drew: every stage is in one panel, the panels are in stage order, every
body of the scene is named and nothing else is, each panel names the bodies of its stages; a number in a
label is a value the statement prints. For every shipped template and for a test bank of scenes written
only for these tests (``tests/data/figures``: the issue's problems, and stranger ones), and for issue 25's
trial templates of the new effects (``tests/data``)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from grader.assign.variants import ProblemVariant
from grader.bank.template import Template, load_bank, load_template
from grader.physics.effects import CATALOGUE
from grader.render.figures import figure_record
from grader.render.panels import ANNOTATIONS, FigureRecord, panel_groups
from grader.render.preview import example_printed
from grader.render.worked import chain_values, si_parameters
from grader.solve.cache import compiled_for

TEST_BANK = Path(__file__).parent / "data" / "figures"


TRIALS = ("bullet-spring", "package-platform", "ramp-and-floor", "incline-up-and-back", "intersection",
          "intersection-reconstruction", "explosion", "recoil", "ball-wall-impulse", "cushion", "oblique-both-moving")
"""Issue 25's trial templates of the new effects (tests/data): their figures are checked as the bank's."""


def _bank() -> dict[str, Template]:
    shipped = load_bank()
    written = {t.id: t for t in (load_template(p) for p in sorted(TEST_BANK.glob("*.yaml")))}
    trials = {t.id: t for t in (load_template(TEST_BANK.parent / f"{name}.yaml") for name in TRIALS)}
    assert not set(shipped) & set(written) and not (set(shipped) | set(written)) & set(trials)
    return {**shipped, **written, **trials}


BANK = _bank()


def example_variant(template: Template) -> ProblemVariant:
    """The template's example (its ``example:`` values, printed as a sheet prints them)."""
    printed = example_printed(template)
    return ProblemVariant("1", template.id, "example", {n: float(v) for n, v in printed.items()}, printed, ())


@pytest.fixture(scope="module")
def figures() -> dict[str, tuple[str, FigureRecord, dict[str, str]]]:
    """Each template's figure (Typst), its record and the printed values, at its example's values."""
    found = {}
    for template_id, template in BANK.items():
        variant = example_variant(template)
        typst, record = figure_record(template, variant, _values(template, variant))
        found[f"{template_id}/0"] = (str(typst), record, dict(variant.printed))
    return found


def _values(template: Template, variant: ProblemVariant) -> dict[str, float]:
    """Every quantity's value (SI, symbols at 1), as the worked solution gives the figure."""
    given = {**si_parameters(template, variant), **dict.fromkeys(template.symbols, 1.0)}
    return chain_values(compiled_for(template), given)


def _bodies(stage_fields: dict[str, object]) -> set[str]:
    named = stage_fields.get("bodies") or [stage_fields.get("body"), stage_fields.get("with")]
    return {str(b) for b in named if b}  # type: ignore[union-attr]


@pytest.mark.parametrize("template_id", sorted(BANK))
def test_the_panels_are_the_stages_in_order_and_name_every_body_and_no_other(
        template_id: str, figures: dict[str, tuple[str, FigureRecord, dict[str, str]]]) -> None:
    template = BANK[template_id]
    stages = template.scene.stages
    for key in (k for k in figures if k.startswith(f"{template_id}/")):
        _, record, _ = figures[key]
        drawn = [index for panel in record.panels for index in panel.stages]
        assert sorted(drawn) == [s.index for s in stages], (key, record)  # each stage in one panel
        firsts = [min(i for i in panel.stages if stages[i].effect not in ANNOTATIONS) for panel in record.panels
                  if any(stages[i].effect not in ANNOTATIONS for i in panel.stages)]
        assert firsts == sorted(firsts), (key, record)  # in stage order
        named = {body for panel in record.panels for body in panel.bodies}
        assert named == set(template.scene.bodies), (key, record)  # every body, nothing else
        for panel in record.panels:
            own = set().union(*(_bodies(dict(stages[i].fields)) for i in panel.stages
                                if stages[i].effect not in ANNOTATIONS))
            assert set(panel.bodies) == own, (key, panel)  # a panel names the bodies of its stages
        if len(record.panels) > 1:
            assert [p.title.split(" · ")[0] for p in record.panels] == [str(n) for n in
                                                                        range(1, len(record.panels) + 1)]


@pytest.mark.parametrize("template_id", sorted(BANK))
def test_a_number_in_a_figure_is_a_value_the_statement_prints(
        template_id: str, figures: dict[str, tuple[str, FigureRecord, dict[str, str]]]) -> None:
    """Given values are labelled with the variant's numbers; an asked quantity is labelled with its
    name only: every number right of an `=` in a label is a printed parameter's (or its magnitude, right
    of ``|v_B| =``: a velocity drawn the way it moves)."""
    for key in (k for k in figures if k.startswith(f"{template_id}/")):
        typst, _, printed = figures[key]
        labels = re.findall(r"fig-label\(\([^)]*\), \"[a-z]+\", \((.*)\)\)", typst)
        for line in (part for label in labels for part in re.findall(r"\$([^$]*)\$", label)):
            if "=" not in line:
                continue
            shown = re.findall(r"(?<![\w\"])(-?\d+(?:\.\d+)?)(?![\w\"])", line.split("=", 1)[1])
            magnitudes = {value.lstrip("-") for value in printed.values()} if line.startswith("|") else set()
            allowed = set(printed.values()) | magnitudes
            assert all(number in allowed or number == "0" for number in shown), (key, line, printed)


def test_the_issues_pendulum_striking_a_hanging_ball_draws_both_pendulums(
        figures: dict[str, tuple[str, FigureRecord, dict[str, str]]]) -> None:
    """Issue 26: it was drawn as the ballistic pendulum, A twice and B not at all. Now: A on its cord,
    A striking B, B on its cord."""
    _, record, _ = figures["cord-pendulum/0"]
    assert [p.bodies for p in record.panels] == [("A",), ("A", "B"), ("B",)]
    assert [p.title for p in record.panels] == ["1 · A swings", "2 · A strikes B", "3 · B swings"]


def test_the_issues_ramp_then_skid_draws_the_ramp_the_impact_and_only_b_sliding(
        figures: dict[str, tuple[str, FigureRecord, dict[str, str]]]) -> None:
    """Issue 26: it was drawn as the skid template's two cars locked together. Now a panel per stage: A
    comes down the ramp (a slope: the smooth ramp, its height dimensioned with the printed value), A
    strikes B, B alone slides to rest."""
    typst, record, printed = figures["ramp-skid/0"]
    assert [p.bodies for p in record.panels] == [("A",), ("A", "B"), ("B",)]
    assert record.panels[0].title == "1 · A slides"
    assert "$h$" in typst and f"$= {printed['h']} thin" in typst  # the dimension: h over its value


def test_the_issues_bullet_into_a_block_on_a_spring_draws_the_spring_and_the_wall(
        figures: dict[str, tuple[str, FigureRecord, dict[str, str]]]) -> None:
    """Issue 26: no spring, no wall, the bullet labelled `-v_b`. Now one panel: the wall (hatched), the
    coils (a zigzag path), the block and the bullet coming in toward the wall labelled v_b, the greatest
    compression named and not valued (it is asked)."""
    typst, record, printed = figures["spring-bullet-block/0"]
    assert [set(p.bodies) for p in record.panels] == [{"block", "bullet"}]
    assert f"v_b = {printed['v_b']}" in typst and "-v_b" not in typst and "- v_b" not in typst
    assert f"k = {printed['k']}" in typst
    coils = [line for line in typst.splitlines() if line.strip().startswith("fig-path(") and line.count("(") > 14]
    assert coils, "no spring drawn"
    assert "$x_\"max\"$" in typst  # the greatest compression: its name alone


def test_the_issues_cars_at_an_intersection_draw_both_cars_with_their_directions(
        figures: dict[str, tuple[str, FigureRecord, dict[str, str]]]) -> None:
    """Issue 26: a car at rest on a line. Now A and B come in along their directions, A north and B east
    (their arrows end at the point of impact, the label their printed speeds), the wreck dashed."""
    typst, record, printed = figures["intersection-cars/0"]
    assert [set(p.bodies) for p in record.panels] == [{"A", "B"}]
    assert f"v_A = {printed['v_A']}" in typst and f"v_B = {printed['v_B']}" in typst
    arrows = re.findall(r"\(\(([\d.]+), ([\d.]+)\), \(([\d.]+), ([\d.]+)\)\)", typst)
    moves = {(round(float(x1) - float(x0), 1) != 0, round(float(y1) - float(y0), 1) != 0) for x0, y0, x1, y1 in arrows}
    assert (True, False) in moves and (False, True) in moves  # a line along east, one along north
    assert "theta =" not in typst  # the wreck's direction is asked: named only


def test_every_effect_of_the_catalogue_has_a_panel_or_labels_one() -> None:
    from grader.render.panels import PANELS

    assert set(CATALOGUE) == set(PANELS) | ANNOTATIONS


def test_a_scene_of_stages_no_panel_claims_has_a_panel_per_stage() -> None:
    """The grouping alone: a swing, an impact and a slide of one body are three panels; the skid
    (both bodies sliding together) and the ballistic pendulum (a bullet) are one."""
    groups = panel_groups(BANK["swing-strike-slide"].scene.stages)
    assert [[s.effect for s in g] for g in groups] == [["swing"], ["impact"], ["slide"]]
    assert [[s.effect for s in g] for g in panel_groups(BANK["skid"].scene.stages)] == [["impact", "slide"]]
    pendulum = panel_groups(BANK["ballistic-pendulum"].scene.stages)
    assert [[s.effect for s in g] for g in pendulum] == [["impact", "swing"]]


# --- the author decides: figure: none, {panels: ...}, {file: ...} --------------------------------

def _variant_of(template: Template) -> tuple[Template, ProblemVariant, dict[str, float]]:
    variant = example_variant(template)
    return template, variant, _values(template, variant)


def _with_figure(tmp_path: Path, template_id: str, figure: object, files: dict[str, str] | None = None) -> Template:
    import yaml

    source = TEST_BANK / f"{template_id}.yaml"
    raw = yaml.safe_load(source.read_text(encoding="utf-8")) if source.exists() else \
        yaml.safe_load((Path(BANK[template_id].where)).read_text(encoding="utf-8"))
    raw["figure"] = figure
    for name, text in (files or {}).items():
        (tmp_path / name).write_text(text, encoding="utf-8")
    path = tmp_path / f"{template_id}.yaml"
    path.write_text(yaml.safe_dump(raw, allow_unicode=True), encoding="utf-8")
    return load_template(path)


def test_figure_none_draws_nothing(tmp_path: Path) -> None:
    template, variant, values = _variant_of(_with_figure(tmp_path, "cord-pendulum", "none"))
    typst, record = figure_record(template, variant, values)
    assert str(typst) == "none" and record.panels == ()


def test_figure_panels_choose_and_merge_the_stages_shown(tmp_path: Path) -> None:
    """`panels: [[1, 2], 3]`: A's swing and the impact in one panel, B's swing in the next."""
    template, variant, values = _variant_of(_with_figure(tmp_path, "cord-pendulum", {"panels": [[2, 1], 3]}))
    _, record = figure_record(template, variant, values)
    assert [p.stages for p in record.panels] == [(0, 1), (2,)]
    assert [set(p.bodies) for p in record.panels] == [{"A"}, {"B"}]  # a merged panel draws its first stage's panel


def test_a_figure_of_the_authors_own_gets_the_variants_values(tmp_path: Path) -> None:
    """A .typ figure beside the template, `{{ L }}` replaced by the printed value, typeset in the
    sheet; an .svg likewise, as an image."""
    from grader.render.typeset import compile_typst

    drawing = '#rect(width: 3cm, height: 1cm)[A on a cord $L = {{ L }}$ m]'
    template, variant, values = _variant_of(_with_figure(tmp_path, "cord-pendulum", {"file": "mine.typ"},
                                                         {"mine.typ": drawing}))
    typst, _ = figure_record(template, variant, values)
    assert f"$L = {variant.printed['L']}$" in str(typst)
    compile_typst(f"#{typst}\n", tagged=False)
    svg = ('<svg xmlns="http://www.w3.org/2000/svg" width="100" height="40"><text x="5" y="20">'
           'L = {{ L }} m</text></svg>')
    template, variant, values = _variant_of(_with_figure(tmp_path, "cord-pendulum", {"file": "mine.svg"},
                                                         {"mine.svg": svg}))
    typst, _ = figure_record(template, variant, values)
    compile_typst(f"#{typst}\n", tagged=False)


@pytest.mark.parametrize(("figure", "files", "message"), [
    ({"panel": [1]}, {}, "figure.panel: expected one of file, panels (did you mean panels?)"),
    ({"panels": [1, 4]}, {}, "figure.panels, panel 2 of 2: expected a list of panels, each a stage's number (1 to 3)"),
    ({"panels": [1, [1, 2]]}, {},
     "figure.panels, panel 2 of 2: expected each stage in one panel at most, got stage 1 again"),
    ({"file": "missing.typ"}, {}, "figure.file: expected a UTF-8 file"),
    ({"file": "../x.typ"}, {}, "figure.file: expected the name of a .typ or .svg file beside the template"),
    ({"file": "a.typ"}, {"a.typ": "$x = {{ nope }}$"}, "expected {{ name }} of parameters only, got {{ nope }}"),
    ({"file": "a.typ"}, {"a.typ": '#read("/etc/passwd")'}, "expected a drawing that reads no file"),
    ("a picture", {}, "figure: expected none, {file: FILE.typ or FILE.svg} or {panels: [1, [2, 3]]}"),
])
def test_a_figure_field_that_cannot_be_used_is_refused_saying_why(
        tmp_path: Path, figure: object, files: dict[str, str], message: str) -> None:
    from grader.base.errors import TemplateError

    with pytest.raises(TemplateError) as refused:
        _with_figure(tmp_path, "cord-pendulum", figure, files)
    assert message in str(refused.value)


# --- velocity arrows and their labels agree (issue 32) --------------------------------------------

_SIGNED = re.compile(r"=\s*([-\u2212]?)\s*\d")


def _velocity_arrows(template: Template, printed: dict[str, str]) -> list[tuple[str, object]]:
    variant = ProblemVariant("1", template.id, "v", {n: float(v) for n, v in printed.items()}, printed, ())
    _, record = figure_record(template, variant, _values(template, variant))
    return [(panel.title, arrow) for panel in record.panels for arrow in panel.velocities]


def _printed_variants(template: Template) -> list[dict[str, str]]:
    from tests.scene_edits import draws

    return [dict(example_variant(template).printed), *draws(template, 6, seed="arrows")]


@pytest.mark.parametrize("template_id", sorted(load_bank()))
def test_no_velocity_label_says_the_opposite_of_its_arrow(template_id: str) -> None:
    """A velocity is an arrow the way the body moves, labelled with its magnitude: no label on a velocity
    arrow shows a negative number, and a label naming a given velocity (``v_B = 3.1 km/h``, ``|v_B| = 5.2
    km/h``) sits on an arrow that points where the statement's value says, read off the printed value
    and the direction the quantity is positive in (coupling's ``v_B = −5.2 km/h`` on a leftward arrow
    said "moves right")."""
    template = BANK[template_id]
    for printed in _printed_variants(template):
        for title, arrow in _velocity_arrows(template, printed):
            for line in arrow.label:  # type: ignore[attr-defined]
                signed = _SIGNED.search(line)
                assert signed is None or not signed.group(1), (template_id, printed, title, line)
                named = re.match(r"\|?([A-Za-z_\"']+[^|= ]*)\|? = ", line)
                given = next((n for n in template.parameters if named and
                              re.sub(r"[\"_ ]", "", named.group(1)) == re.sub(r"_", "", n)), None)
                if given is None or arrow.positive is None or float(printed[given]) == 0:  # type: ignore[attr-defined]
                    continue
                along = sum(d * p for d, p in zip(arrow.direction, arrow.positive, strict=True))  # type: ignore[attr-defined]
                assert along * float(printed[given]) > 0, (template_id, printed, title, line, arrow)


def test_the_issues_coupling_labels_car_bs_leftward_velocity_with_its_magnitude() -> None:
    """Issue 32: `v_B = −5.2 km/h` on an arrow already pointing left. Now `|v_B| = 5.2 km/h` on it."""
    template = BANK["coupling"]
    printed = {**example_variant(template).printed, "v_B": "-5.2"}
    arrows = {arrow.label: arrow for _, arrow in _velocity_arrows(template, printed)}  # type: ignore[attr-defined]
    leftward = [a for label, a in arrows.items() if any("5.2" in line for line in label)]
    assert [a.label for a in leftward] == [('|v_B| = 5.2 thin "km/h"',)]
    assert leftward[0].direction == (-1.0, 0.0)


def _paths(template: Template, printed: dict[str, str]) -> list[str]:
    variant = ProblemVariant("1", template.id, "v", {n: float(v) for n, v in printed.items()}, printed, ())
    typst, _ = figure_record(template, variant, _values(template, variant))
    return re.findall(r"fig-path\([^\n]*", str(typst))


def test_the_issues_wall_throw_draws_the_asked_heights_not_to_scale_and_the_givens_to_scale() -> None:
    """Issue 32: `y_hit` and `x_land` could be measured off wall-throw's figure. The path now depends on
    nothing but the givens that do not decide them alone: another speed or restitution draws the same
    path; another release height or wall distance does not."""
    template = BANK["wall-throw"]
    printed = dict(example_variant(template).printed)
    drawn = _paths(template, printed)
    assert drawn and _paths(template, {**printed, "v0": "19.0", "e": "0.45"}) == drawn
    assert _paths(template, {**printed, "h0": "1.90"}) != drawn
    assert _paths(template, {**printed, "D": "4.0"}) != drawn


@pytest.mark.parametrize("length", [0.15, 0.45, 2.0])
def test_a_dimensions_label_keeps_clear_of_its_arrows(length: float) -> None:
    """Issue 32: pile-driver's `h_rebound` was written over the arrow heads of its short dimension line.
    The label's box (as the drawing estimates it) now crosses none of the dimension's arrows."""
    from grader.render.drawing import Drawing, _crosses

    canvas = Drawing()
    canvas.dimension((1.0, 0.0), (1.0, length), ['h_"rebound" = 0.10 thin "m"'], "right")
    (at, box), = canvas.labels
    placed = (at[0] + box[0], at[1] + box[1], at[0] + box[2], at[1] + box[3])
    assert not any(_crosses(placed, a, b) for a, b in canvas.strokes), (placed, canvas.strokes)
    assert placed[0] >= 1.0 + 0.2  # beside the line, not on it


# --- what the contact sheet showed (docs/contact_sheet.py) ------------------------------------------

def test_a_separation_shows_before_and_after_side_by_side_and_no_line_joins_them(
        figures: dict[str, tuple[str, FigureRecord, dict[str, str]]]) -> None:
    """The whole and its parts were joined by a dotted line, which read as a connection between bodies;
    they are two states, captioned "before" and "after", with nothing drawn between them."""
    for key in ("gun-recoil/0", "shell-explosion/0", "spring-carts/0", "explosion/0", "recoil/0"):
        typst, _, _ = figures[key]
        assert '"dotted"' not in typst, key
        assert '$"before"$' in typst and '$"after"$' in typst, key


def test_words_before_a_value_keep_their_colon(figures: dict[str, tuple[str, FigureRecord, dict[str, str]]]) -> None:
    """`"relative": u` set a bare colon in math, spaced as a relation ("relative : u"); the colon is the
    words' own (`"relative:" u`)."""
    for key, (typst, _, _) in figures.items():
        assert not re.search(r'"\s*:', typst), key


@pytest.mark.parametrize("template_id", ["incline-slide", "incline-up-and-back", "ramp-and-floor", "cushion-stop"])
def test_a_strip_of_a_slope_or_an_impulse_is_not_shrunk(template_id: str) -> None:
    """A panel wider than its room in a strip is shrunk (its geometry, not its text) until its labels crowd
    it: an incline's angle ran into the slope. These panels now fit their room unshrunk: their labels sit
    above their arrows and under the base, and a strip's narrower column leaves its room to the other."""
    from grader.render.panels import _panel, panel_groups, strip_widths
    from grader.render.scene_view import SceneView

    template = BANK[template_id]
    variant = example_variant(template)
    scene = SceneView(template, variant, _values(template, variant))
    naturals = [_panel(scene, group).natural_width() for group in panel_groups(template.scene.stages)]
    assert all(natural <= room + 1e-9 for natural, room in zip(naturals, strip_widths(naturals), strict=True)), \
        naturals


def test_a_label_keeps_its_gap_when_its_drawing_is_shrunk() -> None:
    """A label placed 0.15 cm under a line stays 0.15 cm under it when the drawing is scaled to fit."""
    from grader.render.drawing import Drawing

    canvas = Drawing()
    canvas.line((0.0, 0.0), (12.0, 0.0))
    canvas.label((6.0, -0.15), "n", ["x"])
    shrunk = str(canvas.typst(max_width=6.0))
    (line_y,), (label_y,) = (re.findall(r"fig-lines\(\(\([0-9.]+, ([0-9.]+)\)", shrunk),
                             re.findall(r'fig-label\(\([-0-9.]+, ([-0-9.]+)\), "n"', shrunk))
    assert float(label_y) - float(line_y) == pytest.approx(0.15, abs=0.011)


@pytest.mark.slow
def test_the_contact_sheet_shows_every_effects_panel(tmp_path: Path) -> None:
    """docs/contact_sheet.py (docs/images/figures.png): every template's figure, and among them a panel
    of each effect that has one; its Typst source compiles."""
    import importlib.util

    from grader.render.panels import PANELS
    from grader.render.typeset import compile_typst

    spec = importlib.util.spec_from_file_location("contact_sheet", Path(__file__).parents[1] / "docs" /
                                                  "contact_sheet.py")
    assert spec is not None and spec.loader is not None
    sheet = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(sheet)
    chosen = sheet.sections()
    assert sum(len(templates) for _, templates in chosen) == len(BANK)
    _, shown = sheet.figures_source(chosen)
    assert shown == set(PANELS)
    compile_typst(sheet.figures_source([(heading, templates[:1]) for heading, templates in chosen])[0], tagged=False)


@pytest.mark.parametrize("beta", ["15", "30", "60"])
def test_the_issues_incline_bounce_draws_n_and_t_at_the_contact(beta: str) -> None:
    """Issue 32: incline-bounce's n-t glyph sat up the slope, away from the point of contact where n and t
    are defined. Both arrows now start at the contact (the panel's origin) and their labels sit within
    a centimetre of it, at every slope the template samples."""
    from grader.render.panels import _panel
    from grader.render.scene_view import SceneView

    template = BANK["incline-bounce"]
    printed = {**example_variant(template).printed, "beta": beta}
    variant = ProblemVariant("1", template.id, "v", {n: float(v) for n, v in printed.items()}, printed, ())
    scene = SceneView(template, variant, _values(template, variant))
    canvas = _panel(scene, panel_groups(template.scene.stages)[0])
    axes = [call for call in canvas.calls if call[0] == "fig-label" and call[3].endswith(("($n$,)", "($t$,)"))]
    assert len(axes) == 2
    assert all((call[1][0][0] ** 2 + call[1][0][1] ** 2) ** 0.5 < 1.0 for call in axes), axes
    assert sum(1 for tail, _ in canvas.strokes if tail == (0.0, 0.0)) == 2


@pytest.mark.parametrize(("template_id", "circles", "rects"), [
    ("two-pendulums", 6, 0),   # each swing: the ball at rest (dashed) and at its angle; the impact: two balls
    ("three-balls", 3, 0),
    ("ramp-slide", 0, 2),      # on the ramp, solid at its top and dashed at its foot (the floor panel: outlines)
    ("ballistic-pendulum", 0, 3),  # no shape given: the block on its cord, dashed at rest; the bullet a slug
])
def test_a_body_is_drawn_as_its_shape(template_id: str, circles: int, rects: int) -> None:
    """Issue 32: two-pendulums drew its balls as blocks. A body's `shape` decides; left out, the panel's own."""
    typst = str(figure_record(BANK[template_id], example_variant(BANK[template_id]),
                              _values(BANK[template_id], example_variant(BANK[template_id])))[0])
    radii = [float(r) for r in re.findall(r"fig-circle\(\([-0-9.]+, [-0-9.]+\), ([0-9.]+)", typst)]
    assert (sum(r > 0.1 for r in radii), typst.count("fig-rect(")) == (circles, rects)  # not a cord's pivot
