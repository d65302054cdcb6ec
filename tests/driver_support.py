"""Helpers shared by the driver tests: where the RobotInfo files are, and simulated robots."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from robotspec.driver.clock import SimClock
from robotspec.driver.robot_info import load_robot_info
from robotspec.driver.sim import SimRobot

from .conftest import DATA, SHARED, shared_path

ROBOTINFO_DIR = SHARED / "robotinfo"
RRP = DATA / "driver_rrp.yml"


def robotinfo(name: str) -> Path:
    """A file of ../shared/robotinfo, or skip when the shared folder is absent."""
    return shared_path("robotinfo", name)


def shared_robotinfo_files() -> list[Path]:
    """Every shared RobotInfo file (empty when ../shared is absent)."""
    return sorted(ROBOTINFO_DIR.glob("*.yml")) if ROBOTINFO_DIR.is_dir() else []


class StallingClock(SimClock):
    """Simulated time in which some of the loop's wake-ups come late by whole stalls.

    ``stalls`` maps a simulated time to a stall in seconds: the first wake-up at or after that
    time returns that much late, as a loop thread preempted on a loaded machine does (a real
    driver loop on a busy 2-core machine misses 20-100 ms now and then). Deterministic: the
    driver's handling of missed periods is tested here, not by hoping the machine is busy.
    """

    def __init__(self, stalls: dict[float, float], start: float = 0.0) -> None:
        super().__init__(start)
        self._stalls = sorted(stalls.items())

    def sleep_until(self, deadline: float) -> None:
        """Advance to ``deadline``, plus the stall due by then (if any)."""
        super().sleep_until(deadline)
        while self._stalls and self._stalls[0][0] <= self.now():
            self.advance(self._stalls.pop(0)[1])


def make_sim(path: Path, period: float = 0.01, **kw: object) -> SimRobot:
    """A simulated robot on simulated time, stepped twice so it is healthy and reporting."""
    kw.setdefault("clock", SimClock())
    robot = SimRobot(load_robot_info(path), update_period=period, **kw)  # type: ignore[arg-type]
    robot.step()
    robot.step()
    return robot


def q_of(robot: SimRobot) -> np.ndarray:
    return np.array(robot.robot_state.joint_position)
