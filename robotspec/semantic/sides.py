"""Which of a two-arm robot's arms is the left one (the seed's ``SpecifiesLeftRightArm``).

Why by position: arm names are the robot maker's words (``l_``, ``left_``, ``arm_1``, a part
prefix), but "left" is geometry: seen from the robot's root in its default pose, the left arm lies
on the +y side. The seed compares the second body of each chain; robotspec compares the mean
position of each arm's bodies below the chain root (frame origins, so bodies without collision
geometry still count, and an arm whose first joint sits on the root's x axis still has a side).
A spec may name the sides instead (``side: left`` on a chain); that wins.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Literal

import numpy as np

from robotspec.errors import KinematicsError

if TYPE_CHECKING:
    from robotspec.model.world import Body, World
    from robotspec.semantic.chains import KinematicChain

__all__ = ["Side", "arm_sides", "lateral_offset"]

Side = Literal["left", "right"]

#: Two arms whose mean lateral positions differ by less than this (m) have no side.
SIDE_TOLERANCE = 1e-6


def lateral_offset(
    world: World,
    root: Body,
    chain: KinematicChain,
    left: tuple[float, float, float] = (0.0, 1.0, 0.0),
) -> float:
    """Mean offset (m) of the chain's bodies below its root along the robot's ``left``.

    In ``root``'s frame, default pose; ``left`` is +y for a robot facing +x (REP 103).
    """
    from robotspec.model.kinematics import Kinematics

    kin = Kinematics(world)
    q = world.default_configuration()
    bodies = [b for b in chain.bodies if b.name != chain.root.name] or [chain.tip]
    axis = np.asarray(left, dtype=np.float64)
    ys = [float(kin.pose(q, b.name, relative_to=root.name)[:3, 3] @ axis) for b in bodies]
    return float(np.mean(ys))


def arm_sides(
    world: World,
    root: Body,
    arms: Sequence[KinematicChain],
    declared: Sequence[Side | None],
    *,
    left: tuple[float, float, float] = (0.0, 1.0, 0.0),
) -> tuple[KinematicChain, KinematicChain]:
    """(left, right) of exactly two arms: declared sides first, else position from ``root``.

    Raises:
        KinematicsError: not two arms, both declared on one side, or side by side on the
            root's x axis with no side declared.
    """
    if len(arms) != 2:
        names = ", ".join(f"'{a.name}'" for a in arms) or "none"
        raise KinematicsError(
            f"left_arm and right_arm need exactly two arms (chains with a manipulator); "
            f"this robot has {len(arms)}: {names}",
            kind="chain",
        )
    a, b = arms
    da, db = declared
    if da is not None or db is not None:
        if da == db:
            raise KinematicsError(
                f"chains '{a.name}' and '{b.name}' are both declared side: {da}",
                kind="chain",
                name=b.name,
            )
        if da == "left" or db == "right":
            return a, b
        return b, a
    ya, yb = lateral_offset(world, root, a, left), lateral_offset(world, root, b, left)
    if abs(ya - yb) < SIDE_TOLERANCE:
        raise KinematicsError(
            f"arms '{a.name}' and '{b.name}' lie side by side on the forward axis of "
            f"'{root.name}' in the default pose; declare 'side: left' on one chain in the spec",
            kind="chain",
            name=a.name,
        )
    return (a, b) if ya > yb else (b, a)
