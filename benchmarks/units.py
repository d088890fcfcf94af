"""What reading student cells with units costs: 100,000 cells, each a number and one of 17 units
(the same kind as the answer's or another: ``cm/s`` for m/s, ``ft-lb`` for J, ``0.651 kN/m`` for N/m),
read by :func:`grader.grade.cells.read_number` in a fresh process, after the import is timed.

    PYTHONPATH=. python benchmarks/units.py [--cells 100000]

Prints the import time of ``grader.grade.cells``, the time to read the cells, and whether pint was
imported (grader 0.x read units with pint, built on the first conversion; it now has its own table).
"""

from __future__ import annotations

import argparse
import random
import sys
import time

UNITS = (("m/s", "m/s"), ("cm/s", "m/s"), ("km/h", "m/s"), ("ft/s", "m/s"), ("mph", "ft/s"), ("kJ", "J"),
         ("N*s", "N*s"), ("lb", "N"), ("ft-lb", "J"), ("deg", "deg"), ("rad", "deg"), ("meters per second", "m/s"),
         ("N/m", "N/m"), ("kN/m", "N/m"), ("mm", "m"), ("°", "deg"), ("%", "%"))


def main() -> None:
    """Time the import, then the cells; one line of results."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cells", type=int, default=100_000)
    count = parser.parse_args().cells
    started = time.perf_counter()
    from grader.grade.cells import read_number

    imported = time.perf_counter()
    rng = random.Random(1)
    kinds = [UNITS[i % len(UNITS)] for i in range(count)]
    cells = [(f"{rng.uniform(0.1, 900):.3g} {typed}", unit) for typed, unit in kinds]
    begun = time.perf_counter()
    unread = sum(type(read_number(text, unit)).__name__ != "CellNumber" for text, unit in cells)
    done = time.perf_counter()
    print(f"import grader.grade.cells: {1000 * (imported - started):.0f} ms; {count:,} cells with units: "
          f"{done - begun:.2f} s ({1e6 * (done - begun) / count:.1f} µs a cell); not read: {unread}; "
          f"pint imported: {'pint' in sys.modules}")


if __name__ == "__main__":
    main()
