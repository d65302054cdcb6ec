"""The parts that hang off the chains: cameras and the neck, the torso, the drive, named states.

Run after the chains and manipulators are decided, because each of these is defined by them: the
torso ends where the arms branch off, the neck is what carries cameras and is not an arm, a camera
rides on the chain it hangs from, a named state belongs to every part whose joints it sets.
"""

from __future__ import annotations

import re
from typing import TYPE_CHECKING

import numpy as np

from robotspec.model.entities import Body, Connection
from robotspec.model.world import World
from robotspec.spec.draft.base import fixed_wheels
from robotspec.spec.draft.confidence import (
    CAMERA_GAZEBO,
    camera_question,
    drive_question,
    drive_rule,
)
from robotspec.spec.draft.driven import counted_drive, stated_drive
from robotspec.spec.draft.limbs import HEAD_WORDS, beside_branch
from robotspec.spec.draft.model import DraftCamera, DraftChain, DraftDrive
from robotspec.spec.draft.naming import unique
from robotspec.spec.draft.sensors import CAMERA_WORDS, find_cameras, find_neck
from robotspec.spec.draft.srdf_groups import state_values
from robotspec.spec.draft.stated_cameras import fill_stated
from robotspec.spec.draft.tree import words

if TYPE_CHECKING:
    from robotspec.spec.draft.build import Drafter

__all__ = ["add_drive", "add_sensors", "add_states", "add_torso"]


# ------------------------------------------------------------------ sensors, torso, neck
#: Why a camera found by its frame's rotation alone is a question.
_BY_ROTATION = "an optical frame by its rotation; no Gazebo sensor states it"


def add_sensors(d: Drafter) -> None:
    """Cameras, the neck that carries the head's cameras, and the arms that carry the rest."""
    tree, world, draft = d.tree, d.world, d.draft
    # A frame turned as optical frames are but ending a limb (Wolfgang's 'l_wrist', the arm's
    # tip and tool frame) is the limb's, not a camera: its rotation alone said camera.
    ends = {c.tip for c in draft.chains} | {m.tool_frame for m in draft.manipulators}
    found = [
        f
        for f in find_cameras(tree)
        if f.stated is not None
        or not f.optical
        or f.body.name not in ends
        or words(f.body.name) & CAMERA_WORDS
    ]
    name_of: dict[str, str] = {}
    for seen in found:
        cam = DraftCamera(unique(seen.name, d.names), seen.body.name, seen.optical)
        if seen.doubt is not None:
            cam.decide.append(seen.doubt)
        if seen.stated is not None:  # a Gazebo sensor states it
            fill_stated(cam, seen.stated, z_ahead=_looks_along_z(d, seen.body))
            cam.stated = None if cam.decide else CAMERA_GAZEBO
            draft.cameras.append(cam)
            name_of[cam.body] = cam.name
            continue
        if not seen.optical:
            if _looks_along_z(d, seen.body):
                cam.looks_along_z = True
                cam.decide.append(
                    "named as a camera, not rotated as an optical frame; its z axis, not its x,"
                    " points the way the robot faces"
                )
            else:
                cam.decide.append("named as a camera, but not rotated as an optical frame")
        elif not cam.decide and (q := camera_question(False, _BY_ROTATION)):
            cam.decide.append(q)  # REP 103's rotation alone: which channel, is it a camera?
        model = _model_preset(seen.body.name)
        if model is not None:
            cam.preset = model
            cam.decide.append(f"preset '{model}' by the frame's name")
        draft.cameras.append(cam)
        name_of[cam.body] = cam.name
    tops = [_first_moving(world, c) for c in draft.chains if c.role in ("arm", "leg")]
    neck = find_neck(tree, found, tops)
    carried: set[str] = set()
    if neck is not None:
        n = DraftChain(
            "neck",
            neck.root.name,
            neck.tip.name,
            "the URDF tree",
            role="neck",
            joints=frozenset(j.name for j in neck.joints if j.is_active),
            yaw_body=None if neck.yaw is None else neck.yaw.name,
            pitch_body=None if neck.pitch is None else neck.pitch.name,
        )
        n.decide.append(f"{len(neck.joints)} joint(s) carrying cameras at the end of a branch")
        for seen in found:
            if world.is_ancestor(neck.tip, seen.body):
                n.sensors.append(name_of[seen.body.name])
                carried.add(seen.body.name)
        draft.neck = n
        kept = []
        for chain in draft.chains:
            if chain.joints == n.joints:
                n.source = f"{chain.source} (a neck: it carries cameras)"
                n.srdf_group = chain.srdf_group  # still a question: a group is no neck
                continue
            kept.append(chain)
        draft.chains = kept
    else:
        _add_head(d, tops)
    for cam in draft.cameras:
        if cam.body in carried:
            continue
        body = world.get_body_by_name(cam.body)
        holders = [c for c in draft.chains if world.is_ancestor(_first_moving(world, c), body)]
        if holders:
            best = max(holders, key=lambda c: world.depth(c.tip))
            best.sensors.append(cam.name)


#: Camera models a frame's name can say, and the preset of ``templates/cameras.yaml`` for each.
_MODELS = {"d435": "realsense_d435", "xtion": "xtion_pro_live", "kinect": "kinect_v1"}


def _model_preset(name: str) -> str | None:
    """The preset of the camera model a frame is named after (G1's 'd435_link'), if shipped."""
    from robotspec.spec.draft.render import camera_presets

    tokens = set(re.split(r"[^a-z0-9]+", name.lower())) | words(name)
    for word, preset in _MODELS.items():
        if word in tokens and preset in camera_presets():
            return preset
    return None


def _looks_along_z(d: Drafter, body: Body) -> bool:
    """Whether a camera's body frame, turned on its joint, looks along its z axis (Baxter's).

    Only for a frame off the limbs (a head's, the body's), rotated from its parent, whose z axis
    points the way the robot faces in the default pose and whose x axis does not.
    """
    world = d.world
    c = world.parent_connection(body)
    if c is None or not c.is_fixed or np.allclose(c.origin[:3, :3], np.eye(3), atol=1e-6):
        return False
    if any(world.is_ancestor(world.bodies[lb.segment.joints[0].child], body) for lb in d.limbs):
        return False
    rot = d.tree.pose(body)[:3, :3]
    ahead = np.asarray(d.forward, dtype=np.float64)
    along_x, along_z = float(rot[:, 0] @ ahead), float(rot[:, 2] @ ahead)
    return along_z > 0.7 and along_x < 0.5


def _add_head(d: Drafter, limb_tops: list[Body]) -> None:
    """A head that carries no camera frame (GR1T2's): a chain of its own, not a neck.

    A neck must carry a camera; a head whose URDF has none is still a part a person moves, so
    it is drafted as ``kind: chain`` with the reason, to become the neck once a camera frame is
    added.
    """
    tree, world = d.tree, d.world
    for seg in tree.segments:
        if tree.moving_children(seg.end) or not seg.joints:
            continue
        if not 1 <= len(seg.joints) <= 4:
            continue
        if any(c.type.value not in ("revolute", "continuous") for c in seg.joints):
            continue
        names = [b.name for b in seg.bodies] + [c.name for c in seg.joints]
        named = any(words(n) & HEAD_WORDS for n in names)
        if not (named or _pan_tilt(d, seg.joints)):
            continue
        if any(world.is_ancestor(top, seg.start) for top in limb_tops):
            continue
        joints = frozenset(c.name for c in seg.joints if c.is_active)
        if not joints or any(c.joints & joints for c in d.draft.chains):
            continue
        if any(m.joints & joints for m in d.draft.manipulators):
            continue  # a finger of a drafted hand (Barrett's), never a head
        first, last = seg.joints[0], seg.joints[-1]
        head = DraftChain(
            unique("head", d.names),
            world.bodies[first.parent].name,
            world.bodies[last.child].name,
            "the URDF tree",
            role="chain",
            joints=joints,
        )
        head.decide.append(
            f"a head of {len(seg.joints)} joint(s) without a camera frame: a neck once one is added"
        )
        d.draft.chains.append(head)
        return


def _pan_tilt(d: Drafter, joints: tuple[Connection, ...] | list[Connection]) -> bool:
    """Whether 2-3 revolute (limited) joints turn about the vertical, then a level axis, upwards.

    Why: a head whose links are named nothing a reader knows (Booster T1's 'H1', 'H2') is
    still a pan and a tilt on top of the body; its run ends higher than it starts.
    """
    if not 2 <= len(joints) <= 3 or any(c.type.value != "revolute" for c in joints):
        return False  # a caster's steer and wheel (continuous) are no head
    if any(c.child in {w.child for w in d.wheels} for c in joints):
        return False
    axes = [np.abs(d.tree.axis_in_root(c)) for c in joints]
    if not (axes[0][2] > 0.9 and any(a[2] < 0.1 for a in axes[1:])):
        return False
    world = d.world
    start = d.tree.position(world.bodies[joints[0].parent])
    end = d.tree.position(world.bodies[joints[-1].child])
    return bool(end[2] > start[2] + 1e-3)


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
    if not joints or any(
        c.name in ch.joints for c in path for ch in draft.chains if ch.joints != joints
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
    if draft.drive is not None and not planner:
        draft.drive.decide = drive_question(virtual, moves)
        draft.drive.stated = drive_rule(virtual, moves)
        if virtual == "floating" and not moves:  # nothing can float it: a base bolted down
            draft.drive = DraftDrive("fixed", None, None, draft.drive.source, draft.drive.decide)
        return
    stated = stated_drive(d.tree, d.facts, wheels) if wheels and movable else None
    if stated is not None:  # what the transmissions or a Gazebo drive plugin say
        draft.drive = stated
        if planner and stated.decide is None:  # the files disagree: asked
            stated.decide, stated.stated = f"{stated.source}, but the SRDF's is fixed", None
    elif wheels and movable:
        kind = counted_drive(d.tree, wheels)
        why = f"{len(wheels)} wheel joints" + (f", {len(casters)} steered casters" * bool(casters))
        draft.drive = DraftDrive(kind, None, None, "the URDF tree", f"{why}: {kind}?")
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


# ----------------------------------------------------------------------------- states
def add_states(d: Drafter) -> None:
    """SRDF group states become named states of every part whose joints they set."""
    if d.srdf is None:
        return
    world, draft = d.world, d.draft
    parts: list[tuple[str | None, frozenset[str], dict[str, dict[str, float]], str]] = []
    for c in [*draft.chains, *(p for p in (draft.torso, draft.neck) if p is not None)]:
        parts.append((c.srdf_group, c.joints, c.states, c.name))
    for m in draft.manipulators:
        parts.append((None, m.joints, m.states, m.name))
    for state, group, values in state_values(d.srdf):
        for part_group, joints, states, part in parts:
            if not joints or state in states:
                continue
            if not (joints <= values.keys() or (group is not None and group == part_group)):
                continue
            chosen = {
                j: v
                for j, v in values.items()
                if j in joints and world.get_connection_by_name(j).is_1dof
            }
            if not chosen:
                continue
            bad = [j for j, v in chosen.items() if not _within(world, j, v)]
            if bad:
                draft.notes.append(
                    f"SRDF state {state!r} of {part!r} left out: {bad[0]!r} is outside its limits"
                )
                continue
            states[state] = chosen


def _first_moving(world: World, chain: DraftChain) -> Body:
    """The body below a chain's first moving joint (what the chain carries starts there)."""
    conns = world.compute_chain_of_connections(chain.root, chain.tip)
    moving = [c for c in conns if not c.is_fixed]
    first = moving[0] if moving else (conns[-1] if conns else None)
    # A head turned beside the chain on its first link (Sawyer's) is not what the chain carries.
    if len(moving) > 1 and beside_branch(world, world.bodies[moving[0].child], chain.tip):
        first = moving[1]
    return world.get_body_by_name(chain.tip) if first is None else world.bodies[first.child]


def _within(world: World, joint: str, value: float) -> bool:
    dof = world.degrees_of_freedom[world.get_connection_by_name(joint).dofs[0]]
    return dof.lower - 1e-9 <= value <= dof.upper + 1e-9
