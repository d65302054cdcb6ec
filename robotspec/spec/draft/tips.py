"""Where a link really ends: the far end of its geometry, for tool frames a draft proposes.

Why: a joint's origin is where a link is hinged, not where it ends. A finger's joint sits at its
base, several centimetres short of the pad; an arm's last joint sits at the wrist, not at the
flange a tool is bolted to. A tool frame "between the finger tips" or "on the flange" is only
where it says when it is put at the far end of the links' collision geometry (their visual
geometry when they have none), measured along the way the hand reaches.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np
import numpy.typing as npt

from robotspec.errors import RobotSpecError
from robotspec.files.meshes import read_vertices as mesh_vertices
from robotspec.model.entities import Body
from robotspec.model.geometry import Box, Capsule, Cylinder, Mesh, Shape, Sphere
from robotspec.spec.draft.ends import END_WORDS
from robotspec.spec.draft.tree import Tree, words

__all__ = [
    "FLANGE",
    "MESH_PATH",
    "between_tips",
    "bit_end",
    "far_end",
    "flange_offset",
    "origin_is_flange",
    "rigid_end",
    "mesh_vertices",
    "shape_points",
    "world_points",
]

#: The key of ``Tree.memo`` holding how to find a mesh file from its URI (``None``: not found).
MESH_PATH = "mesh_path"
#: The key of ``Tree.memo`` holding the points of each body read so far (by body index).
BODY_POINTS = "body_points"

F64 = npt.NDArray[np.float64]

#: Why a flange frame is where it is (the draft's ``# from`` note).
FLANGE = "the far end of the last link, the way the arm reaches (a flange)"
#: Points around a cylinder's rim (enough for its far end along any direction, to 2 %).
RIM = 16
#: A link whose geometry reaches less than this past its origin (m) has no far end to speak of.
MIN_REACH = 1e-3


def shape_points(shape: Shape, find: Callable[[str], str | None] | None = None) -> F64:
    """Points bounding one shape, in its body's frame (N x 3); none for an unreadable mesh.

    Why points rather than a box: the far end along a direction is the largest projection of
    the points, exact for boxes and meshes, close for round shapes. ``find`` locates a mesh
    the description kept as a URI only (the drafter loads without resolving meshes).
    """
    g = shape.geometry
    local: F64
    if isinstance(g, Box):
        half = np.asarray(g.size, dtype=np.float64) / 2
        signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)])
        local = signs * half
    elif isinstance(g, Sphere):
        local = np.vstack([np.eye(3), -np.eye(3)]) * g.radius
    elif isinstance(g, Cylinder | Capsule):
        t = np.linspace(0.0, 2 * np.pi, RIM, endpoint=False)
        ring = np.stack([np.cos(t), np.sin(t), np.zeros_like(t)], axis=1) * g.radius
        cap = g.radius if isinstance(g, Capsule) else 0.0
        ends = [ring + [0.0, 0.0, z] for z in (-g.length / 2, g.length / 2)]
        tips = np.array([[0.0, 0.0, -g.length / 2 - cap], [0.0, 0.0, g.length / 2 + cap]])
        local = np.vstack([*ends, tips])
    elif isinstance(g, Mesh) and (path := g.path or (find(g.uri) if find else None)):
        try:
            vertices = mesh_vertices(path)
        except RobotSpecError:
            return np.zeros((0, 3))
        local = vertices * np.asarray(g.scale, dtype=np.float64)
    else:
        return np.zeros((0, 3))
    homo = np.hstack([local, np.ones((len(local), 1))])
    out: F64 = (np.asarray(shape.origin, dtype=np.float64) @ homo.T).T[:, :3]
    return out


def _finder(tree: Tree) -> Callable[[str], str | None]:
    """How this draft finds a mesh from its URI: the one in ``tree.memo``, else one made here.

    Made once per draft, from the URDF's own place (its folder and the packages around it);
    a mesh it cannot find, or finds outside the allowed folders, is no geometry (``None``).
    """
    find = tree.memo.get(MESH_PATH)
    if find is None:
        from robotspec.files.packages import PackageResolver

        source = tree.world.source
        resolver = PackageResolver.create(source) if source else None
        here = None if not source else Path(source).parent

        def find(uri: str) -> str | None:
            if resolver is None:
                return None
            try:
                path = resolver.resolve(uri, relative_to=here)
            except RobotSpecError:
                return None
            return str(path) if path.is_file() else None

        tree.memo[MESH_PATH] = find
    out: Callable[[str], str | None] = find
    return out


def _body_points(tree: Tree, body: Body) -> F64:
    """Points bounding a body's collision geometry (else its visual), each body read once."""
    known: dict[int, F64] = tree.memo.setdefault(BODY_POINTS, {})
    if body.index not in known:
        shapes = body.collisions or body.visuals
        parts = [shape_points(s, _finder(tree)) for s in shapes]
        parts = [p for p in parts if len(p)]
        known[body.index] = np.vstack(parts) if parts else np.zeros((0, 3))
    return known[body.index]


def world_points(tree: Tree, body: Body) -> F64:
    """:func:`_body_points` in the world frame, in the default pose (none: an empty (0, 3))."""
    pose = tree.poses[body.index]
    points = _body_points(tree, body)
    out: F64 = (pose[:3, :3] @ points.T).T + np.asarray(pose[:3, 3], dtype=np.float64)
    return out


def _point(v: F64) -> tuple[float, float, float]:
    """A point as the draft writes it: to 0.1 mm, with no negative zero."""
    x, y, z = (round(float(c), 4) for c in v)
    return (x + 0.0, y + 0.0, z + 0.0)


def far_end(tree: Tree, body: Body, direction: F64) -> F64:
    """Where ``body`` ends along ``direction`` (world frame, default pose): a world point.

    The point is the body's origin moved along ``direction`` to its geometry's farthest extent
    (never backwards); sideways it stays on the origin, so two fingers' far ends keep the
    midpoint between them on the hand's axis.
    """
    pose = tree.poses[body.index]
    origin: F64 = np.asarray(pose[:3, 3], dtype=np.float64)
    n = float(np.linalg.norm(direction))
    world_pts = world_points(tree, body)
    if n < 1e-9 or not len(world_pts):
        return origin
    d = direction / n
    reach = float(np.max((world_pts - origin) @ d))
    return origin + max(reach, 0.0) * d


def _farthest_way(points: F64, axis: F64, out: F64) -> tuple[F64, float] | None:
    """The way ``points`` reach farthest: a joint's axis (either sense) or its offset's way.

    Returns that way and how far they reach along it (``None``: no axis or no points).

    Why these ways: a last link reaches along its joint's axis (a wrist roll, Panda's and iiwa's
    last link) or the way its offset points (an elbow turning a rigid forearm and hand, Booster
    T1's); both in the link's frame.
    """
    n = float(np.linalg.norm(axis))
    if n < 1e-9 or not len(points):
        return None
    ways = [axis / n, -axis / n]
    if float(np.linalg.norm(out)) >= MIN_REACH:
        ways.append(out / np.linalg.norm(out))
    way = max(ways, key=lambda w: float(np.max(points @ w)))
    return way, float(np.max(points @ way))


def _last_reach(tree: Tree, tip: Body) -> tuple[F64, float] | None:
    """The way and reach of a last link on a moving joint (``None``: fixed, or no shape)."""
    c = tree.world.parent_connection(tip)
    if c is None or c.is_fixed:
        return None
    out = c.origin[:3, :3].T @ c.origin[:3, 3]  # the last offset, in the tip's frame
    return _farthest_way(_body_points(tree, tip), np.asarray(c.axis, dtype=np.float64), out)


def flange_offset(tree: Tree, tip: Body) -> tuple[float, float, float] | None:
    """Where a bare arm's flange is on its last link: the far end of it, the way the arm reaches.

    Why: an arm with nothing mounted and no flange link (a bare KUKA iiwa, a humanoid's rigid
    hand link) still needs a tool frame, and the one a user would bolt a tool to is the end
    face of the last link: along the last joint's axis or the way its offset points, whichever
    the link's geometry reaches farther along. ``None`` when it has no geometry out there, or
    when the link's origin is on that face already (:func:`origin_is_flange`).
    """
    found = _last_reach(tree, tip)
    if found is None or found[1] < AT_FACE:
        return None
    way, reach = found
    return _point(reach * way)


#: How near (m) a bare arm's last link's origin must be to its far end to be its flange.
AT_FACE = 0.01


def origin_is_flange(tree: Tree, tip: Body) -> bool:
    """Whether a bare arm's last link's origin already lies on its end face (within AT_FACE).

    Why: a frame proposed a few millimetres from a link's own origin is that origin written
    again; the link itself is the flange a user bolts a tool to (a small arm whose last link is
    a thin disc with its frame on the face). Only for a last link on a moving joint with a shape.
    """
    found = _last_reach(tree, tip)
    return found is not None and found[1] < AT_FACE


def between_tips(tree: Tree, root: Body, tips: Sequence[Body]) -> tuple[float, float, float]:
    """Between the far ends of finger tips, in ``root``'s frame (default pose).

    The way the hand reaches is from ``root`` to the tips' origins; each tip is moved out
    along it to where its geometry ends (the pads, not the finger joints).
    """
    at = [np.asarray(tree.poses[t.index][:3, 3], dtype=np.float64) for t in tips]
    mid = np.mean(at, axis=0)
    reach = mid - tree.poses[root.index][:3, 3]
    if float(np.linalg.norm(reach)) < 1e-6:
        # Tips hinged at the root's own origin (myCobot's jaws): no way to reach along is
        # known (their meshes' units may be anything), so the frame stays there, asked.
        return (0.0, 0.0, 0.0)
    ends = np.mean([far_end(tree, t, reach) for t in tips], axis=0)
    local = np.linalg.inv(tree.poses[root.index]) @ np.append(ends, 1.0)
    return _point(local[:3])


#: How far out (m) a fixed last link must hang to be a rigid part of the arm, not a flange.
RIGID_OUT = 0.05
#: The farthest (m) a rigid last link's shape may reach; farther, its mesh is not to scale.
RIGID_MAX = 0.5


def rigid_end(tree: Tree, link: Body) -> tuple[float, float, float] | None:
    """Where a rigid link past an arm's last joint ends: its shape's far end the way it hangs.

    ``None`` when it is not one: a bare frame, a flange plate (on a fixed joint less than
    RIGID_OUT out, its shape reaching less than RIGID_OUT past it), or named as an end (a
    flange, a tool). Hung out RIGID_OUT or more, a shape reaching farther than RIGID_MAX, or not
    out at all, gives the link's origin (its mesh is not to scale or placed elsewhere), still a
    frame on the link that a person moves.
    """
    c = tree.world.parent_connection(link)
    if c is None or not c.is_fixed or not (link.collisions or link.visuals):
        return None
    if words(link.name) & END_WORDS:
        return None
    out = c.origin[:3, :3].T @ c.origin[:3, 3]  # the offset, in the link's frame
    n = float(np.linalg.norm(out))
    points = _body_points(tree, link)
    if n < RIGID_OUT:
        # Fixed at the joint itself: a flange plate, or a rigid hand whose shape reaches out
        # from the joint (a humanoid's hand link bolted on its forearm's roll): the shape says.
        return _reach_past_joint(tree, link, c.origin, points)
    way = out / n
    reach = float(np.max(points @ way)) if len(points) else 0.0
    if not MIN_REACH <= reach <= RIGID_MAX:
        return (0.0, 0.0, 0.0)
    return _point(reach * way)


def _reach_past_joint(
    tree: Tree, link: Body, fixed: F64, points: F64
) -> tuple[float, float, float] | None:
    """Where a shaped link fixed (nearly) at the last joint ends, when it reaches far past it.

    Why: a flange plate is a few millimetres thick; a rigid hand or forearm end bolted at the
    joint reaches several centimetres out, and a tool held there is met at its far end, not at
    the joint. The way is the last joint's axis or the way its offset points (as for a bare
    arm's flange, :func:`flange_offset`), in the link's frame; ``None`` when the shape reaches
    less than RIGID_OUT that way (a plate: the link is the flange) or more than RIGID_MAX.
    """
    world = tree.world
    c = world.parent_connection(link)
    up = None if c is None else world.parent_connection(world.bodies[c.parent])
    if up is None or up.is_fixed:
        return None
    turn = fixed[:3, :3].T  # the joint's child frame, in the link's axes
    out = turn @ (up.origin[:3, :3].T @ up.origin[:3, 3])
    found = _farthest_way(points, turn @ np.asarray(up.axis, dtype=np.float64), out)
    if found is None or not RIGID_OUT <= found[1] <= RIGID_MAX:
        return None
    way, reach = found
    return _point(reach * way)


#: The cosine within which the way a tool points is taken as one of its link's axes (45 deg).
ALONG_AXIS = 0.7
#: Why a frame at a rigid tool's bit is where it is (the draft's ``# from`` note).
BIT = "the far end of the tool's last link (its bit's tip), the way the tool points"


def bit_end(tree: Tree, top: Body, tool: Body) -> tuple[float, float, float] | None:
    """Where a rigid tool's last link ends, when its origin is not at its end: its working tip.

    Why: a drill's bit, a probe or a pen is often its own link with its origin at the middle of
    its shape (a cylinder centred on it); the tool works where the shape ends, along the link's
    axis nearest the way the tool points from the arm (``top`` to ``tool``). Only for a shaped
    leaf on a fixed joint strictly below ``top`` with nothing moving below ``top`` (a gripper's
    jaw is not a bit), whose shape reaches AT_FACE or more past its origin that way; the point
    is in ``tool``'s frame.
    """
    world = tree.world
    c = world.parent_connection(tool)
    if tool is top or c is None or not c.is_fixed or world.child_bodies(tool):
        return None
    if tree.moves_below(top) or not world.is_ancestor(top, tool):
        return None
    way = tree.poses[tool.index][:3, 3] - tree.poses[top.index][:3, 3]
    n = float(np.linalg.norm(way))
    points = _body_points(tree, tool)
    if n < MIN_REACH or not len(points):
        return None
    local = tree.poses[tool.index][:3, :3].T @ (way / n)  # the way, in the tool's frame
    # A bit points along one of its link's axes (a cylinder's z): the one nearest that way.
    axes = np.vstack([np.eye(3), -np.eye(3)])
    best = axes[int(np.argmax(axes @ local))]
    local = best if float(best @ local) > ALONG_AXIS else local
    reach = float(np.max(points @ local))
    if not AT_FACE <= reach <= RIGID_MAX:
        return None
    return _point(reach * local)
