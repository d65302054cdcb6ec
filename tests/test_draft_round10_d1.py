"""Chains, grippers, torso and drive read from the files' structure (issue 30, round 10).

Small layouts built here, one shape each (no robot's files, no robot's name): an arm on a
chassis whose fixed layers carry a finger's word, a one-jaw gripper named as a gripper swinging
against the forearm's own shape, SRDF groups that are parts of the torso, two wheels under an
SRDF planar virtual joint, a linkage finger whose rod hangs below its pad.
"""

from __future__ import annotations

from pathlib import Path

from tests.draft_support import draft_layout
from tests.test_draft_blind import _WHEEL, _draft_srdf, _joint, _link


def _box(size: str, xyz: str = "0 0 0") -> str:
    """A collision box of ``size`` centred at ``xyz`` of its link."""
    return f'<collision><origin xyz="{xyz}"/><geometry><box size="{size}"/></geometry></collision>'


def _arm_on(parent: str, prefix: str = "", joints: int = 4, xyz: str = "0 0 0.2") -> list[str]:
    """A ``joints``-joint arm of 20 cm links from ``parent``; its last link is PREFIX+'link{n}'."""
    parts: list[str] = []
    above = parent
    for i in range(1, joints + 1):
        child = f"{prefix}link{i}"
        axis = "0 0 1" if i % 2 else "0 1 0"
        parts += [
            _link(child, size=0.04),
            _joint(f"{prefix}j{i}", above, child, xyz=xyz if i == 1 else "0 0 0.2", axis=axis),
        ]
        above = child
    return parts


def test_links_above_an_arms_first_joint_are_never_a_fingers(tmp_path: Path) -> None:
    # A chassis built of fixed layers, one named 'middle' (a finger's word in a hand): the arm
    # standing on them is still an arm; only links its joints move could be a finger's.
    parts = [
        _link("base", size=0.3),
        _link("base_middle", size=0.3),
        _joint("base_to_middle", "base", "base_middle", "fixed", "0 0 0.2"),
        _link("base_top", size=0.3),
        _joint("middle_to_top", "base_middle", "base_top", "fixed", "0 0 0.2"),
        *_arm_on("base_top"),
    ]
    d = draft_layout(tmp_path, "robot", parts)
    (arm,) = d.chains
    assert arm.role == "arm" and arm.joints == frozenset({"j1", "j2", "j3", "j4"})


def _one_jaw(axis: str, swing: tuple[float, float]) -> list[str]:
    """A 4-joint arm whose forearm's shape runs 14 cm on past a 'gripper' hinged 9 cm out.

    The gripper is a single 5 cm jaw on a revolute joint about ``axis``, within ``swing``.
    """
    parts = [_link("base", size=0.1), *_arm_on("base", joints=3)]
    parts += [
        f'<link name="forearm">{_box("0.03 0.03 0.14", "0 0 0.07")}</link>',
        _joint("elbow_yaw", "link3", "forearm", xyz="0 0 0.2", axis="0 0 1"),
        f'<link name="gripper">{_box("0.01 0.01 0.05", "0 0 0.025")}</link>',
        (
            '<joint name="gripper_joint" type="revolute"><parent link="forearm"/>'
            f'<child link="gripper"/><origin xyz="0.02 0 0.09"/><axis xyz="{axis}"/>'
            f'<limit lower="{swing[0]}" upper="{swing[1]}" effort="1" velocity="1"/></joint>'
        ),
    ]
    return parts


def test_a_gripper_link_swinging_against_the_forearms_shape_is_its_one_jaw(
    tmp_path: Path,
) -> None:
    # A hobby servo's +-120 degrees about an axis across the hinge's offset, the forearm's
    # own shape reaching 5 cm past the hinge (the fixed jaw): the joint is the gripper's.
    d = draft_layout(tmp_path, "robot", _one_jaw("1 0 0", (-2.09, 2.09)))
    (arm,) = d.chains
    assert arm.tip == "forearm" and "gripper_joint" not in arm.joints
    assert arm.joints == frozenset({"j1", "j2", "j3", "elbow_yaw"})


def test_a_gripper_link_rolled_about_its_offset_is_turned_by_the_arm(tmp_path: Path) -> None:
    # The same shapes, the joint turning about the way the link is hung out (a wrist roll):
    # the arm's last joint, whatever the link is named.
    d = draft_layout(tmp_path, "robot", _one_jaw("0.2169 0 0.9762", (-2.09, 2.09)))
    (arm,) = d.chains
    assert "gripper_joint" in arm.joints


def _lifted_torso() -> list[str]:
    """A base, a 2-joint lift, a 2-joint waist up to 'body', two 4-joint arms from 'body'."""
    parts = [
        _link("base", size=0.3),
        _link("lift1", size=0.1),
        _joint("lift1_joint", "base", "lift1", "prismatic", "0 0 0.2", "0 0 1"),
        _link("lift2", size=0.1),
        _joint("lift2_joint", "lift1", "lift2", "prismatic", "0 0 0.2", "0 0 1"),
        _link("waist", size=0.1),
        _joint("waist_yaw", "lift2", "waist", xyz="0 0 0.2", axis="0 0 1"),
        _link("body", size=0.2),
        _joint("waist_pitch", "waist", "body", xyz="0 0 0.1", axis="0 1 0"),
        *_arm_on("body", "l_", xyz="0 0.2 0.1"),
        *_arm_on("body", "r_", xyz="0 -0.2 0.1"),
    ]
    return parts


def test_srdf_groups_of_the_lift_and_the_waist_are_the_torsos_parts(tmp_path: Path) -> None:
    # The SRDF groups the lift and the waist apart (as a planner moves them) and the arms:
    # the lift and the waist are the torso's, not two chains of unknown kind.
    groups = (
        '<group name="lifter"><joint name="lift1_joint"/><joint name="lift2_joint"/></group>'
        '<group name="waist"><joint name="waist_yaw"/><joint name="waist_pitch"/></group>'
        '<group name="larm"><chain base_link="body" tip_link="l_link4"/></group>'
        '<group name="rarm"><chain base_link="body" tip_link="r_link4"/></group>'
    )
    d = _draft_srdf(tmp_path, "robot", _lifted_torso(), groups)
    assert sorted(c.name for c in d.chains) == ["larm", "rarm"]
    assert d.torso is not None
    assert d.torso.joints == frozenset({"lift1_joint", "lift2_joint", "waist_yaw", "waist_pitch"})
    assert any("the SRDF group 'waist' moves part of it" in r for r in d.torso.decide)


def _two_wheeled(with_plugin: bool) -> list[str]:
    """A box base on two continuous wheels on one axle (y), a 4-joint arm on top."""
    parts = [_link("base_link", size=0.3)]
    for side, y in (("left", 0.2), ("right", -0.2)):
        parts += [
            _link(f"{side}_wheel", _WHEEL),
            _joint(f"{side}_wheel_joint", "base_link", f"{side}_wheel", "continuous",
                   f"0 {y} -0.1", "0 1 0"),
        ]  # fmt: skip
    parts += _arm_on("base_link")
    if with_plugin:
        parts.append(
            '<gazebo><plugin name="drive" filename="libgazebo_ros_diff_drive.so">'
            "<leftJoint>left_wheel_joint</leftJoint><rightJoint>right_wheel_joint</rightJoint>"
            "</plugin></gazebo>"
        )
    return parts


_PLANAR = (
    '<virtual_joint name="world_joint" type="planar" parent_frame="odom" child_link="base_link"/>'
    '<group name="arm"><chain base_link="base_link" tip_link="link4"/></group>'
)


def test_two_wheels_on_one_axle_under_a_planar_virtual_joint_drive_differentially(
    tmp_path: Path,
) -> None:
    # MoveIt models every wheeled base as a planar joint; two wheels on one axle say the base
    # drives differentially (asked: the planar joint may be an omni base's).
    d = _draft_srdf(tmp_path, "robot", _two_wheeled(False), _PLANAR)
    assert d.drive is not None and d.drive.type == "differential"
    assert d.drive.decide is not None and "the SRDF's joint is planar" in d.drive.decide


def test_a_drive_plugin_states_the_drive_under_a_planar_virtual_joint(tmp_path: Path) -> None:
    d = _draft_srdf(tmp_path, "robot", _two_wheeled(True), _PLANAR)
    assert d.drive is not None and d.drive.type == "differential" and d.drive.decide is None


def _linkage_gripper() -> list[str]:
    """A 4-joint arm, a palm, two fingers: knuckle, finger (its pad out), a rod folding back.

    Each side: a driven (or mimic) knuckle, a finger on a mimic joint whose shape reaches 6 cm
    out, and the linkage's rod hung below the finger on a mimic joint, its shape running back
    toward the palm (a closed loop cut open below the pad).
    """
    parts = [_link("base", size=0.1), *_arm_on("base"), _link("palm", size=0.06)]
    parts.append(_joint("palm_mount", "link4", "palm", "fixed", "0 0 0.1"))
    for side, sign in (("left", 1), ("right", -1)):
        mimic = "" if side == "left" else '<mimic joint="left_knuckle_joint"/>'
        parts += [
            f'<link name="{side}_knuckle">{_box("0.01 0.01 0.04", "0 0 0.02")}</link>',
            (
                f'<joint name="{side}_knuckle_joint" type="revolute"><parent link="palm"/>'
                f'<child link="{side}_knuckle"/><origin xyz="0 {sign * 0.03} 0.03"/>'
                f'<axis xyz="{sign} 0 0"/><limit lower="0" upper="0.8" effort="1" velocity="1"/>'
                f"{mimic}</joint>"
            ),
            f'<link name="{side}_finger">{_box("0.01 0.01 0.06", "0 0 0.03")}</link>',
            (
                f'<joint name="{side}_finger_joint" type="revolute"><parent link="{side}_knuckle"/>'
                f'<child link="{side}_finger"/><origin xyz="0 0 0.04"/><axis xyz="{sign} 0 0"/>'
                '<limit lower="0" upper="0.8" effort="1" velocity="1"/>'
                '<mimic joint="left_knuckle_joint" multiplier="-1"/></joint>'
            ),
            f'<link name="{side}_rod">{_box("0.01 0.01 0.05", "0 0 -0.02")}</link>',
            (
                f'<joint name="{side}_rod_joint" type="revolute"><parent link="{side}_finger"/>'
                f'<child link="{side}_rod"/><origin xyz="0 0 0.01"/><axis xyz="{sign} 0 0"/>'
                '<limit lower="0" upper="0.8" effort="1" velocity="1"/>'
                '<mimic joint="left_knuckle_joint"/></joint>'
            ),
        ]
    return parts


def test_a_fingers_rod_folding_back_below_its_pad_is_not_its_tip(tmp_path: Path) -> None:
    d = draft_layout(tmp_path, "robot", _linkage_gripper())
    (m,) = d.manipulators
    assert m.is_gripper
    assert {m.thumb.tip, m.finger.tip} == {"left_finger", "right_finger"}  # type: ignore[union-attr]


def test_a_servo_jaw_of_a_wide_range_beside_a_fixed_jaw_is_the_grippers(tmp_path: Path) -> None:
    # Unnamed links, every joint written with a servo's +-120 degrees: the last joint swings
    # a leaf across its offset beside a fixed leaf reaching past its hinge (the fixed jaw).
    parts = [_link("base", size=0.1), *_arm_on("base", joints=3)]
    parts += [
        f'<link name="fixed_part">{_box("0.01 0.01 0.01")}</link>',
        _joint("fixed_part_joint", "link3", "fixed_part", "fixed", "0.064 -0.01 0"),
        f'<link name="moving_part">{_box("0.01 0.01 0.04", "0.02 0 0")}</link>',
        (
            '<joint name="moving_part_joint" type="revolute"><parent link="link3"/>'
            '<child link="moving_part"/><origin xyz="0.048 0.01 0"/><axis xyz="0 0 1"/>'
            '<limit lower="-2.09" upper="2.09" effort="1" velocity="1"/></joint>'
        ),
    ]
    d = draft_layout(tmp_path, "robot", parts)
    (arm,) = d.chains
    assert arm.joints == frozenset({"j1", "j2", "j3"})


def _leg(prefix: str, x: float, y: float, arm: bool) -> list[str]:
    """A 3-joint leg (hip about x, thigh and calf about y) ending at a fixed ball foot.

    ``arm``: the calf also carries, on a fixed mount beside the foot, three joints to a
    gripper body (a loco-manipulator's small arm).
    """
    foot = '<collision><geometry><sphere radius="0.02"/></geometry></collision>'
    parts = [
        _link(f"{prefix}_hip", size=0.04),
        _joint(f"{prefix}_hip_joint", "trunk", f"{prefix}_hip", xyz=f"{x} {y} 0", axis="1 0 0"),
        _link(f"{prefix}_thigh", size=0.04),
        _joint(f"{prefix}_thigh_joint", f"{prefix}_hip", f"{prefix}_thigh", xyz="0 0 0"),
        _link(f"{prefix}_calf", size=0.04),
        _joint(f"{prefix}_calf_joint", f"{prefix}_thigh", f"{prefix}_calf", xyz="0 0 -0.2"),
        _link(f"{prefix}_foot", foot),
        _joint(f"{prefix}_foot_fixed", f"{prefix}_calf", f"{prefix}_foot", "fixed", "0 0 -0.2"),
    ]
    if arm:
        parts += [
            _link(f"{prefix}_mount", size=0.02),
            _joint(f"{prefix}_mount_fixed", f"{prefix}_calf", f"{prefix}_mount", "fixed",
                   "0.02 0 -0.15"),
            _link(f"{prefix}_a1", size=0.02),
            _joint(f"{prefix}_a1_joint", f"{prefix}_mount", f"{prefix}_a1", xyz="0 0 0"),
            _link(f"{prefix}_a2", size=0.02),
            _joint(f"{prefix}_a2_joint", f"{prefix}_a1", f"{prefix}_a2", xyz="0.05 0 0",
                   axis="1 0 0"),
            _link(f"{prefix}_a3", size=0.02),
            _joint(f"{prefix}_a3_joint", f"{prefix}_a2", f"{prefix}_a3", xyz="0.08 0 0",
                   axis="0 0 1"),
        ]  # fmt: skip
    return parts


def test_a_leg_carrying_an_arm_ends_where_its_twins_end(tmp_path: Path) -> None:
    # Four legs alike from one trunk; the two front calves carry three more joints beside
    # their feet: four 3-joint legs, and two arms carried by the front legs.
    parts = [_link("trunk", size=0.2)]
    for prefix, x, y in (("fl", 0.2, 0.05), ("fr", 0.2, -0.05), ("rl", -0.2, 0.05)):
        parts += _leg(prefix, x, y, arm=x > 0)
    parts += _leg("rr", -0.2, -0.05, arm=False)
    d = draft_layout(tmp_path, "robot", parts)
    legs = {c.tip: c.joints for c in d.chains if c.role == "leg"}
    arms = {c.root: c.joints for c in d.chains if c.role == "arm"}
    assert set(legs) == {"fl_foot", "fr_foot", "rl_foot", "rr_foot"}
    assert all(len(j) == 3 for j in legs.values())
    assert arms == {
        side + "_calf": frozenset({f"{side}_a1_joint", f"{side}_a2_joint", f"{side}_a3_joint"})
        for side in ("fl", "fr")
    }


def test_a_head_on_the_shoulder_is_known_by_its_gazebo_camera(tmp_path: Path) -> None:
    # A one-arm robot whose first arm link carries a panning head (its screen and camera):
    # the head's frame is named by a maker's id, but a Gazebo camera sensor is on it. The
    # shoulder joint below the head is the arm's first, not a torso.
    parts = [
        _link("base", size=0.2),
        _link("l0", size=0.1),
        _joint("j0", "base", "l0", xyz="0 0 0.1", axis="0 0 1"),
        _link("pan_link", size=0.08),
        _joint("pan", "l0", "pan_link", xyz="0 0 0.3", axis="0 0 1"),
        '<link name="s1_frame"/>',
        _joint("s1_mount", "pan_link", "s1_frame", "fixed", "0.05 0 0.1"),
        '<gazebo reference="s1_frame"><sensor name="s1" type="camera"><camera>'
        "<horizontal_fov>1.0</horizontal_fov><image><width>640</width><height>480</height>"
        "</image></camera></sensor></gazebo>",
    ]
    above = "l0"
    for i, axis in enumerate(("0 1 0", "0 0 1", "0 1 0", "0 0 1"), 1):
        parts += [_link(f"l{i}", size=0.04), _joint(f"j{i}", above, f"l{i}",
                  xyz="0.1 0 0.2" if i == 1 else "0 0 0.2", axis=axis)]  # fmt: skip
        above = f"l{i}"
    d = draft_layout(tmp_path, "robot", parts)
    (arm,) = [c for c in d.chains if c.role == "arm"]
    assert arm.joints == frozenset({"j0", "j1", "j2", "j3", "j4"}) and d.torso is None


def test_wheels_alone_under_a_floating_virtual_joint_say_the_drive(tmp_path: Path) -> None:
    # A MoveIt config that floats a wheeled base: nothing but the wheels moves it (no legs,
    # no rotors), so the wheels say the drive, asked.
    floating = _PLANAR.replace('type="planar"', 'type="floating"')
    d = _draft_srdf(tmp_path, "robot", _two_wheeled(False), floating)
    assert d.drive is not None and d.drive.type == "differential"
    assert d.drive.decide is not None and "the SRDF's joint is floating" in d.drive.decide
