"""Step 4 of the timestep: the command of this step, from the mode and the client's requests.

Jogs (freespace, joint, Cartesian, with the wait for the arm's arrival), trajectories, the
position and velocity streams, the halt ramp, and the guard every command passes. Motion planning
itself is in :mod:`~robotspec.driver.profiles` and :mod:`~robotspec.driver.cartesian`.
"""

from __future__ import annotations

import math

import numpy as np

from robotspec.arrays import F64
from robotspec.driver.cartesian_jog import CartesianJog
from robotspec.driver.conversions import (
    POSITION_UNITS,
    VELOCITY_UNITS,
    convert_command,
    seqno_out_of_order,
)
from robotspec.driver.errors import (
    OperationAbortedError,
    OperationFailedError,
)
from robotspec.driver.profiles import JogMotion, StreamLimiter
from robotspec.driver.state import (
    CommandMode,
    StateFlags,
)

__all__ = [
    "JOG_ARRIVAL_SPEED",
    "JOG_ARRIVAL_TOLERANCE",
    "JOG_SETTLE_TIMEOUT_S",
    "STREAM_STALE_SEQNOS",
    "CommandFill",
]


#: Position-stream commands more than this many state seqnos old are ignored (reference: 10).
STREAM_STALE_SEQNOS = 10
#: A waiting jog returns once the measured position is within this of where the jog ended, on
#: every joint (rad or m) ...
JOG_ARRIVAL_TOLERANCE = 1e-4
#: ... and every joint's measured speed is below this (rad/s or m/s).
JOG_ARRIVAL_SPEED = 1e-3
#: A waiting jog whose arm has not arrived this long after its profile ended fails.
JOG_SETTLE_TIMEOUT_S = 1.0
#: A velocity-stream command must let the joint stop at its limit even if it stays applied for
#: this many periods (the next command may come late; steps up to twice this keep the guarantee).
VELOCITY_HORIZON_PERIODS = 2.0


class CommandFill(CartesianJog):
    """Step 4: the command for this step.

    A driver of a real arm sets the arrival rule of waiting jogs to its robot (encoder
    resolution, steady-state error) by overriding these class attributes.
    """

    #: A waiting jog has arrived when every joint is within this of where it ended (rad or m) ...
    jog_arrival_tolerance: float = JOG_ARRIVAL_TOLERANCE
    #: ... and every joint's measured speed is below this (rad/s or m/s).
    jog_arrival_speed: float = JOG_ARRIVAL_SPEED
    #: A waiting jog fails when the arm has not arrived this long after the motion finished (s).
    jog_settle_timeout: float = JOG_SETTLE_TIMEOUT_S

    def _fill_robot_command(self, now: float) -> tuple[bool, F64 | None, F64 | None]:
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
        if mode is not CommandMode.position_command and mode is not CommandMode.velocity_command:
            self._stream_limiter = None
        if mode is CommandMode.halt:
            if prev in _MOTION_MODES and self._sent_last_step and self._last_sent is not None:
                self._halt_ramp = self._new_motion(self._last_sent, self._last_sent_velocity)
                self._halt_ramp.at_velocity(np.zeros(self._joint_count), 0.0)
            if self._halt_ramp is not None:
                q = self._halt_ramp.step(self._step_dt)
                if self._halt_ramp.done:
                    self._halt_ramp = None
                return True, q, None
            return True, None, None
        self._halt_ramp = None
        if mode is CommandMode.jog:
            return True, self._fill_jog(now), None
        if mode is CommandMode.trajectory:
            return True, self._fill_trajectory(now), None
        if mode is CommandMode.position_command:
            return True, self._fill_position_stream(now), None
        if mode is CommandMode.velocity_command:
            return True, None, self._fill_velocity_stream()
        if mode is CommandMode.homing:
            return True, None, None
        return False, None, None

    def _start_point(self) -> tuple[F64, F64]:
        """Where a new motion starts: the last command if one went out last step, else measured.

        The velocity is the last command's, or else the measured one (an arm braking by itself
        after its commands stopped is still moving).
        """
        if self._sent_last_step and self._last_sent is not None:
            return self._last_sent.copy(), self._last_sent_velocity.copy()
        n = self._joint_count
        if self._sent_velocity is not None:
            return self._joint_position.copy(), self._sent_velocity.copy()
        if self._joint_velocity.shape[0] == n:
            return self._joint_position.copy(), self._joint_velocity.copy()
        return self._joint_position.copy(), np.zeros(n)

    def _new_motion(self, q: F64, v: F64) -> JogMotion:
        vlim, alim = self._jog_limits()
        return JogMotion(
            q, v, vlim, alim, self._limits.lower, self._limits.upper, self._update_period
        )

    def _fill_jog(self, now: float) -> F64 | None:
        motion = self._jog
        if motion is None:
            # Hold where the last jog ended, so a lagging arm settles there instead of braking.
            if self._jog_waiter is not None:
                self._check_jog_arrival(now)
            return self._jog_hold
        if self._jog_cartesian is not None and motion.t < motion.velocity_until:
            self._update_cartesian_jog(motion)
        q = motion.step(self._step_dt)  # a new array, never modified afterwards
        self._jog_hold = q
        if self._jog_cartesian is not None and motion.limit_braking:
            self._stop_cartesian_jog(motion, self._limit_reason(q))
        if motion.done:
            self._jog = None
            self._jog_cartesian = None
            if self._jog_waiter is not None:
                self._jog_settle_deadline = now + self.jog_settle_timeout
        return q

    def _check_jog_arrival(self, now: float) -> None:
        """A waited-for jog whose profile ended: succeed once the arm is there, or time out.

        Why wait for the arm and not for the profile: the command leads the arm by a period (more
        under jitter), so a caller told "done" when the profile ended found the arm short of the
        target and still moving.
        """
        waiter, hold = self._jog_waiter, self._jog_hold
        if waiter is None or hold is None:
            return
        q, v = self._joint_position.tolist(), self._joint_velocity.tolist()
        n = self._joint_count
        if len(q) == n and len(v) == n:
            err = [abs(a - b) for a, b in zip(q, hold.tolist(), strict=True)]
            tol, speed = self.jog_arrival_tolerance, self.jog_arrival_speed
            if max(err) <= tol and max(map(abs, v)) <= speed:
                waiter.succeed()
                self._jog_waiter = None
                self._jog_settle_deadline = None
                return
        deadline = self._jog_settle_deadline
        if deadline is not None and now > deadline:
            worst = max(range(n), key=lambda i: abs(q[i] - float(hold[i]))) if len(q) == n else 0
            off = abs(q[worst] - float(hold[worst])) if len(q) == n else math.nan
            waiter.fail(
                OperationFailedError(
                    f"Jog did not arrive: joint '{self._joint_names[worst]}' is {off:.3g} from "
                    f"where the jog ended {self.jog_settle_timeout:g} s after the motion "
                    f"finished (tolerance {self.jog_arrival_tolerance:g})"
                )
            )
            self._jog_waiter = None
            self._jog_settle_deadline = None

    def _fill_trajectory(self, now: float) -> F64 | None:
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
        if task.last_setpoint is not None:
            # A step longer than MAX_STEP_PERIODS (the loop stalled: a loaded machine, a pause)
            # moves the trajectory on by the time the step covers, as the jog and halt profiles
            # and the arm's own integration do (clock.step_duration), not by the wall time: the
            # rest is a pause. Without this the setpoint jumped ahead by the stall, the arm
            # could not follow, and a trajectory failed with "Trajectory tolerance failure"
            # after a 0.1 s stall at 250 Hz (issue 31).
            behind = (t - task.time) - self._step_dt
            if behind > 1e-9:
                task.start_time += behind
                t -= behind
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

    def _stream_limiter_now(self) -> StreamLimiter:
        """The stream's limiter, restarted from the current motion when the stream was idle."""
        lim = self._stream_limiter
        if lim is None or not (self._sent_last_step or self._sent_velocity is not None):
            q0, v0 = self._start_point()
            alim = self._limits.acceleration
            lim = StreamLimiter(
                q0, v0, self._limits.velocity, alim, self._limits.lower, self._limits.upper
            )
            self._stream_limiter = lim
            self._stream_target = None
        return lim

    def _fill_position_stream(self, now: float) -> F64 | None:
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
        limiter = self._stream_limiter_now()
        sample = q.tolist()
        # The stream's own velocity, from its last two samples: a steadily moving stream is
        # followed without lag, also between the samples of a client slower than the loop (the
        # target moves on at that velocity for at most one sample interval: a first-order hold);
        # a stream that holds still is braked onto.
        if cmd is not self._stream_used:
            prev = self._stream_target
            velocity = None
            span = 0.0
            if prev is not None and now > prev[0]:
                span = now - prev[0]
                velocity = [(a - b) / span for a, b in zip(sample, prev[1], strict=True)]
            self._stream_target = (now, sample, velocity, span)
            self._stream_used = cmd
        assert self._stream_target is not None
        t_sample, _, velocity, span = self._stream_target
        target, target_velocity = sample, None
        age = now - t_sample
        if velocity is not None and age < span:
            target = [x + v * age for x, v in zip(sample, velocity, strict=True)]
            target_velocity = velocity
        return limiter.position(target, target_velocity, self._step_dt)

    def _fill_velocity_stream(self) -> F64 | None:
        cmd = self._stream_velocity
        if cmd is None:
            return None
        if abs(cmd.state_seqno - self._state_seqno) > STREAM_STALE_SEQNOS:
            return None
        v = convert_command(cmd, self._joint_count, VELOCITY_UNITS)
        if v is None or self._joint_position.shape[0] != self._joint_count:
            return None
        self._stream_valid = StateFlags.valid_velocity_command
        limiter = self._stream_limiter_now()
        # A fixed horizon: the braking guarantee holds for steps up to twice as long (see
        # profiles.StreamLimiter.velocity); the arm's own soft limits cover longer stalls.
        horizon = VELOCITY_HORIZON_PERIODS * self._update_period
        return limiter.velocity(
            (v * self._speed_ratio).tolist(),
            self._joint_position.tolist(),
            self._step_dt,
            horizon,
        )

    def _guard_command(self, pos: F64 | None, vel: F64 | None) -> tuple[F64 | None, F64 | None]:
        """Every outgoing command passes the guard (limits, rate, finiteness)."""
        if pos is not None:
            ref = (
                self._last_sent if (self._sent_last_step and self._last_sent is not None) else None
            )
            if ref is None:
                if self._joint_position.shape[0] != self._joint_count:
                    return None, None
                ref = self._joint_position
            out = self._guard.position(pos, ref, self._step_dt)
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

    def _record_sent(self, pos: F64 | None, vel: F64 | None) -> None:
        if pos is not None:
            consecutive = self._last_sent is not None and self._sent_last_step
            self._prev_sent = self._last_sent if consecutive else None
            self._sent_dt = self._step_dt
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
    def _last_sent_velocity(self) -> F64:
        """The velocity of the last command sent (zero when none went out last step).

        The velocity command, or the difference of the last two consecutive position commands
        over the step between them. Why computed on demand: only a starting jog or halt ramp
        reads it, not every step.
        """
        if self._sent_velocity is not None:
            return self._sent_velocity
        if self._prev_sent is not None and self._last_sent is not None and self._sent_dt > 0.0:
            velocity: F64 = (self._last_sent - self._prev_sent) / self._sent_dt
            return velocity
        return np.zeros(self._joint_count)


_MOTION_MODES = frozenset(
    {
        CommandMode.jog,
        CommandMode.trajectory,
        CommandMode.position_command,
        CommandMode.velocity_command,
    }
)
