"""``draft_spec``: the detectors' findings joined into one draft, SRDF first, the tree always.

Order of trust: what the SRDF states (groups, end effectors, virtual joint, group states) is taken
as written, in its own names; the tree fills in what the SRDF does not say (the hands' structure,
tool frames, cameras, neck, torso, drive) and is the only source without an SRDF. Anything the
tree suggests is a guess and carries a ``DECIDE`` reason.
"""

from __future__ import annotations

import numpy as np

from robotspec.description.srdf import Srdf
from robotspec.model.entities import Body
from robotspec.model.world import World
from robotspec.spec.draft.base import own_base, own_drive, wheel_joints
from robotspec.spec.draft.driven import stated_wheels
from robotspec.spec.draft.facts import FileFacts
from robotspec.spec.draft.hands import (
    Gripper,
    facing_quaternion,
    find_fingers,
    find_gripper,
    find_tool_frame,
    hand_center,
    hand_joints,
    is_named_tcp,
)
from robotspec.spec.draft.limbs import (
    FINGER_WORDS,
    HAND_WORDS,
    MAX_HAND_SPAN,
    Limb,
    eyes,
    find_limbs,
    group_end,
    hand_span,
    is_named,
)
from robotspec.spec.draft.model import (
    Draft,
    DraftChain,
    DraftDrive,
    DraftFrame,
    DraftManipulator,
)
from robotspec.spec.draft.naming import (
    facing,
    join,
    leg_code,
    named_side,
    ordered_words,
    role_by_name,
    side_labels,
    side_of,
    unique,
)
from robotspec.spec.draft.parts import add_drive, add_sensors, add_states, add_torso
from robotspec.spec.draft.srdf_groups import (
    GroupJoints,
    end_effector_root,
    group_chains,
    group_notes,
)
from robotspec.spec.draft.tips import FLANGE, between_tips, flange_offset
from robotspec.spec.draft.tool_frames import fixed_jaw, frame_at_tips, is_bare_frame
from robotspec.spec.draft.tree import Tree, words

__all__ = ["Drafter", "draft_spec"]


class _SubsetIndex:
    """Answers "is another of these joint sets a strict part of this one?" without a full scan.

    Why: an SRDF may hold 10^5 groups; comparing each with all others is quadratic (minutes).
    A part of a set holds that set's least joint, so only the sets filed under one of its
    joints are compared, and each distinct set is asked once.
    """

    def __init__(self, sets: list[frozenset[str]]) -> None:
        self._by_least: dict[str, list[frozenset[str]]] = {}
        self._empty = False
        for s in dict.fromkeys(sets):
            if s:
                self._by_least.setdefault(min(s), []).append(s)
            else:
                self._empty = True
        self._answers: dict[frozenset[str], bool] = {}

    def has_strict_subset(self, target: frozenset[str]) -> bool:
        """Whether a set of the index is a strict subset of ``target``."""
        answer = self._answers.get(target)
        if answer is None:
            answer = (self._empty and bool(target)) or any(
                s < target for j in target for s in self._by_least.get(j, ())
            )
            self._answers[target] = answer
        return answer


class Drafter:
    """One drafting run; each method fills one part of ``self.draft``."""

    def __init__(
        self,
        world: World,
        srdf: Srdf | None,
        name: str,
        urdf: str,
        srdf_ref: str | None,
        facts: FileFacts | None = None,
    ) -> None:
        self.world = world
        self.srdf = srdf
        self.groups = GroupJoints(joints={})
        self.names: set[str] = set()
        root = world.root
        drive: DraftDrive | None = None
        vj = None
        if srdf is not None:
            vj = next((v for v in srdf.virtual_joints if world.has_body(v.child_link)), None)
        own = self.own_base = own_base(world)  # kept before the filter: chains() reads it
        if own is not None and vj is not None:
            above = world.get_body_by_name(vj.child_link)
            if above is not own.root and above not in world.ancestors(own.root):
                own = None  # the SRDF's virtual joint moves a link below the URDF's base joints
        if own is not None:
            # The URDF moves its base itself (LoCoBot, a simulator's planar joint): those joints
            # are the drive, not an arm's or a neck's, and the robot starts below them.
            root = own.root
        elif vj is not None:
            root = world.get_body_by_name(vj.child_link)
            kind = {"planar": "omni", "floating": "floating", "fixed": "fixed"}.get(vj.type)
            if kind is not None and (kind == "fixed" or root is world.root):
                drive = DraftDrive(
                    kind, vj.name, vj.parent_frame, f"the SRDF's virtual joint '{vj.name}'"
                )
        self.tree = Tree(world, root)
        self.facts = self.tree.memo["facts"] = facts or FileFacts()  # read before any guess
        # Found once, on the tree's poses (one forward kinematics for the whole draft).
        self.wheels = stated_wheels(self.tree, self.facts, wheel_joints(world, self.tree.poses))
        if own is not None:
            drive = own_drive(world, own, self.wheels)
        self.limbs = find_limbs(self.tree)
        self.forward, forward_why = facing(self.tree, self.limbs)
        self.draft = Draft(
            name=name,
            urdf=urdf,
            srdf=srdf_ref,
            root=root.name,
            drive=drive,
            chains=[],
            manipulators=[],
            cameras=[],
        )
        if forward_why is not None:
            self.draft.forward, self.draft.forward_decide = self.forward, forward_why

    # ------------------------------------------------------------------------------ chains
    def chains(self) -> list[tuple[DraftChain, Limb | None]]:
        """SRDF groups that are chains (matched to the tree's limbs), then the other limbs."""
        limbs = self.limbs
        out: list[tuple[DraftChain, Limb | None]] = []
        used: set[int] = set()
        if self.srdf is not None:
            self.groups = GroupJoints.of(self.world, self.srdf)
            self.draft.notes.extend(group_notes(self.groups))
            found = group_chains(self.world, self.srdf, self.groups)
            joins = _SubsetIndex([lb.joints for lb in limbs] + [gc.joints for gc in found])
            accepted: set[frozenset[str]] = set()
            hands = [lb.hand for lb in limbs if lb.hand is not None]
            base = self.own_base
            base_joints = {c.name for c in self.wheels}
            if base is not None:
                base_joints |= set(base.joints or ()) | ({base.planar} if base.planar else set())
            for gc in found:
                # A group is evidence of what a planner moves together, not of what the part
                # is: one joint is a gripper's or a tool's, the base's joints are the drive.
                if len(gc.joints) == 1:
                    self.draft.notes.append(
                        f"SRDF group {gc.group.name!r} moves one joint: not drafted as a chain"
                    )
                    continue
                if gc.joints <= base_joints:
                    self.draft.notes.append(
                        f"SRDF group {gc.group.name!r} moves the base: the drive, not a chain"
                    )
                    continue
                if gc.joints in accepted or joins.has_strict_subset(gc.joints):
                    self.draft.notes.append(
                        f"SRDF group {gc.group.name!r} joins or repeats other chains; not drafted"
                    )
                    continue
                if any(self.world.is_ancestor(h, gc.root) for h in hands):
                    continue  # a hand's own joints (Panda's 'hand'): its manipulator has them
                accepted.add(gc.joints)
                limb_i = next(
                    (i for i, lb in enumerate(limbs) if lb.joints & gc.joints and i not in used),
                    None,
                )
                limb = limbs[limb_i] if limb_i is not None else None
                if limb_i is not None:
                    used.add(limb_i)
                end = group_end(self.world, gc.tip, limb, gc.joints)
                c = DraftChain(
                    unique(gc.group.name, self.names),
                    gc.root.name,
                    end,
                    f"the SRDF group '{gc.group.name}'",
                    role=limb.kind if limb is not None else role_by_name(gc.group.name),
                    # A group's <chain> ends at its tip: past it, root and tip are written.
                    group=gc.group.name if gc.single_chain and end == gc.tip.name else None,
                    srdf_group=gc.group.name,
                    joints=gc.joints,
                )
                if limb is None or limb.joints != gc.joints:
                    # The tree does not confirm the group as an arm or a leg of these joints.
                    c.decide.append(
                        "the SRDF groups these joints; the tree finds "
                        + ("no arm or leg there" if limb is None else f"a {limb.kind} of others")
                    )
                out.append((c, limb))
        rest = [lb for i, lb in enumerate(limbs) if i not in used]
        for kind in ("arm", "leg"):
            group = [lb for lb in rest if lb.kind == kind]
            if not group:
                continue
            labels, by_name = side_labels(self.tree, group, self.forward)
            for lb, label in zip(group, labels, strict=True):
                if not label and any(leg_code(lb)):
                    # One leg left over by the SRDF's groups (HyQ's): its code, as theirs.
                    label = ordered_words(lb.segment.bodies[0].name)[0]
                    label = label if kind == "leg" else ""
                c = DraftChain(
                    unique(join(label, kind), self.names),
                    lb.root.name,
                    lb.tip.name,
                    "the URDF tree",
                    role=kind,
                    joints=lb.joints,
                )
                c.decide.append(f"{'an arm' if kind == 'arm' else 'a leg'}: {lb.why}")
                named = named_side(lb)
                if by_name and kind == "arm" and label in ("left", "right"):
                    c.side = label
                    c.decide.append("the default pose does not tell the sides; its links do")
                elif label in ("left", "right") and named not in (None, label):
                    c.decide.append(f"{label} by position, but its links say {named}")
                out.append((c, lb))
        return out

    # ----------------------------------------------------------------------- manipulators
    def manipulator(
        self,
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
        gripper, why = find_gripper(tree, hand) if hand is not None else (None, "no hand")
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
        mount = top
        while (tool is None or carrying) and gripper is not None and mount is not tip:
            up = world.parent_connection(mount)
            if up is None or not up.is_fixed:
                break
            mount = world.bodies[up.parent]
            beside = find_tool_frame(tree, mount, others, prefer, leaf=carrying)
            if beside is not None and (
                world.child_bodies(beside) or world.is_ancestor(beside, top)
            ):
                beside = None  # the mount itself, a flange above the gripper: not beside it
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
        if stated is not None and world.is_ancestor(top, stated) and is_bare_frame(world, stated):
            tool, decide = stated, []  # the SRDF end effector's parent link: a fact
        frame: DraftFrame | None = None
        if tool is not None:
            tool_name = tool.name
            # A bare frame named as a TCP, or the SRDF's, is the files' answer (no question);
            # other names and links are guesses. (Above the hand: said already.)
            if not decide and not is_named_tcp(world, tool) and tool is not stated:
                jaw = tool is fixed_jaw(world, top)  # a one-jaw gripper's: by where it is
                decide.append(
                    f"the tool frame '{tool.name}' "
                    + ("at the fixed jaw's end" if jaw else "by its name")
                )
        elif gripper is not None:
            tool_name = unique(f"{name}_tool_frame", self.names | set(world.body_names))
            mid = (tree.poses[gripper.thumb_tip.index] + tree.poses[gripper.finger_tip.index])[
                :3, 3
            ] / 2
            local = np.linalg.inv(tree.poses[gripper.root.index]) @ np.append(mid, 1.0)
            if float(np.linalg.norm(local[:3])) < ON_ROOT:
                # The gripper's own link sits between its finger tips (Fetch's 'gripper_link'):
                # it is the tool frame the URDF has, not a new one at the same place.
                tool_name = gripper.root.name
                decide.append(f"the tool frame '{tool_name}': between the finger tips")
            elif at := frame_at_tips(tree, gripper.root, (gripper.thumb_tip, gripper.finger_tip)):
                tool_name = at.name  # a bare frame the URDF puts between the tips
                decide.append(f"the tool frame '{tool_name}': a frame between the finger tips")
            else:
                frame = DraftFrame(
                    tool_name,
                    gripper.root.name,
                    between_tips(tree, gripper.root, (gripper.thumb_tip, gripper.finger_tip)),
                    "the URDF has no tool frame: between the finger tips in the default pose",
                )
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
        elif not tree.moves_below(top) and (flange := flange_offset(tree, top)) is not None:
            flange_name = "flange" if name == "tool" else f"{name}_flange"
            tool_name = unique(flange_name, self.names | set(world.body_names))
            frame = DraftFrame(tool_name, top.name, flange, f"the URDF has no tool frame: {FLANGE}")
        elif hand is None and (up := world.parent_connection(top)) is not None and up.is_fixed:
            tool_name = top.name  # the flange link the chain ends at, past its last joint
            decide.append(f"the tool frame '{tool_name}': the link past the arm's last joint")
        else:
            tool_name = top.name
            decide.append("no tool frame link found; add one under description.frames")
        if any(m.tool_frame == tool_name for m in self.draft.manipulators):
            self.draft.notes.append(
                f"chain {chain.name!r}: its tool frame {tool_name!r} has a manipulator already"
            )
            return None
        if frame is not None:
            self.draft.frames.append(frame)
        m = DraftManipulator(unique(name, self.names), top.name, tool_name, "", decide)
        if gripper is not None:
            m.thumb, m.finger = gripper.thumb, gripper.finger
            m.source = f"{gripper.found} below '{gripper.root.name}'"
            if gripper.decide:
                decide.append(gripper.decide)
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
        m.joints = hand_joints(tree, top)
        self._facing(m, gripper, tip, frame)
        self.draft.manipulators.append(m)
        chain.manipulator = m.name
        return m

    def _facing(
        self, m: DraftManipulator, gripper: Gripper | None, tip: Body, frame: DraftFrame | None
    ) -> None:
        """Grasp along the hand's reach: root to finger tips, or chain tip to tool frame."""
        tree, world = self.tree, self.world
        tool = world.get_body_by_name(frame.parent if frame is not None else m.tool_frame)
        rot = tree.poses[tool.index][:3, :3]
        if gripper is not None:
            ref = tree.poses[gripper.root.index][:3, 3]
            target = (
                tree.poses[gripper.thumb_tip.index][:3, 3]
                + tree.poses[gripper.finger_tip.index][:3, 3]
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
            m.decide.append("front_facing_orientation: grasping along the hand's reach")

    def lone_hand(self) -> DraftManipulator | None:
        """A hand or a gripper alone (no arm): one manipulator rooted at the robot's root.

        Why not nothing: a hand's URDF (Allegro's, a WSG-50's) is a part that specs compose onto
        an arm; its spec is its manipulator, fingers and tool frame. It is a hand when its
        fingers make a parallel gripper, or when two or more short moving branches leave its
        root, or when its links are named as a hand's.
        """
        tree, world = self.tree, self.world
        root = tree.root
        # Where the fingers split: down the single moving branch from the root, through a mount
        # (fixed joints) and a wrist (at most MAX_WRIST joints, drafted as a chain of its own).
        split, wrist = root, []
        while len(kids := tree.moving_children(split)) == 1:
            c = world.parent_connection(kids[0])
            if c is not None and c.is_active:
                wrist.append(c.name)
            split = kids[0]
        if len(wrist) > MAX_WRIST:
            split, wrist = root, []
        if eyes(tree, split):
            return None  # a head's eyes, each carrying a camera: no hand
        gripper, _ = find_gripper(tree, split)
        # Wheels (continuous joints about a level axis turning a wheel's shape) are never fingers.
        wheels = {c.child for c in self.wheels}

        def rolls(body: Body) -> bool:
            return any(a.index in wheels for a in (*world.ancestors(body), body))

        if gripper is not None and (rolls(gripper.thumb_tip) or rolls(gripper.finger_tip)):
            gripper = None
        # Fingers have phalanges: a branch of one joint (a rotor, a wheel) is not one.
        branches = [
            k
            for k in tree.moving_children(split)
            if sum(1 for b in world.subtree(k) if not _fixed_above(world, b)) >= 2
            and not any(b.index in wheels for b in world.subtree(k))
        ]
        named = any(is_named(b.name, HAND_WORDS | FINGER_WORDS) for b in world.subtree(split))
        small = hand_span(tree, split) <= MAX_HAND_SPAN
        if gripper is None and not (len(branches) >= 2 and (small or named)):
            return None
        if wrist:
            holder = DraftChain(
                unique("wrist", self.names),
                root.name,
                split.name,
                "the URDF tree",
                joints=frozenset(wrist),
                decide=[f"a wrist: {len(wrist)} joint(s) from the root to where the fingers split"],
            )
            self.draft.chains.append(holder)
        else:
            holder = DraftChain("hand", root.name, root.name, "the URDF tree")
        m = self.manipulator(holder, None, "gripper" if gripper else "hand", start=split)
        if m is not None and not wrist:
            m.decide.insert(0, "a hand alone (no arm): rooted at the robot's root")
            self.draft.lone_hand = m.name
        return m

    def end_effectors(self, chains: list[tuple[DraftChain, Limb | None]]) -> None:
        """SRDF end effectors become the manipulators of the chains they hang from."""
        assert self.srdf is not None
        world = self.world
        for ee in self.srdf.end_effectors:
            # An end effector whose group is an arm's own (Alex's 'left_arm_end_effector', group
            # 'left_arm') is that arm's hand, not something hanging below the arm's root.
            arm = next(((c, lb) for c, lb in chains if c.srdf_group == ee.group), None)
            start: Body | None
            if arm is not None:
                arm_hand = arm[1].hand if arm[1] is not None else None
                start = arm_hand or world.get_body_by_name(arm[0].tip)
            else:
                start = end_effector_root(world, self.srdf, ee, self.groups)
            if start is None:
                self.draft.notes.append(f"end effector {ee.name!r}: its links are not in the URDF")
                continue
            owners = [
                (c, lb)
                for c, lb in chains
                if world.is_ancestor(c.tip, start)
                and (ee.parent_group is None or c.group in (None, ee.parent_group))
            ]
            named = [
                o for o in owners if ee.parent_group is not None and o[0].name == ee.parent_group
            ]
            pick = [arm] if arm is not None else named
            pick = pick or sorted(owners, key=lambda o: -world.depth(o[0].tip))
            if not pick:
                self.draft.notes.append(f"end effector {ee.name!r} is on no drafted chain")
                continue
            chain, limb = pick[0]
            if chain.manipulator is not None:
                self.draft.notes.append(
                    f"end effector {ee.name!r}: chain {chain.name!r} has one already"
                )
                continue
            hand_start = start
            if (
                limb is not None
                and limb.hand is not None
                and (world.is_ancestor(start, limb.hand) or world.is_ancestor(limb.hand, start))
            ):
                hand_start = limb.hand  # the EE names a link of the hand; the tree knows its root
            name = ee.name
            if name in self.names:  # Talos' feet are named as their legs
                name = f"{ee.name}_{'foot' if chain.role == 'leg' else 'hand'}"
            parent = (
                world.get_body_by_name(ee.parent_link) if world.has_body(ee.parent_link) else None
            )
            m = self.manipulator(chain, limb, name, hand_start, parent)
            if m is not None:
                m.source = f"the SRDF end effector '{ee.name}' ({m.source})"


#: A point between the finger tips this close to the gripper's link (m) is that link.
ON_ROOT = 0.01
#: Most joints between a lone hand's root and where its fingers split (a wrist, not an arm).
MAX_WRIST = 3


def _bare_frames(world: World, body: Body) -> list[Body]:
    """The frames fixed on ``body``: children on fixed joints, without geometry or children."""
    out = []
    for k in world.child_bodies(body):
        c = world.parent_connection(k)
        if c is not None and c.is_fixed and not world.child_bodies(k):
            if not (k.collisions or k.visuals):
                out.append(k)
    return out


def _fixed_above(world: World, body: Body) -> bool:
    c = world.parent_connection(body)
    return c is None or c.is_fixed


def draft_spec(
    world: World,
    *,
    urdf_ref: str,
    srdf: Srdf | None,
    srdf_ref: str | None,
    name: str,
    facts: FileFacts | None = None,
) -> Draft:
    """Decide what the files say and what a person must; see the module docstring.

    ``facts``: what the URDF states beyond its tree (Gazebo sensors, transmissions).
    """
    d = Drafter(world, srdf, name, urdf_ref, srdf_ref, facts)
    chains = d.chains()
    d.draft.chains = [c for c, _ in chains]
    if srdf is not None:
        d.end_effectors(chains)
    arms = [(c, lb) for c, lb in chains if c.role in ("arm", "chain") and c.manipulator is None]
    for c, lb in arms:
        if c.role == "chain" and (lb is None or lb.hand is None):
            continue  # an SRDF chain of the tree's unknowns: no hand to offer
        side = side_of(c.name)
        word = "gripper"
        if lb is not None and lb.hand is not None:
            g, _ = find_gripper(d.tree, lb.hand)
            if g is None:
                fingered = find_fingers(d.tree, lb.hand) is not None
                word = "hand" if fingered or "hand" in words(lb.hand.name) else "tool"
        else:
            word = "tool"
        d.manipulator(c, lb, join(side, word) if side else word)
    if not d.draft.chains and not d.draft.manipulators:
        d.lone_hand()
    add_sensors(d)
    add_torso(d)
    add_drive(d)
    add_states(d)
    return d.draft
