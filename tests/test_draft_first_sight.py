"""Drafts of shapes the blind corpus's robots showed at first sight (issue 30), on small layouts.

Each layout is the shape of a mistake the drafter made on robots it had never seen (measured
before any change): a palm plate carrying two fingers, a hand whose digits flex on one joint
each, a three-finger hand taken for a head. The rule that leaves an item unmarked is recorded on
the draft (``stated``) and never written into the spec.
"""

from __future__ import annotations

from pathlib import Path

from robotspec.spec.draft import render_draft
from robotspec.spec.draft.confidence import GRIPPER_MIMIC, RULES, TOOL_ON_HAND
from tests.test_draft_blind import _WHEEL, _draft, _draft_srdf, _joint, _link


def _digit(prefix: str, parent: str, xyz: str, joints: int = 2, mimic: str = "") -> list[str]:
    """A finger of ``joints`` moving links from ``parent`` (its tip: ``{prefix}_{joints}``)."""
    out: list[str] = []
    above = parent
    for i in range(1, joints + 1):
        out.append(_link(f"{prefix}_{i}", size=0.01))
        j = _joint(f"{prefix}_q{i}", above, f"{prefix}_{i}", xyz=xyz if i == 1 else "0 0 0.03")
        if mimic and i == 1:
            j = j.replace("</joint>", f'<mimic joint="{mimic}"/></joint>')
        out.append(j)
        above = f"{prefix}_{i}"
    return out


def test_a_palm_plate_carrying_two_fingers_gives_both_fingers(tmp_path: Path) -> None:
    # Schunk SVH: ring and little finger sit on a plate that turns on its own joint; the hand
    # has five fingers, not four with the plate as one of them.
    parts = [
        _link("base", size=0.05),
        _link("palm", size=0.04),
        _joint("mount", "base", "palm", kind="fixed"),
        *_digit("thumb", "palm", "0.03 -0.03 0.02"),
        *_digit("index", "palm", "0.03 0.02 0.06"),
        *_digit("middle", "palm", "0.01 0.02 0.06"),
        _link("plate", size=0.01),
        _joint("plate_joint", "palm", "plate", xyz="-0.02 0.02 0.04"),
        *_digit("ring", "plate", "0.0 0.0 0.02"),
        *_digit("pinky", "plate", "-0.02 0.0 0.02"),
    ]
    d = _draft(tmp_path, "svh", parts)
    (m,) = d.manipulators
    assert m.is_hand and m.thumb is not None
    assert m.thumb.tip == "thumb_2"
    assert {f.tip for f in m.fingers.values()} == {"index_2", "middle_2", "ring_2", "pinky_2"}


def test_a_hand_alone_whose_digits_flex_on_one_joint_is_a_hand_not_nothing(
    tmp_path: Path,
) -> None:
    # Mia: five digits of one joint each (two mimic a third) and a TCP frame among the tips.
    # The spec cannot write a finger of one link, so the hand is generic, asked, with its TCP.
    parts = [
        _link("flange", size=0.05),
        _link("palm", size=0.04),
        _joint("palm_mount", "flange", "palm", kind="fixed"),
        '<link name="hand_tcp"/>',
        _joint("tcp_joint", "palm", "hand_tcp", kind="fixed", xyz="0 0 0.13"),
        *_digit("thumb", "palm", "0.03 -0.03 0.02", joints=2),
        *_digit("index", "palm", "0.03 0.02 0.06", joints=1),
        *_digit("middle", "palm", "0.01 0.02 0.06", joints=1),
        *_digit("ring", "palm", "-0.01 0.02 0.06", joints=1, mimic="middle_q1"),
        *_digit("little", "palm", "-0.03 0.02 0.06", joints=1, mimic="middle_q1"),
    ]
    d = _draft(tmp_path, "mia", parts)
    (m,) = d.manipulators
    assert m.tool_frame == "hand_tcp"
    assert m.decide  # a generic hand: a question
    assert d.lone_hand == m.name


def test_a_finger_of_a_hand_alone_is_never_a_head(tmp_path: Path) -> None:
    # Barrett BH8: three fingers of two or three joints from the palm; a finger whose joints
    # pan and tilt is still the hand's, not a head drafted beside it.
    parts = [
        _link("palm", size=0.05),
        *_digit("f1", "palm", "0.03 0.02 0.05", joints=3),
        *_digit("f2", "palm", "-0.03 0.02 0.05", joints=3),
        *_digit("f3", "palm", "0 -0.03 0.05", joints=2),
    ]
    d = _draft(tmp_path, "bh8", parts)
    assert [m.is_hand for m in d.manipulators] == [True]
    assert not any(c.name.startswith("head") for c in d.chains)


def test_the_rule_that_leaves_an_item_unmarked_is_recorded_not_written(tmp_path: Path) -> None:
    # An arm whose gripper's fingers a mimic tag couples, with a TCP frame on the gripper:
    # stated by two rules; the draft records them and the spec's text does not carry them.
    parts = [_link("base", size=0.05)]
    above = "base"
    for i in range(1, 7):
        parts += [_link(f"arm_{i}", size=0.03), _joint(f"arm_q{i}", above, f"arm_{i}")]
        above = f"arm_{i}"
    parts += [
        _link("gripper_base", size=0.03),
        _joint("gripper_mount", above, "gripper_base", kind="fixed"),
        '<link name="tool0"/>',
        _joint("tcp", "gripper_base", "tool0", kind="fixed", xyz="0 0 0.1"),
        _link("left_finger", size=0.01),
        _joint("left_q", "gripper_base", "left_finger", kind="prismatic", xyz="0 0.02 0.05"),
        _link("right_finger", size=0.01),
        _joint(
            "right_q", "gripper_base", "right_finger", kind="prismatic", xyz="0 -0.02 0.05"
        ).replace("</joint>", '<mimic joint="left_q" multiplier="-1"/></joint>'),
    ]
    d = _draft(tmp_path, "arm", parts)
    (m,) = d.manipulators
    assert m.tool_frame == "tool0"
    assert not m.decide
    assert m.stated == (TOOL_ON_HAND, GRIPPER_MIMIC)
    text = render_draft(d)
    assert not any(rule in text for rule in RULES)


def _mobile_arm_with_gripper() -> list[str]:
    """A two-wheel base with a 4-joint arm, a marker frame and two mimic-coupled jaws on link5."""
    parts = [_link("base_footprint", size=0.2)]
    for side, y in (("left", 0.15), ("right", -0.15)):
        parts += [
            _link(f"wheel_{side}", _WHEEL),
            _joint(
                f"wheel_{side}_joint", "base_footprint", f"wheel_{side}", "continuous", f"0 {y} 0"
            ),
        ]
    parts += [_link("link1", size=0.03), _joint("arm_mount", "base_footprint", "link1", "fixed")]
    for i in range(2, 6):
        parts += [_link(f"link{i}", size=0.03), _joint(f"joint{i - 1}", f"link{i - 1}", f"link{i}")]
    jaw = _joint("jaw_l", "link5", "jaw_left", "prismatic", "0.1 0.02 0")
    mimic = _joint("jaw_r", "link5", "jaw_right", "prismatic", "0.1 -0.02 0", axis="0 -1 0")
    parts += [
        # the TCP as the file has it: a marker box to look at, no collision shape
        _link("end_effector_link", size=0.01),
        _joint("end_effector_joint", "link5", "end_effector_link", "fixed", "0.13 0 0"),
        _link("jaw_left", size=0.01),
        jaw,
        _link("jaw_right", size=0.01),
        mimic.replace("</joint>", '<mimic joint="jaw_l"/></joint>'),
    ]
    return parts


def test_an_srdf_group_ending_at_a_frame_beside_the_fingers_ends_where_both_hang(
    tmp_path: Path,
) -> None:
    # TurtleBot3 with OpenMANIPULATOR-X: the SRDF's 'arm' group lists the fixed joint to
    # 'end_effector_link', a frame on link5 beside the jaws; its end effector's parent is link5.
    # The SRDF's fixed virtual joint is the planner's: the wheels say the base moves (asked).
    srdf = (
        '<group name="arm"><joint name="joint1"/><joint name="joint2"/><joint name="joint3"/>'
        '<joint name="joint4"/><joint name="end_effector_joint"/></group>'
        '<group name="gripper"><joint name="jaw_l"/><joint name="jaw_r"/></group>'
        '<end_effector name="tcp" parent_link="link5" group="gripper"/>'
        '<virtual_joint name="vj" type="fixed" parent_frame="odom" child_link="base_footprint"/>'
    )
    d = _draft_srdf(tmp_path, "tb3", _mobile_arm_with_gripper(), srdf)
    (arm,) = d.chains
    assert arm.tip == "link5"
    (m,) = d.manipulators
    assert m.is_gripper and m.tool_frame == "end_effector_link"
    assert {m.thumb.tip, m.finger.tip} == {"jaw_left", "jaw_right"}  # type: ignore[union-attr]
    assert d.drive is not None and d.drive.type == "differential" and d.drive.decide


def _two_joint_branches(words: tuple[str, str]) -> list[str]:
    """A body with two 2-joint branches (left +y, right -y), each 0.3 m long, named by words."""
    parts = [_link("body", size=0.2)]
    for side, y in (("l", 0.2), ("r", -0.2)):
        upper, lower = (f"{side}_{w}" for w in words)
        parts += [
            _link(f"{side}_shoulder_link", size=0.02),
            _joint(f"{side}_pitch", "body", f"{side}_shoulder_link", xyz=f"0 {y} 0.3"),
            _link(upper, size=0.02),
            _joint(f"{side}_roll", f"{side}_shoulder_link", upper, axis="1 0 0", xyz="0 0 -0.01"),
            _link(lower, size=0.02),
            _joint(f"{side}_elbow", upper, lower, "fixed", xyz="0 0 -0.3"),
        ]
    return parts


def test_two_joints_make_an_arm_when_its_links_say_so(tmp_path: Path) -> None:
    # Quori: shoulder pitch and roll, the elbow fixed; a 2-joint branch is an arm only by its
    # links' names (structure cannot tell it from an antenna), and asked.
    d = _draft(tmp_path, "quori", _two_joint_branches(("arm_upper", "arm_lower")))
    arms = sorted(c.name for c in d.chains if c.role == "arm")
    assert arms == ["left_arm", "right_arm"]
    assert all(c.decide for c in d.chains)
    plain = _draft(tmp_path, "antennas", _two_joint_branches(("stalk", "tuft")))
    assert not [c for c in plain.chains if c.role == "arm"]


def _six_joint_arm(last: str = "link_6") -> list[str]:
    parts = [_link("base_link", size=0.05)]
    above = "base_link"
    for i in range(1, 7):
        name = last if i == 6 else f"link_{i}"
        parts += [_link(name, size=0.03), _joint(f"j{i}", above, name, xyz="0 0 0.1")]
        above = name
    return parts


def test_a_bare_arm_whose_last_mesh_is_missing_gets_a_frame_to_place(tmp_path: Path) -> None:
    # HEXFELLOW Firefly: the last link's mesh (the gripper itself) names a package the wheel
    # lacks. Where the flange is cannot be measured: a new frame at the link's origin, asked.
    mesh = '<visual><geometry><mesh filename="package://absent_pkg/meshes/gp80.STL"/></geometry></visual>'
    parts = _six_joint_arm()
    parts[-2] = _link("link_6", mesh)
    d = _draft(tmp_path, "firefly", parts)
    (m,) = d.manipulators
    (frame,) = d.frames
    assert (frame.parent, frame.xyz, m.tool_frame) == ("link_6", (0.0, 0.0, 0.0), frame.name)
    assert m.decide


def _hand_on(parent: str) -> list[str]:
    """A palm fixed on ``parent`` by a joint named as a flange, with three 2-joint fingers."""
    return [
        _link("palm", size=0.04),
        _joint("flange-palm", parent, "palm", "fixed"),
        *_digit("thumb", "palm", "0.03 -0.03 0.02"),
        *_digit("index", "palm", "0.03 0.02 0.06"),
        *_digit("middle", "palm", "0.01 0.02 0.06"),
    ]


def test_a_hand_is_not_its_own_tcp_by_the_name_of_its_mount_joint(tmp_path: Path) -> None:
    # Schunk SIH on a UR5e: 'flange-palm' joins the palm (which carries the fingers) to the
    # flange, beside ROS-Industrial's 'tool0' (the arm's flange frame, not the hand's TCP).
    parts = [
        *_six_joint_arm("wrist_3"),
        _link("flange", size=0.02),
        _joint("wrist_3-flange", "wrist_3", "flange", "fixed", xyz="0 0 0.05"),
        '<link name="tool0"/>',
        _joint("flange-tool0", "flange", "tool0", "fixed", xyz="0 0 0.001"),
        *_hand_on("flange"),
    ]
    d = _draft(tmp_path, "sih", parts)
    (m,) = d.manipulators
    assert m.is_hand and m.tool_frame not in ("palm", "tool0")
    assert [f.parent for f in d.frames] == ["palm"]


def test_a_tcp_on_the_base_a_hand_alone_is_fixed_to_is_its_tool_frame(tmp_path: Path) -> None:
    # qb SoftHand: the palm is fixed on 'hand_base', which also carries the URDF's TCP frame.
    parts = [
        _link("hand_base", size=0.05),
        *_hand_on("hand_base"),
        '<link name="hand_end_effector_link"/>',
        _joint("ee_joint", "hand_base", "hand_end_effector_link", "fixed", xyz="0 0 0.14"),
    ]
    d = _draft(tmp_path, "softhand", parts)
    (m,) = d.manipulators
    assert m.is_hand and m.tool_frame == "hand_end_effector_link"
    assert m.decide  # beside the hand: asked


def test_four_driven_wheels_named_omni_make_an_omni_base(tmp_path: Path) -> None:
    # Summit-XLS: four continuous wheels on parallel axles, each with a velocity transmission;
    # parallel axles cannot tell skid steer from mecanum, the wheels' meshes ('omni_wheel_1')
    # can. The same base with plain wheels stays a skid steer (differential), both asked.
    def base(mesh: str) -> list[str]:
        parts = [_link("chassis", size=0.3)]
        for i, xyz in enumerate(("0.2 0.2 0", "0.2 -0.2 0", "-0.2 0.2 0", "-0.2 -0.2 0")):
            shape = f'<visual><geometry><mesh filename="{mesh}_{i}.dae"/></geometry></visual>'
            parts += [
                _link(f"wheel_{i}", _WHEEL + shape),
                _joint(f"wheel_{i}_joint", "chassis", f"wheel_{i}", "continuous", xyz),
                f'<transmission name="t{i}"><type>transmission_interface/SimpleTransmission'
                f'</type><joint name="wheel_{i}_joint"><hardwareInterface>hardware_interface/'
                f"VelocityJointInterface</hardwareInterface></joint></transmission>",
            ]
        return parts

    omni = _draft(tmp_path, "summit", base("omni_wheel"))
    assert omni.drive is not None and omni.drive.type == "omni" and omni.drive.decide
    skid = _draft(tmp_path, "skid", base("tyre"))
    assert skid.drive is not None and skid.drive.type == "differential" and skid.drive.decide


def test_rotors_on_revolute_joints_are_never_a_hands_digits(tmp_path: Path) -> None:
    # Iris: four rotors on 'revolute' joints limited to +-1e16 rad; one-joint branches are a
    # hand's digits only on ranges a digit could have.
    parts = [_link("frame", size=0.3)]
    for i, xyz in enumerate(("0.2 0.2 0.05", "0.2 -0.2 0.05", "-0.2 0.2 0.05", "-0.2 -0.2 0.05")):
        joint = _joint(f"spinner_{i}_joint", "frame", f"spinner_{i}", xyz=xyz, axis="0 0 1")
        parts += [
            _link(f"spinner_{i}", size=0.05),
            joint.replace('lower="-1" upper="1"', 'lower="-1e16" upper="1e16"'),
        ]
    d = _draft(tmp_path, "quad", parts)
    assert not d.manipulators
