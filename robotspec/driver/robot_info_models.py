"""The Robot Raconteur ``RobotInfo`` models: strict, immutable, one per robdef structure.

Why a module of its own: the models check one field at a time (unknown keys, enum names, unit
quaternions, finite numbers); reading a file, locating its problems and the cross-field checks
are :mod:`robotspec.driver.robot_info` and :mod:`robotspec.driver.robot_info_checks`, which
both build on these.
"""

from __future__ import annotations

import math
from typing import Any
from uuid import UUID

from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    field_validator,
    model_validator,
)

from robotspec.driver.robot_info_enums import (
    CAPABILITY_BITS,
    CapabilityName,
    EffortUnitName,
    JointEffortUnits,
    JointPositionUnits,
    JointType,
    JointTypeName,
    PositionUnitName,
    RobotCapability,
    RobotTypeCode,
    RobotTypeName,
    ToolCapabilityName,
    ToolTypeCode,
    ToolTypeName,
)

__all__ = [
    "MAX_LIMIT",
    "QUAT_TOL",
    "DeviceClass",
    "DeviceInfo",
    "Identifier",
    "JointInfo",
    "JointLimits",
    "KinChainInfo",
    "NamedPose",
    "PayloadInfo",
    "Pose",
    "Quaternion",
    "RobotInfo",
    "SpatialInertia",
    "SpatialVector",
    "ToolInfo",
    "Transform",
    "Vector3",
]

#: Quaternions must be unit length to this tolerance (real files carry 6-digit rounding).
QUAT_TOL = 1e-4
#: Largest magnitude of a joint limit value (position, velocity, acceleration, ...), for the same
#: reason: the braking arithmetic squares ``acceleration * period``.
MAX_LIMIT = 1e9


class _Model(BaseModel):
    """Base of every RobotInfo model: unknown keys are errors, instances are immutable.

    NaN and infinity are refused in every float field (``allow_inf_nan=False``): a NaN in an axis,
    an offset or a flange quaternion would otherwise load and be published as NaN poses.
    """

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


class Identifier(_Model):
    """A name with an optional UUID; the YAML may give a plain string (a name with no UUID)."""

    name: str = ""
    uuid: UUID | None = None

    @model_validator(mode="before")
    @classmethod
    def _from_string(cls, value: Any) -> Any:
        # Why: the reference accepts ``device: abb_robot`` as shorthand for ``{name: abb_robot}``.
        if isinstance(value, str):
            return {"name": value}
        return value


class Vector3(_Model):
    """``{x, y, z}``; every component is required, as in the reference named-array parser."""

    x: float
    y: float
    z: float

    def as_tuple(self) -> tuple[float, float, float]:
        """The components as a tuple, for numpy."""
        return (self.x, self.y, self.z)


class Quaternion(_Model):
    """``{w, x, y, z}``; must be unit length (the reference silently uses zero as identity)."""

    w: float
    x: float
    y: float
    z: float

    @model_validator(mode="after")
    def _unit(self) -> Quaternion:
        # hypot: a component of 1e200 gives a norm of 1e200, not an OverflowError from ``**``.
        norm = math.hypot(self.w, self.x, self.y, self.z)
        if abs(norm - 1.0) > QUAT_TOL:
            raise ValueError(f"quaternion must have unit norm (norm is {norm:.6g})")
        return self

    def as_tuple(self) -> tuple[float, float, float, float]:
        """``(w, x, y, z)``."""
        return (self.w, self.x, self.y, self.z)


class Pose(_Model):
    """A pose as the geometry robdef names it: ``orientation`` then ``position``."""

    orientation: Quaternion = Field(default_factory=lambda: Quaternion(w=1.0, x=0.0, y=0.0, z=0.0))
    position: Vector3 = Field(default_factory=lambda: Vector3(x=0.0, y=0.0, z=0.0))


class Transform(_Model):
    """A transform as the geometry robdef names it: ``rotation`` then ``translation``."""

    rotation: Quaternion = Field(default_factory=lambda: Quaternion(w=1.0, x=0.0, y=0.0, z=0.0))
    translation: Vector3 = Field(default_factory=lambda: Vector3(x=0.0, y=0.0, z=0.0))


class NamedPose(_Model):
    """``NamedPose``: a pose with optional frame names (device_origin_pose)."""

    parent_frame: Identifier | None = None
    frame: Identifier | None = None
    pose: Pose


class SpatialInertia(_Model):
    """A link or tool inertia: mass, centre of mass and inertia tensor entries."""

    m: float
    com: Vector3
    ixx: float
    ixy: float
    ixz: float
    iyy: float
    iyz: float
    izz: float


class SpatialVector(_Model):
    """``SpatialVelocity`` / ``SpatialAcceleration``: angular and linear parts."""

    angular: Vector3
    linear: Vector3


class DeviceClass(_Model):
    """One ``device_classes`` entry."""

    class_identifier: Identifier
    subclasses: tuple[str, ...] = ()


class DeviceInfo(_Model):
    """``com.robotraconteur.device.DeviceInfo``."""

    device: Identifier = Field(default_factory=Identifier)
    parent_device: Identifier | None = None
    manufacturer: Identifier | None = None
    model: Identifier | None = None
    options: tuple[Any, ...] = ()
    capabilities: tuple[Any, ...] = ()
    serial_number: str = ""
    device_classes: tuple[DeviceClass, ...] = ()
    user_description: str = ""
    description_resource: Any = None
    implemented_types: tuple[str, ...] = ()
    device_origin_pose: NamedPose | None = None
    associated_devices: dict[str, Any] = Field(default_factory=dict)
    tags: tuple[Identifier, ...] = ()
    extended: dict[str, Any] = Field(default_factory=dict)

    @field_validator("serial_number", mode="before")
    @classmethod
    def _serial_as_text(cls, value: Any) -> Any:
        # Why: real files write ``serial_number: 123456789``, which YAML reads as an int.
        if isinstance(value, int) and not isinstance(value, bool):
            return str(value)
        return value


class JointLimits(_Model):
    """Joint limits in radians (metres) and per second; velocity and acceleration must be > 0."""

    lower: float = 0.0
    upper: float = 0.0
    home: float = 0.0
    velocity: float = Field(gt=0.0)
    acceleration: float = Field(gt=0.0)
    jerk: float = 0.0
    effort: float = 0.0
    reduced_velocity: float = 0.0
    reduced_acceleration: float = 0.0
    reduced_jerk: float = 0.0
    reduced_effort: float = 0.0

    @field_validator("*", mode="after")
    @classmethod
    def _finite(cls, value: float) -> float:
        if not math.isfinite(value):
            raise ValueError("must be a finite number")
        if abs(value) > MAX_LIMIT:
            raise ValueError(f"must be within +-{MAX_LIMIT:g}")
        return value

    @model_validator(mode="after")
    def _ordered(self) -> JointLimits:
        if self.lower > self.upper:
            raise ValueError(f"lower limit {self.lower} is above upper limit {self.upper}")
        return self


class JointInfo(_Model):
    """One joint: name, type, limits and units."""

    joint_identifier: Identifier
    joint_type: JointTypeName = JointType.revolute
    joint_limits: JointLimits
    default_units: PositionUnitName = JointPositionUnits.radian
    default_effort_units: EffortUnitName = JointEffortUnits.newton_meter
    passive: bool = False
    extended: dict[str, Any] = Field(default_factory=dict)


class ToolInfo(_Model):
    """``com.robotraconteur.robotics.tool.ToolInfo``; ``tcp`` is the flange-to-TCP transform."""

    device_info: DeviceInfo = Field(default_factory=DeviceInfo)
    tool_type: ToolTypeName = ToolTypeCode.unknown
    tool_capabilities: tuple[ToolCapabilityName, ...] = ()
    tcp: Transform = Field(default_factory=Transform)
    inertia: SpatialInertia | None = None
    fiducials: tuple[Any, ...] = ()
    actuation_time: float = 0.0
    close_position: float = 0.0
    open_position: float = 0.0
    command_min: float = 0.0
    command_max: float = 0.0
    command_close: float = 0.0
    command_open: float = 0.0
    sensor_type: tuple[Any, ...] = ()
    sensor_min: tuple[float, ...] = ()
    sensor_max: tuple[float, ...] = ()
    sensor_units: tuple[Any, ...] = ()
    extended: dict[str, Any] = Field(default_factory=dict)

    @property
    def name(self) -> str:
        """The tool's device name (what tool_changed events report)."""
        return self.device_info.device.name


class PayloadInfo(_Model):
    """``com.robotraconteur.robotics.payload.PayloadInfo``."""

    device_info: DeviceInfo = Field(default_factory=DeviceInfo)
    inertia: SpatialInertia | None = None
    fiducials: tuple[Any, ...] = ()
    extended: dict[str, Any] = Field(default_factory=dict)

    @property
    def name(self) -> str:
        """The payload's device name (what payload_changed events report)."""
        return self.device_info.device.name


class KinChainInfo(_Model):
    """One kinematic chain in H/P form (axes and offsets in the base frame at q = 0)."""

    kin_chain_identifier: Identifier = Field(default_factory=Identifier)
    H: tuple[Vector3, ...]
    P: tuple[Vector3, ...]
    link_inertias: tuple[SpatialInertia, ...] = ()
    link_identifiers: tuple[Identifier, ...] = ()
    link_fiducials: tuple[Any, ...] = ()
    joint_numbers: tuple[int, ...]
    flange_pose: Pose | None = None
    flange_identifier: Identifier | None = None
    current_tool: ToolInfo | None = None
    current_payload: PayloadInfo | None = None
    tcp_max_velocity: SpatialVector | None = None
    tcp_max_acceleration: SpatialVector | None = None
    tcp_reduced_max_velocity: SpatialVector | None = None
    tcp_reduced_max_acceleration: SpatialVector | None = None
    description: str = ""
    extended: dict[str, Any] = Field(default_factory=dict)

    @field_validator("joint_numbers")
    @classmethod
    def _increasing(cls, value: tuple[int, ...]) -> tuple[int, ...]:
        if not value:
            raise ValueError("a chain needs at least one joint")
        for a, b in zip(value, value[1:], strict=False):
            if b <= a:
                raise ValueError(f"joint_numbers must be strictly increasing ({a} then {b})")
        if value[0] < 0:
            raise ValueError("joint_numbers must not be negative")
        return value

    @property
    def name(self) -> str:
        """The chain's name (``kin_chain_identifier``)."""
        return self.kin_chain_identifier.name


class RobotInfo(_Model):
    """``com.robotraconteur.robotics.robot.RobotInfo``."""

    device_info: DeviceInfo
    robot_type: RobotTypeName = RobotTypeCode.unknown
    joint_info: tuple[JointInfo, ...]
    chains: tuple[KinChainInfo, ...]
    robot_capabilities: tuple[CapabilityName, ...] = ()
    signal_info: tuple[Any, ...] = ()
    parameter_info: tuple[Any, ...] = ()
    config_seqno: int = Field(default=0, ge=0, le=65535)
    trajectory_interpolation_modes: tuple[Any, ...] = ()
    extended: dict[str, Any] = Field(default_factory=dict)

    @property
    def joint_names(self) -> tuple[str, ...]:
        """Joint names in global joint order."""
        return tuple(j.joint_identifier.name for j in self.joint_info)

    @property
    def capability_bits(self) -> int:
        """The ``robot_capabilities`` bit set the reference would serve."""
        bits = 0
        for c in self.robot_capabilities:
            bits |= CAPABILITY_BITS[c]
        return bits

    def has(self, capability: RobotCapability) -> bool:
        """Whether the robot declares ``capability``."""
        return capability in self.robot_capabilities
