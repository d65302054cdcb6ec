"""Homing stays within the acceleration limits: when it arrives, and when it is halted.

Issue 31: the client scenario "home(), halted 0.3 s in, then home() again", from rest, braked at
1.37 x the acceleration limit. The simulated controller homed at the homing speed until it
reached home, then stopped dead: the whole homing speed lost in one step (3.7 x the limit on the
RRP arm). Every step below is checked against the limit, from the arm's own velocity and the
step's own duration (simulated clocks, so every run is the same).
"""

from __future__ import annotations

import numpy as np
import pytest

from robotspec.driver.clock import JitteryClock, SimClock
from robotspec.driver.errors import OperationAbortedError
from robotspec.driver.robot_info import load_robot_info
from robotspec.driver.sim import SimRobot
from robotspec.driver.state import CommandMode, RobotState, StateFlags

from .driver_support import RRP, robotinfo

#: Floating-point rounding only: a velocity change computed as ``a * dt`` and divided back.
ROUNDING = 1e-9


class Recorder:
    """The arm's true velocity after every step, and the step's time."""

    def __init__(self, robot: SimRobot) -> None:
        self.robot = robot
        self.t: list[float] = []
        self.v: list[np.ndarray] = []
        robot.add_state_listener(self)

    def __call__(self, st: RobotState) -> None:
        self.t.append(st.ts)
        self.v.append(self.robot.sim_velocity)

    def worst_acceleration_ratio(self, since: int = 0) -> float:
        """The largest |dv/dt| over the acceleration limit, over the steps from ``since``."""
        t = np.array(self.t[since:])
        v = np.array(self.v[since:])
        dt = np.diff(t)
        acc = np.abs(np.diff(v, axis=0)) / dt[:, None]
        return float((acc / self.robot.limits.acceleration).max())


#: Where homing starts: this fraction of the way from home to the upper limits. Several, because
#: how hard the old controller stopped depended on where its last step landed.
FRACTIONS = (0.3, 0.5, 0.7)


def _away_from_home(info_path: object, clock: SimClock, fraction: float = 0.5) -> SimRobot:
    info = load_robot_info(info_path)  # type: ignore[arg-type]
    probe = SimRobot(info, clock=SimClock())
    lim = probe.limits
    start = lim.home + fraction * (lim.upper - lim.home)
    robot = SimRobot(info, clock=clock, initial_position=start)
    robot.step()
    robot.step()
    return robot


def _infos() -> list[object]:
    return [RRP, pytest.param("sawyer.yml", id="sawyer")]


def _path(which: object) -> object:
    return robotinfo(which) if isinstance(which, str) else which


@pytest.mark.parametrize("fraction", FRACTIONS)
@pytest.mark.parametrize("which", _infos())
def test_home_halted_then_home_again_stays_within_the_acceleration_limits(
    which: object, fraction: float
) -> None:
    robot = _away_from_home(_path(which), SimClock(), fraction)
    rec = Recorder(robot)
    robot.command_mode = CommandMode.homing
    first = robot.home(wait=False)
    robot.run_for(0.3)
    moving = float(np.abs(robot.sim_velocity).max())
    assert moving > 0.0  # halted mid-move, not at rest
    robot.halt()
    robot.step()
    assert first.done and isinstance(first.error, OperationAbortedError)
    halted_at = len(rec.t) - 1
    robot.command_mode = CommandMode.homing
    robot.home(wait=True)  # from the braking arm, all the way home
    robot.run_for(0.05)
    st = robot.robot_state
    assert st.flags & StateFlags.homed
    np.testing.assert_allclose(st.joint_position, robot.limits.home, atol=1e-9)
    np.testing.assert_array_equal(robot.sim_velocity, 0.0)
    assert rec.worst_acceleration_ratio(halted_at) <= 1.0 + ROUNDING
    assert rec.worst_acceleration_ratio() <= 1.0 + ROUNDING


@pytest.mark.parametrize("fraction", FRACTIONS)
@pytest.mark.parametrize("which", _infos())
def test_halting_homing_brakes_within_the_limits_to_rest(which: object, fraction: float) -> None:
    robot = _away_from_home(_path(which), SimClock(), fraction)
    rec = Recorder(robot)
    robot.command_mode = CommandMode.homing
    robot.home(wait=False)
    robot.run_for(0.3)
    robot.halt()
    robot.run_for(1.0)
    np.testing.assert_array_equal(robot.sim_velocity, 0.0)
    assert rec.worst_acceleration_ratio() <= 1.0 + ROUNDING


def test_homing_under_jitter_arrives_within_the_limits() -> None:
    """Late wake-ups (steps of varying length) change when homing arrives, not how hard."""
    robot = _away_from_home(RRP, JitteryClock(mean_late=0.002, max_late=0.02, seed=31))
    rec = Recorder(robot)
    robot.command_mode = CommandMode.homing
    robot.home(wait=True)
    assert robot.step().flags & StateFlags.homed
    assert rec.worst_acceleration_ratio() <= 1.0 + ROUNDING
