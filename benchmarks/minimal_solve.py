"""The baseline for ``grader solve ID --batch FILE --json``: what a competent user would write instead.

``numpy.loadtxt`` reads the CSV (comma-separated, a header of parameter names), the template's closed
form is written out with numpy as a textbook gives it (``textbook.py``, beside this script), and each
row becomes the same JSON line ``grader`` prints (``{"template", "row", "params", "answers": {NAME:
{"value", "unit"}}}``) through ``json.dumps``. No units in cells, no validation, no refused rows, no
undefined answers: that is what the comparison measures. Templates with symbolic answers
(car-collision) are not covered.

Run: ``python benchmarks/minimal_solve.py pile-driver rows.csv > answers.jsonl``. Adding a template (``solve.py``
then times it too): its closed form in ``textbook.py`` and its answers' units in :data:`UNITS`.
"""

from __future__ import annotations

import json
import sys

import numpy as np
from textbook import FORMS, NUMPY

UNITS: dict[str, dict[str, str]] = {
    "drop-rebound": {"e": "", "loss_pct": "%"},
    "pile-driver": {"v_pile": "m/s", "e": "", "loss_pct": "%"},
    "ball-plate": {"v_out": "ft/s", "theta_out": "deg"},
    "oblique-spheres": {"v1_out": "m/s", "v2_out": "m/s", "theta1_out": "deg", "loss_pct": "%"},
    "head-on": {"v1_out": "m/s", "v2_out": "m/s", "loss_pct": "%", "energy_lost": "J", "impulse": "N·s"},
    "head-on-inverse": {"v2_out": "m/s", "e": "", "loss_pct": "%"},
    "coupling": {"v_common": "km/h", "energy_lost": "kJ", "loss_pct": "%", "impulse": "kN·s"},
    "moving-plate": {"v_out": "m/s", "h_out": "m"},
    "incline-bounce": {"v_out": "m/s", "theta_out": "deg"},
    "billiards": {"v_cue": "m/s", "v_obj": "m/s", "angle_cue": "deg", "loss_pct": "%"},
    "offset-spheres": {"v1_out": "m/s", "v2_out": "m/s", "theta1_out": "deg", "theta2_out": "deg", "loss_pct": "%"},
    "three-balls": {"v1_out": "m/s", "v2_out": "m/s", "v3_out": "m/s"},
    "two-rebounds": {"e": "", "h0": "m", "loss_pct": "%"},
    "successive-bounces": {"h_n": "m", "distance": "m", "t_total": "s"},
    "ballistic-pendulum": {"v_bullet": "m/s", "loss_pct": "%"},
    "skid": {"v_A": "km/h", "loss_pct": "%"},
    "wall-throw": {"y_hit": "m", "v_hit": "m/s", "v_out": "m/s", "x_land": "m"},
}
"""The templates this script answers, with each answer's unit as the template prints it."""


def main(template: str, path: str) -> None:
    """Answer every row of ``path`` and print one JSON line per row."""
    with open(path, encoding="utf-8") as handle:
        names = handle.readline().strip().split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    params = {name: data[:, i] for i, name in enumerate(names)}
    answers = FORMS[template](NUMPY, **params)
    param_lists = {name: column.tolist() for name, column in params.items()}
    answer_lists = {name: (answers[name].tolist(), unit) for name, unit in UNITS[template].items()}
    write = sys.stdout.write
    for row in range(len(data)):
        write(json.dumps({"template": template, "row": row + 1,
                          "params": {name: values[row] for name, values in param_lists.items()},
                          "answers": {name: {"value": values[row], "unit": unit}
                                      for name, (values, unit) in answer_lists.items()}}) + "\n")


if __name__ == "__main__":
    main(*sys.argv[1:3])
