"""``draft_spec``: the detectors' findings joined into one draft, SRDF first, the tree always.

Order of trust: what the SRDF states (groups, end effectors, virtual joint, group states) is taken
as written, in its own names; the tree fills in what the SRDF does not say (the hands' structure,
tool frames, cameras, neck, torso, drive) and is the only source without an SRDF. Anything the
tree suggests is a guess and carries a ``DECIDE`` reason.
"""

from __future__ import annotations

from robotspec.description.srdf import Srdf
from robotspec.model.entities import Body
from robotspec.model.world import World
from robotspec.spec.draft.base import own_base, own_drive, wheel_joints
from robotspec.spec.draft.confidence import CHAIN_SRDF, chain_question
from robotspec.spec.draft.driven import stated_wheels
from robotspec.spec.draft.facts import FileFacts
from robotspec.spec.draft.hands import find_fingers, find_gripper
from robotspec.spec.draft.limbs import Limb, find_limbs, group_end
from robotspec.spec.draft.lone_hand import lone_hand
from robotspec.spec.draft.manipulators import manipulator
from robotspec.spec.draft.model import Draft, DraftChain, DraftDrive, DraftManipulator
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
from robotspec.spec.draft.parts import add_sensors, add_states
from robotspec.spec.draft.srdf_groups import (
    GroupJoints,
    end_effector_root,
    group_chains,
    group_notes,
)
from robotspec.spec.draft.torso_drive import add_drive, add_torso
from robotspec.spec.draft.tree import Tree, words
from robotspec.spec.draft.unassigned import find_questions
from robotspec.spec.draft.whole import keep_marks

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
            # A parent frame that is a link of the URDF cannot be declared (the compiler
            # refuses it): the SRDF's joint is a setup assistant's, the tree decides the drive.
            declarable = not world.has_body(vj.parent_frame)
            if kind is not None and declarable and (kind == "fixed" or root is world.root):
                drive = DraftDrive(
                    kind, vj.name, vj.parent_frame, f"the SRDF's virtual joint '{vj.name}'"
                )
        self.tree = Tree(world, root)
        self.facts = self.tree.memo["facts"] = facts or FileFacts()  # read before any guess
        # Found once, on the tree's poses (one forward kinematics for the whole draft).
        self.wheel_shaped = wheel_joints(world, self.tree.poses)
        self.wheels = stated_wheels(self.tree, self.facts, self.wheel_shaped)
        if own is not None:
            drive = own_drive(world, own, self.wheels)
        self.limbs = find_limbs(self.tree, frozenset(c.name for c in self.wheels))
        # Wheels at legs' ends, known by the leg they end (a wheel-legged robot's): the drive's.
        known = {c.name for c in self.wheels}
        self.wheels += [lb.wheel for lb in self.limbs if lb.wheel and lb.wheel.name not in known]
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
        used: set[int] = set()
        out = self._group_chains(used) if self.srdf is not None else []
        rest = [lb for i, lb in enumerate(self.limbs) if i not in used]
        return out + self._tree_chains(rest)

    def _group_chains(self, used: set[int]) -> list[tuple[DraftChain, Limb | None]]:
        """The SRDF's groups that are chains; ``used`` gets the limbs they were matched to."""
        assert self.srdf is not None
        limbs = self.limbs
        out: list[tuple[DraftChain, Limb | None]] = []
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
            agrees = limb is not None and limb.joints == gc.joints
            if not agrees:
                # The tree does not confirm the group as an arm or a leg of these joints.
                c.decide.append(
                    "the SRDF groups these joints; the tree finds "
                    + ("no arm or leg there" if limb is None else f"a {limb.kind} of others")
                )
            elif q := chain_question(self.srdf, gc.group.name, gc.tip.name, agrees):
                c.decide.append(q)  # confirmed, but nothing in the SRDF hangs on it
            else:
                c.stated = CHAIN_SRDF
            out.append((c, limb))
        return out

    def _tree_chains(self, rest: list[Limb]) -> list[tuple[DraftChain, Limb | None]]:
        """The arms and legs the tree finds that no SRDF group took, named by side."""
        out: list[tuple[DraftChain, Limb | None]] = []
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
        """The hand at a chain's end (``manipulators.manipulator``)."""
        return manipulator(self, chain, limb, name, start, stated)

    def lone_hand(self) -> DraftManipulator | None:
        """A hand or a gripper alone (``lone_hand.lone_hand``)."""
        return lone_hand(self)

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
                if (world.is_ancestor(c.tip, start) or _frame_beside(world, c.tip, start))
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
            if _frame_beside(world, chain.tip, start):
                # The group ends at a frame beside the hand (TurtleBot3's 'end_effector_link'
                # on link5, beside the fingers): the chain ends where both hang, the frame is
                # the hand's tool frame.
                tip = world.get_body_by_name(chain.tip)
                up = world.parent_connection(tip)
                assert up is not None  # a frame beside the hand hangs on a fixed joint
                chain.tip, chain.group = world.bodies[up.parent].name, None
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


def _frame_beside(world: World, tip_name: str, start: Body) -> bool:
    """Whether the chain's tip is a frame fixed on a link above ``start`` (not on it).

    A frame: a leaf on a fixed joint with no collision shape (a marker's look at most).
    """
    tip = world.get_body_by_name(tip_name)
    up = world.parent_connection(tip)
    if up is None or not up.is_fixed or world.child_bodies(tip) or tip.collisions:
        return False
    if world.is_ancestor(tip, start):
        return False
    return world.is_ancestor(world.bodies[up.parent], start)


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
    keep_marks(d)  # a rule's files state only part of an item: its mark stays
    d.draft.questions = find_questions(d)  # after every part: what none of them covers
    return d.draft
