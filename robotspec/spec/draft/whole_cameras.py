"""Whether a Gazebo-stated camera is stated WHOLE: the checks that keep its ``DECIDE`` mark.

Why apart from ``whole`` (issue 30, item 3): a Gazebo sensor states that a camera exists and
where it sees from, not which of the device's frames a spec names, nor whether two eyes are one
camera or two; these checks read the device around the sensor (``whole``'s table, camera row).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from robotspec.model.entities import Body
from robotspec.model.rotations import rpy_to_matrix
from robotspec.spec.draft.confidence import CAMERA_GAZEBO
from robotspec.spec.draft.model import DraftCamera
from robotspec.spec.draft.sensors import stated_channels
from robotspec.spec.draft.stated_cameras import COLOUR, DEVICE_SPAN, MAX_SENSORS, channel_words
from robotspec.spec.draft.tool_frames import own_geometry

if TYPE_CHECKING:
    from robotspec.spec.draft.build import Drafter

__all__ = ["SPOT", "camera_marks"]

#: Gazebo sensor types whose images a person uses as a camera's (the rest: thermal, labels...).
_PLAIN = frozenset(
    {"camera", "depth", "rgbd", "multicamera", "wideanglecamera", "depth_camera", "rgbd_camera"}
)
#: The widest stereo baseline (m) two identical imagers of one device have (a MultiSense S21's
#: 21 cm; a ZED's 12 cm, HSR-B's head pair 14 cm).
_STEREO_BASE = 0.25
#: How near (m) a frame must be to a sensor to be where it sees from.
SPOT = 0.01
_SPOT = SPOT
#: The cosine within which a frame's z axis is a view direction (8 degrees).
_ALONG = 0.99
#: The cosine within which a drafted frame looks the way its Gazebo sensor does (25 degrees).
_AGREE = 0.9
#: A Gazebo camera looks along +x of its sensor's frame.
_X = np.array([1.0, 0.0, 0.0])
#: Fixed joints walked above and below a camera's frame for the frames fixed to it.
_RIGID_DEPTH = 3


#: Words naming a device's colour channel.
def _fixed_to(d: Drafter, body: Body) -> list[Body]:
    """The frames fixed to ``body`` (a few fixed joints above it, and below those)."""
    world = d.world
    top = body
    for _ in range(_RIGID_DEPTH):
        c = world.parent_connection(top)
        if c is None or not c.is_fixed or top is d.tree.root:
            break
        top = world.bodies[c.parent]
    out, level = [top], [top]
    for _ in range(2 * _RIGID_DEPTH):
        level = [
            k
            for b in level
            for k in world.child_bodies(b)
            if (c := world.parent_connection(k)) is not None and c.is_fixed
        ]
        out += level
    return out


# ------------------------------------------------------------------------------ cameras
def _camera_doubt(d: Drafter, cam: DraftCamera) -> str | None:
    """What of a Gazebo-stated camera the sensor leaves to inference, if anything."""
    world, tree, facts = d.world, d.tree, d.facts
    body = world.get_body_by_name(cam.body)
    root = d.tree.rigid_root(body)
    at = tree.poses[body.index][:3, 3]
    sensors = [
        g
        for g in facts.cameras[:MAX_SENSORS]
        if world.has_body(g.link)
        and world.get_body_by_name(g.link).index in tree.inside
        and d.tree.rigid_root(world.get_body_by_name(g.link)) is root
        and float(np.linalg.norm(tree.poses[world.get_body_by_name(g.link).index][:3, 3] - at))
        <= DEVICE_SPAN
    ]
    odd = sorted({g.type for g in sensors} - _PLAIN)
    if odd:
        return f"a Gazebo '{odd[0]}' sensor: a camera whose images a person uses?"
    # The frames the device's other sensors resolve to, not drafted: the colour channel was
    # chosen among them by its name.
    drafted = {c.body for c in d.draft.cameras}
    taken = [tree.poses[world.get_body_by_name(c).index][:3, 3] for c in drafted]
    others = [
        b.name
        for b in (world.bodies[i] for i in stated_channels(d.tree))
        if b.name not in drafted
        and d.tree.rigid_root(b) is root
        and float(np.linalg.norm(tree.poses[b.index][:3, 3] - at)) <= DEVICE_SPAN
        # a frame where a drafted camera is (a stereo pair's frame on its left eye): the same
        and all(float(np.linalg.norm(tree.poses[b.index][:3, 3] - t)) > _SPOT for t in taken)
    ]
    if others and not _only_colour(cam.body, others):
        return f"the device's sensors see from '{others[0]}' too: which channel is the camera?"
    spots = [
        tree.poses[world.get_body_by_name(g.link).index] @ np.array([*g.pose[:3], 1.0])
        for g in sensors
    ]
    stated = {g.frame for g in sensors if g.frame} | {g.link for g in sensors}
    if cam.body not in stated and all(float(np.linalg.norm(s[:3] - at)) > _SPOT for s in spots):
        return f"'{cam.body}' is neither where the sensor sees from nor a frame it names"
    # Another frame of the device looking the same way (a colour optical frame beside the
    # depth one the sensor sits on; the second eye of a stereo pair): the sensor states a
    # device, not which of its frames a spec names, nor whether a pair is one camera or two.
    view = _view(d, cam, body)
    # The way the sensor looks (its frame's +x, Gazebo's convention) against the way the frame
    # drafted for it looks: apart, the file states a camera, not that this frame is its view.
    looks = [
        tree.poses[world.get_body_by_name(g.link).index][:3, :3]
        @ np.asarray(rpy_to_matrix(*g.pose[3:]))
        @ _X
        for g in sensors
    ]
    if looks and max(float(v @ view) for v in looks) < _AGREE:
        return f"'{cam.body}' looks another way than its Gazebo sensor: which frame is the camera?"
    for k in _fixed_to(d, body):
        if k is body or float(np.linalg.norm(tree.poses[k.index][:3, 3] - at)) > DEVICE_SPAN:
            continue
        # A frame the draft did not take (a drafted neighbour is a camera of its own).
        frame = k.name not in drafted and not world.child_bodies(k) and not own_geometry(k)
        here = tree.poses[k.index][:3, 3]
        frame = frame and all(float(np.linalg.norm(here - t)) > _SPOT for t in taken)
        if frame and _only_colour(cam.body, [k.name]):
            continue  # the colour channel beside the device's others, each named so
        if frame and float(tree.poses[k.index][:3, 2] @ view) > _ALONG:
            return f"'{k.name}', fixed beside it, looks the same way: which frame is the camera?"
    return None


def _only_colour(chosen: str, others: list[str]) -> bool:
    """Whether ``chosen`` alone is named as a colour channel (its device's others are not).

    Why: a device's channels are told apart only by their names; when the chosen frame says
    colour and no other frame of the device does, the names agree with the spec's convention
    (the colour image is the camera). Anything less (no channel words, two colour frames, the
    chosen one named depth) is a guess, and keeps its mark.
    """
    return _colour(chosen) and not any(_colour(o) for o in others)


def _colour(name: str) -> bool:
    return bool(channel_words(name) & COLOUR)


def _view(d: Drafter, cam: DraftCamera, body: Body) -> np.ndarray:
    """The way a drafted camera looks, in the root's frame."""
    if cam.optical or cam.looks_along_z:
        axis: tuple[float, float, float] = (0.0, 0.0, 1.0)
    else:
        axis = cam.axis or (1.0, 0.0, 0.0)
    return np.asarray(d.tree.poses[body.index][:3, :3] @ np.array(axis))


def _pairs(d: Drafter) -> dict[str, str]:
    """Gazebo-stated cameras that are two eyes of one device, each with the question.

    Two identical imagers (the same field of view) on one rigid mount, within a stereo rig's
    baseline of each other and looking the same way are a stereo pair: whether a spec lists
    one camera or both is a convention the files do not settle (a tracking camera's two
    fisheyes, a head's pair).
    """
    world, tree = d.world, d.tree
    cams = [
        (c, world.get_body_by_name(c.body))
        for c in d.draft.cameras
        if c.stated == CAMERA_GAZEBO and c.field_of_view is not None and world.has_body(c.body)
    ]
    out: dict[str, str] = {}
    for i, (a, ab) in enumerate(cams):
        for b, bb in cams[i + 1 :]:
            if a.field_of_view != b.field_of_view or tree.rigid_root(ab) is not tree.rigid_root(bb):
                continue
            gap = float(np.linalg.norm(tree.poses[ab.index][:3, 3] - tree.poses[bb.index][:3, 3]))
            if gap > _STEREO_BASE or float(_view(d, a, ab) @ _view(d, b, bb)) < _ALONG:
                continue
            why = "two eyes of one device ('{}', '{}'): one camera in the spec, or both?"
            out.setdefault(a.body, why.format(a.body, b.body))
            out.setdefault(b.body, why.format(a.body, b.body))
    return out


def camera_marks(d: Drafter) -> None:
    """Give back the mark of every Gazebo-stated camera the sensor states only part of."""
    pairs = _pairs(d)
    for cam in d.draft.cameras:
        if cam.stated == CAMERA_GAZEBO and not cam.decide and d.world.has_body(cam.body):
            if (why := pairs.get(cam.body) or _camera_doubt(d, cam)) is not None:
                cam.decide.append(why)
                cam.stated = None
