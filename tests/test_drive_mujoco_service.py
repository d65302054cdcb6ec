"""The physics driver behind the same Robot Raconteur service: a client jogs MuJoCo's arm.

A real-time loop at 100 Hz (the machine's own jitter) around the PR2's right arm on MuJoCo,
gravity compensated, served over loopback to a separate client node. The checks are on where the
measured arm ends and on what the client reads (measured positions, torques), never on timing.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

pytest.importorskip("RobotRaconteur", reason="robotraconteur is not installed")
pytest.importorskip("RobotRaconteurCompanion", reason="robotraconteurcompanion is not installed")
pytest.importorskip("mujoco", reason="the plant is MuJoCo (pip install '.[mujoco]')")

from robotspec.cli.physics import physics_target
from robotspec.driver.loop import JOG_ARRIVAL_TOLERANCE
from robotspec.driver.mujoco_plant import MujocoSimRobot
from robotspec.driver.state import CommandMode
from robotspec.service.server import RobotServer, ServeOptions

from .conftest import erd_robots
from .test_service import (  # noqa: F401 - fixtures
    Served,
    client_node,
    short_tmp,
)


@pytest.fixture
def pr2_physics(short_tmp: Path, client_node: Any) -> Iterator[Served]:  # noqa: F811 - fixtures
    erd_robots()
    target = physics_target("pr2", "right_arm", gravity_compensation=True)
    info = target.exported.info
    driver = MujocoSimRobot(info, target.plant, update_period=0.01)
    server = RobotServer(driver, info, ServeOptions(port=0, state_dir=short_tmp / "rr"))
    with server:
        robot = client_node.ConnectService(server.url)
        try:
            yield Served(server, driver, client_node, robot)
        finally:
            client_node.DisconnectService(robot)


def test_a_client_jogs_the_physics_arm_over_rr(pr2_physics: Served) -> None:
    served = pr2_physics
    driver = served.driver
    assert isinstance(driver, MujocoSimRobot)
    r = served.robot
    r.command_mode = int(CommandMode.jog)
    served.wait_mode(CommandMode.jog)
    lim = driver.limits
    target = driver.sim_position + 0.2 * (0.5 * (lim.lower + lim.upper) - driver.sim_position)
    r.jog_freespace(target, 0.5 * lim.velocity, True)
    # the waiting jog returned once MuJoCo's measured arm was there, and the client reads it
    assert np.max(np.abs(driver.measured_position - target)) <= JOG_ARRIVAL_TOLERANCE
    assert np.max(np.abs(served.q() - target)) <= 10 * JOG_ARRIVAL_TOLERANCE
    effort = np.array(served.state().joint_effort)
    assert effort.shape == (7,) and np.all(np.isfinite(effort))
