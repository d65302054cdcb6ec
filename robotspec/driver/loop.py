"""The driver's real-time machinery: its loop, timing, and timestep pipeline.

:class:`DriverLoop`, the base of :class:`~robotspec.driver.robot_driver.RobotDriver`, follows
``robotraconteur_abstract_robot.AbstractRobot`` 0.2.2 (the seed document is the contract; the
upstream source is ``abstract_robot.py`` of robotraconteur-abstract-robot). Each timestep runs, in
order: feedback (``_read_feedback``, the subclass), communication check, robot state check, command
fill, the command guard, state fill, and ``_send_robot_command`` (the subclass). The state machine
is the reference's (``AbstractRobot._verify_robot_state`` and its ``command_mode`` setter), rule for
rule; its deliberate deviations are listed in ``docs/driver.md``.

Time comes from a :class:`~robotspec.driver.clock.Clock`. With a simulated clock and no loop
thread, blocking calls (a ``wait=True`` jog, a trajectory ``Next()``) step the loop themselves
until they finish, so tests run deterministically in simulated time with no sleeping.

The client API (the seed's public members) is :class:`~robotspec.driver.robot_driver.RobotDriver`,
a subclass; this module is the machinery it drives. The loop's jobs are mixins over its state
(:class:`~robotspec.driver.loop_state.LoopState`): the state machine (steps 2 and 3,
:mod:`~robotspec.driver.modes`), the command fill (step 4, :mod:`~robotspec.driver.fill`) and the
state fill (step 5, :mod:`~robotspec.driver.state_fill`); this module keeps the loop, its timing,
the order of the steps and the waiting of blocking calls.
"""

from __future__ import annotations

import heapq
import threading
from abc import ABC, abstractmethod
from collections.abc import Callable

from robotspec.arrays import F64
from robotspec.driver.clock import step_duration
from robotspec.driver.commands import (
    RobotJointCommand,
)
from robotspec.driver.errors import (
    NotImplementedDriverError,
    OperationAbortedError,
    OperationFailedError,
)
from robotspec.driver.fill import (
    JOG_ARRIVAL_SPEED,
    JOG_ARRIVAL_TOLERANCE,
    JOG_SETTLE_TIMEOUT_S,
    STREAM_STALE_SEQNOS,
    CommandFill,
)
from robotspec.driver.handles import (
    Completion,
    TrajectoryGenerator,
    TrajectoryStatus,
)
from robotspec.driver.loop_timing import LoopStats
from robotspec.driver.state import (
    CommandMode,
    RobotState,
    StateFlags,
)

__all__ = [
    "JOG_ARRIVAL_SPEED",
    "JOG_ARRIVAL_TOLERANCE",
    "JOG_SETTLE_TIMEOUT_S",
    "STREAM_STALE_SEQNOS",
    "Completion",
    "DriverLoop",
    "LoopStats",
    "RobotJointCommand",
    "TrajectoryGenerator",
    "TrajectoryStatus",
]


#: A blocking call in manual stepping mode gives up after this much (simulated) time.
MAX_WAIT_S = 3600.0


class DriverLoop(CommandFill, ABC):
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

    # Every field is set up by LoopState.__init__ (same arguments).

    def _read_feedback(self, now: float) -> None:
        """Step 1: fill feedback fields from the robot (override, or update under ``_lock``)."""

    @abstractmethod
    def _send_robot_command(
        self, now: float, joint_pos_cmd: F64 | None, joint_vel_cmd: F64 | None
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
        timing = self._timing
        self._clock.sleep_until(timing.next_deadline)
        t = self._clock.now()
        timing.woke(t)
        now = t - self._epoch
        self._run_scheduled(now)
        self._run_timestep(now)
        return self._state

    def loop_stats(self) -> LoopStats:
        """Steps run, periods missed and the latest wake-up, by the loop's own clock.

        Why: whether something (a client's upload, the machine's load) made the loop miss its
        deadlines is counted where the deadlines are kept; benchmarks and tests read it here.
        """
        return self._timing.stats()

    def reset_loop_stats_worst(self) -> None:
        """Start a new window for :attr:`LoopStats.worst_late_s` (counts keep running)."""
        self._timing.reset_worst()

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

    def _run_timestep(self, now: float) -> None:
        """One timestep: feedback, checks, command, states, send. Never raises.

        Why the guard around everything: in the reference an exception here kills the loop
        thread silently and clients read a frozen state forever. Here the driver reports an
        error state and keeps running.
        """
        with self._lock:
            self._state_seqno += 1
            self._step_dt = step_duration(now, self._last_step_now, self._update_period)
            self._last_step_now = now
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
