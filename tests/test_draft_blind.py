"""Drafts of robot shapes met on the blind corpus's tune half (issue 30), each on a small layout.

Each layout is the shape of a mistake the drafter made on real robots: read what the files
already say (tip frames, tool frames, wheels) before guessing from names.
"""

from __future__ import annotations

from pathlib import Path

from robotspec.compiler import check_spec
from robotspec.spec.draft import Draft, render_draft
from robotspec.spec.draft.run import draft_from_files
from tests.draft_support import draft_layout as _draft

_BOX = '<visual><geometry><box size="{s} {s} {s}"/></geometry></visual>'
#: A wheel's shape: a flat cylinder about the link's y axis.
_WHEEL = (
    '<collision><origin rpy="1.5708 0 0"/>'
    '<geometry><cylinder radius="0.1" length="0.04"/></geometry></collision>'
)


def _link(name: str, geometry: str | None = None, size: float = 0.02) -> str:
    inner = geometry if geometry is not None else _BOX.format(s=size)
    return f'<link name="{name}">{inner}</link>'


def _joint(
    name: str,
    parent: str,
    child: str,
    kind: str = "revolute",
    xyz: str = "0 0 0.05",
    axis: str = "0 1 0",
    rpy: str = "0 0 0",
) -> str:
    limit = '<limit lower="-1" upper="1" effort="1" velocity="1"/>'
    if kind == "prismatic":
        limit = '<limit lower="0" upper="0.04" effort="1" velocity="1"/>'
    moving = (
        "" if kind == "fixed" else f'<axis xyz="{axis}"/>' + (limit if kind != "continuous" else "")
    )
    return (
        f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="{xyz}" rpy="{rpy}"/>{moving}</joint>'
    )


def _finger(prefix: str, parent: str, xyz: str, tip: str) -> list[str]:
    """A 2-joint finger from ``parent`` ending at a bare fixed frame ``tip``."""
    return [
        _link(f"{prefix}_1"),
        _joint(f"{prefix}_q1", parent, f"{prefix}_1", xyz=xyz),
        _link(f"{prefix}_2"),
        _joint(f"{prefix}_q2", f"{prefix}_1", f"{prefix}_2", xyz="0 0 0.03"),
        f'<link name="{tip}"/>',
        _joint(f"{tip}_joint", f"{prefix}_2", tip, kind="fixed", xyz="0 0 0.03"),
    ]


def test_a_hand_on_a_mount_and_a_wrist_gets_its_wrist_chain_and_the_tip_frames(
    tmp_path: Path,
) -> None:
    # The Shadow and Inspire hands: root, a fixed mount, a 2-joint wrist, then the palm where
    # the fingers split; each finger ends at a bare frame the URDF names as its tip.
    parts = [
        _link("forearm", size=0.05),
        _link("mount"),
        _joint("mount_joint", "forearm", "mount", kind="fixed"),
        _link("wrist"),
        _joint("wrist_q1", "mount", "wrist", axis="1 0 0"),
        _link("palm", size=0.05),
        _joint("wrist_q2", "wrist", "palm"),
        *_finger("thumb", "palm", "0.03 0.03 0.02", "thumb_tip"),
        *_finger("index", "palm", "0.03 0 0.06", "index_tip"),
        *_finger("middle", "palm", "0 0 0.06", "middle_tip"),
        *_finger("ring", "palm", "-0.03 0 0.06", "ring_tip"),
    ]
    d = _draft(tmp_path, "wristhand", parts)
    (wrist,) = d.chains
    assert (wrist.root, wrist.tip, wrist.joints) == (
        "forearm",
        "palm",
        frozenset({"wrist_q1", "wrist_q2"}),
    )
    (hand,) = d.manipulators
    assert hand.is_hand and hand.thumb is not None and hand.thumb.tip == "thumb_tip"
    assert {f.tip for f in hand.fingers.values()} == {"index_tip", "middle_tip", "ring_tip"}
    # A tool frame between the tips, on the palm; the hand is on its wrist, not alone.
    assert [f.parent for f in d.frames] == ["palm"] and hand.tool_frame == d.frames[0].name
    assert wrist.manipulator == hand.name and d.lone_hand is None


def test_a_hand_alone_behind_a_fixed_mount_is_a_hand(tmp_path: Path) -> None:
    # The Ability hand: base_link -> base -> palm (fixed joints), then five fingers.
    parts = [
        _link("base_link", size=0.05),
        _link("palm", size=0.05),
        _joint("mount", "base_link", "palm", kind="fixed"),
        *_finger("thumb", "palm", "0.03 0.03 0.02", "thumb_tip"),
        *_finger("index", "palm", "0.03 0 0.06", "index_tip"),
        *_finger("middle", "palm", "0 0 0.06", "middle_tip"),
    ]
    d = _draft(tmp_path, "mounted", parts)
    assert d.chains == []
    (hand,) = d.manipulators
    assert hand.is_hand and hand.root == "palm" and d.lone_hand == hand.name
    assert hand.thumb is not None and hand.thumb.tip == "thumb_tip"


def test_two_wheels_are_no_gripper(tmp_path: Path) -> None:
    # Freight, TurtleBot3: a base whose two moving branches are wheels (continuous joints about
    # a level axis, each turning a flat cylinder), named as nothing in particular.
    parts = [
        _link("chassis", size=0.3),
        _link("left_roller", _WHEEL),
        _joint("left_j", "chassis", "left_roller", "continuous", "0 0.2 0", "0 1 0"),
        _link("left_hub"),
        _joint("left_hub_j", "left_roller", "left_hub", "fixed", "0 0.02 0"),
        _link("right_roller", _WHEEL),
        _joint("right_j", "chassis", "right_roller", "continuous", "0 -0.2 0", "0 1 0"),
        _link("right_hub"),
        _joint("right_hub_j", "right_roller", "right_hub", "fixed", "0 -0.02 0"),
    ]
    d = _draft(tmp_path, "rover", parts)
    assert d.manipulators == [] and d.frames == []


def _arm(end: str) -> list[str]:
    """A base and a 4-joint arm ending at ``end``."""
    parts = [_link("base", size=0.1)]
    parent = "base"
    for i, axis in enumerate(("0 0 1", "0 1 0", "0 1 0", "0 0 1"), 1):
        child = end if i == 4 else f"link{i}"
        parts += [_link(child, size=0.04), _joint(f"j{i}", parent, child, xyz="0 0 0.2", axis=axis)]
        parent = child
    return parts


def _jaws(root: str, half_width: float) -> list[str]:
    """Two prismatic jaws below ``root``, at +-``half_width`` along y, reaching 5 cm out."""
    parts = []
    for side, sign in (("left", 1), ("right", -1)):
        parts += [
            _link(f"{side}_jaw", '<visual><origin xyz="0 0 0.05"/>'
                  '<geometry><box size="0.01 0.01 0.1"/></geometry></visual>'),
            _joint(f"{side}_jaw_q", root, f"{side}_jaw", "prismatic",
                   f"0 {sign * half_width} 0", f"0 {sign} 0"),
        ]  # fmt: skip
    return parts


def test_a_tcp_beside_the_gripper_on_its_mount_is_the_tool_frame(tmp_path: Path) -> None:
    # Kinova Gen3 lite: the wrist carries a mount; on it hang 'tool_frame' and the gripper.
    parts = [
        *_arm("wrist"),
        _link("mount"),
        _joint("mount_joint", "wrist", "mount", "fixed"),
        '<link name="tool_frame"/>',
        _joint("tool_frame_joint", "mount", "tool_frame", "fixed", "0 0 0.13"),
        _link("gripper_base", size=0.04),
        _joint("gripper_base_joint", "mount", "gripper_base", "fixed"),
        *_jaws("gripper_base", 0.03),
    ]
    d = _draft(tmp_path, "tcpbeside", parts)
    (m,) = d.manipulators
    assert m.is_gripper and m.tool_frame == "tool_frame" and m.root == "mount"
    assert d.frames == []


def test_a_gripper_link_between_its_finger_tips_is_the_tool_frame(tmp_path: Path) -> None:
    # Fetch: the fingers slide from 'gripper_link' symmetrically; their tips' midpoint is it.
    parts = [
        *_arm("wrist"),
        _link("gripper_link", size=0.04),
        _joint("gripper_joint", "wrist", "gripper_link", "fixed", "0 0 0.1"),
        *_jaws("gripper_link", 0.03),
    ]
    d = _draft(tmp_path, "between", parts)
    (m,) = d.manipulators
    assert m.is_gripper and m.tool_frame == "gripper_link" and d.frames == []
    assert any("between the finger tips" in r for r in m.decide)


def test_the_one_frame_fixed_on_a_fingerless_hand_is_its_tool_frame(tmp_path: Path) -> None:
    # iCub's rigid hands: 'l_hand' carries one bare frame, 'l_hand_dh_frame'.
    parts = [
        *_arm("l_hand"),
        '<link name="l_hand_dh_frame"/>',
        _joint("l_hand_dh_joint", "l_hand", "l_hand_dh_frame", "fixed", "0 0 0.06"),
    ]
    d = _draft(tmp_path, "rigid", parts)
    (m,) = d.manipulators
    assert m.tool_frame == "l_hand_dh_frame" and d.frames == []
    assert any("one frame fixed on the hand" in r for r in m.decide)


def test_init_drafts_a_xacro_as_configured_by_its_arguments(tmp_path: Path) -> None:
    # Franka's fr3.urdf.xacro adds the hand only with hand:=true: `--xacro-arg` drafts the robot
    # as configured, and the draft keeps the arguments so that it loads the same robot.
    import yaml

    from robotspec.cli.app import app
    from robotspec.cli.output import run_app

    arm = "".join(_arm("wrist"))
    jaws = "".join(
        [
            _link("gripper_base", size=0.04),
            _joint("gripper_base_joint", "wrist", "gripper_base", "fixed"),
            *_jaws("gripper_base", 0.03),
        ]
    )
    xacro = tmp_path / "arm.urdf.xacro"
    xacro.write_text(
        '<robot name="arm" xmlns:xacro="http://www.ros.org/wiki/xacro">'
        '<xacro:arg name="hand" default="false"/>'
        f'{arm}<xacro:if value="$(arg hand)">{jaws}</xacro:if></robot>'
    )
    out = tmp_path / "arm.yaml"
    argv = ["init", str(xacro), "-o", str(out), "--xacro-arg", "hand=true"]
    assert run_app(app, argv) == 0
    data = yaml.safe_load(out.read_text())
    assert data["description"]["xacro_args"] == {"hand": "true"}
    (m,) = data["manipulators"].values()
    assert m["type"] == "parallel_gripper"
    assert check_spec(out).robot is not None  # valid as written, with the hand
    # Without the argument: the xacro's default, no hand; a malformed argument is refused.
    plain = tmp_path / "plain.yaml"
    assert run_app(app, ["init", str(xacro), "-o", str(plain)]) == 0
    assert "xacro_args" not in yaml.safe_load(plain.read_text())["description"]
    assert (
        run_app(app, ["init", str(xacro), "-o", str(tmp_path / "x.yaml"), "--xacro-arg", "hand"])
        == 2
    )


def test_an_arm_ending_where_its_fingers_split_ends_there_whatever_the_palm_is_named(
    tmp_path: Path,
) -> None:
    # xArm7 with the Ability hand: the arm's flange carries 'thumb_base', which carries every
    # finger; a palm named after the thumb is still the hand, not a finger ending the arm.
    parts = [
        *_arm("link4"),
        _link("thumb_base", size=0.05),
        _joint("wrist2thumb", "link4", "thumb_base", "fixed", "0 0 0.03"),
        *_finger("thumb", "thumb_base", "0.03 0.03 0.02", "thumb_tip"),
        *_finger("index", "thumb_base", "0.03 0 0.06", "index_tip"),
        *_finger("middle", "thumb_base", "0 0 0.06", "middle_tip"),
    ]
    d = _draft(tmp_path, "palmthumb", parts)
    (arm,) = d.chains
    assert (arm.role, arm.root, arm.tip) == ("arm", "base", "link4")
    (hand,) = d.manipulators
    assert hand.is_hand and hand.thumb is not None and hand.thumb.tip == "thumb_tip"


def _draft_srdf(tmp_path: Path, name: str, parts: list[str], groups: str) -> Draft:
    urdf = tmp_path / f"{name}.urdf"
    urdf.write_text(f'<robot name="{name}">' + "".join(parts) + "</robot>")
    srdf = tmp_path / f"{name}.srdf"
    srdf.write_text(f'<robot name="{name}">{groups}</robot>')
    draft, _ = draft_from_files(str(urdf), str(srdf), folder=tmp_path, base_folder=tmp_path)
    spec = tmp_path / f"{name}.yaml"
    spec.write_text(render_draft(draft))
    assert check_spec(spec).robot is not None  # valid as written
    return draft


def test_srdf_groups_are_evidence_not_the_answer(tmp_path: Path) -> None:
    # A mobile manipulator's SRDF: an 'arm' group the tree confirms, a one-joint 'gripper'
    # group, a 'base' group of the URDF's own x, y and theta base joints.
    parts = [
        *_arm("wrist"),
        _link("jaw_base", size=0.04),
        _joint("jaw_base_joint", "wrist", "jaw_base", "fixed"),
        *_jaws("jaw_base", 0.03),
        '<link name="odom"/><link name="odom_x"/><link name="odom_y"/>',
        _joint("x_j", "odom", "odom_x", "prismatic", "0 0 0", "1 0 0"),
        _joint("y_j", "odom_x", "odom_y", "prismatic", "0 0 0", "0 1 0"),
        _joint("theta_j", "odom_y", "base", "continuous", "0 0 0", "0 0 1"),
    ]
    groups = (
        '<group name="arm"><chain base_link="base" tip_link="wrist"/></group>'
        '<group name="gripper"><joint name="left_jaw_q"/></group>'
        '<group name="base"><chain base_link="odom" tip_link="base"/></group>'
    )
    d = _draft_srdf(tmp_path, "mobile", parts, groups)
    # Neither the one-joint gripper group nor the base group is a chain.
    assert [c.srdf_group for c in d.chains] == ["arm"]
    assert any("'gripper' moves one joint" in n for n in d.notes)
    assert any("'base' moves the base" in n for n in d.notes)
    # The group the tree confirms is an arm, and the gripper beside the base is the arm's, a
    # parallel gripper (not a generic tool). Nothing in the SRDF hangs on the group: a question.
    (arm,) = d.chains
    assert arm.role == "arm" and arm.decide == [
        "the SRDF groups these joints ('arm'), but no end effector hangs on the group"
    ]
    (m,) = d.manipulators
    assert m.is_gripper and arm.manipulator == m.name
    # An end effector on the group states it: no question (confidence's rule).
    ee = '<end_effector name="hand" parent_link="wrist" group="gripper" parent_group="arm"/>'
    stated = _draft_srdf(tmp_path, "mobile_ee", parts, groups + ee)
    assert [(c.srdf_group, c.decide) for c in stated.chains] == [("arm", [])]
    # A group the tree does not confirm (two of the arm's four joints) is a question.
    sweep = '<group name="sweep"><joint name="j2"/><joint name="j3"/></group>'
    (part,) = _draft_srdf(tmp_path, "sweep", parts, sweep).chains
    assert part.srdf_group == "sweep" and part.decide


def test_a_gripper_link_far_from_its_frame_ends_an_arm_and_a_tcp_beside_it_is_the_tool_frame(
    tmp_path: Path,
) -> None:
    # Alicia-M: the wrist carries 'tool0' and 'grasp_base', whose frame lies 70 cm out (the
    # fingers' joints bring them back): the fingers are short, so the arm ends there, and the
    # leaf 'tool0' beside the gripper is its TCP, not 'grasp_base' (it carries the fingers).
    parts = [
        *_arm("link4"),
        '<link name="tool0"/>',
        _joint("tool0_joint", "link4", "tool0", "fixed", "0 0 0.15"),
        _link("grasp_base"),
        _joint("grasp_base_joint", "link4", "grasp_base", "fixed", "0 0 0.7"),
        *_jaws("grasp_base", 0.03),
    ]
    parts = [
        p.replace('<origin xyz="0 0.03 0"', '<origin xyz="0 0.03 -0.6"').replace(
            '<origin xyz="0 -0.03 0"', '<origin xyz="0 -0.03 -0.6"'
        )
        for p in parts
    ]
    d = _draft(tmp_path, "faraway", parts)
    (arm,) = d.chains
    assert (arm.role, arm.tip) == ("arm", "link4")
    (m,) = d.manipulators
    assert m.is_gripper and m.tool_frame == "tool0" and d.frames == []


def test_a_tcp_the_urdf_names_is_stated_a_guessed_name_is_asked(tmp_path: Path) -> None:
    # UR's 'tool0', Franka's '*_tcp': a bare frame named as a TCP is the files' answer, with no
    # DECIDE mark on it; a frame found by a weaker name ('flange') stays a question.
    for frame, asked in (("tool0", False), ("hand_tcp", False), ("flange", True)):
        parts = [
            *_arm("wrist"),
            f'<link name="{frame}"/>',
            _joint(f"{frame}_joint", "wrist", frame, "fixed", "0 0 0.1"),
        ]
        (m,) = _draft(tmp_path, f"arm_{frame}", parts).manipulators
        assert m.tool_frame == frame
        assert any("by its name" in r for r in m.decide) is asked
