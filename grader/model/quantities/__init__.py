"""Quantities, defined once for every stage: units, dimensions, numbers and significant figures.

The key's side and the student's side mean the same thing by "2.1 lb", "three significant figures" and
"a speed" because both read them here:

- :mod:`~grader.model.quantities.units`: the table of exact units and the one unit grammar; templates,
  ``--set``, batch files and keys read units with :func:`parse_unit`, student cells with
  :func:`unit_factor`, which layers the words students type (``meters``, ``lbs``, ``µs``) on the same table;
- :mod:`~grader.model.quantities.dimensions`: dimension arithmetic (:func:`dimension_of`) and the one table
  that says a dimension in words (``a speed``) and as its SI unit (``m/s``);
- :mod:`~grader.model.quantities.rounding`: the number grammar of templates and batch files, and the one
  significant-figure rule (the number as it prints, halves up) for printing, rounding and grading.

No pint. grader's own table knows every unit a student of impact problems types, exactly, with the
pound a force by construction, and costs nothing to build. Measured with ``PYTHONPATH=. python
benchmarks/units.py`` (100,000 cells, 17 kinds of unit, each converted into the answer's; three runs each
on a shared 2-core machine): 3.8 to 4.4 s with pint (its import takes 0.16 s, its registry 0.13 s on the
first conversion), 0.8 to 1.3 s with the table; ``grader list`` imports neither. What pint knew beyond the
table (yards, knots, furlongs) no answer here needs; such a unit is "unknown", which tells the student
what to write.
"""

from grader.model.quantities.dimensions import (
    ACCELERATION,
    ANGLE,
    ENERGY,
    FORCE,
    IMPULSE,
    LENGTH,
    MASS,
    POWER,
    PURE,
    SPEED,
    STIFFNESS,
    TIME,
    Dimension,
    as_dimension,
    dimension,
    dimension_of,
    si_unit,
    words,
)
from grader.model.quantities.rounding import (
    MAX_TEXT,
    NUMBER,
    half_unit,
    leading_exponent,
    printed_text,
    round_figures,
    scientific,
    significant,
    significant_binary,
    split_quantity,
)
from grader.model.quantities.units import (
    MAX_POWER,
    Unit,
    UnitMismatchError,
    UnknownUnitError,
    parse_unit,
    unit_factor,
    unit_factors,
)

__all__ = ["ACCELERATION", "ANGLE", "ENERGY", "FORCE", "IMPULSE", "LENGTH", "MASS", "MAX_POWER", "MAX_TEXT",
           "NUMBER", "POWER", "PURE", "SPEED", "STIFFNESS", "TIME", "Dimension", "Unit", "UnitMismatchError",
           "UnknownUnitError", "as_dimension", "dimension", "dimension_of", "half_unit", "leading_exponent",
           "parse_unit", "printed_text", "round_figures", "scientific", "si_unit", "significant", "significant_binary",
           "split_quantity",
           "unit_factor", "unit_factors", "words"]
