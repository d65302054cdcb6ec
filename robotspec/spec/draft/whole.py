"""Whether the files state a drafted item WHOLE: the checks that keep a ``DECIDE`` mark.

Why a pass of its own (issue 30, item 3): a rule of ``confidence`` drops an item's mark because
a file states it, but a file often states only part of the item. A Gazebo sensor states that a
camera exists and where it sees from, not which of the device's frames the spec wants; a mimic
tag states that two fingers are coupled, not where their tips are; a TCP name states a frame,
not that it is the only one; a drive plugin states a drive in simulation, which a planar-move
plugin fakes for any base. Drafts of robots seen for the first time showed wrong items left
unmarked exactly there. This pass runs after every part is drafted and only ever ADDS a mark
(and clears the rule that had dropped it), where the files leave part of the item to inference:

============  ==========================================================================
item          keeps (gets back) its mark when
============  ==========================================================================
camera        it is one eye of a stereo pair (two identical imagers on one mount, side by
              side: one camera or two?); the sensor's type is no plain image camera
              (thermal, segmentation, a logical camera); another sensor of the device sees
              from a frame the draft did not take, or a bare frame fixed beside the camera
              (within 10 cm, not where a drafted camera is) looks the same way (a colour
              optical frame beside the depth one the sensor sits on), unless the chosen
              frame alone is named as the colour channel; the frame is neither where the
              sensor sees from, nor its link, nor a frame its plugin names
tool frame    the hand (or the chain's end) holds another frame named as a TCP; a gripper's
              or hand's TCP moves with a finger, lies behind the hand's root or less than
              halfway out to between its tips' far ends (the hand's mount: a flange, an
              SRDF's parent link at the wrist); without a hand, a shape hangs past the arm's
              last joint (a tool bolted on); without tips, a shaped link fixed with the frame
              lies farther out than it
gripper       the two tips end differently (one on its jaw, one on a pad fixed past its jaw);
              a joint driven on its own moves beside the two fingers (a third finger)
chain         the SRDF group's joints include a prismatic one (a lift: torso or arm?); the
              group is named as a leg and the tree finds an arm (or the other way round)
drive         a fixed virtual joint on a robot with wheels (turning, wheel-shaped or on
              fixed joints), casters, a drive plugin, or more than two limbs (legs drafted
              as arms); a floating one on a robot with wheels; drive plugins that disagree,
              one moving the base in the plane (``planar_move``), naming no wheels, leaving
              driven wheels out, or on a robot with legs
facing        (+x by default, no names said) the robot's two arms or legs lie apart along x,
              its four legs stand wider along y than x, or a differential base's wheels all
              turn about x
============  ==========================================================================

The camera row's checks read the device around the sensor: ``whole_cameras``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from robotspec.model.entities import Body
from robotspec.model.geometry import Cylinder
from robotspec.spec.draft.base import fixed_wheels
from robotspec.spec.draft.confidence import (
    CHAIN_SRDF,
    DRIVE_FIXED,
    DRIVE_FLOATING,
    DRIVE_PLUGIN,
    GRIPPER_MIMIC,
    TOOL_AT_END,
    TOOL_ON_HAND,
    TOOL_SRDF,
)
from robotspec.spec.draft.model import DraftChain, DraftManipulator
from robotspec.spec.draft.naming import role_by_name
from robotspec.spec.draft.tips import between_tips
from robotspec.spec.draft.tool_frames import is_named_tcp, own_geometry
from robotspec.spec.draft.tree import words
from robotspec.spec.draft.whole_cameras import SPOT, camera_marks

if TYPE_CHECKING:
    from robotspec.spec.draft.build import Drafter

__all__ = ["keep_marks"]

#: How near (m) two places must be to count as one (a facing's least gap is twice this).
_SPOT = SPOT
_TOOLS = (TOOL_SRDF, TOOL_ON_HAND, TOOL_AT_END)
#: How far out (share of the way from the hand's root to between its tips' far ends) a TCP
#: lies at least: nearer the root it is the hand's mount.
_OUT = 0.5
#: The least |x| of a unit wheel axis turning about x (within 25 degrees).
_LEVEL_AXIS = 0.9


# -------------------------------------------------------------------------- manipulators
def _tcp_doubt(d: Drafter, m: DraftManipulator, rules: tuple[str, ...]) -> str | None:
    """Why a manipulator's stated tool frame or fingers are not the files' whole answer."""
    world = d.world
    if not world.has_body(m.root) or not world.has_body(m.tool_frame):
        return None
    root, tool = world.get_body_by_name(m.root), world.get_body_by_name(m.tool_frame)
    if any(r in _TOOLS for r in rules):
        other = [b.name for b in world.subtree(root) if b is not tool and is_named_tcp(world, b)]
        if other:
            return f"'{other[0]}' is named as a TCP too: which is the tool frame?"
        if TOOL_AT_END in rules:
            # No hand found, but a shape hangs past the arm's last joint: a tool bolted on
            # (a torch, a suction cup, fingers on fixed joints) whose TCP the name may not be.
            last = d.tree.rigid_root(root)  # the link the arm's last joint moves
            shaped = [b.name for b in world.subtree(last) if b is not last and own_geometry(b)]
            if shaped:
                return f"'{shaped[0]}' hangs past the arm's last joint: a tool, whose TCP?"
        if (why := _short_of_tips(d, m, root, tool)) is not None:
            return why
        if (past := _shape_past(d, m, tool)) is not None:
            return f"'{past}' reaches past the tool frame: a tool bolted on, whose TCP?"
    if GRIPPER_MIMIC in rules and m.thumb is not None and m.finger is not None:
        # The mimic tag couples the fingers; where their tips are it does not say. Two alike
        # fingers end alike: one ending on its jaw and the other on a pad fixed past its jaw
        # is a file that models the sides differently (which link is each tip?).
        ends = [
            world.parent_connection(f.tip) for f in (m.thumb, m.finger) if world.has_body(f.tip)
        ]
        if len(ends) == 2 and len({c is not None and c.is_fixed for c in ends}) == 2:
            return (
                f"the finger tips '{m.thumb.tip}' and '{m.finger.tip}' end differently: the tips?"
            )
        # Nor does it say that the two are all the hand's fingers: a joint driven on its own
        # beside them (a third finger, a spread) makes a hand the tag does not describe.
        if (third := _beside_fingers(d, m, root)) is not None:
            return f"'{third}' moves beside the two fingers: a third finger, a hand?"
    return None


def _beside_fingers(d: Drafter, m: DraftManipulator, root: Body) -> str | None:
    """A joint driven on its own below the hand's root, outside both fingers, if any.

    Driven: not a mimic, and, where the file has transmissions or ``ros2_control`` blocks,
    one of the joints they drive (PR2's gripper slider and screw are no finger's).
    """
    world = d.world
    held: set[int] = set()
    for f in (m.thumb, m.finger):
        if f is None or not world.has_body(f.tip):
            return None
        b = world.get_body_by_name(f.tip)  # up to the finger's first link past the root
        while (up := world.parent_connection(b)) is not None and up.parent != root.index:
            b = world.bodies[up.parent]
        if up is None:
            return None  # the tip is not below the hand's root
        held |= {k.index for k in world.subtree(b)}
    act = d.facts.actuation
    for b in world.subtree(root):
        up = world.parent_connection(b)
        if b is root or up is None or not up.is_active or b.index in held:
            continue
        if act.stated and up.name not in act.joints:
            continue  # the control blocks drive it not (a linkage's slider, a screw)
        return up.name
    return None


def _shape_past(d: Drafter, m: DraftManipulator, tool: Body) -> str | None:
    """A shaped link fixed with a tipless hand's tool frame, farther out than the frame lies.

    Farther out: along the way from the last joint's link to the frame. Why: a TCP name or an
    SRDF end effector's parent link at a flange says where the arm ends, not where a rigid
    tool bolted past it (a suction cup, a torch) meets the work.
    """
    world, tree = d.world, d.tree
    if m.thumb is not None or m.fingers:
        return None  # a hand with tips: ``_short_of_tips`` says where its TCP lies
    last = tree.rigid_root(tool)  # the link the last joint moves
    base = tree.position(last)
    way = tree.position(tool) - base
    out = float(np.linalg.norm(way))
    if out < _SPOT:
        return None  # a frame at the joint: no way out to measure along
    way = way / out
    for b in world.subtree(last):
        if b is last or not own_geometry(b) or tree.rigid_root(b) is not last:
            continue
        if float((tree.position(b) - base) @ way) > out + _SPOT:
            return b.name
    return None


def _short_of_tips(d: Drafter, m: DraftManipulator, root: Body, tool: Body) -> str | None:
    """Why a TCP a name or the SRDF states is not where a hand's tool is: between its tips.

    Why: a name or an SRDF end effector's parent link states a frame, not that it is the point
    the fingers close on. A frame on one finger (below a joint of the hand) moves with that
    finger; a frame at the hand's mount (a flange, ROS-Industrial's ``tool0`` beside the
    gripper it carries, an SRDF's parent link at the wrist) is short of the tips: a spec's
    tool frame is out between the tips' far ends (``docs/getting-started.md``).
    """
    world, tree = d.world, d.tree
    fingers = [f for f in (m.thumb, m.finger, *m.fingers.values()) if f is not None]
    tips = [world.get_body_by_name(f.tip) for f in fingers if world.has_body(f.tip)]
    if len(tips) < 2 or not world.is_ancestor(root, tool):
        return None
    b = tool
    while b is not root and (up := world.parent_connection(b)) is not None:
        if not up.is_fixed:
            return f"the tool frame '{tool.name}' moves with '{up.name}': on a finger?"
        b = world.bodies[up.parent]
    centre = np.asarray(between_tips(tree, root, tips), dtype=np.float64)
    span = float(centre @ centre)
    if span < _SPOT**2:
        return None  # tips hinged at the root itself: no way out is known
    at = (np.linalg.inv(tree.poses[root.index]) @ tree.poses[tool.index])[:3, 3]
    share = float(at @ centre) / span
    if share < 0:
        return f"the tool frame '{tool.name}' lies behind the hand, away from its tips"
    if share < _OUT:
        return f"the tool frame '{tool.name}' lies at the hand's mount, short of its tips"
    return None


def _chain_doubt(d: Drafter, c: DraftChain) -> str | None:
    world = d.world
    lifts = [
        j
        for j in sorted(c.joints)
        if world.has_connection(j) and world.get_connection_by_name(j).type.value == "prismatic"
    ]
    if lifts:
        return f"the SRDF group moves '{lifts[0]}', a prismatic joint: a torso's lift or the arm's?"
    # The tree's kind against the group's own word for it: two sources that disagree (a
    # planner's 'left_leg' the tree takes for an arm) state neither.
    named = role_by_name(c.srdf_group or "")
    if named in ("arm", "leg") and named != c.role:
        found = f"{'an' if c.role[:1] in ('a', 'e', 'i', 'o', 'u') else 'a'} {c.role}"
        return f"the SRDF group '{c.srdf_group}' is named as a {named}; the tree finds {found}"
    return None


# -------------------------------------------------------------------------------- drive
def _drive_doubt(d: Drafter, rule: str) -> str | None:
    world, facts, draft = d.world, d.facts, d.draft
    legs = [c for c in draft.chains if c.role == "leg"]
    limbs = [c for c in draft.chains if c.role in ("arm", "leg")]
    if rule == DRIVE_FIXED and len(limbs) > 2:
        return f"the SRDF's virtual joint is fixed, but the tree has {len(limbs)} limbs: legs?"
    if rule == DRIVE_FIXED:
        casters = [c for c in world.connections if words(c.name) & {"caster", "castor"}]
        if d.wheel_shaped or d.wheels or fixed_wheels(world) or casters or facts.actuation.drives:
            return "the SRDF's virtual joint is fixed, but the files model wheels or a drive"
    elif rule == DRIVE_FLOATING:
        if d.wheels or d.wheel_shaped:
            return "the SRDF's virtual joint is floating, but the robot has wheels: their drive?"
    elif rule == DRIVE_PLUGIN:
        drives = facts.actuation.drives
        plugins = [p for p in drives if all(world.has_connection(w) for w in p.wheels)]
        if not plugins:
            return None
        plugin = plugins[0]  # the one the drive was taken from (``driven.stated_drive``)
        if len({p.kind for p in plugins}) > 1:
            return f"the Gazebo drive plugins disagree: {', '.join(p.plugin for p in plugins)}"
        name = plugin.plugin.lower()
        if "planar" in name:
            return f"the Gazebo plugin '{plugin.plugin}' moves the base in the plane: its wheels?"
        if not plugin.wheels:
            return f"the Gazebo plugin '{plugin.plugin}' names no wheels"
        named = set(plugin.wheels)
        driven = [
            c.name
            for c in d.wheels
            if c.name not in named and facts.actuation.velocity_only(c.name)
        ]
        if driven:
            return f"wheel '{driven[0]}' is driven too, but the drive plugin leaves it out"
        if len(legs) >= 2:
            return "wheels at the ends of legs: rolling, or walking?"
    return None


# ------------------------------------------------------------------------------ facing
def _facing_doubt(d: Drafter) -> str | None:
    """Why a facing drafted +x by default (no names said otherwise) is a question.

    A pair of arms (or legs) lies across the way the robot faces. When a pair's first links
    lie apart along x, the robot faces +y or -y, and +x (REP 103's default, kept when no side
    names say otherwise) is a guess the files contradict: which side is left only names say.
    So do four legs whose hips stand farther apart across x than along it (a quadruped's trunk
    is long the way it walks), and a differential base whose wheels all turn about x (it
    rolls along y), each about its own cylinder's axis.
    """
    world, tree, draft = d.world, d.tree, d.draft
    for role in ("arm", "leg"):
        limbs = [c for c in draft.chains if c.role == role]
        if len(limbs) not in (2, 4):
            continue
        spots = []
        for c in limbs:
            moving = [world.get_connection_by_name(j) for j in c.joints if world.has_connection(j)]
            if not moving:
                break
            first = min(moving, key=lambda j: world.depth(world.bodies[j.child]))
            spots.append(tree.position(world.bodies[first.child]))
        if len(spots) != len(limbs):
            continue
        if len(spots) == 2:
            gap = spots[0] - spots[1]
            if abs(float(gap[0])) > max(2 * abs(float(gap[1])), _SPOT * 2):
                return f"its two {role}s lie apart along x: it faces +y or -y, not +x?"
        elif role == "leg":
            # Four legs stand longer along the body than across it (a trunk is long).
            span = np.ptp(np.asarray(spots), axis=0)
            if float(span[1]) > max(1.5 * float(span[0]), _SPOT * 2):
                return "its four legs stand farther apart along y than x: it faces +y or -y?"
    # A differential base rolls across its wheels' axle: an axle along x drives along y. Only
    # where each wheel's cylinder lies about its joint's axis (an axis a file leaves out is x).
    if draft.drive is not None and draft.drive.type == "differential" and d.wheels:
        rolling = all(_rolls_about_axis(world.bodies[c.child], c.axis) for c in d.wheels)
        axes = [tree.axis_in_root(c) for c in d.wheels]
        if rolling and all(abs(float(a[0])) > _LEVEL_AXIS for a in axes):
            return "its wheels turn about x: it drives along y, not x?"
    return None


def _rolls_about_axis(body: Body, axis: tuple[float, float, float]) -> bool:
    """Whether a wheel's own cylinder lies about its joint's ``axis`` (its body's frame)."""
    for shape in (*body.collisions, *body.visuals):
        if isinstance(shape.geometry, Cylinder):
            along = np.asarray(shape.origin)[:3, 2]
            return abs(float(along @ np.asarray(axis, dtype=np.float64))) > _LEVEL_AXIS
    return False


def keep_marks(d: Drafter) -> None:
    """Give back the mark of every item whose rule's files state only part of it."""
    draft = d.draft
    camera_marks(d)
    for m in draft.manipulators:
        if m.stated and (why := _tcp_doubt(d, m, m.stated)) is not None:
            m.decide.append(why)
            m.stated = ()
    for c in draft.chains:
        if c.stated == CHAIN_SRDF and not c.decide and (why := _chain_doubt(d, c)) is not None:
            c.decide.append(why)
            c.stated = None
    if draft.forward_decide is None and draft.forward in (None, (1.0, 0.0, 0.0)):
        if (why := _facing_doubt(d)) is not None:
            draft.forward, draft.forward_decide = (1.0, 0.0, 0.0), why
    dr = draft.drive
    if dr is not None and dr.stated and not dr.decide:
        if (why := _drive_doubt(d, dr.stated)) is not None:
            dr.decide, dr.stated = why, None
