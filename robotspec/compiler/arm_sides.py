"""Checks of a compiled robot's left and right arms against the spec's ``side`` entries.

Why after assembly: sides are geometry (positions in the default pose), which needs the
compiled chains; a declared side that contradicts the geometry is most likely a swapped name.
"""

from __future__ import annotations

from collections.abc import Mapping

from robotspec.diagnostics import Diagnostics
from robotspec.errors import KinematicsError
from robotspec.semantic import AbstractRobot
from robotspec.semantic.sides import arm_sides, lateral_offset
from robotspec.spec.models import ChainSpec

__all__ = ["check_arm_sides"]


def check_arm_sides(
    robot: AbstractRobot, chains: Mapping[str, ChainSpec], diag: Diagnostics
) -> None:
    """Record the problems of the spec's ``side`` entries and of telling the arms apart."""
    declared = {name: c.side for name, c in chains.items() if c.side is not None}
    arms = robot.arms
    arm_names = {a.name for a in arms}
    for name in declared:
        if name not in arm_names:
            diag.error(
                ("chains", name, "side"),
                f"chain '{name}' carries no manipulator; only an arm has a side",
            )
    if len(arms) != 2:
        for name in declared:
            if name in arm_names:
                diag.warning(
                    ("chains", name, "side"),
                    f"the robot has {len(arms)} arms; left_arm and right_arm need exactly two",
                )
        return
    sides = [declared.get(a.name) for a in arms]
    try:
        arm_sides(robot.world, robot.root, arms, sides, left=robot.left_axis)
    except KinematicsError as exc:
        bad = exc.name if exc.name is not None else arms[0].name
        if any(sides):
            diag.error(("chains", bad, "side"), exc.message)
        else:
            diag.warning(("chains", bad), exc.message)
        return
    if not any(sides):
        return
    a, b = arms
    ya = lateral_offset(robot.world, robot.root, a, robot.left_axis)
    yb = lateral_offset(robot.world, robot.root, b, robot.left_axis)
    left_by_position = a if ya > yb else b
    named = next(arm for arm, side in zip(arms, sides, strict=True) if side is not None)
    side = declared[named.name]
    if (side == "left") != (named is left_by_position):
        other = b if named is a else a
        where = "right" if side == "left" else "left"
        diag.warning(
            ("chains", named.name, "side"),
            f"chain '{named.name}' is declared side: {side}, but in the default pose it lies "
            f"{where} of '{other.name}' seen from '{robot.root.name}'",
        )
