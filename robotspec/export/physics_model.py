"""The MuJoCo model a physics-backed driver steps, built from the robot's MJCF export.

Why a model of its own and not the exported file as it is: the driver commands one chain, and
everything else must stay where the robot's default configuration puts it. Joints outside the
chain (and outside its mimic followers) are welded where they can be exactly: a joint whose
default value is zero is removed (its body then sits where the MJCF places it), as is a free
joint (the export places its body at the default pose). One with another default value keeps
its position servo, which holds its default keyframe target (``ctrl``); without a servo (a
passive joint) a joint equality holds it there. Why weld rather than leave it all to the
servos: a mobile base's planar or floating drive has no servo and would drift under the arm's
reaction forces or fall under gravity, and every welded degree of freedom is one MuJoCo no
longer integrates (the PR2's right arm: 7 instead of 30). The keyframes go (their ``qpos`` no
longer fits the welded model); the plant sets the default configuration by joint name.

Everything happens in memory: the XML is edited with lxml and the meshes are handed to
MuJoCo as bytes (``MjModel.from_xml_string(xml, assets)``); nothing is written to disk. Why in
the export room: it reads the export and the robot's world; the driver package, which steps the
result (:class:`~robotspec.driver.mujoco_model.PlantModel`), stays free of both.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from lxml import etree

from robotspec.arrays import F64
from robotspec.driver.mujoco_model import PlantModel
from robotspec.errors import RobotSpecError
from robotspec.export.mjcf import MjcfExport
from robotspec.export.mjcf_bodies import nums
from robotspec.extras import MUJOCO, require
from robotspec.semantic import AbstractRobot

__all__ = ["plant_model"]


def _weld_joints(
    root: etree._Element,
    keep: set[str],
    servoed: set[str],
    values: dict[str, float],
    free: set[str],
) -> list[str]:
    """Weld the joints of ``root`` not in ``keep`` (see the module docstring); their names.

    A joint at zero (and a free joint) is removed; a servoed one elsewhere is left to its servo;
    any other is held by a joint equality at its default value.
    """
    welded: list[str] = []
    held: list[tuple[str, float]] = []
    for joint in list(root.iter("joint", "freejoint")):
        parent = joint.getparent()
        name = joint.get("name", "")
        if parent is None or parent.tag != "body" or name in keep:
            continue
        if name in free or values.get(name, 0.0) == 0.0:
            parent.remove(joint)
        elif name in servoed:
            continue
        else:
            held.append((name, values[name]))
        welded.append(name)
    removed = {n for n in welded if n not in dict(held)}
    equality = root.find("equality")
    if equality is not None:
        for eq in list(equality):
            if eq.tag != "joint":
                continue
            first, second = eq.get("joint1", ""), eq.get("joint2")
            if first in removed:
                equality.remove(eq)
            elif second is not None and second in removed:
                # the leader is welded: the follower holds its default value
                del eq.attrib["joint2"]
                eq.set("polycoef", nums((values.get(first, 0.0), 0.0, 0.0, 0.0, 0.0)))
    if held:
        if equality is None:
            equality = etree.SubElement(root, "equality")
        for name, value in held:
            etree.SubElement(equality, "joint", joint1=name, polycoef=nums((value, 0, 0, 0, 0)))
    actuators = root.find("actuator")
    if actuators is not None:
        for act in list(actuators):
            if act.get("joint") in removed:
                actuators.remove(act)
    return welded


def _start_values(
    robot: AbstractRobot,
    export: MjcfExport,
    chain_joints: Sequence[str],
    initial: Sequence[float] | F64 | None,
) -> tuple[dict[str, float], set[str]]:
    """Each exported joint's value at the start (the chain at ``initial``), and the free ones."""
    world = robot.world
    q = world.default_configuration().copy()
    dof_index = {d.name: d.index for d in world.degrees_of_freedom}
    start = [q[dof_index[n]] if n in dof_index else 0.0 for n in chain_joints]
    for name, value in zip(chain_joints, start if initial is None else initial, strict=True):
        if name not in dof_index:
            raise RobotSpecError(
                f"the chain's joint '{name}' is not a degree of freedom of {robot.name}",
                kind="joint",
                name=name,
            )
        q[dof_index[name]] = float(value)
    values: dict[str, float] = {}
    free: set[str] = set()
    for j in export.joints:
        if j.kind == "free":
            free.add(j.name)
        else:
            values[j.name] = j.multiplier * float(q[j.dof]) + j.offset
    return values, free


def _kept_joints(root: etree._Element, chain_joints: Sequence[str]) -> set[str]:
    """The chain and the mimic followers of a kept leader (their equality moves them)."""
    keep = set(chain_joints)
    couplings = [
        (eq.get("joint1", ""), eq.get("joint2"))
        for eq in root.iterfind("equality/joint")
        if eq.get("joint2") is not None
    ]
    grown = True
    while grown:
        grown = False
        for follower, leader in couplings:
            if leader in keep and follower not in keep:
                keep.add(follower)
                grown = True
    return keep


def plant_model(
    robot: AbstractRobot,
    export: MjcfExport,
    chain_joints: Sequence[str],
    initial: Sequence[float] | F64 | None = None,
    *,
    gravity_compensation: bool = False,
) -> PlantModel:
    """The MuJoCo model of ``export`` with ``chain_joints`` free and the rest as described above.

    ``initial`` is the chain's starting configuration (default: the robot's default
    configuration, as every other degree of freedom). ``gravity_compensation`` cancels gravity
    on every body (``gravcomp``, as ``mjcf_export(..., gravity_compensation=True)`` does), so
    one export serves both. Raises a
    RobotSpecError naming the joint when a chain joint has no position servo in the export.
    """
    mujoco: Any = require(MUJOCO, "--physics mujoco")
    values, free = _start_values(robot, export, chain_joints, initial)
    servoed = set(export.actuated)
    missing = [n for n in chain_joints if n not in servoed]
    if missing:
        raise RobotSpecError(
            f"the chain's joint '{missing[0]}' has no position servo in the MJCF export "
            "(only commanded 1-DOF joints get one); --physics mujoco drives servoed joints only",
            kind="joint",
            name=missing[0],
        )
    parser = etree.XMLParser(resolve_entities=False, no_network=True)
    root = etree.fromstring(export.xml.encode(), parser)
    keyframe = root.find("keyframe")
    if keyframe is not None:
        root.remove(keyframe)
    welded = _weld_joints(root, _kept_joints(root, chain_joints), servoed, values, free)
    if gravity_compensation:
        for body in root.iter("body"):
            body.set("gravcomp", "1")
    assets = {rel: produce() for rel, produce in export.meshes}
    model = mujoco.MjModel.from_xml_string(etree.tostring(root, encoding="unicode"), assets)
    # The controller's feed-forward may put a servo's target beyond a joint limit (a joint held
    # at its limit against gravity); the joint's own range still stops the arm there.
    model.actuator_ctrllimited[:] = 0
    qpos0 = np.array(model.qpos0, dtype=np.float64)
    ctrl0 = np.zeros(model.nu)
    act_of_joint = {int(model.actuator_trnid[a, 0]): a for a in range(model.nu)}
    for name, value in values.items():
        jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name)
        if jid < 0:
            continue
        qpos0[model.jnt_qposadr[jid]] = value
        if jid in act_of_joint:
            ctrl0[act_of_joint[jid]] = value
    ids = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, n) for n in chain_joints]
    actuator = tuple(act_of_joint[j] for j in ids)
    kp = np.array([model.actuator_gainprm[a, 0] for a in actuator], dtype=np.float64)
    kv = np.array([-model.actuator_biasprm[a, 2] for a in actuator], dtype=np.float64)
    return PlantModel(
        model=model,
        qpos0=qpos0,
        ctrl0=ctrl0,
        joint_qpos=tuple(int(model.jnt_qposadr[j]) for j in ids),
        joint_dof=tuple(int(model.jnt_dofadr[j]) for j in ids),
        actuator=actuator,
        kp=kp,
        kv=kv,
        welded=tuple(welded),
        gravity_compensation=bool(np.any(model.body_gravcomp > 0.0)),
    )
