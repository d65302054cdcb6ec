"""coraplex's robot-specific motions apply to ``to_sdt``'s robots (issue 32, item 2).

coraplex picks a robot's own motions by class identity (``AlternativeMotion.check_for_alternative``
compares ``original_class() == robot.__class__``); a spec's ``sdt: {class: ...}`` makes
``to_sdt``'s robot an instance of SDT's own class. These tests use coraplex 26.7's own function
and alternatives, unpatched.

What is a stand-in, and why: coraplex imports giskardpy (its motion charts and solver) at
module level, and giskardpy is not on PyPI. Where it is absent, :func:`_recording_giskardpy`
makes every ``giskardpy.*`` module SDT's stand-in does not already provide an empty module
whose classes record how they were built: coraplex's code runs as written, and a motion chart
is the record of the giskardpy goal coraplex chose (a solver that would run it is not
installable here; with real giskardpy these tests run against it unchanged). No Stretch URDF
exists on this machine (SDT's wheel lacks its resources, example-robot-data has none), so the
Stretch is a Stretch-shaped URDF the test writes: SDT's Stretch link names, a differential
base, mast, lift, telescoping arm, gripper, head camera.
"""

from __future__ import annotations

import importlib.abc
import importlib.machinery
import importlib.util
import os
import sys
import types
import warnings
from collections.abc import Iterator
from functools import cache
from pathlib import Path
from typing import Any

import pytest

from robotspec.semantic import AbstractRobot
from tests.conftest import erd_robots, shared_path
from tests.sdt_support import sdt  # noqa: F401

pytestmark = pytest.mark.usefixtures("sdt", "coraplex")


# ------------------------------------------------------------------ giskardpy, recorded
class _Recorded:
    """A giskardpy class as coraplex uses it: built with arguments, which it keeps."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        self.args = args
        self.kwargs = kwargs
        self.__dict__.update(kwargs)

    def __class_getitem__(cls, item: Any) -> Any:
        return cls


class _RecordingModule(types.ModuleType):
    def __getattr__(self, name: str) -> Any:
        if name.startswith("__"):
            raise AttributeError(name)
        cls = type(name, (_Recorded,), {"__module__": self.__name__})
        setattr(self, name, cls)
        return cls


class _RecordingFinder(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Finds ``giskardpy.*`` modules nothing else found (the last finder on ``sys.meta_path``)."""

    def find_spec(self, fullname: str, path: Any, target: Any = None) -> Any:
        if fullname.split(".")[0] != "giskardpy":
            return None
        return importlib.machinery.ModuleSpec(fullname, self, is_package=True)

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> types.ModuleType:
        return _RecordingModule(spec.name)

    def exec_module(self, module: types.ModuleType) -> None:
        module.__path__ = []


@pytest.fixture(scope="module")
def coraplex() -> Iterator[None]:
    """coraplex importable: real giskardpy if installed, else the recording modules."""
    if importlib.util.find_spec("coraplex") is None:
        reason = "coraplex is not installed (docs/sdt.md: coraplex, how to install it)"
        if os.environ.get("ROBOTSPEC_REQUIRE_SDT"):  # CI's SDT environment installs it
            pytest.fail(f"ROBOTSPEC_REQUIRE_SDT is set but {reason}")
        pytest.skip(reason)
    real = importlib.util.find_spec("giskardpy.motion_statechart") is not None
    finder = None if real else _RecordingFinder()
    if finder is not None:
        sys.meta_path.append(finder)
    try:
        yield
    finally:
        if finder is not None:
            sys.meta_path.remove(finder)


def _alternatives() -> list[type]:
    from coraplex.alternative_motion_mappings import (
        hsrb_motion_mapping,
        stretch_motion_mapping,
        tiago_motion_mapping,
    )

    return [
        hsrb_motion_mapping.HSRBMoveMotion,
        stretch_motion_mapping.StretchMoveToolCenterPoint,
        stretch_motion_mapping.StretchMoveSim,
        stretch_motion_mapping.StretchMoveReal,
        stretch_motion_mapping.StretchClose,
        tiago_motion_mapping.TiagoMoveSim,
    ]


def _check(robot: Any, motion: type, execution: str) -> type | None:
    from coraplex.alternative_motion_mapping import AlternativeMotion
    from coraplex.datastructures.enums import ExecutionType
    from coraplex.plans.executables import GiskardExecutable

    before = GiskardExecutable.execution_type
    GiskardExecutable.execution_type = getattr(ExecutionType, execution)
    try:
        return AlternativeMotion.check_for_alternative(_alternatives(), robot, motion)
    finally:
        GiskardExecutable.execution_type = before


# ----------------------------------------------------------------------------- robots
_BOX = '<{tag}><geometry><box size="0.05 0.05 0.05"/></geometry></{tag}>'
_LINK = f'<link name="{{}}">{_BOX.format(tag="visual")}{_BOX.format(tag="collision")}</link>'
#: (joint, type, parent, child, xyz, axis): SDT's Stretch names; lengths roughly a Stretch 2's.
_JOINTS = [
    ("joint_left_wheel", "continuous", "base_link", "link_left_wheel", "0 0.17 0.05", "0 0 1"),
    ("joint_right_wheel", "continuous", "base_link", "link_right_wheel", "0 -0.17 0.05", "0 0 1"),
    ("joint_mast", "fixed", "base_link", "link_mast", "-0.07 0.13 0.03", None),
    ("joint_lift", "prismatic", "link_mast", "link_lift", "0 0 0.2", "0 0 1"),
    ("joint_arm_l0", "prismatic", "link_lift", "link_arm_l0", "0 -0.1 0", "0 -1 0"),
    ("joint_wrist_yaw", "revolute", "link_arm_l0", "link_wrist_yaw", "0 -0.1 0", "0 0 1"),
    ("joint_wrist_pitch", "revolute", "link_wrist_yaw", "link_wrist_pitch", "0 -0.05 0", "1 0 0"),
    ("joint_wrist_roll", "revolute", "link_wrist_pitch", "link_wrist_roll", "0 -0.05 0", "0 1 0"),
    ("joint_gripper", "fixed", "link_wrist_roll", "link_straight_gripper", "0 -0.05 0", None),
    (
        "joint_gripper_finger_left",
        "prismatic",
        "link_straight_gripper",
        "link_gripper_finger_left",
        "0.03 -0.05 0",
        "1 0 0",
    ),
    (
        "joint_gripper_finger_right",
        "prismatic",
        "link_straight_gripper",
        "link_gripper_finger_right",
        "-0.03 -0.05 0",
        "-1 0 0",
    ),
    (
        "joint_fingertip_left",
        "fixed",
        "link_gripper_finger_left",
        "link_gripper_fingertip_left",
        "0 -0.05 0",
        None,
    ),
    (
        "joint_fingertip_right",
        "fixed",
        "link_gripper_finger_right",
        "link_gripper_fingertip_right",
        "0 -0.05 0",
        None,
    ),
    ("joint_grasp_center", "fixed", "link_straight_gripper", "link_grasp_center", "0 -0.1 0", None),
    ("joint_head", "fixed", "link_mast", "link_head", "0 0 1.3", None),
    ("joint_head_pan", "revolute", "link_head", "link_head_pan", "0.1 0 0", "0 0 1"),
    ("joint_head_tilt", "revolute", "link_head_pan", "link_head_tilt", "0 0 0.05", "0 1 0"),
    (
        "joint_camera",
        "fixed",
        "link_head_tilt",
        "camera_color_optical_frame",
        "0.03 0 0.02",
        None,
    ),
]

_SPEC = """\
robotspec: 1
name: Stretch
sdt: {class: Stretch}
description: {urdf: stretch.urdf}
root: base_link
forward: [0, -1, 0]
drive: {type: differential, parent_frame: odom}
torso:
  root: link_mast
  tip: link_lift
  states: {low: {joint_lift: 0.0}, mid: {joint_lift: 0.5}, high: {joint_lift: 1.0}}
neck: {root: link_head, tip: link_head_tilt, sensors: [head_camera]}
chains:
  arm: {root: link_lift, tip: link_wrist_roll, manipulator: gripper}
manipulators:
  gripper:
    type: parallel_gripper
    root: link_straight_gripper
    tool_frame: link_grasp_center
    front_facing_orientation: [0, 0, 0, 1]
    thumb: {root: link_gripper_finger_left, tip: link_gripper_fingertip_left}
    finger: {root: link_gripper_finger_right, tip: link_gripper_fingertip_right}
sensors:
  head_camera:
    type: camera
    body: camera_color_optical_frame
    forward_facing_axis: [0, 0, 1]
    field_of_view: {horizontal: 0.99483, vertical: 0.75049}
    minimal_height: 1.366
    maximal_height: 1.4
    default: true
"""


def _stretch_urdf() -> str:
    links = {"base_link", *(j[3] for j in _JOINTS)}
    joints = []
    for name, kind, parent, child, xyz, axis in _JOINTS:
        limit = ""
        if kind in ("prismatic", "revolute"):
            limit = '<limit lower="0" upper="1" effort="10" velocity="0.5"/>'
        joints.append(
            f'<joint name="{name}" type="{kind}"><parent link="{parent}"/>'
            f'<child link="{child}"/><origin xyz="{xyz}"/>'
            + (f'<axis xyz="{axis}"/>' if axis else "")
            + f"{limit}</joint>"
        )
    body = "".join(_LINK.format(n) for n in sorted(links)) + "".join(joints)
    return f'<?xml version="1.0"?><robot name="stretch">{body}</robot>'


@cache
def _stretch(folder: Path) -> Any:
    from robotspec.compiler import compile_robot
    from robotspec.interop.sdt import to_sdt

    (folder / "stretch.urdf").write_text(_stretch_urdf(), encoding="utf-8")
    (folder / "stretch.yaml").write_text(_SPEC, encoding="utf-8")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return to_sdt(compile_robot(folder / "stretch.yaml"))


@pytest.fixture(scope="module")
def stretch(tmp_path_factory: pytest.TempPathFactory) -> Any:
    return _stretch(tmp_path_factory.mktemp("stretch"))


@cache
def _shipped(name: str) -> tuple[AbstractRobot, Any]:
    from robotspec.interop.sdt import to_sdt
    from robotspec.robots import load

    paths = [shared_path("robots", "hsrb")] if name == "hsrb" else []
    if name != "hsrb":
        erd_robots()
    robot = load(name, package_paths=paths)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return robot, to_sdt(robot)


# ------------------------------------------------------------------------------ tests
def test_the_spec_list_is_sdts_robot_classes() -> None:
    import pkgutil

    import semantic_digital_twin.robots as robots
    from semantic_digital_twin.robots.robot_parts import AbstractRobot as SdtRobot

    from robotspec.spec.sdt import SDT_ROBOT_CLASSES

    found = {}
    for info in pkgutil.iter_modules(robots.__path__):
        module = importlib.import_module(f"{robots.__name__}.{info.name}")
        for name, value in vars(module).items():
            if (
                isinstance(value, type)
                and issubclass(value, SdtRobot)
                and value.__module__ == module.__name__
                and not getattr(value, "__abstractmethods__", None)
            ):
                found[name] = info.name
    assert found == SDT_ROBOT_CLASSES


def test_stretch_gets_its_differential_move(stretch: Any) -> None:
    from coraplex.alternative_motion_mappings.stretch_motion_mapping import (
        StretchClose,
        StretchMoveReal,
        StretchMoveSim,
        StretchMoveToolCenterPoint,
    )
    from coraplex.robot_plans import ClosingMotion, MoveMotion, MoveToolCenterPointMotion
    from semantic_digital_twin.robots.stretch import Stretch
    from semantic_digital_twin.world_description.connections import DifferentialDrive

    assert type(stretch) is Stretch and stretch.name.name == "Stretch"
    assert isinstance(stretch.drive, DifferentialDrive)
    assert _check(stretch, MoveMotion, "SIMULATED") is StretchMoveSim
    assert _check(stretch, MoveMotion, "REAL") is StretchMoveReal
    assert _check(stretch, MoveToolCenterPointMotion, "SIMULATED") is StretchMoveToolCenterPoint
    assert _check(stretch, ClosingMotion, "SIMULATED") is StretchClose
    assert stretch.validate()


def test_tiago_and_hsrb_get_theirs() -> None:
    from coraplex.alternative_motion_mappings.hsrb_motion_mapping import HSRBMoveMotion
    from coraplex.alternative_motion_mappings.tiago_motion_mapping import TiagoMoveSim
    from coraplex.robot_plans import MoveMotion
    from semantic_digital_twin.robots.hsrb import HSRB
    from semantic_digital_twin.robots.tiago import Tiago

    _, tiago = _shipped("tiago")
    assert type(tiago) is Tiago
    assert _check(tiago, MoveMotion, "SIMULATED") is TiagoMoveSim
    _, hsrb = _shipped("hsrb")
    assert type(hsrb) is HSRB
    assert _check(hsrb, MoveMotion, "REAL") is HSRBMoveMotion
    assert _check(hsrb, MoveMotion, "SIMULATED") is None  # coraplex has none for it


def test_without_a_class_no_alternative_applies() -> None:
    # The same Tiago built with a generated class: coraplex does not know it.
    from coraplex.robot_plans import MoveMotion

    from robotspec.interop.sdt import to_sdt
    from robotspec.interop.sdt.classes import robot_class
    from robotspec.interop.sdt.mapping import robot_recipe

    robot, tiago = _shipped("tiago")
    generated = robot_class(robot_recipe(robot))
    world = tiago._world
    assert generated is not type(tiago)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        other = to_sdt(robot, sdt_class=generated)
    assert type(other) is generated and world is not other._world
    assert _check(other, MoveMotion, "SIMULATED") is None


def test_a_move_motion_on_stretch_becomes_a_differential_drive_goal(stretch: Any) -> None:
    # coraplex's own route: a MoveMotion's node in a plan of the Stretch's world parses into
    # the executable giskardpy runs; its task is StretchMoveSim's chart, giskardpy's
    # differential-drive goal to the target in the world's frame at floor height (not the
    # omni CartesianPose). The node is made as coraplex's execute_single makes it, by hand:
    # coraplex 26.7's factories import a module written in Python 3.12 syntax (``type X =``),
    # which this Python 3.11 environment cannot import.
    from coraplex.datastructures.dataclasses import Context
    from coraplex.datastructures.enums import ExecutionType
    from coraplex.plans.executables import GiskardExecutable
    from coraplex.plans.plan import Plan
    from coraplex.plans.plan_node import MotionNode
    from coraplex.robot_plans import MoveMotion
    from semantic_digital_twin.spatial_types.spatial_types import Pose

    world = stretch._world
    context = Context.from_world(world, alternative_motion_mappings=_alternatives())
    target = Pose.from_xyz_rpy(1.0, 0.5, 0.3, 0, 0, 0.7, reference_frame=world.root)
    motion = MoveMotion(target=target)
    node = MotionNode(designator=motion)
    Plan(context=context).add_node(node)
    before = GiskardExecutable.execution_type
    GiskardExecutable.execution_type = ExecutionType.SIMULATED
    try:
        assert motion.robot is stretch
        assert motion.get_alternative_motion().__name__ == "StretchMoveSim"
        executable = node.parse()
    finally:
        GiskardExecutable.execution_type = before
    assert isinstance(executable, GiskardExecutable)
    [(mapped, chart)] = executable.motion_mappings.items()
    assert mapped is node
    assert type(chart).__name__ == "DifferentialDriveBaseGoal"
    goal = chart.goal_pose
    assert (float(goal.x), float(goal.y), float(goal.z)) == pytest.approx((1.0, 0.5, 0.0))
