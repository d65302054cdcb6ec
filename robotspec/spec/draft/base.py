"""The base a URDF moves itself, and wheels known by their shape, for the drafted drive.

Why by structure: bases are modelled as a URDF ``planar`` joint or as prismatic x, prismatic y
and revolute z joints (``odom_x``/``odom_y``/``odom_theta``, but just as often ``joint_x`` or
``base_footprint_joint_1``), below a root frame and fixed joints of any name. Their types and
axes decide, proven by the compiler's own check, so a drafted drive validates. Wheels the same
way: a continuous joint turning a flat cylinder or a ball about a horizontal axis is a wheel
whatever its name (``fl_caster_r``), and a drone's propeller (a vertical axis) is not.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robotspec.model.entities import Body, Connection, ConnectionType
from robotspec.model.geometry import Cylinder, Sphere
from robotspec.model.kinematics import Kinematics
from robotspec.model.world import World
from robotspec.spec.draft.model import DraftDrive
from robotspec.spec.draft.tree import words

__all__ = ["OwnBase", "fixed_wheels", "own_base", "own_drive", "wheel_joints"]

#: Words that name a spinning part that is no wheel.
_NOT_WHEELS = frozenset({"rotor", "propeller", "prop", "fan"})


@dataclass(frozen=True)
class OwnBase:
    """The URDF's own base motion: its joints and the link they move (the robot's root)."""

    #: The moved link, which the draft makes the robot's root.
    root: Body
    #: The x, y, theta joints (``drive.joints``), or None for a planar joint.
    joints: tuple[str, str, str] | None = None
    #: The planar joint (``drive.joint``), or None for three joints.
    planar: str | None = None


def _fixed_above(world: World, body: Body) -> bool:
    """Whether only fixed joints lie between the world's root and ``body``."""
    return all(
        (c := world.parent_connection(b)) is None or c.is_fixed
        for b in (*world.ancestors(body), body)
    )


def _moving_child(world: World, body: Body) -> Body | None:
    kids = [
        k
        for k in world.child_bodies(body)
        if not world.parent_connection(k).is_fixed  # type: ignore[union-attr]
    ]
    return kids[0] if len(kids) == 1 else None


def _three_joints(world: World, first: Connection) -> tuple[str, str, str] | None:
    """The x, y, theta joints starting at the prismatic ``first``, if they are a planar base."""
    from robotspec.errors import RobotSpecError
    from robotspec.model.planar_drive import collapse_planar_joints

    found = [first.name]
    body = world.bodies[first.child]
    while len(found) < 3:
        nxt = _moving_child(world, body)
        if nxt is None:
            return None
        found.append(world.parent_connection(nxt).name)  # type: ignore[union-attr]
        body = nxt
    joints = (found[0], found[1], found[2])
    try:
        collapse_planar_joints(world, joints)
    except RobotSpecError:
        return None
    return joints


def own_base(world: World) -> OwnBase | None:
    """The base motion the URDF models itself, reached from its root through fixed joints only.

    A ``planar`` joint, or prismatic x, prismatic y and revolute z joints in a row; the first
    found in the tree's order. None when the URDF has neither above its moving parts.
    """
    for c in world.connections:
        if c.type not in (ConnectionType.PLANAR, ConnectionType.PRISMATIC):
            continue
        if not _fixed_above(world, world.bodies[c.parent]):
            continue
        if c.type is ConnectionType.PLANAR:
            return OwnBase(world.bodies[c.child], planar=c.name)
        joints = _three_joints(world, c)
        if joints is not None:
            theta = world.get_connection_by_name(joints[2])
            return OwnBase(world.bodies[theta.child], joints=joints)
    return None


def _wheel_shaped(body: Body, axis: np.ndarray) -> bool:
    """A flat cylinder about ``axis`` (in the body's frame) or a ball among its shapes."""
    for shape in (*body.collisions, *body.visuals):
        g = shape.geometry
        if isinstance(g, Sphere):
            return True
        if isinstance(g, Cylinder) and g.length <= 2.0 * g.radius:
            along = np.asarray(shape.origin)[:3, 2]
            if abs(float(along @ axis)) > 0.9:
                return True
    return False


def _on_a_swivel(world: World, c: Connection, poses: np.ndarray | None = None) -> bool:
    """Whether the wheel joint ``c`` hangs from a body another turning joint moves (a caster).

    Why: a caster's wheel is a flat cylinder on a level continuous joint like a driven wheel,
    but it follows its swivel; counting it made a two-wheeled base with four casters (TIAGo)
    look like a six-wheeled omni base.
    """
    above = world.parent_connection(world.bodies[c.parent])
    if above is None or above.type not in (ConnectionType.CONTINUOUS, ConnectionType.REVOLUTE):
        return False
    if poses is None:
        return True
    # A swivel turns about the vertical; a knee above a wheel (a wheel-legged robot's, LimX's)
    # turns about a level axis, and the wheel at the leg's end is driven.
    up = poses[above.child][:3, :3] @ np.asarray(above.axis, dtype=np.float64)
    return abs(float(up[2])) / (float(np.linalg.norm(up)) or 1.0) > SWIVEL_VERTICAL


#: How vertical (the cosine to z) the axis of a joint above a wheel must be to be a swivel.
SWIVEL_VERTICAL = 0.7


def wheel_joints(world: World, poses: np.ndarray | None = None) -> list[Connection]:
    """The joints that turn wheels: named so, or continuous and wheel-shaped about a level axis.

    Why both: a name is enough when it says ``wheel`` (meshes cannot be measured here); a
    nameless wheel is known by its cylinder turning about its own axis, held level in the
    default pose (a propeller's axis stands up). ``poses``: the default pose's forward
    kinematics when the caller has them (the drafter's tree), computed here otherwise.
    """
    moving = [c for c in world.connections if c.is_active]
    out = []
    for c in moving:
        named = words(c.name) | words(world.bodies[c.child].name)
        if named & _NOT_WHEELS:
            continue
        if "wheel" in words(c.name):
            out.append(c)
            continue
        if c.type is not ConnectionType.CONTINUOUS and not _turns_round(world, c):
            continue
        axis = np.asarray(c.axis, dtype=np.float64)
        if not _wheel_shaped(world.bodies[c.child], axis):
            continue
        if poses is None:
            poses = Kinematics(world).forward(world.default_configuration())
        if _on_a_swivel(world, c, poses):
            continue  # a caster's wheel: it rolls where its swivel lets it, nobody drives it
        level = poses[c.child][:3, :3] @ axis
        if abs(float(level[2])) < 0.3:
            out.append(c)
    return out


#: A revolute joint allowed more than this (rad: ten turns) is a continuous one written with
#: limits (LimX's wheels: +-1000 rad); a leg's joints may turn +-3 pi (ANYmal B's), not more.
MANY_TURNS = 20 * np.pi


def _turns_round(world: World, c: Connection) -> bool:
    """Whether ``c`` is revolute with a range of several turns (LimX's wheels: +-1000 rad)."""
    if c.type is not ConnectionType.REVOLUTE or not c.dofs:
        return False
    dof = world.degrees_of_freedom[c.dofs[0]]
    return not dof.is_bounded or dof.upper - dof.lower > MANY_TURNS


def fixed_wheels(world: World) -> list[Connection]:
    """Fixed joints carrying a link named a wheel (a simulator's base moved by other joints).

    Why: Fetch in ManiSkill moves its base by x/y/theta joints and models its two wheels on
    fixed joints; they still tell a two-wheeled (differential) base from an omni one. Casters
    (named so) are no wheels that drive.
    """
    out = []
    for c in world.connections:
        if not c.is_fixed:
            continue
        named = words(c.name) | words(world.bodies[c.child].name)
        if "wheel" in named and not named & (_NOT_WHEELS | {"caster", "castor"}):
            out.append(c)
    return out


def own_drive(world: World, base: OwnBase, wheels: list[Connection]) -> DraftDrive:
    """The drafted drive of the URDF's own base: omni, or differential on exactly two wheels.

    Why a DECIDE mark: the joints say the base moves in the plane, not whether it can move
    sideways; two driven wheels say it cannot, anything else is drafted omni for a person to check.
    """
    rolled = ""
    if not wheels:  # wheels modelled on fixed joints still say what carries the base
        wheels = fixed_wheels(world)
        rolled = " on fixed joints" if wheels else ""
    kind = "differential" if len(wheels) == 2 else "omni"
    why = f"{len(wheels)} wheels{rolled}: {kind}?" if wheels else f"{kind}?"
    if base.joints is not None:
        return DraftDrive(
            kind,
            source="the URDF's base joints",
            decide=f"the URDF's x, y, theta joints move the base; {why}",
            joints=base.joints,
        )
    return DraftDrive(
        kind,
        base.planar,
        source=f"the URDF's planar joint '{base.planar}'",
        decide=f"the URDF's planar joint '{base.planar}' moves the base; {why}",
    )
