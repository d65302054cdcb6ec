"""The driver loop's state: every field of the loop, set up from the RobotInfo.

Why a class of its own: the loop's jobs (the timestep pipeline in :mod:`~robotspec.driver.loop`,
the state machine in :mod:`~robotspec.driver.modes`, the command fill in
:mod:`~robotspec.driver.fill`, the state fill in :mod:`~robotspec.driver.state_fill`) all read and
write one set of fields under one lock. They are mixins over this class, so each module has one
job and the type checker still sees every field where it is used.
"""

from __future__ import annotations

import math
import threading
from collections import deque
from collections.abc import Callable

import numpy as np

from robotspec.arrays import F64
from robotspec.driver.cartesian import chain_reach
from robotspec.driver.chain_kinematics import HPChain
from robotspec.driver.clock import Clock, RealClock
from robotspec.driver.commands import (
    CommandGuard,
    JointLimitArrays,
    RobotJointCommand,
)
from robotspec.driver.conversions import (
    as_lists,
    tool_transform,
)
from robotspec.driver.errors import (
    InvalidArgumentError,
)
from robotspec.driver.handles import (
    Completion,
    TrajectoryTask,
)
from robotspec.driver.loop_timing import LoopTiming
from robotspec.driver.profiles import JogMotion, StreamLimiter
from robotspec.driver.robot_info import (
    PayloadInfo,
    Pose,
    RobotCapability,
    RobotInfo,
    ToolInfo,
)
from robotspec.driver.state import (
    CommandMode,
    ControllerState,
    OperationalMode,
    RobotState,
    StateFlags,
    TcpPose,
)
from robotspec.model.rotations import quat_wxyz_to_matrix

__all__ = ["LoopState"]


class LoopState:
    """Every field of the driver loop; the arguments are ``DriverLoop``'s."""

    def __init__(
        self,
        robot_info: RobotInfo,
        default_joint_count: int = 0,
        *,
        clock: Clock | None = None,
        update_period: float = 0.01,
    ) -> None:
        if not (math.isfinite(update_period) and update_period > 0):
            raise InvalidArgumentError("update period must be a positive number of seconds")
        self._robot_info = robot_info
        self._joint_names: tuple[str, ...] = robot_info.joint_names
        self._joint_count = len(self._joint_names) or default_joint_count
        self._robot_uuid = robot_info.device_info.device.uuid
        self._robot_caps = robot_info.capability_bits
        self._uses_homing = robot_info.has(RobotCapability.homing_command)
        self._has_position_command = robot_info.has(RobotCapability.position_command)
        self._has_velocity_command = robot_info.has(RobotCapability.velocity_command)
        self._has_jog_command = robot_info.has(RobotCapability.jog_command)
        self._has_trajectory_command = robot_info.has(RobotCapability.trajectory_command)
        self._limits = JointLimitArrays.from_info(robot_info)
        self._set_up_chains(robot_info)
        self._set_up_seed_fields(update_period)
        self._lock = threading.RLock()
        self._clock: Clock = clock if clock is not None else RealClock()
        self._set_up_internals(update_period)

    def _set_up_chains(self, robot_info: RobotInfo) -> None:
        """Each chain's H/P kinematics, reach, tool and payload, from the RobotInfo."""
        n = self._joint_count
        chains = robot_info.chains
        self._chain_joints = [np.array(c.joint_numbers, dtype=np.intp) for c in chains]
        self._hp: list[HPChain] = []
        self._reach: list[float] = []
        for c in chains:
            fp = c.flange_pose or Pose()
            self._hp.append(
                HPChain(
                    np.array([h.as_tuple() for h in c.H]),
                    np.array([p.as_tuple() for p in c.P]),
                    prismatic=[bool(self._limits.prismatic[j]) for j in c.joint_numbers],
                    flange_rotation=quat_wxyz_to_matrix(fp.orientation.as_tuple()),
                    flange_position=np.array(fp.position.as_tuple()),
                )
            )
            self._reach.append(chain_reach(self._hp[-1].p, self._hp[-1].flange_p))
        self._current_tool: list[ToolInfo | None] = [c.current_tool for c in chains]
        self._current_payload: list[PayloadInfo | None] = [c.current_payload for c in chains]
        self._current_payload_pose: list[Pose | None] = [None for _ in chains]
        self._tool_tf: list[tuple[F64, F64] | None] = [
            tool_transform(t) for t in self._current_tool
        ]
        self._tool_tf_lists = [as_lists(t) for t in self._tool_tf]
        self._chain_idx_list = [list(c.joint_numbers) for c in chains]
        self._chain_is_all = [idx == list(range(n)) for idx in self._chain_idx_list]
        self._endpoint_key: tuple[bytes, bytes, int] | None = None
        self._endpoint_cache: tuple[list[TcpPose], list[F64]] | None = None

    def _set_up_seed_fields(self, update_period: float) -> None:
        """The reference driver's own fields: modes, measured state, flags, timeouts."""
        self._keep_going = False
        self._update_period = update_period
        self._speed_ratio = 1.0
        self._jog_joint_limit = math.radians(1000.0)
        self._trajectory_error_tol = math.radians(5.0)
        self._command_mode = CommandMode.halt
        self._operational_mode = OperationalMode.manual_reduced_speed
        self._controller_state = ControllerState.undefined
        self._joint_position: F64 = np.zeros(0)
        self._joint_velocity: F64 = np.zeros(0)
        self._joint_effort: F64 = np.zeros(0)
        self._position_command: F64 | None = None
        self._velocity_command: F64 | None = None
        self._endpoint_pose: list[TcpPose] | None = None
        self._endpoint_vel: list[F64] | None = None
        self._last_robot_state = -math.inf
        self._last_joint_state = -math.inf
        self._last_endpoint_state = -math.inf
        self._state_seqno = 0
        self._homed = False
        self._ready = False
        self._enabled = False
        self._stopped = False
        self._error = False
        self._estop_source = 0
        self._communication_failure = True
        self._communication_timeout = 0.25
        self._config_seqno = 1
        self._base_set_operational_mode = True
        self._base_set_controller_state = True

    def _set_up_internals(self, update_period: float) -> None:
        """Fields beyond the seed: the guard, jogs, streams, trajectories, timing, listeners."""
        self._guard = CommandGuard(self._limits, update_period)
        self._fault_message = ""
        self._flags = StateFlags.none
        self._flags_int = -1
        self._prev_mode = CommandMode.halt
        self._jog: JogMotion | None = None
        self._jog_waiter: Completion | None = None
        #: When the profile of a waited-for jog has ended: the arm must arrive by this time.
        self._jog_settle_deadline: float | None = None
        self._stream_limiter: StreamLimiter | None = None
        #: The last stream sample: (arrival time, position, velocity from the sample before, the
        #: interval between the two).
        self._stream_target: tuple[float, list[float], list[float] | None, float] | None = None
        self._stream_used: RobotJointCommand | None = None
        #: The duration of the current step (real elapsed time, see clock.step_duration).
        self._step_dt = update_period
        self._last_step_now: float | None = None
        self._jog_cartesian: tuple[int, F64] | None = None
        self._halt_ramp: JogMotion | None = None
        self._homing: Completion | None = None
        self._traj_active: TrajectoryTask | None = None
        self._traj_queue: deque[TrajectoryTask] = deque()
        self._traj_failed_this_step = False
        self._traj_hold: F64 | None = None
        self._jog_hold: F64 | None = None
        self._stream_position: RobotJointCommand | None = None
        self._stream_velocity: RobotJointCommand | None = None
        self._stream_last_seqno = -1
        self._stream_valid = StateFlags.none
        self._last_sent: F64 | None = None
        # What _last_sent_velocity derives from, lazily (it is read only when a motion starts):
        # the position sent the step before _last_sent, or the velocity command sent.
        self._prev_sent: F64 | None = None
        self._sent_velocity: F64 | None = None
        self._sent_dt = update_period
        self._sent_last_step = False
        self._epoch = self._clock.now()
        #: Deadlines, and the loop's own count of late wake-ups and missed periods.
        self._timing = LoopTiming(update_period, self._epoch)
        self._thread: threading.Thread | None = None
        #: Callers blocked in :meth:`_wait_for` on the loop thread: (predicate, event).
        self._waiters: list[tuple[Callable[[], bool], threading.Event]] = []
        self._scheduled: list[tuple[float, int, Callable[[], None]]] = []
        self._scheduled_count = 0
        self._listeners: list[Callable[[RobotState], None]] = []
        self._state = RobotState(
            ts=0.0,
            seqno=0,
            command_mode=self._command_mode,
            operational_mode=self._operational_mode,
            controller_state=self._controller_state,
            flags=StateFlags.communication_failure,
        )
        #: (event, chain, name) of tool_changed / payload_changed, in order.
        self.events: list[tuple[str, int, str]] = []
