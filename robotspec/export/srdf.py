"""A MoveIt SRDF from a compiled robot: the spec's semantics in the format planners read.

Why: a robot described once in a spec should not need a second, hand-kept SRDF for MoveIt. The
mapping follows what MoveIt's Setup Assistant writes: one group per chain (``<chain>``), one
group per manipulator (its links) with an ``<end_effector>`` on the chain that carries it, group
states from the spec's named states, the drive as the ``<virtual_joint>``, and the robot's
disabled collision pairs and bodies with their reasons.
"""

from __future__ import annotations

from lxml import etree

from robotspec.description.srdf import (
    DisabledCollision,
    DisableDefaultCollisions,
    EnabledCollision,
    EndEffector,
    Group,
    GroupChain,
    GroupState,
    PassiveJoint,
    Srdf,
    VirtualJoint,
)
from robotspec.semantic import AbstractRobot, Finger

__all__ = ["WHOLE_ROBOT_GROUP", "srdf_from_robot", "write_srdf"]

#: The group that robot-level states (not owned by one part) are written against.
WHOLE_ROBOT_GROUP = "whole_robot"

_VIRTUAL_TYPES = {"planar": "planar", "floating": "floating"}


def srdf_from_robot(robot: AbstractRobot) -> Srdf:
    """The SRDF of ``robot``; every name it writes exists in the robot's URDF (plus the drive)."""
    w = robot.world
    groups, end_effectors, manip_groups = _groups(robot)
    states, need_whole = _states(robot, {g.name for g in groups}, manip_groups)
    if need_whole or not groups:
        joints = tuple(c.name for c in robot.controlled_connections)
        groups.append(Group(WHOLE_ROBOT_GROUP, joints=joints))
    virtual: list[VirtualJoint] = []
    drive = robot.drive
    if drive is not None and drive.type.value in _VIRTUAL_TYPES:
        virtual.append(
            VirtualJoint(
                drive.name,
                _VIRTUAL_TYPES[drive.type.value],
                w.bodies[drive.parent].name,
                w.bodies[drive.child].name,
            )
        )
    passive: tuple[PassiveJoint, ...] = ()
    if robot.srdf is not None:
        passive = tuple(
            PassiveJoint(p.name) for p in robot.srdf.passive_joints if w.has_connection(p.name)
        )
    return Srdf(
        robot_name=w.name,
        groups=tuple(groups),
        group_states=tuple(states),
        end_effectors=tuple(end_effectors),
        virtual_joints=tuple(virtual),
        passive_joints=passive,
        disabled_collisions=_disabled_collisions(robot),
        disable_default_collisions=tuple(
            DisableDefaultCollisions(name) for name in sorted(robot.disabled_collision_bodies)
        ),
    )


def _groups(robot: AbstractRobot) -> tuple[list[Group], list[EndEffector], dict[str, str]]:
    """A group per chain (fingers aside) and per manipulator, an end effector per manipulator.

    Returns the groups, the end effectors, and each manipulator's group name.
    """
    groups: list[Group] = []
    end_effectors: list[EndEffector] = []
    chain_groups: dict[str, str] = {}
    for chain in robot.all_chains:
        if isinstance(chain, Finger):
            continue  # fingers are links of their gripper's group
        groups.append(Group(chain.name, chains=(GroupChain(chain.root.name, chain.tip.name),)))
        chain_groups[chain.name] = chain.name
    carried_by = {
        c.manipulator.name: c for c in robot.kinematic_chains if c.manipulator is not None
    }
    taken = {g.name for g in groups}
    manip_groups: dict[str, str] = {}
    for m in robot.manipulators:
        group_name = m.name if m.name not in taken else f"{m.name}_group"
        taken.add(group_name)
        manip_groups[m.name] = group_name
        links = tuple(b.name for b in robot.world.subtree(m.root))
        groups.append(Group(group_name, links=links))
        owner = carried_by.get(m.name)
        parent_link = owner.tip.name if owner is not None else _parent_link(robot, m.root.name)
        end_effectors.append(
            EndEffector(
                name=f"{m.name}_ee" if m.name == group_name else m.name,
                parent_link=parent_link,
                group=group_name,
                parent_group=None if owner is None else chain_groups.get(owner.name),
            )
        )
    return groups, end_effectors, manip_groups


def _states(
    robot: AbstractRobot, group_names: set[str], manip_groups: dict[str, str]
) -> tuple[list[GroupState], bool]:
    """Each joint state against its part's group; whether one needs the whole-robot group."""
    states: list[GroupState] = []
    need_whole = False
    for key, state in robot.joint_states.items():
        # Keys are "part.state" (right_arm.park, torso.low) or a robot-level "state".
        part = key.split(".", 1)[0] if "." in key else ""
        part = manip_groups.get(part, part)
        group = part if part in group_names else WHOLE_ROBOT_GROUP
        need_whole |= group == WHOLE_ROBOT_GROUP
        states.append(
            GroupState(state.name, group, tuple((j, (float(v),)) for j, v in state.joints))
        )
    return states, need_whole


def _disabled_collisions(robot: AbstractRobot) -> tuple[DisabledCollision, ...]:
    """The robot's disabled pairs in body order, each with its SRDF reason (else "User")."""
    reasons: dict[frozenset[str], str] = {}
    if robot.srdf is not None:
        for d in robot.srdf.disabled_collisions:
            reasons.setdefault(frozenset((d.link1, d.link2)), d.reason or "User")
    order = {b.name: i for i, b in enumerate(robot.world.bodies)}
    disabled = []
    for pair in robot.disabled_collision_pairs:
        if len(pair) != 2:
            continue  # a body "against itself" (added by hand): MoveIt has no such pair
        a, b = sorted(pair, key=lambda n: order.get(n, len(order)))
        disabled.append(DisabledCollision(a, b, reasons.get(pair, "User")))
    disabled.sort(key=lambda d: (order.get(d.link1, 0), order.get(d.link2, 0)))
    return tuple(disabled)


def _parent_link(robot: AbstractRobot, body: str) -> str:
    """The link above a manipulator that no chain carries (MoveIt needs a parent link)."""
    conn = robot.world.parent_connection(body)
    return body if conn is None else robot.world.bodies[conn.parent].name


def write_srdf(srdf: Srdf) -> str:
    """The SRDF as MoveIt writes it: one element kind after another, four-space indentation.

    Deterministic (the records' order is kept), always in MoveIt's dialect, and read back by
    :func:`robotspec.description.srdf_reader.parse_srdf_bytes` into an equal value (except ``file``
    and line numbers).
    """
    root = etree.Element("robot", name=srdf.robot_name)
    for g in srdf.groups:
        el = etree.SubElement(root, "group", name=g.name)
        for link in g.links:
            etree.SubElement(el, "link", name=link)
        for joint in g.joints:
            etree.SubElement(el, "joint", name=joint)
        for c in g.chains:
            etree.SubElement(el, "chain", base_link=c.base_link, tip_link=c.tip_link)
        for sub in g.subgroups:
            etree.SubElement(el, "group", name=sub)
    for s in srdf.group_states:
        el = etree.SubElement(root, "group_state", name=s.name)
        if s.group is not None:
            el.set("group", s.group)
        for joint, values in s.joint_values:
            etree.SubElement(el, "joint", name=joint, value=" ".join(repr(v) for v in values))
    for e in srdf.end_effectors:
        el = etree.SubElement(
            root, "end_effector", name=e.name, parent_link=e.parent_link, group=e.group
        )
        if e.parent_group is not None:
            el.set("parent_group", e.parent_group)
    for v in srdf.virtual_joints:
        etree.SubElement(
            root,
            "virtual_joint",
            name=v.name,
            type=v.type,
            parent_frame=v.parent_frame,
            child_link=v.child_link,
        )
    for p in srdf.passive_joints:
        etree.SubElement(root, "passive_joint", name=p.name)
    for d in srdf.disable_default_collisions:
        etree.SubElement(root, "disable_default_collisions", link=d.link)
    tagged: list[tuple[EnabledCollision | DisabledCollision, str]] = [
        *((e, "enable_collisions") for e in srdf.enabled_collisions),
        *((d, "disable_collisions") for d in srdf.disabled_collisions),
    ]
    for pair, tag in tagged:
        el = etree.SubElement(root, tag, link1=pair.link1, link2=pair.link2)
        if pair.reason is not None:
            el.set("reason", pair.reason)
    etree.indent(root, space="    ")
    body = etree.tostring(root, encoding="unicode")
    return f'<?xml version="1.0"?>\n{body}\n'
