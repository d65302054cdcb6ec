"""RobotInfo export from a world chain: H/P FK equals the world's FK; YAML round trip; the CLI."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from robotspec.description.urdf import load_urdf
from robotspec.driver.chain_kinematics import HPChain
from robotspec.driver.clock import SimClock
from robotspec.driver.export import (
    DEFAULT_ACCELERATION_FACTOR,
    dump_robot_info_yaml,
    export_chain,
    robot_info_from_chain,
)
from robotspec.driver.robot_info import (
    JointType,
    RobotInfo,
    load_robot_info,
    read_robot_info_text,
)
from robotspec.driver.sim import SimRobot
from robotspec.driver.state import CommandMode
from robotspec.errors import KinematicsError, RobotInfoError
from robotspec.model.kinematics import ChainKinematics
from robotspec.model.rotations import quat_wxyz_to_matrix
from robotspec.model.world import World
from tests.conftest import erd_robots, shared_path

CONFIGS = 50
TOL = 1e-9


def hp_of(info: RobotInfo, chain: int = 0) -> HPChain:
    """The H/P chain exactly as the driver builds it from a RobotInfo."""
    c = info.chains[chain]
    assert c.flange_pose is not None
    prismatic = [info.joint_info[j].joint_type is JointType.prismatic for j in c.joint_numbers]
    return HPChain(
        np.array([h.as_tuple() for h in c.H]),
        np.array([p.as_tuple() for p in c.P]),
        prismatic=prismatic,
        flange_rotation=quat_wxyz_to_matrix(c.flange_pose.orientation.as_tuple()),
        flange_position=np.array(c.flange_pose.position.as_tuple()),
    )


def assert_fk_matches(
    world: World, root: str, tip: str, info: RobotInfo, flange: str | None = None, seed: int = 0
) -> None:
    """HPChain FK of ``info`` == ChainKinematics FK at CONFIGS random configs within limits."""
    ck = ChainKinematics(world, world.get_body_by_name(root), world.get_body_by_name(flange or tip))
    hp = hp_of(info)
    names = info.joint_names
    dof_index = [world.get_degree_of_freedom_by_name(n).index for n in names]
    lo = np.array([j.joint_limits.lower for j in info.joint_info])
    hi = np.array([j.joint_limits.upper for j in info.joint_info])
    rng = np.random.default_rng(seed)
    worst = 0.0
    for k in range(CONFIGS):
        q = np.zeros(len(names)) if k == 0 else rng.uniform(lo, hi)
        qw = np.zeros(len(world.degrees_of_freedom))
        qw[dof_index] = q
        t = ck.fk(qw)
        r, p = hp.fk(q)
        worst = max(
            worst, float(np.max(np.abs(r - t[:3, :3]))), float(np.max(np.abs(p - t[:3, 3])))
        )
    assert worst < TOL, f"H/P FK differs from the world FK by {worst:.3g}"


def roundtrip(info: RobotInfo) -> RobotInfo:
    loaded = read_robot_info_text(dump_robot_info_yaml(info))
    assert loaded.info == info
    return loaded.info


# ------------------------------------------------------------------------------ robots


@pytest.fixture(scope="module")
def pr2() -> World:
    return load_urdf(erd_robots() / "pr2_description/urdf/pr2.urdf", meshes="keep")


def test_pr2_right_arm(pr2: World) -> None:
    ex = export_chain(pr2, "torso_lift_link", "r_wrist_roll_link", device_name="pr2_right_arm")
    info = ex.info
    assert info.joint_names == (
        "r_shoulder_pan_joint",
        "r_shoulder_lift_joint",
        "r_upper_arm_roll_joint",
        "r_elbow_flex_joint",
        "r_forearm_roll_joint",
        "r_wrist_flex_joint",
        "r_wrist_roll_joint",
    )
    chain = info.chains[0]
    assert len(chain.H) == 7 and len(chain.P) == 8
    assert chain.link_identifiers[0].name == "torso_lift_link"
    assert chain.flange_identifier is not None
    assert chain.flange_identifier.name == "r_wrist_roll_link"
    # Continuous joints: revolute (the Companion refuses "continuous") within +-2 pi, with a note.
    roll = info.joint_info[4]
    assert roll.joint_type is JointType.revolute
    assert roll.joint_limits.upper == pytest.approx(2 * math.pi)
    assert any("r_forearm_roll_joint" in n and "no position limits" in n for n in ex.notes)
    # URDF velocity and effort limits carry over; acceleration is the documented default.
    pan = info.joint_info[0].joint_limits
    assert pan.velocity == pytest.approx(2.088)
    assert pan.effort == pytest.approx(30.0)
    assert pan.acceleration == pytest.approx(DEFAULT_ACCELERATION_FACTOR * 2.088)
    assert any("acceleration" in n for n in ex.notes)
    assert_fk_matches(pr2, "torso_lift_link", "r_wrist_roll_link", info)
    roundtrip(info)


def test_pr2_keep_continuous_and_acceleration_overrides(pr2: World) -> None:
    ex = export_chain(
        pr2,
        "torso_lift_link",
        "r_wrist_roll_link",
        device_name="pr2",
        keep_continuous=True,
        continuous_limit=math.pi,
        acceleration={"r_shoulder_pan_joint": 3.0},
    )
    info = ex.info
    assert info.joint_info[4].joint_type is JointType.continuous
    assert info.joint_info[4].joint_limits.lower == pytest.approx(-math.pi)
    assert info.joint_info[0].joint_limits.acceleration == 3.0
    assert "r_shoulder_pan_joint" not in next(n for n in ex.notes if "acceleration" in n)
    loaded = read_robot_info_text(dump_robot_info_yaml(info))
    assert loaded.info == info
    assert any("continuous" in w.message for w in loaded.warnings)
    with pytest.raises(RobotInfoError, match="joints not in the chain: nope"):
        export_chain(
            pr2, "torso_lift_link", "r_wrist_roll_link", device_name="x", acceleration={"nope": 1.0}
        )
    with pytest.raises(RobotInfoError, match="acceleration must be a positive"):
        export_chain(pr2, "torso_lift_link", "r_wrist_roll_link", device_name="x", acceleration=0.0)


def test_pr2_fixed_joints_folded_and_flange_beyond_tip(pr2: World) -> None:
    # base_link -> r_gripper_palm_link crosses the fixed r_gripper_palm_joint after the wrist.
    info = robot_info_from_chain(
        pr2, "base_link", "r_wrist_roll_link", device_name="pr2", flange="r_gripper_palm_link"
    )
    assert info.joint_names[0] == "torso_lift_joint"
    assert info.joint_info[0].joint_type is JointType.prismatic
    assert info.joint_info[0].default_units.value == "meter"
    assert info.joint_info[0].default_effort_units.value == "newton"
    assert len(info.joint_info) == 8
    flange_id = info.chains[0].flange_identifier
    assert flange_id is not None and flange_id.name == "r_gripper_palm_link"
    assert_fk_matches(pr2, "base_link", "r_wrist_roll_link", info, flange="r_gripper_palm_link")
    roundtrip(info)


def test_pr2_refusals(pr2: World) -> None:
    # A moving joint between the tip and the flange.
    with pytest.raises(RobotInfoError, match="r_gripper_l_finger_joint.*beyond the tip"):
        export_chain(
            pr2,
            "torso_lift_link",
            "r_wrist_roll_link",
            device_name="x",
            flange="r_gripper_l_finger_link",
        )
    # Root not above tip.
    with pytest.raises(KinematicsError, match="not an ancestor"):
        export_chain(pr2, "r_wrist_roll_link", "torso_lift_link", device_name="x")
    # No movable joint.
    with pytest.raises(RobotInfoError, match="no movable joint"):
        export_chain(pr2, "r_gripper_palm_link", "r_gripper_palm_link", device_name="x")


def test_pr2_mimic_inside_chain_is_refused(pr2: World) -> None:
    mimics = [c for c in pr2.connections if c.is_mimic]
    assert mimics, "PR2 has mimic joints in its grippers"
    c = mimics[0]
    root = pr2.bodies[c.parent].name
    # The chain from two links above the mimic down to its child.
    above = pr2.parent_connection(root)
    assert above is not None
    start = pr2.bodies[above.parent].name
    with pytest.raises(RobotInfoError, match=f"joint '{c.name}'.*mimics") as exc:
        export_chain(pr2, start, pr2.bodies[c.child].name, device_name="x")
    assert exc.value.name == c.name
    assert exc.value.line == c.line


def test_panda(tmp_path: Path) -> None:
    world = load_urdf(erd_robots() / "panda_description/urdf/panda.urdf", meshes="keep")
    info = robot_info_from_chain(
        world, "panda_link0", "panda_link7", device_name="panda", flange="panda_hand_tcp"
    )
    assert len(info.joint_info) == 7
    assert_fk_matches(world, "panda_link0", "panda_link7", info, flange="panda_hand_tcp")
    out = tmp_path / "panda.yml"
    out.write_text(dump_robot_info_yaml(info, header="Franka Panda\nexported"))
    assert out.read_text().startswith("# Franka Panda\n# exported\n")
    assert load_robot_info(out) == info


def test_ur5_erd() -> None:
    world = load_urdf(erd_robots() / "ur_description/urdf/ur5_robot.urdf", meshes="keep")
    info = robot_info_from_chain(
        world, "base_link", "wrist_3_link", device_name="ur5", flange="tool0"
    )
    assert len(info.joint_info) == 6
    assert_fk_matches(world, "base_link", "wrist_3_link", info, flange="tool0")
    roundtrip(info)


def test_ur5e_shared() -> None:
    world = load_urdf(shared_path("robots", "ur5e", "ur5e.urdf"), meshes="keep")
    info = robot_info_from_chain(
        world, "base_link", "wrist_3_link", device_name="ur5e", flange="tool0"
    )
    assert_fk_matches(world, "base_link", "wrist_3_link", info, flange="tool0")
    # The published driver file is in UR's 'base' frame, 180 deg about z from base_link (note
    # §1(c)); from 'base' the exported flange at q = 0 agrees with it to the file's ~1 mm rounding.
    published = load_robot_info(shared_path("robotinfo", "ur5e.yml"))
    from robotspec.model.kinematics import Kinematics

    t_base = Kinematics(world).pose(np.zeros(6), "base", relative_to="base_link")
    r_ours, p_ours = hp_of(info).fk(np.zeros(6))
    r_pub, p_pub = hp_of(published).fk(np.zeros(6))
    r_in_base = t_base[:3, :3].T @ r_ours
    p_in_base = t_base[:3, :3].T @ (p_ours - t_base[:3, 3])
    assert np.allclose(p_in_base, p_pub, atol=2e-3)
    assert np.allclose(r_in_base, r_pub, atol=1e-6)


def test_hsrb_prismatic_and_mimic() -> None:
    world = load_urdf(shared_path("robots", "hsrb", "hsrb4s.urdf"), meshes="keep")
    info = robot_info_from_chain(world, "base_link", "hand_palm_link", device_name="hsrb_arm")
    assert info.joint_names[0] == "arm_lift_joint"
    assert info.joint_info[0].joint_type is JointType.prismatic
    assert_fk_matches(world, "base_link", "hand_palm_link", info)
    roundtrip(info)
    # torso_lift_joint mimics arm_lift_joint: no H/P form.
    with pytest.raises(RobotInfoError, match="'torso_lift_joint'.*mimics 'arm_lift_joint'"):
        robot_info_from_chain(world, "base_link", "head_tilt_link", device_name="hsrb_head")


def test_exported_robot_is_drivable(pr2: World) -> None:
    info = robot_info_from_chain(pr2, "torso_lift_link", "r_wrist_roll_link", device_name="pr2")
    robot = SimRobot(info, clock=SimClock())
    robot.step()
    robot.step()
    robot.command_mode = CommandMode.jog
    q0 = np.array(robot.robot_state.joint_position)
    target = np.clip(q0 + 0.2, robot.limits.lower, robot.limits.upper)
    robot.jog_freespace(target, robot.limits.velocity * 0.5, wait=True)
    assert np.allclose(robot.robot_state.joint_position, target, atol=1e-3)
    # The driver's endpoint pose equals the world FK at the reached configuration.
    ck = ChainKinematics(
        pr2, pr2.get_body_by_name("torso_lift_link"), pr2.get_body_by_name("r_wrist_roll_link")
    )
    qw = np.zeros(len(pr2.degrees_of_freedom))
    qw[[pr2.get_degree_of_freedom_by_name(n).index for n in info.joint_names]] = (
        robot.robot_state.joint_position
    )
    assert np.allclose(robot.robot_state.kin_chain_tcp[0].position, ck.fk(qw)[:3, 3], atol=1e-9)


def test_yaml_is_reference_shaped(pr2: World) -> None:
    info = robot_info_from_chain(pr2, "torso_lift_link", "r_wrist_roll_link", device_name="pr2")
    data = yaml.safe_load(dump_robot_info_yaml(info))
    # Keys the reference parser reads as zero when absent are always written.
    j = data["joint_info"][0]
    assert j["joint_type"] == "revolute" and j["default_units"] == "radian"
    assert {"lower", "upper", "velocity", "acceleration"} <= set(j["joint_limits"])
    assert "jerk" not in j["joint_limits"]
    assert data["chains"][0]["flange_pose"]["position"] == {"x": 0.0, "y": 0.0, "z": 0.0}
    assert data["robot_capabilities"] == [
        "jog_command",
        "trajectory_command",
        "position_command",
        "velocity_command",
    ]


# ------------------------------------------------------------------------------ the CLI


def run_cli(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    """Run ``robotspec ARGV`` in-process; returns (exit code, stdout, stderr)."""
    from robotspec.cli.app import app
    from robotspec.cli.output import run_app

    code = run_app(app, list(argv))
    out = capsys.readouterr()
    return code, out.out, out.err


@pytest.fixture
def pr2_spec() -> str:
    erd_robots()  # the shipped pr2 spec loads its URDF from example-robot-data
    return "pr2"


def test_cli_export_robotinfo_stdout(capsys: pytest.CaptureFixture[str], pr2_spec: str) -> None:
    code, out, err = run_cli(capsys, "export", "robotinfo", pr2_spec, "--chain", "right_arm")
    assert code == 0, err
    assert out.startswith("# RobotInfo of chain 'right_arm' of pr2, exported by robotspec.\n")
    info = read_robot_info_text(out).info
    assert info.device_info.device.name == "PR2_right_arm"
    assert info.chains[0].kin_chain_identifier.name == "right_arm"
    assert info.joint_names[0] == "r_shoulder_pan_joint" and len(info.joint_names) == 7
    assert "note: joint 'r_forearm_roll_joint' (continuous) has no position limits" in err
    assert "note: the description gives no acceleration limits" in err


def test_cli_export_robotinfo_file_is_drivable(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, pr2_spec: str
) -> None:
    out_file = tmp_path / "pr2_right.yml"
    code, out, err = run_cli(
        capsys, "export", "robotinfo", pr2_spec, "--chain", "right_arm", "-o", str(out_file)
    )
    assert code == 0, err
    assert out == ""
    assert f"wrote {out_file} (7 joints, chain right_arm)" in err
    # The same FK as the world model of the compiled spec.
    from robotspec.compiler import compile_robot

    robot = compile_robot("pr2")
    c = robot.get_chain("right_arm")
    assert_fk_matches(robot.world, c.root.name, c.tip.name, load_robot_info(out_file))
    # ... and `drive --sim` runs it.
    code, out, err = run_cli(
        capsys, "drive", "--sim", str(out_file), "--duration", "0.2", "--virtual-time"
    )
    assert code == 0, err
    assert "final mode halt, flags 0x60000" in out


def test_cli_export_unknown_chain(capsys: pytest.CaptureFixture[str], pr2_spec: str) -> None:
    code, out, err = run_cli(capsys, "export", "robotinfo", pr2_spec, "--chain", "right_armm")
    assert code == 1
    assert out == ""
    assert "chain 'right_armm' not found" in err


def test_cli_export_needs_chain(capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run_cli(capsys, "export", "robotinfo", "pr2")
    assert code == 2
    assert "--chain" in err


def test_cli_drive_spec_chain(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, pr2_spec: str
) -> None:
    script = tmp_path / "jog.yaml"
    script.write_text(
        "- call: command_mode\n"
        "  args: {mode: jog}\n"
        "- call: jog_joint\n"
        "  args: {joint_velocity: [0.1, 0, 0, 0, 0, 0, 0], timeout: 0.5, wait: true}\n"
        "- call: command_mode\n"
        "  args: {mode: trajectory}\n"
        "  expect: {error: InvalidOperation, message: 'Must switch to \"halt\"'}\n"
        "- check: {command_mode: jog}\n"
    )
    code, out, err = run_cli(
        capsys,
        "drive",
        "--spec",
        pr2_spec,
        "--chain",
        "right_arm",
        "--virtual-time",
        "--script",
        str(script),
    )
    assert code == 0, err
    assert "driving PR2_right_arm (7 joints, 1 chain) in simulation at 100 Hz (virtual time)" in err
    assert "scenario: 4 of 4 steps as expected" in out


def test_cli_drive_spec_needs_chain(capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run_cli(capsys, "drive", "--spec", "pr2")
    assert code == 2
    assert "--spec needs --chain NAME" in err
