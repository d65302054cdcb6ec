"""Tool frames by where they lie: the bare frames at a tool's far end or out between fingers.

Why its own module (split from ``tool_frames``, which reads names first): these rules decide a
TCP from the tree's shape alone, for files whose names say nothing (a maker's ids, issue 30's
``renamed`` robustness row): a bare leaf at the far end of a rigid tool, one between a
gripper's two finger tips, one out on a hand the way its fingers reach.
"""

from __future__ import annotations

import numpy as np

from robotspec.model.entities import Body
from robotspec.model.world import World
from robotspec.spec.draft.tips import far_end
from robotspec.spec.draft.tree import Tree, words

__all__ = [
    "AT_END",
    "BEYOND_TIPS",
    "OFF_AXIS",
    "SENSOR_WORDS",
    "bare_fixed_leaf",
    "end_frame",
    "frame_at_tips",
    "frame_past_fingers",
    "line_end",
    "own_geometry",
]


def bare_fixed_leaf(world: World, body: Body) -> bool:
    """Whether ``body`` is a frame: a leaf on a fixed joint, without geometry."""
    c = world.parent_connection(body)
    return (
        c is not None
        and c.is_fixed
        and not world.child_bodies(body)
        and not (body.collisions or body.visuals)
    )


def own_geometry(body: Body) -> bool:
    """Whether ``body`` itself has a shape (visual or collision)."""
    return bool(body.collisions or body.visuals)


#: Words of frames that are a sensor's, not a tool's (an F/T sensor's frame, an IMU's...).
SENSOR_WORDS = frozenset(
    {"ft", "imu", "force", "torque", "sensor", "camera", "cam", "optical", "laser", "lidar"}
    | {"led", "light", "gyro", "accel", "accelerometer", "mic", "microphone", "com", "mass"}
)
#: How far (m) a frame may lie from the far end of the geometry it ends, to be at that end.
AT_END = 0.01
#: ... or this fraction of the way out, for large tools.
AT_END_SHARE = 0.1


def end_frame(tree: Tree, top: Body, candidates: list[Body]) -> Body | None:
    """The one bare frame at the far end of a rigid end effector, whatever its name.

    Why structure: an arm's tool with nothing that moves (a ball, a probe, a welding torch)
    often carries a frame where it touches the work, named as nothing this module knows
    (CENTAURO's 'ball1_tip'); it is a bare leaf placed out at the far end of the tool's
    geometry, the way it points from the last joint. Frames at the mount (an F/T sensor's, a
    legacy link's) sit at its origin, frames named as sensors are the sensors'. ``None`` when
    anything moves below ``top``, or when not exactly one frame is at the end.
    """
    world = tree.world
    if tree.moves_below(top):
        return None
    facts = tree.memo.get("facts")
    sensed = set(getattr(facts, "sensor_links", {}) or {})
    here = np.asarray(tree.poses[top.index][:3, 3], dtype=np.float64)
    solid = [b for b in world.subtree(top) if own_geometry(b)]
    found = []
    for b in candidates:
        if b is top or not bare_fixed_leaf(world, b) or b.name in sensed:
            continue
        if words(b.name) & SENSOR_WORDS:
            continue
        d = np.asarray(tree.poses[b.index][:3, 3], dtype=np.float64) - here
        along = float(np.linalg.norm(d))
        if along < AT_END or not solid:
            continue
        reach = max(float((far_end(tree, s, d) - here) @ d) / along for s in solid)
        if abs(along - reach) <= max(AT_END, AT_END_SHARE * reach):
            found.append(b)
    return found[0] if len(found) == 1 else None


#: How far off the way from a hand to its finger tips a TCP may lie, per metre out.
OFF_WAY = 0.25


def frame_past_fingers(tree: Tree, top: Body, candidates: list[Body]) -> Body | None:
    """A bare frame fixed on the hand, out the way its fingers reach: the TCP, by structure.

    Why: makers name a hand's TCP anything ('end_effector', 'grasp_link', 'manipulator', an
    id); what they all do is fix a bare leaf on the hand (not on a finger) out between the
    fingers, along the way from the hand to the far ends of its finger tips, at most a little
    beyond them, and no nearer the hand than where its fingers are hinged (nearer: a wrist
    sensor's or a mount's frame). Of several, one on that way before one off it by up to half
    the pads' spread (a thumb opposing two fingers pulls the way aside), then the farthest out
    (a palm-surface frame, then the grasp point). Frames named as sensors and Gazebo sensors'
    links are the sensors'.
    """
    world = tree.world
    carrier = tree.rigid_root(top)
    # The last shaped link of each finger (its pad; a bare tip frame past it says nothing).
    shaped = [
        b for b in world.subtree(top) if own_geometry(b) and tree.rigid_root(b) is not carrier
    ]
    tips = [b for b in shaped if not any(own_geometry(k) for k in world.subtree(b)[1:])]
    if not tips:
        return None
    here = np.asarray(tree.poses[top.index][:3, 3], dtype=np.float64)
    way = np.mean([tree.poses[t.index][:3, 3] for t in tips], axis=0) - here
    pads = [far_end(tree, t, way) for t in tips]
    ends = np.mean(pads, axis=0)
    reach = float(np.linalg.norm(ends - here))
    if reach < OFF_AXIS:
        return None
    axis = (ends - here) / reach
    # Fingers set round the axis unevenly (a thumb opposing two) pull it aside: a TCP may lie
    # as far off it as half the pads' spread around it.
    spread = max(float(np.linalg.norm((p - here) - ((p - here) @ axis) * axis)) for p in pads)
    # Where the fingers are hinged on the hand: a frame short of them is a mount's or a
    # wrist sensor's (HSR-B's F/T frame between its wrist and palm), not the TCP.
    bases = [
        float((tree.poses[b.index][:3, 3] - here) @ axis)
        for b in world.subtree(top)
        if (c := world.parent_connection(b)) is not None
        and not c.is_fixed
        and tree.rigid_root(world.bodies[c.parent]) is carrier
    ]
    start = min(bases, default=0.0)
    facts = tree.memo.get("facts")
    sensed = set(getattr(facts, "sensor_links", {}) or {})
    found: list[tuple[bool, float, Body]] = []
    for b in candidates:
        if b is top or not bare_fixed_leaf(world, b) or tree.rigid_root(b) is not carrier:
            continue
        if b.name in sensed or words(b.name) & SENSOR_WORDS:
            continue
        d = np.asarray(tree.poses[b.index][:3, 3], dtype=np.float64) - here
        along = float(d @ axis)
        off = float(np.linalg.norm(d - along * axis))
        if not max(start, 0.0) < along <= reach + BEYOND_TIPS:
            continue
        # On the way out first; then, off it by up to half the pads' spread.
        if off <= max(OFF_AXIS, OFF_WAY * along):
            found.append((True, along, b))
        elif off <= spread / 2:
            found.append((False, along, b))
    return max(found, key=lambda f: (f[0], f[1], -f[2].index))[2] if found else None


#: How far off the line from a gripper's root through its tips' far ends a frame may lie (m).
OFF_AXIS = 0.01
#: How far beyond the tips' far ends a frame between the fingers may lie (m).
BEYOND_TIPS = 0.03


def frame_at_tips(tree: Tree, root: Body, tips: tuple[Body, Body]) -> Body | None:
    """A bare frame the URDF puts between a gripper's finger tips, whatever its name.

    Why structure first: a TCP is often named as nothing this module knows (a
    'pinch_point', a 'grasp_center'); a frame fixed on the gripper (not on a finger) that lies
    on the gripper's axis between the fingers' bases and just beyond their far ends is one.
    """
    world = tree.world
    on_fingers = {b.index for t in tips for b in world.ancestors(t)} - {
        b.index for b in world.ancestors(root)
    }
    here = np.asarray(tree.poses[root.index][:3, 3], dtype=np.float64)
    way = np.mean([tree.poses[t.index][:3, 3] for t in tips], axis=0) - here
    ends = np.mean([far_end(tree, t, way) for t in tips], axis=0)  # the pads, not the joints
    reach = float(np.linalg.norm(ends - here))
    if reach < OFF_AXIS:
        return None
    axis = (ends - here) / reach
    found = []
    for b in world.subtree(root):
        c = world.parent_connection(b)
        if b is root or c is None or not bare_fixed_leaf(world, b) or c.parent in on_fingers:
            continue
        d = np.asarray(tree.poses[b.index][:3, 3], dtype=np.float64) - here
        along = float(d @ axis)
        if float(np.linalg.norm(d - along * axis)) <= OFF_AXIS and 0 < along <= reach + BEYOND_TIPS:
            found.append(b)
    return found[0] if len(found) == 1 else None


def line_end(tree: Tree, top: Body) -> Body | None:
    """The shaped leaf farthest out along the arm's last joint axis, fixed past that joint.

    Why: past the last joint a maker often bolts parts (a gripper's base, then its mount
    point) fixed one on the other, the last on the joint's axis, beside sensors hung off it
    (a wrist camera, a range finder): the tool is met at the end on the axis, whatever the
    parts are named. Only when nothing moves below ``top``, of the leaves with a shape fixed to
    the link the last joint moves, within ``OFF_AXIS`` of its axis and at least ``AT_END``
    along it; not a Gazebo sensor's link nor one named as a sensor. A bare frame there is
    ``end_frame``'s to judge (short of the tool's far end it is a mount's or a centre's).
    """
    world = tree.world
    moved = tree.rigid_root(top)
    c = world.parent_connection(moved)
    if c is None or c.is_fixed or tree.moves_below(top):
        return None
    pose = tree.poses[moved.index]
    axis = pose[:3, :3] @ np.asarray(c.axis, dtype=np.float64)
    n = float(np.linalg.norm(axis))
    if n < 1e-9:
        return None
    axis = axis / n
    facts = tree.memo.get("facts")
    sensed = set(getattr(facts, "sensor_links", {}) or {})
    found: list[tuple[float, Body]] = []
    for b in world.subtree(top):
        if b is top or world.child_bodies(b) or not own_geometry(b):
            continue  # bare frames: end_frame's (at the far end of the shapes, or none)
        if b.name in sensed or words(b.name) & SENSOR_WORDS:
            continue
        d = np.asarray(tree.poses[b.index][:3, 3] - pose[:3, 3], dtype=np.float64)
        along = float(d @ axis)
        if abs(along) >= AT_END and float(np.linalg.norm(d - along * axis)) <= OFF_AXIS:
            found.append((abs(along), b))
    return max(found, key=lambda f: (f[0], -f[1].index))[1] if found else None
