"""Notes ``robotspec inspect`` prints about choices a spec may make on purpose.

Why notes and not warnings: turning the SRDF's collision rules off, or controlling no joint, is
allowed (a spec for perception only, a robot checked without its SRDF), so ``validate`` accepts
it; but a reader of the compiled robot should not have to discover it.
"""

from __future__ import annotations

import sys
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from robotspec.semantic import AbstractRobot

__all__ = ["print_notes", "robot_notes"]


def robot_notes(robot: AbstractRobot) -> list[str]:
    """What the spec turned off: the SRDF's collision rules, every controlled joint."""
    out = []
    srdf = robot.srdf
    if srdf is not None and srdf.disabled_collisions and not robot.disabled_collision_pairs:
        out.append(
            f"the spec turns the SRDF's collision rules off (collision: {{use_srdf: false}}): "
            f"its {len(srdf.disabled_collisions)} disable_collisions entries are not applied"
        )
    if robot.controlled_joint_names is not None and not robot.controlled_joint_names:
        out.append("the spec controls no joints (controlled_joints: [])")
    return out


def print_notes(robot: AbstractRobot) -> None:
    """The notes, one per line on stderr (stdout stays a table or JSON)."""
    for note in robot_notes(robot):
        sys.stderr.write(f"note: {note}\n")
