"""A world as a pinocchio model, and the record ``robot.to_pinocchio()`` returns.

Why: tools built on pinocchio (pink, crocoddyl, placo, ...) should start from a compiled robot's
semantics (its chains' tips, tool frames, cameras, allowed-collision rules) rather than from the
raw URDF. The model is built from the world model, not by re-reading the URDF, so it is the same
robot robotspec computes with: frames added by the spec, composed robots, the drive. The
collision model and the semantic frames are added in :mod:`robotspec.interop.pinocchio`.

How the world maps onto pinocchio, chosen so a robotspec configuration ``q`` is a pinocchio
configuration of the same length and meaning (:meth:`PinocchioRobot.configuration` only
reorders, and returns ``q`` itself when the orders already agree):

- revolute and continuous joints are one-coordinate revolute joints (``RX``/``RY``/``RZ`` or
  unaligned; a continuous joint is *not* pinocchio's cos/sin ``RUBX``), prismatic joints likewise;
- mimic joints are pinocchio mimic joints of their leader (no coordinate of their own);
- a planar connection is two unaligned prismatic joints and a revolute one (``name/x``,
  ``name/y``, ``name/theta``), a floating one three prismatic and three revolute joints
  (translation, then yaw, pitch, roll about fixed axes): robotspec's own parametrisation;
- fixed joints are folded into frames: every body is a ``BODY`` frame, named as the body.

Bodies carry no inertia here (robotspec's world is kinematic): dynamics algorithms need
inertias set by the caller.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

import numpy as np

from robotspec.arrays import F64, finite_array, real_array
from robotspec.errors import KinematicsError
from robotspec.extras import PINOCCHIO, require
from robotspec.model.entities import Connection, ConnectionType
from robotspec.model.world import World

__all__ = ["PinocchioRobot", "import_pinocchio", "set_limits", "to_se3", "world_to_pinocchio"]


def import_pinocchio() -> Any:
    """The pinocchio module, or a RobotSpecError saying how to install it."""
    return require(PINOCCHIO, "robot.to_pinocchio()")


@dataclass(frozen=True)
class PinocchioRobot:
    """A compiled robot as pinocchio objects, with the ids of its semantic frames.

    ``model`` is the kinematic tree, ``collision_model`` the robot's collision geometries with
    exactly the pairs robotspec checks (the SRDF's and spec's allowed-collision rules applied),
    ``pair_bodies`` the body pair of each of its collision pairs. ``frames`` maps every body
    name to its frame id; ``chain_tips``, ``tool_frames`` and ``cameras`` map the semantic
    names (chain, manipulator, camera) to frame ids.
    """

    model: Any
    collision_model: Any
    frames: Mapping[str, int]
    chain_tips: Mapping[str, int] = field(default_factory=lambda: MappingProxyType({}))
    tool_frames: Mapping[str, int] = field(default_factory=lambda: MappingProxyType({}))
    cameras: Mapping[str, int] = field(default_factory=lambda: MappingProxyType({}))
    pair_bodies: tuple[tuple[str, str], ...] = ()
    q_index: tuple[int, ...] = ()

    def configuration(self, q: object) -> F64:
        """The pinocchio configuration of a robotspec configuration ``q`` (same length)."""
        arr = real_array(q, "configuration", KinematicsError)  # complex refused, not truncated
        if arr.shape != (len(self.q_index),):
            raise KinematicsError(
                f"configuration must have shape ({len(self.q_index)},), got {arr.shape}"
            )
        finite_array(arr, "configuration", KinematicsError)
        if self.q_index == tuple(range(len(self.q_index))):
            return arr
        return arr[list(self.q_index)]


def world_to_pinocchio(world: World) -> tuple[Any, dict[str, int], tuple[int, ...]]:
    """The pinocchio model of ``world``, the frame id of every body, and the configuration order.

    The order: entry ``i`` of a pinocchio configuration is entry ``order[i]`` of robotspec's.
    """
    pin = import_pinocchio()
    model = pin.Model()
    model.name = world.name
    # Per body: the joint it moves with and its placement in that joint's frame.
    joint_of = [0] * len(world.bodies)
    placement: list[F64] = [np.eye(4) for _ in world.bodies]
    frame_of: dict[str, int] = {}
    root = world.bodies[0]
    frame_of[root.name] = model.addFrame(
        pin.Frame(root.name, 0, 0, pin.SE3.Identity(), pin.FrameType.BODY)
    )
    dof_joint: dict[int, int] = {}  # robotspec DOF -> pinocchio joint that owns it
    for c in _leaders_first(world):
        parent_joint = joint_of[c.parent]
        origin = placement[c.parent] @ np.asarray(c.origin, dtype=np.float64)
        if c.type is ConnectionType.FIXED:
            joint_of[c.child] = parent_joint
            placement[c.child] = origin
        else:
            joint_of[c.child] = _add_joints(pin, model, c, parent_joint, origin, dof_joint)
            placement[c.child] = np.eye(4)
        body = world.bodies[c.child]
        frame_of[body.name] = model.addFrame(
            pin.Frame(
                body.name,
                joint_of[c.child],
                frame_of[world.bodies[c.parent].name],
                to_se3(pin, placement[c.child]),
                pin.FrameType.BODY,
            )
        )
    order = [0] * model.nq
    for dof, jid in dof_joint.items():
        order[model.joints[jid].idx_q] = dof
    return model, frame_of, tuple(order)


def _leaders_first(world: World) -> list[Connection]:
    """The connections, parents first and every mimic joint after its leader.

    pinocchio numbers a mimic joint's leader before it; a mimic may sit in an earlier branch
    than its leader (HSR-B: the torso follows the arm lift), so such a branch waits for it.
    """
    placed = {world.bodies[0].index}
    led: set[int] = set()
    pending = list(world.connections)
    out: list[Connection] = []
    while pending:
        waiting: list[Connection] = []
        for c in pending:
            if c.parent in placed and (c.mimic is None or c.dofs[0] in led):
                out.append(c)
                placed.add(c.child)
                if c.mimic is None:
                    led.update(c.dofs)
            else:
                waiting.append(c)
        if len(waiting) == len(pending):
            c = waiting[0]
            raise KinematicsError(
                f"mimic joint '{c.name}' follows '{c.mimic.leader if c.mimic else '?'}', which "
                "is not a joint of the tree above it or beside it",
                name=c.name,
            )
        pending = waiting
    return out


def to_se3(pin: Any, m: F64) -> Any:
    """A 4 x 4 pose as a pinocchio ``SE3`` (contiguous copies: pinocchio refuses strided views)."""
    return pin.SE3(np.ascontiguousarray(m[:3, :3]), np.ascontiguousarray(m[:3, 3]))


def _one_axis(pin: Any, revolute: bool, axis: F64) -> Any:
    """The joint model of one rotation about or translation along ``axis``."""
    for k, letter in enumerate("XYZ"):
        unit = np.zeros(3)
        unit[k] = 1.0
        if np.array_equal(axis, unit):
            return getattr(pin, ("JointModelR" if revolute else "JointModelP") + letter)()
    if revolute:
        return pin.JointModelRevoluteUnaligned(axis)
    return pin.JointModelPrismaticUnaligned(axis)


def _add_joints(
    pin: Any, model: Any, c: Connection, parent: int, origin: F64, dof_joint: dict[int, int]
) -> int:
    """Add the joint(s) of moving connection ``c``; returns the joint its child moves with."""
    from robotspec.model.kinematics import _REVOLUTE, _motions

    motions = _motions(c)
    single = len(motions) == 1
    joint = parent
    for i, m in enumerate(motions):
        axis = np.asarray(m.axis, dtype=np.float64)
        jm = _one_axis(pin, m.kind == _REVOLUTE, axis)
        name = c.name if single else c.name + c.type.dof_suffixes[_suffix_index(c, i)]
        place = to_se3(pin, origin) if i == 0 else pin.SE3.Identity()
        if c.mimic is not None:
            leader = dof_joint.get(m.dof)
            if leader is None:
                raise KinematicsError(
                    f"mimic joint '{c.name}' comes before its leader '{c.mimic.leader}' in the "
                    "tree; pinocchio needs the leader first",
                    name=c.name,
                )
            lead = model.joints[leader]
            jm.setIndexes(leader, lead.idx_q, lead.idx_v, lead.idx_vExtended)
            jm = pin.JointModelMimic(jm, m.multiplier, m.offset)
            joint = model.addJoint(joint, pin.JointModel(jm), place, name)
            continue
        joint = model.addJoint(joint, jm, place, name)  # limits: see _set_limits
        dof_joint[m.dof] = joint
    return joint


def _suffix_index(c: Connection, i: int) -> int:
    """Which DOF suffix the i-th elementary motion of a multi-DOF connection carries."""
    if c.type is ConnectionType.FLOATING:
        return (0, 1, 2, 5, 4, 3)[i]  # motions: x, y, z, yaw, pitch, roll
    return i


def set_limits(model: Any, world: World, order: tuple[int, ...]) -> None:
    """Copy the DOFs' position and velocity limits (unlimited as +-1e30, as pinocchio likes)."""
    big = 1e30
    dofs = world.degrees_of_freedom
    lo = np.array([max(dofs[d].lower, -big) for d in order])
    hi = np.array([min(dofs[d].upper, big) for d in order])
    vel = np.array([min(dofs[d].velocity, big) for d in order])
    model.lowerPositionLimit = lo
    model.upperPositionLimit = hi
    model.velocityLimit = vel
