"""Pictures of a simulation: position, velocity and contact force against time, one column per
phase (a 1 ms contact and a 0.6 s fall do not share a time axis legibly)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from grader.errors import GraderError

if TYPE_CHECKING:
    from grader.simulate.walker import Simulation


def plot_simulation(simulation: Simulation, target: Path) -> None:
    """Write a PNG of every phase's positions, velocities and contact force."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        raise GraderError("--plot needs matplotlib: pip install matplotlib") from None
    import numpy as np

    phases = simulation.phases
    figure, axes = plt.subplots(3, len(phases), figsize=(4.2 * len(phases), 7.5), squeeze=False,
                                constrained_layout=True)
    for column, phase in enumerate(phases):
        time = np.array(phase.path.t)
        states = np.array(phase.path.y)
        half = states.shape[1] // 2
        scale, unit = (1e3, "ms") if time[-1] - time[0] < 0.05 else (1.0, "s")
        shown = [i for i in range(half) if np.ptp(states[:, i]) > 0 or np.ptp(states[:, half + i]) > 0]
        for row, offset, label in ((0, 0, "position (m)"), (1, half, "velocity (m/s)")):
            for index in shown:
                axes[row][column].plot((time - time[0]) * scale, states[:, offset + index], marker=".",
                                       markersize=3, label=phase.names[offset + index])
            axes[row][column].set_ylabel(label)
            axes[row][column].legend(fontsize=8)
        axes[2][column].plot((time - time[0]) * scale, phase.path.force, color="#d62728", marker=".", markersize=3)
        axes[2][column].set_ylabel("contact force (N)")
        axes[2][column].set_xlabel(f"time in phase ({unit})")
        axes[0][column].set_title(phase.label, fontsize=10)
    nominal = f"; {', '.join(simulation.nominal)} = 1 (no value in the template)" if simulation.nominal else ""
    figure.suptitle(f"{simulation.template}: simulated with {', '.join(simulation.effects)}{nominal}")
    target.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(target, dpi=110)
    plt.close(figure)
