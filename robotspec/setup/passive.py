"""Passive joints, as MoveIt's Setup Assistant's screen of that name sets them.

Why in the SRDF the session keeps: a passive joint (a caster wheel, a spring, a bumper) moves
but has no motor, and a spec says so where MoveIt does, as the SRDF's ``<passive_joint>``: the
compiled robot's controlled joints leave it out (unless the spec lists ``controlled_joints``,
which then decides). So making a joint passive, or actuated again, writes the SRDF the session
keeps until save (the robot's own SRDF, or one written from the compiled robot when the spec
names none, with the joint added or dropped), names it in the spec, and remembers the choice so
a regenerated collision matrix keeps it. Each is one change undo takes back.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

from robotspec.errors import closest_names
from robotspec.setup.session import SetupError, SetupSession

if TYPE_CHECKING:
    from robotspec.description.srdf import Srdf

__all__ = ["PassiveRow", "apply_passive", "passive_rows", "set_passive"]


@dataclass(frozen=True)
class PassiveRow:
    """One moving joint: passive or not, and whether a person chose it here."""

    joint: str
    passive: bool
    by_hand: bool


def passive_rows(session: SetupSession) -> list[PassiveRow]:
    """Every moving, non-mimic joint of the robot, passive as the spec's SRDF says."""
    robot = session.validation.robot
    if robot is None:
        return []
    passive = set() if robot.srdf is None else {p.name for p in robot.srdf.passive_joints}
    chosen = dict(session.extras.passive)
    return [
        PassiveRow(c.name, c.name in passive, c.name in chosen)
        for c in robot.connections
        if c.is_active and not c.is_mimic
    ]


def apply_passive(srdf: Srdf, choices: dict[str, bool]) -> Srdf:
    """``srdf`` with a person's choices: True makes a joint passive, False actuated again."""
    from robotspec.description.srdf import PassiveJoint

    kept = [p for p in srdf.passive_joints if p.name not in choices]
    kept += [PassiveJoint(j) for j, passive in choices.items() if passive]
    return replace(srdf, passive_joints=tuple(kept))


def set_passive(session: SetupSession, joint: str, *, passive: bool) -> str:
    """Make ``joint`` passive (True) or actuated again; the SRDF is kept until save. Says what."""
    from robotspec.export.srdf import srdf_from_robot, write_srdf

    robot = session.validation.robot
    if robot is None:
        raise SetupError("the spec has errors; fix them before choosing passive joints")
    moving = [r.joint for r in passive_rows(session)]
    if joint not in moving:
        raise SetupError(
            f"no moving joint '{joint}' (a fixed or mimic joint is never planned for)",
            kind="joint",
            name=joint,
            suggestions=closest_names(joint, moving),
        )
    base = robot.srdf if robot.srdf is not None else srdf_from_robot(robot)
    srdf = apply_passive(base, {joint: passive})
    what = "passive (no motor: not planned for, not commanded)" if passive else "actuated"
    name, _ = session.keep_srdf(
        write_srdf(srdf),
        extras=lambda e: e.with_passive(joint, passive),
        what=f"joint {joint}: {what}",
    )
    note = ""
    if robot.controlled_joint_names is not None:
        note = "; the spec's controlled_joints still decides which joints are commanded"
    return f"{joint}: {what}; kept in {name} until save, and on regenerate{note}"
