"""What every semantic part shares: a name, a root body, a world, and one owning robot.

Why views: a part holds the world and the bodies it names, and derives everything else (chain
bodies, connections, DOFs) from the world on demand, so the world stays the single source of
truth. A part belongs to at most one robot (the seed's ``assign_to_robot`` rule).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from robotspec.errors import RobotSpecError
from robotspec.model.world import Body, World

if TYPE_CHECKING:
    from robotspec.semantic.robot import AbstractRobot

__all__ = ["AssignmentError", "JointState", "SemanticRobotAnnotation"]


class AssignmentError(RobotSpecError, ValueError):
    """A part was attached to a second robot, or a unique part was added twice.

    Also a ValueError, as in the reference, so callers written against it keep working.
    """


@dataclass(frozen=True)
class JointState:
    """A named configuration of some joints (park, open, close, torso low/mid/high).

    ``joints`` keeps the order the spec wrote; values are in the joints' units (rad or m).
    """

    name: str
    part: str
    joints: tuple[tuple[str, float], ...]

    def as_dict(self) -> dict[str, float]:
        """Joint name to value."""
        return dict(self.joints)


@dataclass(eq=False)
class SemanticRobotAnnotation:
    """A semantic part rooted at a body of the world (the seed's ``SemanticRobotAnnotation``)."""

    name: str
    root: Body
    world: World = field(repr=False)
    _robot: AbstractRobot | None = field(default=None, init=False, repr=False)

    def __post_init__(self) -> None:
        self.world.add_semantic_annotation(self)

    @property
    def _world(self) -> World:
        """The seed's name for the world back-reference."""
        return self.world

    @property
    def robot(self) -> AbstractRobot | None:
        """The robot this part belongs to, once assigned."""
        return self._robot

    def assign_to_robot(self, robot: AbstractRobot) -> None:
        """Attach to ``robot``; idempotent for the same robot, refused for another."""
        if self._robot is robot:
            return
        if self._robot is not None:
            raise AssignmentError(
                f"{type(self).__name__} '{self.name}' already belongs to robot "
                f"'{self._robot.name}'; it cannot be added to '{robot.name}'",
                name=self.name,
            )
        self._robot = robot

    def __hash__(self) -> int:
        return hash((type(self).__name__, self.name, self.root.name))

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.name!r}, root={self.root.name!r})"
