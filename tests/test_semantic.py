"""The seed API on the compiled PR2: every member the seed names exists and behaves.

The contract is ../shared/seeds/semantic-abstract-robot-overview.txt: robots and parts are views
over one world, each part belongs to one robot, chains derive their bodies and connections from
the world, and the robot answers controlled connections, drive, limits and collision questions.
"""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from robotspec.compiler import compile_robot, shipped_specs
from robotspec.errors import KinematicsError, NotFoundError
from robotspec.model.world import Connection, World
from robotspec.robots import PR2
from robotspec.semantic import (
    AbstractRobot,
    Arm,
    AssignmentError,
    Camera,
    CollisionCheckingConfig,
    EmptyChainWarning,
    FieldOfView,
    Finger,
    GenericManipulator,
    KinematicChain,
    Manipulator,
    Neck,
    ParallelGripper,
    SemanticRobotAnnotation,
    Sensor,
    Torso,
)
from tests.conftest import erd_robots


@pytest.fixture(scope="module")
def pr2() -> PR2:
    """A PR2 the tests only read."""
    erd_robots()
    return PR2.load()


@pytest.fixture
def fresh_pr2() -> PR2:
    """A PR2 (with its own world) a test may change."""
    erd_robots()
    return PR2.load()


def velocity(world: World, joint: str) -> float:
    c = world.get_connection_by_name(joint)
    return world.degrees_of_freedom[c.dofs[0]].velocity


# --------------------------------------------------------------------------- members
def test_robot_members(pr2: PR2) -> None:
    assert isinstance(pr2, AbstractRobot)
    assert pr2.root.name == "base_footprint"
    assert pr2._world is pr2.world
    assert isinstance(pr2.torso, Torso)
    assert isinstance(pr2.neck, Neck)
    assert all(isinstance(m, ParallelGripper) for m in pr2.manipulators)
    assert all(isinstance(s, Camera) for s in pr2.sensors)
    assert {c.name for c in pr2.manipulator_chains} == {"left_arm", "right_arm"}
    assert all(isinstance(c, Arm) and c.manipulator for c in pr2.manipulator_chains)
    assert pr2.sensor_chains == [pr2.neck]
    assert pr2.arms == pr2.manipulator_chains
    assert pr2.cameras == pr2.sensors
    # the robot's bodies: its branch of the world, not the drive's parent frame
    names = {b.name for b in pr2.bodies}
    assert "base_footprint" in names and "odom_combined" not in names
    assert pr2.kinematic_structure_entities == pr2.bodies
    assert pr2.drive not in pr2.connections
    assert "PR2" in repr(pr2)


def test_chain_views(pr2: PR2) -> None:
    arm = pr2.get_chain("left_arm")
    entities = arm.kinematic_structure_entities
    assert entities[0] is arm.root and entities[-1] is arm.tip
    assert arm.bodies == entities
    assert arm.regions == []  # robotspec's world has bodies only
    # the world's chain, element for element
    w = pr2.world
    assert entities == w.compute_chain_of_kinematic_structure_entities(arm.root, arm.tip)
    assert arm.connections == w.compute_chain_of_connections(arm.root, arm.tip)
    for parent, child, conn in zip(entities[:-1], entities[1:], arm.connections, strict=True):
        assert (conn.parent, conn.child) == (parent.index, child.index)
    assert [c.name for c in arm.active_connections] == [
        c.name for c in arm.connections if not c.is_fixed
    ]
    assert len(arm.degrees_of_freedom) == 7
    with pytest.raises(NotFoundError, match="did you mean 'left_arm'"):
        pr2.get_chain("left_amr")


def test_manipulator_and_camera_members(pr2: PR2) -> None:
    g = pr2.manipulators[0]
    assert isinstance(g, Manipulator) and isinstance(g, ParallelGripper)
    assert isinstance(g.finger, Finger) and isinstance(g.thumb, Finger)
    assert g.finger is not g.thumb
    assert pr2.world.is_ancestor(g.root, g.tool_frame)
    assert len(g.front_facing_orientation) == 4 and len(g.front_facing_axis) == 3
    cam = pr2.sensors[0]
    assert isinstance(cam, Sensor) and isinstance(cam, Camera)
    assert isinstance(cam.field_of_view, FieldOfView)
    assert 0 < cam.field_of_view.vertical_angle < cam.field_of_view.horizontal_angle < math.pi
    assert cam.minimal_height <= cam.maximal_height


def test_controlled_connections_default_and_override(pr2: PR2, tmp_path: Path) -> None:
    assert pr2.controlled_connections
    assert all(c.is_active and not c.is_mimic for c in pr2.controlled_connections)
    spec = tmp_path / "arm_only.yaml"
    spec.write_text(
        f"extends: {shipped_specs()['pr2']}\nname: arm_only\n"
        "controlled_joints: [l_shoulder_pan_joint, l_elbow_flex_joint]\n"
    )
    robot = compile_robot(spec)
    assert [c.name for c in robot.controlled_connections] == [
        "l_shoulder_pan_joint",
        "l_elbow_flex_joint",
    ]


def test_drive(pr2: PR2) -> None:
    drive = pr2.drive
    assert isinstance(drive, Connection)
    assert pr2.world.bodies[drive.child] is pr2.root
    assert pr2.world.parent_connection(pr2.root) is drive


def test_default_collision_config(pr2: PR2) -> None:
    assert pr2.default_collision_config == CollisionCheckingConfig(
        buffer_zone_distance=0.05, violated_distance=0.0, disabled=False, max_avoided_bodies=1
    )


# --------------------------------------------------------------------------- limits
def test_tighten_velocity_limits_only_tightens(fresh_pr2: PR2) -> None:
    robot, w = fresh_pr2, fresh_pr2.world
    before_pan = velocity(w, "head_pan_joint")  # 1.0 after the spec's default cap
    before_tilt = velocity(w, "head_tilt_joint")
    conn = w.get_connection_by_name("head_pan_joint")
    robot.tighten_dof_velocity_limits_of_1dof_connections({conn: 0.4, "head_tilt_joint": 99.0})
    assert velocity(w, "head_pan_joint") == 0.4 < before_pan
    assert velocity(w, "head_tilt_joint") == before_tilt  # a looser value changes nothing
    robot.tighten_dof_velocity_limits_of_1dof_connections({"head_pan_joint": 0.8})
    assert velocity(w, "head_pan_joint") == 0.4


def test_tighten_velocity_limits_refuses_bad_input(fresh_pr2: PR2) -> None:
    robot = fresh_pr2
    drive = robot.drive
    assert drive is not None
    with pytest.raises(NotFoundError, match="not found in robot 'PR2'"):
        robot.tighten_dof_velocity_limits_of_1dof_connections({"l_gripper_tool_joint": 0.1})
    with pytest.raises(NotFoundError):  # the drive is not one of the robot's 1-DOF joints
        robot.tighten_dof_velocity_limits_of_1dof_connections({drive: 0.1})
    with pytest.raises(
        KinematicsError,
        match="'l_gripper_r_finger_joint' is a mimic joint of 'l_gripper_l_finger_joint'",
    ):
        robot.tighten_dof_velocity_limits_of_1dof_connections({"l_gripper_r_finger_joint": 0.1})
    for bad in (0.0, -1.0, math.nan, math.inf):
        with pytest.raises(KinematicsError):
            robot.tighten_dof_velocity_limits_of_1dof_connections({"head_pan_joint": bad})
    assert velocity(robot.world, "head_pan_joint") == 1.0


# --------------------------------------------------------------------------- SRDF
def test_load_srdf_keeps_pairs_with_geometry_only(fresh_pr2: PR2, tmp_path: Path) -> None:
    robot, w = fresh_pr2, fresh_pr2.world
    with_geom = ["base_link", "l_upper_arm_link", "r_upper_arm_link"]
    without = "l_gripper_tool_frame"
    assert all(w.get_body_by_name(n).has_collision for n in with_geom)
    assert not w.get_body_by_name(without).has_collision
    srdf = tmp_path / "pr2.srdf"
    srdf.write_text(
        '<robot name="pr2">\n'
        '  <disable_collisions link1="base_link" link2="l_upper_arm_link" reason="Never"/>\n'
        f'  <disable_collisions link1="base_link" link2="{without}" reason="Never"/>\n'
        '  <disable_default_collisions link="r_upper_arm_link"/>\n'
        "</robot>\n"
    )
    robot.disabled_collision_pairs.clear()
    robot.disabled_collision_bodies.clear()
    robot.load_srdf(srdf)
    assert robot.disabled_collision_pairs == {frozenset(("base_link", "l_upper_arm_link"))}
    assert robot.disabled_collision_bodies == {"r_upper_arm_link"}
    enabled = {b.name for b in robot.bodies_with_enabled_collision}
    assert "r_upper_arm_link" not in enabled and "l_upper_arm_link" in enabled
    # without a path: the spec's own SRDF, applied at compile time already
    robot.load_srdf()
    assert len(robot.disabled_collision_pairs) > 1


def test_srdf_applied_at_compile_time(pr2: PR2) -> None:
    assert pr2.srdf is not None
    geom = {b.name for b in pr2.bodies_with_collisions}
    expected = {
        p
        for p in (frozenset((d.link1, d.link2)) for d in pr2.srdf.disabled_collisions)
        if p <= geom
    }
    assert pr2.disabled_collision_pairs == expected


# --------------------------------------------------------------------------- assembly
def test_every_part_is_registered_in_the_world(pr2: PR2) -> None:
    registered = pr2.world.semantic_annotations
    parts: list[SemanticRobotAnnotation] = [
        *pr2.all_chains,
        *pr2.manipulators,
        *pr2.sensors,
    ]
    for m in pr2.manipulators:
        assert isinstance(m, ParallelGripper)
        parts += [m.finger, m.thumb]
    for part in parts:
        assert any(a is part for a in registered), part
    assert pr2.world.get_semantic_annotations_by_type(Camera) == pr2.sensors
    for part in [*pr2.all_chains, *pr2.manipulators, *pr2.sensors]:
        assert part.robot is pr2


def test_a_part_belongs_to_one_robot(fresh_pr2: PR2) -> None:
    pr2, w = fresh_pr2, fresh_pr2.world
    other = AbstractRobot(name="other", root=pr2.root, world=w)
    gripper = pr2.manipulators[0]
    gripper.assign_to_robot(pr2)  # idempotent for its own robot
    pr2.add_manipulator(gripper)
    assert pr2.manipulators.count(gripper) == 1
    with pytest.raises(AssignmentError, match="already belongs to robot 'PR2'"):
        other.add_manipulator(gripper)
    with pytest.raises(ValueError):  # the reference's exception type still works
        pr2.sensors[0].assign_to_robot(other)
    with pytest.raises(AssignmentError):
        other.add_kinematic_chain(pr2.get_chain("left_arm"))
    assert gripper.robot is pr2


def test_add_parts_to_a_new_robot(fresh_pr2: PR2) -> None:
    w = fresh_pr2.world
    body = w.get_body_by_name
    robot = AbstractRobot(name="mini", root=body("base_footprint"), world=w)
    torso = Torso(name="t", root=body("base_link"), world=w, tip=body("torso_lift_link"))
    robot.add_torso(torso)
    robot.add_torso(torso)  # the same torso again is fine
    with pytest.raises(AssignmentError, match="already has torso"):
        robot.add_torso(Torso(name="t2", root=body("base_link"), world=w, tip=body("base_link")))
    tool = GenericManipulator(
        name="tool",
        root=body("r_gripper_palm_link"),
        world=w,
        tool_frame=body("r_gripper_tool_frame"),
    )
    cam = Camera(name="cam", root=body("r_forearm_cam_optical_frame"), world=w)
    arm = Arm(
        name="arm",
        root=body("torso_lift_link"),
        world=w,
        tip=body("r_wrist_roll_link"),
        manipulator=tool,
        sensors=[cam],
    )
    robot.add_kinematic_chain(arm)
    # the chain brings its manipulator and sensor, and is filed under both perspectives
    assert robot.manipulators == [tool] and robot.sensors == [cam]
    assert robot.manipulator_chains == [arm] and robot.sensor_chains == [arm]
    assert tool.robot is robot and cam.robot is robot and torso.robot is robot
    for part in (torso, tool, cam, arm):
        assert any(a is part for a in w.semantic_annotations)
    lift = KinematicChain(name="lift", root=body("base_link"), world=w, tip=body("torso_lift_link"))
    with pytest.warns(EmptyChainWarning, match="neither a manipulator nor a sensor"):
        robot.add_kinematic_chain(lift)
    assert lift in robot.kinematic_chains
    assert lift not in robot.manipulator_chains and lift not in robot.sensor_chains


def test_neck_is_a_sensor_chain(fresh_pr2: PR2) -> None:
    w = fresh_pr2.world
    body = w.get_body_by_name
    robot = AbstractRobot(name="head_only", root=body("base_footprint"), world=w)
    cam = Camera(name="c", root=body("wide_stereo_optical_frame"), world=w)
    neck = Neck(
        name="n",
        root=body("torso_lift_link"),
        world=w,
        tip=body("head_tilt_link"),
        sensors=[cam],
        yaw_body=body("head_pan_link"),
    )
    robot.add_neck(neck)
    assert robot.neck is neck and robot.sensor_chains == [neck] and robot.sensors == [cam]
    with pytest.raises(AssignmentError, match="already has neck"):
        robot.add_neck(
            Neck(
                name="n2",
                root=body("head_pan_link"),
                world=w,
                tip=body("head_tilt_link"),
                sensors=[cam],
            )
        )


# --------------------------------------------------------------------------- views
def test_semantic_objects_are_views_over_the_world(fresh_pr2: PR2) -> None:
    robot, w = fresh_pr2, fresh_pr2.world
    arm = robot.get_chain("right_arm")
    assert all(part.world is w for part in [*robot.all_chains, *robot.manipulators])
    dof = next(d for d in arm.degrees_of_freedom if d.connection == "r_elbow_flex_joint")
    assert dof.velocity == 1.0
    w.tighten_velocity_limits({dof.name: 0.25})  # changed in the world ...
    after = next(d for d in arm.degrees_of_freedom if d.connection == "r_elbow_flex_joint")
    assert after.velocity == 0.25  # ... shows through the chain
    assert velocity(robot.world, "r_elbow_flex_joint") == 0.25


def test_from_world_needs_a_spec(pr2: PR2) -> None:
    with pytest.raises(TypeError, match="has no spec"):
        AbstractRobot.from_world(pr2.world)
