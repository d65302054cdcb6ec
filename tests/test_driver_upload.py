"""A trajectory of any length reaches a running loop without the loop doing its work (issue 31).

Decoding, checking and planning run on the uploading thread, outside the loop's lock; the loop
receives the finished plan in one hand-over and samples it at a cost that does not depend on its
length. Tested without timing: by the loop's own counters on a clock charged with the loop
thread's own calls (:mod:`tests.upload_support`), by what runs on the loop thread, by what a step
calls and allocates with a short and a long trajectory, and with the planner held mid-plan.
"""

from __future__ import annotations

import sys
import threading
import tracemalloc
from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest

from robotspec.driver import trajectory as trajectory_module
from robotspec.driver.clock import SimClock
from robotspec.driver.robot_info import load_robot_info
from robotspec.driver.sim import SimRobot
from robotspec.driver.state import CommandMode, RobotState
from robotspec.driver.trajectory import JointTrajectory, TrajectoryColumns, columns_of

from .driver_support import RRP
from .upload_support import LoopThreadProfile, WorkClock, sway, wait_steps

LONG = 20_000
SHORT = 200
PERIOD = 0.005


def _trajectory(robot: SimRobot, m: int) -> JointTrajectory:
    lim = robot.limits
    t, q = sway(np.array(robot.robot_state.joint_position), lim.lower, lim.upper, m)
    return JointTrajectory.from_arrays(t.tolist(), q)


@pytest.fixture
def running() -> Iterator[tuple[SimRobot, WorkClock]]:
    """A driver whose loop thread runs on a :class:`WorkClock`, in trajectory mode."""
    clock = WorkClock()
    robot = SimRobot(load_robot_info(RRP), clock=clock, update_period=PERIOD)
    robot._start_robot()
    try:
        wait_steps(robot, 3)
        robot.command_mode = CommandMode.trajectory
        yield robot, clock
    finally:
        robot._stop_robot()


def test_a_long_upload_costs_the_loop_no_period(running: tuple[SimRobot, WorkClock]) -> None:
    """20,000 waypoints uploaded and then run: the loop misses no period by its own count."""
    robot, clock = running
    traj = _trajectory(robot, LONG)
    profile = LoopThreadProfile(clock)
    profile.install(robot)
    before = robot.loop_stats()
    robot.reset_loop_stats_worst()
    gen = robot.execute_trajectory(traj)  # decoded, checked and planned on this thread
    status = gen.Next()  # the loop runs it for up to 5 s of its time, then says "running"
    assert status.action_status.name == "running"
    profile.remove(robot)
    gen.Abort()
    during = robot.loop_stats().since(before)
    assert profile.planning_on_loop_thread() == set()
    assert during.steps >= 900  # 5 s at 5 ms: the loop ran the long trajectory
    assert during.missed_periods <= 2, during
    assert during.worst_late_periods < 1.0, during


def test_planning_holds_no_lock_the_loop_needs(
    running: tuple[SimRobot, WorkClock], monkeypatch: pytest.MonkeyPatch
) -> None:
    """With the planner held mid-plan, the loop keeps stepping; the plan arrives afterwards."""
    robot, _ = running
    held, release = threading.Event(), threading.Event()
    planner_threads: list[threading.Thread] = []
    real_time_scale = trajectory_module.time_scale

    def slow_time_scale(*args: Any, **kwargs: Any) -> Any:
        planner_threads.append(threading.current_thread())
        held.set()
        assert release.wait(60)
        return real_time_scale(*args, **kwargs)

    monkeypatch.setattr(trajectory_module, "time_scale", slow_time_scale)
    traj = _trajectory(robot, LONG)
    result: list[Any] = []
    uploader = threading.Thread(target=lambda: result.append(robot.execute_trajectory(traj)))
    uploader.start()
    try:
        assert held.wait(60)
        wait_steps(robot, 50)  # would time out if planning held the loop's lock
        assert robot._traj_active is None  # nothing handed over before the plan is finished
    finally:
        release.set()
        uploader.join(60)
    assert planner_threads == [uploader]
    assert result and robot._traj_active is not None
    assert robot._traj_active.interp.n_waypoints == LONG


def _step_costs(m: int) -> tuple[list[int], list[int]]:
    """Calls and peak bytes allocated by each of 40 steps running an ``m``-waypoint trajectory."""
    robot = SimRobot(load_robot_info(RRP), clock=SimClock(), update_period=0.01)
    robot.step()
    robot.step()
    robot.command_mode = CommandMode.trajectory
    gen = robot.execute_trajectory(_trajectory(robot, m))
    calls = [0]
    per_step: list[int] = []
    peaks: list[int] = []

    def profile(frame: Any, event: str, arg: Any) -> None:
        if event in ("call", "c_call"):
            calls[0] += 1

    def after_step(_: RobotState) -> None:
        if tracemalloc.is_tracing():
            current, peak = tracemalloc.get_traced_memory()
            peaks.append(peak - current)
            per_step.append(calls[0])
            calls[0] = 0
            tracemalloc.reset_peak()

    def start() -> None:
        tracemalloc.start()
        tracemalloc.reset_peak()
        sys.setprofile(profile)

    def stop() -> None:
        sys.setprofile(None)
        tracemalloc.stop()

    robot.add_state_listener(after_step)
    robot.at(0.5, start)  # the trajectory is running by then (it starts at the first Next)
    robot.at(0.9, stop)
    gen.Next()  # steps the loop for 5 s (simulated), then says "running"
    gen.Abort()
    return per_step[1:-1], peaks[1:-1]


def test_a_step_costs_the_same_with_a_long_trajectory() -> None:
    """What a step calls and allocates does not grow with the trajectory (no copy, no scan)."""
    short_calls, short_peaks = _step_costs(SHORT)
    long_calls, long_peaks = _step_costs(LONG)
    assert len(short_calls) >= 30 and len(long_calls) == len(short_calls)
    assert max(long_calls) <= max(short_calls)
    # A copy of the trajectory would be 20,000 x 3 x 8 bytes; a list of its times 160 kB.
    assert max(long_peaks) <= max(short_peaks) + 256


def test_columns_are_what_the_checks_see() -> None:
    """The in-process trajectory and its columns check and plan alike (same messages)."""
    robot = SimRobot(load_robot_info(RRP), clock=SimClock())
    robot.step()
    traj = _trajectory(robot, 50)
    cols = columns_of(traj, 3)
    assert isinstance(cols, TrajectoryColumns) and cols.size == 50
    np.testing.assert_array_equal(cols.positions[7], traj.waypoints[7].joint_position)  # type: ignore[index]
    assert cols.velocities is None and int(cols.lengths.min()) == 3
