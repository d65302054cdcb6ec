"""Robots composed from parts: joined trees against pinocchio, semantics, round trips, errors."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from robotspec.collision import CollisionRules
from robotspec.compiler import check_spec, compile_robot
from robotspec.description_export import bundle, joined_urdf, urdf_text
from robotspec.errors import RobotSpecError
from robotspec.kinematics import Kinematics
from robotspec.semantic import AbstractRobot
from robotspec.spec import load_spec
from robotspec.srdf import write_srdf
from robotspec.srdf_export import srdf_from_robot
from robotspec.world import World

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
    from robotspec.spec import shipped_spec_files

    return shipped_spec_files()[name]


def test_semantics_survive_composition() -> None:
    erd_robots()
    mobile = compile_robot("b1_ur5_allegro")
    arm = mobile.get_chain("ur5_arm")
    # The hand's manipulator, prefixed, is the arm chain's; its tool frame is the hand's frame.
    assert arm.manipulator is not None and arm.manipulator.name == "allegro_hand"
    assert arm.manipulator.tool_frame.name == "allegro_grasp_frame"
    assert mobile.world.is_ancestor(arm.tip, arm.manipulator.tool_frame)
    hand_alone = compile_robot(_spec_file("b1_ur5_allegro").parent / "parts" / "allegro_right_hand.yaml")
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
