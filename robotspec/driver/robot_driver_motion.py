"""The client API's motion commands: jogs, trajectories and the streaming wires.

Why apart from :mod:`robotspec.driver.robot_driver`: these members check a motion request and
hand it to the loop (a jog profile, a planned trajectory, a streamed sample); the driver's
file keeps the command-mode state machine and the robot's status. Each member takes the loop's
lock for its hand-over only.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from robotspec.arrays import F64
from robotspec.driver.commands import RobotJointCommand, finite_scalar, joint_array
from robotspec.driver.conversions import twist_vector
from robotspec.driver.errors import (
    InvalidArgumentError,
    InvalidOperationError,
    OperationAbortedError,
)
from robotspec.driver.handles import Completion, TrajectoryGenerator, TrajectoryTask
from robotspec.driver.profiles import JogMotion
from robotspec.driver.robot_driver_tools import ToolCommands
from robotspec.driver.state import CommandMode
from robotspec.driver.trajectory import JointTrajectory, TrajectoryColumns, load_trajectory
from robotspec.errors import DriverError
from robotspec.exact import exact

__all__ = ["MotionCommands"]


class MotionCommands(ToolCommands):
    """Jogs (joint space, to a position, Cartesian), trajectories and streamed commands."""

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
