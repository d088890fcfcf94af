"""One quantities layer: the units templates and students use are one table read by one grammar, and
one significant-figure rule prints and rounds (grader/model/quantities)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from grader.bank.template import load_bank
from grader.base.errors import GraderError
from grader.grade.cells import CellNumber, CellWrongUnit, read_number
from grader.model.quantities import (
    ENERGY,
    FORCE,
    IMPULSE,
    STIFFNESS,
    parse_unit,
    printed_text,
    round_figures,
    scientific,
    si_unit,
    significant,
    significant_binary,
    unit_factor,
    words,
)
from grader.solve.batch import read_value

LBF = 0.45359237 * 9.80665

# The new effects' units: (unit, its SI factor, its dimension)
EFFECT_UNITS = [
    ("N", 1.0, FORCE), ("N/m", 1.0, STIFFNESS), ("N·s", 1.0, IMPULSE), ("N*s", 1.0, IMPULSE), ("J", 1.0, ENERGY),
    ("ft·lb", 0.3048 * LBF, ENERGY), ("ft-lb", 0.3048 * LBF, ENERGY), ("lb/in", LBF / 0.0254, STIFFNESS),
    ("kN", 1000.0, FORCE), ("kJ", 1000.0, ENERGY), ("N·m", 1.0, ENERGY), ("kN/m", 1000.0, STIFFNESS),
]


@pytest.mark.parametrize(("unit", "to_si", "dimension"), EFFECT_UNITS)
def test_the_effects_units_are_template_units(unit: str, to_si: float, dimension: tuple[int, ...]) -> None:
    parsed = parse_unit(unit)
    assert parsed.dimension == dimension
    assert parsed.to_si == pytest.approx(to_si, rel=1e-15)


@pytest.mark.parametrize(("unit", "to_si", "dimension"), EFFECT_UNITS)
def test_the_effects_units_are_student_units(unit: str, to_si: float, dimension: tuple[int, ...]) -> None:
    """A student's cell in any of them converts into the key's unit of the same dimension, by the same factor."""
    si = si_unit(dimension)
    cell = read_number(f"2.5 {unit}", si)
    assert isinstance(cell, CellNumber)
    assert cell.value == pytest.approx(2.5 * to_si, rel=1e-15)
    assert unit_factor(unit, unit) == 1.0


def test_a_template_parameter_in_newtons_per_metre_takes_a_cell_in_kilonewtons_per_metre() -> None:
    """The template's side (``--set``, batch files) and the student's read ``651 N/m`` and ``0.651 kN/m`` alike."""
    template = load_bank()["drop-rebound"]
    stiffness = dataclasses.replace(template.parameters["h_drop"], unit=parse_unit("N/m"))
    assert read_value("651 N/m", stiffness, "--set k") == 651.0
    assert read_value("0.651 kN/m", stiffness, "--set k") == pytest.approx(651.0, rel=1e-15)
    assert read_value("3.717 lb/in", stiffness, "--set k") == pytest.approx(3.717 * LBF / 0.0254, rel=1e-15)
    for text in ("651 N/m", "0.651 kN/m", "651 N·m^-1", "651 newtons per meter"):
        assert read_number(text, "N/m") == CellNumber(pytest.approx(651.0, rel=1e-15), text.split(" ", 1)[1])  # type: ignore[arg-type]
    with pytest.raises(GraderError, match="'N' cannot be converted to N/m"):
        read_value("651 N", stiffness, "--set k")


def test_a_unit_of_another_dimension_is_named_in_words() -> None:
    assert read_number("5 N/m", "N") == CellWrongUnit("expected a force (N), got a stiffness (N/m)")
    assert read_number("5 N·m", "N·s") == CellWrongUnit("expected an impulse (N·s), got an energy (N·m)")
    assert words(parse_unit("kg*m^2").dimension) == "a quantity in kg·m²"


def test_a_pound_is_a_force_on_both_sides() -> None:
    """The table says so once: the template's ``lb`` and the student's ``lb`` convert alike."""
    assert parse_unit("lb").dimension == FORCE
    assert unit_factor("lb", "N") == parse_unit("lb").to_si
    assert unit_factor("lbs", "kg") == pytest.approx(0.45359237, rel=1e-15)  # only a mass fits


def test_words_students_type_are_not_template_units() -> None:
    """The student's words are layered on the table: a template keeps to its symbols."""
    assert unit_factor("meters per second", "m/s") == 1.0
    assert unit_factor("µs", "s") == pytest.approx(1e-6, rel=1e-15)
    with pytest.raises(GraderError, match="unknown unit 'meters'"):
        parse_unit("meters")


@pytest.mark.parametrize(("value", "figures", "printed"), [
    (2.675, 3, "2.68"), (0.125, 2, "0.13"), (45.125, 4, "45.13"), (0.45375, 4, "0.4538"), (-2.5, 1, "-3"),
    (2398.7, 3, "2400"), (9.995, 3, "10.00"), (0.0012345, 4, "0.001235"),
])
def test_one_rule_rounds_the_number_as_it_prints_halves_up(value: float, figures: int, printed: str) -> None:
    assert printed_text(value, None, figures) == printed
    assert float(significant(value, figures)) == float(printed)
    assert round_figures(np.array([value]), figures).tolist() == [float(printed)]


def test_the_worked_solutions_variant_rounds_the_binary_value_halves_to_even() -> None:
    """Where the two differ (ties in the printed digits), the answer keys keep what they always printed."""
    assert [str(significant_binary(v, 4)) for v in (45.125, 0.45375, 50.625)] == ["45.12", "0.4537", "50.62"]
    assert [str(significant(v, 4)) for v in (45.125, 0.45375, 50.625)] == ["45.13", "0.4538", "50.63"]
    for value in np.random.default_rng(1).uniform(-1e6, 1e6, 2000):
        assert float(significant_binary(value, 3)) == float(f"{value:.2e}")


def test_scientific_keeps_the_figures() -> None:
    assert scientific(significant(17683.2, 3), 3) == ("1.77", 4)
    assert scientific(significant(9.996, 3), 3) == ("1.00", 1)
    assert scientific(significant(-0.000123456, 2), 2) == ("-1.2", -4)
    assert math.isnan(round_figures(np.array([math.nan]), 3)[0])
