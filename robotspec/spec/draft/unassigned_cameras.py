"""Camera-like frames no drafted camera is on, asked as ``DECIDE`` questions (issue 30).

Why apart from ``unassigned`` (what no drafted part covers): the camera half reads frames, not
joints. A frame looks like a camera when a Gazebo sensor of an image kind sits on it, when its
link is named as one (or drawn with a mesh named as one: ``d405.stl``), or when it is a bare
frame with a generic name turned as optical frames are (x level, y down; not at a limb's end or
on a finger, where tool frames and tips are). One question per device (frames fixed to one link
within 10 cm), none where a drafted camera is on the device.
"""

from __future__ import annotations

import re
from typing import TYPE_CHECKING

import numpy as np

from robotspec.model.entities import Body
from robotspec.spec.draft.model import DraftQuestion
from robotspec.spec.draft.optical import camera_words
from robotspec.spec.draft.sensors import IMAGE_KINDS, NOT_CAMERA_WORDS
from robotspec.spec.draft.stated_cameras import DEVICE_SPAN
from robotspec.spec.draft.tree import words

if TYPE_CHECKING:
    from robotspec.spec.draft.build import Drafter

__all__ = ["SENSORS", "camera_questions"]

#: The spec section camera questions are written in.
SENSORS = "sensors"
#: An optical frame's x axis is level (|z component| below this), its y points down (below
#: minus this): a camera's image rows run level and its columns downwards.
_LEVEL, _DOWN = 0.2, 0.5
#: Names shown at most in a question.
_SHOWN = 4
_TOKENS = re.compile(r"[^a-z0-9]+")


def _rigid_root(d: Drafter, body: Body) -> Body:
    world = d.world
    while (c := world.parent_connection(body)) is not None and c.is_fixed:
        body = world.bodies[c.parent]
    return body


def _near(d: Drafter, a: Body, b: Body) -> bool:
    """Whether ``a`` and ``b`` are fixed to one link within 10 cm (one device's frames)."""
    if _rigid_root(d, a) is not _rigid_root(d, b):
        return False
    gap = float(np.linalg.norm(d.tree.position(a) - d.tree.position(b)))
    return gap <= DEVICE_SPAN


def _limb_ends(d: Drafter) -> set[int]:
    """The links (rigid roots) at the drafted limbs' ends and below the hands' moving joints."""
    world, draft = d.world, d.draft
    names = {c.tip for c in draft.chains} | {m.tool_frame for m in draft.manipulators}
    names |= {f.parent for f in draft.frames}
    out = {_rigid_root(d, world.get_body_by_name(n)).index for n in names if world.has_body(n)}
    for m in draft.manipulators:
        for j in m.joints:
            if world.has_connection(j):
                child = world.bodies[world.get_connection_by_name(j).child]
                out |= {b.index for b in world.subtree(child)}
    return out


def _turned_optical(d: Drafter, b: Body, taken: set[int]) -> bool:
    """A bare frame (a leaf without shape on a fixed joint) turned as optical frames are.

    Why: a camera whose frame has a generic name and no Gazebo sensor (a rear camera turned
    180 degrees, a depth camera tilted down) is known only by its axes in the default pose:
    x level, y pointing down, z ahead (REP 103). A frame named after nothing but turned so is
    asked about, never drafted: a tool frame or a marker may be turned so too.
    """
    world = d.world
    c = world.parent_connection(b)
    if c is None or not c.is_fixed or world.child_bodies(b) or b.visuals or b.collisions:
        return False
    if _rigid_root(d, b).index in taken:
        return False  # on a limb's end or a finger: a tool frame, a finger's tip
    rot = d.tree.poses[b.index][:3, :3]
    return abs(float(rot[2, 0])) < _LEVEL and float(rot[2, 1]) < -_DOWN


def _camera_mesh(b: Body) -> str | None:
    """The file name of ``b``'s own mesh when it is named as a camera (``d405.stl``), if any.

    Why: a link's name may say nothing (``sensor_mount``, a neutral id) while the mesh it is
    drawn with names the device (a vendor's ``d435.dae``, a ``camera.obj``): the file states
    what the link looks like. Asked about, never drafted: a camera's mount or holder is drawn
    with such a mesh too.
    """
    for shape in (*b.visuals, *b.collisions):
        uri = getattr(shape.geometry, "uri", None)
        if not isinstance(uri, str):
            continue
        file = uri.replace("\\", "/").rsplit("/", 1)[-1]
        if _named_camera(file.rsplit(".", 1)[0]):
            return file
    return None


def _named_camera(name: str) -> bool:
    """Whether a name holds a camera's word and no other sensor's word.

    A camera's word alone or closing a compound (``handeye``, ``wristcam``): the drafter's own
    test (``optical.camera_words``), so a frame is asked about exactly as it would be drafted.
    """
    w = words(name) | set(_TOKENS.split(name.lower()))
    return not w & NOT_CAMERA_WORDS and bool(camera_words(w))


def camera_questions(d: Drafter) -> list[DraftQuestion]:
    """One question per camera-like device no drafted camera is on."""
    world, tree, draft = d.world, d.tree, d.draft
    drafted = [world.get_body_by_name(c.body) for c in draft.cameras if world.has_body(c.body)]
    taken = _limb_ends(d)
    why: dict[int, str] = {}
    for link, kind in d.facts.sensor_links.items():
        if world.has_body(link) and any(k in kind for k in IMAGE_KINDS):
            why[world.get_body_by_name(link).index] = f"a Gazebo '{kind}' sensor"
    for b in world.bodies:
        if b.index in why or (b is tree.root and drafted):
            continue  # the root only when no camera is drafted (a camera's own file)
        if (words(b.name) | set(_TOKENS.split(b.name.lower()))) & NOT_CAMERA_WORDS:
            continue
        if _named_camera(b.name):
            why[b.index] = "a frame named as a camera"
        elif (mesh := _camera_mesh(b)) is not None:
            why[b.index] = f"a link whose mesh '{mesh}' is named as a camera"
        elif _turned_optical(d, b, taken):
            why[b.index] = "a bare frame turned as a camera's optical frame (z ahead, y down)"
    devices: list[list[Body]] = []
    for i in sorted(why):
        b = world.bodies[i]
        if i not in tree.inside or any(b is k or _near(d, b, k) for k in drafted):
            continue
        for dev in devices:
            if _near(d, b, dev[0]):
                dev.append(b)
                break
        else:
            devices.append([b])
    out = []
    for dev in devices:
        names = [b.name for b in dev]
        shown = ", ".join(names[:_SHOWN]) + (" ..." if len(names) > _SHOWN else "")
        text = f"{shown} ({why[dev[0].index]}) is no drafted camera: a camera? which frame?"
        out.append(DraftQuestion(SENSORS, text, frozenset(), frozenset(names)))
    return out
