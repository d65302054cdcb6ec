"""Which frame is a manipulator's tool frame: the one the URDF names, or one it implies.

Why its own module: a tool frame is read from the files before anything is guessed. A bare
frame named as a TCP (``tool0``, ``*_tcp``, ``grasp_frame``...) is the files' answer; a bare
frame on the joint a hand's fingers mimic is the hand's TCP (NAO's ``l_gripper``); a bare frame
at the far end of a rigid tool is its tip, whatever its name; names weaker than these are
questions; a hand with none gets a frame proposed between its tips, at the far ends of their
geometry (``tips.between_tips``).
"""

from __future__ import annotations

import numpy as np

from robotspec.model.entities import Body, Connection
from robotspec.model.world import World
from robotspec.spec.draft.tips import between_tips, far_end
from robotspec.spec.draft.tree import Tree, words

__all__ = [
    "TCP_NAMES",
    "TOOL_HINTS",
    "bare_fixed_leaf",
    "bare_run_end",
    "end_frame",
    "find_tool_frame",
    "fixed_jaw",
    "frame_at_tips",
    "hand_center",
    "is_bare_frame",
    "is_named_tcp",
    "own_geometry",
]

#: How tool frames are usually named, best first: (substring of the name, or a whole word).
TOOL_HINTS: tuple[str, ...] = (
    "tool_frame",
    "tcp",
    "grasping_frame",
    "grasp_frame",
    "gripper_frame",
    "grasp",
    "tool0",
    "end_effector",
    "endeffector",
    "ee_link",
    "eef",
    "ee",
    "endpoint",
    "tool_link",
    "tool",
    "flange",
)


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


def bare_run_end(world: World, top: Body) -> Body:
    """The last of a run of bare frames fixed one below the other from ``top``, else ``top``.

    Why: past an arm's last joint a maker often fixes a frame on a frame (a UR's ``flange``,
    then ``tool0`` turned to the tool's convention): nothing is bolted to the run but where it
    ends, so its end is the tool frame whatever either is named. Only a single line of frames
    (each the one child of the one above, no shape): a branch says nothing about which end.
    """
    body = top
    while len(kids := world.child_bodies(body)) == 1:
        c = world.parent_connection(kids[0])
        if c is None or not c.is_fixed or kids[0].collisions or kids[0].visuals:
            return top
        body = kids[0]
    return top if kids else body


def _carries_moving(world: World, body: Body) -> bool:
    """Whether a moving joint hangs on ``body`` (fingers, jaws)."""
    return any(
        (c := world.parent_connection(k)) is not None and not c.is_fixed
        for k in world.child_bodies(body)
    )


def _matches(hint: str, name: tuple[str, set[str]]) -> bool:
    """Whether a name (lower-cased, and its words) holds a hint: inside it, or as a word."""
    if "_" in hint or len(hint) > 4:
        return hint in name[0]
    return hint in name[1]


def _named_as(name: str) -> tuple[str, set[str]]:
    return name.lower(), words(name)


#: Names a URDF gives its TCP: a bare frame so named is a tool frame the files decide.
TCP_NAMES: tuple[str, ...] = (
    "tool_frame",
    "tcp",
    "grasping_frame",
    "grasp_frame",
    "tool0",
    "end_effector_link",
    "ee_link",
)


def is_bare_frame(world: World, body: Body) -> bool:
    """Whether ``body`` is a bare frame: a leaf without geometry on a fixed joint."""
    c = world.parent_connection(body)
    return c is not None and c.is_fixed and not world.child_bodies(body) and not own_geometry(body)


def is_named_tcp(world: World, body: Body) -> bool:
    """Whether ``body`` is a bare frame (a leaf without geometry, on a fixed joint) named a TCP."""
    if not is_bare_frame(world, body):
        return False
    name = _named_as(body.name)
    return any(_matches(hint, name) for hint in TCP_NAMES)


def find_tool_frame(
    tree: Tree,
    top: Body,
    exclude: frozenset[int] = frozenset(),
    prefer: Body | None = None,
    leaf: bool = False,
) -> Body | None:
    """The best-named tool frame in ``top``'s subtree (``exclude``: bodies of other parts).

    Of equally named frames, one hanging from ``prefer`` (where the fingers split) wins: the
    TCP sits between the fingers, the flange above them (Interbotix's 'ee_gripper_link' beside
    'ee_arm_link'). ``leaf``: only frames without children count.
    """
    world = tree.world
    candidates = [b for b in world.subtree(top) if b.index not in exclude]
    if leaf:  # frames only (a TCP), never a link carrying fingers
        candidates = [b for b in candidates if not world.child_bodies(b)]
    near = set() if prefer is None else {b.index for b in world.subtree(prefer)}
    # The link's name, or its fixed joint's (Baxter's 'right_gripper' hangs on 'right_endpoint').
    names: dict[int, list[tuple[str, set[str]]]] = {}
    for b in candidates:
        c = world.parent_connection(b)
        names[b.index] = [_named_as(b.name)]
        # A link fingers hang on is named by its own name only: its joint to the arm is the
        # flange it is bolted to (Schunk SIH's 'flange-palm'), not a TCP.
        if c is not None and c.is_fixed and not _carries_moving(world, b):
            names[b.index].append(_named_as(c.name))
    for hint in TOOL_HINTS:
        hits = [b for b in candidates if any(_matches(hint, n) for n in names[b.index])]
        if hits:
            # A TCP is a frame (a leaf), not a link carrying fingers ('fingers_link' on 'ee_bar').
            return min(
                hits,
                key=lambda b: (
                    b.index not in near,
                    bool(world.child_bodies(b)),
                    world.depth(b),
                    b.index,
                ),
            )
    # Last: a bare frame named as the gripper (iCub's 'l_gripper' below 'l_hand'), fixed or
    # turned by the joint the fingers mimic (NAO's 'l_gripper' on 'LHand': the hand's TCP).
    bare = [
        b
        for b in candidates
        if "gripper" in names[b.index][0][1]
        and not world.child_bodies(b)
        and not own_geometry(b)
        and (c := world.parent_connection(b)) is not None
        and (c.is_fixed or _leads_fingers(world, c, top))
    ]
    if bare:
        return min(bare, key=lambda b: (world.depth(b), b.index))
    jaw = fixed_jaw(world, top) if top.index not in exclude else None
    return jaw if jaw is not None or leaf else end_frame(tree, top, candidates)


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


def fixed_jaw(world: World, hand: Body) -> Body | None:
    """A one-jaw gripper's fixed jaw: the fixed leaf with geometry beside its one moving jaw.

    Why: a gripper of one moving jaw (Darwin-OP's) closes it onto a fixed jaw; the fixed jaw's
    frame, reaching at least as far out as the moving jaw's hinge, is where it grasps. Only
    when the hand carries these two and nothing else.
    """
    kids = world.child_bodies(hand)
    moving = [k for k in kids if (c := world.parent_connection(k)) is not None and not c.is_fixed]
    if len(moving) != 1 or world.child_bodies(moving[0]):
        return None
    hinge = world.parent_connection(moving[0])
    assert hinge is not None
    out = float(np.linalg.norm(hinge.origin[:3, 3]))
    jaws = [
        k
        for k in kids
        if k is not moving[0]
        and k.collisions
        and not world.child_bodies(k)
        and (c := world.parent_connection(k)) is not None
        and c.is_fixed
        and float(np.linalg.norm(c.origin[:3, 3])) >= out
    ]
    # Nothing else hangs on the hand (a gripper's linkage, fingertips: a hand of another kind).
    return jaws[0] if len(jaws) == 1 and len(kids) == 2 else None


def _leads_fingers(world: World, c: Connection, top: Body) -> bool:
    """Whether ``c`` is an active joint that joints of other branches below ``top`` mimic.

    Why: a hand driven by one motor is often modelled as a bare link on the motor's joint, the
    fingers mimicking it; that link is a frame (no geometry, nothing below), not a finger.
    """
    if not c.is_active:
        return False
    return any(
        o.is_mimic and set(o.dofs) & set(c.dofs)
        for b in world.subtree(top)
        if (o := world.parent_connection(b)) is not None and o is not c
    )


def hand_center(tree: Tree, top: Body) -> tuple[float, float, float] | None:
    """Between a hand's finger tips in the default pose, in ``top``'s frame (``None``: no tips).

    The tips are the leaves with geometry below ``top``; a tool frame proposed there is a guess.
    """
    world = tree.world
    tips = [
        b
        for b in world.subtree(top)
        if b is not top and not world.child_bodies(b) and own_geometry(b)
    ]
    if not tips:  # tips the URDF names as bare frames at the fingers' ends (Ability's '*_tip')
        tips = [
            b
            for b in world.subtree(top)
            if b is not top
            and bare_fixed_leaf(world, b)
            and (up := world.parent_connection(b)) is not None
            and up.parent != top.index  # on a finger, not on the hand itself
            and (c := world.parent_connection(world.bodies[up.parent])) is not None
            and not c.is_fixed
        ]
    if not tips:
        return None
    return between_tips(tree, top, tips)  # at the far ends of the tips' geometry


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
