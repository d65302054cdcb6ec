"""The frames a URDF's Gazebo camera sensors see from: cameras the files state, not guesses.

A Gazebo camera looks along +x of its sensor frame (the ``reference`` link moved by the sensor's
``<pose>``). Its images are published in the frame its plugin names, by ROS convention an optical
frame (z forward); when it names none, the optical frame under its link is the camera (the
frame a person writes in a spec), and when there is none either, the link itself, with the axis
Gazebo looks along. One device, one camera: PR2's stereo pair names one frame from two sensors,
and a RealSense's colour, depth and infrared sensors sit a few centimetres apart on one mount;
the colour channel is the camera.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

from robotspec.description.gazebo import GazeboCamera
from robotspec.model.entities import Body
from robotspec.model.rotations import rpy_to_matrix
from robotspec.spec.draft.facts import FileFacts
from robotspec.spec.draft.model import DraftCamera
from robotspec.spec.draft.optical import OPTICAL, device_groups, names_silent, pick_channel
from robotspec.spec.draft.tree import Tree, words

__all__ = ["COLOUR", "StatedCamera", "channel_words", "fill_stated", "stated_cameras"]

#: Words naming a channel of an RGB-D device (a tracking camera's fisheye pair: one device).
_CHANNELS = frozenset(
    {"color", "colour", "rgb", "depth", "ir", "infra", "infrared", "ired", "fisheye"}
)
COLOUR = frozenset({"color", "colour", "rgb"})
#: How far apart (m) the channels of one device may be (a RealSense's are 1.5 to 5 cm).
DEVICE_SPAN = 0.1
#: Camera sensors read per robot (a robot has tens; grouping devices compares pairs of them).
MAX_SENSORS = 256
#: How near (m) a frame must be to the sensor to be where it sees from.
SPOT = 0.01
#: Fixed joints searched above and below a sensor's link for its optical frame.
_OPTICAL_DEPTH = 3
#: The cosine within which a frame's axis is the camera's view (8 degrees).
_ALONG = 0.99


@dataclass(frozen=True)
class StatedCamera:
    """A Gazebo camera resolved to a frame of the tree.

    ``optical``: it looks along +z of ``body``; otherwise along ``axis`` (in ``body``'s frame).
    ``how``: which rule chose the frame (written into the draft as its source). ``doubt``: why
    the axis is still a question (the plugin names the sensor's own x-forward link as if it
    were an optical frame), else None.
    """

    name: str
    body: Body
    fact: GazeboCamera
    optical: bool
    axis: tuple[float, float, float]
    how: str
    doubt: str | None = None


def channel_words(text: str) -> set[str]:
    """The channel words of a frame's name (``ired1`` -> ``ired``; colour, depth, infrared...)."""
    ws = words(text) | set(re.split(r"[^a-z0-9]+", text.lower()))
    # 'ired1', 'infra2', 'color1': a channel word with a number after it.
    return {w.rstrip("0123456789") for w in ws} & _CHANNELS


def _rep103(tree: Tree, body: Body) -> bool:
    c = tree.world.parent_connection(body)
    return c is not None and c.is_fixed and bool(np.allclose(c.origin[:3, :3], OPTICAL, atol=1e-3))


def _rigid_group(tree: Tree, link: Body) -> list[Body]:
    """Frames fixed to ``link``: up to three fixed joints above it, and below those."""
    world = tree.world
    tops = [link]
    for _ in range(_OPTICAL_DEPTH):
        c = world.parent_connection(tops[-1])
        if c is None or not c.is_fixed or tops[-1] is tree.root:
            break
        tops.append(world.bodies[c.parent])
    out = list(tops)
    level = list(tops)
    for _ in range(_OPTICAL_DEPTH):
        nxt = []
        for b in level:
            for k in world.child_bodies(b):
                c = world.parent_connection(k)
                if c is not None and c.is_fixed and k not in out:
                    nxt.append(k)
        out += nxt
        level = nxt
    return out


def _optical_at(
    tree: Tree, link: Body, view: np.ndarray, at: np.ndarray, named: Body | None
) -> Body | None:
    """The frame fixed to ``link``, where the sensor is, whose +z is the sensor's view.

    Below the link (an optical child) or above it (HSR-B's optical camera link carrying an
    x-forward ``*_gazebo_frame``). Of several in one place: one below the link, the sensor's
    own (a RealSense's left infrared and depth frames coincide; PR2's left stereo camera and
    the pair's frame too), then the plugin's frame, then one named for colour, then one
    rotated as REP 103 says.
    """
    found: list[tuple[int, int, int, int, int, Body]] = []
    for k in _rigid_group(tree, link):
        pose = tree.poses[k.index]
        if float(pose[:3, 2] @ view) < _ALONG:
            continue
        if float(np.linalg.norm(pose[:3, 3] - at)) > SPOT:
            continue
        channel = channel_words(k.name)
        rank = 0 if channel & COLOUR else 2 if channel else 1
        below = 0 if tree.world.is_ancestor(link, k) else 1
        rep = 0 if _rep103(tree, k) else 1
        found.append((below, 0 if k is named else 1, rank, rep, k.index, k))
    return min(found, key=lambda f: f[:5])[5] if found else None


def _device_frame(tree: Tree, body: Body, view: np.ndarray) -> Body | None:
    """The device's own optical frame beside a channel's (TIAGo's 'xtion_optical_frame').

    Why: a URDF that gives an RGB-D device an optical frame of its own, named as the channel's
    without the channel word and looking the same way, means that frame as the camera (the specs
    written for such robots name it); the colour channel sits a centimetre or two beside it.
    """
    world = tree.world
    parts = re.split(r"([^A-Za-z0-9]+)", body.name)
    kept = [p for p in parts if p.lower().rstrip("0123456789") not in _CHANNELS]
    if len(kept) == len(parts):
        return None
    name = re.sub(r"[^A-Za-z0-9]{2,}", "_", "".join(kept)).strip("_")
    if name == body.name or not world.has_body(name):
        return None
    other = world.get_body_by_name(name)
    if other.index not in tree.inside or tree.rigid_root(other) is not tree.rigid_root(body):
        return None
    pose = tree.poses[other.index]
    far = float(np.linalg.norm(pose[:3, 3] - tree.poses[body.index][:3, 3]))
    return other if far <= DEVICE_SPAN and float(pose[:3, 2] @ view) > _ALONG else None


def _own_frame(
    tree: Tree, link: Body, named: Body | None, view: np.ndarray, at: np.ndarray
) -> bool:
    """Whether the plugin's frame is this sensor's own channel, a little beside where it is.

    Why: a RealSense plugin simulates its colour, depth and infrared images at the device's
    link and publishes them in the colour optical frame 1.5 cm beside it; that frame is the
    camera a person writes. Only a frame rigid with the link, within a device's span, looking
    the sensor's way, and named by sensors at this one spot (``_resolve``'s caller checks).
    """
    if named is None or tree.rigid_root(named) is not tree.rigid_root(link):
        return False
    pose = tree.poses[named.index]
    near = float(np.linalg.norm(pose[:3, 3] - at)) <= DEVICE_SPAN
    return near and float(pose[:3, 2] @ view) > _ALONG


def _resolve(tree: Tree, g: GazeboCamera, shared: frozenset[str]) -> StatedCamera | None:
    """The frame a Gazebo camera ``g`` sees from (``shared``: frames named from several spots)."""
    world = tree.world
    if not world.has_body(g.link):
        return None
    link = world.get_body_by_name(g.link)
    if link.index not in tree.inside:
        return None
    pose = tree.poses[link.index]
    view = pose[:3, :3] @ rpy_to_matrix(*g.pose[3:])[:, 0]
    at = (pose @ np.array([*g.pose[:3], 1.0]))[:3]
    named: Body | None = None
    if g.frame is not None and world.has_body(g.frame):
        named = world.get_body_by_name(g.frame)
        named = named if named.index in tree.inside else None
    # Where the sensor is, an optical frame looking its way is the camera; the plugin's frame
    # elsewhere (PR2's 'wide_stereo_optical_frame', between the pair) names the device's.
    # A frame the plugin names for sensors at this one spot only, just beside it, is its own.
    own = g.frame not in shared and _own_frame(tree, link, named, view, at)
    body = named if own else _optical_at(tree, link, view, at, named)
    how = f"the optical frame where it is on '{g.link}'"
    if body is not None and body is named:
        how = f"its plugin's frame '{named.name}'"
    elif body is None and named is not None:
        body, how = named, f"its plugin's frame '{named.name}'"
    elif body is None:
        body, how = link, f"its link '{g.link}' (a Gazebo camera looks along +x)"
    device = _device_frame(tree, body, view)
    if device is not None:
        body, how = device, f"{how}, its device's own frame '{device.name}'"
    d = tree.poses[body.index][:3, :3].T @ view
    axis = (round(float(d[0]), 4), round(float(d[1]), 4), round(float(d[2]), 4))
    doubt = None
    # A sensor put on an optical frame itself looks along its x in Gazebo; the frame says +z.
    optical = float(d[2]) > _ALONG or (_rep103(tree, body) and "optical" in words(body.name))
    if not optical and named is link and float(d[0]) > _ALONG:
        # The plugin publishes images in the sensor's own link as if it were an optical frame.
        doubt = (
            f"the Gazebo sensor '{g.name}' looks along +x of '{body.name}', and its plugin"
            " publishes images in it as in an optical frame (+z)"
        )
    name = re.sub(r"(_optical)?(_frame|_link)?$", "", body.name) or body.name
    return StatedCamera(name, body, g, optical, axis, f"the Gazebo sensor '{g.name}': {how}", doubt)


def _one_device(tree: Tree, a: StatedCamera, b: StatedCamera) -> bool:
    """Whether two sensors are channels of one device (or one camera named twice)."""
    if a.body is b.body or a.fact.link == b.fact.link:
        return True
    # Frames named as nothing (a maker's ids): a depth sensor and a camera beside it, rigid
    # on one link and looking one way, are one RGB-D device. Two plain cameras so placed may
    # be a stereo pair a spec lists eye by eye (PR2's): apart.
    if names_silent(a.body.name) and names_silent(b.body.name):
        rgbd = a.fact.has_depth or b.fact.has_depth
        return rgbd and device_groups(tree, [a.body, b.body]) == [[a.body, b.body]]
    # Channels by their frames' names: a stereo depth camera (Go1's five) is a device alone.
    if not (channel_words(a.body.name) and channel_words(b.body.name)):
        return False
    if tree.rigid_root(a.body) is not tree.rigid_root(b.body):
        return False
    far = tree.poses[a.body.index][:3, 3] - tree.poses[b.body.index][:3, 3]
    # One device's channels look one way: a tracking camera beside an RGB-D one (CENTAURO's
    # T265 4 cm from its D435i, tilted otherwise) is another device.
    same_way = float(_view(tree, a) @ _view(tree, b)) > _ALONG
    return float(np.linalg.norm(far)) <= DEVICE_SPAN and same_way


def _view(tree: Tree, c: StatedCamera) -> np.ndarray:
    """The way a stated camera looks, in the world (default pose), a unit vector."""
    local = np.array([0.0, 0.0, 1.0]) if c.optical else np.asarray(c.axis, dtype=np.float64)
    v: np.ndarray = np.asarray(tree.poses[c.body.index][:3, :3] @ local, dtype=np.float64)
    n = float(np.linalg.norm(v))
    return v / n if n > 1e-9 else v


def _preference(c: StatedCamera) -> tuple[int, int]:
    channel = channel_words(c.body.name) | channel_words(c.fact.name)
    if channel & COLOUR:
        return (0, 0)
    return (1 if not channel else 2, 0 if c.optical else 1)


def stated_cameras(tree: Tree, facts: FileFacts) -> tuple[list[StatedCamera], set[int]]:
    """One camera per device the Gazebo sensors simulate, in file order; its colour channel.

    Also the indices of every body a sensor resolved to or its plugin names, the channels left
    out included: none of them is another camera.
    """
    sensors = facts.cameras[:MAX_SENSORS]
    # Frames the plugins of sensors at different spots name (PR2's stereo pair's middle).
    spots: dict[str, set[tuple[str, tuple[float, ...]]]] = {}
    for g in sensors:
        if g.frame is not None:
            spots.setdefault(g.frame, set()).add((g.link, tuple(round(v, 4) for v in g.pose[:3])))
    shared = frozenset(f for f, at in spots.items() if len(at) > 1)
    resolved = [r for g in sensors if (r := _resolve(tree, g, shared)) is not None]
    devices: list[list[StatedCamera]] = []
    for r in resolved:
        home = next((d for d in devices if any(_one_device(tree, r, o) for o in d)), None)
        if home is None:
            devices.append([r])
        else:
            home.append(r)
    out = []
    for device in devices:
        if len(device) > 1 and all(names_silent(c.body.name) for c in device):
            # Nothing named: the channel by the frames' spots (optical.pick_channel).
            chosen = pick_channel(tree, list(dict.fromkeys(c.body for c in device)))
            out.append(next(c for c in device if c.body is chosen))
            continue
        order = sorted(range(len(device)), key=lambda i: (*_preference(device[i]), i))
        out.append(device[order[0]])
    world = tree.world
    named = {
        world.get_body_by_name(g.frame).index
        for g in sensors
        if g.frame and world.has_body(g.frame)
    }
    return out, {r.body.index for r in resolved} | named


def fill_stated(cam: DraftCamera, s: StatedCamera, *, z_ahead: bool) -> None:
    """What the Gazebo sensor states, written into the drafted camera ``cam``.

    The frame and the axis are facts (no DECIDE mark), and so are the angles when the sensor
    gives its field of view and image size (the vertical angle from the pixels, square pixels).
    ``z_ahead``: whether the frame's z axis points the way the robot faces, which settles a
    plugin that names its sensor's own x-forward link as an optical frame.
    """
    g = s.fact
    size = f", {g.width}x{g.height} px" if g.width and g.height else ""
    cam.source = s.how + size
    h, v = g.horizontal_fov, g.vertical_fov
    if h is not None and v is not None and 0.0 < h < math.pi and 0.0 < v < math.pi:
        cam.field_of_view = (round(h, 5), round(v, 5))
    if s.optical:
        return
    if s.doubt is not None:
        if z_ahead:
            cam.looks_along_z = True
            cam.decide.append(f"{s.doubt}; its z axis points the way the robot faces")
        else:
            cam.decide.append(s.doubt)
        return
    x, y, z = s.axis
    if z > _ALONG:
        cam.looks_along_z = True
    elif x < _ALONG:
        norm = math.sqrt(x * x + y * y + z * z)
        cam.axis = (round(x / norm, 4), round(y / norm, 4), round(z / norm, 4))
