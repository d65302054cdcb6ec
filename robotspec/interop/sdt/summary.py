"""Any SDT robot (hand-written or bridged) as plain data, for comparing two robots part for part.

Why: the bridge's claim is parity with SDT's hand-written classes; a comparison needs both
robots in one vocabulary (names, tuples, floats), not SDT objects whose equality is identity.
The tests and the benchmark compare with it; a user can diff their own class against
``to_sdt``'s the same way.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

__all__ = ["PartSummary", "RobotSummary", "summarize"]

_KINDS = ("MobileBase", "Torso", "Neck", "Arm", "EndEffector", "Finger", "Camera", "Sensor")


@dataclass(frozen=True, order=True)
class PartSummary:
    """One part: its SDT kind and what names it; fields that do not apply are None."""

    kind: str
    root: str
    tip: str | None = None
    tool_frame: str | None = None
    thumb: str | None = None  # root body of the thumb (end effectors with fingers)
    fingers: tuple[str, ...] = ()  # root bodies of the other fingers
    axis: tuple[float, ...] | None = None  # front-facing (end effector) or forward (camera)
    field_of_view: tuple[float, float] | None = None  # (vertical, horizontal)
    heights: tuple[float, float] | None = None  # cameras: (minimal, maximal)
    default_camera: bool | None = None


@dataclass(frozen=True)
class RobotSummary:
    """The robot: parts (sorted), hardware-interface joints, velocity limits, sides."""

    parts: tuple[PartSummary, ...]
    hardware_joints: frozenset[str]
    velocity_limits: dict[str, float | None]
    left_arm: tuple[str, str] | None
    right_arm: tuple[str, str] | None
    joint_states: dict[str, dict[str, float]]


def _name(entity: Any) -> str | None:
    return None if entity is None else str(entity.name.name)


def _vector(v: Any) -> tuple[float, ...]:
    return tuple(round(float(x), 9) for x in v.to_np()[:3])


def _kind(part: Any) -> str:
    names = {c.__name__ for c in type(part).__mro__}
    return next(k for k in _KINDS if k in names)


def _part(part: Any) -> PartSummary:
    kind = _kind(part)
    fields: dict[str, Any] = {"kind": kind, "root": _name(part.root)}
    if hasattr(part, "tip"):
        fields["tip"] = _name(part.tip)
    if kind == "EndEffector":
        fields["tool_frame"] = _name(part.tool_frame)
        fields["axis"] = _vector(part.front_facing_axis)
        fingers = list(getattr(part, "fingers", []))
        if fingers:
            thumb = part.thumb
            fields["thumb"] = _name(thumb.root)
            fields["fingers"] = tuple(sorted(str(_name(f.root)) for f in fingers if f is not thumb))
    if kind == "Camera":
        fov = part.field_of_view
        fields["axis"] = _vector(part.forward_facing_axis)
        fields["field_of_view"] = (float(fov.vertical_angle), float(fov.horizontal_angle))
        fields["heights"] = (float(part.minimal_height), float(part.maximal_height))
        fields["default_camera"] = bool(part.default_camera)
    return PartSummary(**fields)


def _chain(arm: Any) -> tuple[str, str] | None:
    return None if arm is None else (str(_name(arm.root)), str(_name(arm.tip)))


def summarize(robot: Any) -> RobotSummary:
    """``robot`` (an SDT ``AbstractRobot``) as a :class:`RobotSummary`."""
    parts = tuple(sorted(_part(p) for p in robot._robot_parts))
    hardware = frozenset(str(_name(c)) for c in robot.controlled_connections)
    limits = {str(_name(c)): c.raw_dof.limits.upper.velocity for c in robot._one_dof_connections}
    states = {
        f"{_kind(p)}:{_name(p.root)}:{_name(getattr(p, 'tip', None))}:{s.state_type.name}": {
            str(_name(c)): float(v) for c, v in zip(s.connections, s.target_values, strict=True)
        }
        for p in robot._robot_parts
        for s in p.joint_states
    }
    return RobotSummary(
        parts=parts,
        hardware_joints=hardware,
        velocity_limits=limits,
        left_arm=_chain(robot.get_left_arm_if_specified()),
        right_arm=_chain(robot.get_right_arm_if_specified()),
        joint_states=states,
    )
