"""``robotspec demo --physics mujoco``: the demo's arm on MuJoCo, gravity compensated if needed.

Why decide gravity compensation from the robot and not per robot name: some URDFs state an
effort their joint cannot hold the arm with, because the real arm has a counterbalance the file
does not describe (the PR2's shoulder springs: 30 N m stated, 52 N m needed to hold the upper
arm at the demo's jog target). Under physics such an arm sags and the demo's scenario fails for
a reason that is the file's, not the driver's. So the demo checks, at the configurations its
scenario visits (home and the jog target), whether every joint's effort holds its links against
gravity; where one does not, it turns gravity compensation on and says which joint and by how
much.
``--gravity-compensation`` / ``--no-gravity-compensation`` overrule the check.
"""

from __future__ import annotations

import sys
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from robotspec.driver.mujoco_model import PlantModel
    from robotspec.driver.robot_info import RobotInfo
    from robotspec.semantic import AbstractRobot

__all__ = ["demo_plant"]


def demo_plant(
    compiled: AbstractRobot,
    robot: str,
    chain: str,
    package_paths: Sequence[Path],
    info: RobotInfo,
    gravity_compensation: bool | None,
) -> tuple[PlantModel, bool]:
    """The plant the demo drives and whether gravity is compensated (``None``: decide)."""
    from robotspec.cli.demo_cmd import demo_positions
    from robotspec.cli.physics import physics_target, replant
    from robotspec.driver.mujoco_model import holding_shortfalls

    target = physics_target(
        robot,
        chain,
        package_paths,
        gravity_compensation=bool(gravity_compensation),
        robot=compiled,
    )
    if gravity_compensation is None:
        short = holding_shortfalls(target.plant, target.joint_names, demo_positions(info))
        if short:
            worst = short[0]
            sys.stderr.write(
                f"note: {worst.joint} needs {worst.needed:.3g} {worst.unit} to hold the arm "
                "against gravity, "
                f"its effort is {worst.effort:.3g} {worst.unit}"
                + (
                    f" ({len(short) - 1} more joint{'s' if len(short) > 2 else ''} short)"
                    if len(short) > 1
                    else ""
                )
                + ": gravity compensated, as a counterbalance the description leaves out would "
                "(--no-gravity-compensation to see it sag)\n"
            )
            return replant(target, gravity_compensation=True).plant, True
        return target.plant, False
    return target.plant, gravity_compensation
