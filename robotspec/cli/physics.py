"""``--physics mujoco`` for ``drive`` and ``demo``: a compiled robot's chain with MuJoCo as plant.

Why in the CLI package: it joins the compiler (spec -> robot), the MJCF export and the driver's
plant model; the driver package stays free of the compiler, as for ``drive --spec``. The export
happens in memory (meshes handed to MuJoCo as bytes), nothing is written.
"""

from __future__ import annotations

import sys
from collections.abc import Sequence
from dataclasses import dataclass
from enum import StrEnum
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from robotspec.driver.export import ExportedRobotInfo
    from robotspec.driver.mujoco_model import PlantModel
    from robotspec.export.mjcf import MjcfExport
    from robotspec.semantic import AbstractRobot

__all__ = ["Physics", "PhysicsTarget", "physics_target", "replant"]


class Physics(StrEnum):
    """What moves the simulated arm: the kinematic profile alone, or MuJoCo under servos."""

    kinematic = "kinematic"
    mujoco = "mujoco"


@dataclass(frozen=True)
class PhysicsTarget:
    """A chain to drive on MuJoCo: its RobotInfo, the compiled robot, its export and plant."""

    robot: AbstractRobot
    exported: ExportedRobotInfo
    export: MjcfExport
    plant: PlantModel

    @property
    def joint_names(self) -> list[str]:
        """The chain's joints in the RobotInfo's order (MJCF joints of the same names)."""
        return [j.joint_identifier.name for j in self.exported.info.joint_info]


def physics_target(
    spec: str | Path,
    chain: str,
    package_paths: Sequence[Path] = (),
    *,
    gravity_compensation: bool = False,
    robot: AbstractRobot | None = None,
) -> PhysicsTarget:
    """Compile ``spec`` (unless ``robot`` is it, compiled), export ``chain`` and its MJCF.

    Raises a RobotSpecError naming ``pip install 'robotspec[mujoco]'`` without MuJoCo, before
    anything is compiled.
    """
    from robotspec.driver.fill import JOG_ARRIVAL_TOLERANCE
    from robotspec.driver.mujoco_model import friction_dead_bands, require_mujoco
    from robotspec.export.physics_model import plant_model

    require_mujoco()
    from robotspec.compiler import compile_robot, resolve_spec
    from robotspec.export.mjcf import mjcf_export
    from robotspec.export.robotinfo import export_robot_chain
    from robotspec.export.urdf import joined_urdf
    from robotspec.spec.load import load_spec

    path = resolve_spec(spec)
    if robot is None:
        robot = compile_robot(path, package_paths=package_paths)
    exported = export_robot_chain(robot, chain)
    tree = joined_urdf(load_spec(path, allowed=package_paths), package_paths=package_paths)
    export = mjcf_export(robot, tree, name="robot")
    for note in export.notes:
        sys.stderr.write(f"note: {note}\n")
    names = [j.joint_identifier.name for j in exported.info.joint_info]
    plant = plant_model(robot, export, names, gravity_compensation=gravity_compensation)
    bands = friction_dead_bands(plant, names, JOG_ARRIVAL_TOLERANCE)
    if bands:
        worst = bands[0]
        listed = ", ".join(
            f"{b.band:.2g} {'m' if b.unit == 'N' else 'rad'} on {b.joint}" for b in bands
        )
        sys.stderr.write(
            f"note: the URDF's dry friction holds {len(bands)} of the chain's joints short of a "
            f"jog's {JOG_ARRIVAL_TOLERANCE:g} arrival (friction over servo stiffness, "
            f"{worst.joint}: {worst.friction:g} {worst.unit} against {worst.stiffness:.3g}): "
            f"{listed}\n"
        )
    return PhysicsTarget(robot, exported, export, plant)


def replant(target: PhysicsTarget, *, gravity_compensation: bool) -> PhysicsTarget:
    """The same target with gravity compensation on or off (the export is reused)."""
    from robotspec.export.physics_model import plant_model

    plant = plant_model(
        target.robot,
        target.export,
        target.joint_names,
        gravity_compensation=gravity_compensation,
    )
    return PhysicsTarget(target.robot, target.exported, target.export, plant)
