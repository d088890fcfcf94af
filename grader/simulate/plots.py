"""Pictures of a simulation: position, velocity and contact force against time, one column per
phase (a 1 ms contact and a 0.6 s fall do not share a time axis legibly)."""

from __future__ import annotations

import io
from pathlib import Path
from typing import TYPE_CHECKING, Any

from grader.base.errors import GraderError
from grader.base.files import write_atomic

if TYPE_CHECKING:
    from grader.simulate.walker import Simulation


def _pyplot() -> Any:
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        raise GraderError("--plot needs matplotlib: pip install matplotlib") from None
    return plt


def plot_formats() -> tuple[str, ...]:
    """The file name endings a plot can be written as (matplotlib's, without the dot).

    >>> {"png", "pdf", "svg"} <= set(plot_formats())
    True
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    _pyplot()
    return tuple(sorted(FigureCanvasAgg.get_supported_filetypes()))


def check_plot_target(target: Path) -> str:
    """The format of a plot file, from its name; refused before any work if it has none we write."""
    formats = plot_formats() if target.suffix else ()
    fmt = target.suffix[1:].lower()
    if fmt not in formats:
        raise GraderError(f"--plot {target}: expected a file name ending in one of "
                          f"{', '.join('.' + f for f in (formats or plot_formats()))}, got "
                          f"{repr(target.suffix) if target.suffix else 'no ending'}")
    if target.is_dir():
        raise GraderError(f"--plot {target}: expected a file name, got a folder")
    folder = target.parent
    if not folder.is_dir():
        raise GraderError(f"--plot {target}: expected a file in an existing folder, but {folder} "
                          f"{'is a file' if folder.exists() else 'does not exist'}; create it first or choose "
                          "another name")
    return fmt


def plot_simulation(simulation: Simulation, target: Path) -> None:
    """Write a picture (PNG, PDF, SVG, ...; the name's ending says which) of every phase's positions,
    velocities and contact force. Written atomically: a failed run leaves no half-written file."""
    fmt = check_plot_target(target)
    plt = _pyplot()
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
    picture = io.BytesIO()
    figure.savefig(picture, format=fmt, dpi=110)
    plt.close(figure)
    try:
        write_atomic(target, picture.getvalue())
    except OSError as error:
        raise GraderError(f"--plot {target}: cannot write ({error.strerror})") from None
