"""What a link's name, mesh and bare child frames say about it being a camera (issue 30).

Why its own module (split from ``sensors``, which finds cameras by where frames lie and how they
are turned): these are the weaker kinds of evidence, read where structure is silent. A link named
as another sensor is none; one named as a mount or holder is what a camera is bolted to; a link
drawn with a mesh named as a camera is one; a device's link carrying only its channels' bare
frames is the device's camera.
"""

from __future__ import annotations

import re

from robotspec.model.entities import Body
from robotspec.spec.draft.optical import camera_words
from robotspec.spec.draft.stated_cameras import channel_words
from robotspec.spec.draft.tree import Tree, words

__all__ = ["COLOUR", "MOUNT_WORDS", "NOT_CAMERA_WORDS", "camera_mesh", "carries_channels"]

#: Words of sensors that are never cameras, whatever their frames' rotation.
NOT_CAMERA_WORDS = frozenset(
    {"imu", "laser", "lidar", "scan", "hokuyo", "accelerometer", "accel", "gyro", "range"}
    | {"sonar", "ft", "force", "torque", "contact", "velodyne", "ultrasound", "projector"}
    | {"gps", "magnetometer", "bumper", "led", "axis", "light", "lamp", "microphone", "mic"}
    | {"speaker", "flashlight", "thermal_sensor"}
)
#: Words of a link that holds a camera rather than being one.
MOUNT_WORDS = frozenset({"mount", "holder", "bracket", "support", "adapter"})
#: Words of a colour channel.
COLOUR = frozenset({"color", "colour", "rgb"})


def camera_mesh(body: Body) -> str | None:
    """The file name of the mesh a link is drawn with, when named as a camera (``d435.dae``).

    Why: a link named as nothing (a maker's ids) drawn with a mesh named as a camera is that
    camera as surely as one so named; never one named as a mount or holder (drawn with the
    camera's mesh too), nor a mesh named as another sensor. Asked like any camera by its name.
    """
    if words(body.name) & MOUNT_WORDS:
        return None
    for shape in (*body.visuals, *body.collisions):
        uri = getattr(shape.geometry, "uri", None)
        if not isinstance(uri, str):
            continue
        file = uri.replace("\\", "/").rsplit("/", 1)[-1]
        stem = file.rsplit(".", 1)[0]
        tokens = words(stem) | set(re.split(r"[^a-z0-9]+", stem.lower()))
        if not tokens & (NOT_CAMERA_WORDS | MOUNT_WORDS) and camera_words(tokens):
            return file
    return None


def carries_channels(tree: Tree, body: Body) -> bool:
    """Whether a link named as a camera is a device carrying its channels' frames.

    Why: a stereo or RGB-D device is often written as its link with bare frames fixed below it,
    one per channel other than colour (a right infrared imager 5 cm aside, a depth frame), none
    turned as an optical frame; the device's link is the camera a person names, not one of its
    channels (one device, one camera). Only when everything below it is such a frame on a fixed
    joint (a lens or colour frame below a camera is where it sees from: that frame stays the
    camera), and never a link named as a mount or holder (what a camera is bolted to is none).
    """
    world = tree.world
    if words(body.name) & MOUNT_WORDS:
        return False
    below = world.subtree(body)[1:]
    return bool(below) and all(
        (c := world.parent_connection(k)) is not None
        and c.is_fixed
        and not (k.collisions or k.visuals)
        and (ch := channel_words(k.name))
        and not ch & COLOUR
        for k in below
    )
