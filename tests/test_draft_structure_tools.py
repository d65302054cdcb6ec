"""Tool frames read from the tree's shape where names say nothing (issue 30: ``renamed``).

Why: makers name a hand's TCP anything ('end_effector', 'grasp_link', 'manipulator', an id);
``tools/corpus/robustness.py --only renamed`` showed the drafter proposing a new frame beside
the one the URDF has as soon as the names were neutral ids. Each test is a small layout of one
shape, its links only numbered, so no name can decide it.
"""

from __future__ import annotations

from pathlib import Path

from tests.draft_support import draft_layout as _draft
from tests.draft_support import joint_xml

_BOX = '<collision><geometry><box size="{s}"/></geometry></collision>'
_MASS = (
    '<inertial><mass value="0.3"/>'
    '<inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial>'
)


def _link(name: str, size: str | None = "0.04 0.04 0.04") -> str:
    shape = "" if size is None else _BOX.format(s=size)
    return f'<link name="{name}">{_MASS if size else ""}{shape}</link>'


_joint = joint_xml  # limits -0.5..0.5, mimic tags without a multiplier


def _arm() -> list[str]:
    """A base and six revolute joints in series (n0 ... n6), each link a box."""
    parts = [_link("n0", "0.2 0.2 0.1")]
    for i in range(1, 7):
        axis = "0 0 1" if i % 2 else "0 1 0"
        parts += [_link(f"n{i}"), _joint(f"q{i}", f"n{i - 1}", f"n{i}", axis=axis)]
    return parts


def test_a_bare_frame_out_past_a_hands_finger_bases_is_its_tcp(tmp_path: Path) -> None:
    """Three two-link fingers on a hand; a bare leaf on the hand out among them is the TCP.

    A bare leaf short of where the fingers are hinged (a wrist sensor's frame) is not.
    """
    parts = _arm()
    parts += [_link("n7", "0.08 0.08 0.02"), _joint("q7", "n6", "n7", "fixed", "0 0 0.05")]
    for k, (x, y) in enumerate(((0.03, 0.02), (-0.03, 0.02), (0.0, -0.03))):
        a, b = f"n{8 + 2 * k}", f"n{9 + 2 * k}"
        parts += [_link(a, "0.01 0.01 0.04"), _joint(f"q{8 + 2 * k}", "n7", a, xyz=f"{x} {y} 0.03")]
        parts += [_link(b, "0.01 0.01 0.04"), _joint(f"q{9 + 2 * k}", a, b, xyz="0 0 0.04")]
    parts += [_link("n14", None), _joint("q14", "n7", "n14", "fixed", "0 0 0.01")]
    parts += [_link("n15", None), _joint("q15", "n7", "n15", "fixed", "0 0 0.09")]
    draft = _draft(tmp_path, "hand", parts)
    [m] = draft.manipulators
    assert m.tool_frame == "n15"
    assert m.decide  # where it lies, not a file's statement: asked
    assert not draft.frames  # nothing proposed beside it


def _jaws(parent: str) -> list[str]:
    """Two prismatic jaws (n9, n10) on ``parent``, the second mimicking the first."""
    return [
        _link("n9", "0.01 0.01 0.05"),
        _joint("q9", parent, "n9", "prismatic", "0 0.02 0.06", "0 1 0"),
        _link("n10", "0.01 0.01 0.05"),
        _joint("q10", parent, "n10", "prismatic", "0 -0.02 0.06", "0 -1 0", "q9"),
    ]


def test_a_bare_frame_beside_the_gripper_on_its_mount_is_its_tcp(tmp_path: Path) -> None:
    """A bare mount carries the gripper and, beside it, a bare leaf out between the jaws."""
    parts = _arm()
    parts += [_link("n7", None), _joint("q7", "n6", "n7", "fixed", "0 0 0.05")]
    parts += [_link("n8", "0.06 0.06 0.04"), _joint("q8", "n7", "n8", "fixed", "0 0 0")]
    parts += _jaws("n8")
    parts += [_link("n11", None), _joint("q11", "n7", "n11", "fixed", "0 0 0.11")]
    draft = _draft(tmp_path, "mount", parts)
    [m] = draft.manipulators
    assert m.tool_frame == "n11"
    assert not draft.frames


def test_a_wrist_sensor_frame_short_of_the_jaws_is_no_tcp(tmp_path: Path) -> None:
    """A bare leaf between the wrist and where the jaws hang is a sensor's: a frame is proposed."""
    parts = _arm()
    parts += [_link("n7", None), _joint("q7", "n6", "n7", "fixed", "0 0 0.02")]
    parts += [_link("n8", "0.06 0.06 0.04"), _joint("q8", "n6", "n8", "fixed", "0 0 0.08")]
    parts += _jaws("n8")
    draft = _draft(tmp_path, "sensor", parts)
    [m] = draft.manipulators
    assert m.tool_frame != "n7"
    assert [f.parent for f in draft.frames] == ["n8"]


def test_a_bare_link_the_fingers_follow_out_on_the_hand_is_its_tcp(tmp_path: Path) -> None:
    """A bare leaf on the hand's motor joint, which the shaped fingers mimic: the hand's TCP.

    The hand is one motor modelled as a bare link out between the fingers; the fingers'
    joints mimic it (the shape of a small humanoid's hand).
    """
    parts = _arm()
    parts += [_link("n7", None), _joint("q7", "n6", "n7", xyz="0 0 0.06", axis="0 0 1")]
    parts += [_link("n8", "0.01 0.01 0.04"), _joint("q8", "n6", "n8", xyz="0 0.015 0.05")]
    parts[-1] = _joint("q8", "n6", "n8", xyz="0 0.015 0.05", mimic="q7")
    parts += [_link("n9", "0.01 0.01 0.04"), _joint("q9", "n6", "n9", xyz="0 -0.015 0.05")]
    parts[-1] = _joint("q9", "n6", "n9", xyz="0 -0.015 0.05", mimic="q7")
    draft = _draft(tmp_path, "motor", parts)
    assert any(m.tool_frame == "n7" for m in draft.manipulators)


def test_the_leaf_farthest_out_on_the_last_joints_axis_is_the_tool_frame(tmp_path: Path) -> None:
    """Past the last joint: a shaped gripper base, a shaped leaf on it out along the axis (the
    mount point), and sensors hung off the axis beside them. The leaf on the axis is the tool
    frame, shape or not; nothing is proposed beside it."""
    parts = _arm()
    parts[-1] = _joint("q6", "n5", "n6", axis="0 0 1")
    parts += [_link("n7"), _joint("q7", "n6", "n7", "fixed", "0 0 0.1")]
    parts += [_link("n8", "0.02 0.02 0.02"), _joint("q8", "n7", "n8", "fixed", "0.04 0.01 0.02")]
    parts += [_link("n9", "0.05 0.05 0.02"), _joint("q9", "n7", "n9", "fixed", "0 0 0")]
    parts += [_link("n10", "0.01 0.01 0.01"), _joint("q10", "n9", "n10", "fixed", "0 0 0.025")]
    draft = _draft(tmp_path, "axis", parts)
    [m] = draft.manipulators
    assert m.tool_frame == "n10"
    assert m.decide and not draft.frames
