"""What sits at an arm's end: a parallel gripper (two finger branches) or a tool, and its frame.

A parallel gripper is a hand whose tree splits into exactly two moving branches with geometry
(linkage helpers without geometry, such as PR2's parallel links, do not count). The thumb is the
finger driven by its own joint; the finger is the one that mimics it (PR2, Panda, Baxter). When
both are driven or both mimic, the left one (seen from the gripper) is taken for the thumb, and
the draft says so.

Two jaws in series, the second hanging on the first (a WSG-50's), are a parallel gripper too; a
branch beside the finger carriage that no joint couples to it (a motor's horn) is not a finger.

Tool frames are searched only in the manipulator's own subtree, so two arms never share one; a
hand without one gets a frame proposed between its tips (``tool_frames``, re-exported here).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from robotspec.description.actuation import Actuation
from robotspec.model.entities import Body
from robotspec.model.world import World
from robotspec.spec.draft.confidence import gripper_question
from robotspec.spec.draft.fingers import find_fingers, finger_tip, hand_branches
from robotspec.spec.draft.limbs import FINGER_WORDS, HAND_WORDS, is_named
from robotspec.spec.draft.linkages import one_actuator, turns_freely
from robotspec.spec.draft.model import DraftFinger
from robotspec.spec.draft.tool_frames import (
    find_tool_frame,
    hand_center,
    is_named_tcp,
)
from robotspec.spec.draft.tree import Tree, solid

__all__ = [
    "Gripper",
    "facing_quaternion",
    "find_fingers",
    "find_gripper",
    "find_tool_frame",
    "hand_center",
    "hand_joints",
    "is_named_tcp",
]


@dataclass(frozen=True)
class Gripper:
    """A two-finger gripper found below a hand."""

    root: Body
    thumb: DraftFinger
    finger: DraftFinger
    thumb_tip: Body
    finger_tip: Body
    decide: str | None
    #: How its fingers were found, for the draft's ``# from`` note.
    found: str = "two finger branches"


def _moved(world: World, body: Body) -> bool:
    """Whether ``body`` hangs on a moving joint."""
    c = world.parent_connection(body)
    return c is not None and not c.is_fixed


def _dofs(tree: Tree, branch: Body) -> set[int]:
    """The degrees of freedom that move a branch (a mimic joint moves its leader's)."""
    world = tree.world
    return {d for b in world.subtree(branch) if (c := world.parent_connection(b)) for d in c.dofs}


def _jaws(tree: Tree, hand: Body) -> Gripper | None:
    """Two jaws in series below ``hand``, the second hanging on the first (a WSG-50's).

    Such a gripper has no split into two branches: the run from the hand passes through both
    jaw joints (prismatic or revolute, each carrying geometry) and ends there.
    """
    world = tree.world
    body = hand
    passed = []
    while True:
        kids = tree.moving_children(body)
        if len(kids) != 1:
            break
        body = kids[0]
        c = world.parent_connection(body)
        if c is not None and not c.is_fixed:
            passed.append(c)
    if kids or len(passed) != 2:
        return None
    j1, j2 = passed
    jaw1, jaw2 = world.bodies[j1.child], world.bodies[j2.child]
    if j1.type != j2.type or not (solid(world, jaw1) and solid(world, jaw2)):
        return None
    named = any(is_named(b.name, FINGER_WORDS | HAND_WORDS) for b in (jaw1, jaw2))
    if j1.type.value != "prismatic" and not named:
        return None  # two revolute links in series are a pendulum, not jaws
    root = world.bodies[j1.parent]
    decide = (
        gripper_question(bool(set(j1.dofs) & set(j2.dofs)), True)
        if j2.is_mimic
        else "both jaws are driven; the upper one is taken for the thumb"
    )
    return Gripper(
        root=root,
        thumb=DraftFinger(root.name, jaw1.name),
        finger=DraftFinger(jaw1.name, jaw2.name),
        thumb_tip=jaw1,
        finger_tip=jaw2,
        decide=decide,
        found="two jaws, one hanging on the other,",
    )


def _sides(
    tree: Tree, root: Body, branches: list[Body], actuation: Actuation | None = None
) -> list[list[Body]] | None:
    """Finger branches grouped into two sides of the hand, or ``None`` if they are not two sides.

    Two branches are two sides. A linkage gripper (Robotiq's, on Tiago Pro) has two branches a
    side, an inner and an outer link: each branch goes to the side of the farther-apart pair of
    tips it is nearer to, and a side holds at most two. One actuator moves a linkage: its mimic
    tags say so, or, in a file without them, its control blocks (one joint driven, the others
    passive or named by no block: ``actuation``).
    """
    if len(branches) == 2:
        return [[branches[0]], [branches[1]]]
    if len(branches) != 4:
        return None
    world = tree.world
    dofs = {
        d
        for k in branches
        for b in world.subtree(k)
        if (c := world.parent_connection(b)) is not None
        for d in c.dofs
    }
    by_dof = _sides_by_dof(tree, branches)
    if by_dof is not None:
        return by_dof
    if len(dofs) != 1 and not one_actuator(world, branches, actuation):
        return None  # a linkage moves with one actuator; several make a hand of fingers
    if any("thumb" in b.name.lower() for k in branches for b in world.subtree(k)):
        return None  # a one-motor hand with a thumb and three fingers (Romeo's) is a hand
    inv = np.linalg.inv(tree.poses[root.index])
    # First by where the branches start: two on each side of the hand's middle, along the line
    # the four bases spread on (a linkage's inner and outer links, Robotiq's).
    bases = np.array([(inv @ tree.poses[k.index])[:3, 3] for k in branches])
    centred = bases - bases.mean(axis=0)
    spread = np.linalg.svd(centred)[2][0]
    along = centred @ spread
    if np.all(np.abs(along) > 1e-4) and int(np.sum(along > 0)) == 2:
        return [[k for k, v in zip(branches, along, strict=True) if v < 0]] + [
            [k for k, v in zip(branches, along, strict=True) if v > 0]
        ]
    at = {b.index: (inv @ tree.poses[finger_tip(tree, b).index])[:3, 3] for b in branches}
    pairs = [(a, b) for i, a in enumerate(branches) for b in branches[i + 1 :]]
    a, b = max(pairs, key=lambda p: float(np.linalg.norm(at[p[0].index] - at[p[1].index])))
    sides: list[list[Body]] = [[a], [b]]
    for k in branches:
        if k is a or k is b:
            continue
        near_a = np.linalg.norm(at[k.index] - at[a.index]) <= np.linalg.norm(
            at[k.index] - at[b.index]
        )
        sides[0 if near_a else 1].append(k)
    return sides if all(len(side) == 2 for side in sides) else None


def _reach(tree: Tree, root: Body, b: Body) -> float:
    """How far ``b``'s frame lies from ``root``'s in the default pose (mm, rounded: ties stay)."""
    d = tree.poses[b.index][:3, 3] - tree.poses[root.index][:3, 3]
    return round(float(np.linalg.norm(d)) * 1000.0)


def _sides_by_dof(tree: Tree, branches: list[Body]) -> list[list[Body]] | None:
    """Four branches two actuators move, two each: each actuator's pair is one side, or None.

    Why: a linkage gripper whose jaws have a motor each (the BCN3D Moveo's servo gear and idler
    gear, each with its pivot arm on a mimic) is two sides of a finger and a linkage link; the
    mimic tags say which links move together, wherever they start on the hand.
    """
    moved = [frozenset(_dofs(tree, k)) for k in branches]
    if any(len(m) != 1 for m in moved):
        return None
    sides: dict[frozenset[int], list[Body]] = {}
    for k, m in zip(branches, moved, strict=True):
        sides.setdefault(m, []).append(k)
    if len(sides) != 2 or any(len(side) != 2 for side in sides.values()):
        return None
    return list(sides.values())


def find_gripper(
    tree: Tree, hand: Body, _depth: int = 0, actuation: Actuation | None = None
) -> tuple[Gripper | None, str]:
    """A parallel gripper at or below ``hand``, or ``None`` and why not.

    ``actuation``: what the URDF's control blocks say (which joints are driven), when known.

    Two branches that no joint couples, one of which splits again into two coupled fingers
    (Interbotix's: the gripper motor's horn beside the finger carriage), are not the fingers:
    the coupled pair below is.
    """
    world = tree.world
    body, branches = hand_branches(tree, hand)
    uncoupled = len(branches) == 2 and not _dofs(tree, branches[0]) & _dofs(tree, branches[1])
    if uncoupled and _depth < 2:  # a horn beside a carriage is one level; never a deep search
        for k in branches:
            deeper, _ = find_gripper(tree, k, _depth + 1, actuation)
            if deeper is not None and deeper.decide is None:
                return deeper, "two coupled finger branches"
    if not branches:
        jaws = _jaws(tree, hand)
        if jaws is not None:
            return jaws, "two jaws, one hanging on the other"
    sides = _sides(tree, body, branches, actuation)
    if sides is None:
        if not branches:
            return None, "no finger branches below it"
        return None, f"{len(branches)} finger branches below '{body.name}', not two sides"
    if any(turns_freely(world, k) for side in sides for k in side):
        # A side driven without end (a car's two front wheels, whatever their names): fingers
        # close within a range; a mimic follows its leader's, whatever its type says.
        return None, f"a branch below '{body.name}' turns without end: not a finger"
    # A side's tip is its deepest moving link; it is driven when one of its joints is not a mimic.
    tips: list[Body] = []
    leaders: list[bool] = []
    for side in sides:
        ends = [finger_tip(tree, k) for k in side]
        # Of a linkage's two ends at one depth, the one a joint moves (Robotiq's finger tip on
        # its mimic joint) is the tip, not the link fixed on the knuckle beside it; of two
        # moved ones (AG-95's outer finger and pad, both on mimics), the one reaching farther
        # out from the hand's root in the default pose, where the pad closes on the object.
        tips.append(
            max(
                ends,
                key=lambda b: (world.depth(b), _moved(world, b), _reach(tree, body, b), -b.index),
            )
        )
        leaders.append(
            any(
                c.is_active
                for k in side
                for c in world.compute_chain_of_connections(body, finger_tip(tree, k))
            )
        )
    # Stated only when a mimic tag couples the two sides, one driving the other (confidence).
    moved = [set().union(*(_dofs(tree, k) for k in side)) for side in sides]
    decide = gripper_question(bool(moved[0] & moved[1]), leaders[0] != leaders[1])
    # Which link is a finger's tip is the files' answer only when each side ends once.
    leaves = [
        sum(1 for k in side for b in world.subtree(k) if not world.child_bodies(b))
        for side in sides
    ]
    if decide is None and max(leaves) > 1:
        decide = "a finger with several end links: its tip is the deepest one a joint moves"
    bare = [t.name for t in tips if not solid(world, t)]
    if decide is None and bare:  # a frame at the pad's end, named by whoever wrote it (PR2's)
        decide = f"the finger tip '{bare[0]}' is a bare frame at the finger's end, not its pad"
    if leaders[0] != leaders[1]:
        thumb_i = 0 if leaders[0] else 1
    else:
        # Neither mimics the other: the thumb is the finger on the hand's +y side.
        rot = np.linalg.inv(tree.poses[body.index])
        ys = [(rot @ tree.poses[t.index])[1, 3] for t in tips]
        thumb_i = 0 if ys[0] >= ys[1] else 1
    finger_i = 1 - thumb_i
    gripper = Gripper(
        root=body,
        thumb=DraftFinger(body.name, tips[thumb_i].name),
        finger=DraftFinger(body.name, tips[finger_i].name),
        thumb_tip=tips[thumb_i],
        finger_tip=tips[finger_i],
        decide=decide,
    )
    return gripper, "two finger branches"


def hand_joints(tree: Tree, top: Body) -> frozenset[str]:
    """The actuated joints below ``top`` (a hand's own joints)."""
    inside = {b.index for b in tree.world.subtree(top)}
    return frozenset(
        c.name
        for c in tree.world.connections
        if c.parent in inside and c.child in inside and c.is_active
    )


def facing_quaternion(axis: np.ndarray) -> tuple[float, float, float, float] | None:
    """The quaternion ``q`` whose ``R^T x`` is ``axis`` (the spec's front-facing convention)."""
    n = float(np.linalg.norm(axis))
    if n < 1e-9:
        return None
    a = axis / n
    # R maps a onto x: rotate about a x x by the angle between them.
    cross = np.cross(a, np.array([1.0, 0.0, 0.0]))
    s, c = float(np.linalg.norm(cross)), float(a[0])
    if s < 1e-9:
        return (0.0, 0.0, 0.0, 1.0) if c > 0 else (0.0, 0.0, 1.0, 0.0)
    k = cross / s
    angle = math.atan2(s, c)
    h = math.sin(angle / 2)
    q = (float(k[0] * h), float(k[1] * h), float(k[2] * h), math.cos(angle / 2))
    return tuple(round(v, 7) for v in q)  # type: ignore[return-value]
