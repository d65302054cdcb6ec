"""A mark stays where a rule's files state only part of an item (``draft/whole.py``, issue 30).

Small layouts, one shape each, built here: the item as a file states it whole (unmarked, its
rule recorded) beside the same item with the part the file leaves to inference (marked).
"""

from __future__ import annotations

from pathlib import Path

from robotspec.spec.draft.confidence import (
    CAMERA_GAZEBO,
    DRIVE_FIXED,
    GRIPPER_MIMIC,
    TOOL_AT_END,
    TOOL_ON_HAND,
)
from robotspec.spec.draft.model import Draft
from tests.test_draft_blind import _WHEEL, _draft, _draft_srdf, _joint, _link

_OPTICAL_RPY = "-1.5707963 0 -1.5707963"


def _sensor(link: str) -> str:
    return (
        f'<gazebo reference="{link}"><sensor name="{link}_sensor" type="camera">'
        "<camera><horizontal_fov>1.0</horizontal_fov><image><width>640</width>"
        "<height>480</height></image></camera></sensor></gazebo>"
    )


def _camera(optical: list[tuple[str, str]]) -> list[str]:
    """A base and a camera body carrying a Gazebo sensor and the bare frames ``optical``."""
    parts = [
        _link("base", size=0.2),
        _link("cam", size=0.02),
        _joint("cam_mount", "base", "cam", kind="fixed", xyz="0.1 0 0.5"),
        _sensor("cam"),
    ]
    for name, xyz in optical:
        parts += [
            f'<link name="{name}"/>',
            _joint(f"{name}_joint", "cam", name, kind="fixed", xyz=xyz, rpy=_OPTICAL_RPY),
        ]
    return parts


def test_a_gazebo_camera_with_one_optical_frame_is_stated(tmp_path: Path) -> None:
    d = _draft(tmp_path, "cam", _camera([("cam_optical", "0 0 0")]))
    (cam,) = d.cameras
    assert (cam.body, cam.decide, cam.stated) == ("cam_optical", [], CAMERA_GAZEBO)


def test_a_second_frame_of_the_device_looking_its_way_keeps_the_mark(tmp_path: Path) -> None:
    # The sensor sits where the depth optical frame is; the colour optical frame, 1.5 cm
    # beside it, looks the same way: the sensor does not say which one a spec names.
    frames = [("cam_depth_optical", "0 0 0"), ("cam_color_optical", "0 0.015 0")]
    d = _draft(tmp_path, "cam", _camera(frames))
    (cam,) = d.cameras
    assert cam.stated is None
    assert cam.decide == [
        "'cam_color_optical', fixed beside it, looks the same way: which frame is the camera?"
    ]


def _gripper(pad: bool) -> list[str]:
    """A 6-joint arm, a gripper with a TCP frame and two mimic-coupled jaws (and pads)."""
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
    if pad:  # a rubber pad with a shape, fixed past the left jaw's last joint
        parts += [
            _link("left_pad", size=0.005),
            _joint("left_pad_joint", "left_finger", "left_pad", kind="fixed", xyz="0 0 0.02"),
        ]
    return parts


def test_mimic_jaws_with_a_tcp_are_stated(tmp_path: Path) -> None:
    (m,) = _draft(tmp_path, "arm", _gripper(pad=False)).manipulators
    assert not m.decide and m.stated == (TOOL_ON_HAND, GRIPPER_MIMIC)


def test_mimic_fingers_that_end_differently_keep_the_mark(tmp_path: Path) -> None:
    # The mimic tag couples the jaws; where a finger's tip is it does not say: one side ends
    # on its jaw, the other on a pad fixed past it.
    (m,) = _draft(tmp_path, "arm", _gripper(pad=True)).manipulators
    assert m.thumb is not None and m.finger is not None
    assert {m.thumb.tip, m.finger.tip} == {"left_pad", "right_finger"}
    assert m.stated == ()
    assert any("end differently" in why for why in m.decide)


def test_a_second_tcp_name_on_the_hand_keeps_the_mark(tmp_path: Path) -> None:
    parts = [
        *_gripper(pad=False),
        '<link name="grasp_frame"/>',
        _joint("grasp", "gripper_base", "grasp_frame", kind="fixed", xyz="0 0 0.12"),
    ]
    (m,) = _draft(tmp_path, "arm", parts).manipulators
    assert m.stated == ()
    assert any("is named as a TCP too" in why for why in m.decide)


_FIXED_BASE = (
    '<virtual_joint name="fixed_base" type="fixed" parent_frame="world" child_link="base"/>'
)


def _arm_on(base: list[str]) -> list[str]:
    parts = [_link("base", size=0.2), *base]
    above = "base"
    for i in range(1, 5):
        parts += [_link(f"l{i}", size=0.03), _joint(f"q{i}", above, f"l{i}", xyz="0 0 0.2")]
        above = f"l{i}"
    return parts


def _drive(d: Draft) -> tuple[str, str | None, str | None]:
    assert d.drive is not None
    return d.drive.type, d.drive.decide, d.drive.stated


def test_a_fixed_virtual_joint_on_an_arm_is_stated(tmp_path: Path) -> None:
    d = _draft_srdf(tmp_path, "arm", _arm_on([]), _FIXED_BASE)
    assert _drive(d) == ("fixed", None, DRIVE_FIXED)


def test_a_fixed_virtual_joint_on_a_base_with_wheels_modelled_fixed_keeps_the_mark(
    tmp_path: Path,
) -> None:
    # The wheels are on fixed joints (the file moves nothing), but the base has wheels: a
    # MoveIt config's fixed virtual joint says what its planner assumes, not the drive.
    wheels = [
        x
        for side, y in (("left", "0.2"), ("right", "-0.2"))
        for x in (
            _link(f"{side}_wheel_link", _WHEEL),
            _joint(f"{side}_wheel_mount", "base", f"{side}_wheel_link", "fixed", f"0 {y} 0"),
        )
    ]
    d = _draft_srdf(tmp_path, "mobile", _arm_on(wheels), _FIXED_BASE)
    kind, why, rule = _drive(d)
    assert kind == "fixed" and rule is None
    assert why == "the SRDF's virtual joint is fixed, but the files model wheels or a drive"


def test_a_planar_move_plugin_is_no_drive_stated(tmp_path: Path) -> None:
    # A simulator's planar_move moves any base sideways: it says nothing of the real drive.
    plugin = '<gazebo><plugin filename="libgazebo_ros_planar_move.so" name="move"/></gazebo>'
    wheels = [
        x
        for side, y in (("a", "0.2"), ("b", "-0.2"))
        for x in (
            _link(f"{side}_roller", _WHEEL),
            _joint(f"{side}_j", "base", f"{side}_roller", "continuous", f"0 {y} 0", "0 1 0"),
        )
    ]
    d = _draft(tmp_path, "base", [_link("base", size=0.2), *wheels, plugin])
    kind, why, rule = _drive(d)
    assert (kind, rule) == ("omni", None)
    assert why is not None and "moves the base in the plane" in why


def test_a_tcp_name_past_a_bolted_on_tool_keeps_the_mark(tmp_path: Path) -> None:
    # No hand (nothing moves past the arm), but a shape is bolted on past its last joint: the
    # frame named 'tool0' may be the flange, not the tool's point.
    bare = [
        '<link name="tool0"/>',
        _joint("tool0_joint", "l4", "tool0", kind="fixed", xyz="0 0 0.05"),
    ]
    (m,) = _draft(tmp_path, "arm", [*_arm_on([]), *bare]).manipulators
    assert (m.tool_frame, m.stated) == ("tool0", (TOOL_AT_END,))
    torch = [
        _link("torch", size=0.03),
        _joint("torch_mount", "l4", "torch", kind="fixed", xyz="0 0 0.05"),
    ]
    (m,) = _draft(tmp_path, "arm", [*_arm_on([]), *bare, *torch]).manipulators
    assert m.tool_frame == "tool0" and m.stated == ()
    assert "'torch' hangs past the arm's last joint: a tool, whose TCP?" in m.decide


def test_the_two_eyes_of_a_stereo_pair_keep_their_marks(tmp_path: Path) -> None:
    # Two identical Gazebo cameras side by side on one mount, looking the same way: one camera
    # in a spec, or both? A third, different imager beside them is a camera of its own.
    parts = [_link("base", size=0.2), _link("mount", size=0.02)]
    parts.append(_joint("mount_joint", "base", "mount", kind="fixed", xyz="0.1 0 0.5"))
    for eye, y in (("left", "0.03"), ("right", "-0.03")):
        parts += [
            f'<link name="{eye}_eye"/>',
            _joint(f"{eye}_joint", "mount", f"{eye}_eye", kind="fixed", xyz=f"0 {y} 0"),
            f'<link name="{eye}_optical"/>',
            _joint(f"{eye}_opt", f"{eye}_eye", f"{eye}_optical", kind="fixed", rpy=_OPTICAL_RPY),
            _sensor(f"{eye}_eye"),
        ]
    d = _draft(tmp_path, "stereo", parts)
    assert len(d.cameras) == 2
    assert all(c.stated is None for c in d.cameras)
    left, right = sorted(c.body for c in d.cameras)
    assert [c.decide for c in d.cameras] == 2 * [
        [f"two eyes of one device ('{left}', '{right}'): one camera in the spec, or both?"]
    ]
