"""The parts that carry the rest or move the whole robot: the torso and the drive.

Split from ``parts`` (cameras, the neck, named states) because these two read the robot's trunk,
not what hangs off the chains: the torso is the run of joints from the root to where the arms
branch off (or the waist down to the legs), and the drive is what moves the root (the SRDF's
virtual joint, else wheels, legs or rotors). Both run after the chains are decided.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from robotspec.model.entities import Body, Connection
from robotspec.model.world import World
from robotspec.spec.draft.base import fixed_wheels
from robotspec.spec.draft.confidence import drive_question, drive_rule
from robotspec.spec.draft.driven import counted_drive, stated_drive
from robotspec.spec.draft.model import DraftChain, DraftDrive
from robotspec.spec.draft.tree import words

if TYPE_CHECKING:
    from robotspec.spec.draft.build import Drafter

__all__ = ["add_drive", "add_torso"]


# ------------------------------------------------------------------------------ torso
def add_torso(d: Drafter) -> None:
    """The moving joints between the robot's root and where its arms branch off."""
    world, draft = d.world, d.draft
    arms = [c for c in draft.chains if c.role == "arm"]
    if not arms:
        return
    branch = world.get_body_by_name(arms[0].root)
    for c in arms[1:]:
        branch = world.common_ancestor(branch, c.root)
    root = d.tree.root
    if not world.is_ancestor(root, branch):
        return
    # A floating or planar joint moves the whole robot (CURI's 'reference' from 'world'): the
    # drive's, never the torso's.
    path = [
        c
        for c in world.compute_chain_of_connections(root, branch)
        if not c.is_fixed and c.type.value not in ("floating", "planar")
    ]
    why = f"the joints between the root and where the arms branch ('{branch.name}')"
    if not path:  # rooted where the arms branch (Booster T1's trunk): the waist below it
        path, why = _waist(d, branch)
        if not path:
            return
    joints = frozenset(c.name for c in path if c.is_active)
    # An SRDF group of some of these joints and no limb's (SEED-Noid's 'lifter' and 'waist',
    # grouped again as 'torso') is a part of the torso a planner moves alone: folded into it.
    parts = {
        id(ch) for ch in draft.chains if ch.role == "chain" and ch.joints and ch.joints < joints
    }
    if not joints or any(
        c.name in ch.joints
        for c in path
        for ch in draft.chains
        if ch.joints != joints and id(ch) not in parts
    ):
        return
    t = DraftChain(
        "torso",
        world.bodies[path[0].parent].name,
        world.bodies[path[-1].child].name,
        "the URDF tree",
        role="torso",
        joints=joints,
    )
    t.decide.append(why)
    kept = []
    for c in draft.chains:
        if c.joints == joints:
            t.source, t.srdf_group = c.source, c.srdf_group  # still a question (confidence)
            continue
        if id(c) in parts:
            t.decide.append(f"the SRDF group '{c.srdf_group or c.name}' moves part of it")
            continue
        kept.append(c)
    draft.chains = kept
    draft.torso = t


def _waist(d: Drafter, branch: Body) -> tuple[list[Connection], str]:
    """The moving joints from where the arms branch down to where the legs branch, if any.

    Why: a humanoid rooted at its upper body has its torso's joints below the root, between
    the arms and the legs (a waist); written from the root down, as the URDF's tree runs.
    """
    world = d.world
    legs = [c for c in d.draft.chains if c.role == "leg"]
    if len(legs) < 2:
        return [], ""
    hips = world.get_body_by_name(legs[0].root)
    for c in legs[1:]:
        hips = world.common_ancestor(hips, c.root)
    if hips is branch or not world.is_ancestor(branch, hips):
        return [], ""
    path = [c for c in world.compute_chain_of_connections(branch, hips) if not c.is_fixed]
    return (
        path,
        f"the joints between where the arms branch ('{branch.name}') and the legs ('{hips.name}')",
    )


# ------------------------------------------------------------------------------ drive
_ROTOR_WORDS = frozenset({"rotor", "propeller", "prop"})


def _rotor(world: World, c: Connection) -> bool:
    """Whether a joint or the link it carries is named as a rotor (Crazyflie's 'prop0_link')."""
    return bool((words(c.name) | words(world.bodies[c.child].name)) & _ROTOR_WORDS)


def add_drive(d: Drafter) -> None:
    """From the SRDF's virtual joint, else guessed from wheels, legs or rotors."""
    draft, world = d.draft, d.world
    if draft.drive is not None and d.own_base is not None:
        return  # the URDF's own base joints: own_drive said what to check
    joints = [c for c in world.connections if not c.is_fixed]
    wheels = d.wheels
    casters = [c for c in joints if "caster" in words(c.name) and "wheel" not in words(c.name)]
    legs = [c for c in draft.chains if c.role == "leg"]
    rotors = [c for c in joints if words(c.name) & _ROTOR_WORDS]
    if not rotors:  # propellers modelled on fixed joints (a simulator's multirotor): 3 or more
        fixed = [c for c in world.connections if c.is_fixed and _rotor(world, c)]
        rotors = fixed if len(fixed) >= 3 else []
    movable = d.tree.root is world.root
    planner = False  # the SRDF's fixed virtual joint on a robot with wheels: a planner's
    if draft.drive is not None:  # the SRDF's virtual joint: stated, or a question (confidence)
        virtual = {"omni": "planar"}.get(draft.drive.type, draft.drive.type)
        moves = bool(wheels or len(legs) >= 2 or rotors)
        planner = virtual == "fixed" and bool(wheels) and movable
    rolls = bool(wheels) and movable and len(legs) < 2 and not rotors
    if draft.drive is not None and virtual in ("planar", "floating") and rolls:
        # MoveIt models a wheeled base as a planar (or floating) joint, whatever its wheels: the
        # URDF's wheels say how it drives (a drive plugin states it; two on one axle:
        # differential). Only on wheels alone: legs or rotors may float the robot.
        wheeled = _wheeled_drive(d, wheels, casters)
        if wheeled.type != "omni" or virtual == "floating":
            said = f"the SRDF's joint is {virtual}"
            wheeled.decide = wheeled.decide and f"{wheeled.decide}; {said}"
            draft.drive = wheeled
            return
    if draft.drive is not None and not planner:
        draft.drive.decide = drive_question(virtual, moves)
        draft.drive.stated = drive_rule(virtual, moves)
        if virtual == "floating" and not moves:  # nothing can float it: a base bolted down
            draft.drive = DraftDrive("fixed", None, None, draft.drive.source, draft.drive.decide)
        return
    if wheels and movable:
        draft.drive = _wheeled_drive(d, wheels, casters)
        stated = draft.drive
        if planner and stated.stated is not None:  # the files disagree: asked
            stated.decide, stated.stated = f"{stated.source}, but the SRDF's is fixed", None
    elif (len(legs) >= 2 or rotors) and movable:
        why = f"{len(legs)} legs" if len(legs) >= 2 else f"{len(rotors)} rotors"
        draft.drive = DraftDrive("floating", None, None, "the URDF tree", f"{why}: floating")
    elif movable and (held := fixed_wheels(world)):  # MPO-500: no joint of the base moves
        # The file models the wheels only for their look; the robot still drives on them.
        kind = "differential" if len(held) == 2 else "omni"
        why = f"{len(held)} wheels on fixed joints (none turns in this file): {kind}?"
        draft.drive = DraftDrive(kind, None, None, "the URDF tree", why)
    else:
        draft.drive = DraftDrive(
            "fixed", None, None, "the URDF tree", "no wheels, legs or rotors: a fixed base"
        )


def _wheeled_drive(d: Drafter, wheels: list[Connection], casters: list[Connection]) -> DraftDrive:
    """The drive of a wheeled base: what the transmissions or a drive plugin say, else counted."""
    stated = stated_drive(d.tree, d.facts, wheels)
    if stated is not None:
        return stated
    kind = counted_drive(d.tree, wheels)
    why = f"{len(wheels)} wheel joints" + (f", {len(casters)} steered casters" * bool(casters))
    return DraftDrive(kind, None, None, "the URDF tree", f"{why}: {kind}?")
