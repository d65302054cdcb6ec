"""What an SRDF says about chains, end effectors and named states, in the tree's terms.

MoveIt groups come in four forms (a ``<chain>``, a list of ``<joint>``, a list of ``<link>``, and
``<group>`` references, freely mixed). Whatever the form, a group is a chain when its moving joints
lie on one path from a root down to a tip and that path moves no other joint; ``GroupJoints``
reduces every form to its joints, and ``serial_chain`` decides.

Why one pass over all groups: SRDFs are downloaded files, and a subgroup chain may be thousands of
groups deep, or a file may hold a hundred thousand groups. Each group's joints are computed once,
children before parents, with an explicit stack (no recursion) and one name index, so drafting
costs time linear in the file. A member the URDF cannot place (a chain running up the tree, a
name the URDF lacks, an undefined subgroup) is reported against its group rather than dropped
silently; the draft shows these as notes.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass, field

from robotspec.description.srdf import EndEffector, Group, Srdf
from robotspec.model.entities import Body
from robotspec.model.world import World

__all__ = [
    "rigidly_beside",
    "GroupChain",
    "GroupJoints",
    "end_effector_root",
    "group_chains",
    "group_notes",
    "joint_set",
]


@dataclass(frozen=True)
class GroupChain:
    """An SRDF group that is a serial chain."""

    group: Group
    root: Body
    tip: Body
    joints: frozenset[str]  # actuated joints
    single_chain: bool  # the group is exactly one <chain> (the spec may then name the group)


def _own_joints(world: World, g: Group, virtual: frozenset[str], problems: list[str]) -> set[str]:
    """The joints ``g`` names itself (not through subgroups); what cannot be placed is listed.

    A virtual joint is MoveIt's, not the URDF's (HSRB's ``world_joint``): not a problem.
    """
    out: set[str] = set()
    for j in g.joints:
        if world.has_connection(j):
            out.add(j)
        elif j not in virtual:
            problems.append(f"no joint {j!r} in the URDF")
    for link in g.links:
        if not world.has_body(link):
            problems.append(f"no link {link!r} in the URDF")
            continue
        c = world.parent_connection(link)
        if c is not None:
            out.add(c.name)
    for ch in g.chains:
        base_link, tip_link = ch.base_link, ch.tip_link
        chain = f"its chain {base_link!r} -> {tip_link!r}"
        lacking = [n for n in (base_link, tip_link) if not world.has_body(n)]
        if lacking:
            problems.append(f"{chain} names {lacking[0]!r}, not a link of the URDF")
            continue
        base, tip = world.get_body_by_name(base_link), world.get_body_by_name(tip_link)
        if world.is_ancestor(base, tip):
            out.update(c.name for c in world.compute_chain_of_connections(base, tip))
        elif world.is_ancestor(tip, base):
            problems.append(f"{chain} runs up the tree (base_link must be above tip_link)")
        else:
            problems.append(f"{chain} spans two branches ({base_link!r} is not above {tip_link!r})")
    return out


@dataclass
class GroupJoints:
    """Every group's joints (subgroups included) and the members the URDF cannot place.

    Built once per SRDF with :meth:`of`; ``joints`` maps each defined group to its joints and
    ``problems`` each group with a broken member to the reasons, in file order.
    """

    joints: dict[str, frozenset[str]]
    problems: dict[str, list[str]] = field(default_factory=dict)
    by_name: dict[str, Group] = field(default_factory=dict)

    @classmethod
    def of(cls, world: World, srdf: Srdf) -> GroupJoints:
        """Walk every group once, subgroups first, with an explicit stack (cycles cut)."""
        by_name: dict[str, Group] = {}
        for g in srdf.groups:
            by_name.setdefault(g.name, g)  # MoveIt keeps the first of two groups of one name
        virtual = frozenset(v.name for v in srdf.virtual_joints)
        own: dict[str, set[str]] = {}
        problems: dict[str, list[str]] = {}
        for name, g in by_name.items():
            found: list[str] = []
            own[name] = _own_joints(world, g, virtual, found)
            undefined = [s for s in g.subgroups if s not in by_name]
            found += [f"its subgroup {s!r} is not defined" for s in undefined]
            if found:
                problems[name] = found
        done: dict[str, frozenset[str]] = {}
        on_path: set[str] = set()
        for start in by_name:
            if start in done:
                continue
            # Post-order: a group is finished when every subgroup is; a subgroup still on the
            # path is a cycle (refused by the reader, cut here all the same).
            path = [start]
            on_path.add(start)
            stack: list[Iterator[str]] = [iter(by_name[start].subgroups)]
            while stack:
                sub = next(stack[-1], None)
                if sub is None:
                    stack.pop()
                    name = path.pop()
                    on_path.discard(name)
                    joints = own[name]
                    for s in by_name[name].subgroups:
                        joints |= done.get(s, frozenset())
                    done[name] = frozenset(joints)
                    continue
                if sub not in by_name or sub in done or sub in on_path:
                    continue
                path.append(sub)
                on_path.add(sub)
                stack.append(iter(by_name[sub].subgroups))
        return cls(done, problems, by_name)

    def of_group(self, name: str) -> set[str]:
        """The joints of group ``name`` (none if the SRDF does not define it)."""
        return set(self.joints.get(name, frozenset()))


def joint_set(world: World, srdf: Srdf, name: str) -> set[str]:
    """Every joint of group ``name`` that the world has, subgroups included (cycles cut).

    One group at a time costs a walk of the whole SRDF; callers asking about many groups build
    one :class:`GroupJoints` instead.
    """
    return GroupJoints.of(world, srdf).of_group(name)


def _serial(world: World, g: Group, joints: set[str]) -> GroupChain | None:
    conns = [world.get_connection_by_name(j) for j in joints]
    moving = [c for c in conns if not c.is_fixed]
    if not moving:
        return None
    if len(g.chains) == 1 and not (g.joints or g.links or g.subgroups):
        ch = g.chains[0]
        root, tip = world.get_body_by_name(ch.base_link), world.get_body_by_name(ch.tip_link)
    else:
        deepest = max(conns, key=lambda c: world.depth(world.bodies[c.child]))
        top = min(conns, key=lambda c: world.depth(world.bodies[c.child]))
        tip = world.bodies[deepest.child]
        root = world.bodies[top.parent]
        if not world.is_ancestor(root, tip):
            return None
    on_path = world.compute_chain_of_connections(root, tip)
    path_moving = {c.name for c in on_path if c.is_active}
    # The group moves exactly the path's joints: none of its joints (mimics included) is off
    # the path (a gripper's two fingers are not a chain), and the path moves none outside it.
    if not path_moving or path_moving != {c.name for c in moving if c.is_active}:
        return None
    if not {c.name for c in moving} <= {c.name for c in on_path}:
        return None
    single = len(g.chains) == 1 and not (g.joints or g.links or g.subgroups)
    return GroupChain(g, root, tip, frozenset(path_moving), single)


def group_chains(world: World, srdf: Srdf, groups: GroupJoints | None = None) -> list[GroupChain]:
    """Every group that is a serial chain, in the SRDF's order."""
    groups = GroupJoints.of(world, srdf) if groups is None else groups
    out = []
    seen: set[str] = set()
    for g in srdf.groups:
        if g.name in seen:
            continue
        seen.add(g.name)
        found = _serial(world, g, groups.of_group(g.name))
        if found is not None:
            out.append(found)
    return out


def group_notes(groups: GroupJoints) -> list[str]:
    """One note per group with a member the URDF cannot place, saying what is left of it."""
    notes: list[str] = []
    for name, reasons in groups.problems.items():
        shown = "; ".join(reasons[:3])
        more = len(reasons) - 3
        if more > 0:
            shown += f"; and {more} more"
        left = "ignored" if groups.joints.get(name) else "the group is not drafted"
        notes.append(f"SRDF group {name!r}: {shown} ({left})")
    return notes


def end_effector_root(
    world: World, srdf: Srdf, ee: EndEffector, groups: GroupJoints | None = None
) -> Body | None:
    """Where an end effector starts: the top of its group, if that hangs below its parent link.

    Some SRDFs give the whole limb as the end effector's group (Talos' feet: group ``l_leg``,
    parent link ``left_sole_link``): the top of that group is the robot's base, so the parent
    link is taken instead.
    """
    groups = GroupJoints.of(world, srdf) if groups is None else groups
    parent = world.get_body_by_name(ee.parent_link) if world.has_body(ee.parent_link) else None
    bodies: list[Body] = []
    for j in sorted(groups.of_group(ee.group)):
        bodies.append(world.bodies[world.get_connection_by_name(j).child])
    g = groups.by_name.get(ee.group)
    if g is not None:
        bodies.extend(world.get_body_by_name(n) for n in g.links if world.has_body(n))
    inside = {b.index for b in bodies}
    # A top has no other group body above it (one walk up per body: linear in the group's size).
    tops = [b for b in bodies if not any(a.index in inside for a in world.ancestors(b)[1:])]
    top = min(tops, key=lambda b: world.depth(b)) if tops else None
    if top is not None and (parent is None or world.is_ancestor(parent, top)):
        return top
    if top is not None and parent is not None:
        # Where the group hangs (its tops' common link: two jaws' carrier); the parent link a
        # TCP frame fixed beside it (HIWIN's 'tool0'): the group is the end effector's.
        hang = top
        for b in tops:
            hang = world.common_ancestor(hang, b)
        if rigidly_beside(world, parent, hang):
            return hang
    return parent


def rigidly_beside(world: World, frame: Body, top: Body) -> bool:
    """Whether ``frame`` is a leaf fixed on a link that carries ``top`` through fixed joints.

    Why: an SRDF end effector's parent link is often the arm's TCP frame, hung on the last
    link beside the flange the gripper is bolted to (HIWIN's 'tool0' on 'link_6', the gripper
    on 'flange'): the frame and the gripper move as one, so the gripper is the end effector's
    and the frame its tool frame, whatever either is named.
    """
    up = world.parent_connection(frame)
    if up is None or not up.is_fixed or world.child_bodies(frame) or world.is_ancestor(frame, top):
        return False
    carrier = world.bodies[up.parent]
    if not world.is_ancestor(carrier, top):
        return False
    return all(c.is_fixed for c in world.compute_chain_of_connections(carrier, top))


def state_values(srdf: Srdf) -> list[tuple[str, str | None, dict[str, float]]]:
    """Group states as (name, group, single-valued finite joint positions)."""
    out = []
    for gs in srdf.group_states:
        values = {j: float(v[0]) for j, v in gs.joint_values if len(v) == 1 and math.isfinite(v[0])}
        out.append((gs.name, gs.group, values))
    return out
