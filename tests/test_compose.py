"""Robots composed from parts: joined trees against pinocchio, semantics, round trips, errors."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robotspec.collision import CollisionRules
from robotspec.compiler import check_spec, compile_robot
from robotspec.errors import RobotSpecError, RobotSpecErrors
from robotspec.export.srdf import srdf_from_robot, write_srdf
from robotspec.export.urdf import bundle, joined_urdf, urdf_text
from robotspec.model.kinematics import Kinematics
from robotspec.model.world import World
from robotspec.semantic import AbstractRobot
from robotspec.spec.load import load_spec

from .conftest import erd_robots

COMPOSED = ("b1_ur5_allegro", "dual_panda")


@pytest.fixture(scope="module", params=COMPOSED)
def composed(request: pytest.FixtureRequest) -> tuple[str, AbstractRobot]:
    erd_robots()
    return request.param, compile_robot(request.param)


def _pin_poses(urdf: Path, world: World, q: np.ndarray, root: str) -> dict[str, np.ndarray]:
    import pinocchio as pin

    model = pin.buildModelFromUrdf(str(urdf))
    data = model.createData()
    qp = pin.neutral(model)
    for j in range(1, model.njoints):
        c = world.get_connection_by_name(model.names[j])
        jm = model.joints[j]
        v = q[c.dofs[0]]
        if c.mimic is not None:
            v = q[c.dofs[0]] * c.mimic.multiplier + c.mimic.offset
        if jm.nq == 2:
            qp[jm.idx_q : jm.idx_q + 2] = (np.cos(v), np.sin(v))
        else:
            qp[jm.idx_q] = v
    pin.forwardKinematics(model, data, qp)
    pin.updateFramePlacements(model, data)
    out = {}
    base = data.oMf[model.getFrameId(root)].homogeneous
    for f in range(model.nframes):
        frame = model.frames[f]
        if frame.type == pin.FrameType.BODY:
            out[frame.name] = np.linalg.inv(base) @ data.oMf[f].homogeneous
    return out


def test_composed_fk_equals_pinocchio_on_exported_urdf(
    composed: tuple[str, AbstractRobot], tmp_path: Path
) -> None:
    name, robot = composed
    loaded = load_spec(_spec_file(name))
    urdf = tmp_path / f"{name}.urdf"
    urdf.write_text(urdf_text(joined_urdf(loaded), comment="test"))
    world = robot.world
    kin = Kinematics(world)
    rng = np.random.default_rng(7)
    lo = np.array([d.lower for d in world.degrees_of_freedom])
    hi = np.array([d.upper for d in world.degrees_of_freedom])
    lo, hi = np.where(np.isfinite(lo), lo, -np.pi), np.where(np.isfinite(hi), hi, np.pi)
    root = robot.root.name
    compared = 0
    for _ in range(5):
        q = rng.uniform(lo, hi)
        # The drive is not in the URDF: compare in the robot root's frame.
        theirs = _pin_poses(urdf, world, q, root)
        for body in world.bodies:
            if body.name not in theirs:
                continue
            mine = kin.pose(q, body.name, relative_to=root)
            np.testing.assert_allclose(mine, theirs[body.name], atol=1e-9, err_msg=body.name)
            compared += 1
    assert compared >= 5 * (len(world.bodies) - 2)


def _spec_file(name: str) -> Path:
    from robotspec.shipped import shipped_spec_files

    return shipped_spec_files()[name]


def test_semantics_survive_composition() -> None:
    erd_robots()
    mobile = compile_robot("b1_ur5_allegro")
    arm = mobile.get_chain("ur5_arm")
    # The hand's manipulator, prefixed, is the arm chain's; its tool frame is the hand's frame.
    assert arm.manipulator is not None and arm.manipulator.name == "allegro_hand"
    assert arm.manipulator.tool_frame.name == "allegro_grasp_frame"
    assert mobile.world.is_ancestor(arm.tip, arm.manipulator.tool_frame)
    hand_alone = compile_robot(
        _spec_file("b1_ur5_allegro").parent / "parts" / "allegro_right_hand.yaml"
    )
    (alone,) = hand_alone.manipulators
    assert alone.tool_frame.name == "grasp_frame"
    np.testing.assert_allclose(
        _relative(mobile, "allegro_palm_link", "allegro_grasp_frame"),
        _relative(hand_alone, "palm_link", "grasp_frame"),
        atol=1e-12,
    )
    # The UR5's bare flange gave way to the hand; its 'world' link merged into the trunk.
    assert [m.name for m in mobile.manipulators] == ["allegro_hand"]
    assert not mobile.world.has_body("ur5_world") and not mobile.world.has_body("world")
    weld = mobile.world.parent_connection("ur5_base_link")
    assert weld is not None and mobile.world.bodies[weld.parent].name == "trunk"
    # Prefixed states of both parts; the base's SRDF virtual joint is the drive.
    assert {"ur5_arm.home", "allegro_hand.open", "allegro_hand.close"} <= set(mobile.joint_states)
    assert mobile.drive is not None and mobile.drive.type.value == "floating"
    assert "ur5_shoulder_pan_joint" in {c.name for c in mobile.controlled_connections}

    dual = compile_robot("dual_panda")
    for side in ("left", "right"):
        chain = dual.get_chain(f"{side}_arm")
        assert chain.manipulator is not None and chain.manipulator.name == f"{side}_hand"
        assert chain.manipulator.tool_frame.name == f"{side}_panda_hand_tcp"
        assert f"{side}_arm.ready" in dual.joint_states
        # Panda's default velocity cap (1.0) stays on Panda's joints.
        dof = dual.world.get_degree_of_freedom_by_name(f"{side}_panda_joint1")
        assert dof.velocity == pytest.approx(1.0)
    assert "ready" in dual.joint_states
    single = compile_robot("panda")
    np.testing.assert_allclose(
        _relative(dual, "left_panda_link0", "left_panda_hand_tcp"),
        _relative(single, "panda_link0", "panda_hand_tcp"),
        atol=1e-12,
    )


def _relative(robot: AbstractRobot, a: str, b: str) -> np.ndarray:
    kin = Kinematics(robot.world)
    q = np.zeros(len(robot.world.degrees_of_freedom))
    return kin.pose(q, b, relative_to=a)


def test_weld_makes_bodies_adjacent_and_cross_part_pairs_are_checked() -> None:
    erd_robots()
    dual = compile_robot("dual_panda")
    rules = CollisionRules.from_robot(dual)
    assert not rules.is_checked("torso_plate", "left_panda_link0")
    assert rules.why_disabled("torso_plate", "left_panda_link0") == "Adjacent"
    assert rules.is_checked("left_panda_hand", "right_panda_hand")
    assert rules.is_checked("stand_base", "left_panda_link7")
    # Each Panda's own SRDF pairs came along, prefixed.
    single = CollisionRules.from_robot(compile_robot("panda"))
    for a, b in single.disabled:
        assert not rules.is_checked(f"left_{a}", f"left_{b}")
        assert not rules.is_checked(f"right_{a}", f"right_{b}")


@pytest.mark.parametrize("name", COMPOSED)
def test_exported_bundle_compiles_to_the_same_robot(name: str, tmp_path: Path) -> None:
    erd_robots()
    result = check_spec(name)
    robot = result.robot
    assert robot is not None
    out = bundle(result, name=name)
    for suffix, text in ((".urdf", out.urdf), (".srdf", out.srdf), (".yaml", out.spec)):
        (tmp_path / f"{name}{suffix}").write_text(text)
    again = check_spec(tmp_path / f"{name}.yaml")
    assert again.warnings == ()
    back = again.robot
    assert back is not None
    w1, w2 = robot.world, back.world
    assert w1.body_names == w2.body_names
    assert w1.connection_names == w2.connection_names
    assert [(d.name, d.lower, d.upper, d.velocity) for d in w1.degrees_of_freedom] == [
        (d.name, d.lower, d.upper, d.velocity) for d in w2.degrees_of_freedom
    ]
    assert _summary(robot) == _summary(back)
    assert robot.disabled_collision_pairs == back.disabled_collision_pairs
    assert {k: v.joints for k, v in robot.joint_states.items()} == {
        k: v.joints for k, v in back.joint_states.items()
    }
    q = np.random.default_rng(3).uniform(-1, 1, len(w1.degrees_of_freedom))
    np.testing.assert_allclose(Kinematics(w1).forward(q), Kinematics(w2).forward(q), atol=1e-12)
    # The SRDF written from the copy is the SRDF written from the original.
    assert write_srdf(srdf_from_robot(back)) == write_srdf(srdf_from_robot(robot))


def _summary(robot: AbstractRobot) -> list[tuple[str, ...]]:
    chains = [
        (c.name, c.root.name, c.tip.name, c.manipulator.name if c.manipulator else "")
        for c in robot.kinematic_chains
    ]
    manips = [(m.name, m.root.name, m.tool_frame.name) for m in robot.manipulators]
    return [*chains, *manips, (robot.root.name, str(robot.drive and robot.drive.type))]


# ------------------------------------------------------------------------ small fixtures
ARM_URDF = """<?xml version="1.0"?>
<robot name="arm">
  <material name="paint"><color rgba="1 0 0 1"/></material>
  <link name="mount"/>
  <link name="base_link">
    <visual><geometry><mesh filename="meshes/base.stl"/></geometry><material name="paint"/></visual>
    <inertial><origin xyz="0 0 0.05"/><mass value="2"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.02"/></inertial>
  </link>
  <link name="upper"><collision><geometry><box size="0.1 0.1 0.4"/></geometry></collision></link>
  <link name="flange"/>
  <joint name="mount_joint" type="fixed"><parent link="mount"/><child link="base_link"/></joint>
  <joint name="shoulder" type="revolute">
    <origin xyz="0 0 0.1"/><axis xyz="0 0 1"/><parent link="base_link"/><child link="upper"/>
    <limit lower="-2" upper="2" velocity="1.5" effort="10"/>
  </joint>
  <joint name="wrist" type="revolute">
    <origin xyz="0 0 0.4" rpy="0 1.5707963267948966 0"/><axis xyz="0 1 0"/>
    <parent link="upper"/><child link="flange"/>
    <limit lower="-2" upper="2" velocity="1.5" effort="10"/>
  </joint>
</robot>
"""

HAND_URDF = """<?xml version="1.0"?>
<robot name="hand">
  <material name="paint"><color rgba="0 0 1 1"/></material>
  <link name="palm">
    <visual><geometry><box size="0.08 0.08 0.02"/></geometry><material name="paint"/></visual>
    <collision><origin xyz="0 0 0.01"/><geometry><box size="0.08 0.08 0.02"/></geometry></collision>
    <inertial><origin xyz="0.01 0 0.02" rpy="0 0 0.3"/><mass value="0.5"/>
      <inertia ixx="0.001" ixy="0.0001" ixz="0" iyy="0.002" iyz="0" izz="0.003"/></inertial>
  </link>
  <link name="finger"><collision><geometry><box size="0.01 0.01 0.05"/></geometry></collision>
    <inertial><mass value="0.05"/>
      <inertia ixx="1e-5" ixy="0" ixz="0" iyy="1e-5" iyz="0" izz="1e-5"/></inertial>
  </link>
  <link name="tcp"/>
  <joint name="finger_joint" type="prismatic">
    <origin xyz="0 0.02 0.03"/><axis xyz="0 1 0"/><parent link="palm"/><child link="finger"/>
    <limit lower="0" upper="0.04" velocity="0.2" effort="10"/>
  </joint>
  <joint name="tcp_joint" type="fixed">
    <origin xyz="0 0 0.1"/><parent link="palm"/><child link="tcp"/>
  </joint>
</robot>
"""

ARM_SPEC = """robotspec: 1
name: Arm
description: {urdf: arm.urdf}
root: mount
drive: {type: fixed}
chains:
  arm: {root: base_link, tip: flange, manipulator: flange, states: {up: {shoulder: 0.5}}}
manipulators:
  flange: {type: generic, root: flange, tool_frame: flange}
"""

HAND_SPEC = """robotspec: 1
name: Hand
description: {urdf: hand.urdf}
root: palm
drive: {type: fixed}
manipulators:
  gripper: {type: generic, root: palm, tool_frame: tcp, states: {open: {finger_joint: 0.04}}}
"""


def _fixture(tmp_path: Path, composed: str, name: str = "robot.yaml") -> Path:
    (tmp_path / "arm.urdf").write_text(ARM_URDF)
    (tmp_path / "hand.urdf").write_text(HAND_URDF)
    (tmp_path / "arm.yaml").write_text(ARM_SPEC)
    (tmp_path / "hand.yaml").write_text(HAND_SPEC)
    (tmp_path / "meshes").mkdir(exist_ok=True)
    (tmp_path / "meshes" / "base.stl").write_text("solid base\nendsolid base\n")
    spec = tmp_path / name
    spec.write_text(composed)
    return spec


ARM_AND_HAND = """robotspec: 1
name: ArmWithHand
parts:
  arm: {spec: arm.yaml}
  hand:
    spec: hand.yaml
    prefix: hand_
    attach: {part: arm, link: flange, xyz: [0, 0, 0.02], replace_root: REPLACE}
"""


def _errors(exc: RobotSpecError) -> list[RobotSpecError]:
    return list(getattr(exc, "errors", (exc,)))


@pytest.mark.parametrize("replace", [False, True])
def test_small_composition_hands_over_and_matches_pinocchio(tmp_path: Path, replace: bool) -> None:
    spec = _fixture(tmp_path, ARM_AND_HAND.replace("REPLACE", str(replace).lower()))
    robot = compile_robot(spec)
    chain = robot.get_chain("arm")
    assert chain.manipulator is not None and chain.manipulator.name == "hand_gripper"
    assert chain.manipulator.tool_frame.name == "hand_tcp"
    assert [m.name for m in robot.manipulators] == ["hand_gripper"]
    assert robot.world.has_body("hand_palm") is not replace
    assert robot.world.has_connection("hand_weld") is not replace
    assert "hand_gripper.open" in robot.joint_states and "arm.up" in robot.joint_states
    # Relative mesh paths of a part are made absolute in the joined file.
    tree = joined_urdf(load_spec(spec))
    (mesh,) = tree.iter("mesh")
    assert mesh.get("filename") == str(tmp_path / "meshes" / "base.stl")
    # Materials of one name but two colours are kept apart.
    names = [m.get("name") for m in tree.iterfind("material")]
    assert names == ["paint", "hand_paint"]
    urdf = tmp_path / "joined.urdf"
    urdf.write_text(urdf_text(tree, comment="test"))
    q = np.array([0.4, -0.7, 0.02])
    theirs = _pin_poses(urdf, robot.world, q, "mount")
    kin = Kinematics(robot.world)
    for body, pose in theirs.items():
        np.testing.assert_allclose(kin.pose(q, body, relative_to="mount"), pose, atol=1e-12)


def test_replaced_root_keeps_the_mass_where_it_was(tmp_path: Path) -> None:
    """pinocchio merges a fixed link's inertia into its parent: replacing must give the same."""
    import pinocchio as pin

    inertias = []
    for replace in (False, True):
        spec = _fixture(tmp_path, ARM_AND_HAND.replace("REPLACE", str(replace).lower()))
        urdf = tmp_path / f"joined_{replace}.urdf"
        urdf.write_text(urdf_text(joined_urdf(load_spec(spec)), comment="test"))
        model = pin.buildModelFromUrdf(str(urdf))
        inertias.append(model.inertias[model.getJointId("wrist")])
    welded, replaced = inertias
    assert replaced.mass == pytest.approx(welded.mass) == pytest.approx(0.5)
    np.testing.assert_allclose(replaced.lever, welded.lever, atol=1e-12)
    np.testing.assert_allclose(replaced.inertia, welded.inertia, atol=1e-12)


def test_a_composed_spec_is_a_part_of_another(tmp_path: Path) -> None:
    _fixture(tmp_path, ARM_AND_HAND.replace("REPLACE", "false"), "arm_with_hand.yaml")
    spec = tmp_path / "two.yaml"
    spec.write_text(
        """robotspec: 1
name: TwoArms
parts:
  left: {spec: arm_with_hand.yaml, prefix: l_}
  right:
    spec: arm_with_hand.yaml
    prefix: r_
    attach: {part: left, link: mount, xyz: [0, -0.5, 0]}
"""
    )
    robot = compile_robot(spec)
    assert sorted(c.name for c in robot.kinematic_chains) == ["l_arm", "r_arm"]
    assert robot.get_chain("r_arm").manipulator.tool_frame.name == "r_hand_tcp"  # type: ignore[union-attr]
    assert "r_hand_gripper.open" in robot.joint_states


BAD = [
    # (what changes in the composed spec, expected messages)
    (
        "attach: {part: arm, link: flang}",
        ["link 'flang' not found in part 'arm' (arm.urdf); did you mean 'flange'?"],
    ),
    (
        "attach: {part: amr, link: flange}",
        ["part 'amr' not found in the spec's parts; did you mean 'arm'?"],
    ),
    (
        "prefix: ''\n    attach: {part: arm, link: flange}",
        ["part 'hand' and part 'arm' both have link 'finger'; give part 'hand' a (different)"],
    ),
]


@pytest.mark.parametrize(("hand", "messages"), BAD)
def test_bad_compositions_are_located_errors(
    tmp_path: Path, hand: str, messages: list[str]
) -> None:
    text = f"""robotspec: 1
name: Bad
parts:
  arm: {{spec: arm.yaml}}
  hand:
    spec: hand.yaml
    {hand}
"""
    if "both have" in messages[0]:
        # Make the clash real: the arm gets a link the hand also has.
        text = text.replace("arm.yaml", "arm2.yaml")
        (tmp_path / "arm.urdf").write_text(ARM_URDF)
    spec = _fixture(tmp_path, text)
    if "both have" in messages[0]:
        (tmp_path / "arm2.urdf").write_text(
            ARM_URDF.replace(
                '<link name="flange"/>', '<link name="flange"/><link name="finger"/>'
            ).replace(
                "</robot>",
                '<joint name="f" type="fixed"><parent link="flange"/>'
                '<child link="finger"/></joint></robot>',
            )
        )
        (tmp_path / "arm2.yaml").write_text(ARM_SPEC.replace("arm.urdf", "arm2.urdf"))
    with pytest.raises(RobotSpecError) as info:
        check_spec(spec)
    errors = _errors(info.value)
    assert len(errors) == len(messages)
    for err, msg in zip(errors, messages, strict=True):
        assert msg in err.message
        assert err.file == str(spec) and err.line is not None and err.line >= 5


def test_every_composition_error_of_a_spec_at_once(tmp_path: Path) -> None:
    spec = _fixture(
        tmp_path,
        """robotspec: 1
name: Bad
parts:
  arm: {spec: arm.yaml}
  hand: {spec: hand.yaml, attach: {part: grip, link: palm}}
  grip: {spec: hand.yaml, prefix: g_, attach: {part: hand, link: palm}}
  ghost: {urdf: ghost.urdf, attach: {part: arm, link: flange}}
  other: {spec: arm.yaml, prefix: o_}
""",
    )
    with pytest.raises(RobotSpecError) as info:
        check_spec(spec)
    text = [f"{e.line}: {e.message}" for e in _errors(info.value)]
    assert any(
        "8: parts.other: part 'other' has no 'attach', and neither has part 'arm'" in t
        for t in text
    )
    assert any(t.startswith("5: ") and "cycle: hand -> grip -> hand" in t for t in text), text
    assert any(t.startswith("7: ") and "ghost.urdf" in t and "file not found" in t for t in text)
    assert len(text) == 3, text  # the cycle once, not once per member


def test_xacro_arm_without_a_spec_composed_with_a_hand(tmp_path: Path) -> None:
    """The ROS-Industrial UR5e xacro (no robotspec spec exists for it) with its MoveIt SRDF."""
    from .conftest import shared_path

    erd_robots()
    ur = shared_path("robots", "ur5e")
    shipped = _spec_file("dual_panda").parent / "parts"
    spec = tmp_path / "ur5e_on_stand.yaml"
    spec.write_text(
        f"""robotspec: 1
name: UR5eOnStand
parts:
  stand: {{urdf: {shipped / "stand.urdf"}}}
  arm:
    urdf: {ur / "ur_description" / "urdf" / "ur5e.xacro"}
    srdf: {ur / "ur5e_moveit_config" / "config" / "ur5e.srdf"}
    package_paths: [{ur}]
    prefix: arm_
    attach: {{part: stand, link: torso_plate, xyz: [0, 0, 0.05], replace_root: true}}
  hand:
    spec: {shipped / "allegro_right_hand.yaml"}
    prefix: hand_
    attach: {{part: arm, link: tool0, xyz: [0, 0, 0.095]}}
chains:
  arm: {{group: arm_manipulator}}
"""
    )
    # The part's files and package folder lie outside the spec's project: refused until the
    # user allows their folder (the shipped parts need no leave).
    with pytest.raises(RobotSpecErrors) as info:
        check_spec(spec)
    assert [(d.line, d.kind) for d in info.value.details] == [
        (6, "URDF"),
        (7, "SRDF"),
        (8, "package path"),
    ]
    assert all("-P/--package-path" in d.message for d in info.value.details)
    result = check_spec(spec, package_paths=[ur])
    assert result.warnings == ()
    robot = result.robot
    assert robot is not None
    chain = robot.get_chain("arm")
    assert (chain.root.name, chain.tip.name) == ("torso_plate", "arm_tool0")
    assert chain.manipulator is not None and chain.manipulator.tool_frame.name == "hand_grasp_frame"
    assert robot.srdf is not None and "arm_manipulator" in robot.srdf.group_names
    # The UR5e's base link merged into the stand's plate, so its first body is adjacent to it.
    rules = CollisionRules.from_robot(robot)
    assert rules.why_disabled("torso_plate", "arm_base_link_inertia") == "Adjacent"
    assert rules.is_checked("stand_base", "hand_palm_link")
    urdf = tmp_path / "joined.urdf"
    urdf.write_text(urdf_text(joined_urdf(load_spec(spec), package_paths=[ur]), comment="test"))
    q = np.random.default_rng(11).uniform(-1.5, 1.5, len(robot.world.degrees_of_freedom))
    theirs = _pin_poses(urdf, robot.world, q, "stand_base")
    kin = Kinematics(robot.world)
    for body, pose in theirs.items():
        np.testing.assert_allclose(kin.pose(q, body, relative_to="stand_base"), pose, atol=1e-9)


# ------------------------------------------------------------------------------------ CLI
def test_cli_inspect_export_and_errors(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    import json

    from .test_cli import run

    erd_robots()
    code, out, _ = run(capsys, "inspect", "parts", "dual_panda", "--json")
    assert code == 0
    rows = json.loads(out)
    assert [(r["part"], r["prefix"], r["attached_to"], r["weld"]) for r in rows] == [
        ("stand", "", None, None),
        ("left", "left_", "stand/torso_plate", "left_weld"),
        ("right", "right_", "stand/torso_plate", "right_weld"),
    ]
    code, _, err = run(capsys, "inspect", "parts", "pr2")
    assert code == 1 and "not composed of parts" in err
    code, _, err = run(capsys, "export", "urdf", "dual_panda", "-o", str(tmp_path / "d.urdf"))
    assert code == 0 and "28 links, 27 joints" in err
    code, _, err = run(capsys, "export", "bundle", "dual_panda", "-o", str(tmp_path / "b"))
    assert code == 0
    code, out, _ = run(capsys, "validate", str(tmp_path / "b" / "dual_panda.yaml"))
    assert code == 0 and "1 of 1 spec valid; 0 errors, 0 warnings" in out
    bad = _fixture(
        tmp_path,
        "robotspec: 1\nname: Bad\nparts:\n  arm: {spec: arm.yaml}\n"
        "  hand: {spec: hand.yaml, attach: {part: arm, link: flang}}\n",
    )
    code, out, err = run(capsys, "validate", str(bad))
    assert code == 1
    assert f"{bad}:5:" in out + err and "did you mean 'flange'?" in out + err
    assert "Traceback" not in out + err


def test_extending_a_composed_spec_and_from_world(tmp_path: Path) -> None:
    from robotspec.robots import DualPanda

    erd_robots()
    child = tmp_path / "child.yaml"
    child.write_text(
        "robotspec: 1\nextends: dual_panda\nname: DualPandaLow\n"
        "parts:\n  left:\n    attach: {part: stand, link: torso_plate, xyz: [0, 0.4, 0.05]}\n"
    )
    robot = compile_robot(child)
    kin = Kinematics(robot.world)
    q = np.zeros(len(robot.world.degrees_of_freedom))
    assert kin.pose(q, "left_panda_link0", relative_to="torso_plate")[1, 3] == pytest.approx(0.4)
    assert robot.get_chain("left_arm").manipulator is not None
    loaded = DualPanda.load()
    again = DualPanda.from_world(loaded.world)
    assert again.world is loaded.world
    assert _summary(again) == _summary(loaded)


PART_FILES = ("arm.yaml", "hand.yaml", "arm.urdf", "hand.urdf")
LINKS = ("mount", "base_link", "flange", "palm", "tcp", "flang")


@st.composite
def compositions(draw: st.DrawFn) -> str:
    n = draw(st.integers(1, 4))
    names = [f"p{i}" for i in range(n)]
    lines = ["robotspec: 1", "name: Random", "parts:"]
    for i, name in enumerate(names):
        source = draw(st.sampled_from(PART_FILES))
        key = "spec" if source.endswith(".yaml") else "urdf"
        lines.append(f"  {name}:")
        lines.append(f"    {key}: {source}")
        lines.append(f"    prefix: '{draw(st.sampled_from(['', 'a_', 'b_', name + '_']))}'")
        if i > 0 or draw(st.booleans()):
            parent = draw(st.sampled_from([*names, "nowhere"]))
            link = draw(st.sampled_from(LINKS))
            replace = draw(st.booleans())
            lines.append(
                f"    attach: {{part: {parent}, link: {link}, xyz: [0, 0, 0.1], "
                f"replace_root: {str(replace).lower()}}}"
            )
    return "\n".join(lines) + "\n"


@settings(max_examples=60, deadline=None)
@given(text=compositions())
def test_random_compositions_compile_or_fail_cleanly(text: str) -> None:
    import shutil
    import tempfile

    folder = Path(tempfile.mkdtemp(prefix="compose-"))
    spec = _fixture(folder, text)
    try:
        result = check_spec(spec)
        loaded = load_spec(spec)
    except RobotSpecError as exc:
        for err in _errors(exc):
            assert err.file is not None and err.message
        return
    finally:
        shutil.rmtree(folder)
    robot = result.robot
    assert robot is not None
    replaced = sum(
        1 for p in loaded.spec.parts.values() if p.attach is not None and p.attach.replace_root
    )
    part_links = {"arm.yaml": 4, "arm.urdf": 4, "hand.yaml": 3, "hand.urdf": 3}
    expected = sum(part_links[p.spec or p.urdf or ""] for p in loaded.spec.parts.values())
    assert len(robot.world.bodies) == expected - replaced


def test_part_files_that_include_each_other(tmp_path: Path) -> None:
    _fixture(tmp_path, "")
    (tmp_path / "a.yaml").write_text(
        "robotspec: 1\nname: A\nparts:\n  arm: {spec: arm.yaml}\n"
        "  more: {spec: b.yaml, prefix: m_, attach: {part: arm, link: flange}}\n"
    )
    (tmp_path / "b.yaml").write_text("robotspec: 1\nname: B\nparts:\n  again: {spec: a.yaml}\n")
    with pytest.raises(RobotSpecError) as info:
        check_spec(tmp_path / "a.yaml")
    (err,) = _errors(info.value)
    assert "parts include each other: a.yaml -> b.yaml -> a.yaml" in err.message
    assert err.file == str(tmp_path / "b.yaml") and err.line == 4


XACRO_PART = """<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="tool">
  <xacro:arg name="length" default="0.1"/>
  <link name="tool_base"/>
  <link name="tool_tip"/>
  <joint name="tool_joint" type="fixed">
    <origin xyz="0 0 $(arg length)"/>
    <parent link="tool_base"/><child link="tool_tip"/>
  </joint>
</robot>
"""


def test_a_xacro_part_with_arguments(tmp_path: Path) -> None:
    _fixture(tmp_path, "")
    (tmp_path / "tool.urdf.xacro").write_text(XACRO_PART)
    spec = tmp_path / "tooled.yaml"
    spec.write_text(
        "robotspec: 1\nname: Tooled\nparts:\n  arm: {spec: arm.yaml}\n"
        "  tool:\n    urdf: tool.urdf.xacro\n    xacro_args: {length: '0.25'}\n"
        "    prefix: t_\n    attach: {part: arm, link: flange, replace_root: true}\n"
        "manipulators:\n  tool: {type: generic, root: flange, tool_frame: t_tool_tip}\n"
        "chains:\n  arm: {root: base_link, tip: flange, manipulator: tool}\n"
    )
    robot = compile_robot(spec)
    assert robot.get_chain("arm").manipulator.tool_frame.name == "t_tool_tip"  # type: ignore[union-attr]
    assert [m.name for m in robot.manipulators] == ["tool"]  # the flange was replaced
    q = np.zeros(len(robot.world.degrees_of_freedom))
    offset = Kinematics(robot.world).pose(q, "t_tool_tip", relative_to="flange")
    np.testing.assert_allclose(offset[:3, 3], [0, 0, 0.25], atol=1e-12)


def test_the_composed_spec_changes_a_parts_entry_key_by_key(tmp_path: Path) -> None:
    erd_robots()
    spec = tmp_path / "typo.yaml"
    spec.write_text(
        "robotspec: 1\nextends: b1_ur5_allegro\nname: Typo\nchains:\n"
        "  ur5_arm: {tip: ur5_wrist_3_lnk}\n"
        "  leg: {kind: chain, root: trunk, tip: FR_foott}\n"
    )
    with pytest.raises(RobotSpecError) as info:
        check_spec(spec)
    text = [f"{e.line}:{e.column}: {e.message}" for e in _errors(info.value)]
    assert text == [
        "5:18: link 'ur5_wrist_3_lnk' not found in typo.yaml (composed); did you mean "
        "'ur5_wrist_3_link', 'ur5_wrist_2_link' or 'ur5_wrist_1_link'?",
        "6:40: link 'FR_foott' not found in typo.yaml (composed); did you mean 'FR_foot', "
        "'RR_foot' or 'RL_foot'?",
    ]
    spec.write_text(spec.read_text().replace("lnk", "link").replace("foott", "foot"))
    robot = compile_robot(spec)
    arm = robot.get_chain("ur5_arm")
    assert arm.root.name == "ur5_base_link"  # kept from the UR5 part's chain
    assert "ur5_arm.home" in robot.joint_states


def test_one_package_name_in_two_parts_resolves_per_part(tmp_path: Path) -> None:
    """Two vendors' packages called 'tools': each part's meshes stay its own."""
    from robotspec.model.geometry import Mesh

    for vendor, mesh in (("a", "one.stl"), ("b", "two.stl")):
        pkg = tmp_path / vendor / "tools"
        (pkg / "meshes").mkdir(parents=True)
        (pkg / "package.xml").write_text("<package><name>tools</name></package>")
        (pkg / "meshes" / mesh).write_text("solid m\nendsolid m\n")
        (pkg / "robot.urdf").write_text(
            f'<robot name="{vendor}"><link name="{vendor}_link"><visual><geometry>'
            f'<mesh filename="package://tools/meshes/{mesh}"/></geometry></visual></link></robot>'
        )
    spec = tmp_path / "two.yaml"
    spec.write_text(
        "robotspec: 1\nname: Two\nparts:\n  a: {urdf: a/tools/robot.urdf}\n"
        "  b: {urdf: b/tools/robot.urdf, attach: {part: a, link: a_link}}\n"
    )
    result = check_spec(spec)
    assert result.warnings == ()
    w = result.robot.world
    paths = {}
    for name in ("a_link", "b_link"):
        (shape,) = w.get_body_by_name(name).visuals
        assert isinstance(shape.geometry, Mesh)
        paths[name] = shape.geometry.path
    assert paths == {
        "a_link": str((tmp_path / "a" / "tools" / "meshes" / "one.stl").resolve()),
        "b_link": str((tmp_path / "b" / "tools" / "meshes" / "two.stl").resolve()),
    }


def test_the_error_output_shown_in_the_docs_is_what_validate_prints(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from .test_cli import run
    from .test_docs import DOCS, blocks

    erd_robots()
    page = DOCS / "composition.md"
    found = list(blocks(page))
    spec = next(b for b in found if b.marks.get("file") == "broken.yaml")
    shown = next(b for b in found if b.lang == "text" and "broken.yaml:" in b.text)
    (tmp_path / "broken.yaml").write_text(spec.text)
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("NO_COLOR", "1")
    code, out, err = run(capsys, "validate", "broken.yaml")
    assert code == 1
    printed = (out + err).splitlines()
    assert sorted(printed) == sorted(shown.text.splitlines())


def test_a_composed_robot_renders_with_every_parts_meshes() -> None:
    from robotspec.render import RenderOptions, build_scene, render_scene

    erd_robots()
    robot = compile_robot("b1_ur5_allegro")
    scene = build_scene(robot)
    q = np.zeros(len(robot.world.degrees_of_freedom))
    from .test_render import _mask

    picture = render_scene(scene, q, RenderOptions(view="front", width=320, height=240))
    shown = {e.name: int(_mask(picture.image, e.colour).sum()) for e in scene.legend}
    assert shown["ur5_arm"] > 200 and shown["allegro_hand"] > 50, shown


@pytest.mark.parametrize("name", COMPOSED)
def test_pinocchio_reads_the_exported_urdf_and_srdf_to_the_same_checked_pairs(
    name: str, tmp_path: Path
) -> None:
    """What MoveIt-style tools load: pinocchio's geometry + SRDF pairs are robotspec's pairs.

    pinocchio never pairs geometries on one rigid body (bodies joined by fixed joints only);
    those pairs can never change, and are the only difference allowed.
    """
    import pinocchio as pin

    from robotspec.files.packages import PackageResolver

    erd_robots()
    result = check_spec(name)
    robot = result.robot
    assert robot is not None
    out = bundle(result, name=name)
    urdf, srdf = tmp_path / f"{name}.urdf", tmp_path / f"{name}.srdf"
    urdf.write_text(out.urdf)
    srdf.write_text(out.srdf)
    dirs = [str(p) for p in PackageResolver.create(None).search_folders]
    model = pin.buildModelFromUrdf(str(urdf))
    geom = pin.buildGeomFromUrdf(model, str(urdf), pin.GeometryType.COLLISION, package_dirs=dirs)
    geom.addAllCollisionPairs()
    pin.removeCollisionPairs(model, geom, str(srdf))

    def body(g: int) -> str:
        return str(model.frames[geom.geometryObjects[g].parentFrame].name)

    theirs = {frozenset((body(p.first), body(p.second))) for p in geom.collisionPairs}
    ours = {frozenset(p) for p in CollisionRules.from_robot(robot).active_pairs()}
    assert theirs <= ours
    w = robot.world
    for pair in ours - theirs:
        a, b = sorted(pair)
        top = w.common_ancestor(a, b)
        joints = [*w.compute_chain_of_connections(top, a), *w.compute_chain_of_connections(top, b)]
        assert all(c.is_fixed for c in joints), f"{a}-{b} moves yet pinocchio does not check it"


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (
            "extends: pr2\nparts:\n  arm: {spec: ur5}\n",
            "'pr2' has a description, so parts cannot be added to it; make it a part instead",
        ),
        ("parts:\n  arm: {spec: ur5, urdf: x.urdf}\n", "a part needs either 'spec' or 'urdf'"),
        (
            "parts:\n  arm: {spec: ur5}\n  hand: {spec: ur5, attach: {part: arm, lnk: tool0}}\n",
            "unknown key 'lnk' at parts.hand.attach.lnk; did you mean 'link'?",
        ),
        ("parts: {}\n", "a spec needs 'description' (its files) or 'parts'"),
    ],
)
def test_malformed_composed_specs(tmp_path: Path, text: str, message: str) -> None:
    spec = tmp_path / "bad.yaml"
    spec.write_text("robotspec: 1\nname: Bad\n" + text)
    with pytest.raises(RobotSpecError) as info:
        check_spec(spec)
    errors = _errors(info.value)
    assert any(message in e.message for e in errors), [e.message for e in errors]
    assert all(e.file == str(spec) and e.line is not None for e in errors)
