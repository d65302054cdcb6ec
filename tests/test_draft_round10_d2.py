"""Tool frames and cameras read from the files' shapes (issue 30, round 10, tools and cameras).

Why: each rule here was found on robots the drafter was not tuned for and is stated for any
maker's files: where a bare arm's last link already has its frame on its end face, where a rigid
hand bolted at the last joint ends, where a hand without shapes is grasped, which frame of a
stereo device is its camera. Each test is a small layout of the rule's shape.
"""

from __future__ import annotations

from functools import partial
from pathlib import Path

from tests.draft_support import draft_layout as _draft
from tests.draft_support import joint_xml

_MASS = (
    '<inertial><mass value="0.3"/>'
    '<inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial>'
)
_joint = partial(joint_xml, limit=(-1.0, 1.0))


def _link(name: str, box: str | None = "0.05 0.05 0.05", at: str = "0 0 0") -> str:
    """A link with a mass, and a box of ``box`` (x y z, m) centred at ``at`` (None: no shape)."""
    shape = (
        ""
        if box is None
        else f'<collision><origin xyz="{at}"/><geometry><box size="{box}"/></geometry></collision>'
    )
    return f'<link name="{name}">{_MASS}{shape}</link>'


def _arm(joints: int = 6) -> list[str]:
    """A fixed base and ``joints`` revolute joints in series, links 'base', 'link1'... ."""
    parts = [_link("base", "0.2 0.2 0.1")]
    for i in range(1, joints + 1):
        axis = "0 0 1" if i % 2 else "0 1 0"
        parent = "base" if i == 1 else f"link{i - 1}"
        parts += [_link(f"link{i}"), _joint(f"joint{i}", parent, f"link{i}", axis=axis)]
    return parts


def test_a_last_link_whose_origin_is_on_its_end_face_is_the_flange(tmp_path: Path) -> None:
    """A thin last link (a disc 8 mm thick ending 4 mm out): no new frame 4 mm from its origin."""
    parts = _arm(5) + [
        _link("link6", "0.06 0.06 0.008", at="0 0 0"),
        _joint("joint6", "link5", "link6", axis="0 0 1"),
    ]
    draft = _draft(tmp_path, "thin", parts)
    [m] = draft.manipulators
    assert m.tool_frame == "link6"
    assert not draft.frames
    assert any("end face" in q for q in m.decide)  # still asked: no tool is named there


def test_a_last_link_reaching_out_still_gets_a_flange_frame(tmp_path: Path) -> None:
    """The same arm whose last link reaches 6 cm along its axis: a frame at the far end."""
    parts = _arm(5) + [
        _link("link6", "0.06 0.06 0.06", at="0 0 0.03"),
        _joint("joint6", "link5", "link6", axis="0 0 1"),
    ]
    draft = _draft(tmp_path, "long", parts)
    [m] = draft.manipulators
    [frame] = draft.frames
    assert m.tool_frame == frame.name and frame.parent == "link6"
    assert frame.xyz == (0.0, 0.0, 0.06)


def _rigid_hand(box: str, at: str) -> list[str]:
    """Five joints, then a shaped 'hand' fixed at the last joint's own origin (no offset)."""
    return _arm(5) + [
        _link("hand", box, at=at),
        _joint("hand_mount", "link5", "hand", kind="fixed", xyz="0 0 0"),
    ]


def test_a_rigid_hand_bolted_at_the_last_joint_is_grasped_at_its_far_end(
    tmp_path: Path,
) -> None:
    """A hand link fixed at the joint, reaching 13 cm along the last axis: the frame is there."""
    draft = _draft(tmp_path, "rigid_hand", _rigid_hand("0.04 0.04 0.13", "0 0 0.065"))
    [m] = draft.manipulators
    [frame] = draft.frames
    assert m.tool_frame == frame.name and frame.parent == "hand"
    assert frame.xyz == (0.0, 0.0, 0.13)


def test_a_flange_plate_at_the_last_joint_stays_the_tool_frame(tmp_path: Path) -> None:
    """The same link as a plate 1 cm thick: it is the flange itself, no frame proposed."""
    draft = _draft(tmp_path, "plate", _rigid_hand("0.06 0.06 0.01", "0 0 0.005"))
    [m] = draft.manipulators
    assert m.tool_frame == "hand" and not draft.frames


def test_a_hand_without_shapes_is_grasped_between_its_fingers(tmp_path: Path) -> None:
    """No shape anywhere (meshes missing): the frame is proposed between the fingers' last links.

    Without it the palm itself became the tool frame; the palm is where the frame hangs.
    """
    parts = [_link("base", None), _link("palm", None)]
    parts += [_joint("wrist", "base", "palm", axis="0 0 1")]
    for f, y in (("a", 0.03), ("b", 0.0), ("c", -0.03)):
        parts += [_link(f"{f}1", None), _link(f"{f}2", None)]
        parts += [_joint(f"{f}_j1", "palm", f"{f}1", xyz=f"0 {y} 0.08")]
        parts += [_joint(f"{f}_j2", f"{f}1", f"{f}2", xyz="0 0 0.04")]
    parts += [_link("t1", None), _link("t2", None)]
    parts += [_joint("t_j1", "palm", "t1", xyz="0.03 0 0.03", axis="0 0 1")]
    parts += [_joint("t_j2", "t1", "t2", xyz="0.03 0 0.02")]
    draft = _draft(tmp_path, "shapeless_hand", parts)
    [m] = draft.manipulators
    assert m.tool_frame != "palm"
    [frame] = [f for f in draft.frames if f.name == m.tool_frame]
    assert frame.parent == "palm" and frame.xyz[2] > 0.08


def _base_with_device(child: str) -> list[str]:
    """A box base with a bare 'front_camera_link' carrying one bare frame 5 cm aside."""
    return [
        _link("base_link", "0.5 0.4 0.2"),
        _link("front_camera_link", None),
        _joint("cam_mount", "base_link", "front_camera_link", kind="fixed", xyz="0.25 0 0.1"),
        _link(child, None),
        _joint("cam_channel", "front_camera_link", child, kind="fixed", xyz="0 -0.05 0"),
    ]


def test_a_device_link_carrying_its_infrared_frame_is_the_camera(tmp_path: Path) -> None:
    """A depth device written as its link and a right infrared frame: one camera, the link."""
    draft = _draft(tmp_path, "device", _base_with_device("front_camera_right_ir_frame"))
    assert [c.body for c in draft.cameras] == ["front_camera_link"]
    assert draft.cameras[0].decide  # named only: a question


def test_a_lens_frame_below_a_camera_link_stays_the_camera(tmp_path: Path) -> None:
    """A frame below the camera's link that names no channel (its lens) is where it sees from."""
    draft = _draft(tmp_path, "lens", _base_with_device("front_camera_lens"))
    assert [c.body for c in draft.cameras] == ["front_camera_lens"]


def test_a_camera_mount_carrying_channels_is_no_camera(tmp_path: Path) -> None:
    """A link named as a camera's mount is what it is bolted to, whatever hangs below it."""
    parts = [
        _link("base_link", "0.5 0.4 0.2"),
        _link("camera_mount", None),
        _joint("m", "base_link", "camera_mount", kind="fixed", xyz="0.25 0 0.1"),
        _link("camera_depth_frame", None),
        _joint("d", "camera_mount", "camera_depth_frame", kind="fixed", xyz="0 -0.05 0"),
    ]
    draft = _draft(tmp_path, "mount", parts)
    assert [c.body for c in draft.cameras] == ["camera_depth_frame"]


def test_a_kinect_v2_gets_no_kinect_v1_preset(tmp_path: Path) -> None:
    """'kinect2' names a Kinect v2, whose optics are not the v1 preset's; 'kinect' names a v1."""
    for name, preset in (("head_kinect2_link", None), ("head_kinect_link", "kinect_v1")):
        parts = [
            _link("base_link", "0.5 0.4 0.2"),
            _link(name, "0.05 0.25 0.05"),
            _joint("k", "base_link", name, kind="fixed", xyz="0.2 0 0.5"),
        ]
        (tmp_path / name).mkdir()
        [cam] = _draft(tmp_path / name, "kinect", parts).cameras
        assert cam.preset == preset


def _drill(bit: str, name: str = "tool_link") -> list[str]:
    """Six joints, a flange, a drill body, its bit: a cylinder centred on its origin."""
    cylinder = (
        f'<link name="{name}">{_MASS}<collision><geometry>'
        f'<cylinder radius="0.004" length="{bit}"/></geometry></collision></link>'
    )
    return _arm(6) + [
        _link("flange", "0.06 0.06 0.01", at="0 0 0.005"),
        _joint("flange_joint", "link6", "flange", kind="fixed", xyz="0 0 0.05"),
        _link("drill_link", "0.05 0.05 0.07", at="0 0 0.035"),
        _joint("drill_joint", "flange", "drill_link", kind="fixed", xyz="0 0 0.0"),
        cylinder,
        _joint("bit_joint", "drill_link", name, kind="fixed", xyz="0.01 0 0.07"),
    ]


def test_a_drill_bit_centred_on_its_origin_is_worked_at_its_tip(tmp_path: Path) -> None:
    """A bit 7.4 cm long centred on its link's origin: the tool frame is 3.7 cm out, on the bit.

    The way from the flange to the bit is 8 degrees off the bit's axis; the bit's own axis is
    the one taken.
    """
    draft = _draft(tmp_path, "drill", _drill("0.074"))
    [m] = draft.manipulators
    [frame] = [f for f in draft.frames if f.name == m.tool_frame]
    assert frame.parent == "tool_link" and frame.xyz == (0.0, 0.0, 0.037)


def test_a_small_tool_link_centred_on_its_origin_stays_the_tool_frame(tmp_path: Path) -> None:
    """A 1 cm stub centred on its origin (a marker cube): its origin is its tip, no new frame."""
    draft = _draft(tmp_path, "stub", _drill("0.01"))
    [m] = draft.manipulators
    assert m.tool_frame == "tool_link"


def test_a_shaped_link_named_as_a_tcp_stays_the_tool_frame(tmp_path: Path) -> None:
    """'tool0' with a rigid tool drawn on it is the maker's TCP: its shape does not move it."""
    draft = _draft(tmp_path, "tool0", _drill("0.074", name="tool0"))
    [m] = draft.manipulators
    assert m.tool_frame == "tool0"


def test_a_name_glued_to_a_camera_word_is_a_camera(tmp_path: Path) -> None:
    """'handeye', 'wristcam': a place glued to a camera's word names a camera (asked)."""
    for name in ("handeye", "wristcam"):
        parts = _arm(6) + [_link(name, "0.04 0.04 0.03"), _joint("m", "link6", name, kind="fixed")]
        (tmp_path / name).mkdir()
        [cam] = _draft(tmp_path / name, "glued", parts).cameras
        assert cam.body == name and cam.decide


def test_a_cameras_own_pose_inside_its_sensor_turns_its_view(tmp_path: Path) -> None:
    """SDF: a <camera>'s <pose> is in its sensor's frame; here it turns the view onto +z.

    The plugin publishes in the link itself; the camera's pose says that link's z is the view,
    so the link is an optical frame the file states (no question about its axis).
    """
    from robotspec.description.gazebo import gazebo_cameras
    from robotspec.files.xmlsafe import parse_xml_bytes
    from robotspec.model.rotations import rpy_to_matrix

    sensor = (
        '<gazebo reference="hand_camera"><sensor name="hand_camera" type="camera">'
        "<camera><pose>0 0 0 0 -1.570796327 1.570796327</pose>"
        "<horizontal_fov>1.0</horizontal_fov><image><width>640</width><height>480</height>"
        '</image></camera><plugin name="p" filename="libgazebo_ros_camera.so">'
        "<frameName>hand_camera</frameName></plugin></sensor></gazebo>"
    )
    parts = _arm(6) + [
        _link("hand_camera", "0.02 0.02 0.02"),
        _joint("cam_mount", "link6", "hand_camera", kind="fixed", xyz="0 0.05 0"),
        sensor,
    ]
    (cam,) = gazebo_cameras(
        parse_xml_bytes(("<robot>" + "".join(parts) + "</robot>").encode(), "r")
    )
    view = rpy_to_matrix(*cam.pose[3:])[:, 0]  # a camera looks along +x of its frame
    assert [round(float(v), 6) + 0.0 for v in view] == [0.0, 0.0, 1.0]
    [drafted] = _draft(tmp_path, "hand_camera", parts).cameras
    assert drafted.body == "hand_camera" and drafted.optical and not drafted.decide


def test_a_moving_last_link_named_as_a_tool_is_no_tool_frame(tmp_path: Path) -> None:
    """'eef' on the arm's last (revolute) joint is a part that turns, not a TCP frame.

    The tool frame is proposed on it, at the far end of its shape, as for any bare arm.
    """
    parts = _arm(5) + [
        _link("arm_eef", "0.03 0.03 0.04", at="0 0 0.02"),
        _joint("joint6", "link5", "arm_eef", axis="0 0 1"),
    ]
    draft = _draft(tmp_path, "eef", parts)
    [m] = draft.manipulators
    [frame] = draft.frames
    assert m.tool_frame == frame.name and frame.parent == "arm_eef"
    assert frame.xyz == (0.0, 0.0, 0.04)


def test_a_shapeless_jaw_named_as_the_gripper_is_no_tcp(tmp_path: Path) -> None:
    """Meshes missing: a jaw 'gripper_link1' that the other jaw mimics is bare like every link.

    Bareness marks a frame (a hand's TCP on the joint its fingers mimic) only in a hand that
    has shapes; here the tool frame is proposed between the jaws, never on one of them.
    """
    parts = [_link("base", None)]
    for i in range(1, 7):
        axis = "0 0 1" if i % 2 else "0 1 0"
        parent = "base" if i == 1 else f"link{i - 1}"
        parts += [_link(f"link{i}", None), _joint(f"joint{i}", parent, f"link{i}", axis=axis)]
    parts += [_link("gripper_base", None)]
    parts += [_joint("mount", "link6", "gripper_base", kind="fixed", xyz="0 0 0.08")]
    for k, (y, ax, mimic) in enumerate((("0.02", "0 1 0", None), ("-0.02", "0 -1 0", "j1")), 1):
        parts += [_link(f"gripper_link{k}", None)]
        parts += [
            _joint(
                f"j{k}", "gripper_base", f"gripper_link{k}", "prismatic", f"0 {y} 0.06", ax, mimic
            )
        ]
    draft = _draft(tmp_path, "shapeless_gripper", parts)
    [m] = draft.manipulators
    assert m.tool_frame not in ("gripper_link1", "gripper_link2")


def _drawn_with(tmp_path: Path, name: str, mesh: str) -> list[str]:
    """A base carrying a leaf ``name`` drawn with ``mesh`` (an empty STL written here)."""
    (tmp_path / "meshes").mkdir(exist_ok=True)
    (tmp_path / "meshes" / mesh).write_text("solid m\nendsolid m\n")
    visual = f'<visual><geometry><mesh filename="meshes/{mesh}"/></geometry></visual>'
    return [
        _link("base_link", "0.5 0.4 0.2"),
        f'<link name="{name}">{_MASS}{visual}</link>',
        _joint("m", "base_link", name, kind="fixed", xyz="0.25 0 0.3"),
    ]


def test_a_link_named_as_nothing_drawn_with_a_cameras_mesh_is_a_camera(tmp_path: Path) -> None:
    """A neutral id drawn with 'd435.stl': the file says camera (asked, with the mesh named)."""
    [cam] = _draft(tmp_path, "mesh", _drawn_with(tmp_path, "n4", "d435.stl")).cameras
    assert cam.body == "n4" and any("d435.stl" in q for q in cam.decide)


def test_a_mount_or_a_sensor_mesh_is_no_camera(tmp_path: Path) -> None:
    """A link named as a mount, or a mesh named as a lidar beside a camera's word, is none."""
    for name, mesh in (("camera_mount", "d435.stl"), ("n5", "lidar_camera_unit.stl")):
        (tmp_path / name).mkdir()
        assert (
            _draft(tmp_path / name, "mesh", _drawn_with(tmp_path / name, name, mesh)).cameras == []
        )
