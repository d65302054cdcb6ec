"""The MuJoCo model a physics-backed driver steps, as data, and what it asks of MuJoCo.

:class:`PlantModel` is the compiled ``mujoco.MjModel`` with the chain's joints, servos and gains
found by name; :func:`robotspec.export.physics_model.plant_model` builds it from a robot's MJCF
export (the driver package stays free of the export and the semantic layer). Nothing here
imports MuJoCo at module level: ``import robotspec`` and the kinematic driver never load it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from robotspec.arrays import F64
from robotspec.extras import MUJOCO, require_present

__all__ = [
    "MUJOCO_INSTALL",
    "DeadBand",
    "PlantModel",
    "Shortfall",
    "friction_dead_bands",
    "holding_shortfalls",
    "require_mujoco",
]

#: What a user without MuJoCo is told to run.
MUJOCO_INSTALL = MUJOCO.command


def require_mujoco(feature: str = "--physics mujoco") -> None:
    """Raise a RobotSpecError naming the extra to install when MuJoCo cannot be imported.

    Why up front: a user asking for physics without the extra gets one line saying what to
    install, before any robot is compiled, not a traceback.
    """
    require_present(MUJOCO, feature)


@dataclass(frozen=True)
class PlantModel:
    """A compiled MuJoCo model with the chain's joints and servos found by name.

    Attributes:
        model: the ``mujoco.MjModel``.
        qpos0: the robot's default configuration as the model's ``qpos`` (chain at default).
        ctrl0: the servos' targets at the default configuration.
        joint_qpos: per chain joint, its address in ``qpos``.
        joint_dof: per chain joint, its address in ``qvel`` (and the ``qfrc_*`` arrays).
        actuator: per chain joint, the index of its position servo.
        kp: per chain joint, its servo's stiffness (N m/rad or N/m).
        kv: per chain joint, its servo's damping (N m s/rad or N s/m).
        welded: the joints welded (removed or held by an equality), in the export's order.
        gravity_compensation: whether every body's gravity is cancelled (``gravcomp``).
    """

    model: Any
    qpos0: F64
    ctrl0: F64
    joint_qpos: tuple[int, ...]
    joint_dof: tuple[int, ...]
    actuator: tuple[int, ...]
    kp: F64
    kv: F64
    welded: tuple[str, ...]
    gravity_compensation: bool


@dataclass(frozen=True)
class Shortfall:
    """A chain joint whose servo cannot hold its links against gravity at some configuration."""

    joint: str
    #: the static torque (N m) or force (N) gravity needs at the worst configuration checked
    needed: float
    #: the servo's force limit (the URDF effort), same unit
    effort: float
    #: "N m" for a hinge, "N" for a slide
    unit: str


def holding_shortfalls(
    plant: PlantModel, chain_joints: Sequence[str], configurations: Sequence[Sequence[float]]
) -> list[Shortfall]:
    """The chain joints whose effort is below the static torque gravity needs, worst first.

    Why: a robot whose URDF leaves out a counterbalance (the PR2's shoulder springs) sags under
    physics with its stated effort; ``robotspec demo`` turns gravity compensation on for it and
    says why, instead of failing its scenario.
    """
    import mujoco  # type: ignore[import-untyped, unused-ignore]

    model = plant.model
    data = mujoco.MjData(model)
    worst: dict[str, Shortfall] = {}
    for q in configurations:
        data.qpos[:] = plant.qpos0
        data.qpos[list(plant.joint_qpos)] = q
        data.qvel[:] = 0.0
        mujoco.mj_forward(model, data)
        for i, name in enumerate(chain_joints):
            a = plant.actuator[i]
            if not model.actuator_forcelimited[a]:
                continue
            effort = float(model.actuator_forcerange[a, 1])
            dof = plant.joint_dof[i]
            needed = abs(float(data.qfrc_bias[dof] - data.qfrc_gravcomp[dof]))
            if needed > effort and (name not in worst or needed > worst[name].needed):
                slide = model.jnt_type[model.dof_jntid[dof]] == mujoco.mjtJoint.mjJNT_SLIDE
                worst[name] = Shortfall(name, needed, effort, "N" if slide else "N m")
    return sorted(worst.values(), key=lambda s: s.effort - s.needed)


@dataclass(frozen=True)
class DeadBand:
    """A chain joint whose dry friction its position servo overcomes only far from the target."""

    joint: str
    #: the URDF ``friction`` (MuJoCo's ``frictionloss``), N m or N
    friction: float
    #: the servo's stiffness, N m/rad or N/m
    stiffness: float
    #: "N m" for a hinge, "N" for a slide
    unit: str

    @property
    def band(self) -> float:
        """How far from its target the joint may stop (rad or m): friction over stiffness."""
        return self.friction / self.stiffness


def friction_dead_bands(
    plant: PlantModel, chain_joints: Sequence[str], tolerance: float
) -> list[DeadBand]:
    """The chain joints whose friction can stop them farther than ``tolerance`` from the target.

    Why: the servos' feed-forward cancels gravity and Coriolis, not dry friction; a servo
    tuned from a light wrist's inertia (Talos: 15-66 N m/rad) against the URDF's 1 N m of
    friction stalls up to 65 mrad short, and a waiting jog reports it as not arrived. Said up
    front, that is a fact of the robot's files, not a mystery of the driver.
    """
    import mujoco  # type: ignore[import-untyped, unused-ignore]

    model = plant.model
    found = []
    for i, name in enumerate(chain_joints):
        dof = plant.joint_dof[i]
        friction = float(model.dof_frictionloss[dof])
        stiffness = float(plant.kp[i])
        if friction > 0.0 and friction > tolerance * stiffness:
            slide = model.jnt_type[model.dof_jntid[dof]] == mujoco.mjtJoint.mjJNT_SLIDE
            found.append(DeadBand(name, friction, stiffness, "N" if slide else "N m"))
    return sorted(found, key=lambda d: -d.band)
