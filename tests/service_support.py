"""Helpers shared by the tests that serve the simulated robot over Robot Raconteur.

Each test starts its own server (an in-process node on a free loopback port, state in a short
temporary folder) around a real-time :class:`SimRobot`, and talks to it through a separate client
node, as any client program would. Nothing here imports Robot Raconteur at import time: the test
modules skip first when it is not installed.
"""

from __future__ import annotations

import os
import shutil
import tempfile
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from robotspec.driver.robot_info import load_robot_info
from robotspec.driver.sim import SimRobot
from robotspec.driver.state import CommandMode
from robotspec.service.node import start_client_node
from robotspec.service.server import RobotServer, ServeOptions

PERIOD = 0.004
#: The longest any condition is waited for, in seconds. It bounds a hang only: every condition
#: holds within a second on an idle machine, and a loaded one (every core busy, the loop thread
#: missing periods) may take many times that (issue 31). No test waits for it to pass.
WAIT = 60.0
#: The longest a child process (``robotspec drive``) is given to start or to stop; a hang bound
#: too (Python and Robot Raconteur take seconds to import on a busy machine).
CHILD_WAIT = 120.0


def wait_until(cond: Callable[[], bool], timeout: float = WAIT) -> None:
    """Poll ``cond`` until it holds; fail after ``timeout`` seconds (a hang, not slowness)."""
    end = time.monotonic() + timeout
    while not cond():
        if time.monotonic() > end:
            raise AssertionError(f"condition not met in {timeout:g} s")
        time.sleep(0.005)


@pytest.fixture
def short_tmp() -> Iterator[Path]:
    """A temporary folder with a short path: the node's UNIX socket path must fit in 107 bytes,
    and pytest's ``tmp_path`` can be long on some systems."""
    path = Path(tempfile.mkdtemp(prefix="rs", dir="/tmp" if os.path.isdir("/tmp") else None))
    yield path
    shutil.rmtree(path, ignore_errors=True)


@pytest.fixture(scope="module")
def client_node(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Any]:
    node = start_client_node(tmp_path_factory.mktemp("rr-client"))
    yield node
    node.Shutdown()


class Served:
    """A running server, its driver and a connected client object."""

    def __init__(self, server: RobotServer, driver: SimRobot, node: Any, robot: Any) -> None:
        self.server = server
        self.driver = driver
        self.node = node
        self.robot = robot

    def state(self) -> Any:
        value, _ = self.robot.robot_state.PeekInValue()
        return value

    def q(self) -> np.ndarray:
        return np.array(self.state().joint_position)

    def struct(self, name: str) -> Any:
        return self.node.GetStructureType(name, self.robot)()

    def wait_mode(self, mode: CommandMode) -> None:
        wait_until(lambda: self.state().command_mode == int(mode))

    def trajectory(self, delta: np.ndarray, duration: float) -> Any:
        q0 = self.q()
        traj = self.struct("com.robotraconteur.robotics.trajectory.JointTrajectory")
        traj.joint_names = list(self.driver.joint_names)
        m = int(round(duration / 0.05)) + 1
        wps = []
        for i in range(m):
            s = i / (m - 1)
            w = self.struct("com.robotraconteur.robotics.trajectory.JointTrajectoryWaypoint")
            w.joint_position = q0 + delta * (3 * s * s - 2 * s**3)
            w.time_from_start = duration * s
            wps.append(w)
        traj.waypoints = wps
        return traj


@contextmanager
def serve(
    info_path: Path, state_dir: Path, client_node: Any, period: float = PERIOD
) -> Iterator[Served]:
    """Serve a real-time simulated robot from ``info_path`` and connect ``client_node`` to it."""
    info = load_robot_info(info_path)
    driver = SimRobot(info, update_period=period)
    server = RobotServer(driver, info, ServeOptions(port=0, state_dir=state_dir))
    with server:
        robot = client_node.ConnectService(server.url)
        try:
            yield Served(server, driver, client_node, robot)
        finally:
            client_node.DisconnectService(robot)
    assert server.service is None


def rr_exception(name: str) -> type[BaseException]:
    import RobotRaconteur as RR

    cls: type[BaseException] = getattr(RR, name)
    return cls
