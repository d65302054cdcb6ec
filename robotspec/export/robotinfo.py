"""A compiled robot's chain as a Robot Raconteur RobotInfo: what ``drive --spec`` simulates.

The driver's own :func:`robotspec.driver.export.export_chain` turns a world chain into a
RobotInfo; this module adds the compiler in front of it (spec -> robot -> chain), so the driver
package never depends on the compiler.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from robotspec.driver.export import ExportedRobotInfo, export_chain

if TYPE_CHECKING:
    from robotspec.semantic import AbstractRobot

__all__ = ["export_robot_chain", "export_spec_chain", "rr_device_name"]


def rr_device_name(robot_name: str, chain_name: str) -> str:
    """A Robot Raconteur device name (``^[a-zA-Z][a-zA-Z0-9_.-]*$``) for a robot's chain."""
    device = re.sub(r"[^A-Za-z0-9_.-]", "_", f"{robot_name}_{chain_name}")
    return device if device[:1].isalpha() else f"robot_{device}"


def export_spec_chain(
    spec: str | Path, chain: str, package_paths: Sequence[str | Path] | None = None
) -> ExportedRobotInfo:
    """Compile ``spec`` and export its chain ``chain`` as a RobotInfo (``export``, ``drive``).

    Why here and not in the driver package: it joins the compiler (spec → robot) with the export
    (world chain → RobotInfo); the driver package stays free of the compiler.
    """
    from robotspec.compiler import compile_robot

    return export_robot_chain(compile_robot(spec, package_paths=package_paths or ()), chain)


def export_robot_chain(robot: AbstractRobot, chain: str) -> ExportedRobotInfo:
    """An already compiled robot's chain ``chain`` as a RobotInfo (``demo`` compiles once)."""
    c = robot.get_chain(chain)
    device = rr_device_name(robot.name, c.name)
    return export_chain(
        robot.world,
        c.root,
        c.tip,
        device_name=device,
        chain_name=c.name,
        description=f"chain '{c.name}' of robot '{robot.name}'",
    )
