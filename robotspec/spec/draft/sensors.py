"""Cameras and the neck that points them.

A frame is an *optical* frame when its rotation from its parent is REP 103's (z forward, x
right, y down), or that rotation tilted up or down (x still right), or, on the body the robot
faces with, turned round to look back (a rear camera), whatever its name; a frame named as a
camera without that rotation is a camera looking along its x axis. IMUs, lasers, range
finders and force sensors are never cameras, whatever their rotation. One device often has
several frames (PR2's ``wide_stereo`` with its simulated left and right cameras, an Xtion's
``rgb`` and ``depth`` channels): one camera per device, the device's own optical frame, else its
colour channel's. The neck is the run of one to three revolute joints that carries cameras and
ends the branch it is on (four for a run whose links are named as a head's).
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

from robotspec.model.entities import Body, Connection
from robotspec.spec.draft.camera_evidence import (
    MOUNT_WORDS,
    NOT_CAMERA_WORDS,
    camera_mesh,
    carries_channels,
)
from robotspec.spec.draft.facts import FileFacts
from robotspec.spec.draft.limbs import HEAD_WORDS, eyes
from robotspec.spec.draft.optical import (
    CAMERA_WORDS,
    OPTICAL,
    TILT,
    camera_words,
    device_groups,
    names_silent,
    optical_from_body,
    optical_rotation,
    pick_channel,
    root_is_optical,
    upside_down,
)
from robotspec.spec.draft.stated_cameras import (
    COLOUR,
    DEVICE_SPAN,
    StatedCamera,
    stated_cameras,
)
from robotspec.spec.draft.tree import Tree, words

__all__ = [
    "CAMERA_WORDS",
    "NOT_CAMERA_WORDS",
    "CameraFound",
    "NeckFound",
    "find_cameras",
    "find_neck",
    "stated_channels",
]

#: Gazebo sensor types that take images: the frames of other sensors are theirs, never cameras.
IMAGE_KINDS = ("camera", "depth", "rgbd", "thermal", "image")
#: REP 103 optical rotation from a body frame (x forward, z up): columns are the optical axes.
_STEM = re.compile(r"(_optical)?(_frame|_link)?$")


@dataclass(frozen=True)
class CameraFound:
    """A camera: its device name, the frame it sees from, and whether that frame is optical.

    ``stated``: the Gazebo sensor that makes it a fact (None for a camera found by its name or
    rotation). ``doubt``: why a found camera is a question although its frame looks like one.
    ``mesh``: the file it is drawn with, when that, not its name, says camera.
    """

    name: str
    body: Body
    optical: bool
    stated: StatedCamera | None = None
    doubt: str | None = None
    mesh: str | None = None


@dataclass(frozen=True)
class NeckFound:
    """A neck: root above its first joint, tip below its last, and its yaw/pitch bodies."""

    root: Body
    tip: Body
    joints: tuple[Connection, ...]
    yaw: Body | None
    pitch: Body | None


def is_optical(tree: Tree, body: Body) -> bool:
    """Whether ``body`` is rotated from its parent as REP 103 optical frames are."""
    c = tree.world.parent_connection(body)
    if c is None or not c.is_fixed:
        return False
    rot = c.origin[:3, :3]
    if optical_rotation(rot):  # REP 103's, or tilted down or up (a camera looking at the floor)
        return True
    # The same turned round (a rear camera, B2W's 'r_dc_link'): x right of a camera looking
    # back is the parent's +y, z behind within 60 degrees of the parent's -x. Only on the
    # body the robot faces with: on a limb or a torso, "behind" says nothing (Baxter's arm
    # buttons, TIAGo Pro's arm mounts are turned so).
    world = tree.world
    bare = not world.child_bodies(body) and not (body.collisions or body.visuals)
    if upside_down(rot) and bare and names_silent(body.name):
        # A bare frame of a camera mounted upside down (optical.upside_down), on the body or
        # on a shaped link; on a bare frame past a moving joint it is a flange's tool frame
        # (a UR's 'tool0' is turned so from its 'flange'). Weaker evidence than a name: only
        # where the name says nothing (Romeo's 'CameraDepth_frame' is turned so beside the
        # head's named body-frame cameras, which it must not hide).
        parent = world.bodies[c.parent]
        return tree.rigid_root(body) is tree.root or bool(parent.collisions or parent.visuals)
    behind = np.allclose(rot[:, 0], -OPTICAL[:, 0], atol=1e-3) and rot[0, 2] < -TILT
    if behind:
        return tree.rigid_root(body) is tree.root
    # Turned so from a body frame higher up its fixed joints or beside it (optical.py).
    return optical_from_body(tree, body)


def _stem(name: str) -> str:
    return _STEM.sub("", name)


def find_cameras(tree: Tree) -> list[CameraFound]:
    """One camera per device, in tree order (found once per tree: the facing asks too)."""
    if "cameras" not in tree.memo:
        tree.memo["cameras"] = _find_cameras(tree)
    return list(tree.memo["cameras"])


def stated_channels(tree: Tree) -> set[int]:
    """The bodies each Gazebo camera sensor resolves to or its plugin names, found once.

    None of them is another camera. Kept with :func:`find_cameras`'s result so that the marks
    (``whole``) read them instead of resolving every sensor a second time.
    """
    find_cameras(tree)
    channels: set[int] = tree.memo["stated_channels"]
    return channels


def _find_cameras(tree: Tree) -> list[CameraFound]:
    world = tree.world
    facts = tree.memo.get("facts")
    facts = facts if isinstance(facts, FileFacts) else FileFacts()
    # What the files state first: each Gazebo camera device, on the frame it publishes in.
    devices, channels = stated_cameras(tree, facts)
    tree.memo["stated_channels"] = channels
    stated = [CameraFound(s.name, s.body, s.optical, s) for s in devices]
    # A link a Gazebo sensor is on is that sensor's (a laser, an IMU, a camera's mount).
    taken = channels | {
        world.get_body_by_name(link).index for link in facts.sensor_links if world.has_body(link)
    }
    found: list[CameraFound] = []
    if tree.root.index not in taken and root_is_optical(tree):
        found.append(CameraFound(_stem(tree.root.name) or tree.root.name, tree.root, True))
    for b in world.bodies:
        if b.index not in tree.inside or b is tree.root or b.index in taken:
            continue
        # Whole tokens too: 'd435_link' splits into 'd' and '435' as words.
        w = words(b.name) | set(re.split(r"[^a-z0-9]+", b.name.lower()))
        if w & NOT_CAMERA_WORDS:
            continue
        optical = is_optical(tree, b)
        parent = world.parent_connection(b)
        parent_words = words(world.bodies[parent.parent].name) if parent is not None else set()
        if optical and parent_words & NOT_CAMERA_WORDS:
            continue
        if optical and parent is not None and _sensor_frame(tree, facts, b, parent.parent):
            continue
        # What a camera is bolted to is none, whatever it is named or drawn with.
        cam_words = camera_words(w) if not w & MOUNT_WORDS else set()
        mesh = None if cam_words else camera_mesh(b)
        if optical and world.child_bodies(b) and not (cam_words or mesh):
            continue  # a link turned as optical frames are, carrying others (iCub's 'neck_2')
        named = (cam_words or mesh) and (not world.child_bodies(b) or carries_channels(tree, b))
        if optical or named:
            found.append(CameraFound(_stem(b.name) or b.name, b, optical, mesh=mesh))
    found = _one_per_nameless_device(tree, found)
    # One per device: drop a camera whose name extends another's on the same rigid body, or
    # is extended by it. Optical frames first: 'camera_link' and its child
    # 'camera_color_optical_frame' are one camera, on the optical frame; the device's own frame
    # (TIAGo's 'xtion_optical_frame'), else of its channels the colour one.
    kept: list[CameraFound] = list(stated)
    order = sorted(
        found, key=lambda c: (not c.optical, _channel_rank(c.name), len(c.name), c.body.index)
    )
    for cam in order:
        carrier = tree.rigid_root(cam.body)
        device = _device(cam.name)
        dup = any(
            tree.rigid_root(k.body) is carrier
            and (
                cam.name == k.name
                or cam.name.startswith(k.name + "_")
                or k.name.startswith(cam.name + "_")
                or _device(k.name) == device
                or _pair(tree, cam, k)
            )
            for k in kept
        )
        # A body frame named as a camera, rigid with an optical frame, is that camera's link.
        optical_here = any(k.optical and tree.rigid_root(k.body) is carrier for k in kept)
        dup = dup or (not cam.optical and optical_here)
        # A frame named as nothing, beside a Gazebo camera and looking its way: a channel of
        # the device the sensor simulates (its depth frame beside the colour one it sees from).
        dup = dup or (
            names_silent(cam.name)
            and any(k.stated is not None and _beside(tree, cam.body, k.body) for k in stated)
        )
        if not dup and stated:
            cam = CameraFound(
                cam.name,
                cam.body,
                cam.optical,
                doubt="a camera by its frame, though no Gazebo sensor of the URDF simulates it",
                mesh=cam.mesh,
            )
        if not dup:
            kept.append(cam)
    kept.sort(key=lambda c: c.body.index)
    return kept


def _sensor_frame(tree: Tree, facts: FileFacts, body: Body, parent: int) -> bool:
    """Whether a bare frame named as nothing is the frame of the sensor on its parent.

    Why: a link carrying only Gazebo sensors that take no images (an IMU, a laser) often has
    the sensor's frame fixed on it, turned as an optical frame (the IMU's axes); its name, where
    it says 'imu', is the only other evidence, and a maker's ids say nothing.
    """
    kind = facts.sensor_links.get(tree.world.bodies[parent].name)
    return kind is not None and kind not in IMAGE_KINDS and names_silent(body.name)


def _beside(tree: Tree, a: Body, b: Body) -> bool:
    """Whether two frames are one device's: rigid on one link, near, looking one way."""
    return bool(device_groups(tree, [a, b]) == [[a, b]])


def _one_per_nameless_device(tree: Tree, found: list[CameraFound]) -> list[CameraFound]:
    """Optical frames whose names say nothing of cameras or channels: one per device.

    Why: names tell a device's channels apart below (``_device``, ``_pair``); frames named as
    nothing (a maker's ids, numbered links) are grouped by where they are and which way they
    look, and the device's camera is chosen by their spots (``optical.pick_channel``).
    """
    nameless = [c for c in found if c.optical and names_silent(c.body.name)]
    if len(nameless) < 2:
        return found
    keep = {pick_channel(tree, g).index for g in device_groups(tree, [c.body for c in nameless])}
    drop = {c.body.index for c in nameless} - keep
    return [c for c in found if c.body.index not in drop]


#: Words naming a channel of a camera device (one device: one camera, on its colour channel).
_CHANNELS = frozenset({"color", "colour", "rgb", "depth", "ir", "infra", "infra1", "infra2"})
#: Words naming one of a stereo pair; with a channel word, both are one device's.
_SIDES = frozenset({"left", "right", "l", "r", "1", "2"})


def _channel_rank(name: str) -> int:
    """Which of a device's frames is its camera first: its own (no channel named), colour, the rest.

    Why not the shortest name: an OpenNI device's 'camera_ir' is shorter than its 'camera_rgb'.
    """
    parts = set(re.split(r"[^a-z0-9]+", name.lower())) | words(name)
    return 0 if not parts & _CHANNELS else 1 if parts & COLOUR else 2


def _device(name: str) -> str:
    """A camera's device: its name without channel words (``head_cam_depth`` -> ``head_cam``)."""
    parts = [p for p in re.split(r"[^A-Za-z0-9]+", name.lower()) if p]
    kept = [p for p in parts if p not in _CHANNELS]
    return "_".join(kept) or name


def _pair(tree: Tree, a: CameraFound, b: CameraFound) -> bool:
    """Whether two channel frames are one RGB-D device's infrared pair ('camera_left_ir').

    Named alike but for a side word, with a channel word, and a few centimetres apart: two
    depth cameras on a robot's two sides (ANYmal's) are two devices.
    """
    words_a = [p for p in re.split(r"[^A-Za-z0-9]+", a.name.lower()) if p]
    words_b = [p for p in re.split(r"[^A-Za-z0-9]+", b.name.lower()) if p]
    if not (set(words_a) | set(words_b)) & _CHANNELS:
        return False
    strip = _CHANNELS | _SIDES
    if [p for p in words_a if p not in strip] != [p for p in words_b if p not in strip]:
        return False
    gap = float(np.linalg.norm(tree.position(a.body) - tree.position(b.body)))
    return gap <= DEVICE_SPAN


def find_neck(tree: Tree, cameras: list[CameraFound], limb_tops: list[Body]) -> NeckFound | None:
    """The neck carrying the most cameras: 1-3 revolute joints ending a branch, cameras on top.

    Of a run, only its last revolute joints count; what is below them (a lift) is not the neck.
    """
    world = tree.world
    best: tuple[int, float, NeckFound] | None = None
    for seg in tree.segments:
        # A head whose eyes turn on their own ends where they split (limbs.eyes).
        if (tree.moving_children(seg.end) and not eyes(tree, seg.end)) or not seg.joints:
            continue
        # The run's last revolute joints (HSR-B's head sits on a lift that mimics the arm's).
        joints: list[Connection] = []
        for c in reversed(seg.joints):
            if c.type.value not in ("revolute", "continuous") or c.is_mimic:
                break
            joints.insert(0, c)
        most = 4 if any(words(b.name) & HEAD_WORDS for b in seg.bodies) else 3
        if not 1 <= len(joints) <= most:
            continue
        if any(world.is_ancestor(top, seg.start) for top in limb_tops):
            continue  # on an arm (a wrist camera's pan), not a neck
        tip = world.bodies[joints[-1].child]
        carried = [c for c in cameras if world.is_ancestor(tip, c.body)]
        if not carried:
            continue
        root = world.bodies[joints[0].parent]
        yaw = pitch = None
        for c in joints:
            axis = np.abs(tree.axis_in_root(c))
            child = world.bodies[c.child]
            if axis[2] > 0.9 and yaw is None:
                yaw = child
            elif axis[1] > 0.9 and pitch is None:
                pitch = child
        neck = NeckFound(root, tip, tuple(joints), yaw, pitch)
        key = (len(carried), float(tree.position(tip)[2]))
        if best is None or key > best[:2]:
            best = (key[0], key[1], neck)
    return None if best is None else best[2]
