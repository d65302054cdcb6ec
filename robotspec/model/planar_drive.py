"""A base modelled in the URDF as x, y and theta joints, made one planar drive connection.

Why: many robots (LoCoBot, Boxy, robots exported from simulators) model their mobile base in
the URDF itself, as a prismatic joint along x, one along y and a revolute joint about z, with two
empty links between them. Planners, the SDT bridge and the driver want one base connection (the
SRDF's ``planar`` virtual joint); this module proves the three joints are exactly that motion
and replaces them, keeping their limits.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from robotspec.errors import KinematicsError
from robotspec.model.entities import Body, Connection, ConnectionType, DegreeOfFreedom
from robotspec.model.geometry import frozen_array
from robotspec.model.world import World

__all__ = ["collapse_planar_joints"]

_TOL = 1e-9
_AXES = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
_ROLES = ("x", "y", "theta")


def _refuse(message: str, world: World, conn: Connection | None = None) -> KinematicsError:
    return KinematicsError(
        message,
        file=world.source,
        line=None if conn is None else conn.line,
        kind="joint",
        name=None if conn is None else conn.name,
    )


def _check(world: World, conns: list[Connection]) -> None:
    """Raise unless ``conns`` translate along x, then y, then turn about z, nothing else."""
    kinds = (
        (ConnectionType.PRISMATIC,),
        (ConnectionType.PRISMATIC,),
        (ConnectionType.REVOLUTE, ConnectionType.CONTINUOUS),
    )
    for i, (conn, role, axis, allowed) in enumerate(zip(conns, _ROLES, _AXES, kinds, strict=True)):
        what = "prismatic" if i < 2 else "revolute or continuous"
        if conn.type not in allowed:
            raise _refuse(
                f"drive joint '{conn.name}' ({role}) must be {what}, it is {conn.type.value}",
                world,
                conn,
            )
        if conn.mimic is not None:
            raise _refuse(f"drive joint '{conn.name}' mimics '{conn.mimic.leader}'", world, conn)
        if not np.allclose(conn.axis, axis, atol=_TOL):
            raise _refuse(
                f"drive joint '{conn.name}' ({role}) must move along {list(axis)} of its "
                f"parent, its axis is {list(conn.axis)}",
                world,
                conn,
            )
        if i and not np.allclose(conn.origin, np.eye(4), atol=_TOL):
            raise _refuse(
                f"drive joint '{conn.name}' must sit at its parent's origin (identity "
                "<origin>): only the first drive joint may be offset",
                world,
                conn,
            )
        if i and conn.parent != conns[i - 1].child:
            raise _refuse(
                f"drive joints must follow each other: '{conn.name}' does not hang from "
                f"'{world.bodies[conns[i - 1].child].name}'",
                world,
                conn,
            )
    for conn in conns[:2]:
        between = world.bodies[conn.child]
        if len(world.child_bodies(between)) != 1:
            raise _refuse(
                f"link '{between.name}' between the drive joints carries other links", world, conn
            )
        if between.collisions:
            raise _refuse(
                f"link '{between.name}' between the drive joints has collision geometry",
                world,
                conn,
            )
    names = {c.name for c in conns}
    for other in world.connections:
        if other.mimic is not None and other.mimic.leader in names:
            raise _refuse(
                f"joint '{other.name}' mimics drive joint '{other.mimic.leader}'", world, other
            )


def collapse_planar_joints(
    world: World, joints: tuple[str, str, str], name: str | None = None
) -> World:
    """A world where the x, y and theta joints are one planar connection named ``name``.

    The two links between them are dropped (they must be empty); the planar DOFs keep the
    joints' position, velocity and effort limits. ``name`` defaults to ``PARENT_T_CHILD``.
    """
    conns = [world.get_connection_by_name(j) for j in joints]
    _check(world, conns)
    parent, child = world.bodies[conns[0].parent], world.bodies[conns[2].child]
    joint = name or f"{parent.name}_T_{child.name}"
    if world.has_connection(joint) and joint not in joints:
        raise _refuse(f"joint '{joint}' already exists", world)
    dropped_bodies = {conns[0].child, conns[1].child}
    body_map: dict[int, int] = {}
    bodies: list[Body] = []
    for b in world.bodies:
        if b.index in dropped_bodies:
            continue
        body_map[b.index] = len(bodies)
        bodies.append(b if b.index == len(bodies) else replace(b, index=len(bodies)))
    dropped_dofs = {d for c in conns for d in c.dofs}
    old = [world.degrees_of_freedom[c.dofs[0]] for c in conns]
    planar = [
        DegreeOfFreedom(
            name=f"{joint}/{role}",
            index=i,
            connection=joint,
            lower=d.lower,
            upper=d.upper,
            velocity=d.velocity,
            effort=d.effort,
        )
        for i, (role, d) in enumerate(zip(_ROLES, old, strict=True))
    ]
    dof_map: dict[int, int] = {}
    dofs: list[DegreeOfFreedom] = list(planar)
    for d in world.degrees_of_freedom:
        if d.index in dropped_dofs:
            continue
        dof_map[d.index] = len(dofs)
        dofs.append(replace(d, index=len(dofs)))
    connections: list[Connection] = [
        Connection(
            name=joint,
            index=0,
            type=ConnectionType.PLANAR,
            parent=body_map[parent.index],
            child=body_map[child.index],
            origin=frozen_array(np.asarray(conns[0].origin, dtype=np.float64)),
            axis=(0.0, 0.0, 1.0),
            dofs=(0, 1, 2),
            line=conns[0].line,
        )
    ]
    gone = {c.index for c in conns}
    for c in world.connections:
        if c.index in gone:
            continue
        connections.append(
            replace(
                c,
                index=len(connections),
                parent=body_map[c.parent],
                child=body_map[c.child],
                dofs=tuple(dof_map[d] for d in c.dofs),
            )
        )
    return World(world.name, bodies, connections, dofs, source=world.source)
