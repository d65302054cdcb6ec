"""The spec's semantic parts: drive, chains, torso, neck, manipulators, fingers, sensors.

Each model documents its fields (description, example, unit) for the JSON Schema editors show.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Annotated, Literal

from pydantic import (
    Field,
    field_validator,
)

if TYPE_CHECKING:
    pass

from robotspec.spec.base import Name, SpecModel, States, finite_values

__all__ = [
    "CameraSpec",
    "ChainSpec",
    "DriveSpec",
    "FieldOfViewSpec",
    "FingerSpec",
    "GenericManipulatorSpec",
    "GenericSensorSpec",
    "HandSpec",
    "ManipulatorSpec",
    "NeckSpec",
    "ParallelGripperSpec",
    "SensorSpec",
    "TorsoSpec",
]


class DriveSpec(SpecModel):
    """How the base moves; by default taken from the SRDF's virtual joint."""

    type: Literal["omni", "differential", "fixed", "floating"] = Field(
        description="omni/differential: planar base; floating: 6 DOF; fixed: none",
        examples=["omni"],
    )
    joint: Name | None = Field(
        default=None,
        description="name of the base connection; a URDF planar (or floating) joint whose "
        "child is the robot's root is the drive as it is: name it here or leave this out",
        examples=["world_joint"],
    )
    parent_frame: Name = Field(
        default="odom", description="the frame the base moves in", examples=["odom_combined"]
    )
    joints: tuple[Name, Name, Name] | None = Field(
        default=None,
        description="the URDF's own base joints, x, y and theta (prismatic along x, along y, "
        "revolute about z), made one planar drive connection named `joint`; the robot's root "
        "is the theta joint's child",
        examples=[["odom_x", "odom_y", "odom_theta"]],
    )


class FingerSpec(SpecModel):
    """A finger as a chain from ``root`` to ``tip``."""

    root: Name = Field(description="the finger's first link", examples=["l_gripper_l_finger_link"])
    tip: Name = Field(description="the finger's tip link", examples=["l_gripper_l_finger_tip_link"])


class _ManipulatorBase(SpecModel):
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
        lambda v: v if v is None else finite_values(v)
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


class HandSpec(_ManipulatorBase):
    """A hand of a thumb and named fingers (more than a parallel gripper's two)."""

    type: Literal["hand"] = Field(description="selects this kind", examples=["hand"])
    thumb: FingerSpec = Field(
        description="the finger that opposes the others",
        examples=[{"root": "link_12.0", "tip": "link_15.0_tip"}],
    )
    fingers: dict[Name, FingerSpec] = Field(
        min_length=1,
        description="the other fingers by name (at least one), each a chain from its root to "
        "its tip",
        examples=[
            {
                "index": {"root": "link_0.0", "tip": "link_3.0_tip"},
                "middle": {"root": "link_4.0", "tip": "link_7.0_tip"},
            }
        ],
    )

    @field_validator("fingers")
    @classmethod
    def _not_thumb(cls, v: dict[str, FingerSpec]) -> dict[str, FingerSpec]:
        if "thumb" in v:
            raise ValueError("'thumb' is the hand's thumb, not one of its fingers: name it apart")
        return v


ManipulatorSpec = Annotated[
    ParallelGripperSpec | HandSpec | GenericManipulatorSpec, Field(discriminator="type")
]


class FieldOfViewSpec(SpecModel):
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


class CameraSpec(SpecModel):
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


class GenericSensorSpec(SpecModel):
    """Any other sensor attached to a body."""

    type: Literal["generic"] = Field(description="selects this kind", examples=["generic"])
    body: Name = Field(description="the link it is on", examples=["base_laser_link"])
    kind: Name | None = Field(
        default=None, description="free-form, e.g. 'lidar' or 'ft'", examples=["lidar"]
    )


SensorSpec = Annotated[CameraSpec | GenericSensorSpec, Field(discriminator="type")]


class ChainSpec(SpecModel):
    """A kinematic chain, by ``root``/``tip`` or by SRDF ``group`` name."""

    kind: Literal["arm", "leg", "chain"] = Field(
        default="arm",
        description="an arm carries a manipulator or a sensor (warned otherwise); a leg or "
        "another chain (a lift, a tail) need not; a chain with a manipulator is an arm",
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


class TorsoSpec(SpecModel):
    """The chain that connects the base to the other chains."""

    root: Name = Field(description="the link the torso starts at", examples=["base_link"])
    tip: Name = Field(description="the link the torso ends at", examples=["torso_lift_link"])
    states: States = Field(
        default_factory=dict,
        description="named joint states",
        examples=[{"low": {"torso_lift_joint": 0.0}}],
        json_schema_extra={"unit": "rad or m (per joint)"},
    )


class NeckSpec(SpecModel):
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
