"""Generators of the reference pages in ``docs/``: the spec reference and the CLI reference.

Why generated: a reference written by hand drifts from the code the day a field or an option is
added. Here the spec reference is read from the Pydantic models of :mod:`robotspec.spec.models`
(types, defaults, descriptions; units and examples from :data:`FIELD_NOTES`, which must cover every
field), its compiler rules are *run* (each rule's message is what the compiler prints today for a
one-line broken spec), and the CLI reference is read from the typer app. ``tests/test_docs.py``
fails when a page in ``docs/`` differs from what this module generates.

Run ``python -m robotspec.docgen`` to rewrite the pages, ``--check`` to only compare them.
"""

from __future__ import annotations

import argparse
import inspect
import json
import os
import sys
import sysconfig
import tempfile
import types
import typing
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from pydantic import BaseModel
from pydantic.fields import FieldInfo

__all__ = [
    "FIELD_NOTES",
    "GENERATED_PAGES",
    "RULES",
    "DocgenError",
    "FieldNote",
    "Rule",
    "cli_reference",
    "generate_pages",
    "main",
    "spec_reference",
    "stale_pages",
]


class DocgenError(Exception):
    """The code and the documentation data disagree (a field without notes, a rule that passes)."""


# --------------------------------------------------------------------------- field notes


@dataclass(frozen=True)
class FieldNote:
    """What the models cannot say about a field: its unit, an example, and a fallback description.

    Attributes:
        unit: the physical unit ("m", "rad", "rad/s or m/s"), or "" when it has none.
        example: one line of YAML as it appears in a spec (``xyz: [0, 0, 0.07]``).
        description: used when the field's ``Field(description=...)`` is empty.
    """

    unit: str
    example: str
    description: str = ""


_JOINT_VALUES = "rad or m (per joint)"

#: Units, examples and descriptions of every spec field, keyed by ``(model name, field name)``.
#: Generation fails when a field of :mod:`robotspec.spec.models` is missing here.
FIELD_NOTES: dict[tuple[str, str], FieldNote] = {
    # RobotSpec
    ("RobotSpec", "robotspec"): FieldNote("", "robotspec: 1"),
    ("RobotSpec", "name"): FieldNote("", "name: PR2", "the robot's name"),
    ("RobotSpec", "extends"): FieldNote("", "extends: pr2"),
    ("RobotSpec", "description"): FieldNote(
        "", "description: {urdf: robot.urdf}", "the robot's files"
    ),
    ("RobotSpec", "parts"): FieldNote(
        "",
        "parts: {arm: {spec: ur5}, hand: {spec: hand.yaml, attach: {part: arm, link: tool0}}}",
    ),
    # PartSpec
    ("PartSpec", "spec"): FieldNote("", "spec: ur5"),
    ("PartSpec", "urdf"): FieldNote(
        "", "urdf: package://example-robot-data/robots/b1_description/urdf/b1.urdf"
    ),
    ("PartSpec", "srdf"): FieldNote("", "srdf: ../config/base.srdf"),
    ("PartSpec", "xacro_args"): FieldNote(
        "", "xacro_args: {arm_id: left}", "arguments of a xacro file (with urdf only)"
    ),
    ("PartSpec", "package_paths"): FieldNote(
        "", "package_paths: [../ros_ws/src]", "extra folders to search for ROS packages"
    ),
    ("PartSpec", "prefix"): FieldNote("", "prefix: left_"),
    ("PartSpec", "attach"): FieldNote("", "attach: {part: base, link: trunk, xyz: [0.3, 0, 0.09]}"),
    # AttachSpec
    ("AttachSpec", "part"): FieldNote("", "part: base"),
    ("AttachSpec", "link"): FieldNote("", "link: tool0"),
    ("AttachSpec", "xyz"): FieldNote("m", "xyz: [0, 0, 0.095]", "position in the link"),
    ("AttachSpec", "rpy"): FieldNote(
        "rad", "rpy: [0, 0, 1.5708]", "roll, pitch, yaw (fixed axes, as in URDF)"
    ),
    ("AttachSpec", "quaternion"): FieldNote("", "quaternion: [0, 0, 0.7071068, 0.7071068]"),
    ("AttachSpec", "joint"): FieldNote("", "joint: hand_mount"),
    ("AttachSpec", "replace_root"): FieldNote("", "replace_root: true"),
    ("RobotSpec", "root"): FieldNote(
        "", "root: base_footprint", "the link the robot starts at; its subtree is the robot"
    ),
    ("RobotSpec", "drive"): FieldNote(
        "", "drive: {type: omni}", "how the base moves (default: from the SRDF's virtual joint)"
    ),
    ("RobotSpec", "torso"): FieldNote(
        "", "torso: {root: base_link, tip: torso_lift_link}", "the torso chain"
    ),
    ("RobotSpec", "neck"): FieldNote(
        "", "neck: {root: torso_lift_link, tip: head_tilt_link, sensors: [kinect]}", "the neck"
    ),
    ("RobotSpec", "chains"): FieldNote(
        "",
        "chains: {left_arm: {root: torso_lift_link, tip: l_wrist_roll_link}}",
        "arms and other kinematic chains, by name",
    ),
    ("RobotSpec", "manipulators"): FieldNote(
        "", "manipulators: {left_gripper: {type: generic, ...}}", "end effectors, by name"
    ),
    ("RobotSpec", "sensors"): FieldNote(
        "", "sensors: {kinect: {type: camera, ...}}", "cameras and other sensors, by name"
    ),
    ("RobotSpec", "velocity_limits"): FieldNote(
        "rad/s or m/s", "velocity_limits: {default: 1.0}", "caps on joint velocities"
    ),
    ("RobotSpec", "controlled_joints"): FieldNote(
        "", "controlled_joints: [torso_lift_joint, head_pan_joint]"
    ),
    ("RobotSpec", "collision"): FieldNote(
        "", "collision: {buffer_distance: 0.05}", "self-collision settings"
    ),
    ("RobotSpec", "import_srdf_group_states"): FieldNote("", "import_srdf_group_states: true"),
    ("RobotSpec", "states"): FieldNote(_JOINT_VALUES, "states: {zero: {head_pan_joint: 0.0}}"),
    # DescriptionSpec
    ("DescriptionSpec", "urdf"): FieldNote(
        "", "urdf: package://example-robot-data/robots/pr2_description/urdf/pr2.urdf"
    ),
    ("DescriptionSpec", "srdf"): FieldNote("", "srdf: ../config/my_robot.srdf"),
    ("DescriptionSpec", "xacro_args"): FieldNote(
        "", "xacro_args: {hand: 'true'}", "arguments passed to xacro (strings)"
    ),
    ("DescriptionSpec", "package_paths"): FieldNote("", "package_paths: [../ros_ws/src]"),
    ("DescriptionSpec", "frames"): FieldNote(
        "",
        "frames: {hand_gripper_tool_frame: {parent: hand_palm_link, xyz: [0, 0, 0.07]}}",
        "extra frames, by name, fixed to a link",
    ),
    # FrameSpec
    ("FrameSpec", "parent"): FieldNote("", "parent: hand_palm_link", "the link the frame is on"),
    ("FrameSpec", "xyz"): FieldNote("m", "xyz: [0, 0, 0.07]", "position in the parent link"),
    ("FrameSpec", "rpy"): FieldNote(
        "rad", "rpy: [0, 0, 1.5708]", "roll, pitch, yaw (fixed axes, as in URDF)"
    ),
    ("FrameSpec", "quaternion"): FieldNote("", "quaternion: [0, 0, 0.7071068, 0.7071068]"),
    # DriveSpec
    ("DriveSpec", "type"): FieldNote(
        "", "type: omni", "omni/differential: planar base; floating: 6 DOF; fixed: none"
    ),
    ("DriveSpec", "joint"): FieldNote("", "joint: world_joint"),
    ("DriveSpec", "parent_frame"): FieldNote("", "parent_frame: odom_combined"),
    # TorsoSpec
    ("TorsoSpec", "root"): FieldNote("", "root: base_link", "the link the torso starts at"),
    ("TorsoSpec", "tip"): FieldNote("", "tip: torso_lift_link", "the link the torso ends at"),
    ("TorsoSpec", "states"): FieldNote(
        _JOINT_VALUES, "states: {low: {torso_lift_joint: 0.0}}", "named joint states"
    ),
    # NeckSpec
    ("NeckSpec", "root"): FieldNote("", "root: torso_lift_link", "the link the neck starts at"),
    ("NeckSpec", "tip"): FieldNote("", "tip: head_tilt_link", "the link the neck ends at"),
    ("NeckSpec", "pitch_body"): FieldNote(
        "", "pitch_body: head_tilt_link", "the link the tilt joint moves"
    ),
    ("NeckSpec", "yaw_body"): FieldNote(
        "", "yaw_body: head_pan_link", "the link the pan joint moves"
    ),
    ("NeckSpec", "sensors"): FieldNote(
        "", "sensors: [kinect]", "names of sensors (from `sensors`) the neck carries; at least one"
    ),
    ("NeckSpec", "states"): FieldNote(
        _JOINT_VALUES, "states: {forward: {head_pan_joint: 0.0}}", "named joint states"
    ),
    # ChainSpec
    ("ChainSpec", "kind"): FieldNote(
        "", "kind: arm", "informational; a chain with a manipulator is an arm"
    ),
    ("ChainSpec", "root"): FieldNote("", "root: torso_lift_link", "the link the chain starts at"),
    ("ChainSpec", "tip"): FieldNote("", "tip: l_wrist_roll_link", "the link the chain ends at"),
    ("ChainSpec", "group"): FieldNote("", "group: left_arm"),
    ("ChainSpec", "manipulator"): FieldNote(
        "", "manipulator: left_gripper", "name of the manipulator (from `manipulators`) at its tip"
    ),
    ("ChainSpec", "sensors"): FieldNote(
        "", "sensors: [hand_camera]", "names of sensors (from `sensors`) the chain carries"
    ),
    ("ChainSpec", "states"): FieldNote(
        _JOINT_VALUES, "states: {park: {l_elbow_flex_joint: -2.12}}", "named joint states"
    ),
    # Manipulators (ParallelGripperSpec and GenericManipulatorSpec share these)
    ("ParallelGripperSpec", "type"): FieldNote("", "type: parallel_gripper"),
    ("GenericManipulatorSpec", "type"): FieldNote("", "type: generic"),
    ("_ManipulatorBase", "root"): FieldNote(
        "", "root: l_gripper_palm_link", "the link the manipulator starts at"
    ),
    ("_ManipulatorBase", "tool_frame"): FieldNote(
        "", "tool_frame: l_gripper_tool_frame", "the frame that grasps (the TCP)"
    ),
    ("_ManipulatorBase", "front_facing_orientation"): FieldNote(
        "", "front_facing_orientation: [-0.7071068, 0, -0.7071068, 0]"
    ),
    ("_ManipulatorBase", "front_facing_axis"): FieldNote("", "front_facing_axis: [0, 0, 1]"),
    ("_ManipulatorBase", "states"): FieldNote(
        _JOINT_VALUES, "states: {open: {l_gripper_l_finger_joint: 0.548}}", "named joint states"
    ),
    ("ParallelGripperSpec", "finger"): FieldNote(
        "",
        "finger: {root: l_gripper_r_finger_link, tip: l_gripper_r_finger_tip_link}",
        "the other finger",
    ),
    ("ParallelGripperSpec", "thumb"): FieldNote(
        "",
        "thumb: {root: l_gripper_l_finger_link, tip: l_gripper_l_finger_tip_link}",
        "the finger that always touches the object",
    ),
    # FingerSpec
    ("FingerSpec", "root"): FieldNote(
        "", "root: l_gripper_l_finger_link", "the finger's first link"
    ),
    ("FingerSpec", "tip"): FieldNote(
        "", "tip: l_gripper_l_finger_tip_link", "the finger's tip link"
    ),
    # CameraSpec
    ("CameraSpec", "type"): FieldNote("", "type: camera"),
    ("CameraSpec", "body"): FieldNote(
        "", "body: wide_stereo_optical_frame", "the link the camera looks from"
    ),
    ("CameraSpec", "preset"): FieldNote("", "preset: kinect_v1"),
    ("CameraSpec", "forward_facing_axis"): FieldNote(
        "",
        "forward_facing_axis: [0, 0, 1]",
        "viewing axis in the body's frame, a unit vector (default: the preset's, else +z)",
    ),
    ("CameraSpec", "field_of_view"): FieldNote(
        "rad", "field_of_view: {horizontal: 0.99483, vertical: 0.75049}", "default: the preset's"
    ),
    ("CameraSpec", "minimal_height"): FieldNote(
        "m",
        "minimal_height: 1.166",
        "lowest height of the camera's frame above the robot's root over the limits of the "
        "joints that move it (checked by FK; default: the preset's, else 0)",
    ),
    ("CameraSpec", "maximal_height"): FieldNote(
        "m",
        "maximal_height: 1.583",
        "highest height of the camera's frame above the robot's root over the limits of the "
        "joints that move it (checked by FK; default: the preset's, else 1)",
    ),
    ("CameraSpec", "default"): FieldNote("", "default: true"),
    # FieldOfViewSpec
    ("FieldOfViewSpec", "horizontal"): FieldNote(
        "rad", "horizontal: 0.99483", "full horizontal angle, in (0, pi)"
    ),
    ("FieldOfViewSpec", "vertical"): FieldNote(
        "rad", "vertical: 0.75049", "full vertical angle, in (0, pi)"
    ),
    # GenericSensorSpec
    ("GenericSensorSpec", "type"): FieldNote("", "type: generic"),
    ("GenericSensorSpec", "body"): FieldNote("", "body: base_laser_link", "the link it is on"),
    ("GenericSensorSpec", "kind"): FieldNote("", "kind: lidar"),
    # VelocityLimitsSpec
    ("VelocityLimitsSpec", "default"): FieldNote(
        "rad/s or m/s", "default: 1.0", "cap for every 1-DOF joint of the robot"
    ),
    ("VelocityLimitsSpec", "joints"): FieldNote(
        "rad/s or m/s", "joints: {head_tilt_joint: 3.5}", "caps by joint name (over the default)"
    ),
    # CollisionSpec
    ("CollisionSpec", "buffer_distance"): FieldNote(
        "m", "buffer_distance: 0.05", "distance collision avoidance keeps"
    ),
    ("CollisionSpec", "violated_distance"): FieldNote(
        "m", "violated_distance: 0.0", "distance below which a collision counts as violated"
    ),
    ("CollisionSpec", "disabled_bodies"): FieldNote(
        "", "disabled_bodies: [base_laser_link]", "links never checked for collision"
    ),
    ("CollisionSpec", "use_srdf"): FieldNote("", "use_srdf: true"),
}


# --------------------------------------------------------------------------- type rendering


def _constraints(metadata: Sequence[Any]) -> str:
    """`` > 0`` / `` >= 0`` from pydantic/annotated-types metadata."""
    out = []
    for m in metadata:
        for attr, sign in (("gt", ">"), ("ge", ">="), ("lt", "<"), ("le", "<=")):
            value = getattr(m, attr, None)
            if isinstance(value, int | float) and not isinstance(value, bool):
                out.append(f"{sign} {value:g}")
        if isinstance(m, FieldInfo):
            out.extend(c for c in [_constraints(m.metadata)] if c)
    return ", ".join(out)


def _is_model(tp: Any) -> bool:
    return isinstance(tp, type) and issubclass(tp, BaseModel)


def _type_text(tp: Any) -> str:
    """A spec field's type in YAML words (``map: name → number``), models as page links."""
    origin = typing.get_origin(tp)
    args = typing.get_args(tp)
    if origin is typing.Annotated:
        inner = "name" if args[0] is str else _type_text(args[0])
        cons = _constraints(args[1:])
        return f"{inner} {cons}" if cons else inner
    if origin is typing.Literal:
        values = [str(a) for a in args]
        return values[0] if len(values) == 1 else "one of " + ", ".join(values)
    if origin in (typing.Union, types.UnionType):
        parts = [a for a in args if a is not type(None)]
        text = " or ".join(_type_text(a) for a in parts)
        return f"{text} or null" if len(parts) < len(args) else text
    if origin is tuple:
        if len(args) == 2 and args[1] is Ellipsis:
            return f"list of {_plural(_type_text(args[0]))}"
        if all(a is float for a in args):
            return f"[{len(args)} numbers]"
        return "[" + ", ".join(_type_text(a) for a in args) + "]"
    if origin is list:
        return f"list of {_plural(_type_text(args[0]))}"
    if origin is dict:
        return f"map: {_type_text(args[0])} → {_type_text(args[1])}"
    if _is_model(tp):
        return f"[{_title(tp)}](#{_anchor(tp)})"
    return {str: "string", float: "number", int: "integer", bool: "true or false"}.get(
        tp, getattr(tp, "__name__", str(tp))
    )


def _plural(word: str) -> str:
    if word.startswith("["):
        return word
    return word if word.endswith("s") else word + "s"


def _title(model: type[BaseModel]) -> str:
    return model.__name__


def _anchor(model: type[BaseModel]) -> str:
    return model.__name__.lower()


def _yaml_value(value: Any) -> str:
    if isinstance(value, BaseModel):
        return (
            "{}" if not value.model_dump(exclude_defaults=True) else json.dumps(value.model_dump())
        )
    if isinstance(value, bool):
        return "true" if value else "false"
    if value is None:
        return "null"
    if isinstance(value, tuple | list):
        return "[" + ", ".join(_yaml_value(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{}" if not value else json.dumps(value)
    return str(value)


def _default_text(field: FieldInfo) -> str:
    if field.is_required():
        return "required"
    if field.default_factory is not None:
        factory = typing.cast(Callable[[], Any], field.default_factory)
        return f"`{_yaml_value(factory())}`"
    return f"`{_yaml_value(field.default)}`"


def _models_in(tp: Any) -> Iterator[type[BaseModel]]:
    if _is_model(tp):
        yield tp
    for a in typing.get_args(tp):
        yield from _models_in(a)


def _where_suffix(tp: Any) -> str:
    """How a field's value nests: ``.<name>`` under a map, ``[i]`` under a list."""
    origin = typing.get_origin(tp)
    args = typing.get_args(tp)
    if origin is typing.Annotated or origin in (typing.Union, types.UnionType):
        for a in args:
            s = _where_suffix(a)
            if s:
                return s
        return ""
    if origin is dict:
        return ".<name>" + _where_suffix(args[1])
    if origin in (list, tuple):
        return "[i]" + _where_suffix(args[0])
    return ""


def _spec_models() -> list[tuple[type[BaseModel], list[str]]]:
    """Every model of the spec format and where it appears, nested ones after their parent."""
    from robotspec.spec.models import RobotSpec

    paths: dict[type[BaseModel], list[str]] = {RobotSpec: ["(the file)"]}
    order: list[type[BaseModel]] = []

    def visit(model: type[BaseModel], where: str) -> None:
        order.append(model)
        for name, field in model.model_fields.items():
            path = name if where == "(the file)" else f"{where}.{name}"
            path += _where_suffix(field.annotation)
            for sub in _models_in(field.annotation):
                if sub in paths:
                    if path not in paths[sub]:
                        paths[sub].append(path)
                    continue
                paths[sub] = [path]
                visit(sub, path)

    visit(RobotSpec, "(the file)")
    return [(m, paths[m]) for m in order]


def _note(model: type[BaseModel], name: str) -> FieldNote:
    for cls in model.__mro__:
        note = FIELD_NOTES.get((cls.__name__, name))
        if note is not None:
            return note
    raise DocgenError(
        f"spec field {model.__name__}.{name} has no entry in robotspec.docgen.FIELD_NOTES "
        "(unit, example, description): add one, then run `python -m robotspec.docgen`"
    )


def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def _doc_text(obj: Any) -> str:
    return inspect.cleandoc(obj.__doc__ or "").replace("``", "`")


def _model_section(model: type[BaseModel], where: list[str]) -> list[str]:
    at = ", ".join(f"`{w}`" for w in where)
    lines = [f"### {_title(model)}", "", f"Where: {at}. {_doc_text(model)}", ""]
    lines += [
        "| key | type | unit | default | description | example |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    for name, field in model.model_fields.items():
        note = _note(model, name)
        key = field.alias or name
        description = field.description or note.description
        if not description and name == "type":
            description = "selects this kind"
        if not description:
            raise DocgenError(f"spec field {model.__name__}.{name} has no description")
        annotation: Any = field.annotation
        type_text = _type_text(annotation)
        if annotation is str and any(getattr(m, "min_length", None) for m in field.metadata):
            type_text = "name"
        cons = _constraints(field.metadata)
        if cons:
            head, nullable, _ = type_text.partition(" or null")
            type_text = f"{head} {cons}" + (", or null" if nullable else "")
        lines.append(
            "| "
            + " | ".join(
                [
                    f"`{key}`",
                    _cell(type_text),
                    note.unit or "",
                    _cell(_default_text(field)),
                    _cell(description),
                    f"`{_cell(note.example)}`",
                ]
            )
            + " |"
        )
    return [*lines, ""]


# --------------------------------------------------------------------------- compiler rules


@dataclass(frozen=True)
class Rule:
    """One check, shown by a one-line change to the shipped PR2 and the message it produces.

    Attributes:
        group: the section of the reference the rule is listed in.
        rule: what is checked, in a few words.
        change: one line of YAML added below ``extends: pr2`` (flow style).
        severity: ``error`` or ``warning``: what the change must produce.
        base: line 2 of the file (``extends: pr2`` unless the rule is about ``extends``).
    """

    group: str
    rule: str
    change: str
    severity: str = "error"
    base: str = "extends: pr2"


#: Every rule the reference lists, each run against the compiler when the page is generated.
RULES: tuple[Rule, ...] = (
    # The format.
    Rule(
        "Format", "unknown keys are errors, with the closest key", "chains: {left_arm: {tipp: x}}"
    ),
    Rule("Format", "values have the field's type", "velocity_limits: {default: fast}"),
    Rule("Format", "numeric bounds (velocity caps > 0)", "velocity_limits: {default: 0}"),
    Rule(
        "Format",
        "required keys",
        "manipulators: {spare: {type: generic, root: base_link}}",
    ),
    Rule(
        "Format",
        "`extends` names a file or a shipped robot (line 2 is `name: mine`)",
        "extends: pr3",
        base="name: mine",
    ),
    # Files.
    Rule("Files", "the URDF exists", "description: {urdf: robots/pr2.urdf}"),
    Rule(
        "Files",
        "`package://` packages exist",
        "description: {urdf: 'package://pr2_descr/urdf/pr2.urdf'}",
    ),
    Rule(
        "Files",
        "an extra frame's parent exists",
        "description: {frames: {tool: {parent: l_gripper_palm_lnk}}}",
    ),
    Rule(
        "Files",
        "an extra frame gives rpy or quaternion, not both",
        "description: {frames: {tool: {parent: l_gripper_palm_link, rpy: [0, 0, 0], "
        "quaternion: [0, 0, 0, 1]}}}",
    ),
    Rule(
        "Files",
        "an extra frame's quaternion is a unit quaternion",
        "description: {frames: {tool: {parent: l_gripper_palm_link, quaternion: [0, 0, 1, 1]}}}",
    ),
    Rule(
        "Files",
        "an extra frame is new",
        "description: {frames: {l_gripper_tool_frame: {parent: l_gripper_palm_link}}}",
    ),
    Rule("Files", "a drive moves the robot's root", "root: base_link"),
    # Chains.
    Rule(
        "Chains", "every link name exists, with the closest names", "torso: {tip: torso_lift_lnk}"
    ),
    Rule(
        "Chains",
        "root is an ancestor of tip (reversed)",
        "chains: {right_arm: {root: r_wrist_roll_link, tip: torso_lift_link}}",
    ),
    Rule(
        "Chains",
        "root is an ancestor of tip (other branch)",
        "chains: {left_arm: {root: r_shoulder_pan_link}}",
    ),
    Rule("Chains", "a chain holds at least one joint", "torso: {root: torso_lift_link}"),
    Rule("Chains", "root and tip, or an SRDF group", "chains: {head: {root: head_pan_link}}"),
    Rule("Chains", "not both an SRDF group and root/tip", "chains: {left_arm: {group: left_arm}}"),
    Rule(
        "Chains",
        "the SRDF group exists",
        "chains: {left_arm: {root: null, tip: null, group: left}}",
    ),
    Rule(
        "Chains",
        "the SRDF group is one `<chain>`",
        "chains: {left_arm: {root: null, tip: null, group: arms}}",
    ),
    Rule(
        "Chains",
        "neck pitch and yaw bodies are on the neck",
        "neck: {pitch_body: l_wrist_roll_link}",
    ),
    Rule("Chains", "a neck carries a sensor", "neck: {sensors: []}"),
    Rule(
        "Chains",
        "a chain's manipulator exists",
        "chains: {left_arm: {manipulator: left_griper}}",
    ),
    Rule(
        "Chains",
        "a manipulator is on one chain",
        "chains: {right_arm: {manipulator: left_gripper}}",
    ),
    Rule(
        "Chains",
        "a chain's manipulator is below its tip",
        "chains: {left_arm: {manipulator: right_gripper}, right_arm: {manipulator: left_gripper}}",
    ),
    Rule(
        "Chains",
        "a chain has a manipulator or a sensor",
        "chains: {head: {root: head_pan_link, tip: head_tilt_link}}",
        "warning",
    ),
    # Manipulators.
    Rule(
        "Manipulators",
        "the tool frame is below the manipulator's root",
        "manipulators: {left_gripper: {tool_frame: r_gripper_tool_frame}}",
    ),
    Rule(
        "Manipulators",
        "front_facing_orientation is a unit quaternion",
        "manipulators: {left_gripper: {front_facing_orientation: [0, 0, 0, 2]}}",
    ),
    Rule(
        "Manipulators",
        "a given front_facing_axis agrees with the orientation (R^T x)",
        "manipulators: {left_gripper: {front_facing_axis: [0, 0, 1]}}",
    ),
    Rule(
        "Manipulators",
        "fingers start below the gripper's root",
        "manipulators: {left_gripper: {thumb: {root: r_gripper_l_finger_link, "
        "tip: r_gripper_l_finger_tip_link}}}",
    ),
    Rule(
        "Manipulators",
        "finger and thumb differ",
        "manipulators: {left_gripper: {thumb: {root: l_gripper_r_finger_link, "
        "tip: l_gripper_r_finger_tip_link}}}",
    ),
    Rule(
        "Manipulators",
        "a manipulator is on a chain",
        "manipulators: {spare: {type: generic, root: base_link, tool_frame: base_link}}",
        "warning",
    ),
    # Sensors.
    Rule("Sensors", "the camera preset exists", "sensors: {kinect: {preset: kinect_v3}}"),
    Rule(
        "Sensors",
        "a camera has a field of view (its own or its preset's)",
        "sensors: {cam: {type: camera, body: l_forearm_cam_optical_frame}}",
    ),
    Rule(
        "Sensors",
        "field-of-view angles lie in (0, pi)",
        "sensors: {kinect: {field_of_view: {horizontal: 3.5, vertical: 0.75}}}",
    ),
    Rule(
        "Sensors",
        "forward_facing_axis is a unit vector",
        "sensors: {kinect: {forward_facing_axis: [0, 0, 2]}}",
    ),
    Rule(
        "Sensors",
        "a frame optical by its rotation (REP 103: z forward, x right, y down) looks along +z; "
        "by its name only: a warning",
        "sensors: {kinect: {forward_facing_axis: [1, 0, 0]}}",
    ),
    Rule("Sensors", "minimal_height <= maximal_height", "sensors: {kinect: {minimal_height: 1.8}}"),
    Rule(
        "Sensors",
        "a field of view is wider than tall (a landscape image)",
        "sensors: {kinect: {field_of_view: {horizontal: 0.75049, vertical: 0.99483}}}",
        "warning",
    ),
    Rule(
        "Sensors",
        "at most one default camera",
        "sensors: {narrow: {type: camera, body: narrow_stereo_optical_frame, preset: kinect_v1, "
        "default: true}}",
    ),
    Rule(
        "Sensors",
        "a sensor is on a chain or the neck",
        "sensors: {narrow: {type: camera, body: narrow_stereo_optical_frame, preset: kinect_v1}}",
        "warning",
    ),
    Rule(
        "Sensors",
        "two cameras are not on one frame",
        "sensors: {kinect2: {type: camera, body: wide_stereo_optical_frame, preset: kinect_v1}}",
        "warning",
    ),
    Rule(
        "Sensors",
        "a camera is not a laser or IMU frame (by the frame's or its mesh's name)",
        "sensors: {laser: {type: camera, body: laser_tilt_link, preset: kinect_v1}}",
        "warning",
    ),
    # Kinematics.
    Rule(
        "Kinematics",
        "a camera's heights are FK's over the limits of every joint that moves it (exact "
        "bounds for lifts, pans and one last joint, else sampled)",
        "sensors: {kinect: {minimal_height: 0.75, maximal_height: 0.99}}",
    ),
    Rule(
        "Kinematics",
        "a sampled range: a height FK reaches is an error, one it never reached a warning",
        "sensors: {kinect: {body: l_forearm_cam_optical_frame}}",
    ),
    Rule(
        "Kinematics",
        "a torso, neck or arm can move (a `kind: chain` or a finger that cannot: a warning)",
        "chains: {mount: {root: base_link, tip: base_laser_link}}",
    ),
    Rule(
        "Kinematics",
        "low, mid, high states give increasing heights of the part's tip",
        "torso: {states: {low: {torso_lift_joint: 0.3}, high: {torso_lift_joint: 0.0}}}",
    ),
    Rule(
        "Kinematics",
        "a gripper's open state is wider than its close state",
        "manipulators: {left_gripper: {states: {open: {l_gripper_l_finger_joint: 0.0}, "
        "close: {l_gripper_l_finger_joint: 0.5}}}}",
    ),
    # Copy-paste.
    Rule(
        "Parts",
        "two parts do not have the same links",
        "chains: {left_arm2: {root: torso_lift_link, tip: l_wrist_roll_link}}",
    ),
    Rule(
        "Parts",
        "two manipulators do not share a tool frame",
        "manipulators: {spare: {type: generic, root: l_gripper_palm_link, "
        "tool_frame: l_gripper_tool_frame}}",
    ),
    Rule("Sensors", "a carried sensor exists", "chains: {left_arm: {sensors: [kinekt]}}"),
    Rule("Sensors", "a sensor has one carrier", "chains: {left_arm: {sensors: [kinect]}}"),
    # Joint states.
    Rule(
        "Joint states",
        "the joint exists",
        "chains: {left_arm: {states: {park: {l_elbow_joint: -2.12}}}}",
    ),
    Rule(
        "Joint states",
        "the joint belongs to the part",
        "chains: {left_arm: {states: {park: {r_elbow_flex_joint: -2.12}}}}",
    ),
    Rule(
        "Joint states",
        "the value is within the joint's limits",
        "torso: {states: {high: {torso_lift_joint: 0.5}}}",
    ),
    Rule(
        "Joint states",
        "a mimic joint is set through its leader",
        "manipulators: {left_gripper: {states: {open: {l_gripper_r_finger_joint: 0.548}}}}",
    ),
    Rule("Joint states", "the joint moves", "states: {tool: {l_gripper_tool_joint: 0.0}}"),
    # Velocity limits and the rest.
    Rule(
        "Joints",
        "a velocity cap names a 1-DOF joint of the robot",
        "velocity_limits: {joints: {l_shoulder_pan: 0.1}}",
    ),
    Rule(
        "Joints",
        "a velocity cap on a mimic joint goes to its leader",
        "velocity_limits: {joints: {l_gripper_r_finger_joint: 0.1}}",
    ),
    Rule(
        "Joints",
        "a velocity cap is on a moving joint",
        "velocity_limits: {joints: {l_gripper_tool_joint: 0.1}}",
    ),
    Rule(
        "Joints",
        "a velocity cap is on the robot's own joints",
        "velocity_limits: {joints: {world_joint: 0.5}}",
    ),
    Rule(
        "Joints",
        "a velocity cap only tightens",
        "velocity_limits: {joints: {head_pan_joint: 10.0}}",
        "warning",
    ),
    Rule("Joints", "controlled joints are actuated joints", "controlled_joints: [l_elbow_flex]"),
    Rule(
        "Joints",
        "a disabled body has collision geometry",
        "collision: {disabled_bodies: [l_gripper_tool_frame]}",
        "warning",
    ),
)

_BROKEN = "broken.yaml"


def _rule_messages(rules: Sequence[Rule]) -> list[list[str]]:
    """Compile each rule's broken spec; return the lines the compiler prints for it.

    The ROS package path variables are cleared meanwhile, so a "package not found" message lists
    the same folders on every machine (site-packages is shown as ``$SITE_PACKAGES``).
    """
    saved = {k: os.environ.pop(k) for k in _ROS_PATH_VARS if k in os.environ}
    try:
        return _run_rules(rules)
    finally:
        os.environ.update(saved)


_ROS_PATH_VARS = ("ROS_PACKAGE_PATH", "AMENT_PREFIX_PATH")


def _run_rules(rules: Sequence[Rule]) -> list[list[str]]:
    from robotspec.compiler import check_spec
    from robotspec.errors import RobotSpecError
    from robotspec.shipped import shipped_spec_files

    specs_dir = str(shipped_spec_files()["pr2"].parent)
    site = sysconfig.get_paths()["purelib"]
    out: list[list[str]] = []
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        prefixes = sorted({str(folder) + "/", str(folder.resolve()) + "/"}, key=len, reverse=True)
        path = folder / _BROKEN
        for rule in rules:
            path.write_text(f"robotspec: 1\n{rule.base}\n{rule.change}\n")
            details = []
            try:
                result = check_spec(path)
                details = [d for w in result.warnings for d in w.details]
            except RobotSpecError as exc:
                details = list(exc.details)
            details = [d for d in details if not (d.file or "").endswith(".srdf")]
            if not any(d.severity == rule.severity for d in details):
                raise DocgenError(
                    f"rule '{rule.rule}': `{rule.change}` gave no {rule.severity} "
                    f"(got {[d.render() for d in details]}); fix the rule in robotspec/docgen.py"
                )
            lines = []
            for d in details:
                text = d.render()
                for p in prefixes:
                    text = text.replace(p, "")
                text = text.replace(specs_dir + "/", "robotspec/specs/")
                lines.append(text.replace(site + "/", "$SITE_PACKAGES/"))
            out.append(lines)
    return out


_SPEC_INTRO = """\
A spec is one YAML file whose top level is [RobotSpec](#robotspec). Every mapping refuses
unknown keys; names (links, joints, SRDF groups) are checked against the robot's URDF and SRDF
when the spec is compiled (`robotspec validate`). Units: lengths in metres, angles in radians,
velocities in rad/s (revolute joints) or m/s (prismatic joints); quaternions are `[x, y, z, w]`.
A joint state maps joint names to positions, each in its joint's unit.

For completion and checks in an editor, write the JSON Schema (`robotspec schema -o
robotspec.schema.json`) and point the YAML language server at it with a first line
`# yaml-language-server: $schema=robotspec.schema.json`; `robotspec init` writes that line.

`extends: NAME` starts from another spec (a file next to this one, or a shipped robot such as
`pr2`): mappings are merged key by key, lists and values are replaced, and the extending file's
lines are the ones errors point at.
"""

_RULES_INTRO = """\
`robotspec validate` reports every problem of a spec at once, one per line, in file order:

```text
FILE:LINE:COL: SEVERITY: LOCATION: MESSAGE
```

`LOCATION` is the dotted path of the YAML node (`chains.left_arm.tip`); messages about a name that
does not exist end with `did you mean ...?` and the closest names in the robot's files. Errors
exit with code 1; warnings do not, unless `--strict` is given. A spec is checked in two stages:
first its shape (keys, types, bounds, as Pydantic validates it), then, once the shape is right,
every name and every rule below. Problems in the SRDF itself (names the URDF lacks) are warnings
pointing into the SRDF, as MoveIt treats them.

Severity policy: an **error** when the spec is provably wrong (a name that does not exist, a chain
that cannot move, a camera height FK proves wrong, two default cameras), a **warning** when it
is only suspicious (a frame named like a laser, a field of view taller than wide, a part nobody
carries). The kinematic checks evaluate forward kinematics: heights are the z coordinate of a
frame's origin in the robot's root frame, over the limits of every joint that moves it
(continuous joints over one turn, other joints at 0 or their nearest limit) and agree within
1 cm. They are exact when every moving joint above the frame is a vertical lift or a pan,
except a last joint (a tilt): the height is then a sum of terms, each bounded in closed form.
Otherwise they are sampled (about 2,000 seeded configurations and the limit box's corners, the
best refined joint by joint): a height the samples reach is proof (the message names the joint
values), a spec height beyond them only a warning. The message says which method ran.

Each example below is a complete file `broken.yaml` that changes the shipped PR2 by one line
(line 3), and the exact output of `robotspec validate broken.yaml` for it:

<!-- fragment: a template, line 3 varies -->
```yaml
robotspec: 1
extends: pr2
chains: {left_arm: {tipp: x}}
```
"""


def spec_reference() -> str:
    """The text of ``docs/spec-reference.md``."""
    from robotspec.spec.models import SPEC_VERSION

    lines = [
        "# Spec reference",
        "",
        "<!-- Generated by `python -m robotspec.docgen` from robotspec/spec/models.py, "
        "robotspec/docgen.py and the compiler's messages; do not edit. -->",
        "",
        f"Spec format version {SPEC_VERSION}. " + _SPEC_INTRO,
    ]
    models = _spec_models()
    lines += ["## Fields", ""]
    lines += [
        f"- [{_title(m)}](#{_anchor(m)}): " + ", ".join(f"`{p}`" for p in w) for m, w in models
    ]
    lines.append("")
    for model, where in models:
        lines += _model_section(model, where)
    lines += ["## Rules the compiler checks", "", _RULES_INTRO]
    messages = _rule_messages(RULES)
    group = ""
    for rule, msgs in zip(RULES, messages, strict=True):
        if rule.group != group:
            group = rule.group
            lines += ["", f"### {group}", "", "| rule | line 3 | output |", "| --- | --- | --- |"]
        shown = "<br>".join(f"`{_cell(m)}`" for m in msgs)
        lines.append(f"| {_cell(rule.rule)} | `{_cell(rule.change)}` | {shown} |")
    lines.append("")
    return "\n".join(lines)


# --------------------------------------------------------------------------- CLI reference


def _param_row(param: Any, ctx: Any) -> str | None:
    """One table row for a parameter, from the help record ``--help`` prints (none for --help)."""
    if "--help" in param.opts or getattr(param, "hidden", False):
        return None
    record = param.get_help_record(ctx)
    if record is None:
        return None
    names, help_text = record
    return f"| `{_cell(names)}` | {_cell(' '.join(help_text.split()))} |"


def _command_sections(cmd: Any, path: list[str], parent_ctx: Any, out: list[str]) -> None:
    from typer._click import Context

    ctx = Context(cmd, info_name=path[-1], parent=parent_ctx, max_content_width=200)
    name = " ".join(path)
    level = "##" if len(path) <= 2 else "###"
    out += [f"{level} `{name}`", ""]
    help_text = inspect.cleandoc(cmd.help or "").replace("``", "`")
    if help_text:
        out += [help_text, ""]
    pieces = " ".join(cmd.collect_usage_pieces(ctx))
    out += ["```text", f"{name} {pieces}".rstrip(), "```", ""]
    rows = [r for r in (_param_row(p, ctx) for p in cmd.get_params(ctx)) if r is not None]
    if rows:
        out += ["| argument / option | help |", "| --- | --- |"]
        out += [*rows, ""]
    sub = getattr(cmd, "commands", None)
    if sub:
        if len(path) > 1:
            out += ["Commands: " + ", ".join(f"`{name} {n}`" for n in sub), ""]
        for sub_name in sub:
            _command_sections(sub[sub_name], [*path, sub_name], ctx, out)


def cli_reference() -> str:
    """The text of ``docs/cli.md``, walked from the typer app's click commands."""
    import typer.main

    from robotspec.cli.app import app

    group = typer.main.get_command(app)
    out = [
        "# CLI reference",
        "",
        "<!-- Generated by `python -m robotspec.docgen` from the typer app (robotspec/cli); "
        "do not edit. -->",
        "",
        "Exit codes: 0 success, 1 an invalid input (every problem printed as "
        "`file:line:col: error: message` on standard error, or on standard output by "
        "`validate`), 2 a usage error, 3 an internal error (a bug: rerun with `--verbose`). "
        "Colours only on a terminal; `NO_COLOR` turns them off.",
        "",
    ]
    _command_sections(group, ["robotspec"], None, out)
    return "\n".join(out).rstrip("\n") + "\n"


# --------------------------------------------------------------------------- performance


def _readme_benchmarks(readme: Path) -> tuple[str, list[str]]:
    """The README's benchmark intro paragraph and table rows (placeholder rows dropped)."""
    text = readme.read_text(encoding="utf-8") if readme.is_file() else ""
    section = text.partition("## Benchmarks")[2].partition("\n## ")[0]
    intro = section.strip().split("\n\n")[0] if section.strip() else ""
    if intro.startswith("|"):
        intro = ""
    rows = [line for line in section.splitlines() if line.startswith("|")]
    data = [r for r in rows[2:] if "filled in by" not in r and r.strip("| ")]
    return intro, (rows[:2] + data if data else [])


def _benchmark_notes(folder: Path) -> list[str]:
    """One entry per ``benchmarks/*.py``: its summary, what it compares and its command."""
    import ast

    out: list[str] = []
    for path in sorted(folder.glob("bench_*.py")):
        doc = ast.get_docstring(ast.parse(path.read_text(encoding="utf-8"))) or ""
        raw = [p.strip() for p in doc.split("\n\n") if p.strip()]
        summary = " ".join(raw[0].split()) if raw else path.stem
        run = next((" ".join(p.split()) for p in raw if p.startswith("Run:")), "")
        command = run.partition("``")[2].partition("``")[0] or f"python benchmarks/{path.name}"
        after = run.partition("``")[2].partition("``")[2].lstrip(" .")
        out += [f"### `benchmarks/{path.name}`", "", summary.replace("``", "`"), ""]
        out += ["```sh", command, "```", ""]
        if after:
            out += [after[0].upper() + after[1:].replace("``", "`"), ""]
        for p in raw[1:]:
            if not p.startswith("Run:"):
                out += [p.replace("``", "`"), ""]
    return out


def performance_page() -> str:
    """The text of ``docs/performance.md``: the README's table and each benchmark's command."""
    root = default_docs_dir().parent
    intro, table = _readme_benchmarks(root / "README.md")
    lines = [
        "# Performance",
        "",
        "<!-- Generated by `python -m robotspec.docgen` from README.md's benchmark table and "
        "the docstrings of benchmarks/*.py; do not edit. -->",
        "",
    ]
    if table:
        lines += [intro, ""] if intro else []
        lines += [*table, ""]
    else:
        lines += [
            "No figures yet: the benchmark table in the README is not filled in. See the "
            "README's Benchmarks section once it is; each figure comes from one of the commands "
            "below.",
            "",
        ]
    lines += [
        "## The benchmarks",
        "",
        "Each runs from the repository root with the dev extra installed "
        "(`pip install -e '.[dev]'`; each names its peer and any extra it needs below); "
        "peers run in the same process, one after the other, so ratios compare like with like.",
        "",
    ]
    lines += _benchmark_notes(root / "benchmarks")
    return "\n".join(lines).rstrip("\n") + "\n"


# --------------------------------------------------------------------------- pages


#: Generated pages: file name in ``docs/`` -> generator.
GENERATED_PAGES: dict[str, Callable[[], str]] = {
    "spec-reference.md": spec_reference,
    "cli.md": cli_reference,
    "performance.md": performance_page,
}


def default_docs_dir() -> Path:
    """``docs/`` of the source checkout this module is in, else ``./docs``."""
    root = Path(__file__).resolve().parents[1]
    if (root / "pyproject.toml").is_file():
        return root / "docs"
    return Path.cwd() / "docs"


def generate_pages() -> dict[str, str]:
    """Every generated page's text, by file name."""
    return {name: make() for name, make in GENERATED_PAGES.items()}


def stale_pages(docs: Path, pages: dict[str, str] | None = None) -> list[str]:
    """Names of generated pages whose file in ``docs`` is missing or differs."""
    pages = generate_pages() if pages is None else pages
    stale = []
    for name, text in pages.items():
        path = docs / name
        if not path.is_file() or path.read_text(encoding="utf-8") != text:
            stale.append(name)
    return stale


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m robotspec.docgen [--check] [--docs DIR]``."""
    parser = argparse.ArgumentParser(
        prog="python -m robotspec.docgen", description="Regenerate docs/spec-reference.md, cli.md."
    )
    parser.add_argument("--check", action="store_true", help="only report stale pages (exit 1)")
    parser.add_argument("--docs", type=Path, default=None, help="the docs folder")
    args = parser.parse_args(argv)
    docs: Path = args.docs or default_docs_dir()
    pages = generate_pages()
    stale = stale_pages(docs, pages)
    if args.check:
        for name in stale:
            sys.stderr.write(f"{docs / name}: stale; run `python -m robotspec.docgen`\n")
        return 1 if stale else 0
    docs.mkdir(parents=True, exist_ok=True)
    for name in stale:
        (docs / name).write_text(pages[name], encoding="utf-8")
        sys.stderr.write(f"wrote {docs / name}\n")
    if not stale:
        sys.stderr.write("generated pages are up to date\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
