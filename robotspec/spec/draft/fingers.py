"""A hand of three or more fingers: which branch is the thumb, and the others by name.

Split from ``hands`` (parallel grippers and tool frames): a thumb is found by its name, else by
structure: the one finger that is no copy of the others (``thumbs``), or where its base lies
against the other fingers' (off their row, or alone across the palm), guesses the draft marks.
Which branches are fingers at all is read from their shapes, or where those are missing from
masses, ranges and mimic tags (``bare_fingers``); a linkage's rods and anything turning without
end never are (``linkages``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robotspec.model.entities import Body
from robotspec.model.world import World
from robotspec.spec.draft.bare_fingers import bare_branches
from robotspec.spec.draft.model import DraftFinger
from robotspec.spec.draft.thumbs import odd_by_shape
from robotspec.spec.draft.tips import world_points
from robotspec.spec.draft.tool_frames import bare_fixed_leaf
from robotspec.spec.draft.tree import Tree, solid, words

__all__ = ["FINGER_NAMES", "Fingers", "find_fingers", "finger_tip", "hand_branches"]


def hand_branches(tree: Tree, hand: Body) -> tuple[Body, list[Body]]:
    """Where the hand first splits (below its single links), and the moving branches there.

    The branches with geometry, and those without whose masses, ranges and mimic tags say they
    are fingers too (``bare_fingers``: a thumb whose meshes are missing beside shaped fingers).
    Where one branch is left of several, the hand splits below it.
    """
    body = hand
    while True:
        kids = tree.moving_children(body)
        if len(kids) != 1:
            break
        body = kids[0]
    branches = bare_branches(tree, kids)
    if len(kids) >= 2 and len(branches) == 1 and _rigid_to_split(tree, branches[0]):
        # The others were no fingers (a gripper motor's prop turning without end beside the
        # finger carriage, Interbotix's): the fingers split further down the one left, where
        # fixed joints carry it (a joint on the way would make it a limb, not a carriage).
        below, deeper = hand_branches(tree, branches[0])
        if len(deeper) >= 2:
            return below, deeper
    return body, branches


def _rigid_to_split(tree: Tree, body: Body) -> bool:
    """Whether ``body`` hangs on a fixed joint and fixed joints alone lead down to its split."""
    world = tree.world
    while True:
        c = world.parent_connection(body)
        if c is None or not c.is_fixed:
            return False
        kids = tree.moving_children(body)
        if len(kids) != 1:
            return True
        body = kids[0]


def finger_tip(tree: Tree, branch: Body) -> Body:
    """The deepest body of a finger branch that a moving joint carries, with geometry if any.

    Geometry first: PR2's xacro hangs a bare frame on a prismatic joint below the finger tip.
    """
    world: World = tree.world
    inside = world.subtree(branch)
    moved = [b for b in inside if (c := world.parent_connection(b)) is not None and not c.is_fixed]
    # A fixed tip link with geometry is the finger's tip (Baxter's 'r_gripper_l_finger_tip');
    # collision geometry first: a leaf with a look only is a decoration (HSR-B's vacuum pad).
    collided = [b for b in inside if b.collisions]
    # A moving link with a mass but no shape is a part whose shape is missing (Shadow's distal
    # phalanx once its mesh is gone, past the middle one's primitive collision).
    missing = [b for b in moved if b.mass and not (b.visuals or b.collisions)]
    if missing and not collided:
        # No collision shape at all: the finger's parts are its links with a mass, fixed ones
        # too (Dex1's pads), but not a fixed leaf with a look only (the vacuum pad, the one
        # visual left once meshes are gone).
        parts = [b for b in inside if b.mass and not _decoration(world, b)]
    else:
        parts = collided + missing
    parts = (
        parts
        or [b for b in inside if b.visuals]
        or [b for b in inside if solid(world, b)]  # a file without shapes: links with a mass
    )
    tip = max(parts or moved or [branch], key=lambda b: (world.depth(b), -b.index))
    tip = _unfolded(tree, branch, tip)
    # A bare frame the URDF fixes at the end of the last phalanx is the tip it names (Ability's
    # 'index_tip', D'Claw's 'link_f1_head'): the only bare leaf hanging there.
    bare = [k for k in world.child_bodies(tip) if bare_fixed_leaf(world, k)]
    if len(bare) == 1 and all(not world.child_bodies(k) for k in world.child_bodies(tip)):
        return bare[0]
    return tip


#: How much farther (m) the link above must reach for a folding-back leaf not to be the tip.
FOLD_MARGIN = 0.01


def _unfolded(tree: Tree, branch: Body, tip: Body) -> Body:
    """The tip, or the moving link it hangs on when the tip folds back toward the finger's base.

    Why: a linkage finger cut open below its pad (TidyBot++'s Robotiq 2F-85, whose inner
    knuckle hangs on the inner finger) ends on a rod that reaches back to the hand; the finger
    ends where its geometry reaches farthest from its base, on the link above. Only when both
    links' shapes are known and the one above reaches clearly farther.
    """
    world = tree.world
    up = world.parent_connection(tip)
    if tip is branch or up is None or up.is_fixed or world.child_bodies(tip):
        return tip
    above = world.bodies[up.parent]
    if above is not branch and not world.is_ancestor(branch, above):
        return tip
    if not _moves(world, above) or not above.collisions:
        return tip
    base = tree.position(branch)
    reach = [_farthest_from(tree, b, base) for b in (above, tip)]
    if reach[0] is None or reach[1] is None or reach[0] - reach[1] < FOLD_MARGIN:
        return tip
    return above


def _farthest_from(tree: Tree, body: Body, point: np.ndarray) -> float | None:
    """How far ``body``'s geometry reaches from ``point`` in the default pose (None: no shape)."""
    at = world_points(tree, body)
    if not len(at):
        return None
    return float(np.max(np.linalg.norm(at - point, axis=1)))


def _decoration(world: World, body: Body) -> bool:
    """Whether ``body`` is a fixed leaf with a look (visual) but no collision shape."""
    c = world.parent_connection(body)
    fixed = c is not None and c.is_fixed
    return fixed and bool(body.visuals) and not body.collisions and not world.child_bodies(body)


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
    body, branches = hand_branches(tree, hand)
    branches = _through_plates(tree, branches)
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
        unspread = _without_spread(world, branches)
        odd = odd_by_shape(world, branches)
        if unspread is not None:
            thumb_i = unspread
            decide = "the thumb is the finger with no spread joint, opposing the two that turn"
        elif odd is not None:
            thumb_i = odd
            decide = "the thumb is the one finger unlike the others (copies of one finger)"
        elif alone is not None and _no_clear_row(at):
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
        fingers[label] = DraftFinger(k.name, finger_tip(tree, k).name)
    thumb = branches[thumb_i]
    out = Fingers(body, DraftFinger(thumb.name, finger_tip(tree, thumb).name), fingers, decide)
    # A finger starts at its first link past the palm; one of a single link has no chain to
    # write (Tiago's, Mia's one-joint digits), and the hand is then drafted as a generic one.
    if any(f.root == f.tip for f in (out.thumb, *out.fingers.values())):
        return None
    return out


def _without_spread(world: World, branches: list[Body]) -> int | None:
    """Of three fingers, the one with a joint fewer than the two others (which have as many).

    Why: a three-finger hand turns two fingers about the palm on spread joints to face the
    third, fixed to the palm (BarrettHand's finger 3, Robotiq's middle finger, DH-3's finger
    2): that one opposes them, as a thumb; its joints say so whatever the fingers are named.
    """
    if len(branches) != 3:
        return None
    counts = [sum(1 for b in world.subtree(k) if _moves(world, b)) for k in branches]
    low = min(counts)
    if counts.count(low) != 1 or len({c for c in counts if c != low}) != 1:
        return None
    if max(counts) - low != 1:
        return None
    return counts.index(low)


#: Branches from one palm that make a hand whose one-link branches are fingers too.
MIN_DIGITS = 4


def _through_plates(tree: Tree, branches: list[Body]) -> list[Body]:
    """Each branch, or the finger branches of a palm plate it is (Schunk SVH's ring and pinky).

    A plate moves on its own joint and splits into two or more branches that each bend
    (two or more moving links): the fingers are those, not the plate.
    """
    world = tree.world
    out: list[Body] = []
    for k in branches:
        split, subs = hand_branches(tree, k)
        bending = [s for s in subs if sum(1 for b in world.subtree(s) if _moves(world, b)) >= 2]
        out += bending if len(subs) >= 2 and len(bending) == len(subs) else [k]
    return out


def _moves(world: World, body: Body) -> bool:
    c = world.parent_connection(body)
    return c is not None and not c.is_fixed


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
