"""Cameras read from the tree's shape where names say nothing (issue 30: ``renamed``).

Why: ``tools/corpus/robustness.py --only renamed`` drafts the tune half with every link and
joint renamed to a neutral id; rules resting on names then drafted each channel of an RGB-D
device as a camera and missed optical frames turned from a frame other than their parent.
Each test is a small layout of one shape, its links only numbered, so no name can decide it.
"""

from __future__ import annotations

from pathlib import Path

from tests.draft_support import draft_layout as _draft

_OPTICAL = "-1.5707963 0 -1.5707963"
_BOX = '<visual><geometry><box size="0.03 0.09 0.025"/></geometry></visual>'


def _link(name: str, box: bool = False) -> str:
    return f'<link name="{name}">{_BOX if box else ""}</link>'


def _fixed(name: str, parent: str, child: str, xyz: str = "0 0 0", rpy: str = "0 0 0") -> str:
    return (
        f'<joint name="{name}" type="fixed"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="{xyz}" rpy="{rpy}"/></joint>'
    )


def _sensor(link: str, kind: str) -> str:
    return (
        f'<gazebo reference="{link}"><sensor name="s{link}" type="{kind}">'
        "<camera><horizontal_fov>1.0</horizontal_fov><image><width>640</width>"
        "<height>480</height></image></camera></sensor></gazebo>"
    )


#: An RGB-D device's body frames on its mount (where each is, as a RealSense's): depth and
#: the first infrared imager at one spot, the second 5 cm aside, colour 1.5 cm the other way,
#: the IMU's accel and gyro frames at one spot behind.
_CHANNELS = {
    "n2": "0 0 0",
    "n4": "0 0 0",
    "n6": "0 -0.05 0",
    "n8": "0 0.015 0",
    "n10": "-0.0117 -0.0055 0.005",
    "n12": "-0.0117 -0.0055 0.005",
}


def _device(sensors: dict[str, str] | None = None) -> list[str]:
    """A base, a device link with a shape, and the channels' body frames with optical children."""
    parts = [_link("n0", box=True), _link("n1", box=True), _fixed("q0", "n0", "n1", "0.1 0 0.5")]
    for i, (frame, xyz) in enumerate(_CHANNELS.items()):
        optical = f"n{int(frame[1:]) + 1}"
        parts += [_link(frame), _fixed(f"q{2 * i + 1}", "n1", frame, xyz)]
        parts += [_link(optical), _fixed(f"q{2 * i + 2}", frame, optical, rpy=_OPTICAL)]
        if sensors and frame in sensors:
            parts.append(_sensor(frame, sensors[frame]))
    return parts


def test_an_unnamed_rgbd_device_is_one_camera_on_the_frame_alone_at_its_spot(
    tmp_path: Path,
) -> None:
    """Six optical frames of one device, none named: one camera, the colour imager's.

    The depth frame shares its spot with the infrared imager it is computed in, the accel
    frame with the gyro's; of the frames alone at their spots, the nearest to the device's
    first frame is the colour one. A guess by shape: asked.
    """
    draft = _draft(tmp_path, "device", _device())
    assert [c.body for c in draft.cameras] == ["n9"]
    assert draft.cameras[0].decide


def test_unnamed_gazebo_channels_of_a_depth_device_are_one_camera(tmp_path: Path) -> None:
    """Gazebo sensors on each channel, named as nothing: one device (it measures depth)."""
    sensors = {"n2": "depth", "n4": "camera", "n6": "camera", "n8": "camera"}
    draft = _draft(tmp_path, "stated", _device(sensors))
    assert [c.body for c in draft.cameras] == ["n9"]


def test_two_unnamed_gazebo_cameras_side_by_side_stay_two(tmp_path: Path) -> None:
    """Two plain camera sensors a few centimetres apart: a stereo pair a spec lists eye by eye."""
    draft = _draft(tmp_path, "pair", _device({"n6": "camera", "n8": "camera"}))
    assert {"n7", "n9"} <= {c.body for c in draft.cameras}


def test_an_optical_frame_turned_from_the_mount_above_its_parent(tmp_path: Path) -> None:
    """A camera link pitched on its mount, its optical child turned from the mount, not it."""
    parts = [
        _link("n0", box=True),
        _link("n1", box=True),
        _fixed("q0", "n0", "n1", "0.07 0 0.03", "0 1.5707963 0"),
        _link("n2"),
        _fixed("q1", "n1", "n2", "0.002 0 0.004", "0 0 -1.5707963"),
    ]
    draft = _draft(tmp_path, "pitched", parts)
    assert [c.body for c in draft.cameras] == ["n2"]


def test_an_optical_frame_beside_its_body_frame(tmp_path: Path) -> None:
    """Two bare frames at one spot, one turned from the other as REP 103 says: the camera.

    Their mount is turned anyhow (a head's motor): neither is optical from it.
    """
    parts = [
        _link("n0", box=True),
        _link("n1", box=True),
        _fixed("q0", "n0", "n1", "0 0 0.3", "0.3 -0.7 1.1"),
        _link("n2"),
        _fixed("q1", "n1", "n2", "0.03 -0.05 0.01", "1.2 0.4 -0.9"),
        _link("n3"),
        _fixed("q2", "n1", "n3", "0.03 -0.05 0.01", _body_times_optical("1.2 0.4 -0.9")),
    ]
    draft = _draft(tmp_path, "beside", parts)
    assert [c.body for c in draft.cameras] == ["n3"]


def _body_times_optical(rpy: str) -> str:
    """The rpy of a frame turned from the frame ``rpy`` as an optical frame is."""
    import numpy as np

    from robotspec.model.rotations import matrix_to_rpy, rpy_to_matrix
    from robotspec.spec.draft.optical import OPTICAL

    r, p, y = (float(v) for v in rpy.split())
    out = matrix_to_rpy(rpy_to_matrix(r, p, y) @ OPTICAL)
    return " ".join(repr(float(v)) for v in np.asarray(out))


def test_a_bare_frame_turned_as_an_upside_down_camera_on_the_body(tmp_path: Path) -> None:
    """z ahead, x left, y up (an optical frame turned half round its z) under the body: a camera."""
    parts = [
        _link("n0", box=True),
        _link("n1"),
        _fixed("q0", "n0", "n1", "0.26 0 0.2", "0 -0.1745 0"),
        _link("n2"),
        _fixed("q1", "n1", "n2", rpy="1.5707963 0 1.5707963"),
    ]
    draft = _draft(tmp_path, "upside", parts)
    assert [c.body for c in draft.cameras] == ["n2"]


def test_a_flange_frame_turned_so_past_an_arms_joint_is_no_camera(tmp_path: Path) -> None:
    """The same turn on a bare flange frame past a moving joint is a tool frame's convention."""
    limit = '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>'
    parts = [
        _link("n0", box=True),
        _link("n1", box=True),
        '<joint name="q0" type="revolute"><parent link="n0"/><child link="n1"/>'
        f'<origin xyz="0 0 0.2"/>{limit}</joint>',
        _link("n2"),
        _fixed("q1", "n1", "n2", "0 0.1 0", "0 -1.5707963 -1.5707963"),
        _link("n3"),
        _fixed("q2", "n2", "n3", rpy="1.5707963 0 1.5707963"),
    ]
    draft = _draft(tmp_path, "flange", parts)
    assert "n3" not in [c.body for c in draft.cameras]


def test_a_tree_rooted_at_the_optical_frame_of_its_shaped_body(tmp_path: Path) -> None:
    """A sensor's own file: the root a bare frame, the device's shaped body fixed at its origin
    turned back to x forward (the root is optical from it). The root is the camera."""
    parts = [
        _link("n0"),
        _link("n1", box=True),
        _fixed("q0", "n0", "n1", rpy="0 -1.5707963 1.5707963"),
        _link("n2"),
        _fixed("q1", "n0", "n2", "0.4 0 -0.04", "-1.5707963 0 0"),
    ]
    draft = _draft(tmp_path, "rooted", parts)
    assert [c.body for c in draft.cameras] == ["n0"]


def test_a_frame_on_a_link_carrying_only_an_imu_sensor_is_the_imus(tmp_path: Path) -> None:
    """A bare frame turned as an optical frame (tilted), fixed on a link whose Gazebo sensor is
    an IMU, named as nothing: the IMU's axes, no camera."""
    parts = [
        _link("n0", box=True),
        _link("n1"),
        _fixed("q0", "n0", "n1", "0.08 -0.01 -0.11", "-2.0943952 0 -1.5707963"),
        '<gazebo reference="n0"><sensor name="s0" type="imu"/></gazebo>',
    ]
    draft = _draft(tmp_path, "imu", parts)
    assert not draft.cameras
