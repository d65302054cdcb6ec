"""The DECIDE rule (``robotspec/spec/draft/confidence.py``) on small layouts (issue 30, item 3).

A part is unmarked only when a file states it; names, shapes and defaults keep their mark.
"""

from __future__ import annotations

from pathlib import Path

from robotspec.spec.draft.confidence import drive_question, gripper_question
from tests.test_draft_blind import _arm, _draft, _draft_srdf, _jaws, _joint, _link

#: REP 103's optical rotation from a body frame.
_OPTICAL = "-1.5708 0 -1.5708"


def _mimic(parts: list[str], joint: str, leader: str) -> list[str]:
    """``parts`` with ``joint`` made a mimic of ``leader``."""
    tag = f'<joint name="{joint}" '
    return [
        p.replace("</joint>", f'<mimic joint="{leader}"/></joint>') if p.startswith(tag) else p
        for p in parts
    ]


def _gripper(tcp_on: str | None, mimic: bool) -> list[str]:
    parts = [
        *_arm("wrist"),
        _link("mount"),
        _joint("mount_joint", "wrist", "mount", "fixed"),
        _link("jaw_base", size=0.04),
        _joint("jaw_base_joint", "mount", "jaw_base", "fixed", "0 0 0.03"),
        *(p.replace(' 0.03 0"', ' 0.03 0.05"') for p in _jaws("jaw_base", 0.03)),
    ]
    if tcp_on is not None:
        parts += [
            '<link name="hand_tcp"/>',
            _joint("tcp_j", tcp_on, "hand_tcp", "fixed", "0 0 0.1"),
        ]
    return _mimic(parts, "right_jaw_q", "left_jaw_q") if mimic else parts


def test_a_mimic_coupled_gripper_with_a_tcp_on_the_hand_is_stated(tmp_path: Path) -> None:
    (m,) = _draft(tmp_path, "stated", _gripper("jaw_base", mimic=True)).manipulators
    assert m.is_gripper and m.tool_frame == "hand_tcp" and m.decide == []
    # The facing follows from the tool frame and the tips: a plain comment, no question.
    assert m.facing == "grasping along the hand's reach"


def test_uncoupled_fingers_and_a_tcp_beside_the_hand_are_questions(tmp_path: Path) -> None:
    (m,) = _draft(tmp_path, "free", _gripper("jaw_base", mimic=False)).manipulators
    assert m.decide == [gripper_question(False, False)]
    # A TCP on the mount beside the gripper, not on it: named so, but where is the question.
    (m,) = _draft(tmp_path, "beside", _gripper("mount", mimic=True)).manipulators
    assert m.tool_frame == "hand_tcp"
    assert any("hangs beside the hand" in r for r in m.decide)


def test_a_proposed_tool_frame_is_a_question_on_the_manipulator(tmp_path: Path) -> None:
    d = _draft(tmp_path, "proposed", _gripper(None, mimic=True))
    (m,) = d.manipulators
    assert [f.name for f in d.frames] == [m.tool_frame]
    assert m.decide == [f"its tool frame '{m.tool_frame}' is proposed (description.frames)"]


def test_an_optical_frame_found_by_its_rotation_is_asked_and_an_ir_pair_is_its_device(
    tmp_path: Path,
) -> None:
    # A RealSense's frames on a mount: colour, depth and the left/right infrared optical frames.
    parts = [*_arm("wrist"), _link("camera_link", size=0.02)]
    parts.append(_joint("camera_joint", "base", "camera_link", "fixed", "0.1 0 0.3"))
    for i, channel in enumerate(("color", "depth", "left_ir", "right_ir")):
        frame = f"camera_{channel}_optical_frame"
        parts += [f'<link name="{frame}"/>']
        parts.append(
            _joint(f"{frame}_j", "camera_link", frame, "fixed", f"0 {0.015 * i} 0", rpy=_OPTICAL)
        )
    d = _draft(tmp_path, "rgbd", parts)
    (cam,) = d.cameras
    assert cam.body == "camera_color_optical_frame" and cam.optical
    assert cam.decide == ["an optical frame by its rotation; no Gazebo sensor states it"]


def test_a_floating_virtual_joint_on_a_bolted_arm_is_drafted_fixed_and_asked(
    tmp_path: Path,
) -> None:
    vj = '<virtual_joint name="vj" type="floating" parent_frame="world" child_link="base"/>'
    d = _draft_srdf(tmp_path, "bolted", _arm("wrist"), vj)
    assert d.drive is not None and d.drive.type == "fixed" and d.drive.joint is None
    assert d.drive.decide == drive_question("floating", moves=False)


def test_the_rule_for_drives_and_grippers() -> None:
    # Stated: a floating base that legs move, a fixed one nothing moves, a mimic-coupled pair.
    assert drive_question("floating", moves=True) is None
    assert drive_question("fixed", moves=False) is None
    assert gripper_question(coupled=True, one_driven=True) is None
    # Asked: a planar base (omni or differential?), a fixed one on wheels, uncoupled fingers.
    assert drive_question("planar", moves=True) and drive_question("fixed", moves=True)
    assert gripper_question(coupled=False, one_driven=True)


def test_a_linkage_finger_ends_at_the_link_its_joints_move(tmp_path: Path) -> None:
    # Robotiq 85: each side a driven (or mimic) knuckle carrying a finger on a fixed joint, and
    # an inner knuckle carrying the finger tip on a mimic joint, both ends at one depth.
    parts = [*_arm("wrist"), _link("palm", size=0.04)]
    parts.append(_joint("palm_j", "wrist", "palm", "fixed"))
    for side, y in (("left", 0.03), ("right", -0.03)):
        tip_xyz = f"0 {y} 0.04"
        parts += [
            _link(f"{side}_knuckle"),
            _joint(f"{side}_knuckle_q", "palm", f"{side}_knuckle", xyz=f"0 {y} 0.05", axis="1 0 0"),
            _link(f"{side}_finger"),
            _joint(f"{side}_finger_j", f"{side}_knuckle", f"{side}_finger", "fixed", f"0 {y} 0.01"),
            _link(f"{side}_inner"),
            _joint(f"{side}_inner_q", "palm", f"{side}_inner", xyz=f"0 {y / 2} 0.06", axis="1 0 0"),
            _link(f"{side}_tip"),
            _joint(f"{side}_tip_q", f"{side}_inner", f"{side}_tip", xyz=tip_xyz, axis="1 0 0"),
        ]  # fmt: skip
    for joint in ("right_knuckle_q", "left_inner_q", "right_inner_q", "left_tip_q", "right_tip_q"):
        parts = _mimic(parts, joint, "left_knuckle_q")
    (m,) = _draft(tmp_path, "linkage", parts).manipulators
    assert m.is_gripper and m.thumb is not None and m.finger is not None
    assert {m.thumb.tip, m.finger.tip} == {"left_tip", "right_tip"}
    # Mimic-coupled, but each side ends at two links: which is the tip is asked.
    assert any("several end links" in r for r in m.decide)


def test_two_depth_cameras_on_two_sides_are_two_devices_and_a_light_is_none(
    tmp_path: Path,
) -> None:
    # ANYmal's left and right depth cameras: named alike but for the side, 40 cm apart; a
    # payload's light turned as optical frames are is no camera.
    parts = list(_arm("wrist"))
    for name, y in (("depth_camera_left", 0.2), ("depth_camera_right", -0.2), ("payload", 0.0)):
        frame = f"{name}_depth_optical_frame" if name != "payload" else "payload_light"
        parts += [f'<link name="{frame}"/>']
        parts.append(_joint(f"{frame}_j", "base", frame, "fixed", f"0.1 {y} 0.3", rpy=_OPTICAL))
    cams = _draft(tmp_path, "sides", parts).cameras
    assert sorted(c.body for c in cams) == [
        "depth_camera_left_depth_optical_frame",
        "depth_camera_right_depth_optical_frame",
    ]


def test_a_pan_tilt_head_without_a_camera_is_drafted_as_a_marked_chain(tmp_path: Path) -> None:
    # Booster T1's head: links 'h1', 'h2', a yaw then a pitch on top of the body; no camera
    # frame, so no neck a spec can hold, but the question must be asked (a marked chain).
    parts = [
        *_arm("wrist"),
        _link("h1"),
        _joint("h_yaw", "base", "h1", xyz="0 0 0.4", axis="0 0 1"),
        _link("h2"),
        _joint("h_pitch", "h1", "h2", xyz="0 0 0.05", axis="0 1 0"),
    ]
    d = _draft(tmp_path, "pantilt", parts)
    head = next(c for c in d.chains if c.joints == {"h_yaw", "h_pitch"})
    assert (head.role, head.root, head.tip) == ("chain", "base", "h2") and head.decide


def test_an_optical_frame_tilted_down_and_a_frame_named_after_its_model_are_cameras(
    tmp_path: Path,
) -> None:
    # A camera looking 30 degrees down at the floor ahead (REP 103's rotation, then a tilt about
    # its x axis), and an Orbbec Astra's body frame named after its model (on the arm).
    parts = [
        *_arm("wrist"),
        '<link name="front_optical"/>',
        _joint("front_j", "base", "front_optical", "fixed", "0.2 0 0.3", rpy="-2.0944 0 -1.5708"),
        '<link name="astra_link"/>',
        _joint("astra_j", "link1", "astra_link", "fixed", "0.2 0 0.1"),
    ]
    cams = {c.body: c for c in _draft(tmp_path, "tilted", parts).cameras}
    assert set(cams) == {"front_optical", "astra_link"}
    assert cams["front_optical"].optical and not cams["astra_link"].optical
    assert all(c.decide for c in cams.values())  # no sensor states either: both asked


def test_a_finger_ending_at_a_bare_frame_is_asked(tmp_path: Path) -> None:
    # PR2's right finger tip carries 'l_finger_tip_frame': the frame is taken for the tip, but
    # the files do not say it is the finger's tip rather than a frame past the pad.
    parts = _gripper("jaw_base", mimic=True)
    parts += ['<link name="pad_frame"/>', _joint("pad_j", "right_jaw", "pad_frame", "fixed")]
    (m,) = _draft(tmp_path, "padframe", parts).manipulators
    assert m.finger is not None and m.finger.tip == "pad_frame"
    assert any("bare frame at the finger's end" in r for r in m.decide)
