"""What hangs at a chain's end: its manipulator (gripper, hand, tool) and tool frame.

Split from ``build`` (which joins the detectors' findings): this module decides, for one chain,
where its hand starts, whether it is a parallel gripper or a hand of fingers, which frame is its
tool frame (the URDF's, the SRDF's, or one proposed between the tips), and which way it faces.
Whether each decision is stated by the files or a question is ``confidence``'s rule.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from robotspec.model.entities import Body
from robotspec.model.world import World
from robotspec.spec.draft.confidence import GRIPPER_MIMIC, TOOL_SRDF, tool_frame_verdict
from robotspec.spec.draft.hands import (
    Gripper,
    facing_quaternion,
    find_fingers,
    find_gripper,
    find_tool_frame,
    hand_center,
    hand_joints,
)
from robotspec.spec.draft.limbs import Limb
from robotspec.spec.draft.model import DraftChain, DraftFrame, DraftManipulator
from robotspec.spec.draft.naming import unique
from robotspec.spec.draft.srdf_groups import rigidly_beside
from robotspec.spec.draft.tips import (
    BIT,
    FLANGE,
    between_tips,
    flange_offset,
    origin_is_flange,
    rigid_end,
)
from robotspec.spec.draft.tool_frames import (
    bare_run_end,
    bit_frame,
    fixed_jaw,
    frame_at_tips,
    is_bare_frame,
    is_named_tcp,
)

if TYPE_CHECKING:
    from robotspec.spec.draft.build import Drafter

__all__ = ["ON_ROOT", "manipulator"]


def manipulator(
    self: Drafter,
    chain: DraftChain,
    limb: Limb | None,
    name: str,
    start: Body | None = None,
    stated: Body | None = None,
) -> DraftManipulator | None:
    """The hand at a chain's end (``start``: where an SRDF end effector says it begins).

    ``stated``: the SRDF end effector's parent link; a bare frame on the hand, it is the
    tool frame the files state (no question asked).
    """
    tree, world = self.tree, self.world
    tip = world.get_body_by_name(chain.tip)
    hand = start if start is not None else (limb.hand if limb is not None else None)
    if hand is not None and not world.is_ancestor(tip, hand):
        hand = None
    decide: list[str] = []
    rules: list[str] = []  # confidence's rules that state what is drafted without a question
    gripper, why = (
        find_gripper(tree, hand, actuation=self.facts.actuation)
        if hand is not None
        else (None, "no hand")
    )
    tool, top, gripper, tip = _tool_and_top(self, chain, limb, tip, hand, gripper, stated, decide)
    tool_name, frame = _tool_name(self, name, tool, top, tip, gripper, hand, stated, decide, rules)
    if any(m.tool_frame == tool_name for m in self.draft.manipulators):
        self.draft.notes.append(
            f"chain {chain.name!r}: its tool frame {tool_name!r} has a manipulator already"
        )
        return None
    if frame is not None:
        self.draft.frames.append(frame)
        decide.append(f"its tool frame '{tool_name}' is proposed (description.frames)")
    m = DraftManipulator(unique(name, self.names), top.name, tool_name, "", decide)
    _fingers(self, m, chain, top, gripper, hand, why, rules)
    m.joints = hand_joints(tree, top)
    m.stated = tuple(rules)
    _facing(self, m, gripper, tip, frame)
    self.draft.manipulators.append(m)
    chain.manipulator = m.name
    return m


def _tool_and_top(
    self: Drafter,
    chain: DraftChain,
    limb: Limb | None,
    tip: Body,
    hand: Body | None,
    gripper: Gripper | None,
    stated: Body | None,
    decide: list[str],
) -> tuple[Body | None, Body, Gripper | None, Body]:
    """The tool frame the URDF or SRDF names (or None) and the manipulator's root.

    Also the gripper (None when the root ended above it) and the chain's tip, which an SRDF
    end effector beside the gripper moves back to where both hang (``chain`` follows).
    """
    tree, world = self.tree, self.world
    top = gripper.root if gripper is not None else (hand or tip)
    others = frozenset(
        b.index
        for lb in self.limbs
        if limb is None or lb.segment is not limb.segment
        if not world.is_ancestor(world.bodies[lb.segment.joints[0].child], tip)
        for b in world.subtree(world.bodies[lb.segment.joints[0].child])
    )
    prefer = None if gripper is None else gripper.root
    tool = find_tool_frame(tree, top, others, prefer)
    # A TCP the URDF hangs beside the gripper, on the mount that carries it (Kinova's
    # 'tool_frame' on 'dummy_link', next to 'gripper_base_link'): the mount is the root.
    # So is a TCP frame beside a gripper whose own link (carrying the fingers) was the only
    # name found (Alicia-M's 'tool0' on the wrist beside 'grasp_base').
    carrying = tool is not None and gripper is not None and tool is gripper.root
    # A hand of fingers too, for a frame named as a TCP only (qb SoftHand's
    # 'qbhand_end_effector_link' on the base the palm is fixed to).
    fingered = gripper is None and hand is not None and find_fingers(tree, hand) is not None
    mount = top
    while (tool is None or carrying) and (gripper is not None or fingered) and mount is not tip:
        up = world.parent_connection(mount)
        if up is None or not up.is_fixed:
            break
        mount = world.bodies[up.parent]
        beside = find_tool_frame(tree, mount, others, prefer, leaf=carrying or fingered)
        if beside is not None and (world.child_bodies(beside) or world.is_ancestor(beside, top)):
            beside = None  # the mount itself, a flange above the gripper: not beside it
        if beside is not None and fingered and not _hand_tcp(world, beside):
            beside = None
        if beside is not None:
            tool, top, carrying = beside, mount, False
    # A tool frame above the hand (a flange, a wrist F/T sensor) only when the hand has no
    # tips to put one between.
    tipless = hand is None or hand_center(tree, top) is None
    if tool is None and top is not tip and gripper is None and tipless:
        tool = find_tool_frame(tree, tip, others, prefer)
        if tool is not None:
            decide.append(f"the only named tool frame is above the hand: root '{tip.name}'")
            top = tip
    if gripper is not None and not world.is_ancestor(top, gripper.root):
        gripper = None
    if (
        stated is not None
        and (world.is_ancestor(top, stated) or rigidly_beside(world, stated, top))
        and is_bare_frame(world, stated)
    ):
        tool = stated  # the SRDF end effector's parent link: a fact
        decide.clear()
        if not world.is_ancestor(top, stated):  # beside the gripper: rooted where both hang
            top = world.bodies[world.parent_connection(stated).parent]  # type: ignore[union-attr]
            if not world.is_ancestor(tip, top):  # the chain ran on into the gripper's mount
                chain.tip, chain.group, tip = top.name, None, top
    return tool, top, gripper, tip


def _tool_name(
    self: Drafter,
    name: str,
    tool: Body | None,
    top: Body,
    tip: Body,
    gripper: Gripper | None,
    hand: Body | None,
    stated: Body | None,
    decide: list[str],
    rules: list[str],
) -> tuple[str, DraftFrame | None]:
    """The tool frame's name, and the frame proposed when the URDF has none."""
    tree, world = self.tree, self.world
    frame: DraftFrame | None = None
    if tool is not None and stated is None and (bit := bit_frame(tree, top, tool)) is not None:
        # A rigid tool's last link centred on its origin (a drill's bit): its tip is out there.
        tool_name = unique(f"{name}_tip", self.names | set(world.body_names))
        frame = DraftFrame(tool_name, tool.name, bit, f"the URDF has no tool frame: {BIT}")
    elif tool is not None:
        tool_name = tool.name
        # Stated or a question: confidence's rule (above the hand: said already).
        at_hand = gripper.root if gripper is not None else hand
        q, rule = tool_frame_verdict(
            world, tool, hand=at_hand, tip=tip, srdf_parent=stated, tree=tree
        )
        if not decide and q is None:
            rules.append(rule or TOOL_SRDF)
        if not decide and q is not None:
            jaw = tool is fixed_jaw(world, top)  # a one-jaw gripper's: by where it is
            decide.append(f"the tool frame '{tool.name}' at the fixed jaw's end" if jaw else q)
    elif gripper is not None:
        tool_name, frame = _gripper_tool(self, name, gripper, decide)
    elif hand is not None and (center := hand_center(tree, top)) is not None:
        tool_name = unique(f"{name}_tool_frame", self.names | set(world.body_names))
        frame = DraftFrame(
            tool_name,
            top.name,
            center,
            "the URDF has no tool frame: between the hand's tips in the default pose",
        )
    elif hand is not None and len(marks := _bare_frames(world, top)) == 1:
        # A fingerless hand with one frame fixed on it (iCub's 'l_hand_dh_frame'): the frame
        # the URDF gives the hand, whatever its name.
        tool_name = marks[0].name
        decide.append(f"the tool frame '{tool_name}': the one frame fixed on the hand")
    elif hand is None and not tree.moves_below(top) and origin_is_flange(tree, top):
        tool_name = top.name  # a frame a few millimetres out would be its origin again
        decide.append(f"the tool frame '{tool_name}': the last link's origin is on its end face")
    elif not tree.moves_below(top) and (flange := flange_offset(tree, top)) is not None:
        flange_name = "flange" if name == "tool" else f"{name}_flange"
        tool_name = unique(flange_name, self.names | set(world.body_names))
        frame = DraftFrame(tool_name, top.name, flange, f"the URDF has no tool frame: {FLANGE}")
    elif (
        hand is None
        and (up := world.parent_connection(top)) is not None
        and up.is_fixed
        and (end := rigid_end(tree, top)) is not None
    ):
        # A rigid link hung out past the last joint (Quori's lower arm on its fixed elbow):
        # no flange link; the tool is met at the far end of its shape.
        tool_name = unique(
            "flange" if name == "tool" else f"{name}_flange", self.names | set(world.body_names)
        )
        frame = DraftFrame(
            tool_name, top.name, end, "the URDF has no tool frame: the far end of the last link"
        )
    elif hand is None and (up := world.parent_connection(top)) is not None and up.is_fixed:
        tool_name = bare_run_end(world, top).name  # the flange, or its frames' end (tool0)
        decide.append(f"the tool frame '{tool_name}': the link past the arm's last joint")
    elif hand is None and not tree.moves_below(top) and _shape_unknown(top):
        # A bare arm's last link whose shape is not loaded (its meshes missing): where the
        # flange is cannot be measured, so the frame starts at the link's origin, asked.
        tool_name = unique(
            "flange" if name == "tool" else f"{name}_flange", self.names | set(world.body_names)
        )
        frame = DraftFrame(
            tool_name,
            top.name,
            (0.0, 0.0, 0.0),
            "the last link's shape is not loaded: "
            "at its origin; move it out to where the tool is bolted",
        )
    else:
        tool_name = top.name
        decide.append("no tool frame link found; add one under description.frames")
    return tool_name, frame


def _gripper_tool(
    self: Drafter, name: str, gripper: Gripper, decide: list[str]
) -> tuple[str, DraftFrame | None]:
    """A parallel gripper's tool frame where the URDF names none: between its finger tips."""
    tree, world = self.tree, self.world
    frame: DraftFrame | None = None
    tool_name = unique(f"{name}_tool_frame", self.names | set(world.body_names))
    mid = (tree.poses[gripper.thumb_tip.index] + tree.poses[gripper.finger_tip.index])[:3, 3] / 2
    local = np.linalg.inv(tree.poses[gripper.root.index]) @ np.append(mid, 1.0)
    apart = tree.poses[gripper.thumb_tip.index][:3, 3] - tree.poses[gripper.finger_tip.index][:3, 3]
    if float(np.linalg.norm(local[:3])) < ON_ROOT and float(np.linalg.norm(apart)) >= ON_ROOT:
        # The gripper's own link sits between its finger tips (Fetch's 'gripper_link'):
        # it is the tool frame the URDF has, not a new one at the same place. Not when the
        # fingers are hinged at its origin too (myCobot's jaws): the URDF says nothing there.
        tool_name = gripper.root.name
        decide.append(f"the tool frame '{tool_name}': between the finger tips")
    elif at := frame_at_tips(tree, gripper.root, (gripper.thumb_tip, gripper.finger_tip)):
        tool_name = at.name  # a bare frame the URDF puts between the tips
        decide.append(f"the tool frame '{tool_name}': a frame between the finger tips")
    else:
        xyz = between_tips(tree, gripper.root, (gripper.thumb_tip, gripper.finger_tip))
        why = "between the finger tips in the default pose"
        if xyz == (0.0, 0.0, 0.0):
            why = "the fingers hinge at the gripper's origin: move it out between their tips"
        frame = DraftFrame(tool_name, gripper.root.name, xyz, f"the URDF has no tool frame: {why}")
    return tool_name, frame


def _fingers(
    self: Drafter,
    m: DraftManipulator,
    chain: DraftChain,
    top: Body,
    gripper: Gripper | None,
    hand: Body | None,
    why: str,
    rules: list[str],
) -> None:
    """The gripper's two fingers, a hand's fingers, or a generic tool's question."""
    tree, world = self.tree, self.world
    decide = m.decide
    if gripper is not None:
        m.thumb, m.finger = gripper.thumb, gripper.finger
        m.source = f"{gripper.found} below '{gripper.root.name}'"
        if gripper.decide:
            decide.append(gripper.decide)
        else:
            rules.append(GRIPPER_MIMIC)
    elif (
        hand is not None
        and chain.role != "leg"
        and (found := find_fingers(tree, hand)) is not None
        and world.is_ancestor(top, found.split)
    ):
        m.thumb, m.fingers = found.thumb, found.fingers
        m.source = f"{len(found.fingers) + 1} finger branches below '{found.split.name}'"
        decide.append(
            "a hand: " + (found.decide or "the thumb by its name") + "; fingers by their links"
        )
    else:
        m.source = "the end of the chain" if hand is None else f"the hand at '{hand.name}'"
        if chain.role == "leg":
            decide.append("a foot")
        elif hand is not None:
            decide.append(f"a generic hand: {why}")


def _facing(
    self: Drafter, m: DraftManipulator, gripper: Gripper | None, tip: Body, frame: DraftFrame | None
) -> None:
    """Grasp along the hand's reach: root to finger tips, or chain tip to tool frame."""
    tree, world = self.tree, self.world
    tool = world.get_body_by_name(frame.parent if frame is not None else m.tool_frame)
    rot = tree.poses[tool.index][:3, :3]
    if gripper is not None:
        ref = tree.poses[gripper.root.index][:3, 3]
        target = (
            tree.poses[gripper.thumb_tip.index][:3, 3] + tree.poses[gripper.finger_tip.index][:3, 3]
        ) / 2
    elif frame is not None:  # a proposed frame: from the hand's root out to it
        ref = tree.poses[tool.index][:3, 3]
        target = (tree.poses[tool.index] @ np.append(np.asarray(frame.xyz), 1.0))[:3]
    else:
        ref, target = tree.poses[tip.index][:3, 3], tree.poses[tool.index][:3, 3]
    axis = rot.T @ (target - ref)
    q = facing_quaternion(axis) if float(np.linalg.norm(axis)) > 0.01 else None
    if q is None:
        m.decide.append("which way does the tool face? (x forward here)")
    else:
        m.front_facing = q
        m.facing = "grasping along the hand's reach"  # follows the tool frame: no question


#: A point between the finger tips this close to the gripper's link (m) is that link.
ON_ROOT = 0.01


def _bare_frames(world: World, body: Body) -> list[Body]:
    """The frames fixed on ``body``: children on fixed joints, without geometry or children."""
    out = []
    for k in world.child_bodies(body):
        c = world.parent_connection(k)
        if c is not None and c.is_fixed and not world.child_bodies(k):
            if not (k.collisions or k.visuals):
                out.append(k)
    return out


def _hand_tcp(world: World, frame: Body) -> bool:
    """Whether ``frame``, beside a hand of fingers, is its TCP: named so, and not a flange.

    ROS-Industrial's ``tool0`` is the arm's flange, where a tool is bolted: beside a mounted
    hand (UR's 'tool0' beside Schunk SIH's palm) it is not the hand's TCP; qb SoftHand's
    'qbhand_end_effector_link' on the base its palm is fixed to is.
    """
    return is_named_tcp(world, frame) and not frame.name.lower().endswith("tool0")


def _shape_unknown(body: Body) -> bool:
    """Whether ``body``'s shape is not loaded: none, or only meshes whose files were not found."""
    shapes = (*body.visuals, *body.collisions)
    return all(getattr(s.geometry, "path", "") is None for s in shapes)
