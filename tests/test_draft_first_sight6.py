"""Drafts of shapes round 6 of the blind corpus showed (issue 30), on small layouts.

Each layout is the shape of a miss on the tune half, built here from boxes (never a copy of a
robot's files): a one-jaw gripper whose fixed jaw is the wrist link's own shape.
"""

from __future__ import annotations

from pathlib import Path

from tests.test_draft_blind import _WHEEL, _arm, _draft, _joint, _link


def _box_link(name: str, size: str, at: str) -> str:
    """A link whose collision box of ``size`` is centred at ``at`` in its frame."""
    box = f'<origin xyz="{at}"/><geometry><box size="{size}"/></geometry>'
    return f'<link name="{name}"><visual>{box}</visual><collision>{box}</collision></link>'


def _one_jaw(jaw_range: str, fixed_jaw_length: float) -> list[str]:
    """A 4-joint arm whose last link 'wrist' holds a fixed jaw of ``fixed_jaw_length`` along x
    and carries one moving jaw 'fngr' hinged 12 cm out about y (nothing named as a hand)."""
    lower, upper = jaw_range.split()
    hinge = (
        '<joint name="f1x" type="revolute"><parent link="wrist"/><child link="fngr"/>'
        '<origin xyz="0.12 0 0.015"/><axis xyz="0 1 0"/>'
        f'<limit lower="{lower}" upper="{upper}" effort="1" velocity="1"/></joint>'
    )
    return [
        *[p for p in _arm("wrist") if 'name="wrist"' not in p or "<joint" in p],
        _box_link("wrist", f"{fixed_jaw_length} 0.04 0.03", f"{fixed_jaw_length / 2} 0 0"),
        _box_link("fngr", "0.08 0.03 0.02", "0.04 0 0"),
        hinge,
    ]


def test_a_jaw_swinging_onto_the_wrists_own_shape_is_a_one_jaw_gripper(tmp_path: Path) -> None:
    # Spot's arm: the wrist link's meshes include the fixed jaw, reaching 20 cm out, past the
    # moving jaw's hinge (12 cm); the jaw swings a quarter turn about an axis across it.
    d = _draft(tmp_path, "one_jaw_shape", _one_jaw("-1.57 0", 0.2))
    (arm,) = d.chains
    assert arm.tip == "wrist" and "f1x" not in arm.joints and len(arm.joints) == 4
    (m,) = d.manipulators
    assert m.root == "wrist"
    (frame,) = [f for f in d.frames if f.name == m.tool_frame]
    assert frame.parent == "wrist"  # a new tool frame on the link holding both jaws


def test_a_last_link_hinged_past_the_shape_above_it_stays_the_arms(tmp_path: Path) -> None:
    # The same joint where the link above ends at the hinge (an elbow turning a forearm, a
    # wrist): no fixed jaw out there, so the last link is the arm's and the chain ends on it.
    d = _draft(tmp_path, "last_link", _one_jaw("-1.57 0", 0.12))
    (arm,) = d.chains
    assert arm.tip == "fngr" and "f1x" in arm.joints


def test_a_wrist_turning_all_the_way_round_is_not_a_jaw(tmp_path: Path) -> None:
    # A full turn is a wrist's roll, not a jaw's swing, whatever the shape above it.
    d = _draft(tmp_path, "wrist_roll", _one_jaw("-3.14 3.14", 0.2))
    (arm,) = d.chains
    assert arm.tip == "fngr" and "f1x" in arm.joints


def test_five_four_joint_fingers_on_one_palm_are_a_hand_not_five_arms(tmp_path: Path) -> None:
    # Tesollo DG-5F's shape: a palm carrying five fingers of four joints each, 24 cm long
    # (long enough for an arm), named by numbers only: a hand of five fingers, no arm.
    parts = [_link("mount", size=0.02), _link("palm", size=0.05)]
    parts.append(_joint("mount_palm", "mount", "palm", "fixed"))
    bases = ("0 0.05 0.02", "0.03 0.02 0.08", "0.03 0 0.08", "0.03 -0.02 0.08", "0.03 -0.04 0.08")
    for f, at in enumerate(bases, 1):
        above = "palm"
        for i in range(1, 5):
            parts.append(_link(f"l_{f}_{i}", size=0.01))
            xyz = at if i == 1 else "0 0 0.06"
            parts.append(_joint(f"j_{f}_{i}", above, f"l_{f}_{i}", xyz=xyz))
            above = f"l_{f}_{i}"
    d = _draft(tmp_path, "five_fingers", parts)
    assert not d.chains
    (m,) = d.manipulators
    assert m.root == "palm" and m.thumb is not None and len(m.fingers) == 4


def _wheeled_legs(wheel_range: str) -> list[str]:
    """A body on four 3-joint legs (abduction, hip, knee), each knee carrying a wheel on a
    revolute joint about y of range ``wheel_range`` (nothing named as a wheel)."""
    lower, upper = wheel_range.split()
    parts = [_link("base", size=0.3)]
    corners = {"lf": (0.2, 0.1), "rf": (0.2, -0.1), "lh": (-0.2, 0.1), "rh": (-0.2, -0.1)}
    for leg, (x, y) in corners.items():
        parts += [
            _link(f"{leg}_hip", size=0.03),
            _joint(f"{leg}_haa", "base", f"{leg}_hip", xyz=f"{x} {y} 0", axis="1 0 0"),
            _link(f"{leg}_thigh", size=0.03),
            _joint(f"{leg}_hfe", f"{leg}_hip", f"{leg}_thigh", xyz="0 0 -0.02"),
            _link(f"{leg}_calf", size=0.03),
            _joint(f"{leg}_kfe", f"{leg}_thigh", f"{leg}_calf", xyz="0 0 -0.2"),
            _link(f"{leg}_roll", _WHEEL),
            f'<joint name="{leg}_whl" type="revolute"><parent link="{leg}_calf"/>'
            f'<child link="{leg}_roll"/><origin xyz="0 0 -0.2"/><axis xyz="0 1 0"/>'
            f'<limit lower="{lower}" upper="{upper}" effort="1" velocity="1"/></joint>',
        ]  # fmt: skip
    return parts


def test_wheels_at_four_legs_ends_roll_the_robot_and_the_legs_end_at_their_axles(
    tmp_path: Path,
) -> None:
    # LimX P311D's shape: each leg's last joint turns a wheel (revolute to +-1000 rad, a
    # continuous joint written with limits), hung on a knee that turns about a level axis (not
    # a caster's swivel). The legs end at the calves; four parallel unsteered wheels: skid steer.
    d = _draft(tmp_path, "wheel_legs", _wheeled_legs("-1000 1000"))
    legs = {c.name: c for c in d.chains}
    assert len(legs) == 4 and all(c.role == "leg" for c in legs.values())
    assert {c.tip for c in legs.values()} == {"lf_calf", "rf_calf", "lh_calf", "rh_calf"}
    assert not any(j.endswith("_whl") for c in legs.values() for j in c.joints)
    assert d.drive is not None and d.drive.type == "differential" and d.drive.decide


def test_a_foot_joint_of_a_limited_range_stays_the_legs(tmp_path: Path) -> None:
    # The same shape with a range a leg's joint may have (ANYmal B's +-3 pi): no wheels.
    d = _draft(tmp_path, "ankle_legs", _wheeled_legs("-9.42 9.42"))
    assert {c.tip for c in d.chains} == {"lf_roll", "rf_roll", "lh_roll", "rh_roll"}
    assert d.drive is not None and d.drive.type == "floating"


def test_four_parallel_wheels_on_a_chassis_stay_an_omni_guess(tmp_path: Path) -> None:
    # RoboMaster S1's shape: four continuous wheels on the chassis itself, parallel axles,
    # nothing named mecanum: skid steer and mecanum look alike, so omni stays the (asked) guess.
    parts = [_link("chassis", size=0.3)]
    for i, (x, y) in enumerate(((0.1, 0.1), (0.1, -0.1), (-0.1, 0.1), (-0.1, -0.1)), 1):
        parts += [
            _link(f"w{i}", _WHEEL),
            _joint(f"w{i}_j", "chassis", f"w{i}", "continuous", f"{x} {y} 0", "0 1 0"),
        ]
    d = _draft(tmp_path, "chassis", parts)
    assert d.drive is not None and d.drive.type == "omni" and d.drive.decide


def test_short_legs_ending_on_feet_at_the_ground_are_legs_not_fingers(tmp_path: Path) -> None:
    # Mini Pupper 2's shape: four 3-joint legs 12 cm long (a finger's length), their links
    # numbered ('lf1'..'lf3'), each ending at a fixed '*foot' link, the lowest points of the
    # robot: legs of a small quadruped, not a hand's fingers.
    parts = [_link("base", size=0.1)]
    corners = {"lf": (0.1, 0.05), "rf": (0.1, -0.05), "lb": (-0.1, 0.05), "rb": (-0.1, -0.05)}
    for leg, (x, y) in corners.items():
        parts += [
            _link(f"{leg}1", size=0.01),
            _joint(f"{leg}_1", "base", f"{leg}1", xyz=f"{x} {y} 0", axis="1 0 0"),
            _link(f"{leg}2", size=0.01),
            _joint(f"{leg}_2", f"{leg}1", f"{leg}2", xyz=f"0 {y / 2.5} 0"),
            _link(f"{leg}3", size=0.01),
            _joint(f"{leg}_3", f"{leg}2", f"{leg}3", xyz="0 0 -0.05"),
            _link(f"{leg}foot", size=0.01),
            _joint(f"{leg}_foot", f"{leg}3", f"{leg}foot", "fixed", "0 0 -0.05"),
        ]
    d = _draft(tmp_path, "small_quadruped", parts)
    assert not d.manipulators
    assert sorted(c.tip for c in d.chains) == ["lbfoot", "lffoot", "rbfoot", "rffoot"]
    assert all(c.role == "leg" for c in d.chains)
    assert d.drive is not None and d.drive.type == "floating"


def _gripper_arm(finger_y: float) -> list[str]:
    """A 4-joint arm, a gripper link fixed on its end, two prismatic fingers (one a mimic)
    hinged ``finger_y`` to each side of the gripper link's origin, their pads 4 cm out."""
    parts = [*_arm("wrist"), _link("grip", size=0.03)]
    parts.append(_joint("grip_mount", "wrist", "grip", "fixed"))
    for side, sign in (("l", 1), ("r", -1)):
        pad = '<origin xyz="0 0 0.04"/><geometry><box size="0.01 0.01 0.02"/></geometry>'
        joint = _joint(f"{side}_q", "grip", f"{side}_pad", "prismatic", f"0 {sign * finger_y} 0")
        if side == "r":
            joint = joint.replace("</joint>", '<mimic joint="l_q" multiplier="-1"/></joint>')
        parts += [f'<link name="{side}_pad"><collision>{pad}</collision></link>', joint]
    return parts


def test_fingers_hinged_at_the_grippers_origin_get_a_new_tool_frame(tmp_path: Path) -> None:
    # myCobot's parallel gripper: both jaws' joints sit at the gripper link's origin (their
    # shapes say where they are): the gripper link is not a frame between the tips.
    d = _draft(tmp_path, "jaws_at_origin", _gripper_arm(0.0))
    (m,) = d.manipulators
    (frame,) = [f for f in d.frames if f.name == m.tool_frame]
    assert frame.parent == "grip" and m.decide


def test_a_gripper_link_between_its_fingers_is_its_tool_frame(tmp_path: Path) -> None:
    # Fetch's gripper: the fingers hinge 3 cm to each side of 'gripper_link', which lies
    # between them: it is the tool frame the URDF has, no new one.
    d = _draft(tmp_path, "link_between", _gripper_arm(0.03))
    (m,) = d.manipulators
    assert m.tool_frame == "grip" and not d.frames


def test_a_rigid_forearm_fixed_past_the_last_joint_ends_the_chain_with_a_frame_on_it(
    tmp_path: Path,
) -> None:
    # Quori's arm: two shoulder joints, then a fixed elbow hanging the lower arm 15 cm out,
    # beside a cover piece fixed at the upper arm's origin. The chain ends at the lower arm
    # and its tool frame is a new one at the far end of its shape (25 cm along it).
    forearm = '<origin xyz="0 0 -0.125"/><geometry><box size="0.04 0.04 0.25"/></geometry>'
    parts = [
        _link("body", size=0.3),
        _link("shoulder", size=0.03),
        _joint("shoulder_pitch", "body", "shoulder", xyz="0 0.2 0.4"),
        _link("arm_upper", size=0.03),
        _joint("shoulder_roll", "shoulder", "arm_upper", xyz="0 0 0", axis="1 0 0"),
        _link("cover", size=0.02),
        _joint("cover_j", "arm_upper", "cover", "fixed", "0 0 0"),
        f'<link name="arm_lower"><collision>{forearm}</collision></link>',
        _joint("elbow", "arm_upper", "arm_lower", "fixed", "0 0 -0.15"),
    ]
    d = _draft(tmp_path, "rigid_forearm", parts)
    (arm,) = d.chains
    assert arm.tip == "arm_lower" and arm.joints == {"shoulder_pitch", "shoulder_roll"}
    (m,) = d.manipulators
    (frame,) = [f for f in d.frames if f.name == m.tool_frame]
    assert frame.parent == "arm_lower" and frame.xyz == (0.0, 0.0, -0.25)


def test_a_frame_ending_an_arm_turned_as_optical_frames_are_is_no_camera(tmp_path: Path) -> None:
    # Wolfgang-OP's wrist: the bare frame past the arm's last joint is turned exactly as a
    # REP 103 optical frame; it ends the arm (its tip and tool frame), so it is not a camera.
    parts = [*_arm("wrist"), '<link name="wrist_frame"/>']
    parts.append(
        _joint("wrist_fix", "wrist", "wrist_frame", "fixed", "0 0 0.1", rpy="-1.5708 0 -1.5708")
    )
    d = _draft(tmp_path, "wrist_frame", parts)
    (arm,) = d.chains
    assert arm.tip == "wrist_frame"
    assert not d.cameras


def test_a_floating_joint_from_the_world_is_not_the_torsos(tmp_path: Path) -> None:
    # CURI's file hangs its base from 'world' by a floating joint; the torso is the yaw joint
    # between the base and where the arms branch, starting on the base, not at the world.
    parts = [
        '<link name="world"/>',
        _link("base", size=0.4),
        '<joint name="reference" type="floating"><parent link="world"/><child link="base"/>'
        "</joint>",
        _link("chest", size=0.1),
        _joint("waist_yaw", "base", "chest", xyz="0 0 0.5", axis="0 0 1"),
    ]
    joints = (("shoulder", "0 1 0"), ("elbow", "0 1 0"), ("wrist", "0 0 1"))
    for side, y in (("left", 0.2), ("right", -0.2)):
        above = "chest"
        for i, (part, axis) in enumerate(joints):
            xyz = f"0 {y if i == 0 else 0} 0.15"
            parts.append(_link(f"{side}_{part}", size=0.03))
            parts.append(_joint(f"{side}_j{i}", above, f"{side}_{part}", xyz=xyz, axis=axis))
            above = f"{side}_{part}"
    d = _draft(tmp_path, "floating_base", parts)
    assert d.torso is not None
    assert d.torso.joints == {"waist_yaw"} and d.torso.root == "base"
