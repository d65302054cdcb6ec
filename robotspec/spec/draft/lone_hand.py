"""A hand or a gripper drafted alone, from a URDF that has no arm (Allegro's, a WSG-50's).

Split from ``manipulators`` (what hangs at a chain's end) because a lone hand is found the other
way round: there is no chain to start from, so this module first decides that the robot *is* a
hand (a parallel gripper, or short limited branches leaving one palm, or links named as a hand's),
drafts the wrist between its root and where the fingers split, then lets ``manipulator`` draft it.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from robotspec.model.entities import Body
from robotspec.model.world import World
from robotspec.spec.draft.fingers import MIN_DIGITS
from robotspec.spec.draft.hands import find_gripper
from robotspec.spec.draft.limbs import (
    FINGER_WORDS,
    HAND_WORDS,
    MAX_HAND_SPAN,
    eyes,
    hand_span,
    is_named,
)
from robotspec.spec.draft.linkages import ball_joint
from robotspec.spec.draft.manipulators import manipulator
from robotspec.spec.draft.model import DraftChain, DraftManipulator
from robotspec.spec.draft.naming import unique

if TYPE_CHECKING:
    from robotspec.spec.draft.build import Drafter

__all__ = ["MAX_DIGIT_RANGE", "MAX_WRIST", "lone_hand"]

#: Most joints between a lone hand's root and where its fingers split (a wrist, not an arm).
MAX_WRIST = 3


def lone_hand(self: Drafter) -> DraftManipulator | None:
    """A hand or a gripper alone (no arm): one manipulator rooted at the robot's root.

    Why not nothing: a hand's URDF (Allegro's, a WSG-50's) is a part that specs compose onto
    an arm; its spec is its manipulator, fingers and tool frame. It is a hand when its
    fingers make a parallel gripper, or when two or more short moving branches leave its
    root, or when its links are named as a hand's.
    """
    tree, world = self.tree, self.world
    root = tree.root
    # Where the fingers split: down the single moving branch from the root, through a mount
    # (fixed joints) and a wrist (at most MAX_WRIST joints, drafted as a chain of its own).
    split, wrist = root, []
    while len(kids := tree.moving_children(split)) == 1:
        c = world.parent_connection(kids[0])
        if c is not None and c.is_active:
            wrist.append(c.name)
        split = kids[0]
    if len(wrist) > MAX_WRIST:
        split, wrist = root, []
    if eyes(tree, split):
        return None  # a head's eyes, each carrying a camera: no hand
    gripper, _ = find_gripper(tree, split, actuation=self.facts.actuation)
    # Wheels (continuous joints about a level axis turning a wheel's shape) are never fingers.
    wheels = {c.child for c in self.wheels}

    def rolls(body: Body) -> bool:
        return any(a.index in wheels for a in (*world.ancestors(body), body))

    if gripper is not None and (rolls(gripper.thumb_tip) or rolls(gripper.finger_tip)):
        gripper = None
    # Fingers have phalanges: a branch of one joint (a rotor, a wheel) is not one, unless the
    # palm has MIN_DIGITS of them on limited joints (a five-finger hand's one-joint digits).
    # Nor are a parallel mechanism's rods, each ending in a ball joint (a Stewart platform's).
    kids = [
        k
        for k in tree.moving_children(split)
        if not any(b.index in wheels for b in world.subtree(k)) and not ball_joint(world, k)
    ]
    branches = [
        k for k in kids if sum(1 for b in world.subtree(k) if not _fixed_above(world, b)) >= 2
    ]
    if len(kids) >= MIN_DIGITS and all(_limited(world, k) for k in kids):
        branches = kids
    named = any(is_named(b.name, HAND_WORDS | FINGER_WORDS) for b in world.subtree(split))
    small = hand_span(tree, split) <= MAX_HAND_SPAN
    if gripper is None and not (len(branches) >= 2 and (small or named)):
        return None
    if wrist:
        holder = DraftChain(
            unique("wrist", self.names),
            root.name,
            split.name,
            "the URDF tree",
            joints=frozenset(wrist),
            decide=[f"a wrist: {len(wrist)} joint(s) from the root to where the fingers split"],
        )
        self.draft.chains.append(holder)
    else:
        holder = DraftChain("hand", root.name, root.name, "the URDF tree")
    m = manipulator(self, holder, None, "gripper" if gripper else "hand", start=split)
    if m is not None and not wrist:
        m.decide.insert(0, "a hand alone (no arm): rooted at the robot's root")
        self.draft.lone_hand = m.name
    return m


#: The widest range (rad or m) of a digit's joint; a rotor's (Iris's 'revolute' +-1e16) is wider.
MAX_DIGIT_RANGE = 2 * math.pi


def _limited(world: World, body: Body) -> bool:
    """Whether ``body`` moves on a joint whose range a digit's could be (never a rotor's)."""
    c = world.parent_connection(body)
    if c is None or c.type.value not in ("revolute", "prismatic") or not c.dofs:
        return False
    dof = world.degrees_of_freedom[c.dofs[0]]
    return dof.is_bounded and dof.upper - dof.lower <= MAX_DIGIT_RANGE


def _fixed_above(world: World, body: Body) -> bool:
    c = world.parent_connection(body)
    return c is None or c.is_fixed
