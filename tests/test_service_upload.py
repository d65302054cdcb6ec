"""A long trajectory uploaded over Robot Raconteur costs the driver loop no period (issue 31).

A real client uploads 20,000 waypoints to a served driver whose loop runs on a clock charged with
the loop thread's own calls (:mod:`tests.upload_support`): Robot Raconteur's decoding, the
service's conversion, the checks and the plan must all run on the thread that received the
call, so the loop's own counters show no missed period and its profile shows none of that work,
however loaded the machine. And the decoding makes one class per structure type: a
35,000-waypoint upload used to make 35,000 classes (a million objects for the collector).
"""

from __future__ import annotations

import gc
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

pytest.importorskip(
    "RobotRaconteur",
    reason="robotraconteur is not installed (pip install robotspec[robotraconteur])",
)
pytest.importorskip(
    "RobotRaconteurCompanion",
    reason="robotraconteurcompanion is not installed (pip install robotspec[robotraconteur])",
)

from robotspec.driver.robot_info import load_robot_info
from robotspec.driver.sim import SimRobot
from robotspec.driver.state import CommandMode
from robotspec.service import convert
from robotspec.service.node import companion, new_node
from robotspec.service.rr_types import cached_structure_types
from robotspec.service.server import RobotServer, ServeOptions

from .driver_support import RRP
from .service_support import client_node, short_tmp
from .upload_support import LoopThreadProfile, WorkClock, sway, wait_steps

__all__ = ["client_node", "short_tmp"]  # fixtures from service_support, used by the tests below

LONG = 20_000
WAYPOINT = "com.robotraconteur.robotics.trajectory.JointTrajectoryWaypoint"


@pytest.fixture
def served(short_tmp: Path, client_node: Any) -> Iterator[tuple[SimRobot, WorkClock, Any]]:
    clock = WorkClock()
    info = load_robot_info(RRP)
    driver = SimRobot(info, clock=clock, update_period=0.005)
    with RobotServer(driver, info, ServeOptions(port=0, state_dir=short_tmp / "rr")) as server:
        robot = client_node.ConnectService(server.url)
        try:
            wait_steps(driver, 3)
            robot.command_mode = int(CommandMode.trajectory)
            yield driver, clock, robot
        finally:
            client_node.DisconnectService(robot)


def _rr_trajectory(node: Any, robot: Any, driver: SimRobot, m: int) -> tuple[Any, np.ndarray]:
    lim = driver.limits
    t, q = sway(np.array(driver.robot_state.joint_position), lim.lower, lim.upper, m)
    new_wp = node.GetStructureType(WAYPOINT, robot)
    traj = node.GetStructureType("com.robotraconteur.robotics.trajectory.JointTrajectory", robot)()
    traj.joint_names = list(driver.joint_names)
    wps = []
    for i in range(m):
        w = new_wp()
        w.joint_position = q[i]
        w.time_from_start = float(t[i])
        wps.append(w)
    traj.waypoints = wps
    return traj, q


def test_a_long_upload_over_rr_costs_the_loop_no_period(
    served: tuple[SimRobot, WorkClock, Any], client_node: Any
) -> None:
    driver, clock, robot = served
    traj, q = _rr_trajectory(client_node, robot, driver, LONG)
    classes = cached_structure_types()
    profile = LoopThreadProfile(clock)
    profile.install(driver)
    before = driver.loop_stats()
    driver.reset_loop_stats_worst()
    gen = robot.execute_trajectory(traj)  # decoded, converted, checked, planned by the service
    wait_steps(driver, 20)  # the loop has run with the plan in hand
    profile.remove(driver)
    during = driver.loop_stats().since(before)
    gen.Close()
    assert profile.planning_on_loop_thread() == set()
    assert during.missed_periods <= 2, during
    assert during.worst_late_periods < 1.0, during
    # The plan that arrived is the trajectory sent, whole.
    task = driver._traj_active or None
    assert task is None or task.interp.n_waypoints == LONG
    # One class per structure type, not one per decoded waypoint.
    assert cached_structure_types() - classes < 10


def test_the_plan_that_arrives_is_the_trajectory_sent(
    served: tuple[SimRobot, WorkClock, Any], client_node: Any
) -> None:
    driver, _, robot = served
    traj, q = _rr_trajectory(client_node, robot, driver, 500)
    gen = robot.execute_trajectory(traj)
    try:
        task = driver._traj_active
        assert task is not None and task.interp.n_waypoints == 500
        np.testing.assert_array_equal(task.interp.positions, q)
        np.testing.assert_array_equal(task.interp.planned_times, np.arange(500) * 0.01)
    finally:
        gen.Close()


@pytest.fixture
def typed_node(short_tmp: Path) -> Iterator[Any]:
    """A node with the standard robdef's types registered (no transport)."""
    node = new_node(short_tmp / "rr-types")
    companion("StdRobDef").RegisterStdRobDefServiceTypes(node)
    yield node
    node.Shutdown()


def test_one_class_per_structure_type(typed_node: Any) -> None:
    """Robot Raconteur looks its class factory up per call: the cache serves every node."""
    first = typed_node.GetStructureType(WAYPOINT)
    gc.collect()
    objects = len(gc.get_objects())
    again = [typed_node.GetStructureType(WAYPOINT) for _ in range(1000)]
    assert all(cls is first for cls in again)
    assert len(gc.get_objects()) - objects < 100  # no class (and its 30 objects) per call


def test_release_waypoints_empties_the_decoded_list(typed_node: Any) -> None:
    traj = typed_node.GetStructureType("com.robotraconteur.robotics.trajectory.JointTrajectory")()
    new_wp = typed_node.GetStructureType(WAYPOINT)
    traj.waypoints = [new_wp() for _ in range(1000)]
    convert.release_waypoints(traj)
    assert traj.waypoints == []
