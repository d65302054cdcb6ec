"""A compiled robot as MuJoCo's MJCF: every body, the spec's semantics, servos, keyframes.

Why not MuJoCo's own URDF reader: it drops every link on a fixed joint (the tool frames with
them), every COLLADA mesh and every velocity limit, adds no actuators and knows nothing of an
SRDF. robotspec has the whole robot compiled (composed parts joined, frames added, names
resolved, disabled pairs read), so the export writes MJCF from the world model:

* one ``<body>`` per body (fixed links too), placed by its joint's origin; a joint per moving
  connection, named as robotspec names it; a floating drive is a ``<freejoint>``;
* inertials and damping from the URDF (:mod:`robotspec.export.mjcf_dynamics`), meshes as binary
  STL (:mod:`robotspec.export.mjcf_meshes`);
* each manipulator's tool frame as a ``<site>`` named after the tool frame, each camera as a
  ``<camera>`` with its vertical field of view, looking along the spec's forward axis;
* disabled collision pairs as ``<exclude>``, disabled bodies' geoms colliding with nothing,
  mimic joints as ``<equality><joint>`` couplings;
* one position servo per commanded 1-DOF joint, range and effort from its limits, gains from
  its largest inertia over a few configurations
  (:func:`robotspec.export.mjcf_dynamics.joint_inertias`);
* the default configuration and every named state as a ``<key>``.

What MJCF cannot hold (velocity limits) is listed in a comment at the top of the file.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from lxml import etree

from robotspec.arrays import F64
from robotspec.export.mjcf_bodies import TINY_MASS, BodyWriter, MjcfJoint, num, nums
from robotspec.export.mjcf_dynamics import Inertial, joint_inertias
from robotspec.model.entities import Connection, ConnectionType
from robotspec.model.rotations import matrix_to_quat_wxyz, rpy_to_matrix
from robotspec.semantic import AbstractRobot
from robotspec.semantic.base import JointState

__all__ = ["MjcfExport", "MjcfJoint", "SERVO_HZ", "mjcf_export", "named_states"]

#: The natural frequency every position servo is tuned to (critically damped), in Hz.
SERVO_HZ = 8.0


@dataclass(frozen=True)
class MjcfExport:
    """The MJCF text, its mesh files, the joints in MuJoCo's qpos order, and the notes."""

    xml: str
    meshes: tuple[tuple[str, Callable[[], bytes]], ...]
    joints: tuple[MjcfJoint, ...]
    actuated: tuple[str, ...]
    notes: tuple[str, ...]

    def qpos(self, robot: AbstractRobot, q: Sequence[float] | F64) -> F64:
        """MuJoCo's ``qpos`` for robotspec's configuration ``q`` (mimic joints followed)."""
        values = np.asarray(q, dtype=np.float64)
        out: list[float] = []
        for j in self.joints:
            if j.kind != "free":
                out.append(j.multiplier * float(values[j.dof]) + j.offset)
                continue
            c = robot.world.connections[j.connection]
            x, y, z, roll, pitch, yaw = (float(values[d]) for d in c.dofs)
            moved = np.eye(4)
            moved[:3, :3] = rpy_to_matrix(roll, pitch, yaw)
            moved[:3, 3] = (x, y, z)
            pose = c.origin @ moved
            out.extend(float(v) for v in pose[:3, 3])
            out.extend(float(v) for v in matrix_to_quat_wxyz(pose[:3, :3]))
        return np.asarray(out, dtype=np.float64)


def named_states(robot: AbstractRobot) -> dict[str, JointState]:
    """Every named state by its keyframe name: the robot's own keys, then ``hand.open``.

    ``annotate mjcf`` names its keyframes the same way (one function for both).
    """
    found = dict(robot.joint_states)
    for m in robot.manipulators:
        for state_name, state in m.states.items():
            found.setdefault(f"{m.name}.{state_name}", state)
    return found


def mjcf_export(
    robot: AbstractRobot,
    tree: etree._Element,
    *,
    name: str,
    servo_hz: float = SERVO_HZ,
    gravity_compensation: bool = False,
) -> MjcfExport:
    """The MJCF of ``robot``; ``tree`` is its joined URDF (inertials, damping), ``name`` the stem.

    The meshes go to the folder ``NAME_meshes`` beside the MJCF file (its ``meshdir``).
    ``gravity_compensation`` cancels gravity on every body (MuJoCo's ``gravcomp``), as a
    counterbalanced arm (PR2: springs the URDF does not describe) or a controller's gravity
    feed-forward does; without it, joints whose URDF effort cannot hold their links sag.
    """
    world = robot.world
    b = BodyWriter(robot, tree, f"{name}_meshes")
    root_el = etree.Element("mujoco", model=robot.name)
    compiler = etree.SubElement(root_el, "compiler", angle="radian", autolimits="true")
    compiler.set("meshdir", f"{name}_meshes")
    compiler.set("inertiafromgeom", "false")
    compiler.set("balanceinertia", "true")
    etree.SubElement(root_el, "option", timestep="0.002", integrator="implicitfast")
    default = etree.SubElement(root_el, "default")
    visual = etree.SubElement(etree.SubElement(default, "default", {"class": "visual"}), "geom")
    visual.attrib.update({"contype": "0", "conaffinity": "0", "group": "2"})
    collision = etree.SubElement(default, "default", {"class": "collision"})
    etree.SubElement(collision, "geom", group="3")
    asset = etree.SubElement(root_el, "asset")
    worldbody = etree.SubElement(root_el, "worldbody")
    root = world.bodies[0]
    b.body(worldbody, root, None)
    for child in world.child_bodies(root):
        conn = world.parent_connection(child)
        if conn is not None and conn.type is ConnectionType.FLOATING:
            b.body(worldbody, child, conn)  # the root sits at the origin: same place
    if gravity_compensation:
        for body_el in worldbody.iter("body"):
            body_el.set("gravcomp", "1")
    for asset_name, file_name, scale in b.assets.declarations():
        mesh = etree.SubElement(asset, "mesh", name=asset_name, file=file_name)
        if scale != (1.0, 1.0, 1.0):
            mesh.set("scale", nums(scale))
    if not len(asset):
        root_el.remove(asset)
    order = [b.joints[el.get("name", "")] for el in worldbody.iter("joint", "freejoint")]
    _couplings(root_el, robot)
    servoed = _servos(root_el, robot, b.inertials, servo_hz)
    out = MjcfExport("", tuple(b.assets.files()), tuple(order), (), ())
    _keyframes(root_el, robot, out, servoed)
    header = _header(robot, servo_hz, gravity_compensation) + [f" note: {n} " for n in b.notes]
    for i, text in enumerate(header):
        root_el.insert(i, etree.Comment(text.replace("--", "- -")))
    etree.indent(root_el, space="  ")
    xml = etree.tostring(root_el, encoding="unicode") + "\n"
    actuated = tuple(c.name for c in servoed)
    return MjcfExport(xml, out.meshes, out.joints, actuated, tuple(b.notes))


def _couplings(root_el: etree._Element, robot: AbstractRobot) -> None:
    """Pairs robotspec never checks as ``<exclude>``; mimic joints as ``<equality><joint>``.

    The pairs are the SRDF's and spec's disabled ones and the adjacent ones (MoveIt's
    adjacency, which robotspec's own checker skips unless the SRDF re-enables them). Why the
    adjacent ones too: MuJoCo filters a body and its parent only when the parent moves, so a
    fixed base (or one the physics driver welds) collided with its first link where their
    hulls overlap (Go2's hips inside its trunk pushed the hind leg 2 mrad off its target).

    MuJoCo's polycoef reads ``joint1 - ref1 = a0 + a1 (joint2 - ref2)``: the URDF's offset, then
    its multiplier (no ``ref`` is written, so both references are zero).
    """
    from robotspec.collision.rules import CollisionRules, pair_key

    world = robot.world
    rules = CollisionRules.from_robot(robot)
    stated = {pair_key(*sorted(p)) for p in robot.disabled_collision_pairs if len(p) == 2}
    adjacent = {p for p in rules.adjacent if not rules.is_checked(*p)}
    pairs = sorted(stated | adjacent)
    if pairs:
        contact = etree.SubElement(root_el, "contact")
        for first, second in pairs:
            etree.SubElement(contact, "exclude", body1=first, body2=second)
    mimics = [(c, c.mimic) for c in world.connections if c.mimic is not None]
    if mimics:
        equality = etree.SubElement(root_el, "equality")
        for c, mimic in mimics:
            leader = world.connections_of_dof(c.dofs[0])[0].name
            coef = (mimic.offset, mimic.multiplier, 0.0, 0.0, 0.0)
            etree.SubElement(equality, "joint", joint1=c.name, joint2=leader, polycoef=nums(coef))


def _servos(
    root_el: etree._Element, robot: AbstractRobot, inertials: Mapping[str, Inertial], hz: float
) -> list[Connection]:
    """The servoed connections, each with a position servo (the commanded 1-DOF joints).

    Each servo is critically damped at ``hz`` from its joint's largest inertia over
    :func:`_tuning_configurations`; the drive's joint has none (a base is not
    position-controlled).
    """
    world = robot.world
    drive = robot.drive
    servoed = [
        c
        for c in world.connections
        if c.is_active and c.is_1dof and (drive is None or c.index != drive.index)
    ]
    if not servoed:
        return servoed
    inertia: dict[str, float] = {}
    for q in _tuning_configurations(robot):
        found = joint_inertias(world, robot.kinematics.forward(q), inertials, servoed)
        for name, value in found.items():
            inertia[name] = max(inertia.get(name, 0.0), value)
    omega = 2.0 * math.pi * hz
    actuator = etree.SubElement(root_el, "actuator")
    for c in servoed:
        dof = world.degrees_of_freedom[c.dofs[0]]
        m = max(inertia[c.name], TINY_MASS)
        act = etree.SubElement(actuator, "position", name=c.name, joint=c.name)
        act.set("kp", num(m * omega * omega))
        act.set("kv", num(2.0 * m * omega))
        if c.type is not ConnectionType.CONTINUOUS and dof.is_bounded:
            act.set("ctrlrange", nums((dof.lower, dof.upper)))
        if math.isfinite(dof.effort) and dof.effort > 0.0:
            act.set("forcerange", nums((-dof.effort, dof.effort)))
    return servoed


def _tuning_configurations(robot: AbstractRobot, samples: int = 8) -> list[F64]:
    """The default configuration, the named states and ``samples`` seeded ones within limits.

    Why not the default alone: a joint's inertia depends on the rest of the arm. At a default
    that folds the arm onto an axis (Kinova's: its base joint sees 1/400 of what it sees with
    the arm stretched out) a servo tuned there is a hundred times too soft and rings for
    seconds. Tuned at the largest inertia seen, it is critically damped or stiffer everywhere.
    """
    world = robot.world
    q0 = world.default_configuration()
    found = [q0] + [world.configuration(s.as_dict()) for s in named_states(robot).values()]
    rng = np.random.default_rng(0)  # the same gains every export
    for _ in range(samples):
        q = q0.copy()
        for dof in world.degrees_of_freedom:
            if dof.is_bounded:
                q[dof.index] = rng.uniform(dof.lower, dof.upper)
            else:
                q[dof.index] = rng.uniform(-math.pi, math.pi)
        found.append(q)
    return found


def _keyframes(
    root_el: etree._Element, robot: AbstractRobot, out: MjcfExport, servoed: list[Connection]
) -> None:
    """The default configuration and every named state as a ``<key>`` (servo targets too)."""
    world = robot.world
    keys = [("default", world.default_configuration())]
    for key_name, state in named_states(robot).items():
        keys.append((key_name, world.configuration(state.as_dict())))
    qpos_index: dict[str, int] = {}
    at = 0
    for j in out.joints:  # a free joint takes 7 entries of qpos (position, quaternion)
        qpos_index[j.name] = at
        at += 7 if j.kind == "free" else 1
    keyframe = etree.SubElement(root_el, "keyframe")
    for key_name, q in keys:
        qpos = out.qpos(robot, q)
        key = etree.SubElement(keyframe, "key", name=key_name, qpos=nums(qpos))
        if servoed:
            key.set("ctrl", nums([qpos[qpos_index[c.name]] for c in servoed]))


def _header(robot: AbstractRobot, servo_hz: float, gravity_compensation: bool) -> list[str]:
    """The comments at the top: what MJCF cannot hold (velocity limits), servos, gravity."""
    limited = [
        f"{d.name}: {num(d.velocity)}"
        for d in robot.world.degrees_of_freedom
        if math.isfinite(d.velocity)
    ]
    return [
        f" {robot.name}: exported by robotspec (robotspec export mjcf). ",
        " MJCF cannot hold velocity limits; the robot's, per degree of freedom (rad/s or m/s): "
        + ("; ".join(limited) if limited else "none")
        + " ",
        f" Position servos: critically damped at {servo_hz:g} Hz from each joint's largest "
        "inertia (default, named states, 8 seeded configurations); forcerange is the URDF effort. ",
        " Gravity compensated on every body (gravcomp). "
        if gravity_compensation
        else " Gravity acts in full: an effort limit that cannot hold a link lets it sag. ",
    ]
