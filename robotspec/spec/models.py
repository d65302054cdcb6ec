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
    AfterValidator,
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


_NOT_IN_XML = frozenset(chr(c) for c in (*range(0x20), 0x7F)) - {"\t", "\n", "\r"}


def _no_control(value: str) -> str:
    """Names are written into SRDF and URDF files: no character XML cannot carry.

    Why not every non-printable character: a URDF may name a link with a newline (XML allows
    it), and a spec must be able to name that link. Echoed names are escaped by the CLI
    (:func:`robotspec.errors.printable`) and drafts quote them, so a newline is harmless.
    """
    bad = next((c for c in value if c in _NOT_IN_XML), None)
    if bad is not None:
        raise ValueError(f"names must not contain control characters (found U+{ord(bad):04X})")
    return value


Name = Annotated[str, Field(min_length=1, max_length=256), AfterValidator(_no_control)]
JointValues = dict[Name, float]
States = dict[Name, JointValues]


def _finite(values: tuple[float, ...]) -> tuple[float, ...]:
    if not all(math.isfinite(v) for v in values):
        raise ValueError("values must be finite numbers")
    return values


class _Model(BaseModel):
    # NaN and infinity are refused wherever a number enters (``abs(x - y) > tol`` is False for
    # NaN, so a NaN would pass every later check).
    model_config = ConfigDict(
        extra="forbid", frozen=True, populate_by_name=True, allow_inf_nan=False
    )


class FrameSpec(_Model):
    """A frame the URDF lacks, fixed to ``parent`` (HSRB's ``hand_gripper_tool_frame``)."""

    parent: Name = Field(description="the link the frame is on", examples=["hand_palm_link"])
    xyz: tuple[float, float, float] = Field(
        default=(0.0, 0.0, 0.0),
        description="position in the parent link",
        examples=[[0, 0, 0.07]],
        json_schema_extra={"unit": "m"},
    )
    rpy: tuple[float, float, float] | None = Field(
        default=None,
        description="roll, pitch, yaw (fixed axes, as in URDF)",
        examples=[[0, 0, 1.5708]],
        json_schema_extra={"unit": "rad"},
    )
    quaternion: tuple[float, float, float, float] | None = Field(
        default=None,
        description="[x, y, z, w]; give rpy or quaternion, not both",
        examples=[[0, 0, 0.7071068, 0.7071068]],
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

    urdf: Name = Field(
        description="URDF or xacro file",
        examples=["package://example-robot-data/robots/pr2_description/urdf/pr2.urdf"],
    )
    srdf: Name | None = Field(
        default=None, description="MoveIt SRDF (optional)", examples=["../config/my_robot.srdf"]
    )
    xacro_args: dict[Name, str] = Field(
        default_factory=dict,
        description="arguments passed to xacro (strings)",
        examples=[{"hand": "true"}],
    )
    package_paths: list[Name] = Field(
        default_factory=list,
        description="extra folders to search for ROS packages",
        examples=[["../ros_ws/src"]],
    )
    frames: dict[Name, FrameSpec] = Field(
        default_factory=dict,
        description="extra frames, by name, fixed to a link",
        examples=[{"hand_gripper_tool_frame": {"parent": "hand_palm_link", "xyz": [0, 0, 0.07]}}],
    )


class AttachSpec(_Model):
    """Where a part is welded: a link of an earlier part, and the pose of the part's root there.

    Names here are the parent part's own names (before its prefix), so renaming a part never
    breaks the parts attached to it.
    """

    part: Name = Field(description="the part this one is attached to", examples=["base"])
    link: Name = Field(
        description="a link of that part, in its own (unprefixed) names", examples=["tool0"]
    )
    xyz: tuple[float, float, float] = Field(
        default=(0.0, 0.0, 0.0),
        description="position in the link",
        examples=[[0, 0, 0.095]],
        json_schema_extra={"unit": "m"},
    )
    rpy: tuple[float, float, float] | None = Field(
        default=None,
        description="roll, pitch, yaw (fixed axes, as in URDF)",
        examples=[[0, 0, 1.5708]],
        json_schema_extra={"unit": "rad"},
    )
    quaternion: tuple[float, float, float, float] | None = Field(
        default=None,
        description="[x, y, z, w]; give rpy or quaternion, not both",
        examples=[[0, 0, 0.7071068, 0.7071068]],
    )
    joint: Name | None = Field(
        default=None,
        description="name of the fixed joint (default: '<part>_weld')",
        examples=["hand_mount"],
    )
    replace_root: bool = Field(
        default=False,
        description="drop the part's root link: its children (and its geometry) move onto "
        "'link', e.g. an arm's 'world' or a hand's mounting plate",
        examples=[True],
    )

    _check = field_validator("xyz", "rpy", "quaternion")(lambda v: v if v is None else _finite(v))

    def pose(self) -> Matrix:
        """The pose of the part's root link in ``link``."""
        return _pose(self.xyz, self.rpy, self.quaternion)


class PartSpec(_Model):
    """One part of a composed robot: a description (URDF/xacro or a spec) and where it is welded."""

    spec: Name | None = Field(
        default=None,
        description="another spec (a path or a shipped robot's name)",
        examples=["ur5"],
    )
    urdf: Name | None = Field(
        default=None,
        description="URDF or xacro file (without a spec)",
        examples=["package://example-robot-data/robots/b1_description/urdf/b1.urdf"],
    )
    srdf: Name | None = Field(
        default=None, description="its SRDF (with urdf only)", examples=["../config/base.srdf"]
    )
    xacro_args: dict[Name, str] = Field(
        default_factory=dict,
        description="arguments of a xacro file (with urdf only)",
        examples=[{"arm_id": "left"}],
    )
    package_paths: list[Name] = Field(
        default_factory=list,
        description="extra folders to search for ROS packages",
        examples=[["../ros_ws/src"]],
    )
    prefix: str = Field(
        default="",
        max_length=128,
        pattern=r"^[A-Za-z0-9_./-]*$",
        description="put before every link, joint, group, state and part name of this part",
        examples=["left_"],
    )
    attach: AttachSpec | None = Field(
        default=None,
        description="where the part is welded; the one part without it is the base",
        examples=[{"part": "base", "link": "trunk", "xyz": [0.3, 0, 0.09]}],
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

    type: Literal["omni", "differential", "fixed", "floating"] = Field(
        description="omni/differential: planar base; floating: 6 DOF; fixed: none",
        examples=["omni"],
    )
    joint: Name | None = Field(
        default=None, description="name of the base connection", examples=["world_joint"]
    )
    parent_frame: Name = Field(
        default="odom", description="the frame the base moves in", examples=["odom_combined"]
    )


class FingerSpec(_Model):
    """A finger as a chain from ``root`` to ``tip``."""

    root: Name = Field(description="the finger's first link", examples=["l_gripper_l_finger_link"])
    tip: Name = Field(description="the finger's tip link", examples=["l_gripper_l_finger_tip_link"])


class _ManipulatorBase(_Model):
    root: Name = Field(
        description="the link the manipulator starts at", examples=["l_gripper_palm_link"]
    )
    tool_frame: Name = Field(
        description="the frame that grasps (the TCP)", examples=["l_gripper_tool_frame"]
    )
    front_facing_orientation: tuple[float, float, float, float] = Field(
        default=(0.0, 0.0, 0.0, 1.0),
        description="tool-frame orientation of a front grasp, quaternion [x, y, z, w]",
        examples=[[-0.7071068, 0, -0.7071068, 0]],
    )
    front_facing_axis: tuple[float, float, float] | None = Field(
        default=None,
        description="derived from the orientation (R^T x) when omitted",
        examples=[[0, 0, 1]],
    )
    states: States = Field(
        default_factory=dict,
        description="named joint states",
        examples=[{"open": {"l_gripper_l_finger_joint": 0.548}}],
        json_schema_extra={"unit": "rad or m (per joint)"},
    )

    _check = field_validator("front_facing_orientation", "front_facing_axis")(
        lambda v: v if v is None else _finite(v)
    )


class ParallelGripperSpec(_ManipulatorBase):
    """A two-finger gripper; the thumb is the finger that always touches the object."""

    type: Literal["parallel_gripper"] = Field(
        description="selects this kind", examples=["parallel_gripper"]
    )
    finger: FingerSpec = Field(
        description="the other finger",
        examples=[{"root": "l_gripper_r_finger_link", "tip": "l_gripper_r_finger_tip_link"}],
    )
    thumb: FingerSpec = Field(
        description="the finger that always touches the object",
        examples=[{"root": "l_gripper_l_finger_link", "tip": "l_gripper_l_finger_tip_link"}],
    )


class GenericManipulatorSpec(_ManipulatorBase):
    """Any other end effector: a tool frame and an orientation."""

    type: Literal["generic"] = Field(description="selects this kind", examples=["generic"])


ManipulatorSpec = Annotated[
    ParallelGripperSpec | GenericManipulatorSpec, Field(discriminator="type")
]


class FieldOfViewSpec(_Model):
    """Angles in radians."""

    horizontal: float = Field(
        description="full horizontal angle, in (0, pi)",
        examples=[0.99483],
        json_schema_extra={"unit": "rad"},
    )
    vertical: float = Field(
        description="full vertical angle, in (0, pi)",
        examples=[0.75049],
        json_schema_extra={"unit": "rad"},
    )


class CameraSpec(_Model):
    """A camera on ``body``; fields missing here are taken from ``preset`` (templates)."""

    type: Literal["camera"] = Field(description="selects this kind", examples=["camera"])
    body: Name = Field(
        description="the link the camera looks from", examples=["wide_stereo_optical_frame"]
    )
    preset: Name | None = Field(
        default=None, description="a camera model from templates/", examples=["kinect_v1"]
    )
    forward_facing_axis: tuple[float, float, float] | None = Field(
        default=None,
        description="viewing axis in the body's frame, a unit vector "
        "(default: the preset's, else +z)",
        examples=[[0, 0, 1]],
    )
    field_of_view: FieldOfViewSpec | None = Field(
        default=None,
        description="default: the preset's",
        examples=[{"horizontal": 0.99483, "vertical": 0.75049}],
        json_schema_extra={"unit": "rad"},
    )
    minimal_height: float | None = Field(
        default=None,
        description="lowest height of the camera's frame above the robot's root over the "
        "limits of the joints that move it (checked by FK; default: the preset's, else 0)",
        examples=[1.166],
        json_schema_extra={"unit": "m"},
    )
    maximal_height: float | None = Field(
        default=None,
        description="highest height of the camera's frame above the robot's root over the "
        "limits of the joints that move it (checked by FK; default: the preset's, else 1)",
        examples=[1.583],
        json_schema_extra={"unit": "m"},
    )
    default: bool = Field(default=False, description="the robot's default camera", examples=[True])


class GenericSensorSpec(_Model):
    """Any other sensor attached to a body."""

    type: Literal["generic"] = Field(description="selects this kind", examples=["generic"])
    body: Name = Field(description="the link it is on", examples=["base_laser_link"])
    kind: Name | None = Field(
        default=None, description="free-form, e.g. 'lidar' or 'ft'", examples=["lidar"]
    )


SensorSpec = Annotated[CameraSpec | GenericSensorSpec, Field(discriminator="type")]


class ChainSpec(_Model):
    """A kinematic chain, by ``root``/``tip`` or by SRDF ``group`` name."""

    kind: Literal["arm", "chain"] = Field(
        default="arm",
        description="informational; a chain with a manipulator is an arm",
        examples=["arm"],
    )
    root: Name | None = Field(
        default=None, description="the link the chain starts at", examples=["torso_lift_link"]
    )
    tip: Name | None = Field(
        default=None, description="the link the chain ends at", examples=["l_wrist_roll_link"]
    )
    group: Name | None = Field(
        default=None, description="an SRDF group with one chain", examples=["left_arm"]
    )
    manipulator: Name | None = Field(
        default=None,
        description="name of the manipulator (from `manipulators`) at its tip",
        examples=["left_gripper"],
    )
    side: Literal["left", "right"] | None = Field(
        default=None,
        description="which arm of a two-arm robot this is, for `left_arm` / `right_arm`; "
        "default: the arm lying on the root's +y side in the default pose",
        examples=["left"],
    )
    sensors: list[Name] = Field(
        default_factory=list,
        description="names of sensors (from `sensors`) the chain carries",
        examples=[["hand_camera"]],
    )
    states: States = Field(
        default_factory=dict,
        description="named joint states",
        examples=[{"park": {"l_elbow_flex_joint": -2.12}}],
        json_schema_extra={"unit": "rad or m (per joint)"},
    )


class TorsoSpec(_Model):
    """The chain that connects the base to the other chains."""

    root: Name = Field(description="the link the torso starts at", examples=["base_link"])
    tip: Name = Field(description="the link the torso ends at", examples=["torso_lift_link"])
    states: States = Field(
        default_factory=dict,
        description="named joint states",
        examples=[{"low": {"torso_lift_joint": 0.0}}],
        json_schema_extra={"unit": "rad or m (per joint)"},
    )


class NeckSpec(_Model):
    """The chain carrying the head sensors; pitch and yaw bodies are optional."""

    root: Name = Field(description="the link the neck starts at", examples=["torso_lift_link"])
    tip: Name = Field(description="the link the neck ends at", examples=["head_tilt_link"])
    pitch_body: Name | None = Field(
        default=None, description="the link the tilt joint moves", examples=["head_tilt_link"]
    )
    yaw_body: Name | None = Field(
        default=None, description="the link the pan joint moves", examples=["head_pan_link"]
    )
    sensors: list[Name] = Field(
        default_factory=list,
        description="names of sensors (from `sensors`) the neck carries; at least one",
        examples=[["kinect"]],
    )
    states: States = Field(
        default_factory=dict,
        description="named joint states",
        examples=[{"forward": {"head_pan_joint": 0.0}}],
        json_schema_extra={"unit": "rad or m (per joint)"},
    )


class VelocityLimitsSpec(_Model):
    """Velocity caps (rad/s or m/s); they only tighten the URDF's limits, of the robot's joints."""

    default: float | None = Field(
        default=None,
        gt=0,
        description="cap for every 1-DOF joint of the robot",
        examples=[1.0],
        json_schema_extra={"unit": "rad/s or m/s"},
    )
    joints: dict[Name, Annotated[float, Field(gt=0)]] = Field(
        default_factory=dict,
        description="caps by joint name (over the default)",
        examples=[{"head_tilt_joint": 3.5}],
        json_schema_extra={"unit": "rad/s or m/s"},
    )


class CollisionSpec(_Model):
    """Self-collision configuration (the seed's ``default_collision_config``)."""

    buffer_distance: float = Field(
        default=0.05,
        ge=0,
        description="distance collision avoidance keeps",
        examples=[0.05],
        json_schema_extra={"unit": "m"},
    )
    violated_distance: float = Field(
        default=0.0,
        ge=0,
        description="distance below which a collision counts as violated",
        examples=[0.0],
        json_schema_extra={"unit": "m"},
    )
    disabled_bodies: list[Name] = Field(
        default_factory=list,
        description="links never checked for collision",
        examples=[["base_laser_link"]],
    )
    use_srdf: bool = Field(
        default=True, description="apply the SRDF's disabled pairs", examples=[True]
    )


class RobotSpec(_Model):
    """A robot: its files, its root, and its semantic parts."""

    robotspec: Literal[1] = Field(default=1, description="spec format version", examples=[1])
    name: Name = Field(description="the robot's name", examples=["PR2"])
    extends: Name | None = Field(
        default=None, description="a base spec this one modifies", examples=["pr2"]
    )
    description: DescriptionSpec | None = Field(
        default=None,
        description="the robot's files; a composed robot gives 'parts' instead",
        examples=[{"urdf": "robot.urdf"}],
    )
    parts: dict[Name, PartSpec] = Field(
        default_factory=dict,
        description="a robot assembled from parts welded together",
        examples=[
            {
                "arm": {"spec": "ur5"},
                "hand": {"spec": "hand.yaml", "attach": {"part": "arm", "link": "tool0"}},
            }
        ],
    )
    root: Name | None = Field(
        default=None,
        description="the robot's root link (composed robots: the base part's)",
        examples=["base_footprint"],
    )
    drive: DriveSpec | None = Field(
        default=None,
        description="how the base moves (default: from the SRDF's virtual joint)",
        examples=[{"type": "omni"}],
    )
    torso: TorsoSpec | None = Field(
        default=None,
        description="the torso chain",
        examples=[{"root": "base_link", "tip": "torso_lift_link"}],
    )
    neck: NeckSpec | None = Field(
        default=None,
        description="the neck",
        examples=[{"root": "torso_lift_link", "tip": "head_tilt_link", "sensors": ["kinect"]}],
    )
    chains: dict[Name, ChainSpec] = Field(
        default_factory=dict,
        description="arms and other kinematic chains, by name",
        examples=[{"left_arm": {"root": "torso_lift_link", "tip": "l_wrist_roll_link"}}],
    )
    manipulators: dict[Name, ManipulatorSpec] = Field(
        default_factory=dict,
        description="end effectors, by name",
        examples=[{"spare": {"type": "generic", "root": "base_link", "tool_frame": "base_link"}}],
    )
    sensors: dict[Name, SensorSpec] = Field(
        default_factory=dict,
        description="cameras and other sensors, by name",
        examples=[{"laser": {"type": "generic", "body": "base_laser_link", "kind": "lidar"}}],
    )
    velocity_limits: VelocityLimitsSpec = Field(
        default_factory=VelocityLimitsSpec,
        description="caps on joint velocities",
        examples=[{"default": 1.0}],
        json_schema_extra={"unit": "rad/s or m/s"},
    )
    controlled_joints: list[Name] | None = Field(
        default=None,
        description="default: every actuated, non-mimic joint of the robot",
        examples=[["torso_lift_joint", "head_pan_joint"]],
    )
    collision: CollisionSpec = Field(
        default_factory=CollisionSpec,
        description="self-collision settings",
        examples=[{"buffer_distance": 0.05}],
    )
    import_srdf_group_states: bool = Field(
        default=False,
        description="add the SRDF's group states as named joint states",
        examples=[True],
    )
    states: States = Field(
        default_factory=dict,
        description="robot-level named joint states",
        examples=[{"zero": {"head_pan_joint": 0.0}}],
        json_schema_extra={"unit": "rad or m (per joint)"},
    )

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
