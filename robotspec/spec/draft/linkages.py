"""Moving branches that are no fingers, whatever their shapes: ball joints and free turns.

Why: a hand's fingers are told from the other branches of a split by what the joints state, not
by names: a finger's joints have a finger's range (a screw, a wheel or a propeller turns without
end), and no finger has a ball joint (three revolute joints at one point, each turning a full
circle: a parallel mechanism's rod, as on a Stewart platform's six legs, which otherwise look
like six identical fingers on a circle).
"""

from __future__ import annotations

import math

import numpy as np

from robotspec.description.actuation import Actuation
from robotspec.model.entities import Body, Connection
from robotspec.model.world import World

__all__ = ["MAX_FINGER_RANGE", "ball_joint", "moving_joints", "one_actuator", "turns_freely"]

#: The widest range (rad or m) of a finger's joint; a screw's or a wheel's is unbounded.
MAX_FINGER_RANGE = 2 * math.pi
#: Joints this close together (m) turn about one point.
AT_ONE_POINT = 1e-6


def moving_joints(world: World, branch: Body) -> list[Connection]:
    """The moving joints of ``branch``'s subtree, the one into it first."""
    return [
        c for b in world.subtree(branch) if (c := world.parent_connection(b)) and not c.is_fixed
    ]


def turns_freely(world: World, branch: Body) -> bool:
    """Whether a joint of ``branch`` has no finger's range (unbounded, or wider than a turn).

    A mimic joint moves within its leader's range, whatever its type says (BCN3D Moveo's
    'continuous' finger tip following its gear).
    """
    for c in moving_joints(world, branch):
        for d in c.dofs:
            dof = world.degrees_of_freedom[d]
            if not dof.is_bounded or dof.upper - dof.lower > MAX_FINGER_RANGE:
                return True
    return False


def ball_joint(world: World, branch: Body) -> bool:
    """Whether ``branch`` holds three revolute joints in a row turning about one point.

    Two joints at one point are common in fingers (a knuckle's spread and flex, a thumb's
    base); three, with axes spanning space, are a spherical joint: a linkage, not a digit.
    """
    for b in world.subtree(branch):
        run = _run_at_one_point(world, b)
        if len(run) >= 3:
            rot = np.eye(3)
            axes = []
            for c in run[-3:]:  # each axis in the frame of the first's parent, joints at zero
                rot = rot @ c.origin[:3, :3]
                axes.append(rot @ np.asarray(c.axis, dtype=np.float64))
            if abs(float(np.linalg.det(np.array(axes)))) > 0.5:
                return True
    return False


def _run_at_one_point(world: World, body: Body) -> list[Connection]:
    """The revolute joints up from ``body`` whose origins add no offset (the top one's first)."""
    run: list[Connection] = []
    c = world.parent_connection(body)
    while c is not None and c.type.value in ("revolute", "continuous"):
        run.append(c)
        if float(np.linalg.norm(c.origin[:3, 3])) > AT_ONE_POINT:
            break  # this joint sits away from its parent's: the run starts here
        c = world.parent_connection(world.bodies[c.parent])
    return run[::-1]


def one_actuator(world: World, branches: list[Body], actuation: Actuation | None) -> bool:
    """Whether the control blocks drive exactly one joint of ``branches``, the rest following.

    Why: a linkage gripper's file may leave out the mimic tags (a simulator couples its links
    by a plugin) while its transmission or ``ros2_control`` block still names the one joint a
    motor drives; the others are passive (named so, or named by no block).
    """
    if actuation is None or not actuation.stated:
        return False
    joints = [c for k in branches for c in moving_joints(world, k)]
    driven = [c for c in joints if c.name in actuation.joints and c.name not in actuation.passive]
    return len(driven) == 1
