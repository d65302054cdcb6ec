"""Validation of client commands, and the guard every outgoing command passes.

Why two layers: client calls (jog, streaming, trajectories) are checked up front so a bad call
fails with a clear InvalidArgument; but a bug in a profile, an interpolation overshoot or a stale
stream must still never reach the robot, so :class:`CommandGuard` clamps every command on the send
path to the joint position limits and to what the velocity limits allow in one period, and refuses
non-finite values outright.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from robotspec.arrays import F64
from robotspec.driver.errors import InvalidArgumentError
from robotspec.driver.robot_info import RobotInfo

__all__ = [
    "CommandGuard",
    "JointLimitArrays",
    "RobotJointCommand",
    "check_speed_ratio",
    "joint_array",
]


@dataclass(frozen=True)
class RobotJointCommand:
    """A streamed ``RobotJointCommand``: what a client writes to the position/velocity wire.

    ``command`` is kept as a float64 array, taken as is when it already is one (the service
    hands over the array Robot Raconteur decoded: no copy, no list on the way); anything else
    (a list, a tuple) is converted once here. Values are checked by the loop, which ignores a
    sample of the wrong length or with NaN, as every invalid stream sample is ignored.
    """

    seqno: int
    state_seqno: int
    command: F64
    units: Sequence[str] = ()

    def __post_init__(self) -> None:
        cmd = self.command
        if not (isinstance(cmd, np.ndarray) and cmd.dtype == np.float64 and cmd.ndim == 1):
            try:
                arr = np.asarray(cmd, dtype=np.float64).reshape(-1)
            except (TypeError, ValueError):
                arr = np.zeros(0)  # never accepted: no joint count is 0
            object.__setattr__(self, "command", arr)


#: Speed ratio range, inclusive (reference: InvalidArgument "Invalid speed_ratio" outside).
SPEED_RATIO_MIN = 0.1
SPEED_RATIO_MAX = 10.0


@dataclass(frozen=True)
class JointLimitArrays:
    """Per-joint limits as arrays, built once so the loop never touches pydantic models."""

    lower: F64
    upper: F64
    velocity: F64
    acceleration: F64
    reduced_velocity: F64
    reduced_acceleration: F64
    home: F64
    prismatic: npt.NDArray[np.bool_]

    @classmethod
    def from_info(cls, info: RobotInfo) -> JointLimitArrays:
        """Arrays from a RobotInfo; reduced limits <= 0 default to the full ones (as reference)."""
        lim = [j.joint_limits for j in info.joint_info]
        vel = np.array([x.velocity for x in lim])
        acc = np.array([x.acceleration for x in lim])
        rv = np.array([x.reduced_velocity for x in lim])
        ra = np.array([x.reduced_acceleration for x in lim])
        arrays = {
            "lower": np.array([x.lower for x in lim]),
            "upper": np.array([x.upper for x in lim]),
            "velocity": vel,
            "acceleration": acc,
            "reduced_velocity": np.where(rv > 0, rv, vel),
            "reduced_acceleration": np.where(ra > 0, ra, acc),
            "home": np.array([x.home for x in lim]),
            "prismatic": np.array([j.joint_type.value == "prismatic" for j in info.joint_info]),
        }
        for a in arrays.values():
            a.flags.writeable = False
        return cls(**arrays)

    @property
    def count(self) -> int:
        """Number of joints."""
        return int(self.lower.shape[0])


def joint_array(name: str, value: Any, n: int) -> F64:
    """``value`` as a finite float array of length ``n``, or InvalidArgument.

    Why here: NaN or infinity in any client input must be refused before it reaches a profile,
    because ``NaN > limit`` is False and would slip through every comparison after it.
    """
    try:
        arr = np.array(value, dtype=np.float64).reshape(-1)
    except (TypeError, ValueError):
        raise InvalidArgumentError(f"{name} must be an array of {n} numbers") from None
    if arr.shape[0] != n:
        raise InvalidArgumentError(f"{name} array must have {n} elements")
    if not np.all(np.isfinite(arr)):
        raise InvalidArgumentError(f"{name} must not contain NaN or infinite values")
    return arr


def finite_scalar(name: str, value: Any) -> float:
    """``value`` as a finite float, or InvalidArgument."""
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise InvalidArgumentError(f"{name} must be a number") from None
    if not math.isfinite(x):
        raise InvalidArgumentError(f"{name} must be finite")
    return x


def check_speed_ratio(value: Any) -> float:
    """A speed ratio in [0.1, 10], or InvalidArgument "Invalid speed_ratio"."""
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise InvalidArgumentError("Invalid speed_ratio") from None
    if not (math.isfinite(x) and SPEED_RATIO_MIN <= x <= SPEED_RATIO_MAX):
        raise InvalidArgumentError("Invalid speed_ratio")
    return x


class CommandGuard:
    """Last check on the send path: finite, within position limits, within velocity limits.

    Position commands are clamped to ``[lower, upper]`` and rate-limited so that the implied
    velocity from the previous command (or the measured position when there is none) never
    exceeds the velocity limit. Velocity commands are clamped to the velocity limit and reduced
    near a position limit so one period cannot cross it. A non-finite command is dropped and
    counted (the loop then reports an error). Work arrays are preallocated.
    """

    def __init__(self, limits: JointLimitArrays, period: float) -> None:
        self.limits = limits
        self.period = period
        self._max_step = limits.velocity * period
        self._neg_max_step = -self._max_step
        self._max_step_l: list[float] = self._max_step.tolist()
        self._velocity_l: list[float] = limits.velocity.tolist()
        self._lower_l: list[float] = limits.lower.tolist()
        self._upper_l: list[float] = limits.upper.tolist()
        self._neg_velocity = -limits.velocity
        self._pos = np.zeros(limits.count)
        self._vel = np.zeros(limits.count)
        self.clamped = 0
        self.refused = 0

    def position(self, cmd: F64, reference: F64, dt: float | None = None) -> F64 | None:
        """The safe position command for ``cmd``, given the previous command or measured q.

        ``dt`` is the time the step covers (default: the period): the velocity limit allows
        ``velocity * dt`` of motion. Per joint in plain floats (the loop calls this every step;
        on a few joints that is several times faster than numpy calls); the clamps propagate NaN
        as numpy's do.
        """
        c = cmd.tolist()
        if not all(map(math.isfinite, c)):
            self.refused += 1
            return None
        r = reference.tolist()
        steps = self._max_step_l
        if dt is not None and dt != self.period:
            steps = [v * dt for v in self._velocity_l]
        out = []
        for x, ref, step, lo, hi in zip(c, r, steps, self._lower_l, self._upper_l, strict=True):
            d = x - ref
            d = -step if d < -step else d
            d = step if d > step else d
            y = d + ref
            y = lo if y < lo else y
            out.append(hi if y > hi else y)
        if out != c:
            self.clamped += 1
        return np.array(out)

    def velocity(self, cmd: F64, measured: F64) -> F64 | None:
        """The safe velocity command for ``cmd`` at measured position ``measured``."""
        if not _finite(cmd):
            self.refused += 1
            return None
        out = self._vel
        np.maximum(cmd, self._neg_velocity, out=out)
        np.minimum(out, self.limits.velocity, out=out)
        dt = self.period
        hi = np.maximum((self.limits.upper - measured) / dt, 0.0)
        lo = np.minimum((self.limits.lower - measured) / dt, 0.0)
        np.maximum(out, lo, out=out)
        np.minimum(out, hi, out=out)
        if out.tolist() != cmd.tolist():
            self.clamped += 1
        return out.copy()


def _finite(a: F64) -> bool:
    """``np.all(np.isfinite(a))`` for the loop's short arrays, at a quarter of the cost."""
    return all(map(math.isfinite, a.tolist()))
