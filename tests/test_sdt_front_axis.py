"""An end effector's front-facing axis: a vector in the hand's frame, R(q)^T x, not SDT's R(q) x.

SDT 26.7 derives ``EndEffector.front_facing_axis`` as the first column of the orientation's
rotation, R x: where the hand frame's x axis points once turned by the orientation, a vector
in the frame the orientation is given in. Its own docstring calls it "the axis of the
end_effector's tool frame that is facing forward", and coraplex uses it so: its pre-grasp pose
is moved along it "in the local coordinate frame of the pose" (``translate_pose_along_local_axis``),
and its ``GraspDescription.manipulation_axis()`` computes that hand-frame axis itself, R^T x.
The two agree when R is symmetric (PR2: identity; HSR-B: a half turn) and differ otherwise.

The Panda (example-robot-data) is such a robot: its spec turns the TCP a quarter turn about y,
so the front axis is the TCP's +z, where its fingers point; SDT's rule gives -z, into the hand.
"""

from __future__ import annotations

import warnings
from functools import cache
from typing import Any

import numpy as np
import pytest

from robotspec.semantic import AbstractRobot, ParallelGripper
from tests.conftest import erd_robots
from tests.sdt_support import sdt  # noqa: F401
from tests.test_sdt_coraplex import coraplex  # noqa: F401

pytestmark = pytest.mark.usefixtures("sdt")


@cache
def _panda() -> tuple[AbstractRobot, Any]:
    from robotspec.interop.sdt import SdtBridgeWarning, to_sdt
    from robotspec.robots import load

    erd_robots()
    robot = load("panda")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SdtBridgeWarning)
        return robot, to_sdt(robot)


def _finger_direction(robot: AbstractRobot) -> np.ndarray:
    """Where the Panda's fingers point from its hand, in the TCP's frame (unit vector)."""
    (hand,) = robot.manipulators
    assert isinstance(hand, ParallelGripper)
    kin, q, tool = robot.kinematics, robot.world.configuration(), hand.tool_frame.name
    hand_in_tool = kin.pose(q, hand.root.name, relative_to=tool)
    tips = [kin.pose(q, f.tip.name, relative_to=tool)[:3, 3] for f in (hand.thumb, hand.finger)]
    d = np.mean(tips, axis=0) - hand_in_tool[:3, 3]
    return d / np.linalg.norm(d)


def test_the_panda_faces_where_its_fingers_point_and_sdt_would_say_the_opposite() -> None:
    from semantic_digital_twin.spatial_types import Quaternion, RotationMatrix

    robot, sdt_robot = _panda()
    (hand,) = robot.manipulators
    fingers = _finger_direction(robot)
    assert hand.front_facing_axis == pytest.approx((0.0, 0.0, 1.0))
    assert float(np.dot(fingers, hand.front_facing_axis)) > 0.99
    # SDT's own rule on the same orientation: the first column of R, into the hand.
    r = RotationMatrix.from_quaternion(Quaternion(*hand.front_facing_orientation)).to_np()
    sdts = r[:3, 0]
    assert sdts == pytest.approx((0.0, 0.0, -1.0), abs=1e-6)
    assert float(np.dot(fingers, sdts)) < -0.99
    # to_sdt's end effector carries robotspec's axis.
    (ee,) = [p for p in sdt_robot._robot_parts if hasattr(p, "front_facing_axis")]
    assert tuple(ee.front_facing_axis.to_np()[:3]) == pytest.approx((0.0, 0.0, 1.0))


@pytest.mark.usefixtures("coraplex")
def test_coraplex_computes_the_hand_frame_axis_as_robotspec_does() -> None:
    from coraplex.datastructures.enums import ApproachDirection, VerticalAlignment
    from coraplex.datastructures.grasp import GraspDescription

    _, sdt_robot = _panda()
    (ee,) = [p for p in sdt_robot._robot_parts if hasattr(p, "front_facing_axis")]
    grasp = GraspDescription(ApproachDirection.FRONT, VerticalAlignment.NoAlignment, ee)
    assert grasp.manipulation_axis() == pytest.approx(list(ee.front_facing_axis.to_np()[:3]))
