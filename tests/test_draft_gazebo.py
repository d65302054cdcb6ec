"""``robotspec init`` reads what a URDF's Gazebo and control blocks state (issue 30).

Small layouts written here, one shape each (an RGB-D device with an optical child, a plugin
naming a frame, a camera without an optical frame, a diff-drive base with velocity
transmissions), then the real PR2 and HSR-B files (skipped when ../shared is absent).
"""

from __future__ import annotations

import math
from pathlib import Path

from robotspec.description.actuation import read_actuation
from robotspec.description.gazebo import gazebo_cameras
from robotspec.files.xmlsafe import parse_xml_bytes
from robotspec.spec.draft.render import render_draft
from robotspec.spec.draft.run import draft_from_files

_OPTICAL_RPY = "-1.5707963 0 -1.5707963"


def _link(name: str) -> str:
    return f'<link name="{name}"/>'


def _fixed(name: str, parent: str, child: str, xyz: str = "0 0 0", rpy: str = "0 0 0") -> str:
    return (
        f'<joint name="{name}" type="fixed"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="{xyz}" rpy="{rpy}"/></joint>'
    )


def _urdf(tmp: Path, body: str) -> Path:
    p = tmp / "robot.urdf"
    p.write_text(f'<robot name="r"><link name="base_link"/>{body}</robot>', encoding="utf-8")
    return p


def _sensor(link: str, kind: str, extra: str = "", pose: str = "") -> str:
    pose_el = f"<pose>{pose}</pose>" if pose else ""
    return (
        f'<gazebo reference="{link}"><sensor name="{link}_sensor" type="{kind}">{pose_el}'
        "<camera><horizontal_fov>1.0</horizontal_fov><image><width>640</width>"
        f"<height>480</height></image></camera>{extra}</sensor></gazebo>"
    )


def _draft(urdf: Path, tmp: Path):  # type: ignore[no-untyped-def]
    draft, _ = draft_from_files(str(urdf), None, folder=tmp, base_folder=tmp)
    return draft


def test_an_rgbd_device_is_one_camera_on_its_colour_optical_frame(tmp_path: Path) -> None:
    # A mount with colour, depth and infrared channels, each a Gazebo sensor on its body frame
    # with an optical child: one camera, the colour optical frame, stated (no DECIDE).
    parts = [_link("mount"), _fixed("mount_joint", "base_link", "mount", "0.1 0 0.5")]
    for i, channel in enumerate(("color", "depth", "infra1")):
        frame, optical = f"mount_{channel}_frame", f"mount_{channel}_optical_frame"
        parts += [
            _link(frame),
            _fixed(f"{channel}_joint", "mount", frame, f"0 {0.015 * i} 0"),
            _link(optical),
            _fixed(f"{channel}_optical_joint", frame, optical, rpy=_OPTICAL_RPY),
            _sensor(frame, "depth" if channel == "depth" else "camera"),
        ]
    d = _draft(_urdf(tmp_path, "".join(parts)), tmp_path)
    (cam,) = d.cameras
    assert cam.body == "mount_color_optical_frame" and cam.optical and not cam.decide
    assert cam.field_of_view is not None and cam.field_of_view[0] == 1.0
    assert math.isclose(
        cam.field_of_view[1], 2 * math.atan(math.tan(0.5) * 480 / 640), abs_tol=1e-4
    )
    text = render_draft(d)
    assert "from the Gazebo sensor 'mount_color_frame_sensor'" in text and "640x480 px" in text


def test_the_frame_a_plugin_names_is_the_camera(tmp_path: Path) -> None:
    # The plugin publishes in 'head_cam_optical', however its links are named ('eye' would be
    # a guess by name; the file says which frame the images are in).
    plugin = (
        '<plugin filename="libgazebo_ros_camera.so">'
        "<frame_name>head_cam_optical</frame_name></plugin>"
    )
    body = "".join(
        [
            _link("eye"),
            _fixed("eye_joint", "base_link", "eye", "0 0 1"),
            _link("head_cam_optical"),
            _fixed("cam_optical_joint", "eye", "head_cam_optical", rpy=_OPTICAL_RPY),
            _link("eye_optical_frame"),
            _fixed("eye_optical_joint", "eye", "eye_optical_frame", "0.05 0 0", _OPTICAL_RPY),
            _sensor("eye", "camera", plugin),
        ]
    )
    d = _draft(_urdf(tmp_path, body), tmp_path)
    cams = {c.body: c for c in d.cameras}
    cam = cams["head_cam_optical"]
    assert cam.optical and not cam.decide
    assert "its plugin's frame 'head_cam_optical'" in (cam.source or "")
    # The other optical frame is only a guess now that a sensor says which frame is the camera.
    assert cams["eye_optical_frame"].decide == [
        "a camera by its frame, though no Gazebo sensor of the URDF simulates it"
    ]


def test_a_camera_without_an_optical_frame_looks_along_its_links_x(tmp_path: Path) -> None:
    # No optical frame, no named frame: the sensor's link, looking along +x as Gazebo's do; a
    # sensor pose pitched down by 0.5 rad is the axis the draft states.
    body = "".join(
        [
            _link("front_sensor_mount"),
            _fixed("mount_joint", "base_link", "front_sensor_mount", "0.2 0 0.3"),
            _sensor("front_sensor_mount", "camera", pose="0 0 0 0 0.5 0"),
        ]
    )
    d = _draft(_urdf(tmp_path, body), tmp_path)
    (cam,) = d.cameras
    assert cam.body == "front_sensor_mount" and not cam.optical and not cam.decide
    assert cam.axis == (round(math.cos(0.5), 4), 0.0, round(-math.sin(0.5), 4))
    assert "forward_facing_axis: [0.8776, 0, -0.4794]" in render_draft(d)


def test_a_laser_link_named_as_a_camera_is_no_camera(tmp_path: Path) -> None:
    body = "".join(
        [
            _link("camera_laser"),
            _fixed("laser_joint", "base_link", "camera_laser", "0.2 0 0.3"),
            '<gazebo reference="camera_laser"><sensor name="scan" type="ray"/></gazebo>',
        ]
    )
    assert _draft(_urdf(tmp_path, body), tmp_path).cameras == []


def test_gazebo_fields_that_are_no_finite_numbers_are_left_out() -> None:
    root = parse_xml_bytes(
        b'<robot name="r"><gazebo reference="a"><sensor name="s" type="camera"><camera>'
        b"<horizontal_fov>nan</horizontal_fov><image><width>-3</width><height>inf</height>"
        b"</image></camera></sensor></gazebo>"
        b'<gazebo reference="b"><sensor name="t" type="camera"><pose>0 0 x 0 0 0</pose>'
        b"</sensor></gazebo></robot>",
        "robot.urdf",
    )
    (cam,) = gazebo_cameras(root)  # the second pose is no six numbers: left out
    assert (cam.horizontal_fov, cam.width, cam.height, cam.vertical_fov) == (None,) * 4


def test_transmissions_and_ros2_control_say_which_joints_are_driven() -> None:
    root = parse_xml_bytes(
        b'<robot name="r">'
        b'<transmission name="t"><joint name="left_drive">'
        b"<hardwareInterface>hardware_interface/VelocityJointInterface</hardwareInterface>"
        b'</joint><actuator name="m"/></transmission>'
        b'<transmission type="pr2_mechanism_model/PR2GripperTransmission" name="g">'
        b'<gap_joint name="gap"/><passive_joint name="finger_l"/></transmission>'
        b'<ros2_control name="s" type="system"><joint name="arm_1">'
        b'<command_interface name="position"/><state_interface name="position"/></joint>'
        b'<joint name="finger_r"><state_interface name="position"/></joint></ros2_control>'
        b'<gazebo><plugin filename="libgazebo_ros_diff_drive.so" name="d">'
        b"<left_joint>left_drive</left_joint><right_joint>right_drive</right_joint>"
        b"</plugin></gazebo></robot>",
        "robot.urdf",
    )
    a = read_actuation(root)
    assert a.velocity_only("left_drive") and not a.velocity_only("arm_1")
    assert a.joints["gap"] == frozenset() and a.passive == {"finger_l", "finger_r"}
    ((plugin),) = a.drives
    assert plugin.kind == "differential" and plugin.wheels == ("left_drive", "right_drive")


def test_pr2_cameras_are_where_its_gazebo_sensors_are(tmp_path: Path) -> None:
    # Seven camera sensors, each a camera: a stereo pair's two sensors are two cameras, each on
    # the optical frame where it is (the pair's 'wide_stereo_optical_frame', which both plugins
    # name, coincides with the left one's and is not a camera of its own).
    from .conftest import shared_path

    pr2 = shared_path("robots", "pr2")
    d, _ = draft_from_files(str(pr2 / "pr2.urdf"), None, folder=tmp_path, package_paths=[pr2])
    cams = {c.body: c for c in d.cameras}
    assert set(cams) == {
        "high_def_optical_frame",
        "wide_stereo_l_stereo_camera_optical_frame",
        "wide_stereo_r_stereo_camera_optical_frame",
        "narrow_stereo_l_stereo_camera_optical_frame",
        "narrow_stereo_r_stereo_camera_optical_frame",
        "l_forearm_cam_optical_frame",
        "r_forearm_cam_optical_frame",
    }
    assert all(c.optical and c.source for c in cams.values())
    # Each stereo pair's two eyes: one camera in a spec, or both, the files do not say (whole).
    pairs = {b for b, c in cams.items() if c.decide}
    assert pairs == {b for b in cams if "stereo" in b}
    assert all(cams[b].decide[0].startswith("two eyes of one device") for b in pairs)
    assert cams["wide_stereo_l_stereo_camera_optical_frame"].field_of_view == (1.5708, 1.287)
    assert "its plugin's frame" in (cams["high_def_optical_frame"].source or "")


def test_hsrb_cameras_are_the_optical_links_above_their_gazebo_frames(tmp_path: Path) -> None:
    # HSR-B hangs an x-forward '*_gazebo_frame' under each optical camera link; its plugins name
    # frames the URDF lacks. The cameras are the optical links, as the shipped spec says.
    from .conftest import shared_path

    hsrb = shared_path("robots", "hsrb")
    d, _ = draft_from_files(str(hsrb / "hsrb4s.urdf"), None, folder=tmp_path, package_paths=[hsrb])
    assert {c.body for c in d.cameras} == {
        "head_l_stereo_camera_link",
        "head_r_stereo_camera_link",
        "head_center_camera_frame",
        "head_rgbd_sensor_link",
        "hand_camera_frame",
    }
    assert all(c.optical and c.source for c in d.cameras)
    # The head's stereo pair is asked (one camera or both); the others are stated.
    assert {c.body for c in d.cameras if c.decide} == {
        "head_l_stereo_camera_link",
        "head_r_stereo_camera_link",
    }
    # Two wheels driven in velocity on a turntable (base_roll_joint): omnidirectional.
    assert d.drive is not None and (d.drive.type, d.drive.source) == (
        "omni",
        "the URDF's transmissions",
    )


def _wheel(name: str, y: float, parent: str = "base_link") -> str:
    # No geometry: neither its name nor its shape says 'wheel'; only the transmission does.
    return (
        f'<link name="{name}"/><joint name="{name}_joint" type="continuous">'
        f'<parent link="{parent}"/><child link="{name}"/><origin xyz="0 {y} 0.05"/>'
        '<axis xyz="0 1 0"/></joint>'
    )


def _velocity(joint: str) -> str:
    return (
        f'<transmission name="{joint}_tr"><joint name="{joint}"><hardwareInterface>'
        "hardware_interface/VelocityJointInterface</hardwareInterface></joint></transmission>"
    )


def test_a_base_whose_transmissions_drive_two_of_four_wheels_is_differential(
    tmp_path: Path,
) -> None:
    # Two driven wheels and two free ones (MiR's shape): the transmissions say which are driven.
    body = "".join(
        [
            _wheel("drive_l", 0.2),
            _wheel("drive_r", -0.2),
            _wheel("front_wheel", 0.1),  # wheels by their names
            _wheel("rear_wheel", -0.1),
            _velocity("drive_l_joint"),
            _velocity("drive_r_joint"),
            '<transmission name="t"><joint name="front_wheel_joint"/></transmission>',
            _velocity("rear_wheel_joint").replace("Velocity", "Effort"),
        ]
    )
    d = _draft(_urdf(tmp_path, body), tmp_path)
    assert d.drive is not None and d.drive.type == "differential"
    assert d.drive.source == "the URDF's transmissions"
    assert d.drive.decide is not None and d.drive.decide.startswith("2 of 4 wheel joints")
    assert d.manipulators == [] and d.chains == []  # wheels, not a gripper's fingers


def test_a_gazebo_drive_plugin_states_the_drive(tmp_path: Path) -> None:
    plugin = (
        '<gazebo><plugin filename="libgazebo_ros_planar_move.so" name="move"/></gazebo>'
        '<gazebo><plugin filename="gz-sim-diff-drive-system" name="gz::sim::systems::DiffDrive">'
        "<left_joint>drive_l_joint</left_joint><right_joint>drive_r_joint</right_joint>"
        "</plugin></gazebo>"
    )
    body = _wheel("drive_l", 0.2) + _wheel("drive_r", -0.2) + plugin
    d = _draft(_urdf(tmp_path, body), tmp_path)
    # The first plugin moving the base: planar_move (omni); the second says differential, and
    # a planar move is a simulator's shortcut for any base: asked (``whole``).
    assert d.drive is not None and d.drive.type == "omni" and d.drive.stated is None
    assert "plugins disagree" in (d.drive.decide or "")
    assert d.drive.source == "the Gazebo drive plugin 'libgazebo_ros_planar_move.so'"


def test_thousands_of_camera_sensors_are_bounded_work(tmp_path: Path) -> None:
    # A hostile file: 2,000 camera sensors on 50 links. Devices are grouped pairwise, so only
    # the first MAX_SENSORS are read; the draft's own thread does bounded work.
    import time

    from robotspec.spec.draft.stated_cameras import MAX_SENSORS

    links = "".join(
        _link(f"cam{i}") + _fixed(f"j{i}", "base_link", f"cam{i}", f"{i} 0 0") for i in range(50)
    )
    sensors = "".join(_sensor(f"cam{i % 50}", "camera") for i in range(2_000))
    start = time.thread_time()
    d = _draft(_urdf(tmp_path, links + sensors), tmp_path)
    assert time.thread_time() - start < 60.0  # CPU of this thread only; quadratic is minutes
    assert len(d.cameras) == 50 and MAX_SENSORS < 2_000  # one per link


def test_an_ackermann_plugin_is_a_differential_drive_asked(tmp_path: Path) -> None:
    # LIMO in its Ackermann mode: a car-like base moves no sideways, but robotspec has no
    # Ackermann kind: differential, its nearest, with the question.
    plugin = (
        '<gazebo><plugin filename="libgazebo_ros_ackerman.so" name="car">'
        "<leftRearJoint>rl_joint</leftRearJoint><rightRearJoint>rr_joint</rightRearJoint>"
        "</plugin></gazebo>"
    )
    body = _wheel("rl", 0.2) + _wheel("rr", -0.2) + plugin
    d = _draft(_urdf(tmp_path, body), tmp_path)
    assert d.drive is not None and d.drive.type == "differential"
    assert d.drive.decide == "an Ackermann (car-like) drive: differential is the nearest kind"
