"""Command modes, state flags and the frozen state snapshot the driver publishes each step.

Why enums with the robdef's numeric values: logs, scripts and a future Robot Raconteur front end
must show exactly the numbers the reference serves (mode 0, flags ``0x60000``, ...), so the
conformance scenarios can be compared literally.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import IntEnum, IntFlag

import numpy as np

from robotspec.arrays import F64

__all__ = [
    "ActionStatus",
    "CommandMode",
    "ControllerState",
    "EstopSource",
    "OperationalMode",
    "RobotState",
    "StateFlags",
    "TcpPose",
]


class CommandMode(IntEnum):
    """``RobotCommandMode``: what the driver is doing on the client's behalf."""

    invalid_state = -1
    halt = 0
    jog = 1
    trajectory = 2
    position_command = 3
    velocity_command = 4
    homing = 5


class OperationalMode(IntEnum):
    """``RobotOperationalMode`` of the vendor controller."""

    undefined = 0
    manual_reduced_speed = 1
    manual_full_speed = 2
    auto = 3
    cobot = 4


class ControllerState(IntEnum):
    """``RobotControllerState`` of the vendor controller."""

    undefined = 0
    init = 1
    motor_on = 2
    motor_off = 3
    guard_stop = 4
    emergency_stop = 5
    emergency_stop_reset = 6


class EstopSource(IntEnum):
    """Where an emergency stop came from (the reference's ``_estop_source`` codes)."""

    none = 0
    button1 = 1
    other = 2
    fault = 3
    internal = 4


class StateFlags(IntFlag):
    """``RobotStateFlags`` bits as the robdef numbers them."""

    none = 0
    error = 0x1
    fatal_error = 0x2
    estop = 0x4
    estop_button1 = 0x8
    estop_software = 0x800
    estop_fault = 0x1000
    estop_internal = 0x2000
    estop_other = 0x4000
    enabled = 0x20000
    ready = 0x40000
    homed = 0x80000
    homing_required = 0x100000
    communication_failure = 0x200000
    valid_position_command = 0x1000000
    valid_velocity_command = 0x2000000
    trajectory_running = 0x4000000


#: The flag each e-stop source adds to ``estop``.
ESTOP_SOURCE_FLAGS: dict[int, StateFlags] = {
    EstopSource.button1: StateFlags.estop_button1,
    EstopSource.other: StateFlags.estop_other,
    EstopSource.fault: StateFlags.estop_fault,
    EstopSource.internal: StateFlags.estop_internal,
}


class ActionStatus(IntEnum):
    """``ActionStatusCode`` values a trajectory generator reports."""

    unknown = 0
    queued = 1
    running = 2
    complete = 3


@dataclass(frozen=True)
class TcpPose:
    """A chain's TCP pose: position (m) and unit quaternion ``(w, x, y, z)``, in the base frame."""

    position: F64
    orientation: F64


def _frozen(a: F64) -> F64:
    if a.dtype == np.float64 and a.ndim == 1:
        # A read-only view of a bytes copy: a third of the cost of copy-then-lock (the loop
        # freezes five arrays a step), and its WRITEABLE flag cannot be turned back on.
        return np.frombuffer(a.tobytes(), dtype=np.float64)
    out = np.array(a, dtype=np.float64, copy=True)
    out.flags.writeable = False
    return out


_EMPTY = _frozen(np.zeros(0))


@dataclass(frozen=True)
class RobotState:
    """One step's published state: RobotState and AdvancedRobotState fields together.

    Snapshots are immutable (arrays are read-only copies), so a client or logger may keep them
    while the loop runs on. Empty arrays mean "not available" (e.g. after communication loss),
    as in the reference.
    """

    ts: float
    seqno: int
    command_mode: CommandMode
    operational_mode: OperationalMode
    controller_state: ControllerState
    flags: StateFlags
    joint_position: F64 = field(default_factory=lambda: _EMPTY)
    joint_velocity: F64 = field(default_factory=lambda: _EMPTY)
    joint_effort: F64 = field(default_factory=lambda: _EMPTY)
    position_command: F64 = field(default_factory=lambda: _EMPTY)
    velocity_command: F64 = field(default_factory=lambda: _EMPTY)
    kin_chain_tcp: tuple[TcpPose, ...] = ()
    kin_chain_tcp_vel: tuple[F64, ...] = ()
    trajectory_running: bool = False
    trajectory_time: float = 0.0
    trajectory_max_time: float = 0.0
    trajectory_current_waypoint: int = 0
    #: How much the segment being run was slowed to stay within the joint limits (its duration
    #: over the planned one; 1.0 as planned or with no trajectory). Not in the robdef.
    trajectory_stretch: float = 1.0
    config_seqno: int = 1
    speed_ratio: float = 1.0
    error_message: str = ""

    @property
    def ready(self) -> bool:
        """Whether the robot reports itself ready to move."""
        return bool(self.flags & StateFlags.ready)


def frozen_array(a: F64 | None) -> F64:
    """A read-only copy of ``a`` (empty when None) for a snapshot."""
    return _EMPTY if a is None else _frozen(a)


_new_object = object.__new__


def robot_state_snapshot(**fields: object) -> RobotState:
    """A :class:`RobotState` from every one of its fields, without the dataclass ``__init__``.

    Why: a frozen dataclass sets each of its 20 fields through ``object.__setattr__``, which at
    1 kHz was the largest single cost of publishing a step. The loop passes every field (a test
    checks the result equals the one the constructor builds); the snapshot is as immutable.
    """
    state: RobotState = _new_object(RobotState)
    state.__dict__.update(fields)
    return state


def tcp_pose_snapshot(position: F64, orientation: F64) -> TcpPose:
    """A :class:`TcpPose` without the frozen-dataclass ``__init__`` (see above)."""
    pose: TcpPose = _new_object(TcpPose)
    pose.__dict__.update(position=position, orientation=orientation)
    return pose
