"""The driver's state machine: communication and robot-state checks, and ending interrupted motion.

Steps 2 and 3 of the timestep (the reference's ``_verify_communication`` and
``_verify_robot_state``, rule for rule, first match wins), what an interrupted motion is told, and
the limits of the current operational mode.
"""

from __future__ import annotations

import numpy as np

from robotspec.arrays import F64
from robotspec.driver.errors import (
    InvalidOperationError,
    OperationAbortedError,
)
from robotspec.driver.loop_state import LoopState
from robotspec.driver.state import (
    CommandMode,
    ControllerState,
    OperationalMode,
)
from robotspec.errors import DriverError

__all__ = ["ModeMachine"]


class ModeMachine(LoopState):
    """Steps 2 and 3 of the timestep, and the mode-dependent rules motion needs."""

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
        """Step 3: the reference's rules, first match wins (``_verify_robot_state``)."""
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
        self._jog_settle_deadline = None
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

    def _jog_limits(self) -> tuple[F64, F64]:
        op = self._operational_mode
        if op is OperationalMode.manual_reduced_speed:
            return self._limits.reduced_velocity, self._limits.reduced_acceleration
        if op in (OperationalMode.manual_full_speed, OperationalMode.cobot):
            return self._limits.velocity, self._limits.acceleration
        raise InvalidOperationError("Invalid operation mode for jog")
