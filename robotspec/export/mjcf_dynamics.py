"""What MuJoCo's physics needs that robotspec's world model does not keep: inertias, damping.

Why a reader of its own: the world model keeps what kinematics, collisions and semantics use
(bodies, joints, limits, masses); an MJCF export also needs each link's full inertial (centre of
mass and tensor) and each joint's damping and friction, which only the URDF states. They are
read from the robot's joined URDF tree (the same tree ``export urdf`` writes) by link and joint
name, and checked like any number that enters: a NaN, an infinity or a negative mass is refused
with the link and the URDF line.

The servo gains come from the same numbers: a position servo tuned to one natural frequency on
every joint needs each joint's own inertia about its axis (a finger and a shoulder differ by
six orders of magnitude), computed here at one configuration (the export takes the largest
over several).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
from lxml import etree

from robotspec.arrays import F64
from robotspec.errors import RobotSpecError
from robotspec.model.entities import Connection, ConnectionType
from robotspec.model.rotations import rpy_to_matrix
from robotspec.model.world import World

__all__ = ["Inertial", "JointDynamics", "joint_inertias", "urdf_dynamics", "urdf_inertials"]


@dataclass(frozen=True)
class Inertial:
    """A link's mass (kg), centre of mass (m, link frame) and tensor about it (link axes)."""

    mass: float
    com: tuple[float, float, float]
    tensor: F64 = field(compare=False, repr=False)


@dataclass(frozen=True)
class JointDynamics:
    """A joint's viscous damping and dry friction as its URDF ``<dynamics>`` states them."""

    damping: float = 0.0
    friction: float = 0.0


def _line(el: etree._Element) -> int | None:
    line = el.sourceline
    return line if isinstance(line, int) else None


def _at(el: etree._Element) -> str:
    """`` (URDF line N)``: the joined tree has no file name, so the line goes in the message.

    Why: an error with a line but no file prints without either; the line of the link or
    joint is what the user needs to find the number in their URDF (a composed robot's line
    is in the part that defines it).
    """
    line = _line(el)
    return f" (URDF line {line})" if line is not None else ""


def _numbers(el: etree._Element, attr: str, count: int, where: str, default: str) -> list[float]:
    text = el.get(attr, default)
    parts = text.split()
    try:
        values = [float(p) for p in parts]
    except ValueError:
        values = []
    if len(values) != count or not all(math.isfinite(v) for v in values):
        raise RobotSpecError(
            f"{where}: {attr}='{text}' must be {count} finite number{'s' * (count > 1)}",
            line=_line(el),
            kind="urdf",
        )
    return values


def urdf_inertials(tree: etree._Element) -> dict[str, Inertial]:
    """Each link's ``<inertial>`` with a positive mass; links without one are left out."""
    found: dict[str, Inertial] = {}
    for link in tree.iterfind("link"):
        name = link.get("name", "")
        el = link.find("inertial")
        if el is None:
            continue
        where = f"link '{name}'{_at(link)}"
        mass_el = el.find("mass")
        mass = 0.0 if mass_el is None else _numbers(mass_el, "value", 1, where, "0")[0]
        if mass < 0.0:
            raise RobotSpecError(f"{where}: negative mass {mass}", line=_line(el), kind="urdf")
        if mass == 0.0:
            continue
        origin = el.find("origin")
        xyz = [0.0, 0.0, 0.0]
        rotation = np.eye(3)
        if origin is not None:
            xyz = _numbers(origin, "xyz", 3, where, "0 0 0")
            rotation = rpy_to_matrix(*_numbers(origin, "rpy", 3, where, "0 0 0"))
        inertia = el.find("inertia")
        tensor = np.zeros((3, 3))
        if inertia is not None:
            names = ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")
            ixx, iyy, izz, ixy, ixz, iyz = (_numbers(inertia, n, 1, where, "0")[0] for n in names)
            tensor = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
        # URDF states the tensor in the inertial frame; MJCF's fullinertia is in the body's.
        in_link = rotation @ tensor @ rotation.T
        in_link.setflags(write=False)
        found[name] = Inertial(mass, (xyz[0], xyz[1], xyz[2]), in_link)
    return found


def urdf_dynamics(tree: etree._Element) -> dict[str, JointDynamics]:
    """Each joint's ``<dynamics damping= friction=>`` (joints without one are left out)."""
    found: dict[str, JointDynamics] = {}
    for joint in tree.iterfind("joint"):
        el = joint.find("dynamics")
        if el is None:
            continue
        where = f"joint '{joint.get('name', '')}'{_at(joint)}"
        damping = _numbers(el, "damping", 1, where, "0")[0]
        friction = _numbers(el, "friction", 1, where, "0")[0]
        if damping < 0.0 or friction < 0.0:
            raise RobotSpecError(
                f"{where}: damping and friction must not be negative",
                line=_line(el),
                kind="urdf",
            )
        found[joint.get("name", "")] = JointDynamics(damping, friction)
    return found


def joint_inertias(
    world: World, poses: F64, inertials: Mapping[str, Inertial], connections: list[Connection]
) -> dict[str, float]:
    """Each 1-DOF connection's inertia about (along) its axis, the rest of the robot held still.

    ``poses`` are every body's poses at one configuration (``Kinematics.forward``). For a
    revolute joint: the sum over the bodies it moves of ``m |a x (c - p)|^2 + a' I a``; for a
    prismatic joint the moved mass. This is the diagonal of the joint-space mass matrix, which
    is what one joint's servo has to accelerate.
    """
    found: dict[str, float] = {}
    for c in connections:
        joint_frame = poses[c.parent] @ c.origin
        axis = joint_frame[:3, :3] @ np.asarray(c.axis, dtype=np.float64)
        point = joint_frame[:3, 3]
        total = 0.0
        for body in world.subtree(world.bodies[c.child]):
            inertial = inertials.get(body.name)
            if inertial is None:
                continue
            pose = poses[body.index]
            if c.type is ConnectionType.PRISMATIC:
                total += inertial.mass
                continue
            com = pose[:3, :3] @ np.asarray(inertial.com) + pose[:3, 3]
            lever = np.cross(axis, com - point)
            tensor = pose[:3, :3] @ inertial.tensor @ pose[:3, :3].T
            total += inertial.mass * float(lever @ lever) + float(axis @ tensor @ axis)
        found[c.name] = total
    return found
