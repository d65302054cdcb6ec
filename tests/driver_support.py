"""Helpers shared by the driver tests: where the RobotInfo files are, and simulated robots."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from robotspec.driver.clock import SimClock
from robotspec.driver.robot_info import load_robot_info
from robotspec.driver.sim import SimRobot

SHARED = Path(__file__).resolve().parents[2] / "shared"
ROBOTINFO_DIR = SHARED / "robotinfo"
DATA = Path(__file__).resolve().parent / "data"
RRP = DATA / "driver_rrp.yml"


def robotinfo(name: str) -> Path:
    """A file of ../shared/robotinfo, or skip when the shared folder is absent."""
    p = ROBOTINFO_DIR / name
    if not p.exists():
        pytest.skip(f"needs {p} (the shared robot files beside the checkout), which is absent")
    return p


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
