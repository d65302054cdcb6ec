"""The Robot Raconteur enumerations a RobotInfo names (robdef stdver 0.10), read by name.

Why a module of its own: the enumerations are the robdef's vocabulary, shared by the RobotInfo
models (:mod:`robotspec.driver.robot_info`), the driver and the service; each is validated by
name with the closest valid names on a typo (``_enum_name``).
"""

from __future__ import annotations

from enum import StrEnum
from typing import Annotated, Any, TypeVar

from pydantic import BeforeValidator

from robotspec.errors import closest_names

__all__ = [
    "CAPABILITY_BITS",
    "DRIVABLE_JOINT_TYPES",
    "CapabilityName",
    "EffortUnitName",
    "JointEffortUnits",
    "JointPositionUnits",
    "JointType",
    "JointTypeName",
    "PositionUnitName",
    "RobotCapability",
    "RobotTypeCode",
    "RobotTypeName",
    "ToolCapability",
    "ToolCapabilityName",
    "ToolTypeCode",
    "ToolTypeName",
]


class RobotTypeCode(StrEnum):
    """``com.robotraconteur.robotics.robot.RobotTypeCode`` by name."""

    unknown = "unknown"
    serial = "serial"
    dual_arm = "dual_arm"
    differential_drive = "differential_drive"
    planar = "planar"
    floating = "floating"
    freeform = "freeform"
    other = "other"


class RobotCapability(StrEnum):
    """``RobotCapabilities`` flag names; the YAML lists names that are ORed into a bit set."""

    unknown = "unknown"
    jog_command = "jog_command"
    trajectory_command = "trajectory_command"
    position_command = "position_command"
    velocity_command = "velocity_command"
    homing_command = "homing_command"
    software_reset_errors = "software_reset_errors"
    software_enable = "software_enable"
    interpolated_trajectory = "interpolated_trajectory"
    raster_trajectory = "raster_trajectory"
    trajectory_queueing = "trajectory_queueing"
    speed_ratio = "speed_ratio"


#: The robdef bit of each capability, for reporting the ``uint32`` the reference serves.
CAPABILITY_BITS: dict[RobotCapability, int] = {
    c: (0 if i == 0 else 1 << (i - 1)) for i, c in enumerate(RobotCapability)
}


class JointType(StrEnum):
    """``com.robotraconteur.robotics.joints.JointType`` by name."""

    unknown = "unknown"
    revolute = "revolute"
    continuous = "continuous"
    prismatic = "prismatic"
    wheel = "wheel"
    screw = "screw"
    other = "other"
    revolute2 = "revolute2"
    universal = "universal"
    ball = "ball"
    planar = "planar"
    floating = "floating"
    other_compound = "other_compound"
    fixed = "fixed"


#: Joint types an H/P chain can drive (the toolbox conversion accepts no others).
DRIVABLE_JOINT_TYPES = frozenset({JointType.revolute, JointType.prismatic, JointType.continuous})


class JointPositionUnits(StrEnum):
    """``JointPositionUnits`` by name; informational, the driver works in radians and metres."""

    implicit = "implicit"
    meter = "meter"
    radian = "radian"
    degree = "degree"
    ticks_lin = "ticks_lin"
    ticks_rot = "ticks_rot"
    nanoticks_lin = "nanoticks_lin"
    nanoticks_rot = "nanoticks_rot"


class JointEffortUnits(StrEnum):
    """``JointEffortUnits`` by name; informational."""

    implicit = "implicit"
    newton = "newton"
    newton_meter = "newton_meter"
    ampere = "ampere"
    volt = "volt"
    pascal = "pascal"
    coulomb = "coulomb"
    tesla = "tesla"
    weber = "weber"
    meter_second2 = "meter_second2"
    radian_second2 = "radian_second2"
    degree_second2 = "degree_second2"


class ToolTypeCode(StrEnum):
    """``com.robotraconteur.robotics.tool.ToolTypeCode`` by name."""

    unknown = "unknown"
    basic_gripper = "basic_gripper"
    basic_continuous_gripper = "basic_continuous_gripper"
    pneumatic_gripper = "pneumatic_gripper"
    electric_gripper = "electric_gripper"
    vacuum_gripper = "vacuum_gripper"
    soft_gripper = "soft_gripper"
    welder = "welder"
    hand = "hand"
    palletizer = "palletizer"
    other = "other"


class ToolCapability(StrEnum):
    """``ToolCapabilities`` flag names."""

    unknown = "unknown"
    open_close_command = "open_close_command"
    continuous_command = "continuous_command"
    homing_command = "homing_command"
    software_reset_errors = "software_reset_errors"
    software_enable = "software_enable"
    sensor_feedback = "sensor_feedback"


_E = TypeVar("_E", bound=StrEnum)


def _enum_name(enum: type[_E], what: str) -> BeforeValidator:
    """A validator that refuses an unknown enum name with the closest valid names.

    Why: pydantic's own message lists every member; a user who wrote ``radians`` wants to read
    "did you mean 'radian'?".
    """
    names = [m.value for m in enum]

    def check(value: Any) -> Any:
        if isinstance(value, str) and value not in names:
            near = closest_names(value, names)
            hint = f"; did you mean '{near[0]}'?" if near else f"; valid: {', '.join(names)}"
            raise ValueError(f"unknown {what} '{value}'{hint}")
        return value

    return BeforeValidator(check)


RobotTypeName = Annotated[RobotTypeCode, _enum_name(RobotTypeCode, "robot_type")]
CapabilityName = Annotated[RobotCapability, _enum_name(RobotCapability, "robot capability")]
JointTypeName = Annotated[JointType, _enum_name(JointType, "joint_type")]
PositionUnitName = Annotated[JointPositionUnits, _enum_name(JointPositionUnits, "position unit")]
EffortUnitName = Annotated[JointEffortUnits, _enum_name(JointEffortUnits, "effort unit")]
ToolTypeName = Annotated[ToolTypeCode, _enum_name(ToolTypeCode, "tool_type")]
ToolCapabilityName = Annotated[ToolCapability, _enum_name(ToolCapability, "tool capability")]
