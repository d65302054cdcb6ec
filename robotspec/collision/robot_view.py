"""What collision checking needs of a robot: a protocol, not the semantic class.

Why a protocol: the collision room sits above the semantic one (a robot's rules come from its
SRDF and spec), and ``robot.to_pinocchio()`` hands the robot to a room that builds on
collision. Had collision named :class:`~robotspec.semantic.robot.AbstractRobot`, that hand-off
would close an import cycle (semantic -> interop -> collision -> semantic). Collision names
only these few members; any compiled robot has them.
"""

from __future__ import annotations

from collections.abc import Collection, Mapping, Sequence
from typing import TYPE_CHECKING, Protocol

if TYPE_CHECKING:
    from robotspec.arrays import F64
    from robotspec.description.srdf import Srdf
    from robotspec.model.world import Body, World

__all__ = ["BufferConfig", "CollisionRobot"]


class BufferConfig(Protocol):
    """The robot's self-collision settings, as far as the rules read them (metres)."""

    @property
    def buffer_zone_distance(self) -> float:
        """Pairs nearer than this are reported by distance queries."""
        ...


class CollisionRobot(Protocol):
    """A robot as collision checking reads it: its world, its bodies, its rules, its states."""

    @property
    def name(self) -> str:
        """The robot's name (messages name it)."""
        ...

    @property
    def world(self) -> World:
        """The world the robot's bodies live in."""
        ...

    @property
    def srdf(self) -> Srdf | None:
        """The SRDF the spec applies, if any."""
        ...

    @property
    def bodies_with_collisions(self) -> Sequence[Body]:
        """The robot's bodies that carry collision geometry."""
        ...

    @property
    def disabled_collision_pairs(self) -> Collection[frozenset[str]]:
        """Body pairs never checked (the SRDF's, and pairs added in code)."""
        ...

    @property
    def disabled_collision_bodies(self) -> Collection[str]:
        """Bodies never checked (the spec's and the SRDF's default-off links)."""
        ...

    @property
    def default_collision_config(self) -> BufferConfig:
        """The robot's self-collision settings."""
        ...

    def state_configuration(
        self,
        states: Sequence[str] | str = (),
        values: Mapping[str, float] | None = None,
    ) -> F64:
        """A configuration from named joint states, then joint values by name."""
        ...
