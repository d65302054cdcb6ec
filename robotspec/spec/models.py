"""The robot spec: a robot's semantics as a short YAML file, validated by Pydantic models.

Why mappings keyed by name (``chains: {left_arm: ...}``) rather than lists: names are the
identity of parts, YAML refuses duplicate keys, and ``extends:`` can override one part of a base
spec by naming it. Every model forbids unknown keys and is frozen; positions of every node are
kept (``yamlio``) so the compiler can report ``file:line:col`` for any name it cannot resolve.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Annotated, Literal

from pydantic import (
    Field,
    field_validator,
    model_validator,
)

from robotspec.errors import SpecError

if TYPE_CHECKING:
    from robotspec.model.geometry import Matrix

from robotspec.spec.base import Name, SpecModel, States, finite_values
from robotspec.spec.parts import (
    CameraSpec,
    ChainSpec,
    DriveSpec,
    FieldOfViewSpec,
    FingerSpec,
    GenericManipulatorSpec,
    GenericSensorSpec,
    HandSpec,
    ManipulatorSpec,
    NeckSpec,
    ParallelGripperSpec,
    SensorSpec,
    TorsoSpec,
)
from robotspec.spec.sdt import SdtSpec

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
    "HandSpec",
    "NeckSpec",
    "ParallelGripperSpec",
    "PartSpec",
    "RobotSpec",
    "SPEC_VERSION",
    "TorsoSpec",
    "VelocityLimitsSpec",
]

SPEC_VERSION = 1


class FrameSpec(SpecModel):
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
        lambda v: v if v is None else finite_values(v)
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


class DescriptionSpec(SpecModel):
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


class AttachSpec(SpecModel):
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

    _check = field_validator("xyz", "rpy", "quaternion")(
        lambda v: v if v is None else finite_values(v)
    )

    def pose(self) -> Matrix:
        """The pose of the part's root link in ``link``."""
        return _pose(self.xyz, self.rpy, self.quaternion)


class PartSpec(SpecModel):
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


class VelocityLimitsSpec(SpecModel):
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


class CollisionSpec(SpecModel):
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


#: Characters besides spaces an ``accept_warnings`` entry's ``says`` must have: enough words to
#: pick one warning out of those at its path (``says: ' '`` would accept any).
MIN_SAYS = 8


class AcceptedWarning(SpecModel):
    """A warning the spec's author has read and accepts, with the reason (shown by ``--strict``).

    Why: some warnings flag what is usually a slip but is right for this robot (a leg that
    carries no tool, a camera fixed to a welded head). Accepting one by one, with a reason,
    keeps ``--strict`` usable without silencing a class of warnings everywhere.
    """

    at: str = Field(
        description="the spec path the warning is about, exactly as the warning prints it "
        "(a parent path accepts nothing below it); a warning about the spec's own SRDF is at "
        "description.srdf",
        examples=["chains.left_leg"],
        min_length=1,
    )
    says: str = Field(
        description="words of the warning's message, as printed (case counts), at least "
        f"{MIN_SAYS} characters besides spaces; they must match one warning at `at`",
        examples=["neither a manipulator nor a sensor"],
        min_length=1,
    )
    because: str = Field(
        description="why the warning does not apply to this robot",
        examples=["a leg carries no tool"],
        min_length=1,
    )

    @field_validator("says")
    @classmethod
    def _says_names_a_warning(cls, value: str) -> str:
        """Refuse ``says`` too short to identify a warning.

        Why: ``says: ' '`` (or ``a``) is a substring of every message, so it would accept
        whatever warning appears at that path later, not the one its author read.
        """
        if len("".join(value.split())) < MIN_SAYS:
            raise ValueError(
                f"'says' must quote the warning: at least {MIN_SAYS} characters besides spaces"
            )
        return value


class RobotSpec(SpecModel):
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
    forward: tuple[float, float, float] | None = Field(
        default=None,
        description="the direction the robot faces, a horizontal unit vector in its root "
        "link's frame (default +x, REP 103); a robot modelled facing -y says [0, -1, 0]: its "
        "left is then +x, and render's front view looks at its face",
        examples=[[0, -1, 0]],
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
    sdt: SdtSpec | None = Field(
        default=None,
        description="the semantic digital twin's robot class this robot is (to_sdt)",
        examples=[{"class": "PR2"}],
    )
    accept_warnings: list[AcceptedWarning] = Field(
        default_factory=list,
        description="warnings read and accepted, one by one, each with its reason; one that "
        "no longer occurs is itself a warning",
        examples=[
            [
                {
                    "at": "chains.left_leg",
                    "says": "neither a manipulator nor a sensor",
                    "because": "a leg carries no tool",
                }
            ]
        ],
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
