"""The Robot Raconteur ``RobotInfo`` YAML, as strict, located Pydantic models.

Why strict: the reference parser (Robot Raconteur Companion ``InfoParser``) silently ignores unknown
keys, so a misspelt ``acceleraton`` leaves the acceleration at 0 and fails much later with a bare
assertion. Here every model forbids extra keys, enums are checked by name, array lengths are checked
against the chain's joint count, and every problem is a :class:`~robotspec.errors.RobotInfoError`
with the file and line of the offending YAML node (through
:func:`robotspec.files.yamlio.load_yaml`).

The field names are the robdef field names (stdver 0.10), so any file the reference accepts and that
has no typos loads here too. Loading never writes anywhere: unlike the reference ``InfoFileLoader``
no device UUID is assigned or persisted, and no lock file is taken.

Things the reference accepts that are only *warnings* here (so all real files still load): a chain
without ``flange_pose`` (identity is used, as the reference does silently) and ``continuous`` joints
(driven as revolute).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import StrEnum
from pathlib import Path
from typing import Annotated, Any, TypeVar
from uuid import UUID

from pydantic import (
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    ValidationError,
    field_validator,
    model_validator,
)

from robotspec.driver.rr_names import rr_name_problem, rr_name_suggestion
from robotspec.errors import RobotInfoError, RobotSpecErrors, closest_names
from robotspec.files.validation import validation_errors
from robotspec.files.yamlio import LocatedYaml, load_yaml, load_yaml_text

__all__ = [
    "CAPABILITY_BITS",
    "DeviceInfo",
    "Identifier",
    "JointEffortUnits",
    "JointInfo",
    "JointLimits",
    "JointPositionUnits",
    "JointType",
    "KinChainInfo",
    "LoadedRobotInfo",
    "PayloadInfo",
    "Pose",
    "Quaternion",
    "RobotCapability",
    "RobotInfo",
    "RobotTypeCode",
    "ToolInfo",
    "Transform",
    "Vector3",
    "load_robot_info",
    "read_robot_info",
    "read_robot_info_text",
]

#: Axis vectors must be unit length to this tolerance (the toolbox asserts the same).
UNIT_TOL = 1e-6
#: Quaternions must be unit length to this tolerance (real files carry 6-digit rounding).
QUAT_TOL = 1e-4
#: Largest magnitude of a link offset or flange position, metres. Why a bound: finite but absurd
#: values (1e200) make the pose and twist arithmetic overflow to infinity in the loop.
MAX_OFFSET_M = 1e3
#: Largest magnitude of a joint limit value (position, velocity, acceleration, ...), for the same
#: reason: the braking arithmetic squares ``acceleration * period``.
MAX_LIMIT = 1e9


class _Model(BaseModel):
    """Base of every RobotInfo model: unknown keys are errors, instances are immutable.

    NaN and infinity are refused in every float field (``allow_inf_nan=False``): a NaN in an axis,
    an offset or a flange quaternion would otherwise load and be published as NaN poses.
    """

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


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


@dataclass(frozen=True)
class LoadedRobotInfo:
    """A validated RobotInfo, the file it came from and the warnings found while loading."""

    info: RobotInfo
    file: str
    warnings: tuple[RobotInfoError, ...] = ()


def _semantic_checks(
    info: RobotInfo, doc: LocatedYaml
) -> tuple[list[RobotInfoError], list[RobotInfoError]]:
    """Cross-field checks pydantic cannot locate well: array lengths and joint references."""
    errors: list[RobotInfoError] = []
    warnings: list[RobotInfoError] = []
    n_joints = len(info.joint_info)

    def err(msg: str, loc: tuple[str | int, ...], *, warn: bool = False) -> None:
        # Point at the key when the problem is the whole value (a list of the wrong length).
        line, col = doc.key_position(loc) if isinstance(loc[-1], str) else doc.position(loc)
        e = RobotInfoError(
            msg,
            file=doc.file,
            line=line,
            column=col,
            location=loc,
            severity="warning" if warn else "error",
        )
        (warnings if warn else errors).append(e)

    device = info.device_info.device
    name_problem = rr_name_problem(device.name) if device.name else None
    if name_problem and device.uuid is None:
        # Served, the device name becomes the node name and its identifier's lock file.
        err(
            f"device_info.device.name '{device.name}' {name_problem}: Robot Raconteur cannot "
            "use it as a device name (letters, digits, '_', '.' and '-', starting with a "
            f"letter); did you mean '{rr_name_suggestion(device.name)}'?",
            ("device_info", "device", "name"),
        )
    if not info.joint_info:
        err("joint_info must list at least one joint", ("joint_info",))
    if not info.chains:
        err("chains must list at least one kinematic chain", ("chains",))
    seen_names: dict[str, int] = {}
    for i, j in enumerate(info.joint_info):
        name = j.joint_identifier.name
        loc: tuple[str | int, ...] = ("joint_info", i, "joint_identifier")
        if not name:
            err(f"joint_info[{i}]: joint_identifier needs a name", loc)
        elif name in seen_names:
            err(f"joint_info[{i}]: joint name '{name}' repeats joint_info[{seen_names[name]}]", loc)
        else:
            seen_names[name] = i
        if j.joint_type not in DRIVABLE_JOINT_TYPES:
            err(
                f"joint_info[{i}]: joint_type '{j.joint_type.value}' cannot be driven "
                "(only revolute, prismatic or continuous)",
                ("joint_info", i, "joint_type"),
            )
        elif j.joint_type is JointType.continuous:
            err(
                f"joint_info[{i}]: joint_type 'continuous' is driven as revolute within its limits "
                "(the reference refuses it)",
                ("joint_info", i, "joint_type"),
                warn=True,
            )
    used: dict[int, int] = {}
    for c, chain in enumerate(info.chains):
        n = len(chain.joint_numbers)
        where = f"chains[{c}]"
        for i, h in enumerate(chain.H):
            norm = math.hypot(h.x, h.y, h.z)  # no OverflowError for 1e200
            if abs(norm - 1.0) > UNIT_TOL:
                err(
                    f"{where}.H[{i}] must be a unit vector (norm is {norm:.6g})",
                    ("chains", c, "H", i),
                )
        offsets: list[tuple[str, tuple[str | int, ...], Vector3]] = [
            (f"P[{i}]", ("chains", c, "P", i), p) for i, p in enumerate(chain.P)
        ]
        if chain.flange_pose is not None:
            loc_f: tuple[str | int, ...] = ("chains", c, "flange_pose", "position")
            offsets.append(("flange_pose.position", loc_f, chain.flange_pose.position))
        for label, loc_p, p in offsets:
            big = max(abs(p.x), abs(p.y), abs(p.z))
            if big > MAX_OFFSET_M:
                err(f"{where}.{label} is {big:g} m from its frame (max {MAX_OFFSET_M:g})", loc_p)
        if len(chain.H) != n:
            err(
                f"{where}.H has {len(chain.H)} axes but the chain has {n} joints (joint_numbers)",
                ("chains", c, "H"),
            )
        if len(chain.P) != n + 1:
            err(
                f"{where}.P has {len(chain.P)} vectors but needs {n + 1} (one more than joints)",
                ("chains", c, "P"),
            )
        if chain.link_identifiers and len(chain.link_identifiers) != n + 1:
            err(
                f"{where}.link_identifiers has {len(chain.link_identifiers)} names "
                f"but needs {n + 1}",
                ("chains", c, "link_identifiers"),
            )
        if chain.link_inertias and len(chain.link_inertias) != n + 1:
            err(
                f"{where}.link_inertias has {len(chain.link_inertias)} entries but needs {n + 1}",
                ("chains", c, "link_inertias"),
            )
        for k, jn in enumerate(chain.joint_numbers):
            if jn >= n_joints:
                err(
                    f"{where}.joint_numbers[{k}] names joint {jn}, but joint_info has only "
                    f"{n_joints} joints (0..{n_joints - 1})",
                    ("chains", c, "joint_numbers", k),
                )
            elif jn in used:
                err(
                    f"{where}.joint_numbers[{k}]: joint {jn} already belongs to chains[{used[jn]}]",
                    ("chains", c, "joint_numbers", k),
                )
            else:
                used[jn] = c
        if chain.flange_pose is None:
            err(
                f"{where} has no flange_pose; the identity is used (the reference does the same "
                "silently)",
                ("chains", c),
                warn=True,
            )
        if chain.current_payload is not None and chain.current_tool is None:
            err(f"{where}.current_payload needs a current_tool", ("chains", c, "current_payload"))
    return errors, warnings


def _read(doc: LocatedYaml) -> LoadedRobotInfo:
    if not isinstance(doc.data, dict):
        raise RobotInfoError("a RobotInfo file must be a YAML mapping", file=doc.file, line=1)
    try:
        info = RobotInfo.model_validate(doc.data)
    except ValidationError as exc:
        raise validation_errors(exc, doc, RobotInfo, RobotInfoError) from None
    errors, warnings = _semantic_checks(info, doc)
    if errors:
        if len(errors) == 1:
            raise errors[0]
        raise RobotSpecErrors(errors, summary=f"{doc.file}: {len(errors)} problems")
    return LoadedRobotInfo(info=info, file=doc.file, warnings=tuple(warnings))


def read_robot_info(path: str | Path) -> LoadedRobotInfo:
    """Load and validate a RobotInfo YAML file, keeping the warnings.

    Raises:
        RobotInfoError: one located problem.
        RobotSpecErrors: several, all reported at once.
    """
    doc = load_yaml(path)
    return _read(doc)


def read_robot_info_text(text: str, file: str = "<string>") -> LoadedRobotInfo:
    """Like :func:`read_robot_info`, from text (tests, generated files)."""
    return _read(load_yaml_text(text, file=file))


def load_robot_info(path: str | Path) -> RobotInfo:
    """Load and validate a RobotInfo YAML file; warnings are dropped (see ``read_robot_info``)."""
    return read_robot_info(path).info
