"""Every shipped manipulator's front axis points out of the hand, checked by forward kinematics.

Why: an axis is three numbers a reviewer reads past; the UR5's pointed into the wrist for
months. The tool frame sits ahead of the manipulator's root along the direction a grasp
approaches from, so that direction, taken from FK, must agree with the declared axis.
"""

from __future__ import annotations

import numpy as np
import pytest

from robotspec.compiler import compile_robot
from robotspec.model.kinematics import Kinematics
from robotspec.shipped import shipped_spec_files

from .conftest import erd_robots, shared_path


def _compile(name: str):  # type: ignore[no-untyped-def]
    if name == "hsrb":
        return compile_robot(name, package_paths=[shared_path("robots", "hsrb")])
    return compile_robot(name)


@pytest.mark.parametrize("name", sorted(shipped_spec_files()))
def test_front_axis_points_from_the_hand_to_its_tool_frame(name: str) -> None:
    erd_robots()  # skips with its reason where example-robot-data is absent
    robot = _compile(name)
    world = robot.world
    poses = Kinematics(world).forward(world.configuration())
    checked = 0
    for manipulator in robot.manipulators:
        tool = poses[manipulator.tool_frame.index]
        reach = tool[:3, 3] - poses[manipulator.root.index][:3, 3]
        if np.linalg.norm(reach) < 1e-6:
            continue  # a tool frame at the root's origin says nothing about the axis
        axis = tool[:3, :3] @ np.asarray(manipulator.front_facing_axis)
        cosine = float(axis @ reach / np.linalg.norm(reach) / np.linalg.norm(axis))
        # within 60 degrees: a hand's grasp frame may sit up along the fingers as well as ahead
        assert cosine > 0.5, (manipulator.name, cosine)
        checked += 1
    assert checked, f"{name}: no manipulator whose tool frame lies ahead of its root"
