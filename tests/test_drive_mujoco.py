"""The driver on MuJoCo physics: MuJoCo is the oracle of what the arm did.

On simulated time (every run the same numbers, whatever the machine's load): a jog arrives within
the driver's own 1e-4 rad with the arm under gravity; the joint torques are the servos' forces,
non-zero under gravity and near zero with it compensated; an e-stop holds the arm where it was
against gravity and motion resumes after a reset; a trajectory ends on its last waypoint; joints
outside the chain stay at the default configuration (a mobile base welded); the demo's scenario
passes under ``--physics mujoco`` on the PR2 (gravity compensated, as the demo decides) and the
Panda. Robots: the shipped Panda and PR2 with example-robot-data's files. Skipped without
MuJoCo (the ``mujoco`` extra).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from robotspec.driver.clock import SimClock
from tests.conftest import erd_robots
from tests.test_cli import run

mujoco = pytest.importorskip("mujoco", reason="the plant is MuJoCo (pip install '.[mujoco]')")

from robotspec.cli.physics import PhysicsTarget, physics_target, replant  # noqa: E402
from robotspec.driver.mujoco_plant import MujocoSimRobot  # noqa: E402


@pytest.fixture(scope="module")
def panda() -> PhysicsTarget:
    erd_robots()
    return physics_target("panda", "arm")


@pytest.fixture(scope="module")
def pr2() -> PhysicsTarget:
    erd_robots()
    return physics_target("pr2", "right_arm", gravity_compensation=True)


def _driver(target: PhysicsTarget) -> MujocoSimRobot:
    robot = MujocoSimRobot(target.exported.info, target.plant, clock=SimClock())
    robot.step()
    robot.step()
    return robot


def _jog_target(robot: MujocoSimRobot, reach: float = 0.3) -> np.ndarray:
    lim = robot.limits
    q0 = robot.sim_position
    return q0 + reach * (0.5 * (lim.lower + lim.upper) - q0)


def test_a_jog_arrives_under_gravity_with_real_torques(panda: PhysicsTarget) -> None:
    robot = _driver(panda)
    target = _jog_target(robot)
    robot.command_mode = "jog"
    robot.jog_freespace(target, 0.5 * robot.limits.velocity, wait=True)
    st = robot.robot_state
    # the driver's arrival rule held on MuJoCo's measured state: within 1e-4 rad and at rest
    assert np.max(np.abs(st.joint_position - target)) <= 1e-4
    assert np.max(np.abs(st.joint_velocity)) <= 1e-3
    assert np.array_equal(st.joint_position, robot.measured_position)
    # the reported torques are the servos' forces, holding the arm against gravity
    assert np.array_equal(st.joint_effort, robot.measured_effort)
    shoulder = robot.joint_names.index("panda_joint2")
    assert abs(st.joint_effort[shoulder]) > 5.0, st.joint_effort
    data = robot.plant_data
    dof = panda.plant.joint_dof[shoulder]
    assert st.joint_effort[shoulder] == pytest.approx(data.qfrc_bias[dof], rel=1e-3, abs=1e-3)


def test_physics_on_simulated_time_gives_the_same_numbers(panda: PhysicsTarget) -> None:
    runs = []
    for _ in range(2):
        robot = _driver(panda)
        robot.command_mode = "jog"
        robot.jog_freespace(_jog_target(robot), 0.5 * robot.limits.velocity, wait=True)
        st = robot.robot_state
        runs.append((st.seqno, st.joint_position.tobytes(), st.joint_effort.tobytes()))
    assert runs[0] == runs[1]


def test_gravity_compensated_arm_needs_almost_no_torque(pr2: PhysicsTarget) -> None:
    robot = _driver(pr2)
    target = _jog_target(robot)
    robot.command_mode = "jog"
    robot.jog_freespace(target, 0.5 * robot.limits.velocity, wait=True)
    robot.run_for(0.5)
    st = robot.robot_state
    assert np.max(np.abs(st.joint_position - target)) <= 1e-4
    assert np.max(np.abs(st.joint_effort)) < 1e-3, st.joint_effort
    # the same arm under gravity: the shoulder needs more than its 30 N m and saturates
    heavy = _driver(replant(pr2, gravity_compensation=False))
    heavy.run_for(1.0)
    shoulder = heavy.joint_names.index("r_shoulder_lift_joint")
    assert heavy.robot_state.joint_effort[shoulder] == pytest.approx(-30.0)
    assert heavy.robot_state.joint_position[shoulder] > 0.3  # sagged from 0


def test_joints_outside_the_chain_are_welded_at_their_default(pr2: PhysicsTarget) -> None:
    # every PR2 joint outside the right arm is at zero by default: all removed, the base too
    model = pr2.plant.model
    assert model.nq == model.nv == 7 and model.nu == 7
    assert {"world_joint/x", "torso_lift_joint", "l_shoulder_pan_joint"} <= set(pr2.plant.welded)
    robot = _driver(pr2)
    robot.command_mode = "jog"
    robot.jog_freespace(_jog_target(robot), robot.limits.velocity, wait=True)
    data = robot.plant_data
    torso = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "torso_lift_link")
    poses = pr2.robot.kinematics.forward(pr2.robot.world.default_configuration())
    index = pr2.robot.world.get_body_by_name("torso_lift_link").index
    assert np.allclose(data.xpos[torso], poses[index][:3, 3], atol=1e-12)


def test_an_estop_holds_the_arm_against_gravity(panda: PhysicsTarget) -> None:
    robot = _driver(panda)
    target = _jog_target(robot, reach=0.6)
    robot.command_mode = "jog"
    robot.jog_freespace(target, 0.5 * robot.limits.velocity, wait=False)
    robot.run_for(0.4)
    moving = np.max(np.abs(robot.robot_state.joint_velocity))
    assert moving > 0.05
    robot.inject_fault("estop")
    robot.run_for(0.3)  # the servos stop the arm where the e-stop found it
    held = robot.robot_state.joint_position.copy()
    robot.run_for(2.0)
    st = robot.robot_state
    assert np.max(np.abs(st.joint_position - held)) < 1e-4
    assert np.max(np.abs(st.joint_velocity)) < 1e-3
    assert abs(st.joint_effort[robot.joint_names.index("panda_joint2")]) > 5.0  # holding
    assert np.max(np.abs(robot.sim_position - held)) < 1e-3  # the reference waits there
    # once the operator releases the e-stop the arm moves again, from where it stopped
    robot.clear_fault("estop")
    robot.run_for(0.1)
    robot.command_mode = "halt"
    robot.command_mode = "jog"
    robot.jog_freespace(target, 0.5 * robot.limits.velocity, wait=True)
    assert np.max(np.abs(robot.robot_state.joint_position - target)) <= 1e-4


def test_a_trajectory_ends_on_its_last_waypoint(panda: PhysicsTarget) -> None:
    from robotspec.driver.trajectory import JointTrajectory

    robot = _driver(panda)
    robot.run_for(0.5)
    # From the state a client reads: the Panda's home sits on joint 4's limit and MuJoCo's
    # limits are soft (the arm sinks micro-radians past it under gravity); the state reports
    # it at the limit, so a trajectory starting there is not refused as outside the limits.
    q0 = robot.robot_state.joint_position.copy()
    lim = robot.limits
    assert np.all(q0 >= lim.lower) and np.all(q0 <= lim.upper)
    q1 = _jog_target(robot, reach=0.4)
    robot.command_mode = "trajectory"
    times = np.linspace(0.0, 4.0, 41)
    out_and_back = np.sin(np.pi * times / 4.0) ** 2  # there at 2 s, back at 4 s, smoothly
    traj = JointTrajectory.from_arrays(times, q0 + np.outer(out_and_back, q1 - q0))
    statuses = list(robot.execute_trajectory(traj))
    assert statuses[-1].action_status.name == "complete"
    robot.run_for(0.2)
    assert np.max(np.abs(robot.robot_state.joint_position - q0)) < 1e-4


def test_the_demo_scenario_passes_under_physics_from_the_command_line(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    # the PR2 with gravity compensated, as the demo decides for it (the next tests)
    erd_robots()
    from robotspec.cli.demo_cmd import demo_scenario
    from robotspec.export.robotinfo import export_spec_chain

    script = tmp_path / "demo.yaml"
    script.write_text(demo_scenario(export_spec_chain("pr2", "right_arm").info))
    code, out, err = run(
        capsys,
        "drive",
        "--spec",
        "pr2",
        "--chain",
        "right_arm",
        "--physics",
        "mujoco",
        "--gravity-compensation",
        "--script",
        str(script),
        "--virtual-time",
    )
    assert code == 0, out + err
    assert out.splitlines()[-1] == "scenario: 8 of 8 steps as expected"
    assert "on MuJoCo physics (gravity compensated) at 100 Hz (virtual time)" in err


def test_the_demo_scenario_passes_under_gravity_on_the_panda(
    panda: PhysicsTarget, tmp_path: Path
) -> None:
    from robotspec.cli.demo_cmd import demo_scenario
    from robotspec.driver.script import load_scenario, mismatch_errors, run_scenario

    script = tmp_path / "demo.yaml"
    script.write_text(demo_scenario(panda.exported.info))
    loaded = load_scenario(script)
    robot = MujocoSimRobot(panda.exported.info, panda.plant, clock=SimClock())
    robot.step()
    results = run_scenario(robot, loaded)
    assert len(results) == 8 and mismatch_errors(loaded, results) == []
    shoulder = robot.joint_names.index("panda_joint2")
    assert abs(robot.robot_state.joint_effort[shoulder]) > 1.0  # gravity held at home


def test_the_demo_compensates_gravity_only_where_an_effort_cannot_hold_the_arm(
    capsys: pytest.CaptureFixture[str], pr2: PhysicsTarget
) -> None:
    from robotspec.cli.demo_physics import demo_plant

    info = pr2.exported.info
    plant, compensated = demo_plant(pr2.robot, "pr2", "right_arm", (), info, None)
    assert compensated and plant.gravity_compensation
    err = capsys.readouterr().err
    assert "note: r_shoulder_lift_joint needs 52.1 N m to hold the arm against gravity, its " in err
    assert "its effort is 30 N m" in err
    plant, compensated = demo_plant(pr2.robot, "pr2", "right_arm", (), info, False)
    assert not compensated and not plant.gravity_compensation


def test_the_demo_leaves_gravity_on_for_an_arm_that_holds_itself(panda: PhysicsTarget) -> None:
    from robotspec.cli.demo_cmd import demo_positions
    from robotspec.driver.mujoco_model import holding_shortfalls

    positions = demo_positions(panda.exported.info)
    assert holding_shortfalls(panda.plant, panda.joint_names, positions) == []


def test_a_servo_outside_the_chain_holds_its_default_under_gravity() -> None:
    # the dual Panda's right joint 4 defaults to -1.5708: not weldable in place, so its servo
    # holds it while the left arm moves (every other right-arm joint is at zero: welded)
    erd_robots()
    target = physics_target("dual_panda", "left_arm")
    model = target.plant.model
    assert "right_panda_joint1" in target.plant.welded
    assert "right_panda_joint4" not in target.plant.welded
    robot = _driver(target)
    robot.command_mode = "jog"
    robot.jog_freespace(_jog_target(robot), 0.5 * robot.limits.velocity, wait=True)
    robot.run_for(0.5)
    j = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, "right_panda_joint4")
    assert robot.plant_data.qpos[model.jnt_qposadr[j]] == pytest.approx(-1.5708, abs=1e-4)
    a = next(a for a in range(model.nu) if model.actuator_trnid[a, 0] == j)
    assert abs(robot.plant_data.actuator_force[a]) > 1.0  # holding the forearm up


def test_a_stalled_loop_is_a_pause_for_the_physics(pr2: PhysicsTarget) -> None:
    # a loop thread preempted for 0.05 to 2 s (a loaded machine): the jog still arrives, and
    # MuJoCo never integrated more than the driver's capped step (no lurch after a stall)
    from tests.driver_support import StallingClock

    clock = StallingClock({0.3: 0.05, 0.6: 2.0, 0.9: 0.5})
    robot = MujocoSimRobot(pr2.exported.info, pr2.plant, clock=clock)
    robot.step()
    robot.step()
    target = _jog_target(robot)
    robot.command_mode = "jog"
    robot.jog_freespace(target, 0.5 * robot.limits.velocity, wait=True)
    assert np.max(np.abs(robot.robot_state.joint_position - target)) <= 1e-4
    simulated = robot.substeps * pr2.plant.model.opt.timestep
    assert simulated < robot._stopwatch_ellapsed_s() - 2.0  # the stalls were not simulated


def test_a_joint_pressed_past_its_soft_limit_is_reported_at_the_limit(
    panda: PhysicsTarget,
) -> None:
    """MuJoCo's limits are soft: the state a client reads stays within the joint limits."""
    robot = _driver(panda)
    i = robot.joint_names.index("panda_joint4")
    data = robot.plant_data
    data.qpos[panda.plant.joint_qpos[i]] = robot.limits.upper[i] + 0.02  # pushed past the stop
    robot.step()
    assert data.qpos[panda.plant.joint_qpos[i]] > robot.limits.upper[i]  # MuJoCo: still past
    assert robot.robot_state.joint_position[i] == robot.limits.upper[i]  # reported at the stop


def test_a_joints_dry_friction_beyond_its_servo_is_said(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The tiny arm's j1 (URDF friction 0.1 N m) stops up to friction/kp short: said up front."""
    from robotspec.driver.mujoco_model import friction_dead_bands
    from tests.test_export_mjcf import TINY_SPEC, TINY_SRDF, TINY_URDF

    (tmp_path / "tiny.urdf").write_text(TINY_URDF)
    (tmp_path / "tiny.srdf").write_text(TINY_SRDF)
    (tmp_path / "tiny.yaml").write_text(TINY_SPEC)
    target = physics_target(tmp_path / "tiny.yaml", "arm")
    bands = friction_dead_bands(target.plant, target.joint_names, 1e-4)
    assert [b.joint for b in bands] == ["j1"]  # j2 has no friction
    j1 = bands[0]
    assert j1.friction == 0.1 and j1.unit == "N m"
    assert j1.band == pytest.approx(0.1 / float(target.plant.kp[0]), rel=1e-12)
    err = capsys.readouterr().err
    assert "note: the URDF's dry friction holds 1 of the chain's joints short of a jog's " in err
    assert f"{j1.band:.2g} rad on j1" in err
    assert friction_dead_bands(target.plant, target.joint_names, 1.0) == []  # within a rad
