"""Torso and drive of a draft (issue 30), each rule on a small layout of its shape."""

from __future__ import annotations

from pathlib import Path

from robotspec.compiler import check_spec
from robotspec.spec.draft import render_draft
from robotspec.spec.draft.run import draft_from_files
from tests.draft_support import draft_layout as _draft

_BOX = '<collision><geometry><box size="0.05 0.05 0.05"/></geometry></collision>'


def _link(name: str) -> str:
    return f'<link name="{name}">{_BOX}</link>'


def _joint(name: str, parent: str, child: str, xyz: str, axis: str = "0 1 0") -> str:
    return (
        f'<joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="{xyz}"/><axis xyz="{axis}"/>'
        '<limit lower="-2" upper="2" effort="1" velocity="1"/></joint>'
    )


def _limb(side: str, parent: str, names: list[str], start: str, step: str) -> list[str]:
    parts, above = [], parent
    for i, n in enumerate(names):
        link = f"{side}_{n}_link"
        axis = ("0 1 0", "1 0 0", "0 0 1")[i % 3]
        parts += [_link(link), _joint(f"{side}_{n}", above, link, start if i == 0 else step, axis)]
        above = link
    return parts


def test_a_humanoid_rooted_at_its_trunk_has_its_waist_as_torso(tmp_path: Path) -> None:
    # Booster T1's shape: arms branch at the root (the trunk), the legs below a waist joint.
    parts = [
        _link("trunk"),
        _link("waist"),
        _joint("waist_yaw", "trunk", "waist", "0 0 -0.2", "0 0 1"),
    ]
    arm = ["shoulder_pitch", "shoulder_roll", "elbow_pitch", "elbow_yaw"]
    leg = ["hip_pitch", "hip_roll", "hip_yaw", "knee", "ankle_pitch", "ankle_roll"]
    for side, y in (("left", "0.15"), ("right", "-0.15")):
        parts += _limb(f"{side}_arm", "trunk", arm, f"0 {y} 0.1", "0 0 -0.15")
        parts += _limb(f"{side}_leg", "waist", leg, f"0 {float(y) / 2} -0.1", "0 0 -0.15")
    d = _draft(tmp_path, "trunk_rooted", parts)
    assert sorted(c.role for c in d.chains) == ["arm", "arm", "leg", "leg"]
    assert d.torso is not None
    assert (d.torso.root, d.torso.tip, d.torso.joints) == ("trunk", "waist", {"waist_yaw"})
    assert d.torso.decide  # a guess from the tree: the person checks it


def _gripper_arm() -> list[str]:
    """A 6-joint arm, a flange, a hand with two sliding fingers, and a bare frame on the hand."""
    parts = [_link("base")]
    parts += _limb("arm", "base", [f"j{i}" for i in range(1, 7)], "0 0 0.1", "0 0 0.15")
    parts += [_link("flange"), _fixed("flange_joint", "arm_j6_link", "flange", "0 0 0.05")]
    parts += [_link("hand"), _fixed("hand_mount", "flange", "hand", "0 0 0.01")]
    for side, y in (("left", "0.03"), ("right", "-0.03")):
        parts += [
            _link(f"{side}_finger"),
            f'<joint name="{side}_finger_joint" type="prismatic"><parent link="hand"/>'
            f'<child link="{side}_finger"/><origin xyz="0 {y} 0.06"/><axis xyz="0 1 0"/>'
            '<limit lower="0" upper="0.04" effort="1" velocity="1"/></joint>',
        ]
    parts += ['<link name="grip_point"/>', _fixed("grip", "hand", "grip_point", "0 0 0.07")]
    return parts


def _fixed(name: str, parent: str, child: str, xyz: str) -> str:
    return (
        f'<joint name="{name}" type="fixed"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="{xyz}"/></joint>'
    )


def test_the_srdf_end_effector_parent_link_is_the_tool_frame(tmp_path: Path) -> None:
    # MoveIt's <end_effector parent_link=...>: a bare frame on the hand is the TCP, a fact.
    urdf = tmp_path / "arm.urdf"
    urdf.write_text('<robot name="arm">' + "".join(_gripper_arm()) + "</robot>")
    srdf = tmp_path / "arm.srdf"
    srdf.write_text(
        '<robot name="arm"><group name="manipulator"><chain base_link="base"'
        ' tip_link="arm_j6_link"/></group>'
        '<group name="gripper"><joint name="left_finger_joint"/>'
        '<joint name="right_finger_joint"/></group>'
        '<end_effector name="gripper" parent_link="grip_point" group="gripper"'
        ' parent_group="manipulator"/></robot>'
    )
    draft, _ = draft_from_files(str(urdf), str(srdf), folder=tmp_path, base_folder=tmp_path)
    spec = tmp_path / "arm.yaml"
    spec.write_text(render_draft(draft))
    assert check_spec(spec).robot is not None
    (chain,) = draft.chains
    assert chain.tip == "flange"  # past the group's tip, to the link the hand is met on
    (m,) = draft.manipulators
    assert (m.name, m.tool_frame) == ("gripper", "grip_point")
    assert not any("tool frame" in q for q in m.decide)  # stated by the SRDF: no question


def _wheel(name: str, parent: str, xyz: str) -> list[str]:
    cylinder = (
        '<collision><origin rpy="1.5708 0 0"/><geometry><cylinder radius="0.06" length="0.03"/>'
        "</geometry></collision>"
    )
    return [f'<link name="{name}">{cylinder}</link>', _fixed(f"{name}_joint", parent, name, xyz)]


def test_a_quadrotor_with_propellers_on_fixed_joints_floats(tmp_path: Path) -> None:
    # Crazyflie's shape in a simulator's URDF: four propeller links, nothing moves.
    parts = [_link("base_link")]
    for i, xyz in enumerate(("0.03 -0.03 0", "-0.03 -0.03 0", "-0.03 0.03 0", "0.03 0.03 0")):
        parts += [
            _link(f"prop{i}_link"),
            _fixed(f"prop{i}_joint", "base_link", f"prop{i}_link", xyz),
        ]
    d = _draft(tmp_path, "quadrotor", parts)
    assert d.drive is not None and d.drive.type == "floating" and d.drive.decide


def test_base_joints_over_two_wheels_on_fixed_joints_are_differential(tmp_path: Path) -> None:
    # ManiSkill's Fetch: x, y, theta joints move the base; its two wheels are on fixed joints.
    parts = ['<link name="root"/><link name="x_link"/><link name="y_link"/>', _link("base_link")]
    for name, parent, child, kind, axis in (
        ("root_x_axis_joint", "root", "x_link", "prismatic", "1 0 0"),
        ("root_y_axis_joint", "x_link", "y_link", "prismatic", "0 1 0"),
        ("root_z_rotation_joint", "y_link", "base_link", "continuous", "0 0 1"),
    ):
        parts.append(
            f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
            f'<axis xyz="{axis}"/><limit lower="-10" upper="10" effort="1" velocity="1"/></joint>'
        )
    parts += _wheel("l_wheel_link", "base_link", "0 0.19 0.05")
    parts += _wheel("r_wheel_link", "base_link", "0 -0.19 0.05")
    d = _draft(tmp_path, "planar_base", parts)
    assert d.drive is not None and d.drive.type == "differential"
    assert "2 wheels on fixed joints" in d.drive.decide
    # Four wheels on fixed joints and no moving base (Neobotix MPO-500): the file models the
    # wheels for their look only, the robot still drives on them: omni, asked.
    still = [_link("base_link")]
    for i, xyz in enumerate(("0.2 0.2 0", "0.2 -0.2 0", "-0.2 0.2 0", "-0.2 -0.2 0")):
        still += _wheel(f"wheel_{i}_link", "base_link", xyz)
    d = _draft(tmp_path, "wheels_held", still)
    assert d.drive is not None and d.drive.type == "omni" and "4 wheels" in d.drive.decide
