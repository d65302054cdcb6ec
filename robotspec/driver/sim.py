"""The simulated robot: joints that track commands within the limits, and injectable faults.

Why a physical model rather than perfect tracking: client code must see what a real arm does --
one period of lag, velocity and acceleration saturation, hard stops at the joint limits, an
instant stop on e-stop -- and must be testable against faults (lost feedback, e-stop, drive
error, disabled drives) without a robot.

The command sent in one step is applied over the following period, and feedback read at the next
step reports the result (``_read_feedback`` integrates, then reports). Like a servo drive that
interpolates its setpoints, the arm treats the position commands as a path in time, one period
late: at time ``t`` it heads for the commanded path at ``t - period`` (interpolated between the
last two commands, extrapolated along them when a step comes late). On time, that is exactly the
last command; under jitter, the arm keeps the commanded velocity instead of lurching, which is
what a real arm does and what lets a jittery loop still end where it was asked.

Like a real controller's soft limits, the arm never approaches a joint limit faster than it can
stop there at its acceleration limit (:func:`~robotspec.driver.profiles.braking_speed`), whatever
it is commanded; the hard stop at the limit is the last resort.

Like a real controller's command interface, the simulated arm has a command watchdog: when no
command arrives from the driver for ``command_timeout`` seconds (the driver stopped sending, e.g.
because feedback was lost), it drops the last command and brakes to a stop at its acceleration
limits, instead of following a stale velocity command into a joint limit.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from robotspec.arrays import F64
from robotspec.driver.clock import Clock, step_duration
from robotspec.driver.errors import InvalidArgumentError
from robotspec.driver.faults import Fault, fault_param, fault_param_value
from robotspec.driver.handles import Completion
from robotspec.driver.profiles import braking_speed
from robotspec.driver.robot_driver import RobotDriver
from robotspec.driver.robot_info import RobotInfo
from robotspec.driver.state import EstopSource

__all__ = ["Fault", "SimRobot"]


class SimRobot(RobotDriver):
    """A :class:`RobotDriver` whose robot is simulated in-process.

    Args:
        robot_info: the robot.
        clock: time source (use :class:`~robotspec.driver.clock.SimClock` in tests).
        update_period: loop period in seconds.
        initial_position: starting joint positions (default: ``home`` clipped to the limits).
        homing_speed: fraction of the velocity limit used while homing.
        command_timeout: the command watchdog, in seconds: with no command from the driver for
            this long, the arm brakes to a stop at its acceleration limits (default 0.1 s).
    """

    #: Default command watchdog timeout in seconds (10 periods at the default 100 Hz).
    DEFAULT_COMMAND_TIMEOUT = 0.1

    def __init__(
        self,
        robot_info: RobotInfo,
        *,
        clock: Clock | None = None,
        update_period: float = 0.01,
        initial_position: Any = None,
        homing_speed: float = 0.25,
        command_timeout: float = DEFAULT_COMMAND_TIMEOUT,
    ) -> None:
        if not (math.isfinite(command_timeout) and command_timeout > 0):
            raise InvalidArgumentError("command timeout must be a positive number of seconds")
        super().__init__(robot_info, clock=clock, update_period=update_period)
        lim = self._limits
        n = self._joint_count
        q0 = lim.home if initial_position is None else np.asarray(initial_position, dtype=float)
        self._q = np.clip(np.array(q0, dtype=np.float64).reshape(n), lim.lower, lim.upper)
        self._v = np.zeros(n)
        self._vmax_l: list[float] = lim.velocity.tolist()
        self._acc_l: list[float] = lim.acceleration.tolist()
        self._lower_l: list[float] = lim.lower.tolist()
        self._upper_l: list[float] = lim.upper.tolist()
        self._pending_pos: F64 | None = None
        self._pending_t = 0.0
        #: The position command before ``_pending_pos`` and when it was sent (consecutive only).
        self._prior_pos: list[float] | None = None
        self._prior_t = 0.0
        self._settle_on: list[float] | None = None
        self._pending_vel: F64 | None = None
        self._sim_enabled = True
        self._sim_error = False
        self._sim_estop = EstopSource.none
        self._feedback_lost = False
        self._frozen = False
        self._raise_in_step = False
        self._sim_homed = False
        self._homing_target: F64 | None = None
        self._homing_completion: Completion | None = None
        self._homing_speed = homing_speed
        self._sim_last_t: float | None = None
        self._command_timeout = command_timeout
        self._last_command_t: float | None = None
        #: How many times the command watchdog has stopped the arm (tests and logs read it).
        self.watchdog_trips = 0
        #: Every command actually sent, as (now, position or None, velocity or None); only kept
        #: when ``record_commands`` is True (tests check invariants on it).
        self.record_commands = False
        self.sent: list[tuple[float, F64 | None, F64 | None]] = []

    # ------------------------------------------------------------------ the simulated arm

    @property
    def sim_position(self) -> F64:
        """The simulated arm's true joint positions (a copy)."""
        return self._q.copy()

    @property
    def sim_velocity(self) -> F64:
        """The simulated arm's true joint velocities (a copy)."""
        return self._v.copy()

    @property
    def command_timeout(self) -> float:
        """The command watchdog timeout in seconds."""
        return self._command_timeout

    def _integrate(self, now: float) -> None:
        last = self._sim_last_t
        self._sim_last_t = now
        if last is None:
            return
        dt = step_duration(now, last, self._update_period)
        if dt <= 0.0:
            return
        stopped = self._sim_estop != EstopSource.none or self._sim_error or not self._sim_enabled
        if stopped or self._frozen:
            self._v[:] = 0.0
            self._pending_pos = self._pending_vel = None
            return
        if (
            self._last_command_t is not None
            and now - self._last_command_t > self._command_timeout
            and (self._pending_pos is not None or self._pending_vel is not None)
        ):
            # Command watchdog: the driver went silent. Drop the stale command; with none,
            # the arm brakes to rest at its acceleration limits (below).
            self._pending_pos = self._pending_vel = None
            self.watchdog_trips += 1
        if self._homing_target is not None and (
            self._homing_completion is None or self._homing_completion.done
        ):
            # The driver ended homing (halt, error, e-stop): the controller stops homing too,
            # instead of carrying on toward home on its own.
            self._homing_target = None
            self._homing_completion = None
        q_l = self._q.tolist()
        v_l = self._servo(q_l, self._desired_velocity(q_l, now, dt), dt)
        self._q[:] = q_l
        self._v[:] = v_l
        if self._homing_target is not None and self._homed_now(q_l, v_l, dt):
            self._q[:] = self._homing_target
            self._v[:] = 0.0
            self._homing_target = None
            self._sim_homed = True
            self._homing_finished(True)

    def _desired_velocity(self, q_l: list[float], now: float, dt: float) -> list[float]:
        """The velocity the controller asks for: homing, the position or velocity command, or 0."""
        n = len(q_l)
        if self._homing_target is not None:
            return self._homing_velocity(q_l, dt)
        if self._pending_vel is not None and self._pending_pos is None:
            return list(self._pending_vel.tolist())
        if self._pending_pos is None:
            return [0.0] * n
        pending = self._pending_pos.tolist()
        aim = self._aim(pending, now)
        v_des_l = [(aim[i] - q_l[i]) / dt for i in range(n)]
        if pending == self._settle_on:
            # A command held still: brake so as to land on it (the braking curve). Without
            # this, short steps make the servo ring around the target.
            for i in range(n):
                err = pending[i] - q_l[i]
                v_cap = braking_speed(abs(err), self._acc_l[i], dt)
                x = v_des_l[i]
                x = -v_cap if x < -v_cap else x
                v_des_l[i] = v_cap if x > v_cap else x
        self._settle_on = pending
        return v_des_l

    def _servo(self, q_l: list[float], v_des_l: list[float], dt: float) -> list[float]:
        """One step of the servos toward ``v_des_l``: speed, acceleration and limit braking.

        Per joint in plain floats (several times faster than numpy calls on a few joints); the
        clamps propagate NaN as np.minimum / np.maximum do. ``q_l`` becomes the new positions;
        returns the new velocities.
        """
        v_l = self._v.tolist()
        vmax_l, acc_l, lower_l, upper_l = self._vmax_l, self._acc_l, self._lower_l, self._upper_l
        for i in range(len(q_l)):
            vm = vmax_l[i]
            x = v_des_l[i]
            x = -vm if x < -vm else x
            x = vm if x > vm else x
            amax_dt = acc_l[i] * dt
            dv = x - v_l[i]
            dv = -amax_dt if dv < -amax_dt else dv
            dv = amax_dt if dv > amax_dt else dv
            v = v_l[i] + dv
            # Soft limits: never faster toward a limit than the arm can stop at it.
            acc = acc_l[i]
            brake = braking_speed(upper_l[i] - q_l[i], acc, dt)
            v = brake if v > brake else v
            brake = -braking_speed(q_l[i] - lower_l[i], acc, dt)
            v = brake if v < brake else v
            q = q_l[i] + v * dt
            if q < lower_l[i]:
                q, v = lower_l[i], 0.0
            elif q > upper_l[i]:
                q, v = upper_l[i], 0.0
            q_l[i] = q
            v_l[i] = v
        return v_l

    def _homing_velocity(self, q_l: list[float], dt: float) -> list[float]:
        """The velocity the homing controller asks for: toward home, braking to stop on it.

        At most the homing speed, and never faster than the joint can still stop on home at its
        acceleration limit (:func:`~robotspec.driver.profiles.braking_speed`). Why the braking:
        homing used to run at the homing speed until it reached home and then stop dead, a
        velocity change of the whole homing speed in one step (3.7 x the acceleration limit on
        the RRP arm, 1.3-1.4 x on a Sawyer: issue 31); the velocity limit alone does not bound
        the deceleration at the end.
        """
        assert self._homing_target is not None
        target = self._homing_target.tolist()
        out = []
        for i, q in enumerate(q_l):
            err = target[i] - q
            cap = self._vmax_l[i] * self._homing_speed
            brake = braking_speed(abs(err), self._acc_l[i], dt)
            cap = brake if brake < cap else cap
            x = err / dt if dt > 0.0 else 0.0
            out.append(-cap if x < -cap else (cap if x > cap else x))
        return out

    def _homed_now(self, q_l: list[float], v_l: list[float], dt: float) -> bool:
        """Whether homing has arrived: every joint on home (to 1e-9) and slow enough to stop.

        "Slow enough": stopping it this step (the velocity set to zero) is a velocity change
        within the acceleration limit, so arriving never brakes harder than the limit.
        """
        assert self._homing_target is not None
        target = self._homing_target.tolist()
        return all(
            abs(q - target[i]) <= 1e-9 and abs(v_l[i]) <= self._acc_l[i] * dt
            for i, q in enumerate(q_l)
        )

    def _aim(self, pending: list[float], now: float) -> list[float]:
        """Where the commanded path was one period ago: the point the arm heads for now.

        On time that is the last command. Early, it lies between the last two commands; late,
        beyond the last one along their velocity (within the joint limits).
        """
        prior = self._prior_pos
        span = self._pending_t - self._prior_t
        if prior is None or not span > 0.0:
            return pending
        tau = now - self._update_period
        frac = (tau - self._prior_t) / span
        if abs(frac - 1.0) < 1e-9:
            return pending
        frac = 0.0 if frac < 0.0 else frac
        out = [p0 + frac * (p1 - p0) for p0, p1 in zip(prior, pending, strict=True)]
        if frac > 1.0:
            lo, hi = self._lower_l, self._upper_l
            out = [lo[i] if x < lo[i] else (hi[i] if x > hi[i] else x) for i, x in enumerate(out)]
        return out

    def _read_feedback(self, now: float) -> None:
        """Integrate the arm over the last period, then report it (unless feedback is lost)."""
        if self._raise_in_step:
            raise RuntimeError("injected fault in the driver step")
        self._integrate(now)
        if self._feedback_lost:
            return
        n = self._joint_count
        if self._joint_position.shape[0] != n:
            self._joint_position = np.zeros(n)
            self._joint_velocity = np.zeros(n)
            self._joint_effort = np.zeros(n)
        self._joint_position[:] = self._q
        self._joint_velocity[:] = self._v
        estop = self._sim_estop != EstopSource.none
        self._enabled = self._sim_enabled
        self._stopped = estop
        self._estop_source = int(self._sim_estop)
        self._error = self._sim_error
        self._ready = self._sim_enabled and not self._sim_error and not estop
        self._homed = self._sim_homed
        self._last_robot_state = now
        self._last_joint_state = now
        self._last_endpoint_state = now

    def _send_robot_command(
        self, now: float, joint_pos_cmd: F64 | None, joint_vel_cmd: F64 | None
    ) -> None:
        previous = self._pending_pos
        if joint_pos_cmd is not None and previous is not None:
            self._prior_pos = previous.tolist()
            self._prior_t = self._pending_t
        else:
            self._prior_pos = None
        self._pending_pos = joint_pos_cmd
        self._pending_t = now
        self._pending_vel = joint_vel_cmd
        self._last_command_t = now
        if joint_pos_cmd is not None:
            self._position_command = joint_pos_cmd
            self._velocity_command = None
        elif joint_vel_cmd is not None:
            self._velocity_command = joint_vel_cmd
            self._position_command = None
        else:
            self._position_command = None
            self._velocity_command = None
        if self.record_commands:
            self.sent.append((now, joint_pos_cmd, joint_vel_cmd))

    def _send_enable(self) -> None:
        self._sim_enabled = True

    def _send_disable(self) -> None:
        self._sim_enabled = False

    def _send_reset_errors(self) -> None:
        # The simulated operator clears the drive error and releases the e-stop.
        self._sim_error = False
        self._sim_estop = EstopSource.none

    def _start_homing(self, completion: Completion) -> None:
        self._homing_target = self._limits.home.copy()
        self._homing_completion = completion

    # ------------------------------------------------------------------ fault injection

    def inject_fault(self, fault: Fault | str, source: int = EstopSource.button1) -> None:
        """Inject ``fault`` (see :class:`Fault`); ``source`` is the e-stop source code."""
        f = Fault(fault)
        if f is Fault.lost_feedback:
            self._feedback_lost = True
        elif f is Fault.estop:
            self._sim_estop = EstopSource(source)
        elif f is Fault.drive_error:
            self._sim_error = True
        elif f is Fault.disabled:
            self._sim_enabled = False
        elif f is Fault.frozen:
            self._frozen = True
        elif f is Fault.step_exception:
            self._raise_in_step = True

    def clear_fault(self, fault: Fault | str | None = None) -> None:
        """Clear one fault, or all of them (the operator fixes the robot at the controller)."""
        faults = list(Fault) if fault is None else [Fault(fault)]
        for f in faults:
            if f is Fault.lost_feedback:
                self._feedback_lost = False
            elif f is Fault.estop:
                self._sim_estop = EstopSource.none
            elif f is Fault.drive_error:
                self._sim_error = False
            elif f is Fault.disabled:
                self._sim_enabled = True
            elif f is Fault.frozen:
                self._frozen = False
            elif f is Fault.step_exception:
                self._raise_in_step = False

    def fault_active(self, fault: Fault | str) -> bool:
        """Whether ``fault`` is injected now.

        ``reset_errors()`` clears the drive error and the e-stop (the simulated operator does).
        """
        f = Fault(fault)
        if f is Fault.lost_feedback:
            return self._feedback_lost
        if f is Fault.estop:
            return self._sim_estop != EstopSource.none
        if f is Fault.drive_error:
            return self._sim_error
        if f is Fault.disabled:
            return not self._sim_enabled
        if f is Fault.frozen:
            return self._frozen
        return self._raise_in_step

    # ------------------------------------------------------------------ faults as parameters

    def getf_param(self, param_name: str) -> Any:
        """``fault.NAME``: whether that fault is injected (see :mod:`robotspec.driver.faults`)."""
        with self._lock:
            return self.fault_active(fault_param(param_name))

    def setf_param(self, param_name: str, value: Any) -> None:
        """``fault.NAME`` = true injects that fault, false clears it (e-stop source: button 1).

        Why: a client connected over Robot Raconteur can test its fault handling this way.
        """
        fault = fault_param(param_name)
        on = fault_param_value(param_name, value)
        with self._lock:
            if on:
                self.inject_fault(fault)
            else:
                self.clear_fault(fault)
