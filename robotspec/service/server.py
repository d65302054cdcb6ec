"""Serve a running driver over Robot Raconteur: node, RobotInfo structure, service, loop.

:class:`RobotServer` ties the pieces together and owns their lifetimes, in this order on start
(and the reverse on stop): the server node (:func:`~robotspec.service.node.start_server_node`),
the RobotInfo structure with the device UUID for its name (taken and locked in the node's state
folder, as the Companion ``InfoFileLoader`` does), the service registration, and the driver's
loop thread. The driver is the one ``drive --sim`` builds; the server only adapts it.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path
from types import TracebackType
from typing import Any

from robotspec.driver.robot_driver import RobotDriver
from robotspec.driver.robot_info import RobotInfo
from robotspec.driver.rr_names import rr_name_suggestion, valid_rr_name
from robotspec.errors import ServiceError
from robotspec.service import convert
from robotspec.service.node import (
    ServerNode,
    companion,
    remove_own_run_files,
    start_server_node,
    valid_name,
)
from robotspec.service.robot_service import ROBOT_SERVICE_TYPE, RobotService

__all__ = ["DEFAULT_PORT", "RobotServer", "ServeOptions", "default_node_name"]

#: The TCP port ``robotspec drive --serve`` listens on unless told otherwise.
DEFAULT_PORT = 58660


@dataclass(frozen=True)
class ServeOptions:
    """How to serve: port (0 = any free one), exposure, names and the state folder."""

    port: int = DEFAULT_PORT
    public: bool = False
    node_name: str | None = None
    state_dir: Path | None = None
    service_name: str = "robot"


def default_node_name(info: RobotInfo, fallback: str) -> str:
    """The robot's device name (else ``fallback``), made a valid RR name.

    Why the device name: the node-name lock then stops a second driver for the same robot.
    """
    name = info.device_info.device.name or fallback
    return name if valid_rr_name(name) else rr_name_suggestion(name)


class RobotServer:
    """A driver served as ``com.robotraconteur.robotics.robot.Robot``; a context manager.

    Args:
        driver: the driver core (its loop is started by :meth:`start`, stopped by :meth:`stop`).
        info: the RobotInfo the driver was built from.
        options: port, exposure, names, state folder.
        fallback_name: node name when the RobotInfo has no device name.
        start_loop: start the driver's loop thread (False when the caller steps it).
    """

    def __init__(
        self,
        driver: RobotDriver,
        info: RobotInfo,
        options: ServeOptions | None = None,
        *,
        fallback_name: str = "robot",
        start_loop: bool = True,
    ) -> None:
        self.driver = driver
        self.info = info
        self.options = options or ServeOptions()
        self.node_name = self.options.node_name or default_node_name(info, fallback_name)
        self._start_loop = start_loop
        self._server: ServerNode | None = None
        self.service: RobotService | None = None
        self.dropped_fields: list[str] = []
        self._locks: list[Any] = []

    @property
    def port(self) -> int:
        """The TCP port actually listened on."""
        if self._server is None:
            raise ServiceError("the server is not running")
        return self._server.port

    @property
    def url(self) -> str:
        """The URL a client on this machine connects to."""
        if self._server is None:
            raise ServiceError("the server is not running")
        return self._server.url(self.options.service_name)

    @property
    def state_dir(self) -> Path:
        """The folder holding the node's NodeID, the device UUID and their locks."""
        if self._server is None:
            raise ServiceError("the server is not running")
        return self._server.state_dir

    def _rr_robot_info(self, node: Any) -> Any:
        data, self.dropped_fields = convert.robot_info_dict(self.info)
        loader = companion("Util.InfoFileLoader").InfoFileLoader(node)
        name = self.info.device_info.device.name
        if name and self.info.device_info.device.uuid is None and not valid_name(name):
            raise ServiceError(
                f"device name '{name}' cannot be given a Robot Raconteur identifier "
                "(use letters, digits, '_', '.' and '-', starting with a letter)"
            )
        try:
            rr_info, lock = loader.LoadInfoFileFromDict(data, convert.ROBOT_INFO_TYPE, "device")
        except Exception as exc:  # noqa: BLE001 - RR raises plain exceptions
            text = str(exc)
            if "in use" in text.lower() or "lock" in text.lower():
                raise ServiceError(
                    f"device '{name}' is already served by another driver (identifier lock in "
                    f"{self.state_dir}); stop it first"
                ) from None
            raise ServiceError(
                f"cannot convert the RobotInfo for Robot Raconteur: {text}"
            ) from None
        if lock is not None:
            self._locks.append(lock)
        return rr_info

    def start(self) -> RobotServer:
        """Start the node, register the service and start the driver loop.

        Raises:
            ServiceError: the port or a name is in use, or the extra is not installed.
        """
        if self._server is not None:
            return self
        opts = self.options
        server = start_server_node(
            node_name=self.node_name,
            port=opts.port,
            public=opts.public,
            state_dir=opts.state_dir,
        )
        self._server = server
        try:
            node = server.node
            companion("StdRobDef").RegisterStdRobDefServiceTypes(node)
            rr_info = self._rr_robot_info(node)
            wall_epoch = time.time() - self.driver._stopwatch_ellapsed_s()
            service = RobotService(self.driver, node, self.info, rr_info, wall_epoch)
            node.RegisterService(opts.service_name, ROBOT_SERVICE_TYPE, service)
            self.service = service
            # The loop calls the publisher directly: one queue put per step, nothing more.
            self.driver.add_state_listener(service.publisher.publish)
            if self._start_loop:
                self.driver._start_robot()
        except BaseException:
            self.stop()
            raise
        return self

    def stop(self) -> None:
        """Stop the loop, close the service and the node, release the locks (idempotent)."""
        service, self.service = self.service, None
        if self._start_loop:
            self.driver._stop_robot()
        if service is not None:
            service.close()
            self.driver.remove_state_listener(service.publisher.publish)
        server, self._server = self._server, None
        if server is not None:
            name = self.info.device_info.device.name
            if self._locks and name:
                # The device identifier's lock file (RR leaves it behind), while still locked.
                remove_own_run_files(
                    [server.state_dir / "run" / "identifiers" / "device" / f"{name}.pid"]
                )
            server.shutdown()
        self._locks.clear()

    def __enter__(self) -> RobotServer:
        return self.start()

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.stop()
