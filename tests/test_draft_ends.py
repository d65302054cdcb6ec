"""Where drafted chains end (issue 30): at the flange, tool or foot link past the last joint.

Each small layout is written here, one rule a test; real robots follow (skipped when absent).
"""

from __future__ import annotations

from pathlib import Path

from robotspec.spec.draft.run import draft_from_files
from tests.draft_support import draft_layout as _draft

from .conftest import erd_robots, shared_path

_BOX = '<collision><geometry><box size="{s} {s} {s}"/></geometry></collision>'


def _link(name: str, geometry: str | None = None, size: float = 0.04) -> str:
    inner = _BOX.format(s=size) if geometry is None else geometry
    return f'<link name="{name}">{inner}</link>'


def _joint(
    name: str,
    parent: str,
    child: str,
    kind: str = "revolute",
    xyz: str = "0 0 0.1",
    axis: str = "0 1 0",
) -> str:
    limit = '<limit lower="-2" upper="2" effort="1" velocity="1"/>'
    moving = "" if kind == "fixed" else f'<axis xyz="{axis}"/>{limit}'
    return (
        f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="{xyz}"/>{moving}</joint>'
    )


def _arm(prefix: str, parent: str, n: int = 6, first_xyz: str = "0 0 0.1") -> list[str]:
    """``n`` revolute joints in series below ``parent``, 15 cm apart, alternating axes."""
    parts: list[str] = []
    above = parent
    for i in range(1, n + 1):
        link = f"{prefix}link{i}"
        axis = "0 0 1" if i % 2 else "0 1 0"
        xyz = first_xyz if i == 1 else "0 0 0.15"
        parts += [_link(link), _joint(f"{prefix}joint{i}", above, link, xyz=xyz, axis=axis)]
        above = link
    return parts


def test_an_arm_ends_at_the_flange_past_its_last_joint(tmp_path: Path) -> None:
    parts = [_link("base"), *_arm("", "base")]
    parts += [_link("flange"), _joint("flange_joint", "link6", "flange", "fixed", "0 0 0.05")]
    d = _draft(tmp_path, "flanged", parts)
    (arm,) = d.chains
    assert (arm.root, arm.tip) == ("base", "flange")
    assert len(arm.joints) == 6
    (tool,) = d.manipulators
    # The flange is the tool frame (a question: no tool is named there), not one short of it.
    assert tool.tool_frame == "flange" and tool.decide


def test_of_several_fixed_children_the_one_on_the_last_axis_ends_the_chain(
    tmp_path: Path,
) -> None:
    parts = [_link("base"), *_arm("", "base")]
    # A cable guide beside the wrist and the flange on the last joint's axis (y here).
    parts += [_link("cable_guide"), _joint("guide", "link6", "cable_guide", "fixed", "0.03 0 0")]
    parts += [_link("mount"), _joint("mount_joint", "link6", "mount", "fixed", "0 0.04 0")]
    (arm,) = _draft(tmp_path, "two_leaves", parts).chains
    assert arm.tip == "mount"


def test_an_arm_stops_above_its_hand_one_fixed_joint_past_its_last_joint(
    tmp_path: Path,
) -> None:
    parts = [_link("base"), *_arm("", "base")]
    parts += [_link("link7"), _joint("link7_joint", "link6", "link7", "fixed", "0 0 0.05")]
    parts += [_link("hand"), _joint("hand_joint", "link7", "hand", "fixed", "0 0 0.02")]
    for side, y in (("left", "0.02"), ("right", "-0.02")):
        finger = f"{side}_finger"
        axis = "0 1 0" if side == "left" else "0 -1 0"
        parts += [
            _link(finger, size=0.01),
            _joint(f"{finger}_joint", "hand", finger, "prismatic", f"0 {y} 0.05", axis),
        ]
    parts[-1] = parts[-1].replace("</joint>", '<mimic joint="left_finger_joint"/></joint>')
    d = _draft(tmp_path, "handed", parts)
    (arm,) = d.chains
    assert arm.tip == "link7"  # the flange: never the hand, never a finger
    assert {m.root for m in d.manipulators} == {"hand"}


def test_a_leg_ends_at_its_foot(tmp_path: Path) -> None:
    parts = [_link("trunk", size=0.3)]
    for side, y in (("left", "0.1"), ("right", "-0.1")):
        above = "trunk"
        for i, word in enumerate(("hip", "thigh", "shank"), start=1):
            link = f"{side}_{word}"
            xyz = f"0 {y} -0.05" if i == 1 else "0 0 -0.2"
            parts += [_link(link), _joint(f"{side}_{word}_joint", above, link, xyz=xyz)]
            above = link
        parts += [
            _link(f"{side}_foot"),
            _joint(f"{side}_ankle", above, f"{side}_foot", "fixed", "0 0 -0.2"),
        ]
    d = _draft(tmp_path, "biped", parts)
    tips = {c.tip for c in d.chains if c.role == "leg"}
    assert tips == {"left_foot", "right_foot"}


def test_a_camera_head_on_the_arms_first_link_is_a_neck_beside_a_whole_arm(
    tmp_path: Path,
) -> None:
    # Sawyer's shape: the head pans on the arm's first link; the arm keeps its first joint.
    parts = [_link("base"), _link("shoulder")]
    parts.append(_joint("j0", "base", "shoulder", xyz="0 0 0.08", axis="0 0 1"))
    parts += _arm("arm_", "shoulder", n=6, first_xyz="0.08 0.05 0.24")
    parts += [_link("head"), _joint("head_pan", "shoulder", "head", xyz="0 0 0.3", axis="0 0 1")]
    parts += [_link("head_camera", ""), _joint("cam", "head", "head_camera", "fixed", "0 0 0.2")]
    parts += [_link("flange", ""), _joint("fl", "arm_link6", "flange", "fixed", "0 0 0.03")]
    d = _draft(tmp_path, "head_on_arm", parts)
    (arm,) = d.chains
    assert "j0" in arm.joints and len(arm.joints) == 7
    assert (arm.root, arm.tip) == ("base", "flange")
    assert d.torso is None
    assert d.neck is not None and d.neck.joints == {"head_pan"}
    assert "head_camera" not in arm.sensors


def test_a_lift_below_a_camera_head_stays_a_torso(tmp_path: Path) -> None:
    # Fetch's shape: a prismatic lift carries the head and the arm; the lift is no shoulder.
    parts = [_link("base"), _link("lift")]
    parts.append(_joint("lift_joint", "base", "lift", "prismatic", "0 0 0.3", "0 0 1"))
    parts += _arm("arm_", "lift", n=6, first_xyz="0.1 0 0.1")
    parts += [_link("head"), _joint("head_pan", "lift", "head", xyz="0 0 0.4", axis="0 0 1")]
    parts += [_link("head_camera", ""), _joint("cam", "head", "head_camera", "fixed", "0 0 0.1")]
    d = _draft(tmp_path, "lift_head", parts)
    (arm,) = d.chains
    assert "lift_joint" not in arm.joints and arm.root == "lift"
    assert d.torso is not None and d.torso.joints == {"lift_joint"}


# --------------------------------------------------------------------------- real robots
def test_panda_ends_at_its_flange_and_tiago_at_its_tool_link(tmp_path: Path) -> None:
    robots = erd_robots()
    urdf = robots / "panda_description/urdf/panda.urdf"
    d, _ = draft_from_files(str(urdf), None, folder=tmp_path)
    assert [c.tip for c in d.chains] == ["panda_link8"]  # docs/getting-started.md's flange
    urdf = robots / "tiago_description/robots/tiago.urdf"
    d, _ = draft_from_files(str(urdf), None, folder=tmp_path)
    assert [c.tip for c in d.chains] == ["arm_tool_link"]


def test_ur5e_ends_at_its_flange_and_its_tool_frame_is_tool0(tmp_path: Path) -> None:
    urdf = shared_path("robots", "ur5e", "ur5e.urdf")
    d, _ = draft_from_files(str(urdf), None, folder=tmp_path)
    (arm,) = d.chains
    assert len(arm.joints) == 6
    (tool,) = d.manipulators
    assert tool.tool_frame == "tool0"


def test_a_vertical_lift_at_the_top_of_an_arm_is_a_torso(tmp_path: Path) -> None:
    # HSR-B's shape: a prismatic lift, then the arm's turning joints, in one run.
    parts = [_link("base"), _link("lift")]
    parts.append(_joint("lift_joint", "base", "lift", "prismatic", "0 0 0.3", "0 0 1"))
    parts += _arm("arm_", "lift", n=4, first_xyz="0.1 0 0.1")
    d = _draft(tmp_path, "lifted", parts)
    (arm,) = d.chains
    assert arm.root == "lift" and "lift_joint" not in arm.joints and len(arm.joints) == 4
    assert d.torso is not None and d.torso.joints == {"lift_joint"}


def test_a_one_jaw_gripper_is_the_hand_not_the_arms_last_joint(tmp_path: Path) -> None:
    # Darwin-OP's shape: the wrist link is the fixed jaw and carries the moving jaw beside a
    # fixed leaf at the fixed jaw's end.
    parts = [_link("base"), *_arm("", "base", n=4)]
    parts += [_link("gripper_fix"), _joint("wrist", "link4", "gripper_fix", xyz="0 0 0.1")]
    parts += [
        _link("gripper_mov", size=0.02),
        _joint("jaw", "gripper_fix", "gripper_mov", xyz="0.01 0 0.05", axis="1 0 0"),
        _link("gripper_fix_end", size=0.01),
        _joint("jaw_end", "gripper_fix", "gripper_fix_end", "fixed", "-0.01 0 0.06"),
    ]
    d = _draft(tmp_path, "one_jaw", parts)
    (arm,) = d.chains
    assert arm.tip == "gripper_fix" and "jaw" not in arm.joints and len(arm.joints) == 5
    (m,) = d.manipulators
    assert (m.root, m.tool_frame) == ("gripper_fix", "gripper_fix_end")


def test_a_head_whose_eyes_turn_is_a_neck_not_an_arm_with_a_gripper(tmp_path: Path) -> None:
    # A 3-joint head splitting into two eyes, each turning a camera: no fingers there.
    parts = [_link("torso", size=0.3), _link("neck_1"), _link("neck_2"), _link("head")]
    parts += [
        _joint("neck_pitch", "torso", "neck_1", xyz="0 0 0.3", axis="0 1 0"),
        _joint("neck_roll", "neck_1", "neck_2", xyz="0 0 0.05", axis="1 0 0"),
        _joint("neck_yaw", "neck_2", "head", xyz="0 0 0.05", axis="0 0 1"),
    ]
    for side, y in (("left", "0.03"), ("right", "-0.03")):
        eye, frame = f"{side}_eye", f"{side}_camera_optical_frame"
        parts += [
            _link(eye, size=0.02),
            _joint(f"{side}_eye_pan", "head", eye, xyz=f"0.05 {y} 0.05", axis="0 0 1"),
            _link(frame, ""),
            f'<joint name="{side}_cam" type="fixed"><parent link="{eye}"/>'
            f'<child link="{frame}"/><origin rpy="-1.5708 0 -1.5708"/></joint>',
        ]
    d = _draft(tmp_path, "eyes", parts)
    assert not d.chains and not d.manipulators
    assert d.neck is not None and d.neck.joints == {"neck_pitch", "neck_roll", "neck_yaw"}
    assert len(d.cameras) == 2
