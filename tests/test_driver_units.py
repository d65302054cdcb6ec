"""Units of the driver: trajectory interpolation, the command guard, profiles, clocks, logs."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robotspec.driver.clock import RealClock, SimClock
from robotspec.driver.commands import CommandGuard, JointLimitArrays, check_speed_ratio, joint_array
from robotspec.driver.errors import InvalidArgumentError, error_kind
from robotspec.driver.profiles import JogMotion, rest_to_rest_time
from robotspec.driver.robot_info import load_robot_info
from robotspec.driver.state import CommandMode
from robotspec.driver.statelog import StateLog
from robotspec.driver.trajectory import JointTrajectory, TrajectoryInterpolator, load_trajectory
from robotspec.errors import RobotSpecError
from tests.driver_support import RRP, make_sim

LIMITS = JointLimitArrays.from_info(load_robot_info(RRP))


@settings(max_examples=50, deadline=None)
@given(
    st.lists(st.lists(st.floats(-1.0, 1.0), min_size=3, max_size=3), min_size=5, max_size=15),
    st.floats(0.0, 1.0),
)
def test_pchip_never_overshoots(points: list[list[float]], frac: float) -> None:
    pos = np.array(points)
    times = np.arange(len(points)) * 0.1
    interp = TrajectoryInterpolator(times, pos)
    t = frac * interp.max_time
    q, k = interp.evaluate(t)
    k = min(k, len(points) - 2)
    lo = np.minimum(pos[k], pos[k + 1]) - 1e-12
    hi = np.maximum(pos[k], pos[k + 1]) + 1e-12
    assert np.all(q >= lo) and np.all(q <= hi)


def test_interpolation_hits_waypoints() -> None:
    times = np.array([0.0, 0.1, 0.2, 0.3, 0.4])
    pos = np.array([[0.0], [0.1], [0.3], [0.2], [0.2]])
    interp = TrajectoryInterpolator(times, pos)
    for t, p in zip(times, pos, strict=True):
        assert interp.evaluate(float(t))[0][0] == pytest.approx(p[0])
    assert interp.evaluate(10.0)[1] == 4


def test_trajectory_refuses_non_finite() -> None:
    traj = JointTrajectory.smooth_move([0, 0, 0.1], [0.1, 0, 0.1], 1.0)
    bad = list(traj.waypoints or ())
    bad[2] = type(bad[2])(joint_position=(float("nan"), 0.0, 0.1), time_from_start=0.1)
    with pytest.raises(InvalidArgumentError, match="Waypoint 2 contains NaN"):
        load_trajectory(
            JointTrajectory(waypoints=tuple(bad)), ("base_yaw", "shoulder", "slide"), LIMITS, 1.0
        )
    with pytest.raises(InvalidArgumentError, match="must not be null"):
        load_trajectory(JointTrajectory(waypoints=None), ("a", "b", "c"), LIMITS, 1.0)


@settings(max_examples=60, deadline=None)
@given(
    st.lists(
        st.floats(-5, 5) | st.sampled_from([float("nan"), float("inf"), -float("inf")]),
        min_size=3,
        max_size=3,
    ),
    st.lists(st.floats(-3, 3), min_size=3, max_size=3),
)
def test_guard_output_always_within_limits(cmd: list[float], ref: list[float]) -> None:
    guard = CommandGuard(LIMITS, 0.01)
    reference = np.clip(np.array(ref), LIMITS.lower, LIMITS.upper)
    out = guard.position(np.array(cmd), reference)
    if not np.all(np.isfinite(cmd)):
        assert out is None
        return
    assert out is not None
    assert np.all(out >= LIMITS.lower) and np.all(out <= LIMITS.upper)
    assert np.all(np.abs(out - reference) <= LIMITS.velocity * 0.01 * (1 + 1e-12))
    vel = guard.velocity(np.array(cmd), reference)
    assert vel is not None
    assert np.all(np.abs(vel) <= LIMITS.velocity)
    nxt = reference + vel * 0.01
    assert np.all(nxt >= LIMITS.lower - 1e-12) and np.all(nxt <= LIMITS.upper + 1e-12)


def test_argument_checks() -> None:
    with pytest.raises(InvalidArgumentError, match="must have 3 elements"):
        joint_array("q", [1, 2], 3)
    with pytest.raises(InvalidArgumentError, match="array of 3 numbers"):
        joint_array("q", ["a", "b", "c"], 3)
    assert check_speed_ratio("0.5") == 0.5
    with pytest.raises(InvalidArgumentError):
        check_speed_ratio("fast")
    assert error_kind(InvalidArgumentError("x")) == "InvalidArgument"
    assert error_kind(ValueError("x")) == "ValueError"


@settings(max_examples=40, deadline=None)
@given(st.lists(st.floats(-3, 3), min_size=3, max_size=3))
def test_jog_profile_reaches_target_within_limits(goal: list[float]) -> None:
    target = np.clip(np.array(goal), LIMITS.lower, LIMITS.upper)
    start = np.clip(np.zeros(3), LIMITS.lower, LIMITS.upper)
    dt = 0.01
    m = JogMotion(
        start, np.zeros(3), LIMITS.velocity, LIMITS.acceleration, LIMITS.lower, LIMITS.upper, dt
    )
    m.to_position(target)
    bound = rest_to_rest_time(target - start, LIMITS.velocity, LIMITS.acceleration).max()
    prev_q, prev_v = start, np.zeros(3)
    for _ in range(int(bound / dt * 1.3) + 20):
        q = m.step()
        v = (q - prev_q) / dt
        assert np.all(np.abs(v) <= LIMITS.velocity * (1 + 1e-9))
        # Acceleration holds to 1 %: the last step onto a joint limit may be clipped.
        assert np.all(np.abs(v - prev_v) <= LIMITS.acceleration * dt * 1.01)
        prev_q, prev_v = q, v
        if m.done:
            break
    assert m.done
    np.testing.assert_array_equal(m.q, target)


def test_clocks() -> None:
    clock = SimClock(1.0)
    clock.sleep_until(2.5)
    assert clock.now() == 2.5
    clock.sleep_until(1.0)
    assert clock.now() == 2.5
    clock.advance(0.5)
    assert clock.now() == 3.0
    real = RealClock()
    t = real.now()
    real.sleep_until(t - 1.0)  # a past deadline returns at once
    assert real.now() >= t


def test_state_log_formats(tmp_path: Path) -> None:
    robot = make_sim(RRP)
    csv_log = StateLog(tmp_path / "s.csv", robot.joint_names, 1)
    json_log = StateLog(tmp_path / "s.jsonl", robot.joint_names, 1)
    robot.add_state_listener(csv_log)
    robot.add_state_listener(json_log)
    robot.run_for(0.05)
    csv_log.close()
    json_log.close()
    lines = (tmp_path / "s.csv").read_text().splitlines()
    assert lines[0].startswith(
        "t,seqno,command_mode,operational_mode,controller_state,flags,q_base"
    )
    assert len(lines) == 1 + csv_log.rows == 6
    recs = [json.loads(x) for x in (tmp_path / "s.jsonl").read_text().splitlines()]
    assert recs[-1]["command_mode"] == "halt" and len(recs[-1]["joint_position"]) == 3
    with pytest.raises(RobotSpecError, match="unknown log format"):
        StateLog(tmp_path / "s.txt", robot.joint_names, 1)


def test_bad_listener_is_dropped_not_fatal() -> None:
    robot = make_sim(RRP)

    def bad(_: object) -> None:
        raise RuntimeError("listener bug")

    robot.add_state_listener(bad)
    robot.run_for(0.05)
    assert robot.robot_state.command_mode is CommandMode.halt
    assert robot.robot_state.error_message == ""


def test_loop_thread_mode() -> None:
    # The real-time path: a loop thread on the real clock; blocking calls wait on it.
    # Short and without timing assertions: it checks that the threads cooperate.
    robot = make_sim(RRP, period=0.002, clock=RealClock())
    robot._start_robot()
    try:
        robot.command_mode = CommandMode.jog
        target = np.array([0.2, 0.1, 0.05])
        robot.jog_freespace(target, robot.limits.velocity, True)
    finally:
        robot._stop_robot()
    # Manual steps after the thread: the arm (1 m/s² on the prismatic joint) settles on the
    # last command; a thread hiccup may have let it overshoot by a few millimetres.
    robot.run_for(0.5)
    assert np.max(np.abs(robot.sim_position - target)) < 1e-6


def test_published_snapshot_is_a_complete_read_only_robot_state() -> None:
    # The loop builds RobotState without its dataclass __init__: every field must be there and
    # equal to what the constructor makes, and every array must stay read-only.
    import dataclasses

    from robotspec.driver.state import RobotState

    robot = make_sim(RRP)
    robot.command_mode = CommandMode.jog
    robot.jog_joint(robot.limits.velocity * 0.1, 0.5)
    state = robot.run_for(0.1)
    names = {f.name for f in dataclasses.fields(RobotState)}
    assert set(vars(state)) == names
    rebuilt = RobotState(**{n: getattr(state, n) for n in names})
    for n in names:
        a, b = getattr(state, n), getattr(rebuilt, n)
        if isinstance(a, np.ndarray):
            np.testing.assert_array_equal(a, b)
        elif n not in ("kin_chain_tcp", "kin_chain_tcp_vel"):
            assert a == b, n
    assert state.trajectory_running is False and state.joint_velocity.any()
    arrays = [
        state.joint_position,
        state.joint_velocity,
        state.joint_effort,
        state.position_command,
    ]
    arrays += [state.kin_chain_tcp[0].position, state.kin_chain_tcp[0].orientation]
    arrays += list(state.kin_chain_tcp_vel)
    for a in arrays:
        assert not a.flags.writeable
        with pytest.raises(ValueError):
            a[0] = 1.0
    with pytest.raises(dataclasses.FrozenInstanceError):
        state.seqno = 3  # type: ignore[misc]
