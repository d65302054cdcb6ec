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


def make_sim(path: Path, period: float = 0.01, **kw: object) -> SimRobot:
    """A simulated robot on simulated time, stepped twice so it is healthy and reporting."""
    kw.setdefault("clock", SimClock())
    robot = SimRobot(load_robot_info(path), update_period=period, **kw)  # type: ignore[arg-type]
    robot.step()
    robot.step()
    return robot


def q_of(robot: SimRobot) -> np.ndarray:
    return np.array(robot.robot_state.joint_position)
