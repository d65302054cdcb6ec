"""What an SRDF says about chains, end effectors and named states, in the tree's terms.

MoveIt groups come in four forms (a ``<chain>``, a list of ``<joint>``, a list of ``<link>``, and
``<group>`` references, freely mixed). Whatever the form, a group is a chain when its moving joints
lie on one path from a root down to a tip and that path moves no other joint; ``joint_set``
reduces every form to its joints, and ``serial_chain`` decides.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from robotspec.description.srdf import EndEffector, Group, Srdf
from robotspec.model.entities import Body
from robotspec.model.world import World

__all__ = ["GroupChain", "end_effector_root", "group_chains", "joint_set"]


@dataclass(frozen=True)
class GroupChain:
    """An SRDF group that is a serial chain."""

    group: Group
    root: Body
    tip: Body
    joints: frozenset[str]  # actuated joints
    single_chain: bool  # the group is exactly one <chain> (the spec may then name the group)


def joint_set(
    world: World,
    srdf: Srdf,
    name: str,
    seen: frozenset[str] = frozenset(),
    memo: dict[str, frozenset[str]] | None = None,
) -> set[str]:
    """Every joint of group ``name`` that the world has, subgroups included (cycles cut).

    ``memo`` keeps each group's joints once computed, so groups shared by many others (a
    diamond of subgroups) cost one walk each, not one per path to them.
    """
    memo = {} if memo is None else memo
    if name in memo:
        return set(memo[name])
    groups = {g.name: g for g in srdf.groups}
    g = groups.get(name)
    if g is None or name in seen:
        return set()
    out = {j for j in g.joints if world.has_connection(j)}
    for link in g.links:
        if world.has_body(link):
            c = world.parent_connection(link)
            if c is not None:
                out.add(c.name)
    for ch in g.chains:
        if world.has_body(ch.base_link) and world.has_body(ch.tip_link):
            base, tip = world.get_body_by_name(ch.base_link), world.get_body_by_name(ch.tip_link)
            if world.is_ancestor(base, tip):
                out.update(c.name for c in world.compute_chain_of_connections(base, tip))
    for sub in g.subgroups:
        out |= joint_set(world, srdf, sub, seen | {name}, memo)
    memo[name] = frozenset(out)
    return out


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


def group_chains(world: World, srdf: Srdf) -> list[GroupChain]:
    """Every group that is a serial chain, in the SRDF's order."""
    out = []
    memo: dict[str, frozenset[str]] = {}
    for g in srdf.groups:
        found = _serial(world, g, joint_set(world, srdf, g.name, memo=memo))
        if found is not None:
            out.append(found)
    return out


def end_effector_root(world: World, srdf: Srdf, ee: EndEffector) -> Body | None:
    """Where an end effector starts: the top of its group, if that hangs below its parent link.

    Some SRDFs give the whole limb as the end effector's group (Talos' feet: group ``l_leg``,
    parent link ``left_sole_link``): the top of that group is the robot's base, so the parent
    link is taken instead.
    """
    parent = world.get_body_by_name(ee.parent_link) if world.has_body(ee.parent_link) else None
    bodies: list[Body] = []
    for j in joint_set(world, srdf, ee.group):
        bodies.append(world.bodies[world.get_connection_by_name(j).child])
    groups = {g.name: g for g in srdf.groups}
    g = groups.get(ee.group)
    if g is not None:
        bodies.extend(world.get_body_by_name(n) for n in g.links if world.has_body(n))
    inside = {b.index for b in bodies}
    # A top has no other group body above it (one walk up per body: linear in the group's size).
    tops = [b for b in bodies if not any(a.index in inside for a in world.ancestors(b)[1:])]
    top = min(tops, key=lambda b: world.depth(b)) if tops else None
    if top is not None and (parent is None or world.is_ancestor(parent, top)):
        return top
    return parent


def state_values(srdf: Srdf) -> list[tuple[str, str | None, dict[str, float]]]:
    """Group states as (name, group, single-valued finite joint positions)."""
    out = []
    for gs in srdf.group_states:
        values = {j: float(v[0]) for j, v in gs.joint_values if len(v) == 1 and math.isfinite(v[0])}
        out.append((gs.name, gs.group, values))
    return out
