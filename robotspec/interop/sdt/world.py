"""robotspec's world model as an SDT ``World``: bodies, shapes, degrees of freedom, joints, drive.

Why from the world model and not from the URDF file: every compiled robot has a world, but not
every robot has one file SDT can read (a composed robot is several files joined in memory; a
spec's extra frames are in no file; HSRB's URDF has a revolute joint without ``<axis>``, which
SDT's parser refuses although URDF defines it as ``1 0 0``; SDT's parser reads axes as integers,
and finds ``package://`` meshes only on a ROS_PACKAGE_PATH entry named after the package).
robotspec's world already holds the resolved mesh paths, the spec's frames and the base joint,
so SDT gets exactly the robot robotspec checked. What robotspec's model does not keep is not
carried: inertia tensors (robotspec keeps masses only) and joint dynamics (damping, friction).

Names are SDT's parser's: each body and joint ``PrefixedName(name, prefix=<URDF robot name>)``;
a mimic joint shares its leader's degree of freedom, with multiplier and offset.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

import numpy as np

from robotspec.errors import RobotSpecError
from robotspec.interop.sdt.failures import mesh_failure
from robotspec.model.entities import ConnectionType
from robotspec.model.geometry import Box, Capsule, Cylinder, Mesh, Shape, Sphere
from robotspec.model.world import World

__all__ = ["building_world", "sdt_world"]


def _limit(value: float) -> float | None:
    return value if math.isfinite(value) else None


def _shapes(sdt: Any, shapes: tuple[Shape, ...], body: Any) -> Any:
    g = sdt.geometry
    out = []
    for s in shapes:
        origin = sdt.HomogeneousTransformationMatrix(
            data=np.asarray(s.origin, dtype=float), reference_frame=body
        )
        color = g.Color(*s.rgba) if s.rgba is not None else g.Color(1, 1, 1, 1)
        geo = s.geometry
        if isinstance(geo, Box):
            out.append(g.Box(origin=origin, scale=g.Scale(*geo.size), color=color))
        elif isinstance(geo, Sphere):
            out.append(g.Sphere(origin=origin, radius=geo.radius, color=color))
        elif isinstance(geo, Cylinder):
            out.append(
                g.Cylinder(origin=origin, width=2 * geo.radius, height=geo.length, color=color)
            )
        elif isinstance(geo, Capsule):
            # SDT has no capsule: its cylinder plus the two caps' length, the enclosing shape.
            out.append(
                g.Cylinder(
                    origin=origin,
                    width=2 * geo.radius,
                    height=geo.length + 2 * geo.radius,
                    color=color,
                )
            )
        elif isinstance(geo, Mesh):
            if geo.path is None:
                continue  # robotspec reported the missing mesh when it loaded the robot
            out.append(g.Mesh(origin=origin, filename=geo.path, scale=g.Scale(*geo.scale)))
    return sdt.ShapeCollection(out, reference_frame=body)


def _dof(sdt: Any, world: World, index: int, name: Any) -> Any:
    d = world.degrees_of_freedom[index]
    lower, upper = sdt.DerivativeMap(), sdt.DerivativeMap()
    lower.position, upper.position = _limit(d.lower), _limit(d.upper)
    v = _limit(d.velocity)
    lower.velocity, upper.velocity = (None, None) if v is None else (-v, v)
    return sdt.DegreeOfFreedom(
        name=name, limits=sdt.DegreeOfFreedomLimits(lower=lower, upper=upper)
    )


def sdt_world(world: World, *, drive: str, prefix: str | None = None) -> Any:
    """A new SDT World holding ``world``'s bodies and joints; the base joint becomes ``drive``.

    ``drive`` is the robot's drive type (``omni``, ``differential``, ``floating``, ``fixed``):
    a planar joint becomes SDT's ``OmniDrive`` or ``DifferentialDrive``, a floating one its
    ``Connection6DoF``. A planar or floating joint elsewhere has no SDT kind and is refused.
    """
    with building_world(world, drive=drive, prefix=prefix) as out:
        pass
    return out


@contextmanager
def building_world(world: World, *, drive: str, prefix: str | None = None) -> Iterator[Any]:
    """:func:`sdt_world`'s world, its modification block still open for the caller's additions.

    Why: SDT recomputes on every closed block (it rebuilds every body's Bullet collision
    shapes, loading and testing each mesh, and compiles its forward kinematics again), so a
    world filled in one block and given a robot in a second pays that twice. What the caller
    adds inside the ``with`` is published with the world, in one block and one recomputation
    (its history is one block, which replays as the two did).
    """
    from robotspec.interop.sdt import sdt_api

    sdt = sdt_api()
    prefix = prefix or world.name

    def pname(n: str) -> Any:
        return sdt.PrefixedName(n, prefix)

    out = sdt.World()
    out.name = prefix
    try:
        with out.modify_world():
            _fill(sdt, out, world, drive, pname)
            yield out
    except Exception as exc:
        failure = mesh_failure(exc)  # SDT's mesh step failed: name it and the mesh file
        if failure is not None:
            raise failure from exc
        if not isinstance(exc, RuntimeError) or "resources" not in str(exc):
            raise
        # SDT's wheel lacks its resources/ folder; its Bullet collision sync loads
        # resources/obj/cylinder.obj for every cylinder of a world (docs/sdt.md).
        raise RobotSpecError(
            f"SDT cannot build this world: {str(exc).strip()}; SDT 26.7's wheel lacks its "
            "resources/ folder (install SDT from its source, or put a unit cylinder mesh, "
            "diameter 1 and height 1, at that path)",
            kind="dependency",
            name="semantic_digital_twin",
        ) from exc


def _fill(sdt: Any, out: Any, world: World, drive: str, pname: Any) -> None:
    """Bodies, degrees of freedom and joints of ``world`` into the SDT world ``out``."""
    bodies = []
    for b in world.bodies:
        body = sdt.Body(name=pname(b.name))
        body.visual = _shapes(sdt, b.visuals, body)
        body.collision = _shapes(sdt, b.collisions, body)
        bodies.append(body)
    out.add_kinematic_structure_entity(bodies[world.root.index])
    for b in bodies:
        if b is not bodies[world.root.index]:
            out.add_kinematic_structure_entity(b)
    dofs: dict[int, Any] = {}
    conns = sorted(world.connections, key=lambda c: c.mimic is not None)
    for c in conns:
        parent, child = bodies[c.parent], bodies[c.child]
        origin = sdt.HomogeneousTransformationMatrix(
            data=np.asarray(c.origin, dtype=float), reference_frame=parent
        )
        if c.type is ConnectionType.FIXED:
            out.add_connection(
                sdt.FixedConnection(
                    name=pname(c.name),
                    parent=parent,
                    child=child,
                    parent_T_connection_expression=origin,
                )
            )
        elif c.type in (ConnectionType.PLANAR, ConnectionType.FLOATING):
            out.add_connection(_base_joint(sdt, out, c.type, drive, parent, child, pname(c.name)))
        else:
            index = c.dofs[0]
            if index not in dofs:
                leader = c.mimic.leader if c.mimic is not None else c.name
                dofs[index] = _dof(sdt, world, index, pname(leader))
                out.add_degree_of_freedom(dofs[index])
            kind = (
                sdt.PrismaticConnection
                if c.type is ConnectionType.PRISMATIC
                else sdt.RevoluteConnection
            )
            out.add_connection(
                kind(
                    name=pname(c.name),
                    parent=parent,
                    child=child,
                    parent_T_connection_expression=origin,
                    multiplier=1.0 if c.mimic is None else c.mimic.multiplier,
                    offset=0.0 if c.mimic is None else c.mimic.offset,
                    axis=sdt.Vector3(*c.axis, reference_frame=parent),
                    raw_dof=dofs[index],
                )
            )


def _base_joint(
    sdt: Any, out: Any, kind: ConnectionType, drive: str, parent: Any, child: Any, name: Any
) -> Any:
    """A planar or floating joint (robotspec makes them only above a robot's root) for SDT."""
    if kind is ConnectionType.PLANAR and drive not in ("omni", "differential"):
        raise RobotSpecError(
            f"joint '{name.name}' is planar but the robot's drive is '{drive}'; SDT has a "
            "planar joint only as an omni or differential drive",
            kind="joint",
            name=name.name,
        )
    if kind is ConnectionType.FLOATING:
        cls = sdt.Connection6DoF
    else:
        cls = sdt.OmniDrive if drive == "omni" else sdt.DifferentialDrive
    return cls.create_with_dofs(world=out, parent=parent, child=child, name=name)
