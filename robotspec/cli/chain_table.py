"""The chains table of a compiled robot: kind, root, tip, joints, DOF, manipulator, sensors.

Shared by ``robotspec inspect chains`` and ``robotspec demo``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from robotspec.cli.table import emit_table

if TYPE_CHECKING:
    from robotspec.semantic import AbstractRobot, KinematicChain

__all__ = ["chain_kind", "print_chains"]


def chain_kind(robot: AbstractRobot, chain: KinematicChain) -> str:
    """What a chain is to the robot: torso, neck, finger, arm (has a manipulator) or chain."""
    if chain is robot.torso:
        return "torso"
    if chain is robot.neck:
        return "neck"
    from robotspec.semantic import Finger

    if isinstance(chain, Finger):
        return "finger"
    return "arm" if chain.manipulator is not None else "chain"


def _chain_row(robot: AbstractRobot, c: KinematicChain) -> dict[str, Any]:
    return {
        "name": c.name,
        "kind": chain_kind(robot, c),
        "root": c.root.name,
        "tip": c.tip.name,
        "joints": len(c.connections),
        "dof": len(c.degrees_of_freedom),
        "manipulator": None if c.manipulator is None else c.manipulator.name,
        "sensors": [s.name for s in c.sensors],
    }


def print_chains(robot: AbstractRobot, *, as_json: bool = False) -> None:
    """Print the robot's chains (fingers of grippers and hands too) as a table or JSON."""
    from robotspec.semantic import Hand, ParallelGripper

    items = [_chain_row(robot, c) for c in robot.all_chains]
    for m in robot.manipulators:
        if isinstance(m, ParallelGripper):
            items += [_chain_row(robot, m.thumb), _chain_row(robot, m.finger)]
        elif isinstance(m, Hand):
            items += [_chain_row(robot, f) for f in m.all_fingers]
    rows = [
        [
            i["name"],
            i["kind"],
            i["root"],
            i["tip"],
            i["joints"],
            i["dof"],
            i["manipulator"],
            ", ".join(i["sensors"]) or None,
        ]
        for i in items
    ]
    headers = ["chain", "kind", "root", "tip", "joints", "dof", "manipulator", "sensors"]
    emit_table(items, headers, rows, as_json)
