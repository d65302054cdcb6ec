"""Joining the parts' SRDFs: every record renamed with its part's names, then concatenated.

Why records and not XML: the compiler reads :class:`~robotspec.description.srdf.Srdf` records,
and the renaming rules (:mod:`robotspec.compose.naming`) apply per field, which records make
explicit.
Virtual joints of welded parts are dropped: a weld fixes the part, so only the base part's
virtual joint (its drive) survives.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

from robotspec.compose.naming import PartNames
from robotspec.description.srdf import (
    DisabledCollision,
    DisableDefaultCollisions,
    EnabledCollision,
    EndEffector,
    GroupChain,
    PassiveJoint,
    Srdf,
)

__all__ = ["merge_srdfs", "rename_srdf"]


def rename_srdf(srdf: Srdf, n: PartNames, *, keep_virtual: bool, keep_collisions: bool) -> Srdf:
    """The SRDF of one part in the composed robot's names."""
    groups = tuple(
        replace(
            g,
            name=n.name(g.name),
            joints=tuple(n.joints(g.joints)),
            links=tuple(n.links(g.links)),
            chains=tuple(
                GroupChain(n.link(c.base_link), n.link(c.tip_link), c.line) for c in g.chains
            ),
            subgroups=tuple(n.name(s) for s in g.subgroups),
        )
        for g in srdf.groups
    )
    states = tuple(
        replace(
            s,
            group=None if s.group is None else n.name(s.group),
            joint_values=tuple((n.joint(j), v) for j, v in s.joint_values),
        )
        for s in srdf.group_states
    )
    effectors = tuple(
        EndEffector(
            n.name(e.name),
            n.link(e.parent_link),
            n.name(e.group),
            None if e.parent_group is None else n.name(e.parent_group),
            e.line,
        )
        for e in srdf.end_effectors
    )
    virtual = (
        tuple(
            replace(v, name=n.joint(v.name), child_link=n.link(v.child_link))
            for v in srdf.virtual_joints
        )
        if keep_virtual
        else ()
    )
    disabled: tuple[DisabledCollision, ...] = ()
    default_off: tuple[DisableDefaultCollisions, ...] = ()
    enabled: tuple[EnabledCollision, ...] = ()
    if keep_collisions:
        disabled = tuple(
            replace(d, link1=n.link(d.link1), link2=n.link(d.link2))
            for d in srdf.disabled_collisions
            if n.link(d.link1) != n.link(d.link2)  # a replaced root may merge a pair into one
        )
        default_off = tuple(
            replace(d, link=n.link(d.link)) for d in srdf.disable_default_collisions
        )
        enabled = tuple(
            replace(e, link1=n.link(e.link1), link2=n.link(e.link2))
            for e in srdf.enabled_collisions
        )
    return Srdf(
        robot_name=srdf.robot_name,
        file=srdf.file,
        groups=groups,
        group_states=states,
        end_effectors=effectors,
        virtual_joints=virtual,
        passive_joints=tuple(PassiveJoint(n.joint(p.name), p.line) for p in srdf.passive_joints),
        disabled_collisions=disabled,
        disable_default_collisions=default_off,
        enabled_collisions=enabled,
    )


def merge_srdfs(robot_name: str, parts: Sequence[Srdf]) -> Srdf:
    """One SRDF holding every part's (already renamed) records, parts in order."""
    return Srdf(
        robot_name=robot_name,
        file=None,
        groups=tuple(g for s in parts for g in s.groups),
        group_states=tuple(g for s in parts for g in s.group_states),
        end_effectors=tuple(e for s in parts for e in s.end_effectors),
        virtual_joints=tuple(v for s in parts for v in s.virtual_joints),
        passive_joints=tuple(p for s in parts for p in s.passive_joints),
        disabled_collisions=tuple(d for s in parts for d in s.disabled_collisions),
        disable_default_collisions=tuple(d for s in parts for d in s.disable_default_collisions),
        enabled_collisions=tuple(e for s in parts for e in s.enabled_collisions),
    )
