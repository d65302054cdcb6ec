"""Conversions at the client boundary: mode names, units of streamed commands, tool frames."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from robotspec.arrays import F64
from robotspec.driver.commands import RobotJointCommand
from robotspec.driver.errors import InvalidArgumentError, InvalidOperationError
from robotspec.driver.robot_info import ToolInfo
from robotspec.driver.state import CommandMode
from robotspec.model.rotations import quat_wxyz_to_matrix

POSITION_UNITS = {
    "implicit": 1.0,
    "radian": 1.0,
    "meter": 1.0,
    "degree": math.pi / 180.0,
    "ticks_rot": 2.0 * math.pi / 2**20,
    "nanoticks_rot": 2.0 * math.pi / (2**20 * 1e9),
}
#: ``RobotJointCommand.seqno`` is a ``uint64``: counters wrap around at this modulus.
SEQNO_MODULUS = 1 << 64
#: A position-stream sample at most this many seqnos behind the last accepted one is out of
#: order and ignored (the reference ignores every lower seqno); one further behind means the
#: client restarted its counter, and is accepted.
STREAM_REORDER_WINDOW = 1000

VELOCITY_UNITS = {
    "implicit": 1.0,
    "radian_second": 1.0,
    "meter_second": 1.0,
    "degree_second": math.pi / 180.0,
}


def parse_mode(value: CommandMode | int | str) -> CommandMode:
    """A client's mode (enum, number or name); ``invalid_state`` cannot be requested."""
    if isinstance(value, CommandMode):
        return value
    if isinstance(value, str):
        try:
            return CommandMode[value]
        except KeyError:
            raise InvalidOperationError("Invalid command mode specified") from None
    try:
        mode = CommandMode(int(value))
    except (ValueError, TypeError):
        raise InvalidOperationError("Invalid command mode specified") from None
    if mode is CommandMode.invalid_state:
        raise InvalidOperationError("Invalid command mode specified")
    return mode


def tool_transform(tool: ToolInfo | None) -> tuple[F64, F64] | None:
    """A tool's TCP as (rotation, translation) in the flange frame; None without a tool."""
    if tool is None:
        return None
    return (
        quat_wxyz_to_matrix(tool.tcp.rotation.as_tuple()),
        np.array(tool.tcp.translation.as_tuple()),
    )


def as_lists(
    tf: tuple[F64, F64] | None,
) -> tuple[list[float], list[float]] | None:
    """A transform as plain lists (row-major rotation, translation), for frozen state."""
    if tf is None:
        return None
    return [float(x) for x in tf[0].reshape(9)], [float(x) for x in tf[1]]


def twist_vector(velocity: Any) -> Any:
    """A spatial velocity from ``{angular: {x,y,z}, linear: {x,y,z}}`` or a 6-sequence."""
    if isinstance(velocity, dict):
        try:
            a, lin = velocity["angular"], velocity["linear"]
            return [a["x"], a["y"], a["z"], lin["x"], lin["y"], lin["z"]]
        except (KeyError, TypeError):
            raise InvalidArgumentError(
                "velocity must be {angular: {x, y, z}, linear: {x, y, z}}"
            ) from None
    return velocity


def convert_command(cmd: RobotJointCommand, n: int, units: dict[str, float]) -> F64 | None:
    """A streamed command in SI units, or None when it must be ignored."""
    values = cmd.command  # a float64 vector (RobotJointCommand converts anything else)
    if values.shape[0] != n or not np.all(np.isfinite(values)):
        return None
    if len(cmd.units) not in (0, n):
        return None
    if cmd.units:
        try:
            scale = np.array([units[u] for u in cmd.units])
        except KeyError:
            return None
        values = values * scale
    return values


def seqno_out_of_order(seqno: int, last: int) -> bool:
    """Whether a stream sample numbered ``seqno`` is older than ``last``, the last accepted.

    The reference ignores any seqno below the last accepted one, so a single sample with a huge
    seqno (a client bug, or a counter near the top of ``uint64``) locks the stream for good:
    every later sample is "older". Here seqnos are compared modulo 2**64, so a counter that wraps
    from 2**64 - 1 to 0 goes on, and a sample counts as out of order only when it is at most
    :data:`STREAM_REORDER_WINDOW` behind; a larger step back is a restarted counter and is
    accepted. Equal seqnos are accepted (the same sample, re-read). ``last`` < 0: none yet.
    """
    if last < 0:
        return False
    behind = (last - seqno) % SEQNO_MODULUS
    return 0 < behind <= STREAM_REORDER_WINDOW
