"""Sensors: a body that perceives; cameras add a viewing axis, a field of view and heights."""

from __future__ import annotations

from dataclasses import dataclass, field

from robotspec.semantic.base import SemanticRobotAnnotation

__all__ = ["Camera", "FieldOfView", "GenericSensor", "Sensor"]


@dataclass(eq=False, repr=False)
class Sensor(SemanticRobotAnnotation):
    """A perceptual device mounted on ``root``."""

    def __hash__(self) -> int:
        return hash((type(self).__name__, self.name, self.root.name))


@dataclass(frozen=True)
class FieldOfView:
    """Opening angles in radians."""

    vertical_angle: float
    horizontal_angle: float


@dataclass(eq=False, repr=False)
class Camera(Sensor):
    """A camera looking along ``forward_facing_axis`` of its body (+z on optical frames)."""

    forward_facing_axis: tuple[float, float, float] = field(default=(0.0, 0.0, 1.0), kw_only=True)
    field_of_view: FieldOfView = field(
        default_factory=lambda: FieldOfView(0.75049, 0.99483), kw_only=True
    )
    minimal_height: float = field(default=0.0, kw_only=True)
    maximal_height: float = field(default=1.0, kw_only=True)
    default_camera: bool = field(default=False, kw_only=True)


@dataclass(eq=False, repr=False)
class GenericSensor(Sensor):
    """Any other sensor (lidar, force-torque, ...); ``kind`` is free-form."""

    kind: str | None = field(default=None, kw_only=True)
