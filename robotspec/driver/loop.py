"""The driver's real-time machinery: its timestep pipeline and its state machine.

:class:`DriverLoop`, the base of :class:`~robotspec.driver.robot_driver.RobotDriver`, follows
``robotraconteur_abstract_robot.AbstractRobot`` 0.2.2 (the seed document is the contract; the
reference note records its behaviour). Each timestep runs, in order: feedback
(``_read_feedback``, the subclass), communication check, robot state check, command fill, the
command guard, state fill, and ``_send_robot_command`` (the subclass). The state machine is the
reference's (§1.2 of the note), rule for rule; its deliberate deviations are listed in
:mod:`robotspec.driver.robot_driver`.

Time comes from a :class:`~robotspec.driver.clock.Clock`. With a simulated clock and no loop
thread, blocking calls (a ``wait=True`` jog, a trajectory ``Next()``) step the loop themselves
until they finish, so tests run deterministically in simulated time with no sleeping.

The client API (the seed's public members) is :class:`~robotspec.driver.robot_driver.RobotDriver`,
a subclass; this module is the machinery it drives.
"""

from __future__ import annotations

import heapq
import math
import struct
import threading
from abc import ABC, abstractmethod
from collections import deque
from collections.abc import Callable

import numpy as np
import numpy.typing as npt

from robotspec.driver.clock import Clock, RealClock
from robotspec.driver.commands import (
    CommandGuard,
    JointLimitArrays,
)
from robotspec.driver.conversions import (
    POSITION_UNITS,
    VELOCITY_UNITS,
    as_lists,
    convert_command,
    seqno_out_of_order,
    tool_transform,
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
    RobotJointCommand,
    TrajectoryGenerator,
    TrajectoryStatus,
    TrajectoryTask,
)
from robotspec.driver.hp_kinematics import HPChain, quat_to_rot, rot_to_quat_tuple
from robotspec.driver.profiles import JogMotion
from robotspec.driver.robot_info import (
    PayloadInfo,
    Pose,
    RobotCapability,
    RobotInfo,
    ToolInfo,
)
from robotspec.driver.state import (
    ESTOP_SOURCE_FLAGS,
    CommandMode,
    ControllerState,
    OperationalMode,
    RobotState,
    StateFlags,
    TcpPose,
    frozen_array,
    robot_state_snapshot,
    tcp_pose_snapshot,
)
from robotspec.errors import DriverError

__all__ = [
    "Completion",
    "DriverLoop",
    "RobotJointCommand",
    "TrajectoryGenerator",
    "TrajectoryStatus",
]

FloatArray = npt.NDArray[np.float64]

#: Position-stream commands more than this many state seqnos old are ignored (reference: 10).
STREAM_STALE_SEQNOS = 10
#: A blocking call in manual stepping mode gives up after this much (simulated) time.
MAX_WAIT_S = 3600.0


class DriverLoop(ABC):
    """The real-time loop of a robot driver: state, timestep pipeline, state machine.

    A subclass fills feedback in :meth:`_read_feedback` and implements
    :meth:`_send_robot_command`, :meth:`_send_enable`, :meth:`_send_disable` and
    :meth:`_send_reset_errors` (and :meth:`_start_homing` if it homes).

    Args:
        robot_info: the validated RobotInfo.
        default_joint_count: unused when ``robot_info`` names the joints (kept for the seed API).
        clock: real (default) or simulated time.
        update_period: the loop period in seconds (reference default 10 ms).
    """

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
        n = self._joint_count
        chains = robot_info.chains
        self._chain_joints = [np.array(c.joint_numbers, dtype=np.intp) for c in chains]
        self._hp: list[HPChain] = []
        for c in chains:
            fp = c.flange_pose or Pose()
            self._hp.append(
                HPChain(
                    np.array([h.as_tuple() for h in c.H]),
                    np.array([p.as_tuple() for p in c.P]),
                    prismatic=[bool(self._limits.prismatic[j]) for j in c.joint_numbers],
                    flange_rotation=quat_to_rot(fp.orientation.as_tuple()),
                    flange_position=np.array(fp.position.as_tuple()),
                )
            )
        self._current_tool: list[ToolInfo | None] = [c.current_tool for c in chains]
        self._current_payload: list[PayloadInfo | None] = [c.current_payload for c in chains]
        self._current_payload_pose: list[Pose | None] = [None for _ in chains]
        self._tool_tf: list[tuple[FloatArray, FloatArray] | None] = [
            tool_transform(t) for t in self._current_tool
        ]
        self._tool_tf_lists = [as_lists(t) for t in self._tool_tf]
        self._chain_idx_list = [list(c.joint_numbers) for c in chains]
        self._chain_is_all = [idx == list(range(n)) for idx in self._chain_idx_list]
        self._endpoint_key: tuple[bytes, bytes, int] | None = None
        self._endpoint_cache: tuple[list[TcpPose], list[FloatArray]] | None = None
        self._keep_going = False
        self._update_period = update_period
        self._speed_ratio = 1.0
        self._jog_joint_limit = math.radians(1000.0)
        self._trajectory_error_tol = math.radians(5.0)
        self._command_mode = CommandMode.halt
        self._operational_mode = OperationalMode.manual_reduced_speed
        self._controller_state = ControllerState.undefined
        self._joint_position: FloatArray = np.zeros(0)
        self._joint_velocity: FloatArray = np.zeros(0)
        self._joint_effort: FloatArray = np.zeros(0)
        self._position_command: FloatArray | None = None
        self._velocity_command: FloatArray | None = None
        self._endpoint_pose: list[TcpPose] | None = None
        self._endpoint_vel: list[FloatArray] | None = None
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
        self._lock = threading.RLock()
        self._clock: Clock = clock if clock is not None else RealClock()
        # --- internals beyond the seed ---
        self._guard = CommandGuard(self._limits, update_period)
        self._fault_message = ""
        self._flags = StateFlags.none
        self._flags_int = -1
        self._prev_mode = CommandMode.halt
        self._jog: JogMotion | None = None
        self._jog_waiter: Completion | None = None
        self._jog_cartesian: tuple[int, FloatArray] | None = None
        self._halt_ramp: JogMotion | None = None
        self._homing: Completion | None = None
        self._traj_active: TrajectoryTask | None = None
        self._traj_queue: deque[TrajectoryTask] = deque()
        self._traj_failed_this_step = False
        self._traj_hold: FloatArray | None = None
        self._jog_hold: FloatArray | None = None
        self._stream_position: RobotJointCommand | None = None
        self._stream_velocity: RobotJointCommand | None = None
        self._stream_last_seqno = -1
        self._stream_valid = StateFlags.none
        self._last_sent: FloatArray | None = None
        # What _last_sent_velocity derives from, lazily (it is read only when a motion starts):
        # the position sent the step before _last_sent, or the velocity command sent.
        self._prev_sent: FloatArray | None = None
        self._sent_velocity: FloatArray | None = None
        self._sent_last_step = False
        self._epoch = self._clock.now()
        self._next_deadline = self._epoch
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

    # ------------------------------------------------------------------ abstract (subclass)

    def _read_feedback(self, now: float) -> None:  # noqa: B027 - optional hook
        """Step 1: fill feedback fields from the robot (override, or update under ``_lock``)."""

    @abstractmethod
    def _send_robot_command(
        self, now: float, joint_pos_cmd: FloatArray | None, joint_vel_cmd: FloatArray | None
    ) -> None:
        """Step 6: send a position or velocity command (both None: no command this step)."""

    @abstractmethod
    def _send_enable(self) -> None:
        """Ask the robot to enable its drives."""

    @abstractmethod
    def _send_disable(self) -> None:
        """Ask the robot to disable its drives."""

    @abstractmethod
    def _send_reset_errors(self) -> None:
        """Ask the robot to clear its errors."""

    def _start_homing(self, completion: Completion) -> None:
        """Start homing; call ``completion.succeed()`` when homed. Override if the robot homes."""
        completion.fail(NotImplementedDriverError("Homing is not implemented by this driver"))

    # ------------------------------------------------------------------ loop and time

    def _perf_counter(self) -> float:
        """The clock's monotonic seconds."""
        return self._clock.now()

    def _stopwatch_ellapsed_s(self) -> float:
        """Seconds since the loop's epoch (the ``now`` every step receives)."""
        return self._clock.now() - self._epoch

    def step(self) -> RobotState:
        """Wait for the next period boundary and run one timestep; return the new state.

        Why public: with a simulated clock, tests and scripts drive the loop step by step.
        Missed deadlines are skipped, not caught up (as the reference does).
        """
        self._clock.sleep_until(self._next_deadline)
        t = self._clock.now()
        self._next_deadline += self._update_period
        if t > self._next_deadline:
            missed = math.floor((t - self._next_deadline) / self._update_period) + 1
            self._next_deadline += missed * self._update_period
        now = t - self._epoch
        self._run_scheduled(now)
        self._run_timestep(now)
        return self._state

    def run_for(self, seconds: float) -> RobotState:
        """Step the loop for ``seconds`` of (clock) time."""
        end = self._stopwatch_ellapsed_s() + seconds
        while self._stopwatch_ellapsed_s() + 1e-12 < end:
            self.step()
        return self._state

    def at(self, t: float, action: Callable[[], None]) -> None:
        """Run ``action`` just before the first timestep at stopwatch time >= ``t``.

        Why: lets a test or scenario inject an event (a halt, a fault) while a blocking call is
        stepping the loop, without threads.
        """
        with self._lock:
            self._scheduled_count += 1
            heapq.heappush(self._scheduled, (t, self._scheduled_count, action))

    def _run_scheduled(self, now: float) -> None:
        while self._scheduled and self._scheduled[0][0] <= now + 1e-12:
            _, _, action = heapq.heappop(self._scheduled)
            action()

    def _start_robot(self) -> None:
        """Start the loop thread (real-time use); blocking calls then wait on it."""
        if self._thread is not None:
            return
        self._keep_going = True
        self._thread = threading.Thread(target=self._loop_thread_func, daemon=True)
        self._thread.start()

    def _loop_thread_func(self) -> None:
        """Loop thread body: step until ``_keep_going`` is cleared."""
        while self._keep_going:
            self.step()

    def _stop_robot(self) -> None:
        """Stop the loop thread and wait for it."""
        self._keep_going = False
        thread, self._thread = self._thread, None
        if thread is not None and thread is not threading.current_thread():
            thread.join()
        with self._lock:
            waiters, self._waiters = self._waiters, []
        for _, event in waiters:
            event.set()  # the waiter sees no loop thread and returns

    def _close(self) -> None:
        """Close the driver: stop the loop."""
        self._stop_robot()

    def _wait_for(self, predicate: Callable[[], bool], timeout: float) -> None:
        """Block until ``predicate()`` or ``timeout`` seconds of clock time.

        With a loop thread the caller waits on it; without one the caller steps the loop itself,
        which is what makes simulated-time tests deterministic.

        Why the loop evaluates the predicate (under ``_lock``, after each step) and wakes the
        caller only once it holds: waking every waiter on every step cost the loop thread a
        futex wake and lock hand-over per step, and the waiter a wake-up per step, for nothing.
        Predicates must be cheap and must not block (they read a flag or two).
        """
        thread = self._thread
        if thread is not None and thread is not threading.current_thread():
            entry = (predicate, threading.Event())
            deadline = self._clock.now() + timeout
            with self._lock:
                if predicate():
                    return
                self._waiters.append(entry)
            try:
                while not entry[1].is_set():
                    remaining = deadline - self._clock.now()
                    if remaining <= 0 or self._thread is None:
                        return
                    entry[1].wait(min(remaining, 0.1))
            finally:
                with self._lock:
                    if entry in self._waiters:
                        self._waiters.remove(entry)
            return
        end = self._stopwatch_ellapsed_s() + timeout
        while not predicate() and self._stopwatch_ellapsed_s() < end:
            self.step()

    def _wait_completion(self, completion: Completion) -> None:
        self._wait_for(lambda: completion.done, MAX_WAIT_S)
        if not completion.done:
            completion.fail(OperationFailedError("Operation timed out"))
        if completion.error is not None:
            raise completion.error

    # ------------------------------------------------------------------ the timestep

    def _run_timestep(self, now: float) -> None:
        """One timestep: feedback, checks, command, states, send. Never raises.

        Why the guard around everything: in the reference an exception here kills the loop
        thread silently and clients read a frozen state forever. Here the driver reports an
        error state and keeps running.
        """
        with self._lock:
            self._state_seqno += 1
        try:
            self._read_feedback(now)
            with self._lock:
                self._stream_valid = StateFlags.none
                self._traj_failed_this_step = False
                res = self._verify_communication(now) and self._verify_robot_state(now)
                ok, pos, vel = self._fill_robot_command(now)
                res = res and ok
                pos, vel = self._guard_command(pos, vel)
                self._fill_states(now)
            if res:
                self._send_robot_command(now, pos, vel)
                self._record_sent(pos, vel)
            else:
                self._record_sent(None, None)
        except Exception as exc:  # noqa: BLE001 - the loop must survive anything
            self._step_failed(now, exc)
        self._publish()

    def _record_sent(self, pos: FloatArray | None, vel: FloatArray | None) -> None:
        if pos is not None:
            consecutive = self._last_sent is not None and self._sent_last_step
            self._prev_sent = self._last_sent if consecutive else None
            self._sent_velocity = None
            self._last_sent = pos
            self._sent_last_step = True
        elif vel is not None:
            self._sent_velocity = vel
            self._prev_sent = None
            self._last_sent = None
            self._sent_last_step = False
        else:
            self._sent_last_step = False
            self._sent_velocity = None
            self._prev_sent = None

    @property
    def _last_sent_velocity(self) -> FloatArray:
        """The velocity of the last command sent (zero when none went out last step).

        The velocity command, or the difference of the last two consecutive position commands
        over the period. Why computed on demand: only a starting jog or halt ramp reads it,
        not every step.
        """
        if self._sent_velocity is not None:
            return self._sent_velocity
        if self._prev_sent is not None and self._last_sent is not None:
            velocity: FloatArray = (self._last_sent - self._prev_sent) / self._update_period
            return velocity
        return np.zeros(self._joint_count)

    def _step_failed(self, now: float, exc: BaseException) -> None:
        with self._lock:
            self._fault_message = f"driver step failed: {type(exc).__name__}: {exc}"
            self._command_mode = CommandMode.invalid_state
            # The step did not get to reset its per-step flags: a stale valid_position_command
            # would otherwise be published beside invalid_state (found by the state machine).
            self._stream_valid = StateFlags.none
            self._traj_failed_this_step = False
            # Nothing (reliably) went out this step: the next command must be rate-limited
            # from the measured position, not from a command sent before the failure, which
            # the arm may be far from by now (found by the state machine: 2.7 x the velocity
            # limit relative to the arm on the first command after recovery).
            self._record_sent(None, None)
            self._end_motion(OperationAbortedError(f"Interrupted: {self._fault_message}"))
            try:
                self._fill_states(now)
            except Exception:  # noqa: BLE001 - fall back to a minimal state
                self._state = RobotState(
                    ts=now,
                    seqno=self._state_seqno,
                    command_mode=self._command_mode,
                    operational_mode=self._operational_mode,
                    controller_state=self._controller_state,
                    flags=StateFlags.error,
                    error_message=self._fault_message,
                )

    def _publish(self) -> None:
        if self._waiters:
            self._wake_waiters()
        for listener in list(self._listeners):
            try:
                listener(self._state)
            except Exception:  # noqa: BLE001 - a bad listener must not stop the loop
                self._listeners.remove(listener)

    def _wake_waiters(self) -> None:
        """Wake the blocked callers whose predicate now holds (see :meth:`_wait_for`)."""
        with self._lock:
            for entry in list(self._waiters):
                try:
                    ready = entry[0]()
                except Exception:  # noqa: BLE001 - let the caller re-check and see the error
                    ready = True
                if ready:
                    self._waiters.remove(entry)
                    entry[1].set()

    def add_state_listener(self, listener: Callable[[RobotState], None]) -> None:
        """Call ``listener(state)`` after every step (loggers, status views)."""
        self._listeners.append(listener)

    # ------------------------------------------------------------------ steps 2 and 3

    def _verify_communication(self, now: float) -> bool:
        """Step 2: communication has failed if any feedback stamp is older than the timeout."""
        timeout = self._communication_timeout
        if (
            now - self._last_robot_state > timeout
            or now - self._last_joint_state > timeout
            or now - self._last_endpoint_state > timeout
        ):
            self._communication_failure = True
            self._command_mode = CommandMode.invalid_state
            if self._base_set_operational_mode:
                self._operational_mode = OperationalMode.undefined
                self._controller_state = ControllerState.undefined
            self._joint_position = np.zeros(0)
            self._joint_velocity = np.zeros(0)
            self._joint_effort = np.zeros(0)
            self._endpoint_pose = None
            self._endpoint_vel = None
            return False
        self._communication_failure = False
        if self._base_set_operational_mode:
            self._operational_mode = OperationalMode.cobot
        return True

    def _verify_robot_state(self, now: float) -> bool:
        """Step 3: the reference's rules, first match wins (note §1.2)."""
        error = self._error or bool(self._fault_message)
        # Deviation: an e-stop ends homing too. The reference keeps homing through an e-stop
        # when the drives still report enabled (they do, flags 0x2000c), so the mode said
        # "homing" on a stopped robot and the pending home() never failed (found by the
        # state machine).
        if (
            self._command_mode is CommandMode.homing
            and self._enabled
            and not error
            and not self._stopped
            and not self._communication_failure
        ):
            if self._base_set_controller_state:
                self._controller_state = ControllerState.motor_off
            return True
        if not self._ready or error or self._communication_failure:
            if self._base_set_controller_state:
                if self._stopped:
                    self._controller_state = ControllerState.emergency_stop
                elif error:
                    self._controller_state = ControllerState.guard_stop
                else:
                    self._controller_state = ControllerState.motor_off
            if error or self._stopped or self._command_mode is not CommandMode.halt:
                self._command_mode = CommandMode.invalid_state
            return False
        if not self._enabled:
            if self._base_set_controller_state:
                self._controller_state = ControllerState.motor_off
            if self._command_mode is not CommandMode.halt:
                self._command_mode = CommandMode.invalid_state
            return False
        if self._command_mode is CommandMode.invalid_state:
            self._command_mode = CommandMode.halt
        if self._base_set_controller_state:
            self._controller_state = ControllerState.motor_on
        return True

    # ------------------------------------------------------------------ step 4

    def _interruption(self) -> OperationAbortedError:
        if self._communication_failure:
            why = "communication with the robot lost"
        elif self._stopped:
            why = "emergency stop"
        elif self._error or self._fault_message:
            why = "robot error"
        elif not self._enabled or not self._ready:
            why = "robot not ready"
        else:
            why = f"command mode changed to {self._command_mode.name}"
        return OperationAbortedError(f"Operation interrupted: {why}")

    def _end_motion(self, error: DriverError) -> None:
        """Fail every pending motion (jog waiter, trajectories) with ``error``."""
        if self._jog_waiter is not None:
            self._jog_waiter.fail(error)
            self._jog_waiter = None
        self._jog = None
        self._jog_cartesian = None
        if self._traj_active is not None:
            self._traj_active.fail(error)
            self._traj_active = None
        while self._traj_queue:
            self._traj_queue.popleft().fail(
                OperationAbortedError("Trajectory cancelled by controller before start")
            )
        if self._homing is not None:
            self._homing.fail(error)
            self._homing = None

    def _fill_robot_command(self, now: float) -> tuple[bool, FloatArray | None, FloatArray | None]:
        """Step 4: the command for this step from the mode and the client's requests."""
        mode = self._command_mode
        prev, self._prev_mode = self._prev_mode, mode
        if mode is not CommandMode.trajectory:
            self._traj_hold = None
        if mode is not CommandMode.jog:
            self._jog_hold = None
        if mode is not CommandMode.trajectory and (
            self._traj_active is not None or self._traj_queue
        ):
            if self._traj_active is not None:
                reason = self._interruption()
                self._traj_active.fail(
                    OperationAbortedError(f"Invalid mode for trajectory execution ({reason})")
                )
                self._traj_active = None
            while self._traj_queue:
                self._traj_queue.popleft().fail(
                    OperationAbortedError("Trajectory cancelled by controller before start")
                )
        if mode is not CommandMode.jog and (self._jog is not None or self._jog_waiter):
            if self._jog_waiter is not None:
                self._jog_waiter.fail(self._interruption())
                self._jog_waiter = None
            self._jog = None
            self._jog_cartesian = None
        if mode is not CommandMode.homing and self._homing is not None:
            self._homing.fail(self._interruption())
            self._homing = None
        if mode is not CommandMode.position_command:
            self._stream_position = None
            self._stream_last_seqno = -1
        if mode is not CommandMode.velocity_command:
            self._stream_velocity = None
        if mode is CommandMode.halt:
            if prev in _MOTION_MODES and self._sent_last_step and self._last_sent is not None:
                self._halt_ramp = self._new_motion(self._last_sent, self._last_sent_velocity)
                self._halt_ramp.at_velocity(np.zeros(self._joint_count), 0.0)
            if self._halt_ramp is not None:
                q = self._halt_ramp.step()
                if self._halt_ramp.done:
                    self._halt_ramp = None
                return True, q, None
            return True, None, None
        self._halt_ramp = None
        if mode is CommandMode.jog:
            return True, self._fill_jog(), None
        if mode is CommandMode.trajectory:
            return True, self._fill_trajectory(now), None
        if mode is CommandMode.position_command:
            return True, self._fill_position_stream(), None
        if mode is CommandMode.velocity_command:
            return True, None, self._fill_velocity_stream()
        if mode is CommandMode.homing:
            return True, None, None
        return False, None, None

    def _start_point(self) -> tuple[FloatArray, FloatArray]:
        """Where a new jog starts: the last command if one went out last step, else measured."""
        if self._sent_last_step and self._last_sent is not None:
            return self._last_sent.copy(), self._last_sent_velocity.copy()
        return self._joint_position.copy(), np.zeros(self._joint_count)

    def _new_motion(self, q: FloatArray, v: FloatArray) -> JogMotion:
        vlim, alim = self._jog_limits()
        return JogMotion(
            q, v, vlim, alim, self._limits.lower, self._limits.upper, self._update_period
        )

    def _fill_jog(self) -> FloatArray | None:
        motion = self._jog
        if motion is None:
            # Hold where the last jog ended, so a lagging arm settles there instead of braking.
            return self._jog_hold
        if self._jog_cartesian is not None:
            self._update_cartesian_jog(motion)
        q = motion.step()  # a new array, never modified afterwards
        self._jog_hold = q
        if motion.done:
            self._jog = None
            self._jog_cartesian = None
            if self._jog_waiter is not None:
                self._jog_waiter.succeed()
                self._jog_waiter = None
        return q

    def _update_cartesian_jog(self, motion: JogMotion) -> None:
        assert self._jog_cartesian is not None
        chain, twist = self._jog_cartesian
        idx = self._chain_joints[chain]
        tf = self._tool_tf[chain]
        _, _, jac = self._hp[chain].fk_jacobian(
            motion.q[idx], None if tf is None else tf[0], None if tf is None else tf[1]
        )
        lam = 0.01
        jjt = jac @ jac.T + lam * lam * np.eye(6)
        qd_chain = jac.T @ np.linalg.solve(jjt, twist)
        vlim = self._jog_limits()[0][idx]
        scale = float(np.max(np.abs(qd_chain) / vlim)) if qd_chain.size else 0.0
        if scale > 1.0:
            qd_chain = qd_chain / scale
        qd = np.zeros(self._joint_count)
        qd[idx] = qd_chain
        if motion.target_velocity is not None:
            motion.target_velocity = qd

    def _fill_trajectory(self, now: float) -> FloatArray | None:
        task = self._traj_active
        if task is None:
            # Hold the end of the last trajectory: an arm that lagged still reaches it.
            return self._traj_hold
        if not task.started:
            if not task.next_called:
                return None
            task.started = True
            task.start_time = now
        t = now - task.start_time
        measured = self._joint_position
        if task.last_setpoint is not None and measured.shape == task.last_setpoint.shape:
            tol = self._trajectory_error_tol
            if any(  # plain floats: a few joints, every step
                abs(m - s) > tol
                for m, s in zip(measured.tolist(), task.last_setpoint.tolist(), strict=True)
            ):
                task.fail(OperationFailedError("Trajectory tolerance failure"))
                self._traj_active = None
                self._traj_failed_this_step = True
                while self._traj_queue:
                    self._traj_queue.popleft().fail(
                        OperationAbortedError("Trajectory cancelled by controller before start")
                    )
                self._command_mode = CommandMode.halt
                self._prev_mode = CommandMode.halt
                return None
        q, wp = task.interp.evaluate(t)  # a new array
        task.time = min(t, task.interp.max_time)
        task.waypoint = wp
        task.last_setpoint = q
        self._traj_hold = q
        if t >= task.interp.max_time:
            task.complete = True
            self._traj_active = self._traj_queue.popleft() if self._traj_queue else None
            if self._traj_active is not None and self._traj_active.next_called:
                self._traj_active.started = True
                self._traj_active.start_time = now + self._update_period
        return q

    def _fill_position_stream(self) -> FloatArray | None:
        cmd = self._stream_position
        if cmd is None:
            return None
        if seqno_out_of_order(cmd.seqno, self._stream_last_seqno):
            return None
        if abs(cmd.state_seqno - self._state_seqno) > STREAM_STALE_SEQNOS:
            return None
        q = convert_command(cmd, self._joint_count, POSITION_UNITS)
        if q is None:
            return None
        self._stream_last_seqno = cmd.seqno
        self._stream_valid = StateFlags.valid_position_command
        return q

    def _fill_velocity_stream(self) -> FloatArray | None:
        cmd = self._stream_velocity
        if cmd is None:
            return None
        if abs(cmd.state_seqno - self._state_seqno) > STREAM_STALE_SEQNOS:
            return None
        v = convert_command(cmd, self._joint_count, VELOCITY_UNITS)
        if v is None:
            return None
        self._stream_valid = StateFlags.valid_velocity_command
        return v * self._speed_ratio

    def _guard_command(
        self, pos: FloatArray | None, vel: FloatArray | None
    ) -> tuple[FloatArray | None, FloatArray | None]:
        """Every outgoing command passes the guard (limits, rate, finiteness)."""
        if pos is not None:
            ref = (
                self._last_sent if (self._sent_last_step and self._last_sent is not None) else None
            )
            if ref is None:
                if self._joint_position.shape[0] != self._joint_count:
                    return None, None
                ref = self._joint_position
            out = self._guard.position(pos, ref)
            if out is None:
                self._fault_message = "non-finite joint position command refused"
            return out, None
        if vel is not None:
            if self._joint_position.shape[0] != self._joint_count:
                return None, None
            outv = self._guard.velocity(vel, self._joint_position)
            if outv is None:
                self._fault_message = "non-finite joint velocity command refused"
            return None, outv
        return None, None

    # ------------------------------------------------------------------ step 5

    def _fill_state_flags(self, now: float) -> None:
        """The ``robot_state_flags`` word; communication failure is reported alone."""
        if self._communication_failure:
            self._flags = StateFlags.communication_failure
            self._flags_int = int(StateFlags.communication_failure)
            return
        f = 0
        if self._error or self._fault_message:
            f |= _F_ERROR
        if self._stopped:
            f |= _F_ESTOP | int(ESTOP_SOURCE_FLAGS.get(self._estop_source, 0))
        if self._enabled:
            f |= _F_ENABLED
        if self._ready:
            f |= _F_READY
        if self._uses_homing:
            f |= _F_HOMED if self._homed else _F_HOMING_REQUIRED
        f |= int(self._stream_valid)
        if self._traj_active is not None and not self._traj_failed_this_step:
            f |= _F_TRAJ
        if f != self._flags_int:
            self._flags_int = f
            self._flags = StateFlags(f)

    def _calc_endpoint_poses(self) -> list[TcpPose]:
        """TCP pose of every chain (tool applied), base frame; also the TCP velocities.

        Cached on (q, qd, tools): an idle robot costs nothing here.
        """
        q = self._joint_position
        qd = self._joint_velocity
        key = (q.tobytes(), qd.tobytes(), self._config_seqno)
        if key == self._endpoint_key and self._endpoint_cache is not None:
            poses, vels = self._endpoint_cache
            self._endpoint_vel = vels
            return poses
        poses = []
        vels = []
        q_list = q.tolist()
        qd_list = qd.tolist() if qd.shape[0] == self._joint_count else None
        for c, hp in enumerate(self._hp):
            tf = self._tool_tf_lists[c]
            if self._chain_is_all[c]:  # one chain of every joint, in order: no gather
                q_c, qd_c = q_list, qd_list
            else:
                idx = self._chain_idx_list[c]
                q_c = [q_list[i] for i in idx]
                qd_c = None if qd_list is None else [qd_list[i] for i in idx]
            rot, pos, twist = hp.tcp_state(
                q_c, qd_c, None if tf is None else tf[0], None if tf is None else tf[1]
            )
            # One read-only array per chain, sliced into position, orientation and twist
            # (views of a read-only buffer stay read-only): one allocation instead of three.
            tcp = np.frombuffer(_PACK_TCP(*pos, *rot_to_quat_tuple(rot), *twist))  # read-only
            poses.append(tcp_pose_snapshot(tcp[0:3], tcp[3:7]))
            vels.append(tcp[7:13])
        self._endpoint_key = key
        self._endpoint_cache = (poses, vels)
        self._endpoint_vel = vels
        return poses

    def _calc_endpoint_pose(self, chain: int) -> TcpPose:
        """TCP pose of ``chain`` (tool applied)."""
        poses = self._endpoint_pose or self._calc_endpoint_poses()
        return poses[chain]

    def _calc_endpoint_vels(self) -> list[FloatArray]:
        """TCP spatial velocity ``[angular, linear]`` of every chain."""
        if self._endpoint_vel is None:
            self._calc_endpoint_poses()
        return list(self._endpoint_vel or [])

    def _calc_endpoint_vel(self, chain: int) -> FloatArray:
        """TCP spatial velocity of ``chain``."""
        return self._calc_endpoint_vels()[chain]

    def _fill_states(self, now: float) -> None:
        """Step 5: flags, endpoint poses and velocities, and the published snapshot."""
        self._fill_state_flags(now)
        comm_ok = not self._communication_failure
        have_q = self._joint_position.shape[0] == self._joint_count
        if comm_ok and have_q:
            self._endpoint_pose = self._calc_endpoint_poses()
        else:
            self._endpoint_pose = None
            self._endpoint_vel = None
        task = self._traj_active
        self._state = robot_state_snapshot(
            ts=now,
            seqno=self._state_seqno,
            command_mode=self._command_mode,
            operational_mode=self._operational_mode,
            controller_state=self._controller_state,
            flags=self._flags,
            joint_position=frozen_array(self._joint_position),
            joint_velocity=frozen_array(self._joint_velocity),
            joint_effort=frozen_array(self._joint_effort),
            position_command=frozen_array(self._position_command),
            velocity_command=frozen_array(self._velocity_command),
            kin_chain_tcp=tuple(self._endpoint_pose or ()),
            kin_chain_tcp_vel=tuple(self._endpoint_vel or ()),
            trajectory_running=bool(self._flags_int & _F_TRAJ),
            trajectory_time=0.0 if task is None else task.time,
            trajectory_max_time=0.0 if task is None else task.interp.max_time,
            trajectory_current_waypoint=0 if task is None else task.waypoint,
            config_seqno=self._config_seqno,
            speed_ratio=self._speed_ratio,
            error_message=self._fault_message,
        )

    def _jog_limits(self) -> tuple[FloatArray, FloatArray]:
        op = self._operational_mode
        if op is OperationalMode.manual_reduced_speed:
            return self._limits.reduced_velocity, self._limits.reduced_acceleration
        if op in (OperationalMode.manual_full_speed, OperationalMode.cobot):
            return self._limits.velocity, self._limits.acceleration
        raise InvalidOperationError("Invalid operation mode for jog")


#: Position, orientation and twist of one TCP as packed bytes (a read-only array's buffer).
_PACK_TCP = struct.Struct("13d").pack

_F_ERROR = int(StateFlags.error)
_F_ESTOP = int(StateFlags.estop)
_F_ENABLED = int(StateFlags.enabled)
_F_READY = int(StateFlags.ready)
_F_HOMED = int(StateFlags.homed)
_F_HOMING_REQUIRED = int(StateFlags.homing_required)
_F_TRAJ = int(StateFlags.trajectory_running)

_MOTION_MODES = frozenset(
    {
        CommandMode.jog,
        CommandMode.trajectory,
        CommandMode.position_command,
        CommandMode.velocity_command,
    }
)
