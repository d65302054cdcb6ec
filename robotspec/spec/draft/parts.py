"""The parts that hang off the chains: cameras and the neck (or a head), and named states.

Run after the chains and manipulators are decided, because each of these is defined by them: the
neck is what carries cameras and is not an arm, a camera rides on the chain it hangs from, a named
state belongs to every part whose joints it sets. The torso and the drive, which read the robot's
trunk instead, are ``torso_drive``'s.
"""

from __future__ import annotations

import re
from typing import TYPE_CHECKING

import numpy as np

from robotspec.model.entities import Body, Connection
from robotspec.model.world import World
from robotspec.spec.draft.confidence import CAMERA_GAZEBO, camera_question
from robotspec.spec.draft.limbs import HEAD_WORDS, beside_branch
from robotspec.spec.draft.model import DraftCamera, DraftChain
from robotspec.spec.draft.naming import unique
from robotspec.spec.draft.sensors import CAMERA_WORDS, find_cameras, find_neck
from robotspec.spec.draft.srdf_groups import state_values
from robotspec.spec.draft.stated_cameras import fill_stated
from robotspec.spec.draft.tree import words

if TYPE_CHECKING:
    from robotspec.spec.draft.build import Drafter

__all__ = ["add_sensors", "add_states"]


# ------------------------------------------------------------------------ sensors, neck
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
            elif seen.mesh is not None:
                cam.decide.append(
                    f"drawn with a mesh named as a camera ('{seen.mesh}'), but not rotated as an"
                    " optical frame"
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
_MODELS = {
    "d435": "realsense_d435",
    "d435i": "realsense_d435",
    "xtion": "xtion_pro_live",
    "kinect": "kinect_v1",
}


def _model_preset(name: str) -> str | None:
    """The preset of the camera model a frame is named after (G1's 'd435_link'), if shipped.

    Whole words only: 'kinect2' is a Kinect v2 (other optics than the v1 preset), not 'kinect'.
    """
    from robotspec.spec.draft.render import camera_presets

    spaced = re.sub(r"(?<=[a-z])(?=[A-Z])", "_", name)  # camelCase splits ('kinectLink')
    tokens = set(re.split(r"[^a-z0-9]+", spaced.lower()))
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
    """Whether 1-3 revolute (limited) joints turn a head: a pan and a tilt, upwards, on top.

    Why: a head whose links are named nothing a reader knows (Booster T1's 'H1', 'H2') is
    still a pan and a tilt on top of the body; its run ends higher than it starts. A makers'
    head may also tilt before it pans, or only pan (one yaw joint); then what makes it the head
    is where it is: the highest part of the robot is on it.
    """
    if not 1 <= len(joints) <= 3 or any(c.type.value != "revolute" for c in joints):
        return False  # a caster's steer and wheel (continuous) are no head
    if any(c.child in {w.child for w in d.wheels} for c in joints):
        return False
    axes = [np.abs(d.tree.axis_in_root(c)) for c in joints]
    if not any(a[2] > 0.9 for a in axes):
        return False  # a head pans about the vertical
    if len(joints) > 1 and not any(a[2] < 0.1 for a in axes):
        return False  # ... and tilts about a level axis
    world = d.world
    start = d.tree.position(world.bodies[joints[0].parent])
    end = d.tree.position(world.bodies[joints[-1].child])
    if not end[2] > start[2] + 1e-3:
        return False
    if len(joints) > 1 and axes[0][2] > 0.9:
        return True  # pan, then tilt: the shape alone says head
    if len(joints) == 1 and not _on_a_chest(d, joints[0]):
        return False
    return _on_top(d, world.bodies[joints[-1].child])


def _on_a_chest(d: Drafter, pan: Connection) -> bool:
    """Whether a lone pan joint can be a head's: alone on a chest the arms hang from.

    A multirotor's rotors are pans on top too (example-robot-data's Iris), but they are
    siblings turning about parallel vertical axes; a lower body's waist turns its torso stub,
    the robot's top, where no arm hangs (Alexander's lower body). A head that only pans turns
    on the link its arms start from (Unitree H2's and EngineAI PM01's torso).
    """
    world, tree = d.world, d.tree
    parent = world.bodies[pan.parent]
    for k in world.child_bodies(parent):
        c = world.parent_connection(k)
        if c is None or c is pan or c.is_fixed:
            continue
        if float(np.abs(tree.axis_in_root(c))[2]) > 0.9:
            return False  # a sibling spinning about the vertical too: rotors
    return any(
        lb.kind == "arm"
        and parent.index in (lb.root.index, world.bodies[lb.segment.joints[0].parent].index)
        for lb in d.limbs
    )


def _on_top(d: Drafter, body: Body) -> bool:
    """Whether the highest frame of the robot (in the default pose) is ``body`` or below it."""
    tree, world = d.tree, d.world
    top = max(float(tree.position(b)[2]) for b in world.bodies if b.index in tree.inside)
    return max(float(tree.position(b)[2]) for b in world.subtree(body)) >= top - 1e-6


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
