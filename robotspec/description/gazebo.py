"""The cameras a URDF's ``<gazebo>`` blocks simulate: what the file states about its cameras.

Why read them: a Gazebo camera sensor names the link it is on, its field of view and image size,
and (in its plugin) the frame its images are published in. That is what ``robotspec init``
otherwise guesses from link names and rotations, and the guess is wrong on the robots that need
it most (an RGB-D device's colour, depth and infrared frames; a camera mount taken for the
camera). Gazebo classic, ``gazebo_ros`` (ROS 2) and gz-sim spell the same facts differently; all
are read here.

Conventions this module relies on (SDF): a camera sensor looks along +x of its frame, which is
the ``reference`` link moved by the sensor's ``<pose>`` (x y z roll pitch yaw); the plugin's
``frameName`` (classic), ``frame_name`` (gazebo_ros) or the camera's ``optical_frame_id`` / the
sensor's ``gz_frame_id`` (gz-sim) name the frame images are published in, by ROS convention an
optical frame (REP 103: z forward, x right, y down).

The tree comes from :func:`robotspec.files.xmlsafe.parse_xml_bytes` (no entities, no network,
bounded size); the work here is one pass over the root's direct ``<gazebo>`` children. Nothing is
raised: a block that does not parse as a camera (an unknown type, a field that is no finite
number) is left out or its field left empty, because these facts are evidence for a draft, not
input the robot needs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from lxml import etree

from robotspec.files.xmlsafe import line_of
from robotspec.model.rotations import matrix_to_rpy, rpy_to_matrix

__all__ = ["CAMERA_TYPES", "GazeboCamera", "channel_frames", "gazebo_cameras", "sensor_links"]

#: Sensor types that are image cameras (classic, gz-sim spellings).
CAMERA_TYPES = frozenset(
    {"camera", "depth", "rgbd", "multicamera", "wideanglecamera", "depth_camera", "rgbd_camera"}
    | {"thermal", "thermal_camera", "segmentation", "segmentation_camera"}
    | {"boundingbox_camera", "logical_camera_image"}
)
#: Types whose device has a depth channel besides its colour one.
DEPTH_TYPES = frozenset({"depth", "rgbd", "depth_camera", "rgbd_camera"})
#: Elements naming the frame images are published in, most specific first.
_FRAME_TAGS = (
    "optical_frame_id",  # gz-sim 8+, in <camera>
    "frame_name",  # gazebo_ros (ROS 2) plugins
    "frameName",  # gazebo classic ROS 1 plugins
    "colorOpticalframeName",  # realsense_gazebo_plugin
    "gz_frame_id",  # gz-sim sensor
    "ignition_frame_id",  # ignition-gazebo sensor
)
#: A RealSense plugin's channels: the suffix of each sensor's name after the plugin's
#: ``<prefix>``, and the element naming the frame that channel's images are published in.
_CHANNEL_TAGS = (
    ("color", "colorOpticalframeName"),
    ("depth", "depthOpticalframeName"),
    ("ired1", "infrared1OpticalframeName"),
    ("ired2", "infrared2OpticalframeName"),
)
#: Most sensors read from one robot file (a file is bounded; this bounds the records kept).
_MAX_SENSORS = 10_000


@dataclass(frozen=True)
class GazeboCamera:
    """One camera sensor of a ``<gazebo reference="LINK">`` block, as the file states it.

    ``pose``: the sensor's pose in the link's frame (x, y, z in m; roll, pitch, yaw in rad), the
    identity when the file gives none; the camera looks along +x of that frame. ``frame``: the
    frame the plugin publishes images in (``None`` when none is named). ``horizontal_fov`` (rad),
    ``width`` and ``height`` (pixels): ``None`` when absent or not a finite positive number.
    """

    name: str
    type: str
    link: str
    line: int | None
    pose: tuple[float, float, float, float, float, float]
    frame: str | None
    horizontal_fov: float | None
    width: int | None
    height: int | None

    @property
    def has_depth(self) -> bool:
        """Whether the device measures depth (an RGB-D or depth camera)."""
        return self.type in DEPTH_TYPES

    @property
    def vertical_fov(self) -> float | None:
        """The full vertical angle the image size implies (square pixels), if known."""
        h, w, ht = self.horizontal_fov, self.width, self.height
        if h is None or w is None or ht is None or h >= math.pi:
            return None
        return 2.0 * math.atan(math.tan(h / 2.0) * ht / w)


def _children(el: etree._Element, tag: str) -> list[etree._Element]:
    return [k for k in el if isinstance(k.tag, str) and k.tag == tag]


def _text(el: etree._Element | None) -> str | None:
    if el is None or el.text is None:
        return None
    text = el.text.strip()
    return text or None


def _positive(text: str | None) -> float | None:
    """A finite positive number, or None (NaN, inf, zero, words are no facts)."""
    if text is None:
        return None
    try:
        v = float(text)
    except ValueError:
        return None
    return v if math.isfinite(v) and v > 0.0 else None


def _pixels(text: str | None) -> int | None:
    v = _positive(text)
    return int(v) if v is not None and v == int(v) and v < 1e6 else None


def _pose(text: str | None) -> tuple[float, float, float, float, float, float] | None:
    if text is None:
        return None
    try:
        v = [float(t) for t in text.split()]
    except ValueError:
        return None
    if len(v) != 6 or not all(math.isfinite(x) for x in v):
        return None
    return (v[0], v[1], v[2], v[3], v[4], v[5])


def _compose(
    outer: tuple[float, float, float, float, float, float],
    inner: tuple[float, float, float, float, float, float],
) -> tuple[float, float, float, float, float, float]:
    """The pose ``inner`` (given in ``outer``'s frame) in the frame ``outer`` is given in."""
    rot = rpy_to_matrix(*outer[3:])
    at = rot @ np.asarray(inner[:3], dtype=np.float64) + np.asarray(outer[:3], dtype=np.float64)
    r, p, y = matrix_to_rpy(rot @ rpy_to_matrix(*inner[3:]))
    x, yy, z = (float(v) for v in at)
    return (x, yy, z, float(r), float(p), float(y))


def _first(sensor: etree._Element, tag: str) -> etree._Element | None:
    """The first ``tag`` at most three levels below ``sensor`` (camera/image/width), in order."""
    level = [sensor]
    for _ in range(3):
        nxt: list[etree._Element] = []
        for el in level:
            for k in el:
                if not isinstance(k.tag, str):
                    continue
                if k.tag == tag:
                    return k
                nxt.append(k)
        level = nxt
    return None


def _frame_name(text: str | None) -> str | None:
    if text is None or text in ("world", "map", "odom"):
        return None
    return text.lstrip("/") or None


def _frame(sensor: etree._Element, block: etree._Element, channels: dict[str, str]) -> str | None:
    """The frame the sensor's images are published in: the sensor's, else its block's plugin.

    ``channels``: the frames a RealSense plugin names per sensor (``channel_frames``); they
    come before the block's plugins, whose first frame element may be another channel's.
    """
    name = None
    for tag in _FRAME_TAGS:
        name = name or _frame_name(_text(_first(sensor, tag)))
    name = name or channels.get((sensor.get("name") or "").strip())
    # The block's own plugins (realsense_gazebo_plugin's), never another sensor's.
    for scope in _children(block, "plugin"):
        for tag in _FRAME_TAGS:
            name = name or _frame_name(_text(_first(scope, tag)))
    return name


def channel_frames(root: etree._Element) -> dict[str, str]:
    """The frame each sensor of a RealSense plugin publishes in, by the sensor's name.

    Why: realsense_gazebo_plugin is a model plugin (often in a ``<gazebo>`` block of its own)
    that finds its sensors by name, ``<prefix>`` + ``color``, ``depth``, ``ired1``, ``ired2``,
    and names one frame per channel; the colour channel's is the camera a person writes.
    """
    out: dict[str, str] = {}
    for block in _children(root, "gazebo"):
        for plugin in _children(block, "plugin"):
            prefix = _text(_first(plugin, "prefix"))
            if prefix is None:
                continue
            for suffix, tag in _CHANNEL_TAGS:
                frame = _frame_name(_text(_first(plugin, tag)))
                if frame is not None:
                    out.setdefault(prefix + suffix, frame)
    return out


def _camera(
    block: etree._Element, sensor: etree._Element, link: str, channels: dict[str, str]
) -> GazeboCamera | None:
    kind = (sensor.get("type") or "").strip().lower()
    if kind not in CAMERA_TYPES:
        return None
    zero = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    pose = _pose(_text(_first(sensor, "pose"))) if _children(sensor, "pose") else zero
    if pose is None:
        return None  # a pose that is no six finite numbers: where it looks is unknown
    camera = _first(sensor, "camera")
    if camera is not None and kind == "multicamera":
        # A stereo pair: the sensor's frame moved by its first camera's pose.
        inner = _pose(_text(_first(camera, "pose"))) if _children(camera, "pose") else zero
        if inner is None or any(inner[3:]):
            inner = zero if inner is None else (*inner[:3], 0.0, 0.0, 0.0)
        pose = (pose[0] + inner[0], pose[1] + inner[1], pose[2] + inner[2], *pose[3:])
    elif camera is not None and _children(camera, "pose"):
        # SDF: a <camera>'s own <pose> is relative to its sensor (Baxter's head camera is
        # pitched and turned so inside a sensor on the link's frame): the camera's frame is
        # the sensor's moved by it.
        inner = _pose(_text(_first(camera, "pose")))
        if inner is None:
            return None
        pose = _compose(pose, inner)
    scope = camera if camera is not None else sensor
    return GazeboCamera(
        name=(sensor.get("name") or "").strip() or link,
        type=kind,
        link=link,
        line=line_of(sensor),
        pose=pose,
        frame=_frame(sensor, block, channels),
        horizontal_fov=_positive(_text(_first(scope, "horizontal_fov"))),
        width=_pixels(_text(_first(scope, "width"))),
        height=_pixels(_text(_first(scope, "height"))),
    )


def _blocks(root: etree._Element) -> list[tuple[etree._Element, str]]:
    """The root's ``<gazebo reference="...">`` blocks and their links."""
    out = []
    for block in _children(root, "gazebo"):
        link = (block.get("reference") or "").strip()
        if link:
            out.append((block, link))
    return out


def gazebo_cameras(root: etree._Element) -> tuple[GazeboCamera, ...]:
    """The camera sensors of a URDF element tree's ``<gazebo>`` blocks, in file order."""
    out: list[GazeboCamera] = []
    channels = channel_frames(root)
    for block, link in _blocks(root):
        for sensor in _children(block, "sensor"):
            cam = _camera(block, sensor, link, channels)
            if cam is not None:
                out.append(cam)
            if len(out) >= _MAX_SENSORS:
                return tuple(out)
    return tuple(out)


def sensor_links(root: etree._Element) -> dict[str, str]:
    """Every link a Gazebo sensor block is on, and every frame a sensor that is no camera names.

    Each with the type of its (first) sensor: the frame an IMU's own plugin publishes in too.
    Why: a link carrying a laser, an IMU or a contact sensor is no camera whatever its name; a
    camera's reference link is its mount, not a second camera; and the frame a RealSense's IMU
    publishes in is turned as an optical frame but is the IMU's, whatever its name.
    """
    out: dict[str, str] = {}
    frames: dict[str, str] = {}
    for block, link in _blocks(root):
        for sensor in _children(block, "sensor"):
            kind = (sensor.get("type") or "").strip().lower()
            out.setdefault(link, kind)
            if kind not in CAMERA_TYPES:  # the sensor's own plugin, never its block's
                for tag in _FRAME_TAGS:
                    if (frame := _frame_name(_text(_first(sensor, tag)))) is not None:
                        frames.setdefault(frame, kind)
                        break
            if len(out) + len(frames) >= _MAX_SENSORS:
                return {**frames, **out}
    return {**frames, **out}
