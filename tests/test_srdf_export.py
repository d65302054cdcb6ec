"""The SRDF written from a compiled robot: names valid, semantics kept, read by pinocchio too.

MoveIt's own parser (srdfdom, C++) is on neither PyPI nor Debian here; pinocchio's SRDF reader
(C++, independent of ours) stands in as the second opinion, beside MoveIt's structural rules.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from robotspec.cli.app import app
from robotspec.cli.output import run_app
from robotspec.compiler import check_spec
from robotspec.description.srdf import Srdf
from robotspec.description.srdf_checks import check_srdf_against, check_srdf_references
from robotspec.description.srdf_reader import parse_srdf_bytes
from robotspec.export.srdf import srdf_from_robot, write_srdf
from robotspec.semantic import AbstractRobot

from .conftest import erd_robots, shared_path


def _export(robot: AbstractRobot) -> tuple[Srdf, str]:
    text = write_srdf(srdf_from_robot(robot))
    return parse_srdf_bytes(text.encode(), file="exported.srdf"), text


def _moveit_rules(srdf: Srdf, robot: AbstractRobot) -> None:
    """What MoveIt's SRDF loader insists on, checked by hand."""
    w = robot.world
    names = [g.name for g in srdf.groups]
    assert len(names) == len(set(names))
    groups = {g.name: g for g in srdf.groups}
    for ee in srdf.end_effectors:
        assert ee.group in groups and ee.group != ee.parent_group
        assert w.has_body(ee.parent_link)
        if ee.parent_group is not None:
            # The parent link is the tip of the parent group's chain.
            assert groups[ee.parent_group].chains[-1].tip_link == ee.parent_link
    for state in srdf.group_states:
        assert state.group in groups
    assert srdf.robot_name == w.name  # MoveIt matches SRDF and URDF by robot name
    assert not check_srdf_references(srdf)
    joints = [*w.connection_names, *(v.name for v in srdf.virtual_joints)]
    assert check_srdf_against(srdf, w.body_names, joints, urdf_name="urdf") == []


def test_pr2_export_keeps_chains_states_and_collisions() -> None:
    erd_robots()
    robot = check_spec("pr2").robot
    srdf, _ = _export(robot)
    _moveit_rules(srdf, robot)
    groups = {g.name: g for g in srdf.groups}
    assert [(c.base_link, c.tip_link) for c in groups["right_arm"].chains] == [
        ("torso_lift_link", "r_wrist_roll_link")
    ]
    ees = {e.group: e for e in srdf.end_effectors}
    assert ees["right_gripper"].parent_link == "r_wrist_roll_link"
    assert ees["right_gripper"].parent_group == "right_arm"
    assert "r_gripper_tool_frame" in groups["right_gripper"].links
    (vj,) = srdf.virtual_joints
    assert (vj.type, vj.child_link) == ("planar", "base_footprint")
    states = {(s.group, s.name): dict(s.joint_values) for s in srdf.group_states}
    assert states[("torso", "high")] == {"torso_lift_joint": (0.3,)}
    assert states[("right_gripper", "open")] == {"r_gripper_l_finger_joint": (0.548,)}
    # Every disabled pair of the compiled robot, with the shipped SRDF's reason kept.
    assert srdf.disabled_pairs() == frozenset(robot.disabled_collision_pairs)
    shipped = {frozenset((d.link1, d.link2)): d.reason for d in robot.srdf.disabled_collisions}  # type: ignore[union-attr]
    for d in srdf.disabled_collisions:
        assert d.reason == (shipped[frozenset((d.link1, d.link2))] or "User")


def _pairs(geom: object) -> set[tuple[str, str]]:
    objs = geom.geometryObjects  # type: ignore[attr-defined]
    return {
        tuple(sorted((objs[p.first].name, objs[p.second].name)))  # type: ignore[misc]
        for p in geom.collisionPairs  # type: ignore[attr-defined]
    }


def test_pr2_export_read_by_pinocchio(tmp_path: pytest.TempPathFactory) -> None:
    pin = pytest.importorskip("pinocchio")
    robots = erd_robots()
    robot = check_spec("pr2").robot
    _, text = _export(robot)
    urdf = str(robots / "pr2_description/urdf/pr2.urdf")
    model = pin.buildModelFromUrdf(urdf)
    geom = pin.buildGeomFromUrdf(
        model, urdf, pin.GeometryType.COLLISION, package_dirs=[str(robots.parent.parent)]
    )

    def removed_by(srdf_text: str) -> set[tuple[str, str]]:
        geom.addAllCollisionPairs()
        everything = _pairs(geom)
        pin.removeCollisionPairsFromXML(model, geom, srdf_text, False)
        return everything - _pairs(geom)

    shipped_text = (robots / "pr2_description/srdf/pr2.srdf").read_text()
    # The export keeps exactly the pairs of the shipped SRDF that have geometry on both sides,
    # so pinocchio removes the same geometry pairs with either file.
    assert removed_by(text) == removed_by(shipped_text)
    assert len(removed_by(text)) > 200
    pin.loadReferenceConfigurationsFromXML(model, text, False)
    assert all(n in model.referenceConfigurations for n in ("park", "high", "open"))
    q = model.referenceConfigurations["high"]
    idx = model.joints[model.getJointId("torso_lift_joint")].idx_q
    assert q[idx] == pytest.approx(0.3)
    assert np.isfinite(q).all()


def test_hsrb_export_is_valid() -> None:
    hsrb = shared_path("robots", "hsrb")
    robot = check_spec("hsrb", package_paths=[hsrb]).robot
    srdf, _ = _export(robot)
    _moveit_rules(srdf, robot)
    # HSRB's passive joints (casters, springs) survive; the stale odom_* names do not.
    assert {p.name for p in srdf.passive_joints} == {p.name for p in robot.srdf.passive_joints}  # type: ignore[union-attr]
    assert not any("odom_" in j for g in srdf.groups for j in g.joints)


@pytest.mark.parametrize("name", ["tiago", "panda", "ur5"])
def test_other_shipped_robots_export(name: str) -> None:
    erd_robots()
    robot = check_spec(name).robot
    srdf, _ = _export(robot)
    _moveit_rules(srdf, robot)
    assert any(g.chains for g in srdf.groups)


def test_cli_export_srdf_round_trips_through_init(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    # spec -> SRDF (export) -> spec (init) -> the same arms and grippers.
    robots = erd_robots()
    out = tmp_path / "pr2_out.srdf"
    assert run_app(app, ["export", "srdf", "pr2", "-o", str(out)]) == 0
    err = capsys.readouterr().err
    assert err == (f"wrote {out}: 6 groups, 2 end effectors, 9 group states, 257 disabled pairs\n")
    draft = tmp_path / "again.yaml"
    urdf = robots / "pr2_description/urdf/pr2.urdf"
    assert run_app(app, ["init", str(urdf), "--srdf", str(out), "-o", str(draft)]) == 0
    again = check_spec(draft).robot
    arms = {c.name: (c.root.name, c.tip.name, c.manipulator) for c in again.kinematic_chains}
    assert arms["right_arm"][:2] == ("torso_lift_link", "r_wrist_roll_link")
    assert arms["right_arm"][2] is not None
    assert arms["right_arm"][2].tool_frame.name == "r_gripper_tool_frame"
