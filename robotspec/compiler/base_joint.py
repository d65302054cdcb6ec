"""A drive the URDF already has: a ``planar`` or ``floating`` joint above the robot's root.

Why: robots exported from simulators and many mobile bases (an omnidirectional base with four
wheels) write the base's motion as one URDF ``planar`` joint from ``odom`` or ``world`` to the
base link. That joint *is* the drive; the spec says which kind (``omni`` or ``differential`` for
a planar joint, ``floating`` for a floating one) and, optionally, names it. Adding a second base
connection above it (what ``drive:`` does for a URDF without one) would be wrong, and refusing
the spec (what happened before) left such robots without a declarable drive.
"""

from __future__ import annotations

from robotspec.diagnostics import Diagnostics
from robotspec.model.entities import Connection, ConnectionType
from robotspec.model.world import World
from robotspec.spec.models import RobotSpec

__all__ = ["base_joint_above_root", "check_urdf_base_joint"]

#: The drive types each kind of URDF base joint can be.
_TYPES = {
    ConnectionType.PLANAR: ("omni", "differential"),
    ConnectionType.FLOATING: ("floating",),
}


def base_joint_above_root(world: World, root: str) -> Connection | None:
    """The URDF's planar or floating joint whose child is the robot's root ``root``, if any."""
    if not world.has_body(root):
        return None
    above = world.parent_connection(world.get_body_by_name(root))
    if above is None or above.type not in _TYPES:
        return None
    return above


def check_urdf_base_joint(
    spec: RobotSpec, joint: Connection, world: World, diag: Diagnostics
) -> None:
    """Record why the spec's ``drive`` cannot be the URDF's base ``joint``, if it cannot.

    The world is left as it is: the joint is the robot's drive already (``robot.drive`` is the
    root's parent connection).
    """
    drive = spec.drive
    assert drive is not None
    kinds = _TYPES[joint.type]
    what = f"the URDF's {joint.type.value} joint '{joint.name}' above the root '{spec.root_link}'"
    if drive.type not in kinds:
        diag.error(
            ("drive", "type"),
            f"{what} is the drive: its type is {' or '.join(kinds)}, not {drive.type}",
        )
    if drive.joints is not None:
        diag.error(
            ("drive", "joints"),
            f"{what} is the drive already; drive.joints names x, y and theta joints, not it",
        )
    if drive.joint is not None and drive.joint != joint.name:
        diag.error(
            ("drive", "joint"),
            f"{what} is the drive; name it '{joint.name}' or leave joint out",
            name=drive.joint,
        )
    parent = world.bodies[joint.parent].name
    if "parent_frame" in drive.model_fields_set and drive.parent_frame != parent:
        diag.error(
            ("drive", "parent_frame"),
            f"{what} moves it in '{parent}'; write '{parent}' or leave parent_frame out",
            name=drive.parent_frame,
        )
