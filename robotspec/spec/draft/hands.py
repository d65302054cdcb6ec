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

from robotspec.model.entities import Body
from robotspec.model.world import World
from robotspec.spec.draft.confidence import gripper_question
from robotspec.spec.draft.limbs import FINGER_WORDS, HAND_WORDS, is_named
from robotspec.spec.draft.model import DraftFinger
from robotspec.spec.draft.tool_frames import (
    bare_fixed_leaf,
    find_tool_frame,
    hand_center,
    is_named_tcp,
    own_geometry,
)
from robotspec.spec.draft.tree import Tree, words

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


def _has_geometry(tree: Tree, body: Body) -> bool:
    return any(b.collisions or b.visuals for b in tree.world.subtree(body))


def _finger_tip(tree: Tree, branch: Body) -> Body:
    """The deepest body of a finger branch that a moving joint carries, with geometry if any.

    Geometry first: PR2's xacro hangs a bare frame on a prismatic joint below the finger tip.
    """
    world = tree.world
    inside = world.subtree(branch)
    moved = [b for b in inside if (c := world.parent_connection(b)) is not None and not c.is_fixed]
    # A fixed tip link with geometry is the finger's tip (Baxter's 'r_gripper_l_finger_tip');
    # collision geometry first: a leaf with a look only is a decoration (HSR-B's vacuum pad).
    solid = [b for b in inside if b.collisions] or [b for b in inside if b.visuals]
    tip = max(solid or moved or [branch], key=lambda b: (world.depth(b), -b.index))
    # A bare frame the URDF fixes at the end of the last phalanx is the tip it names (Ability's
    # 'index_tip', D'Claw's 'link_f1_head'): the only bare leaf hanging there.
    bare = [k for k in world.child_bodies(tip) if bare_fixed_leaf(world, k)]
    if len(bare) == 1 and all(not world.child_bodies(k) for k in world.child_bodies(tip)):
        return bare[0]
    return tip


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
    if j1.type != j2.type or not (own_geometry(jaw1) and own_geometry(jaw2)):
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


def _sides(tree: Tree, root: Body, branches: list[Body]) -> list[list[Body]] | None:
    """Finger branches grouped into two sides of the hand, or ``None`` if they are not two sides.

    Two branches are two sides. A linkage gripper (Robotiq's, on Tiago Pro) has two branches a
    side, an inner and an outer link: each branch goes to the side of the farther-apart pair of
    tips it is nearer to, and a side holds at most two.
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
    if len(dofs) != 1:
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
    at = {b.index: (inv @ tree.poses[_finger_tip(tree, b).index])[:3, 3] for b in branches}
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


def _branches(tree: Tree, hand: Body) -> tuple[Body, list[Body]]:
    """Where the hand first splits (below its single links), and the moving branches there."""
    body = hand
    while True:
        kids = tree.moving_children(body)
        if len(kids) != 1:
            break
        body = kids[0]
    return body, [k for k in tree.moving_children(body) if _has_geometry(tree, k)]


def find_gripper(tree: Tree, hand: Body, _depth: int = 0) -> tuple[Gripper | None, str]:
    """A parallel gripper at or below ``hand``, or ``None`` and why not.

    Two branches that no joint couples, one of which splits again into two coupled fingers
    (Interbotix's: the gripper motor's horn beside the finger carriage), are not the fingers:
    the coupled pair below is.
    """
    world = tree.world
    body, branches = _branches(tree, hand)
    uncoupled = len(branches) == 2 and not _dofs(tree, branches[0]) & _dofs(tree, branches[1])
    if uncoupled and _depth < 2:  # a horn beside a carriage is one level; never a deep search
        for k in branches:
            deeper, _ = find_gripper(tree, k, _depth + 1)
            if deeper is not None and deeper.decide is None:
                return deeper, "two coupled finger branches"
    if not branches:
        jaws = _jaws(tree, hand)
        if jaws is not None:
            return jaws, "two jaws, one hanging on the other"
    sides = _sides(tree, body, branches)
    if sides is None:
        if not branches:
            return None, "no finger branches below it"
        return None, f"{len(branches)} finger branches below '{body.name}', not two sides"
    # A side's tip is its deepest moving link; it is driven when one of its joints is not a mimic.
    tips: list[Body] = []
    leaders: list[bool] = []
    for side in sides:
        ends = [_finger_tip(tree, k) for k in side]
        # Of a linkage's two ends at one depth, the one a joint moves (Robotiq's finger tip on
        # its mimic joint) is the tip, not the link fixed on the knuckle beside it.
        tips.append(max(ends, key=lambda b: (world.depth(b), _moved(world, b), -b.index)))
        leaders.append(
            any(
                c.is_active
                for k in side
                for c in world.compute_chain_of_connections(body, _finger_tip(tree, k))
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
    bare = [t.name for t in tips if not own_geometry(t)]
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


#: Names of a hand's fingers besides the thumb, as links often carry them.
FINGER_NAMES = ("index", "middle", "ring", "pinky", "little")


@dataclass(frozen=True)
class Fingers:
    """A hand of three or more finger branches: its thumb and the others by name."""

    split: Body
    thumb: DraftFinger
    fingers: dict[str, DraftFinger]
    decide: str | None


def find_fingers(tree: Tree, hand: Body) -> Fingers | None:
    """The fingers of a hand at or below ``hand`` that splits into three or more branches.

    The thumb is the branch named so; else the one whose base lies farthest from the others'
    (it opposes them), which is a guess. The others are named by their links (``index``,
    ``middle``...) or numbered.
    """
    world = tree.world
    body, branches = _branches(tree, hand)
    if len(branches) < 3:
        return None
    names = [{w for b in world.subtree(k) for w in words(b.name)} for k in branches]
    named = [i for i, n in enumerate(names) if "thumb" in n]
    decide = None
    if len(named) == 1:
        thumb_i = named[0]
    else:
        at = [tree.position(k) for k in branches]

        def apart(i: int) -> tuple[float, float]:
            # The others' bases on one line (a palm's row of fingers), this one off it.
            others = at[:i] + at[i + 1 :]
            return (-round(_line_residual(others), 6), _off_line(at[i], others))

        thumb_i = max(range(len(at)), key=apart)
        decide = "the thumb is the finger whose base lies off the row of the others'"
        alone = _alone_on_a_side(tree, body, branches)
        if alone is not None and _no_clear_row(at):
            # Bases on a circle (D'Claw's three fingers): no row; the one opposing the others
            # across the palm is the thumb.
            thumb_i = alone
            decide = "the thumb is the finger alone on its side of the palm, opposing the others"
    fingers: dict[str, DraftFinger] = {}
    count = 0
    for i, k in enumerate(branches):
        if i == thumb_i:
            continue
        count += 1
        label = next((w for w in FINGER_NAMES if w in names[i]), f"finger_{count}")
        while label in fingers:
            label = f"{label}_{count}"
        fingers[label] = DraftFinger(k.name, _finger_tip(tree, k).name)
    thumb = branches[thumb_i]
    out = Fingers(body, DraftFinger(thumb.name, _finger_tip(tree, thumb).name), fingers, decide)
    # A finger starts at its first link past the palm; one of a single link has no chain to
    # write (Tiago's), and the hand is then drafted as a generic one.
    if any(f.root == f.tip for f in (out.thumb, *out.fingers.values())):
        return None
    return out


#: Off-row distances closer than this ratio tell no row of fingers from a thumb.
ROW_RATIO = 1.25


def _no_clear_row(at: list[np.ndarray]) -> bool:
    """Whether no base lies clearly farther off the others' row than the next one does."""
    offs = sorted(
        (_off_line(p, at[:i] + at[i + 1 :]) for i, p in enumerate(at)),
        reverse=True,
    )
    return len(offs) >= 2 and offs[0] < ROW_RATIO * offs[1]


def _alone_on_a_side(tree: Tree, split: Body, branches: list[Body]) -> int | None:
    """The one branch whose base lies on the other side of the palm's x-z plane (its y sign)."""
    inv = np.linalg.inv(tree.poses[split.index])
    ys = [float((inv @ tree.poses[k.index])[1, 3]) for k in branches]
    for sign in (1.0, -1.0):
        side = [i for i, y in enumerate(ys) if sign * y > 1e-3]
        rest = [i for i, y in enumerate(ys) if sign * y < -1e-3]
        if len(side) == 1 and len(rest) == len(ys) - 1:
            return side[0]
    return None


def _line_residual(points: list[np.ndarray]) -> float:
    """How far ``points`` are from lying on one line (the spread across their principal axis)."""
    pts = np.asarray(points)
    s = np.linalg.svd(pts - pts.mean(axis=0), compute_uv=False)
    return float(np.sqrt(np.sum(s[1:] ** 2)))


def _off_line(p: np.ndarray, others: list[np.ndarray]) -> float:
    """How far ``p`` lies from the line the ``others`` best lie on (their principal axis)."""
    pts = np.asarray(others)
    centre = pts.mean(axis=0)
    _, _, vt = np.linalg.svd(pts - centre)
    d = p - centre
    return float(np.linalg.norm(d - (d @ vt[0]) * vt[0]))


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
