"""The robot spec: a robot's semantics as a short YAML file, validated by Pydantic models.

Why mappings keyed by name (``chains: {left_arm: ...}``) rather than lists: names are the
identity of parts, YAML refuses duplicate keys, and ``extends:`` can override one part of a base
spec by naming it. Every model forbids unknown keys and is frozen; positions of every node are
kept (``yamlio``) so the compiler can report ``file:line:col`` for any name it cannot resolve.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Annotated, Literal

from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    field_validator,
    model_validator,
)

from robotspec.errors import SpecError

if TYPE_CHECKING:
    from robotspec.model.geometry import Matrix

__all__ = [
    "AttachSpec",
    "CameraSpec",
    "ChainSpec",
    "CollisionSpec",
    "DescriptionSpec",
    "DriveSpec",
    "FieldOfViewSpec",
    "FingerSpec",
    "FrameSpec",
    "GenericManipulatorSpec",
    "GenericSensorSpec",
    "NeckSpec",
    "ParallelGripperSpec",
    "PartSpec",
    "RobotSpec",
    "SPEC_VERSION",
    "TorsoSpec",
    "VelocityLimitsSpec",
]

SPEC_VERSION = 1

Name = Annotated[str, Field(min_length=1, max_length=256)]
JointValues = dict[Name, float]
States = dict[Name, JointValues]


def _finite(values: tuple[float, ...]) -> tuple[float, ...]:
    if not all(math.isfinite(v) for v in values):
        raise ValueError("values must be finite numbers")
    return values


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, populate_by_name=True)


class FrameSpec(_Model):
    """A frame the URDF lacks, fixed to ``parent`` (HSRB's ``hand_gripper_tool_frame``)."""

    parent: Name
    xyz: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rpy: tuple[float, float, float] | None = None
    quaternion: tuple[float, float, float, float] | None = Field(
        default=None, description="[x, y, z, w]; give rpy or quaternion, not both"
    )

    _check_xyz = field_validator("xyz", "rpy", "quaternion")(
        lambda v: v if v is None else _finite(v)
    )

    def pose(self) -> Matrix:
        """The frame's pose in its parent (quaternion if given, else rpy, else identity)."""
        return _pose(self.xyz, self.rpy, self.quaternion)


def _pose(
    xyz: tuple[float, float, float],
    rpy: tuple[float, float, float] | None,
    quaternion: tuple[float, float, float, float] | None,
) -> Matrix:
    # Imported here: reading and validating a spec needs no numpy (the CLI starts faster).
    from robotspec.model.geometry import pose_from_xyz_quaternion, pose_from_xyz_rpy

    if quaternion is not None:
        return pose_from_xyz_quaternion(xyz, quaternion)
    return pose_from_xyz_rpy(xyz, rpy or (0.0, 0.0, 0.0))


class DescriptionSpec(_Model):
    """Where the robot's files are: paths relative to the spec, absolute, or ``package://``."""

    urdf: Name = Field(description="URDF or xacro file")
    srdf: Name | None = Field(default=None, description="MoveIt SRDF (optional)")
    xacro_args: dict[Name, str] = Field(default_factory=dict)
    package_paths: list[Name] = Field(
        default_factory=list, description="extra folders to search for ROS packages"
    )
    frames: dict[Name, FrameSpec] = Field(default_factory=dict)


class AttachSpec(_Model):
    """Where a part is welded: a link of an earlier part, and the pose of the part's root there.

    Names here are the parent part's own names (before its prefix), so renaming a part never
    breaks the parts attached to it.
    """

    part: Name = Field(description="the part this one is attached to")
    link: Name = Field(description="a link of that part, in its own (unprefixed) names")
    xyz: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rpy: tuple[float, float, float] | None = None
    quaternion: tuple[float, float, float, float] | None = Field(
        default=None, description="[x, y, z, w]; give rpy or quaternion, not both"
    )
    joint: Name | None = Field(
        default=None, description="name of the fixed joint (default: '<part>_weld')"
    )
    replace_root: bool = Field(
        default=False,
        description="drop the part's root link: its children (and its geometry) move onto "
        "'link', e.g. an arm's 'world' or a hand's mounting plate",
    )

    _check = field_validator("xyz", "rpy", "quaternion")(lambda v: v if v is None else _finite(v))

    def pose(self) -> Matrix:
        """The pose of the part's root link in ``link``."""
        return _pose(self.xyz, self.rpy, self.quaternion)


class PartSpec(_Model):
    """One part of a composed robot: a description (URDF/xacro or a spec) and where it is welded."""

    spec: Name | None = Field(
        default=None, description="another spec (a path or a shipped robot's name)"
    )
    urdf: Name | None = Field(default=None, description="URDF or xacro file (without a spec)")
    srdf: Name | None = Field(default=None, description="its SRDF (with urdf only)")
    xacro_args: dict[Name, str] = Field(default_factory=dict)
    package_paths: list[Name] = Field(default_factory=list)
    prefix: str = Field(
        default="",
        max_length=128,
        pattern=r"^[A-Za-z0-9_./-]*$",
        description="put before every link, joint, group, state and part name of this part",
    )
    attach: AttachSpec | None = Field(
        default=None, description="where the part is welded; the one part without it is the base"
    )

    @model_validator(mode="after")
    def _one_source(self) -> PartSpec:
        if (self.spec is None) == (self.urdf is None):
            raise ValueError("a part needs either 'spec' or 'urdf' (not both)")
        if self.spec is not None and (self.srdf or self.xacro_args or self.package_paths):
            raise ValueError(
                "'srdf', 'xacro_args' and 'package_paths' belong in the part's own spec"
            )
        return self


class DriveSpec(_Model):
    """How the base moves; by default taken from the SRDF's virtual joint."""

    type: Literal["omni", "differential", "fixed", "floating"]
    joint: Name | None = Field(default=None, description="name of the base connection")
    parent_frame: Name = Field(default="odom", description="the frame the base moves in")


class FingerSpec(_Model):
    """A finger as a chain from ``root`` to ``tip``."""

    root: Name
    tip: Name


class _ManipulatorBase(_Model):
    root: Name
    tool_frame: Name
    front_facing_orientation: tuple[float, float, float, float] = Field(
        default=(0.0, 0.0, 0.0, 1.0),
        description="tool-frame orientation of a front grasp, quaternion [x, y, z, w]",
    )
    front_facing_axis: tuple[float, float, float] | None = Field(
        default=None, description="derived from the orientation (R^T x) when omitted"
    )
    states: States = Field(default_factory=dict)

    _check = field_validator("front_facing_orientation", "front_facing_axis")(
        lambda v: v if v is None else _finite(v)
    )


class ParallelGripperSpec(_ManipulatorBase):
    """A two-finger gripper; the thumb is the finger that always touches the object."""

    type: Literal["parallel_gripper"]
    finger: FingerSpec
    thumb: FingerSpec


class GenericManipulatorSpec(_ManipulatorBase):
    """Any other end effector: a tool frame and an orientation."""

    type: Literal["generic"]


ManipulatorSpec = Annotated[
    ParallelGripperSpec | GenericManipulatorSpec, Field(discriminator="type")
]


class FieldOfViewSpec(_Model):
    """Angles in radians."""

    horizontal: float
    vertical: float


class CameraSpec(_Model):
    """A camera on ``body``; fields missing here are taken from ``preset`` (templates)."""

    type: Literal["camera"]
    body: Name
    preset: Name | None = Field(default=None, description="a camera model from templates/")
    forward_facing_axis: tuple[float, float, float] | None = None
    field_of_view: FieldOfViewSpec | None = None
    minimal_height: float | None = None
    maximal_height: float | None = None
    default: bool = Field(default=False, description="the robot's default camera")


class GenericSensorSpec(_Model):
    """Any other sensor attached to a body."""

    type: Literal["generic"]
    body: Name
    kind: Name | None = Field(default=None, description="free-form, e.g. 'lidar' or 'ft'")


SensorSpec = Annotated[CameraSpec | GenericSensorSpec, Field(discriminator="type")]


class ChainSpec(_Model):
    """A kinematic chain, by ``root``/``tip`` or by SRDF ``group`` name."""

    kind: Literal["arm", "chain"] = "arm"
    root: Name | None = None
    tip: Name | None = None
    group: Name | None = Field(default=None, description="an SRDF group with one chain")
    manipulator: Name | None = None
    sensors: list[Name] = Field(default_factory=list)
    states: States = Field(default_factory=dict)


class TorsoSpec(_Model):
    """The chain that connects the base to the other chains."""

    root: Name
    tip: Name
    states: States = Field(default_factory=dict)


class NeckSpec(_Model):
    """The chain carrying the head sensors; pitch and yaw bodies are optional."""

    root: Name
    tip: Name
    pitch_body: Name | None = None
    yaw_body: Name | None = None
    sensors: list[Name] = Field(default_factory=list)
    states: States = Field(default_factory=dict)


class VelocityLimitsSpec(_Model):
    """Velocity caps (rad/s or m/s); they only tighten the URDF's limits, of the robot's joints."""

    default: float | None = Field(default=None, gt=0)
    joints: dict[Name, Annotated[float, Field(gt=0)]] = Field(default_factory=dict)


class CollisionSpec(_Model):
    """Self-collision configuration (the seed's ``default_collision_config``)."""

    buffer_distance: float = Field(default=0.05, ge=0)
    violated_distance: float = Field(default=0.0, ge=0)
    disabled_bodies: list[Name] = Field(default_factory=list)
    use_srdf: bool = Field(default=True, description="apply the SRDF's disabled pairs")


class RobotSpec(_Model):
    """A robot: its files, its root, and its semantic parts."""

    robotspec: Literal[1] = Field(default=1, description="spec format version")
    name: Name
    extends: Name | None = Field(default=None, description="a base spec this one modifies")
    description: DescriptionSpec | None = Field(
        default=None, description="the robot's files; a composed robot gives 'parts' instead"
    )
    parts: dict[Name, PartSpec] = Field(
        default_factory=dict, description="a robot assembled from parts welded together"
    )
    root: Name | None = Field(
        default=None, description="the robot's root link (composed robots: the base part's)"
    )
    drive: DriveSpec | None = None
    torso: TorsoSpec | None = None
    neck: NeckSpec | None = None
    chains: dict[Name, ChainSpec] = Field(default_factory=dict)
    manipulators: dict[Name, ManipulatorSpec] = Field(default_factory=dict)
    sensors: dict[Name, SensorSpec] = Field(default_factory=dict)
    velocity_limits: VelocityLimitsSpec = Field(default_factory=VelocityLimitsSpec)
    controlled_joints: list[Name] | None = Field(
        default=None, description="default: every actuated, non-mimic joint of the robot"
    )
    collision: CollisionSpec = Field(default_factory=CollisionSpec)
    import_srdf_group_states: bool = Field(
        default=False, description="add the SRDF's group states as named joint states"
    )
    states: States = Field(default_factory=dict, description="robot-level named joint states")

    @model_validator(mode="after")
    def _description_or_parts(self) -> RobotSpec:
        if self.description is None and not self.parts:
            raise ValueError("a spec needs 'description' (its files) or 'parts' (a composed robot)")
        if self.description is not None and self.parts:
            if self.extends is not None:
                raise ValueError(
                    f"'{self.extends}' has a description, so parts cannot be added to it; make "
                    f"it a part instead: parts: {{base: {{spec: {self.extends}}}, ...}}"
                )
            raise ValueError(
                "give 'description' or 'parts', not both; put extra frames in a part's spec"
            )
        if self.description is not None and self.root is None:
            raise ValueError("missing required key 'root' (the robot's root link)")
        return self

    @property
    def files(self) -> DescriptionSpec:
        """The description of a flat (not composed) spec; compilation flattens composed ones."""
        if self.description is None:
            raise SpecError(f"spec '{self.name}' is composed of parts and has no description")
        return self.description

    @property
    def root_link(self) -> str:
        """The root link of a flat spec (always set once validated and flattened)."""
        if self.root is None:
            raise SpecError(f"spec '{self.name}' names no root link")
        return self.root
