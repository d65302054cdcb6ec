"""Every RobotInfo (the shared real files and the local fixture) driven by jog and trajectory."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from robotspec.driver.state import ActionStatus, CommandMode, StateFlags
from robotspec.driver.trajectory import JointTrajectory
from tests.driver_support import RRP, make_sim, q_of, shared_robotinfo_files

FILES = [RRP, *shared_robotinfo_files()]


def _within_limits(robot: object, cmds: np.ndarray) -> None:
    lim = robot.limits  # type: ignore[attr-defined]
    period = robot.update_period  # type: ignore[attr-defined]
    assert np.all(cmds >= lim.lower - 1e-12) and np.all(cmds <= lim.upper + 1e-12)
    assert np.all(np.abs(np.diff(cmds, axis=0)) <= lim.velocity * period * (1 + 1e-9))


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.name)
def test_jog_and_trajectory(path: Path) -> None:
    robot = make_sim(path)
    robot.record_commands = True
    lim = robot.limits
    assert int(robot.robot_state.flags) & int(StateFlags.ready)
    n_chains = len(robot.robot_info.chains)
    assert len(robot.robot_state.kin_chain_tcp) == n_chains

    # Jog to a point a quarter of the way toward each upper limit, at half speed.
    robot.command_mode = CommandMode.jog
    q0 = q_of(robot)
    target = q0 + 0.25 * (lim.upper - q0)
    robot.jog_freespace(target, 0.5 * lim.velocity, True)
    robot.step()
    np.testing.assert_allclose(q_of(robot), target, atol=1e-9)
    # Jog one joint by velocity.
    qd = np.zeros(len(q0))
    qd[0] = -0.2 * lim.velocity[0]
    robot.jog_joint(qd, 0.3, True)
    robot.halt()
    robot.run_for(0.05)

    # A trajectory back toward the start, then execute to completion.
    robot.command_mode = CommandMode.trajectory
    start = q_of(robot)
    end = start + 0.5 * (q0 - start)
    traj = JointTrajectory.smooth_move(start, end, 4.0)  # feasible for the RML63 (1 rad/s²)
    gen = robot.execute_trajectory(traj)
    statuses = [s.action_status for s in gen]
    assert statuses[-1] is ActionStatus.complete
    robot.run_for(1.0)  # the driver holds the end; an arm with low limits (RML63) catches up
    np.testing.assert_allclose(q_of(robot), end, atol=1e-9)

    cmds = np.array([c[1] for c in robot.sent if c[1] is not None])
    _within_limits(robot, cmds)
    st = robot.robot_state
    assert st.command_mode is CommandMode.trajectory
    assert np.all(np.isfinite(st.joint_position))
    for pose in st.kin_chain_tcp:
        assert np.linalg.norm(pose.orientation) == pytest.approx(1.0)
