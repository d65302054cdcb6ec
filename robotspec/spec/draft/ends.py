"""Where a chain ends: the flange, tool or foot link past its last joint.

Split from ``limbs`` (which finds the runs): a chain ends at the link a tool or the ground is
met on, found among the fixed children of the last moving link by where they sit (on the last
joint's axis, or the only one out from the link's origin) before their names.
"""

from __future__ import annotations

import numpy as np

from robotspec.model.entities import Body
from robotspec.spec.draft.tree import Tree, words

__all__ = ["END_WORDS", "ON_AXIS", "chain_end"]


#: Words of a link that ends a chain past its last joint (a flange, a tool, a foot).
END_WORDS = frozenset({"flange", "tool", "tool0", "ee", "eef", "tcp", "foot", "sole", "toe"})
#: How far off the last joint's axis (m) a fixed child may sit and still be on it.
ON_AXIS = 1e-3


def chain_end(tree: Tree, tip: Body, hand: Body | None, leg: bool = False) -> Body:
    """Where a chain ends: the flange, tool or foot link one fixed joint past its last joint.

    Why: a chain ends at the link a tool or the ground is met on (``docs/getting-started.md``:
    Panda's ``panda_link8``), not one fixed joint short at the last moving link. One step:
    toward the hand when there is one (never the hand itself), else to the fixed child below
    which nothing moves (never into a finger); of several, the only one on the last joint's
    axis, else the only one named as an end, else (a leg's) the one clearly lowest. Otherwise
    the last moving link.
    """
    world = tree.world
    up = world.parent_connection(tip)
    axis = None if up is None or up.is_fixed else np.asarray(up.axis, dtype=np.float64)
    kids = [k for k in world.child_bodies(tip) if (c := world.parent_connection(k)) and c.is_fixed]
    if hand is not None:
        nxt = next((k for k in kids if world.is_ancestor(k, hand)), None)
        return tip if nxt is None or nxt is hand else nxt
    kids = [k for k in kids if not tree.moves_below(k)]
    return _pick_end(tree, kids, axis) or (_lowest(tree, kids) if leg else None) or tip


#: How much lower (m) than the other fixed children a leg's foot frame must sit.
BELOW = 0.01


def _lowest(tree: Tree, kids: list[Body]) -> Body | None:
    """A leg's foot among several fixed children: the one clearly lowest in the default pose.

    Why: the foot is where the leg meets the ground, whatever the frames beside it (a contact
    sensor's, a shell's) are named; only when it is lower than each of them.
    """
    if len(kids) < 2:
        return None
    by_z = sorted(kids, key=lambda k: float(tree.position(k)[2]))
    return by_z[0] if tree.position(by_z[1])[2] - tree.position(by_z[0])[2] > BELOW else None


def _pick_end(tree: Tree, kids: list[Body], axis: np.ndarray | None) -> Body | None:
    """The fixed child a chain ends at: the only one, the one on the axis, or the one named so."""
    if len(kids) <= 1:
        return kids[0] if kids else None
    if axis is not None:
        on_axis = []
        for k in kids:
            c = tree.world.parent_connection(k)
            assert c is not None
            at = c.origin[:3, 3]
            off = at - float(at @ axis) * axis
            if float(np.linalg.norm(off)) < ON_AXIS and float(np.linalg.norm(at)) > ON_AXIS:
                on_axis.append(k)
        if len(on_axis) == 1:
            return on_axis[0]
    named = [k for k in kids if words(k.name) & END_WORDS]
    if len(named) == 1:
        return named[0]
    # The only one hung out from the link's origin, the others on it (parts of the link's
    # look: Quori's 'r_arm_upper2lower' beside the lower arm fixed 15 cm out at the elbow).
    out = [k for k in kids if float(np.linalg.norm(_origin(tree, k))) > OUT]
    return out[0] if len(out) == 1 and len(kids) - 1 == _at_origin(tree, kids) else None


#: How far out (m) a fixed child must hang to be where a chain goes on, not part of the link.
OUT = 0.05


def _origin(tree: Tree, k: Body) -> np.ndarray:
    c = tree.world.parent_connection(k)
    assert c is not None
    return np.asarray(c.origin[:3, 3], dtype=np.float64)


def _at_origin(tree: Tree, kids: list[Body]) -> int:
    return sum(1 for k in kids if float(np.linalg.norm(_origin(tree, k))) < ON_AXIS)
