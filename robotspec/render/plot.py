"""``robotspec drive --plot``: joint positions and position commands over time, after a run.

Why a recorder of our own rather than re-reading ``--log``: the plot must work without a log
file, and a listener that keeps three arrays per step costs nothing next to the loop. Why
matplotlib's Agg backend: it draws to a PNG with no display; it is selected explicitly, so a
user's MPLBACKEND cannot make ``drive`` open a window.

matplotlib is imported through ``importlib`` and used as ``Any`` so the package's strict typing
does not depend on its stubs.
"""

from __future__ import annotations

import importlib
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from robotspec.arrays import F64
from robotspec.driver.state import RobotState
from robotspec.extras import MATPLOTLIB, require

__all__ = ["JointTrace", "PlotSummary", "plot_joint_trace"]


class JointTrace:
    """A state listener that records time, joint positions and position commands per step."""

    def __init__(self, joint_names: tuple[str, ...]) -> None:
        self.joint_names = joint_names
        self._t: list[float] = []
        self._q: list[F64] = []
        self._cmd: list[F64] = []

    def __call__(self, st: RobotState) -> None:
        """Record one state (a lost-feedback state, with empty arrays, records NaN)."""
        n = len(self.joint_names)
        self._t.append(float(st.ts))
        self._q.append(_row(st.joint_position, n))
        self._cmd.append(_row(st.position_command, n))

    def __len__(self) -> int:
        return len(self._t)

    def arrays(self) -> tuple[F64, F64, F64]:
        """Times (N,), positions (N, J) and commands (N, J), NaN where not available."""
        n = len(self.joint_names)
        if not self._t:
            return np.zeros(0), np.zeros((0, n)), np.zeros((0, n))
        return np.array(self._t), np.stack(self._q), np.stack(self._cmd)


def _row(values: F64, n: int) -> F64:
    out = np.full(n, math.nan)
    k = min(n, len(values))
    out[:k] = values[:k]
    return out


@dataclass(frozen=True)
class PlotSummary:
    """What was drawn: lines of positions and of commands, and the samples per line."""

    path: Path
    position_lines: int
    command_lines: int
    samples: int

    @property
    def lines(self) -> int:
        """All lines drawn."""
        return self.position_lines + self.command_lines


def plot_joint_trace(trace: JointTrace, path: Path, *, title: str = "") -> PlotSummary:
    """Draw each joint's position (solid) and its command (dashed, same colour) into a PNG.

    A joint's command line is left out when no position command was ever sent to it (the robot
    was only jogged or halted), so the line count tells what the run commanded.
    """
    matplotlib: Any = require(MATPLOTLIB, "--plot")
    matplotlib.use("Agg", force=True)
    figure_mod: Any = importlib.import_module("matplotlib.figure")
    backend: Any = importlib.import_module("matplotlib.backends.backend_agg")
    t, q, cmd = trace.arrays()
    t = t - t[0] if len(t) else t
    fig = figure_mod.Figure(figsize=(10, 5.5), dpi=100, layout="constrained")
    backend.FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    colours = matplotlib.colormaps["tab20"].colors
    n_pos = n_cmd = 0
    for j, name in enumerate(trace.joint_names):
        colour = colours[(2 * j) % len(colours)]
        ax.plot(t, q[:, j], color=colour, linewidth=1.6, label=name)
        n_pos += 1
        if np.any(np.isfinite(cmd[:, j])):
            ax.plot(t, cmd[:, j], color=colour, linewidth=1.0, linestyle="--")
            n_cmd += 1
    ax.set_xlabel("time (s)")
    ax.set_ylabel("joint position (rad or m)")
    ax.set_title(title or "joint positions (solid) and position commands (dashed)")
    ax.grid(True, alpha=0.3)
    if trace.joint_names:
        ax.legend(loc="center left", bbox_to_anchor=(1.01, 0.5), fontsize="small", frameon=False)
    metadata = {
        "Software": "robotspec drive --plot",
        "robotspec:position_lines": str(n_pos),
        "robotspec:command_lines": str(n_cmd),
        "robotspec:samples": str(len(t)),
    }
    import io

    from robotspec.files.writing import write_file

    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", metadata=metadata)
    write_file(path, buffer.getvalue(), force=True)  # never through a link; whole or not at all
    return PlotSummary(path=path, position_lines=n_pos, command_lines=n_cmd, samples=len(t))
