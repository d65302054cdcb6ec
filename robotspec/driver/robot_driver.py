"""The seed's client API of a robot driver: command modes, status, enable, homing.

:class:`RobotDriver` is what clients (scripts, the Robot Raconteur service, tests) call. Every
member checks its arguments and the state machine, then hands work to the timestep pipeline of
:class:`~robotspec.driver.loop.DriverLoop`, which it extends. The client API is three files,
one job each: this one (the command-mode state machine and what the robot reports),
:mod:`~robotspec.driver.robot_driver_motion` (jogs, trajectories, streamed commands) and
:mod:`~robotspec.driver.robot_driver_tools` (tools and payloads on each chain).

The reference's defects are not copied: the deliberate deviations, each tested, are listed once,
in ``docs/driver.md`` ("Deliberate deviations from the reference").
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from robotspec.driver.commands import (
    JointLimitArrays,
    check_speed_ratio,
)
from robotspec.driver.conversions import (
    parse_mode,
)
from robotspec.driver.errors import (
    InvalidArgumentError,
    InvalidOperationError,
    NotImplementedDriverError,
    OperationFailedError,
)
from robotspec.driver.handles import (
    Completion,
    HomingGenerator,
)
from robotspec.driver.robot_driver_motion import MotionCommands
from robotspec.driver.robot_info import (
    DeviceInfo,
    RobotCapability,
    RobotInfo,
)
from robotspec.driver.state import (
    CommandMode,
    ControllerState,
    OperationalMode,
    RobotState,
)

__all__ = ["RobotDriver"]


class RobotDriver(MotionCommands):
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
