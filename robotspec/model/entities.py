"""The records a world is made of: bodies, connections, degrees of freedom, mimic rules.

Frozen and index-addressed, so a world can hand them out freely: a semantic object that keeps a
``Body`` keeps a value, never a handle into mutable state.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from enum import StrEnum

from robotspec.model.geometry import Matrix, Shape

__all__ = ["Body", "Connection", "ConnectionType", "DegreeOfFreedom", "Mimic"]


class ConnectionType(StrEnum):
    """How a connection moves its child; the names are URDF's joint types."""

    FIXED = "fixed"
    REVOLUTE = "revolute"
    CONTINUOUS = "continuous"
    PRISMATIC = "prismatic"
    FLOATING = "floating"
    PLANAR = "planar"

    @property
    def dof_count(self) -> int:
        """How many degrees of freedom a connection of this type owns (mimics own none)."""
        return _DOF_COUNT[self]

    @property
    def dof_suffixes(self) -> tuple[str, ...]:
        """Names appended to the connection's name for multi-DOF connections."""
        return _DOF_SUFFIXES[self]


_DOF_COUNT = {
    ConnectionType.FIXED: 0,
    ConnectionType.REVOLUTE: 1,
    ConnectionType.CONTINUOUS: 1,
    ConnectionType.PRISMATIC: 1,
    ConnectionType.FLOATING: 6,
    ConnectionType.PLANAR: 3,
}
_DOF_SUFFIXES: dict[ConnectionType, tuple[str, ...]] = {
    ConnectionType.FIXED: (),
    ConnectionType.REVOLUTE: ("",),
    ConnectionType.CONTINUOUS: ("",),
    ConnectionType.PRISMATIC: ("",),
    # Floating: translation then fixed-axis roll/pitch/yaw, like a URDF origin.
    ConnectionType.FLOATING: ("/x", "/y", "/z", "/roll", "/pitch", "/yaw"),
    # Planar: two translations in the plane normal to the axis, then rotation about it.
    ConnectionType.PLANAR: ("/x", "/y", "/theta"),
}


@dataclass(frozen=True)
class Mimic:
    """A connection that follows another: ``q = multiplier * q_leader + offset``."""

    leader: str
    multiplier: float = 1.0
    offset: float = 0.0


@dataclass(frozen=True)
class Body:
    """A rigid body (URDF link or added frame); the seed's ``KinematicStructureEntity``."""

    name: str
    index: int
    visuals: tuple[Shape, ...] = ()
    collisions: tuple[Shape, ...] = ()
    mass: float | None = None
    line: int | None = None

    @property
    def has_collision(self) -> bool:
        """Whether the body has any collision geometry."""
        return bool(self.collisions)


@dataclass(frozen=True)
class Connection:
    """A joint between a parent and a child body.

    ``origin`` is the parent-to-joint-frame transform (URDF joint origin); ``axis`` is a unit
    vector in the joint frame. ``dofs`` are the indices of the world's degrees of freedom that
    drive it: its own for an active joint, its leader's for a mimic, none for a fixed joint.
    """

    name: str
    index: int
    type: ConnectionType
    parent: int
    child: int
    origin: Matrix = field(compare=False, repr=False)
    axis: tuple[float, float, float] = (1.0, 0.0, 0.0)
    dofs: tuple[int, ...] = ()
    mimic: Mimic | None = None
    line: int | None = None

    @property
    def is_fixed(self) -> bool:
        """Fixed connections never move."""
        return self.type is ConnectionType.FIXED

    @property
    def is_mimic(self) -> bool:
        """Mimic connections move but are not commanded on their own."""
        return self.mimic is not None

    @property
    def is_active(self) -> bool:
        """A connection with its own degrees of freedom (the seed's ``ActiveConnection``)."""
        return bool(self.dofs) and self.mimic is None

    @property
    def is_1dof(self) -> bool:
        """Revolute, continuous and prismatic connections (the seed's ``ActiveConnection1DOF``)."""
        return self.type.dof_count == 1


@dataclass(frozen=True)
class DegreeOfFreedom:
    """One scalar coordinate of the world's configuration, with its limits (SI units).

    Unlimited quantities are ``-inf``/``inf``, never ``None``, so limit arithmetic needs no special
    cases.
    """

    name: str
    index: int
    connection: str
    lower: float
    upper: float
    velocity: float = math.inf
    effort: float = math.inf

    @property
    def is_bounded(self) -> bool:
        """Whether the position has finite limits on both sides."""
        return math.isfinite(self.lower) and math.isfinite(self.upper)
