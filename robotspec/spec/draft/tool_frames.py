"""Which frame is a manipulator's tool frame: the one the URDF names, or one it implies.

Why its own module: a tool frame is read from the files before anything is guessed. A bare
frame named as a TCP (``tool0``, ``*_tcp``, ``grasp_frame``...) is the files' answer; a bare
frame on the joint a hand's fingers mimic is the hand's TCP (NAO's ``l_gripper``); a bare frame
at the far end of a rigid tool is its tip, and one fixed on a hand out the way its fingers
reach is its TCP, whatever their names (``tool_places``: the rules by where a frame lies);
names weaker than these are questions; a hand with none gets a frame proposed between its
tips, at the far ends of their geometry (``tips.between_tips``).
"""

from __future__ import annotations

import numpy as np

from robotspec.model.entities import Body, Connection
from robotspec.model.world import World
from robotspec.spec.draft.tips import between_tips, bit_end
from robotspec.spec.draft.tool_places import (
    AT_END,
    bare_fixed_leaf,
    end_frame,
    frame_at_tips,
    frame_past_fingers,
    line_end,
    own_geometry,
)
from robotspec.spec.draft.tree import Tree, words

__all__ = [
    "TCP_NAMES",
    "TOOL_HINTS",
    "bare_fixed_leaf",
    "bare_run_end",
    "bit_frame",
    "end_frame",
    "find_tool_frame",
    "fixed_jaw",
    "frame_at_tips",
    "hand_center",
    "is_bare_frame",
    "is_named_tcp",
    "line_end",
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


#: A bare frame: a leaf without geometry on a fixed joint (one predicate, two names in use).
is_bare_frame = bare_fixed_leaf


def bit_frame(tree: Tree, top: Body, tool: Body) -> tuple[float, float, float] | None:
    """Where a rigid tool's bit ends (:func:`tips.bit_end`), unless its link is named as a TCP.

    Why: a link named as a TCP ('tool0' with a rigid gripper's jaws drawn on it) is the frame
    the maker put where the tool works; its shape says nothing against that name.
    """
    name = _named_as(tool.name)
    if any(_matches(hint, name) for hint in TCP_NAMES):
        return None
    return bit_end(tree, top, tool)


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
    # A link on a moving joint is a part that moves (an arm's last link named 'eef'), never a
    # frame a name makes a TCP: the tool frame is then proposed on it, not the link itself.
    named = [b for b in candidates if (c := world.parent_connection(b)) is None or c.is_fixed]
    for hint in TOOL_HINTS:
        hits = [b for b in named if any(_matches(hint, n) for n in names[b.index])]
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
    # The turned one is the hand's TCP by structure alone, named as anything, when it is out
    # from the hand (at the hand's origin it is the motor's stand-in: HSR-B's, qb SoftHand's).
    # Bareness tells a frame from a finger only where the hand has shapes (not in a file whose
    # meshes are missing, where every finger is bare).
    shaped = any(own_geometry(b) for b in world.subtree(top))
    bare = [
        b
        for b in candidates
        if not world.child_bodies(b)
        and not own_geometry(b)
        and (c := world.parent_connection(b)) is not None
        and (
            (c.is_fixed or (shaped and _leads_fingers(world, c, top)))
            if "gripper" in names[b.index][0][1]
            else _leads_fingers(world, c, top, shaped=True)
            and float(np.linalg.norm(c.origin[:3, 3])) > AT_END
        )
    ]
    if bare:
        return min(bare, key=lambda b: (world.depth(b), b.index))
    # A bare frame fixed on the hand, out towards its finger tips: its TCP, whatever its name.
    if (past := frame_past_fingers(tree, top, candidates)) is not None:
        return past
    jaw = fixed_jaw(world, top) if top.index not in exclude else None
    if jaw is not None or leaf:
        return jaw
    return end_frame(tree, top, candidates) or line_end(tree, top)


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


def _leads_fingers(world: World, c: Connection, top: Body, shaped: bool = False) -> bool:
    """Whether ``c`` is an active joint that joints of other branches below ``top`` mimic.

    Why: a hand driven by one motor is often modelled as a bare link on the motor's joint, the
    fingers mimicking it; that link is a frame (no geometry, nothing below), not a finger.
    ``shaped``: only fingers with a shape count (a file without shapes has bare fingers, one
    of which leads the other: a finger, not a frame).
    """
    if not c.is_active:
        return False
    return any(
        o.is_mimic
        and set(o.dofs) & set(c.dofs)
        and (not shaped or any(own_geometry(k) for k in world.subtree(b)))
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
    if not tips and not any(own_geometry(b) for b in world.subtree(top)):
        # A hand without any shape (its meshes missing, or a kinematics-only file): its
        # fingers' last links, past a moving joint, are the tips; the frame lies between their
        # origins, a guess short of the pads that the draft asks about like any other.
        tips = [
            b
            for b in world.subtree(top)
            if b is not top
            and not world.child_bodies(b)
            and any(not c.is_fixed for c in world.compute_chain_of_connections(top.name, b.name))
        ]
    if not tips:
        return None
    return between_tips(tree, top, tips)  # at the far ends of the tips' geometry
