"""Drafts of shapes round 7 of the blind corpus showed (issue 30): tool frames and cameras.

Each layout is the shape of a first-sight miss on the tune half, built here from boxes (never a
copy of a robot's files, never keyed on a robot's name): a rigid tool whose tip frame is named
as nothing known; a RealSense plugin that names one frame per channel from a block of its own;
a tracking camera's fisheye pair beside an RGB-D device looking another way.
"""

from __future__ import annotations

from pathlib import Path

from lxml import etree

from robotspec.description.gazebo import channel_frames, gazebo_cameras
from tests.test_draft_blind import _arm, _draft, _joint, _link

_OPTICAL_RPY = "-1.5707963 0 -1.5707963"


def _ball_tool(tip_z: float, extra: list[str] | None = None) -> list[str]:
    """A 4-joint arm whose last link 'wrist' holds a rigid 'ball' (a 6 cm box reaching 7 cm
    out along -z) and a bare frame 'contact' ``tip_z`` along z; beside it, at the mount, a
    sensor's frame 'ft_wrist' and a legacy bare link 'wrist_8'."""
    box = '<geometry><box size="0.06 0.06 0.06"/></geometry>'
    ball = f'<visual><origin xyz="0 0 -0.04"/>{box}</visual>'
    return [
        *_arm("wrist"),
        _link("ball", ball),
        _joint("ball_joint", "wrist", "ball", "fixed", "0 0 0"),
        '<link name="contact"/>',
        _joint("contact_joint", "ball", "contact", "fixed", f"0 0 {tip_z}"),
        '<link name="ft_wrist"/>',
        _joint("ft_joint", "wrist", "ft_wrist", "fixed", "0 0 0"),
        '<link name="wrist_8"/>',
        _joint("wrist_8_joint", "ball", "wrist_8", "fixed", "0 0 0"),
        *(extra or []),
    ]


def test_the_bare_frame_at_a_rigid_tools_far_end_is_its_tool_frame(tmp_path: Path) -> None:
    # CENTAURO's ball hands: the contact point is a bare frame at the ball's far end, named as
    # nothing a TCP is named; the F/T frame and the legacy link at the mount are not it.
    d = _draft(tmp_path, "ball_tip", _ball_tool(-0.07))
    (m,) = d.manipulators
    assert m.tool_frame == "contact" and d.frames == []
    assert m.decide  # found by where it is, not stated: asked


def test_a_bare_frame_short_of_the_tools_end_is_no_tool_frame(tmp_path: Path) -> None:
    # The same frame half-way into the ball (a centre of mass, a mount): not where the tool
    # touches the work, so the draft proposes a frame at the far end instead.
    d = _draft(tmp_path, "ball_mid", _ball_tool(-0.035))
    (m,) = d.manipulators
    assert m.tool_frame != "contact"


def test_two_bare_frames_at_the_end_leave_the_choice_open(tmp_path: Path) -> None:
    # Two frames at the far end (a tip and a marker): the structure cannot choose.
    other = [
        '<link name="marker"/>',
        _joint("marker_joint", "ball", "marker", "fixed", "0.01 0 -0.07"),
    ]
    d = _draft(tmp_path, "ball_two", _ball_tool(-0.07, other))
    (m,) = d.manipulators
    assert m.tool_frame not in ("contact", "marker")


def _frame(name: str, parent: str, xyz: str = "0 0 0", rpy: str = "0 0 0") -> list[str]:
    return [f'<link name="{name}"/>', _joint(f"{name}_joint", parent, name, "fixed", xyz, rpy=rpy)]


def _sensor(link: str, name: str, kind: str, extra: str = "") -> str:
    return (
        f'<sensor name="{name}" type="{kind}"><camera><horizontal_fov>1.2</horizontal_fov>'
        f"<image><width>640</width><height>480</height></image></camera>{extra}</sensor>"
    )


def _realsense(prefix: str, parent: str, xyz: str, pitch: float = 0.0) -> list[str]:
    """A RealSense-like device: '<prefix>_link' with depth, infrared and colour frames (colour
    1.5 cm beside the link's origin), four Gazebo sensors on the link named '<prefix>color',
    '<prefix>depth', '<prefix>ired1', '<prefix>ired2', and a model plugin in a block of its own
    naming each channel's optical frame (the depth one: the colour frame)."""
    p = prefix
    parts = [_link(f"{p}_link", size=0.02)]
    parts.append(_joint(f"{p}_joint", parent, f"{p}_link", "fixed", xyz, rpy=f"0 {pitch} 0"))
    for channel, y in (("depth", 0.0), ("left_ir", 0.0), ("right_ir", -0.05), ("color", 0.015)):
        parts += _frame(f"{p}_{channel}_frame", f"{p}_link", f"0 {y} 0")
        parts += _frame(f"{p}_{channel}_optical_frame", f"{p}_{channel}_frame", rpy=_OPTICAL_RPY)
    sensors = "".join(
        _sensor(f"{p}_link", f"{p}{s}", "depth" if s == "depth" else "camera")
        for s in ("color", "ired1", "ired2", "depth")
    )
    imu = (
        f'<sensor name="{p}accel" type="imu"><plugin filename="libgazebo_ros_imu_sensor.so">'
        f"<frameName>{p}_accel_optical_frame</frameName></plugin></sensor>"
    )
    parts.append(f'<gazebo reference="{p}_link">{sensors}{imu}</gazebo>')
    parts.append(
        '<gazebo><plugin filename="librealsense_gazebo_plugin.so" name="rs">'
        f"<prefix>{p}</prefix>"
        f"<colorOpticalframeName>{p}_color_optical_frame</colorOpticalframeName>"
        f"<infrared1OpticalframeName>{p}_left_ir_optical_frame</infrared1OpticalframeName>"
        f"<infrared2OpticalframeName>{p}_right_ir_optical_frame</infrared2OpticalframeName>"
        f"<depthOpticalframeName>{p}_color_optical_frame</depthOpticalframeName>"
        "</plugin></gazebo>"
    )
    return parts


def test_a_realsense_plugin_names_each_channels_frame_by_its_prefix() -> None:
    text = "<robot name='r'><link name='base_link'/>" + "".join(
        _realsense("dev", "base_link", "0.2 0 0.3")
    )
    root = etree.fromstring((text + "</robot>").encode())
    assert channel_frames(root) == {
        "devcolor": "dev_color_optical_frame",
        "devdepth": "dev_color_optical_frame",
        "devired1": "dev_left_ir_optical_frame",
        "devired2": "dev_right_ir_optical_frame",
    }
    frames = {g.name: g.frame for g in gazebo_cameras(root)}
    assert frames["devired1"] == "dev_left_ir_optical_frame"
    assert frames["devcolor"] == "dev_color_optical_frame"


def test_a_realsense_simulated_at_its_link_is_one_camera_on_its_colour_frame(
    tmp_path: Path,
) -> None:
    # The sensors sit at the link's origin, where the depth and left infrared optical frames
    # are; the plugin publishes colour (and aligned depth) in the colour optical frame 1.5 cm
    # beside it: that frame is the camera the file names.
    parts = [_link("base_link", size=0.2), *_realsense("dev", "base_link", "0.2 0 0.3")]
    d = _draft(tmp_path, "realsense", parts)
    (cam,) = d.cameras
    assert cam.body == "dev_color_optical_frame" and cam.optical  # (its mark: confidence's)
    assert "its plugin's frame 'dev_color_optical_frame'" in (cam.source or "")


def test_a_fisheye_pair_is_one_device_and_another_device_beside_it_stays_one(
    tmp_path: Path,
) -> None:
    # A tracking camera (two fisheye sensors 6 cm apart, each publishing in its own optical
    # frame) 4 cm from an RGB-D device tilted 30 degrees down: two cameras, the pair's first.
    parts = [_link("base_link", size=0.2), *_realsense("dev", "base_link", "0.2 0 0.3", 0.52)]
    for i, y in ((1, 0.03), (2, -0.03)):
        fish = f"trk_fisheye{i}_frame"
        parts += _frame(fish, "base_link", f"0.22 {y} 0.33")
        parts += _frame(f"trk_fisheye{i}_optical_frame", fish, rpy=_OPTICAL_RPY)
        plugin = (
            f"<plugin filename='x.so'><frameName>trk_fisheye{i}_optical_frame</frameName></plugin>"
        )
        parts.append(
            f'<gazebo reference="{fish}">'
            f"{_sensor(fish, f'trkfisheye{i}', 'wideanglecamera', plugin)}</gazebo>"
        )
    d = _draft(tmp_path, "fisheye", parts)
    assert sorted(c.body for c in d.cameras) == [
        "dev_color_optical_frame",
        "trk_fisheye1_optical_frame",
    ]


def test_optical_frames_turned_round_are_rear_cameras(tmp_path: Path) -> None:
    # A legged base's bare frames rotated as REP 103 says but looking back, level and tilted
    # 45 degrees down (B2W's rear cameras), beside the same looking ahead: four cameras. A
    # frame turned to look sideways is left alone (a joint's frame is often turned so), and
    # so is one turned round on a moving link.
    back, back_down = "-1.5708 0 1.5708", "-2.3562 0 1.5708"
    parts = [_link("base_link", size=0.3)]
    for name, xyz, rpy in (
        ("front_cam", "0.4 0 0", "-1.5708 0 -1.5708"),
        ("front_depth", "0.42 0 0.06", "-2.3562 0 -1.5708"),
        ("rear_cam", "-0.4 0 0", back),
        ("rear_depth", "-0.42 0 0.04", back_down),
        ("side_frame", "0 0.2 0", "-1.5708 0 0"),
    ):
        parts += _frame(name, "base_link", xyz, rpy)
    # The same turned-round frame on a moving link (an arm's button panel): no camera.
    parts += [_link("arm", size=0.05), _joint("arm_j", "base_link", "arm", xyz="0 0 0.3")]
    parts += _frame("arm_panel", "arm", "0 0 0.1", back)
    d = _draft(tmp_path, "rear", parts)
    cams = {c.body: c for c in d.cameras}
    assert sorted(cams) == ["front_cam", "front_depth", "rear_cam", "rear_depth"]
    assert cams["rear_depth"].optical and cams["rear_depth"].decide  # by rotation: asked


def test_the_frame_an_imu_sensor_publishes_in_is_no_camera(tmp_path: Path) -> None:
    # A device's IMU publishes in a frame turned as optical frames are, named as nothing a
    # camera or an IMU is named: the Gazebo IMU sensor's plugin says whose frame it is.
    parts = [_link("base_link", size=0.2), *_realsense("dev", "base_link", "0.2 0 0.3")]
    parts += _frame("dev_m", "dev_link", "0 -0.02 0")
    parts += _frame("dev_m_optical", "dev_m", rpy=_OPTICAL_RPY)
    parts.append(
        '<gazebo reference="dev_m"><sensor name="m" type="imu"><plugin filename="x.so">'
        "<frameName>dev_m_optical</frameName></plugin></sensor></gazebo>"
    )
    d = _draft(tmp_path, "imu_frame", parts)
    assert [c.body for c in d.cameras] == ["dev_color_optical_frame"]


def test_an_rgbd_device_without_sensors_is_one_camera_on_its_colour_frame(
    tmp_path: Path,
) -> None:
    # An OpenNI-style device with no Gazebo sensor: 'cam_ir' is shorter than 'cam_rgb', but
    # the colour channel is the camera; the device's own optical frame would come first.
    parts = [_link("base_link", size=0.2), _link("cam_link", size=0.02)]
    parts.append(_joint("cam_joint", "base_link", "cam_link", "fixed", "0.2 0 0.3"))
    for channel, y in (("ir", 0.0), ("depth", 0.0), ("rgb", -0.025)):
        parts += _frame(f"cam_{channel}_frame", "cam_link", f"0 {y} 0")
        parts += _frame(f"cam_{channel}_optical_frame", f"cam_{channel}_frame", rpy=_OPTICAL_RPY)
    d = _draft(tmp_path, "openni", parts)
    assert [c.body for c in d.cameras] == ["cam_rgb_optical_frame"]
    own = _frame("cam_optical_frame", "cam_link", rpy=_OPTICAL_RPY)
    d = _draft(tmp_path, "openni_own", [*parts, *own])
    assert [c.body for c in d.cameras] == ["cam_optical_frame"]
