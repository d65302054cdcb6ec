"""Optical frames and camera devices read from the tree's shape, not from names (issue 30).

Why its own module: a camera frame is told by where it is and how it is turned, which holds
for any maker's names. An *optical* frame (REP 103: z forward, x right, y down) is turned so
from a *body* frame of the camera (x forward, z up): its parent, as most files write it, or a
frame higher up the fixed joints it hangs on (a camera link pitched on its mount carrying an
optical frame turned from the mount), or the camera's body frame beside it at the same spot
(two sibling frames, one per convention). One RGB-D device carries several optical frames a
few centimetres apart looking one way (colour, depth, two infrared imagers, an IMU's accel and
gyro frames): one device is one camera. Where names tell the channels apart, ``sensors`` uses
them; where they do not, the shape does: the depth image is computed in one infrared imager's
frame, so those two frames share one spot, as an IMU's accel and gyro frames do; the colour
imager stands alone at its own spot, the nearest such to the device's first frame.
"""

from __future__ import annotations

import re
from collections.abc import Sequence

import numpy as np

from robotspec.model.entities import Body
from robotspec.spec.draft.tree import Tree, words

__all__ = [
    "CAMERA_CLOSINGS",
    "CAMERA_WORDS",
    "OPTICAL",
    "TILT",
    "camera_words",
    "device_groups",
    "names_silent",
    "optical_from_body",
    "optical_rotation",
    "pick_channel",
    "root_is_optical",
    "upside_down",
]

CAMERA_WORDS = frozenset(
    {"camera", "cam", "optical", "rgb", "rgbd", "xtion", "kinect", "realsense", "stereo"}
    | {"webcam", "zed", "eye", "vision", "d435", "d415", "asus"}
    # Device models a frame is often named after.
    | {"d405", "d435i", "d455", "d457", "l515", "zed2", "zed2i", "zedm", "kinect2", "azure"}
    | {"astra", "orbbec", "femto", "gemini", "primesense", "carmine", "oak", "mynteye"}
    | {"flir", "basler", "ximea", "pointgrey", "bumblebee", "multisense"}
)
#: How a word glued from a place and a camera's word ends (``handeye``, ``wristcam``).
CAMERA_CLOSINGS = ("camera", "cam", "eye")


def camera_words(tokens: set[str]) -> set[str]:
    """The tokens of a name that name a camera: a camera's word, or a compound closing in one.

    Why compounds: makers glue a place to the word (``handeye``, ``headcamera``, ``wristcam``:
    a hand-eye camera, a head camera); the glued word names a camera as surely as the word
    alone. A closing needs a few letters before it ('scam', 'geye' are no compounds).
    """
    glued = {
        t for t in tokens if any(t.endswith(c) and len(t) >= len(c) + 3 for c in CAMERA_CLOSINGS)
    }
    return (tokens & CAMERA_WORDS) | glued


#: Words that tell one frame of a device from another: channels and sides.
TELLING_WORDS = frozenset(
    {"color", "colour", "rgb", "depth", "ir", "infra", "infrared", "ired", "fisheye"}
    | {"left", "right", "l", "r"}
)

#: REP 103 optical rotation from a body frame (x forward, z up): columns are the optical axes.
OPTICAL = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])
#: The cosine within which a tilted optical frame's z axis stays of its body frame's x (60 deg).
TILT = 0.5
#: How near (m) two frames are to be at one spot.
SAME_SPOT = 1e-3
#: How far apart (m) the optical frames of one device may be (a RealSense's are 1.5 to 5 cm).
DEVICE_SPAN = 0.1
#: The cosine within which two frames look one way (8 degrees).
ALONG = 0.99
#: Fixed joints climbed above a frame for the body frame it is turned from.
_UP = 3


def names_silent(name: str) -> bool:
    """Whether a frame's name says nothing of cameras, channels or sides (a maker's ids).

    Why: where a name speaks, the device's frames are told apart by it (``sensors``,
    ``stated_cameras``); only where none does is the device read from the shape alone.
    """
    tokens = words(name) | set(re.split(r"[^a-z0-9]+", name.lower()))
    tokens |= {t.rstrip("0123456789") for t in tokens}
    return not tokens & (CAMERA_WORDS | TELLING_WORDS)


def optical_rotation(rot: np.ndarray) -> bool:
    """Whether ``rot`` (a frame in its body frame's axes) is REP 103's, or it tilted up/down."""
    if np.allclose(rot, OPTICAL, atol=1e-3):
        return True
    # Tilted down or up (a camera looking at the floor ahead): x still right (-y of the body
    # frame), z ahead within 60 degrees of its x.
    return bool(np.allclose(rot[:, 0], OPTICAL[:, 0], atol=1e-3) and rot[0, 2] > TILT)


def upside_down(rot: np.ndarray) -> bool:
    """Whether ``rot`` is an optical frame turned half round its z: a camera mounted upside down.

    z still ahead (within 60 degrees, tilted up or down), x left and y up: the image rotated
    180 degrees, as a camera hung under its mount writes it (a base camera's, a head's screen
    camera's). Only a bare leaf named as nothing is read so (``sensors.is_optical``,
    ``optical_from_body``): weaker evidence than a name.
    """
    return bool(np.allclose(rot[:, 0], -OPTICAL[:, 0], atol=1e-3) and rot[0, 2] > TILT)


def _bare_leaf(tree: Tree, body: Body) -> bool:
    return not tree.world.child_bodies(body) and not (body.collisions or body.visuals)


def optical_from_body(tree: Tree, body: Body) -> bool:
    """Whether ``body`` is turned as an optical frame from a body frame above or beside it.

    Its parent is checked by ``sensors.is_optical``; here the frames higher up the fixed joints
    it hangs on (up to its rigid root), and a bare sibling frame at the same spot.
    """
    world = tree.world
    c = world.parent_connection(body)
    if c is None or not c.is_fixed or not _bare_leaf(tree, body):
        return False
    pose = tree.poses[body.index]
    up = world.bodies[c.parent]
    for _ in range(_UP):
        above = world.parent_connection(up)
        if above is None or up is tree.root or not above.is_fixed:
            break
        up = world.bodies[above.parent]
        rot = tree.poses[up.index][:3, :3].T @ pose[:3, :3]
        if optical_rotation(rot) or (upside_down(rot) and names_silent(body.name)):
            return True
    for k in world.child_bodies(world.bodies[c.parent]):
        kc = world.parent_connection(k)
        if k is body or kc is None or not kc.is_fixed or world.child_bodies(k):
            continue
        if k.collisions or k.visuals:
            continue
        near = float(np.linalg.norm(tree.poses[k.index][:3, 3] - pose[:3, 3])) <= SAME_SPOT
        rot = tree.poses[k.index][:3, :3].T @ pose[:3, :3]
        if near and (optical_rotation(rot) or (upside_down(rot) and names_silent(body.name))):
            return True
    return False


def root_is_optical(tree: Tree) -> bool:
    """Whether the tree's root is a camera's optical frame, its shaped body turned from it.

    Why: a sensor's own description (a stereo head's) often roots its tree at the camera's
    optical frame and hangs the device's shaped body below it, turned back to x forward. The
    root is then a bare frame whose one shaped child, fixed at its origin, sees it turned as
    an optical frame is from its body frame.
    """
    world, root = tree.world, tree.root
    if root.collisions or root.visuals:
        return False
    for k in world.child_bodies(root):
        c = world.parent_connection(k)
        if c is None or not c.is_fixed or not (k.collisions or k.visuals):
            continue
        if float(np.linalg.norm(c.origin[:3, 3])) <= SAME_SPOT and optical_rotation(
            c.origin[:3, :3].T
        ):
            return True
    return False


def device_groups(tree: Tree, frames: Sequence[Body]) -> list[list[Body]]:
    """``frames`` (optical) grouped into devices: rigid on one link, near, looking one way.

    Why: without names, one RGB-D device's colour, depth, infrared and IMU frames are as many
    optical frames; a frame joins a group when it is rigid with, within ``DEVICE_SPAN`` of and
    looking the same way as one of its frames. Groups and their members keep ``frames``' order.
    """
    groups: list[list[Body]] = []
    for f in frames:
        home = next((g for g in groups if any(_one_device(tree, f, o) for o in g)), None)
        if home is None:
            groups.append([f])
        else:
            home.append(f)
    return groups


def _one_device(tree: Tree, a: Body, b: Body) -> bool:
    if tree.rigid_root(a) is not tree.rigid_root(b):
        return False
    pa, pb = tree.poses[a.index], tree.poses[b.index]
    near = float(np.linalg.norm(pa[:3, 3] - pb[:3, 3])) <= DEVICE_SPAN
    return near and float(pa[:3, 2] @ pb[:3, 2]) > ALONG


def pick_channel(tree: Tree, group: Sequence[Body]) -> Body:
    """The device's camera among its optical frames, by their spots (module docstring).

    A frame alone at its spot before frames sharing one (depth with its infrared imager, an
    IMU's accel with its gyro); of those, the nearest to the device's first frame.
    """
    spots = [tree.poses[b.index][:3, 3] for b in group]

    def shared(i: int) -> bool:
        return any(
            j != i and float(np.linalg.norm(spots[i] - spots[j])) <= SAME_SPOT
            for j in range(len(group))
        )

    first = spots[0]
    order = sorted(
        range(len(group)),
        key=lambda i: (shared(i), float(np.linalg.norm(spots[i] - first)), group[i].index),
    )
    return group[order[0]]
