"""State logs: one row per loop step, as CSV or JSON lines (chosen by the file extension).

Why both: CSV opens in a spreadsheet or pandas with no code; JSON lines keep the nesting (one
pose per chain) and are easy to stream through ``jq``.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path
from typing import IO, Any

from robotspec.driver.state import RobotState
from robotspec.errors import RobotSpecError

__all__ = ["LOG_SUFFIXES", "StateLog"]

LOG_SUFFIXES = {".csv": "csv", ".jsonl": "jsonl", ".json": "jsonl", ".ndjson": "jsonl"}


class StateLog:
    """Writes :class:`RobotState` snapshots to ``path``; use as a state listener."""

    def __init__(self, path: Path, joint_names: tuple[str, ...], n_chains: int) -> None:
        fmt = LOG_SUFFIXES.get(path.suffix.lower())
        if fmt is None:
            raise RobotSpecError(
                f"unknown log format '{path.suffix}' (use .csv or .jsonl)", file=str(path)
            )
        self.format = fmt
        self.path = path
        self.rows = 0
        try:
            self._fh: IO[str] = path.open("w", encoding="utf-8", newline="")
        except OSError as exc:
            raise RobotSpecError(f"cannot write log: {exc.strerror}", file=str(path)) from None
        self._names = joint_names
        self._n_chains = n_chains
        self._csv: Any = None
        if fmt == "csv":
            self._csv = csv.writer(self._fh)
            header = ["t", "seqno", "command_mode", "operational_mode", "controller_state", "flags"]
            header += [f"q_{n}" for n in joint_names]
            header += [f"qcmd_{n}" for n in joint_names]
            for c in range(n_chains):
                header += [f"tcp{c}_{a}" for a in ("x", "y", "z", "qw", "qx", "qy", "qz")]
            # trajectory_stretch after error: columns read by position keep their place.
            header += ["error", "trajectory_stretch"]
            self._csv.writerow(header)

    def __call__(self, st: RobotState) -> None:
        """Append one state."""
        self.rows += 1
        n = len(self._names)
        if self._csv is not None:
            row: list[Any] = [
                f"{st.ts:.6f}",
                st.seqno,
                st.command_mode.name,
                st.operational_mode.name,
                st.controller_state.name,
                f"0x{int(st.flags):x}",
            ]
            row += _pad(st.joint_position.tolist(), n)
            row += _pad(st.position_command.tolist(), n)
            for c in range(self._n_chains):
                if c < len(st.kin_chain_tcp):
                    p = st.kin_chain_tcp[c]
                    row += [*p.position.tolist(), *p.orientation.tolist()]
                else:
                    row += [""] * 7
            row.append(st.error_message)
            row.append(f"{st.trajectory_stretch:.6g}")
            self._csv.writerow(row)
            return
        rec = {
            "t": round(st.ts, 6),
            "seqno": st.seqno,
            "command_mode": st.command_mode.name,
            "operational_mode": st.operational_mode.name,
            "controller_state": st.controller_state.name,
            "flags": int(st.flags),
            "joint_position": st.joint_position.tolist(),
            "joint_velocity": st.joint_velocity.tolist(),
            "position_command": st.position_command.tolist(),
            "velocity_command": st.velocity_command.tolist(),
            "kin_chain_tcp": [
                {"position": p.position.tolist(), "orientation": p.orientation.tolist()}
                for p in st.kin_chain_tcp
            ],
            "trajectory_running": st.trajectory_running,
            "trajectory_time": st.trajectory_time,
            "trajectory_max_time": st.trajectory_max_time,
            "trajectory_stretch": st.trajectory_stretch,
            "error": st.error_message,
        }
        self._fh.write(json.dumps(rec) + "\n")

    def close(self) -> None:
        """Flush and close the file."""
        self._fh.close()


def _pad(values: list[float], n: int) -> list[Any]:
    return [*values, *([""] * (n - len(values)))] if len(values) < n else values
