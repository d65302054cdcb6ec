"""End effectors: a tool frame plus the orientation of a front grasp."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from robotspec.model.rotations import quaternion_to_matrix
from robotspec.model.world import Body
from robotspec.semantic.base import JointState, SemanticRobotAnnotation
from robotspec.semantic.chains import Finger

__all__ = [
    "GenericManipulator",
    "Hand",
    "Manipulator",
    "ParallelGripper",
    "front_facing_axis_of",
]


def front_facing_axis_of(q: tuple[float, float, float, float]) -> tuple[float, float, float]:
    """The reference's rule: the first row of R(q), i.e. R(q)^T x.

    Every hand-written (orientation, axis) pair of the reference satisfies it (PR2 identity -> x,
    HSRB (-1, 0, -1, 0) -> z); the later "first column" variant disagrees for asymmetric rotations.
    """
    r = quaternion_to_matrix(*q)
    row = r[0, :]
    row = np.where(np.abs(row) < 1e-12, 0.0, row)
    return (float(row[0]), float(row[1]), float(row[2]))


@dataclass(eq=False, repr=False)
class Manipulator(SemanticRobotAnnotation):
    """An end effector rooted at ``root`` with a ``tool_frame``."""

    tool_frame: Body = field(kw_only=True)
    front_facing_orientation: tuple[float, float, float, float] = field(
        default=(0.0, 0.0, 0.0, 1.0), kw_only=True
    )
    front_facing_axis: tuple[float, float, float] = field(default=(1.0, 0.0, 0.0), kw_only=True)
    states: dict[str, JointState] = field(default_factory=dict, kw_only=True)

    def __hash__(self) -> int:
        return hash((type(self).__name__, self.name, self.root.name, self.tool_frame.name))


@dataclass(eq=False, repr=False)
class ParallelGripper(Manipulator):
    """Two fingers; the thumb is the one that always touches the grasped object."""

    finger: Finger = field(kw_only=True)
    thumb: Finger = field(kw_only=True)


@dataclass(eq=False, repr=False)
class Hand(Manipulator):
    """A thumb and named fingers (at least one): a hand of more than a gripper's two fingers."""

    thumb: Finger = field(kw_only=True)
    fingers: dict[str, Finger] = field(kw_only=True)

    @property
    def all_fingers(self) -> tuple[Finger, ...]:
        """The thumb first, then the fingers in the spec's order."""
        return (self.thumb, *self.fingers.values())


@dataclass(eq=False, repr=False)
class GenericManipulator(Manipulator):
    """Any end effector without modelled fingers (suction cup, tool flange)."""
