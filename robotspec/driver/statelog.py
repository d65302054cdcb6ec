"""State logs: one row per loop step, as CSV or JSON lines (chosen by the file extension).

Why both: CSV opens in a spreadsheet or pandas with no code; JSON lines keep the nesting (one
pose per chain) and are easy to stream through ``jq``.
"""

from __future__ import annotations

import csv
import errno
import json
import os
import stat
from pathlib import Path
from typing import IO, Any

from robotspec.driver.state import RobotState
from robotspec.errors import RobotSpecError

__all__ = ["LOG_SUFFIXES", "StateLog"]

LOG_SUFFIXES = {".csv": "csv", ".jsonl": "jsonl", ".json": "jsonl", ".ndjson": "jsonl"}


def _open_log(path: Path) -> IO[str]:
    """The log file, opened as ``write_file`` opens outputs: never through a link, never a FIFO.

    Why not :func:`robotspec.files.writing.write_file`: a log is streamed row by row while the
    driver runs, not written whole; the last component is opened with ``O_NOFOLLOW`` (a link
    planted at the log's name is refused) and must be a regular file.
    """
    flags = os.O_WRONLY | os.O_CREAT | os.O_TRUNC
    flags |= getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NONBLOCK", 0)
    try:
        if path.is_symlink():
            raise OSError(errno.ELOOP, "is a symbolic link")
        fd = os.open(path, flags, 0o666)
    except OSError as exc:
        why = {
            errno.ELOOP: "is a symbolic link; robotspec does not write through links",
            errno.ENXIO: "not a regular file (a FIFO without a reader)",
        }.get(exc.errno or 0, exc.strerror or str(exc))
        raise RobotSpecError(
            f"cannot write log: {why}",
            file=str(path),
            kind="output",
        ) from None
    if not stat.S_ISREG(os.fstat(fd).st_mode):
        os.close(fd)
        raise RobotSpecError(
            "cannot write log: not a regular file (a device, FIFO or socket)",
            file=str(path),
            kind="output",
        )
    os.set_blocking(fd, True)
    return os.fdopen(fd, "w", encoding="utf-8", newline="")


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
        self._fh: IO[str] = _open_log(path)
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
            "joint_effort": st.joint_effort.tolist(),
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
