"""The ``com.robotraconteur.robotics.robot.Robot`` service object: an adapter over a driver.

Every member delegates to the :class:`~robotspec.driver.robot_driver.RobotDriver` that
``drive --sim`` runs; nothing about the robot's behaviour is implemented here. The adapter only
converts values (:mod:`robotspec.service.convert`), maps the driver's errors to the Robot
Raconteur exceptions of the same name (:mod:`robotspec.service.calls`), and hands each step's
state to its publisher thread (:mod:`robotspec.service.publisher`), which sends it on the wires
and the pipe.

Threading: RR calls members from its thread pool; the driver's own lock serialises them against
the loop thread. Calls that block until the robot has done something (``jog_*`` with
``wait=True``, a trajectory's ``Next()``, homing) run on a small executor owned by the adapter and
are answered through RR's asynchronous handlers, so a few slow clients can never starve RR's
pool (which also serves ``halt()``, marked urgent in the robdef).

Where the adapter deliberately differs from the reference service (robotraconteur-abstract-robot
0.2.2's ``AbstractRobot`` service), beyond what the driver already fixes: ``halt()``, ``home()``,
``operational_mode``, ``controller_state`` and ``current_errors`` work; ``robot_info.config_seqno``
follows tool and payload changes; joint units on AdvancedRobotState are meter / newton for prismatic
joints; the state structures are built without allocation and only for wires and pipes somebody
reads, and they are packed and sent by a publisher thread of the adapter's own, not by the control
loop.
"""

from __future__ import annotations

import threading
from concurrent.futures import ThreadPoolExecutor
from typing import Any

from robotspec.driver.errors import InvalidArgumentError
from robotspec.driver.robot_driver import RobotDriver
from robotspec.driver.robot_info import RobotInfo
from robotspec.service import convert
from robotspec.service.calls import (
    AsyncCalls,
    Handler,
    HomingGeneratorService,
    TrajectoryGeneratorService,
    rr_errors,
    to_rr_error,
)
from robotspec.service.node import companion, rr
from robotspec.service.publisher import StatePublisher

__all__ = ["ROBOT_SERVICE_TYPE", "RobotService", "to_rr_error"]

ROBOT_SERVICE_TYPE = "com.robotraconteur.robotics.robot.Robot"


class RobotService:
    """The service object registered as ``com.robotraconteur.robotics.robot.Robot``.

    Args:
        driver: the running driver core (its loop thread must be started by the owner).
        node: the RR node the service is registered on.
        info: the validated RobotInfo the driver was built from.
        rr_info: the same RobotInfo as an RR structure (device UUID assigned).
        wall_epoch: Unix time of the driver loop's time zero (for timestamps).
        max_blocking_calls: threads for calls that wait on the robot.
    """

    # Wires and the pipe are created by Robot Raconteur when the object is registered (readonly
    # ones as broadcasters, writeonly ones as unicast receivers); declared for the type checker
    # only, so that RR sees no attribute and installs its defaults.
    robot_state: Any
    advanced_robot_state: Any
    robot_state_sensor_data: Any
    device_clock_now: Any
    position_command: Any
    velocity_command: Any

    def __init__(
        self,
        driver: RobotDriver,
        node: Any,
        info: RobotInfo,
        rr_info: Any,
        wall_epoch: float,
        max_blocking_calls: int = 8,
    ) -> None:
        rrmod = rr()
        self.driver = driver
        self.node = node
        self._info = info
        self._rr_info = rr_info
        self._device_info = rr_info.device_info
        self._executor = ThreadPoolExecutor(max_blocking_calls, thread_name_prefix="robotspec-rr")
        self.run_async = AsyncCalls(self._executor)
        dt_util = companion("Util.DateTimeUtil").DateTimeUtil(node)
        self._datetime_util = dt_util
        self._isoch_info_type = node.GetStructureType("com.robotraconteur.device.isoch.IsochInfo")
        self._isoch_epoch = dt_util.TimeSpec2Now(self._device_info)
        joints = node.GetConstants("com.robotraconteur.robotics.joints")
        self._pos_unit_names = {int(v): k for k, v in joints["JointPositionUnits"].items()}
        self._vel_unit_names = {int(v): k for k, v in joints["JointVelocityUnits"].items()}
        self._info_lock = threading.Lock()
        self._rr_tools: list[Any] = [c.current_tool for c in rr_info.chains]
        self._rr_payloads: list[Any] = [c.current_payload for c in rr_info.chains]
        self._info_seqno = -1
        self._stream_ep = {"position": -1, "velocity": -1}
        self._stream_lock = threading.Lock()
        #: Packs and sends each step's state on the wires and the pipe, from its own thread.
        self.publisher = StatePublisher(self, node, info, self._device_info, wall_epoch)
        self.tool_changed = rrmod.EventHook()
        self.payload_changed = rrmod.EventHook()
        self.param_changed = rrmod.EventHook()

    # ------------------------------------------------------------------ RR lifecycle

    def RRServiceObjectInit(self, context: Any, service_path: str) -> None:  # noqa: N802
        """Called by RR once the wires exist: stream receivers, backlog, publishing."""
        self.robot_state_sensor_data.MaxBacklog = 3
        self.position_command.InValueChanged += self._on_position_command
        self.velocity_command.InValueChanged += self._on_velocity_command
        self.publisher.attach(context)

    def close(self) -> None:
        """Stop publishing and accepting blocking calls (pending ones end with the driver)."""
        self.publisher.close()
        self._executor.shutdown(wait=False, cancel_futures=True)

    # ------------------------------------------------------------------ info and modes

    @property
    def device_info(self) -> Any:
        """The robot's DeviceInfo (with the UUID assigned for its name)."""
        return self._device_info

    @property
    def robot_info(self) -> Any:
        """RobotInfo with the attached tools and payloads and the current ``config_seqno``."""
        with self._info_lock:
            # The live seqno: the published state's lags a step behind an attach or detach.
            seqno = self.driver.config_seqno
            if seqno != self._info_seqno:
                for i, chain in enumerate(self._rr_info.chains):
                    chain.current_tool = self._rr_tools[i]
                    chain.current_payload = self._rr_payloads[i]
                self._rr_info.config_seqno = seqno
                self._info_seqno = seqno
            return self._rr_info

    @property
    def command_mode(self) -> int:
        """The current ``RobotCommandMode``."""
        return int(self.driver.command_mode)

    @command_mode.setter
    def command_mode(self, value: int) -> None:
        with rr_errors():
            self.driver.set_command_mode(int(value))

    @property
    def operational_mode(self) -> int:
        """The controller's ``RobotOperationalMode``."""
        return int(self.driver.operational_mode)

    @property
    def controller_state(self) -> int:
        """The controller's ``RobotControllerState``."""
        return int(self.driver.controller_state)

    @property
    def current_errors(self) -> list[Any]:
        """The driver's current errors as EventLogMessages (empty when healthy)."""
        return convert.event_log_messages(
            self.node,
            self._device_info.device,
            self.driver.current_errors,
            self._datetime_util.UtcNow(self._device_info),
        )

    @property
    def speed_ratio(self) -> float:
        """The speed ratio in [0.1, 10]."""
        return self.driver.speed_ratio

    @speed_ratio.setter
    def speed_ratio(self, value: float) -> None:
        with rr_errors():
            self.driver.speed_ratio = float(value)

    @property
    def isoch_info(self) -> Any:
        """Loop rate, maximum downsample and loop epoch."""
        s = self._isoch_info_type()
        s.update_rate = 1.0 / self.driver.update_period
        s.max_downsample = 1000
        s.isoch_epoch = self._isoch_epoch
        return s

    @property
    def isoch_downsample(self) -> int:
        """This client's downsample: it receives every (n+1)-th state."""
        rrmod = rr()
        ds = self.publisher.current_downsampler
        if ds is None:
            return 0
        return int(ds.GetClientDownsample(rrmod.ServerEndpoint.GetCurrentEndpoint()))

    @isoch_downsample.setter
    def isoch_downsample(self, value: int) -> None:
        rrmod = rr()
        if not 0 <= int(value) <= 1000:
            raise rrmod.InvalidArgumentException("isoch_downsample must be within 0-1000")
        ds = self.publisher.downsampler()
        ds.SetClientDownsample(rrmod.ServerEndpoint.GetCurrentEndpoint(), int(value))

    # ------------------------------------------------------------------ simple functions

    def halt(self) -> None:
        """Stop motion: mode ``halt`` (brakes at the acceleration limits)."""
        with rr_errors():
            self.driver.halt()

    def enable(self) -> None:
        """Enable the drives."""
        with rr_errors():
            self.driver.enable()

    def disable(self) -> None:
        """Disable the drives."""
        with rr_errors():
            self.driver.disable()

    def reset_errors(self) -> None:
        """Clear driver faults and the robot's errors."""
        with rr_errors():
            self.driver.reset_errors()

    # ------------------------------------------------------------------ motion

    def async_jog_freespace(
        self, joint_position: Any, max_velocity: Any, wait: bool, handler: Handler
    ) -> None:
        """Jog to a joint position; with ``wait`` answer on arrival."""
        self.run_async.void(
            lambda: self.driver.jog_freespace(joint_position, max_velocity, bool(wait)),
            handler,
            bool(wait),
        )

    def async_jog_joint(
        self, joint_velocity: Any, timeout: float, wait: bool, handler: Handler
    ) -> None:
        """Jog at a joint velocity for ``timeout`` seconds; with ``wait`` answer at the stop."""
        self.run_async.void(
            lambda: self.driver.jog_joint(joint_velocity, float(timeout), bool(wait)),
            handler,
            bool(wait),
        )

    def async_jog_cartesian(
        self, max_velocity: Any, timeout: float, wait: bool, handler: Handler
    ) -> None:
        """Jog one chain's TCP at a spatial velocity (``{chain: SpatialVelocity}``, one entry)."""

        def run() -> None:
            if not isinstance(max_velocity, dict) or len(max_velocity) != 1:
                raise InvalidArgumentError(
                    "max_velocity must map exactly one kinematic chain to a SpatialVelocity"
                )
            ((chain, vel),) = max_velocity.items()
            twist = convert.spatial_velocity_from_rr(vel)
            self.driver.jog_cartesian(twist, float(timeout), bool(wait), chain=int(chain))

        self.run_async.void(run, handler, bool(wait))

    def execute_trajectory(self, trajectory: Any) -> TrajectoryGeneratorService:
        """Check and queue a trajectory; the client drives it with ``Next()``."""
        with rr_errors():
            try:
                columns = convert.trajectory_from_rr(trajectory, len(self.driver.joint_names))
            finally:
                convert.release_waypoints(trajectory)
            gen = self.driver.execute_trajectory(columns)
        return TrajectoryGeneratorService(self.run_async, self.node, gen)

    def home(self) -> HomingGeneratorService:
        """Home the robot (needs ``homing`` mode); the client drives it with ``Next()``."""
        with rr_errors():
            gen = self.driver.homing_generator()
        return HomingGeneratorService(self.run_async, gen)

    # ------------------------------------------------------------------ streaming

    def _on_stream(self, which: str, value: Any, ep: int) -> None:
        names = self._pos_unit_names if which == "position" else self._vel_unit_names
        try:
            cmd = convert.joint_command_from_rr(value, names)
        except (TypeError, ValueError, AttributeError):
            return  # a malformed command is ignored, as every invalid stream sample is
        with self._stream_lock:
            # A new client restarts its seqno: the driver accepts it (the reference does too).
            new_client = ep != self._stream_ep[which]
            self._stream_ep[which] = ep
            if which == "position":
                self.driver.set_position_command(cmd, new_client=new_client)
            else:
                self.driver.set_velocity_command(cmd)

    def _on_position_command(self, value: Any, ts: Any, ep: int) -> None:
        self._on_stream("position", value, ep)

    def _on_velocity_command(self, value: Any, ts: Any, ep: int) -> None:
        self._on_stream("velocity", value, ep)

    # ------------------------------------------------------------------ tools and payloads

    def tool_attached(self, chain: int, tool: Any) -> None:
        """A tool was attached to ``chain``; its TCP now defines the chain's endpoint."""
        with rr_errors():
            model = convert.tool_from_rr(tool)
            self.driver.tool_attached(int(chain), model)
            assert model is not None
            with self._info_lock:
                self._rr_tools[int(chain)] = tool
                self._info_seqno = -1  # rebuilt on the next read, whatever the seqno
        self.tool_changed.fire(int(chain), model.name)

    def tool_detached(self, chain: int, tool_name: str) -> None:
        """The tool ``tool_name`` (or "" for whichever) was detached from ``chain``."""
        with rr_errors():
            self.driver.tool_detached(int(chain), str(tool_name))
            with self._info_lock:
                self._rr_tools[int(chain)] = None
                self._info_seqno = -1  # rebuilt on the next read, whatever the seqno
        self.tool_changed.fire(int(chain), "")

    def payload_attached(self, chain: int, payload: Any, pose: Any) -> None:
        """A payload was attached to the tool of ``chain`` at ``pose`` relative to the TCP."""
        with rr_errors():
            model = convert.payload_from_rr(payload)
            self.driver.payload_attached(int(chain), model, convert.pose_from_rr(pose))
            assert model is not None
            with self._info_lock:
                self._rr_payloads[int(chain)] = payload
                self._info_seqno = -1  # rebuilt on the next read, whatever the seqno
        self.payload_changed.fire(int(chain), model.name)

    def payload_detached(self, chain: int, payload_name: str) -> None:
        """The payload ``payload_name`` (or "") was detached from ``chain``."""
        with rr_errors():
            self.driver.payload_detached(int(chain), str(payload_name))
            with self._info_lock:
                self._rr_payloads[int(chain)] = None
                self._info_seqno = -1  # rebuilt on the next read, whatever the seqno
        self.payload_changed.fire(int(chain), "")

    # ------------------------------------------------------------------ parameters and signals

    def getf_param(self, param_name: str) -> Any:
        """A driver parameter as a ``varvalue`` (the simulator's: ``fault.NAME``, a bool)."""
        with rr_errors():
            return convert.to_varvalue(self.driver.getf_param(str(param_name)))

    def setf_param(self, param_name: str, value: Any) -> None:
        """Set a driver parameter (the simulator's: ``fault.NAME`` to true or false)."""
        name = str(param_name)
        with rr_errors():
            self.driver.setf_param(name, convert.from_varvalue(value))
        self.param_changed.fire(name)

    def getf_signal(self, signal_name: str) -> Any:
        """A signal value (not implemented by the simulated robot)."""
        with rr_errors():
            return self.driver.getf_signal(str(signal_name))

    def setf_signal(self, signal_name: str, value: Any) -> None:
        """Set a signal (not implemented by the simulated robot)."""
        with rr_errors():
            self.driver.setf_signal(str(signal_name), value)
