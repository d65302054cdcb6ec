"""A one-jaw gripper at an arm's end: one moving jaw closing onto a jaw fixed to the wrist.

Split from ``limbs`` (where an arm ends): such a gripper (Darwin-OP's, Spot's) has one joint
below the wrist, and that joint is the gripper's, not the arm's last. What says so is the
structure, not the names: the moving jaw is a leaf on a joint that swings it (a limited range,
its axis across the way it sticks out), and beside it on the same link hangs a fixed leaf with
collision geometry reaching at least as far out as the moving jaw's hinge. Where the fixed jaw
reaches is read from its geometry (Spot's jaw link sits at the wrist's origin, its shape 20 cm
out), not only from where its joint puts its frame.
"""

from __future__ import annotations

import math

import numpy as np

from robotspec.model.entities import Body
from robotspec.spec.draft.tips import far_end
from robotspec.spec.draft.tree import Segment, Tree

__all__ = ["MAX_JAW_RANGE", "one_jaw"]

#: The widest swing (rad) of a moving jaw: three quarters of a turn (a hobby servo's +-120
#: degrees, AiNex's jaw). A wrist's last joint turns farther (FAIRINO's +-175 degrees, about
#: an axis that, in the default pose, may lie across its offset as a jaw's does).
MAX_JAW_RANGE = 1.5 * math.pi
#: How far from square to the way it sticks out a jaw's axis may be (the cosine between them).
ACROSS = 0.3


def one_jaw(tree: Tree, seg: Segment, cut: int, named: bool = True) -> bool:
    """Whether ``seg.bodies[cut]`` is a gripper's one moving jaw (its run's end, a leaf).

    ``named``: the link was found by a hand's or finger's name; unnamed, the joint must also
    swing like a jaw (a revolute joint of limited range whose axis lies across its offset, or a
    prismatic one), so that a wrist's last roll beside a fixed camera is not taken for a jaw.
    """
    world = tree.world
    jaw = seg.bodies[cut]
    c = world.parent_connection(jaw)
    if cut == 0 or jaw is not seg.end or world.child_bodies(jaw) or c is None or c.is_fixed:
        return False
    hinge = float(np.linalg.norm(c.origin[:3, 3]))
    if not named and not _swings(tree, jaw, hinge):
        return False
    carrier = seg.bodies[cut - 1]
    at = np.asarray(c.origin[:3, 3], dtype=np.float64)
    if any(
        _fixed_jaw_reaches(tree, carrier, k, at, hinge)
        for k in world.child_bodies(carrier)
        if k is not jaw
    ):
        return True
    # The fixed jaw modelled as the carrier's own shape (Spot's 'arm_link_wr1' holds the front
    # jaw's meshes): it reaches past the hinge by half the moving jaw's length or more (an
    # upper arm's shape ends near its elbow, well short of half the forearm). A link named as
    # a gripper must swing like a jaw too (a wrist turning a gripper rolls about its offset).
    if not carrier.collisions or (named and not _swings(tree, jaw, hinge)):
        return False
    past = _reach(tree, carrier, carrier, at) - hinge
    return past > 0 and past >= JAW_OVERLAP * _reach(tree, jaw, carrier, at)


#: How much of the moving jaw's length a carrier's own shape must reach past the hinge.
JAW_OVERLAP = 0.5


def _reach(tree: Tree, body: Body, carrier: Body, hinge_at: np.ndarray) -> float:
    """How far ``body``'s shape reaches, the way the hinge lies from the carrier's origin."""
    pose = tree.poses[carrier.index]
    way = pose[:3, :3] @ hinge_at
    n = float(np.linalg.norm(way))
    if n < 1e-9:
        return 0.0
    here = tree.poses[body.index][:3, 3]
    end = far_end(tree, body, way)
    base = float((here - pose[:3, 3]) @ (way / n)) if body is carrier else 0.0
    return base + float((end - here) @ (way / n))


def _swings(tree: Tree, jaw: Body, hinge: float) -> bool:
    """Whether ``jaw``'s joint moves it as a jaw: a short swing across its offset, or a slide."""
    world = tree.world
    c = world.parent_connection(jaw)
    if c is None or not c.dofs:
        return False
    kind = c.type.value
    if kind == "prismatic":
        return True
    if kind != "revolute" or hinge < 1e-6:
        return False
    dof = world.degrees_of_freedom[c.dofs[0]]
    if not dof.is_bounded or dof.upper - dof.lower > MAX_JAW_RANGE:
        return False
    axis = np.asarray(c.axis, dtype=np.float64)
    out = c.origin[:3, :3].T @ c.origin[:3, 3]  # the offset, in the jaw's frame
    n = float(np.linalg.norm(axis)) * float(np.linalg.norm(out))
    return n > 1e-9 and abs(float(axis @ out)) / n <= ACROSS


def _fixed_jaw_reaches(
    tree: Tree, carrier: Body, k: Body, hinge_at: np.ndarray, hinge: float
) -> bool:
    """Whether ``k`` is a fixed leaf with collision geometry as far out as the moving hinge."""
    world = tree.world
    f = world.parent_connection(k)
    if f is None or not f.is_fixed or world.child_bodies(k) or not k.collisions:
        return False
    if float(np.linalg.norm(f.origin[:3, 3])) >= hinge:
        return True
    # Its shape's far end the way the hinge lies from the carrier (world frame, default pose).
    pose = tree.poses[carrier.index]
    way = pose[:3, :3] @ np.asarray(hinge_at, dtype=np.float64)
    end = far_end(tree, k, way)
    reach = float((end - pose[:3, 3]) @ (way / max(float(np.linalg.norm(way)), 1e-9)))
    return reach >= hinge
