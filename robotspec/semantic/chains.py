"""Kinematic chains: arms, fingers, the torso and the neck, as views over the world's tree."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Literal

from robotspec.model.world import Body, Connection, DegreeOfFreedom
from robotspec.semantic.base import JointState, SemanticRobotAnnotation

if TYPE_CHECKING:
    from robotspec.semantic.manipulators import Manipulator
    from robotspec.semantic.robot import AbstractRobot
    from robotspec.semantic.sensors import Sensor

__all__ = ["Arm", "Finger", "KinematicChain", "Neck", "Torso"]


@dataclass(eq=False, repr=False)
class KinematicChain(SemanticRobotAnnotation):
    """The bodies from ``root`` down to ``tip``; may carry a manipulator and sensors."""

    tip: Body = field(kw_only=True)
    manipulator: Manipulator | None = field(default=None, kw_only=True)
    sensors: list[Sensor] = field(default_factory=list, kw_only=True)
    states: dict[str, JointState] = field(default_factory=dict, kw_only=True)

    @property
    def kinematic_structure_entities(self) -> list[Body]:
        """Root to tip, both included."""
        return self.world.compute_chain_of_kinematic_structure_entities(self.root, self.tip)

    @property
    def bodies(self) -> list[Body]:
        """The chain's bodies (robotspec's world has only bodies)."""
        return self.kinematic_structure_entities

    @property
    def regions(self) -> list[Body]:
        """Regions of the chain: none; robotspec's world has no regions."""
        return []

    @property
    def connections(self) -> list[Connection]:
        """Connections between consecutive chain bodies (empty when root is tip)."""
        return self.world.compute_chain_of_connections(self.root, self.tip)

    @property
    def active_connections(self) -> list[Connection]:
        """Connections with degrees of freedom of their own (no fixed, no mimic)."""
        return [c for c in self.connections if c.is_active]

    @property
    def degrees_of_freedom(self) -> list[DegreeOfFreedom]:
        """Degrees of freedom that move the chain, in chain order (mimic leaders included)."""
        seen: dict[int, DegreeOfFreedom] = {}
        for c in self.connections:
            for d in c.dofs:
                seen.setdefault(d, self.world.degrees_of_freedom[d])
        return list(seen.values())

    def assign_to_robot(self, robot: AbstractRobot) -> None:
        """Attach the chain, then its manipulator and sensors, to ``robot``."""
        super().assign_to_robot(robot)
        if self.manipulator is not None:
            robot.add_manipulator(self.manipulator)
        for s in self.sensors:
            robot.add_sensor(s)

    def __hash__(self) -> int:
        return hash((type(self).__name__, self.name, self.root.name, self.tip.name))

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.name!r}, {self.root.name!r} -> {self.tip.name!r})"


@dataclass(eq=False, repr=False)
class Arm(KinematicChain):
    """A chain that carries a manipulator; ``side`` when the spec names it (left or right)."""

    side: Literal["left", "right"] | None = field(default=None, kw_only=True)


@dataclass(eq=False, repr=False)
class Finger(KinematicChain):
    """A finger of a gripper: a chain with an unambiguous tip."""


@dataclass(eq=False, repr=False)
class Torso(KinematicChain):
    """The chain joining the base to the other chains; its assignment does not propagate."""

    def assign_to_robot(self, robot: AbstractRobot) -> None:
        """Attach only the torso itself (the reference's rule)."""
        SemanticRobotAnnotation.assign_to_robot(self, robot)


@dataclass(eq=False, repr=False)
class Neck(KinematicChain):
    """The chain carrying the head sensors, with optional pitch and yaw bodies."""

    pitch_body: Body | None = field(default=None, kw_only=True)
    yaw_body: Body | None = field(default=None, kw_only=True)
