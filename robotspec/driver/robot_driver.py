"""The seed's client API of a robot driver: modes, jogs, trajectories, streams, tools.

:class:`RobotDriver` is what clients (scripts, the Robot Raconteur service, tests) call. Every
member checks its arguments and the state machine, then hands work to the timestep pipeline of
:class:`~robotspec.driver.loop.DriverLoop`, which it extends.

The reference's defects are not copied: the deliberate deviations, each tested, are listed once,
in ``docs/driver.md`` ("Deliberate deviations from the reference").
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from robotspec.arrays import F64
from robotspec.driver.commands import (
    JointLimitArrays,
    RobotJointCommand,
    check_speed_ratio,
    finite_scalar,
    joint_array,
)
from robotspec.driver.conversions import (
    as_lists,
    parse_mode,
    tool_transform,
    twist_vector,
)
from robotspec.driver.errors import (
    InvalidArgumentError,
    InvalidOperationError,
    NotImplementedDriverError,
    OperationAbortedError,
    OperationFailedError,
)
from robotspec.driver.handles import (
    Completion,
    HomingGenerator,
    TrajectoryGenerator,
    TrajectoryTask,
)
from robotspec.driver.loop import DriverLoop
from robotspec.driver.profiles import JogMotion
from robotspec.driver.robot_info import (
    MAX_OFFSET_M,
    QUAT_TOL,
    DeviceInfo,
    PayloadInfo,
    Pose,
    Quaternion,
    RobotCapability,
    RobotInfo,
    ToolInfo,
)
from robotspec.driver.state import (
    CommandMode,
    ControllerState,
    OperationalMode,
    RobotState,
)
from robotspec.driver.trajectory import JointTrajectory, TrajectoryColumns, load_trajectory
from robotspec.errors import DriverError
from robotspec.exact import exact
from robotspec.model.rotations import quat_wxyz_to_matrix

__all__ = ["RobotDriver"]


class RobotDriver(DriverLoop):
    """Base class of robot drivers (the seed's ``AbstractRobot``): the client API over the loop.

    A subclass fills feedback in :meth:`_read_feedback` and implements
    :meth:`_send_robot_command`, :meth:`_send_enable`, :meth:`_send_disable` and
    :meth:`_send_reset_errors` (and :meth:`_start_homing` if it homes); see :class:`DriverLoop`
    for the constructor's arguments.
    """

    # ------------------------------------------------------------------ client API: modes

    @property
    def robot_state(self) -> RobotState:
        """The state published by the last step."""
        return self._state

    @property
    def command_mode(self) -> CommandMode:
        """The current command mode."""
        return self._command_mode

    @command_mode.setter
    def command_mode(self, value: CommandMode | int | str) -> None:
        self.set_command_mode(value)

    def set_command_mode(self, value: CommandMode | int | str) -> None:
        """Request a command mode: the reference's checks, in the order of its setter."""
        mode = parse_mode(value)
        with self._lock:
            current = self._command_mode
            comm_ok = not self._communication_failure
            error = self._error or bool(self._fault_message)
            if mode is CommandMode.halt and self._fault_message and not self._error:
                # A driver-internal fault is cleared by switching to halt (escalation level 1).
                self._fault_message = ""
                self._command_mode = CommandMode.halt
                return
            if current is CommandMode.invalid_state:
                if mode is CommandMode.homing:
                    if self._enabled and comm_ok and self._uses_homing:
                        self._command_mode = mode
                        return
                    raise InvalidOperationError("Cannot set homing command mode in current state")
                if mode is CommandMode.halt and self._enabled and not error and comm_ok:
                    self._command_mode = mode
                    return
            if not comm_ok:
                raise InvalidOperationError("Cannot set robot command mode in current state")
            if not self._ready and mode is not CommandMode.halt:
                if not (mode is CommandMode.homing and self._enabled and not error):
                    raise InvalidOperationError("Cannot set robot command mode in current state")
            if current is not CommandMode.halt and mode is not CommandMode.halt:
                raise InvalidOperationError('Must switch to "halt" before selecting new mode')
            if mode is CommandMode.jog:
                if not self._has_jog_command:
                    raise InvalidOperationError("Robot does not support jog command mode")
                self._jog = None
            elif mode is CommandMode.trajectory:
                if not self._has_trajectory_command:
                    raise InvalidOperationError("Robot does not support trajectory command mode")
            elif mode is CommandMode.position_command:
                if not self._has_position_command:
                    raise InvalidOperationError("Robot does not support position command mode")
            elif mode is CommandMode.velocity_command:
                if not self._has_velocity_command:
                    raise InvalidOperationError("Robot does not support velocity command mode")
            elif mode is CommandMode.homing:
                if not self._uses_homing:
                    raise InvalidOperationError("Robot does not support homing command mode")
            elif mode is not CommandMode.halt:
                raise InvalidOperationError("Invalid command mode specified")
            self._command_mode = mode

    def halt(self) -> None:
        """Stop motion: command mode ``halt`` (the reference lacks this robdef function)."""
        self.set_command_mode(CommandMode.halt)

    @property
    def operational_mode(self) -> OperationalMode:
        """The controller's operational mode."""
        return self._operational_mode

    @property
    def controller_state(self) -> ControllerState:
        """The controller's state."""
        return self._controller_state

    @property
    def current_errors(self) -> tuple[str, ...]:
        """Human-readable current errors (empty when healthy)."""
        out: list[str] = []
        if self._communication_failure:
            out.append("communication failure")
        if self._fault_message:
            out.append(self._fault_message)
        if self._error:
            out.append("robot error")
        if self._stopped:
            out.append("emergency stop")
        return tuple(out)

    @property
    def speed_ratio(self) -> float:
        """The speed ratio in [0.1, 10]."""
        return self._speed_ratio

    @speed_ratio.setter
    def speed_ratio(self, value: float) -> None:
        self._speed_ratio = check_speed_ratio(value)

    @property
    def joint_names(self) -> tuple[str, ...]:
        """Joint names in global order."""
        return self._joint_names

    @property
    def limits(self) -> JointLimitArrays:
        """Joint limits as arrays."""
        return self._limits

    @property
    def update_period(self) -> float:
        """The loop period in seconds."""
        return self._update_period

    @property
    def isoch_info(self) -> dict[str, float]:
        """``IsochInfo``: update rate, max downsample and epoch."""
        return {
            "update_rate": 1.0 / self._update_period,
            "max_downsample": 1000.0,
            "isoch_epoch": self._epoch,
        }

    @property
    def config_seqno(self) -> int:
        """The live ``config_seqno`` (the state snapshot's lags until the next step)."""
        with self._lock:
            return self._config_seqno

    @property
    def robot_info(self) -> RobotInfo:
        """The RobotInfo with current tools and payloads and the live ``config_seqno``."""
        with self._lock:
            chains = tuple(
                c.model_copy(
                    update={
                        "current_tool": self._current_tool[i],
                        "current_payload": self._current_payload[i],
                    }
                )
                for i, c in enumerate(self._robot_info.chains)
            )
            return self._robot_info.model_copy(
                update={"chains": chains, "config_seqno": self._config_seqno}
            )

    @property
    def device_info(self) -> DeviceInfo:
        """The RobotInfo's DeviceInfo."""
        return self._robot_info.device_info

    # ------------------------------------------------------------------ enable, errors, homing

    def enable(self) -> None:
        """Enable the drives (needs ``software_enable``)."""
        if not self._robot_info.has(RobotCapability.software_enable):
            raise InvalidOperationError("Robot does not support software enable")
        self._send_enable()

    def disable(self) -> None:
        """Disable the drives (needs ``software_enable``)."""
        if not self._robot_info.has(RobotCapability.software_enable):
            raise InvalidOperationError("Robot does not support software enable")
        self._send_disable()

    def reset_errors(self) -> None:
        """Clear a driver fault, and the robot's errors (needs ``software_reset_errors``)."""
        with self._lock:
            had_fault = bool(self._fault_message)
            self._fault_message = ""
        if self._robot_info.has(RobotCapability.software_reset_errors):
            self._send_reset_errors()
        elif not had_fault:
            raise InvalidOperationError("Robot does not support software reset errors")

    def home(self, wait: bool = True) -> Completion:
        """Home the robot (mode ``homing``); with ``wait`` return when homed."""
        with self._lock:
            if self._command_mode is not CommandMode.homing:
                raise InvalidOperationError("Robot must be in homing command mode to home")
            if self._homing is not None:
                raise InvalidOperationError("Homing already in progress")
            completion = Completion()
            self._homing = completion
            self._start_homing(completion)
        if wait:
            self._wait_completion(completion)
        return completion

    def homing_generator(self) -> HomingGenerator:
        """A generator whose first ``Next()`` homes the robot (needs ``homing_command``).

        Why: Robot Raconteur's ``home()`` returns a generator; the service hands this one out.
        """
        if not self._robot_info.has(RobotCapability.homing_command):
            raise InvalidOperationError("Robot does not support homing")
        return HomingGenerator(self)

    def _homing_finished(self, success: bool, message: str = "") -> None:
        """Called by the subclass when homing ends."""
        with self._lock:
            if self._homing is None:
                return
            if success:
                self._homing.succeed()
            else:
                self._homing.fail(OperationFailedError(message or "Homing failed"))
            self._homing = None

    # ------------------------------------------------------------------ jogging

    def _jog_preamble(self, not_ready: type[DriverError]) -> None:
        if self._command_mode is not CommandMode.jog:
            raise InvalidOperationError("Robot not in jog mode")
        if not self._ready or self._communication_failure:
            raise not_ready("Robot not ready")

    def _install_jog(self, motion: JogMotion, wait: bool) -> Completion | None:
        if self._jog_waiter is not None:
            self._jog_waiter.fail(OperationAbortedError("Operation interrupted by new jog command"))
        self._jog = motion
        self._jog_settle_deadline = None
        waiter = Completion() if wait else None
        self._jog_waiter = waiter
        return waiter

    def jog_freespace(self, joint_position: Any, max_velocity: Any, wait: bool = False) -> None:
        """Jog to ``joint_position`` (rad/m) at up to ``max_velocity``; ``wait`` for arrival."""
        n = self._joint_count
        with self._lock:
            self._jog_preamble(InvalidOperationError)
            target = joint_array("joint_position", joint_position, n)
            vmax = joint_array("max_velocity", max_velocity, n)
            if np.any(vmax <= 0.0):
                raise InvalidArgumentError("max_velocity must be greater than zero")
            vlim, alim = self._jog_limits()
            for i in range(n):
                if vmax[i] > vlim[i]:
                    raise InvalidArgumentError(
                        f"max_velocity[{i}] is greater than joint limits ({exact(vlim[i])})"
                    )
            measured = self._joint_position
            if np.any(np.abs(target - measured) > self._jog_joint_limit):
                raise InvalidArgumentError(
                    "Position command must be within "
                    f"{math.degrees(self._jog_joint_limit):.0f} degrees from current position"
                )
            lo, hi = self._limits.lower, self._limits.upper
            for i in range(n):
                if not lo[i] <= target[i] <= hi[i]:
                    raise InvalidArgumentError(
                        f"joint_position[{i}] = {exact(target[i])} is outside the joint limits "
                        f"[{exact(lo[i])}, {exact(hi[i])}]"
                    )
            ratio = self._speed_ratio
            existing = self._jog
            if existing is None:
                q0, v0 = self._start_point()
                motion = self._new_motion(q0, v0)
            else:
                motion = existing
            motion.vmax = np.minimum(vmax * ratio, vlim)
            motion.amax = np.minimum(alim * ratio, alim)
            motion.to_position(target, synchronize=existing is None)
            self._jog_cartesian = None
            waiter = self._install_jog(motion, wait)
        if waiter is not None:
            self._wait_completion(waiter)

    def jog_joint(self, joint_velocity: Any, timeout: float, wait: bool = False) -> None:
        """Jog at ``joint_velocity`` for ``timeout`` seconds, then stop; ``wait`` for the stop."""
        n = self._joint_count
        with self._lock:
            self._jog_preamble(OperationAbortedError)
            qd = joint_array("joint_velocity", joint_velocity, n)
            t = finite_scalar("timeout", timeout)
            if t <= 0.0:
                raise InvalidArgumentError("Invalid jog timeout specified")
            vlim, alim = self._jog_limits()
            if np.any(np.abs(qd) > vlim):
                raise InvalidArgumentError("Joint velocity exceeds joint limits")
            waiter = self._velocity_jog(qd, t, wait, vlim, alim)
        if waiter is not None:
            self._wait_completion(waiter)

    def _velocity_jog(
        self, qd: F64, timeout: float, wait: bool, vlim: F64, alim: F64
    ) -> Completion | None:
        existing = self._jog
        if existing is None:
            q0, v0 = self._start_point()
            motion = self._new_motion(q0, v0)
        else:
            motion = existing
        motion.vmax = vlim.copy()
        motion.amax = np.minimum(alim * self._speed_ratio, alim)
        motion.t = 0.0
        motion.coordinated = False
        motion.at_velocity(qd, timeout)
        return self._install_jog(motion, wait)

    def jog_cartesian(
        self, velocity: Any, timeout: float, wait: bool = False, chain: int = 0
    ) -> None:
        """Jog a chain's TCP at spatial ``velocity`` ``[wx, wy, wz, vx, vy, vz]`` (base frame).

        The joint velocities come from the chain's Jacobian (damped least squares, see
        :mod:`robotspec.driver.cartesian`), scaled down together when one would exceed its limit,
        recomputed every step; all joints speed up and brake together, so the tool keeps its
        direction. Refused (InvalidArgument) when the chain cannot move along ``velocity`` at this
        pose (near a singularity, too few joints, a joint at its limit); a jog that reaches such
        a pose on its way brakes to a stop, and a waiting caller gets OperationFailed.
        """
        with self._lock:
            self._jog_preamble(OperationAbortedError)
            twist = joint_array("velocity", twist_vector(velocity), 6)
            t = finite_scalar("timeout", timeout)
            if t <= 0.0:
                raise InvalidArgumentError("Invalid jog timeout specified")
            self._check_chain(chain, "jog")
            q_start = self._jog.q if self._jog is not None else self._start_point()[0]
            rates = self._cartesian_rates(chain, q_start, twist)
            if isinstance(rates, str):
                raise InvalidArgumentError(f"jog_cartesian refused: {rates}")
            vlim, alim = self._jog_limits()
            waiter = self._velocity_jog(np.zeros(self._joint_count), t, wait, vlim, alim)
            assert self._jog is not None
            self._jog.coordinated = True
            self._jog.target_velocity = rates
            self._jog_cartesian = (chain, twist)
        if waiter is not None:
            self._wait_completion(waiter)

    # ------------------------------------------------------------------ trajectories

    def execute_trajectory(
        self, trajectory: JointTrajectory | TrajectoryColumns
    ) -> TrajectoryGenerator:
        """Check and queue a trajectory; drive it by calling ``Next()`` on the generator.

        Everything proportional to the trajectory runs on the caller's thread (the service
        thread that received the upload), outside the loop's lock: decoding into arrays, the
        waypoint checks and the plan (interpolation and any stretch) only read the immutable
        limits and the speed ratio, sampled once. The finished plan reaches the loop at a
        period boundary in one O(1) hand-over: the start-point and mode checks and one
        reference stored (active task or queue) under the lock the loop holds for each whole
        step. The loop then samples it in O(1) per step (O(log n) when it enters a new
        segment) and publishes scalars of it, never a copy. So a client uploading 50,000
        waypoints does not make the loop miss its periods.
        """
        ratio = self._speed_ratio
        interp = load_trajectory(trajectory, self._joint_names, self._limits, ratio)
        with self._lock:
            measured = self._joint_position
            if measured.shape[0] != self._joint_count or np.any(
                np.abs(measured - interp.positions[0]) > self._trajectory_error_tol
            ):
                raise InvalidArgumentError("Starting waypoint too far from current joint positions")
            if self._command_mode is not CommandMode.trajectory:
                raise InvalidOperationError(
                    "Robot must be in trajectory mode to execute trajectory"
                )
            task = TrajectoryTask(interp)
            if self._traj_active is None:
                self._traj_active = task
            else:
                self._traj_queue.append(task)
            return TrajectoryGenerator(self, task)

    def _abort_trajectory(self, task: TrajectoryTask) -> None:
        """Abort: drop to ``halt`` (which ends every trajectory on the next step)."""
        with self._lock:
            if self._command_mode is CommandMode.trajectory:
                self._command_mode = CommandMode.halt
            if self._traj_active is task:
                self._traj_active = None
            if task in self._traj_queue:
                self._traj_queue.remove(task)

    def _cancel_trajectory(self, task: TrajectoryTask) -> None:
        """Close: remove one task; closing the active one cancels the queue too."""
        with self._lock:
            if self._traj_active is task:
                self._traj_active = None
                while self._traj_queue:
                    self._traj_queue.popleft().fail(
                        OperationAbortedError("Trajectory cancelled by controller before start")
                    )
            elif task in self._traj_queue:
                self._traj_queue.remove(task)

    # ------------------------------------------------------------------ streaming

    def set_position_command(self, command: RobotJointCommand, *, new_client: bool = False) -> None:
        """Write the position-command wire (used in ``position_command`` mode only).

        ``new_client``: the sample comes from another client than the previous one. Its seqno
        counter is its own, so the ordering check restarts with it (as the reference does when
        another endpoint writes the wire); the Robot Raconteur service sets it.
        """
        with self._lock:
            if new_client:
                self._stream_last_seqno = -1
            if self._command_mode is CommandMode.position_command:
                self._stream_position = command

    def set_velocity_command(self, command: RobotJointCommand) -> None:
        """Write the velocity-command wire (used in ``velocity_command`` mode only)."""
        with self._lock:
            if self._command_mode is CommandMode.velocity_command:
                self._stream_velocity = command

    # ------------------------------------------------------------------ tools and payloads

    def _check_chain(self, chain: int, what: str) -> None:
        if not (isinstance(chain, int) and 0 <= chain < len(self._hp)):
            raise InvalidArgumentError(f"Invalid kinematic chain {chain} for {what}")

    def tool_attached(self, chain: int, tool: ToolInfo | None) -> None:
        """A tool was attached to ``chain``: its TCP now defines the endpoint."""
        if tool is None:
            raise InvalidArgumentError("Tool cannot be null")
        with self._lock:
            self._check_chain(chain, "tool")
            if self._current_tool[chain] is not None:
                raise InvalidArgumentError(f"Tool already attached to kinematic chain {chain}")
            tf = tool_transform(tool)
            _check_frame(f"tool '{tool.name}' tcp", tool.tcp.rotation, tf)
            self._current_tool[chain] = tool
            self._tool_tf[chain] = tf
            self._tool_tf_lists[chain] = as_lists(self._tool_tf[chain])
            self._config_seqno += 1
            self.events.append(("tool_changed", chain, tool.name))

    def tool_detached(self, chain: int, tool_name: str) -> None:
        """The tool named ``tool_name`` (or "" for any) was detached from ``chain``."""
        with self._lock:
            self._check_chain(chain, "tool")
            tool = self._current_tool[chain]
            if tool is None:
                raise InvalidArgumentError(f"Tool not attached to kinematic chain {chain}")
            if self._current_payload[chain] is not None:
                raise InvalidArgumentError("Cannot remove tool while payload attached")
            if tool_name not in ("", tool.name):
                raise InvalidArgumentError(
                    f"Invalid tool name to detach: '{tool_name}' (attached: '{tool.name}')"
                )
            self._current_tool[chain] = None
            self._tool_tf[chain] = None
            self._tool_tf_lists[chain] = None
            self._config_seqno += 1
            self.events.append(("tool_changed", chain, ""))

    def payload_attached(self, chain: int, payload: PayloadInfo | None, pose: Pose | None) -> None:
        """A payload was attached to the tool of ``chain`` at ``pose`` relative to the TCP."""
        if payload is None:
            raise InvalidArgumentError("Payload cannot be null")
        with self._lock:
            self._check_chain(chain, "payload")
            if self._current_tool[chain] is None:
                raise InvalidArgumentError(
                    f"No tool attached to kinematic chain {chain}, cannot attach payload"
                )
            if self._current_payload[chain] is not None:
                raise InvalidArgumentError(f"Payload already attached to kinematic chain {chain}")
            if pose is not None:
                p = pose.position
                tf_p = (quat_wxyz_to_matrix(pose.orientation.as_tuple()), np.array([p.x, p.y, p.z]))
                _check_frame(f"payload '{payload.name}' pose", pose.orientation, tf_p)
            self._current_payload[chain] = payload
            self._current_payload_pose[chain] = pose or Pose()
            self._config_seqno += 1
            self.events.append(("payload_changed", chain, payload.name))

    def payload_detached(self, chain: int, payload_name: str) -> None:
        """The payload named ``payload_name`` (or "") was detached from ``chain``."""
        with self._lock:
            self._check_chain(chain, "payload")
            payload = self._current_payload[chain]
            if payload is None:
                raise InvalidArgumentError(f"Payload not attached to kinematic chain {chain}")
            if payload_name not in ("", payload.name):
                raise InvalidArgumentError(
                    f"Invalid payload name to detach: '{payload_name}' (attached: '{payload.name}')"
                )
            self._current_payload[chain] = None
            self._current_payload_pose[chain] = None
            self._config_seqno += 1
            self.events.append(("payload_changed", chain, ""))

    # ------------------------------------------------------------------ state listeners

    def remove_state_listener(self, listener: Callable[[RobotState], None]) -> None:
        """Stop calling ``listener`` after each step (no error if it was not added)."""
        try:
            self._listeners.remove(listener)
        except ValueError:
            pass

    # ------------------------------------------------------------------ parameters and signals

    def getf_param(self, param_name: str) -> Any:
        """No parameters in the base driver."""
        raise InvalidArgumentError("Invalid parameter")

    def setf_param(self, param_name: str, value: Any) -> None:
        """No parameters in the base driver."""
        raise InvalidArgumentError("Invalid parameter")

    def getf_signal(self, signal_name: str) -> Any:
        """Signals are not implemented by the base driver."""
        raise NotImplementedDriverError("Not implemented")

    def setf_signal(self, signal_name: str, value: Any) -> None:
        """Signals are not implemented by the base driver."""
        raise NotImplementedDriverError("Not implemented")


def _check_frame(what: str, rotation: Quaternion, frame: tuple[F64, F64] | None) -> None:
    """Refuse a tool TCP or payload pose with NaN, infinity, bad rotation or absurd offset.

    Why here as well as in the models: a ``ToolInfo`` built with ``model_construct`` (or by
    another front end) skips validation, and a NaN TCP would be published as a NaN pose.
    """
    q = rotation.as_tuple()
    if frame is None:
        return
    values = [*q, *frame[1].tolist()]
    if not all(math.isfinite(v) for v in values):
        raise InvalidArgumentError(f"{what} must not contain NaN or infinite values")
    if abs(math.hypot(*q) - 1.0) > QUAT_TOL:
        raise InvalidArgumentError(f"{what}: rotation must be a unit quaternion")
    if max(abs(v) for v in frame[1].tolist()) > MAX_OFFSET_M:
        raise InvalidArgumentError(f"{what}: offset beyond {MAX_OFFSET_M:g} m")
