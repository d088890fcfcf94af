"""The baseline for ``grader solve ID --batch FILE --json``: what a competent user would write instead.

``numpy.loadtxt`` reads the CSV (comma-separated, a header of parameter names), the template's closed
form is written out with numpy as a textbook gives it, and each row becomes the same JSON line
``grader`` prints (``{"template", "row", "params", "answers": {NAME: {"value", "unit"}}}``) through
``json.dumps``. No units in cells, no validation, no refused rows, no undefined answers: that is
what the comparison measures. Templates with symbolic answers (car-collision) are not covered.

Run: ``python benchmarks/minimal_solve.py pile-driver rows.csv > answers.jsonl``.
"""

from __future__ import annotations

import json
import sys
from collections.abc import Callable

import numpy as np

G = 9.81  # the bank's g, m/s^2


def drop_rebound(h_drop: np.ndarray, h_rebound: np.ndarray) -> dict[str, tuple[np.ndarray, str]]:
    e = np.sqrt(h_rebound / h_drop)
    return {"e": (e, ""), "loss_pct": (100 * (h_drop - h_rebound) / h_drop, "%")}


def pile_driver(m_ram: np.ndarray, m_pile: np.ndarray, h_drop: np.ndarray,
                h_rebound: np.ndarray) -> dict[str, tuple[np.ndarray, str]]:
    v_ram = np.sqrt(2 * G * h_drop)  # just before the impact, down
    v_back = np.sqrt(2 * G * h_rebound)  # just after, up
    v_pile = m_ram * (v_ram + v_back) / m_pile  # momentum
    e = (v_pile + v_back) / v_ram
    before = m_ram * v_ram**2
    loss = 100 * (before - m_ram * v_back**2 - m_pile * v_pile**2) / before
    return {"v_pile": (v_pile, "m/s"), "e": (e, ""), "loss_pct": (loss, "%")}


def ball_plate(v: np.ndarray, theta: np.ndarray, e: np.ndarray) -> dict[str, tuple[np.ndarray, str]]:
    normal, tangent = e * v * np.sin(np.radians(theta)), v * np.cos(np.radians(theta))
    return {"v_out": (np.hypot(normal, tangent), "ft/s"), "theta_out": (np.degrees(np.arctan2(normal, tangent)), "deg")}


def oblique_spheres(v1: np.ndarray, theta: np.ndarray, e: np.ndarray, m1: np.ndarray,
                    m2: np.ndarray) -> dict[str, tuple[np.ndarray, str]]:
    normal, tangent = v1 * np.cos(np.radians(theta)), v1 * np.sin(np.radians(theta))
    v1_normal = (m1 - e * m2) * normal / (m1 + m2)
    v2_normal = (1 + e) * m1 * normal / (m1 + m2)
    v1_out = np.hypot(v1_normal, tangent)
    before = m1 * v1**2
    loss = 100 * (before - m1 * v1_out**2 - m2 * v2_normal**2) / before
    return {"v1_out": (v1_out, "m/s"), "v2_out": (np.abs(v2_normal), "m/s"),
            "theta1_out": (np.degrees(np.arctan2(v1_normal, tangent)), "deg"), "loss_pct": (loss, "%")}


CLOSED_FORMS: dict[str, Callable[..., dict[str, tuple[np.ndarray, str]]]] = {
    "drop-rebound": drop_rebound, "pile-driver": pile_driver, "ball-plate": ball_plate,
    "oblique-spheres": oblique_spheres,
}


def main(template: str, path: str) -> None:
    """Answer every row of ``path`` and print one JSON line per row."""
    with open(path, encoding="utf-8") as handle:
        names = handle.readline().strip().split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    params = {name: data[:, i] for i, name in enumerate(names)}
    answers = CLOSED_FORMS[template](**params)
    param_lists = {name: column.tolist() for name, column in params.items()}
    answer_lists = {name: (values.tolist(), unit) for name, (values, unit) in answers.items()}
    write = sys.stdout.write
    for row in range(len(data)):
        write(json.dumps({"template": template, "row": row + 1,
                          "params": {name: values[row] for name, values in param_lists.items()},
                          "answers": {name: {"value": values[row], "unit": unit}
                                      for name, (values, unit) in answer_lists.items()}}) + "\n")


if __name__ == "__main__":
    main(*sys.argv[1:3])
