"""The compiler's second pass: create the semantic parts once every name has resolved.

Nothing here checks anything; :func:`robotspec.compiler.build.build_robot` only calls
:func:`assemble` when the first pass recorded no error, so every lookup below succeeds.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TypedDict

from robotspec.compiler.context import Build
from robotspec.compiler.parts import CameraValues
from robotspec.model.geometry import UNIT_TOL
from robotspec.model.world import Body, World
from robotspec.semantic import (
    AbstractRobot,
    Arm,
    Camera,
    CollisionCheckingConfig,
    FieldOfView,
    Finger,
    GenericManipulator,
    GenericSensor,
    Hand,
    JointState,
    KinematicChain,
    Manipulator,
    Neck,
    ParallelGripper,
    Sensor,
    Torso,
    front_facing_axis_of,
)
from robotspec.spec.models import CameraSpec, FingerSpec, HandSpec, ParallelGripperSpec

__all__ = ["Resolved", "assemble", "drive_type"]


@dataclass(frozen=True)
class Resolved:
    """What the first pass resolved: the bodies each part starts and ends at."""

    root: Body
    torso: tuple[Body, Body] | None
    neck: tuple[Body, Body] | None
    manipulators: dict[str, tuple[Body, Body]]
    chains: dict[str, tuple[Body, Body]]
    cameras: dict[str, CameraValues]
    velocity: dict[str, float]


class _ManipulatorFields(TypedDict):
    """What every manipulator kind takes (typed, so ``**`` keeps mypy's checks)."""

    name: str
    root: Body
    world: World
    tool_frame: Body
    front_facing_orientation: tuple[float, float, float, float]
    front_facing_axis: tuple[float, float, float]
    states: dict[str, JointState]


def _part_states(b: Build, prefix: str) -> dict[str, JointState]:
    """The states recorded for one part, keyed without the part's prefix."""
    cut = len(prefix) + 1
    return {k[cut:]: v for k, v in b.states.items() if k.startswith(prefix + ".")}


def _sensors(b: Build, r: Resolved) -> dict[str, Sensor]:
    w = b.world
    out: dict[str, Sensor] = {}
    for name, spec in b.spec.sensors.items():
        body = w.get_body_by_name(spec.body)
        if isinstance(spec, CameraSpec):
            v = r.cameras[name]
            out[name] = Camera(
                name=name,
                root=body,
                world=w,
                forward_facing_axis=v.forward_facing_axis,
                field_of_view=FieldOfView(vertical_angle=v.vertical, horizontal_angle=v.horizontal),
                minimal_height=v.minimal_height,
                maximal_height=v.maximal_height,
                default_camera=spec.default,
            )
        else:
            out[name] = GenericSensor(name=name, root=body, world=w, kind=spec.kind)
    return out


def _finger(w: World, name: str, f: FingerSpec) -> Finger:
    return Finger(
        name=name, root=w.get_body_by_name(f.root), world=w, tip=w.get_body_by_name(f.tip)
    )


def _manipulators(b: Build, r: Resolved) -> dict[str, Manipulator]:
    w = b.world
    out: dict[str, Manipulator] = {}
    for name, spec in b.spec.manipulators.items():
        mroot, tool = r.manipulators[name]
        ax = spec.front_facing_axis or front_facing_axis_of(spec.front_facing_orientation)
        axis = (float(ax[0]), float(ax[1]), float(ax[2]))
        common = _ManipulatorFields(
            name=name,
            root=mroot,
            world=w,
            tool_frame=tool,
            front_facing_orientation=spec.front_facing_orientation,
            front_facing_axis=axis,
            states=_part_states(b, name),
        )
        if isinstance(spec, ParallelGripperSpec):
            thumb = _finger(w, f"{name}_thumb", spec.thumb)
            finger = _finger(w, f"{name}_finger", spec.finger)
            out[name] = ParallelGripper(**common, finger=finger, thumb=thumb)
        elif isinstance(spec, HandSpec):
            out[name] = Hand(
                **common,
                thumb=_finger(w, f"{name}_thumb", spec.thumb),
                fingers={k: _finger(w, f"{name}_{k}", f) for k, f in spec.fingers.items()},
            )
        else:
            out[name] = GenericManipulator(**common)
    return out


def assemble(b: Build, r: Resolved, robot_class: type[AbstractRobot]) -> AbstractRobot:
    """Create the robot and its parts as views over the (prepared) world."""
    spec, w = b.spec, b.world
    cfg = spec.collision
    robot = robot_class(
        name=spec.name,
        root=r.root,
        world=w,
        default_collision_config=CollisionCheckingConfig(
            buffer_zone_distance=cfg.buffer_distance, violated_distance=cfg.violated_distance
        ),
        srdf=b.srdf,
        drive_type=drive_type(b),
        forward_axis=forward_axis(b),
        controlled_joint_names=None
        if spec.controlled_joints is None
        else tuple(spec.controlled_joints),
        sdt_class=None if spec.sdt is None else spec.sdt.class_,
    )
    sensors = _sensors(b, r)
    manipulators = _manipulators(b, r)
    if spec.torso is not None and r.torso is not None:
        tr, tt = r.torso
        robot.add_torso(
            Torso(name="torso", root=tr, world=w, tip=tt, states=_part_states(b, "torso"))
        )
    if spec.neck is not None and r.neck is not None:
        n = spec.neck
        nr, nt = r.neck
        robot.add_neck(
            Neck(
                name="neck",
                root=nr,
                world=w,
                tip=nt,
                sensors=[sensors[s] for s in n.sensors],
                pitch_body=None if n.pitch_body is None else w.get_body_by_name(n.pitch_body),
                yaw_body=None if n.yaw_body is None else w.get_body_by_name(n.yaw_body),
                states=_part_states(b, "neck"),
            )
        )
    _add_chains(robot, b, r, sensors, manipulators)
    carried = {s.name for ch in robot.kinematic_chains for s in ch.sensors}
    for name, sensor in sensors.items():
        if name not in carried:
            robot.add_sensor(sensor)
    for manipulator in manipulators.values():
        if manipulator not in robot.manipulators:
            robot.add_manipulator(manipulator)
    robot.joint_states.update(b.states)
    if r.velocity:
        w.tighten_velocity_limits(r.velocity)
    robot.disabled_collision_bodies.update(cfg.disabled_bodies)
    if cfg.use_srdf:
        robot.load_srdf()
    return robot


def drive_type(b: Build) -> str:
    """The base drive: declared in the spec, else read from the connection above the root."""
    if b.spec.drive is not None:
        return b.spec.drive.type
    root = b.robot_root
    parent = None if root is None else b.world.parent_connection(root)
    if parent is None or parent.is_fixed:
        return "fixed"
    return {"planar": "omni", "floating": "floating"}.get(parent.type.value, parent.type.value)


def forward_axis(b: Build) -> tuple[float, float, float]:
    """The spec's ``forward`` (checked by :func:`check_forward`), unit length; default +x."""
    f = b.spec.forward
    if f is None:
        return (1.0, 0.0, 0.0)
    n = math.sqrt(sum(x * x for x in f)) or 1.0
    return (f[0] / n, f[1] / n, f[2] / n)


def check_forward(b: Build) -> None:
    """The robot's forward axis must be a horizontal unit vector of its root's frame."""
    f = b.spec.forward
    if f is None:
        return
    n = math.sqrt(sum(x * x for x in f))
    if abs(n - 1.0) > UNIT_TOL:
        b.diag.error(("forward",), f"must be a unit vector, its length is {n:.4g}")
    elif abs(f[2]) > UNIT_TOL:
        b.diag.error(
            ("forward",),
            f"must be horizontal (z = 0) in the root's frame: the robot faces along the "
            f"ground, not {list(f)}",
        )


def _add_chains(
    robot: AbstractRobot,
    b: Build,
    r: Resolved,
    sensors: Mapping[str, Sensor],
    manipulators: Mapping[str, Manipulator],
) -> None:
    """Each spec chain as an arm (when it carries a manipulator) or a plain kinematic chain."""
    spec, w = b.spec, b.world
    for name, c in spec.chains.items():
        cr, ct = r.chains[name]
        sensors_of = [sensors[s] for s in c.sensors]
        if c.manipulator is not None:
            robot.add_arm(
                Arm(
                    name=name,
                    root=cr,
                    world=w,
                    tip=ct,
                    manipulator=manipulators[c.manipulator],
                    sensors=sensors_of,
                    states=_part_states(b, name),
                    side=c.side,
                )
            )
            continue
        robot.add_kinematic_chain(
            KinematicChain(
                name=name,
                root=cr,
                world=w,
                tip=ct,
                sensors=sensors_of,
                states=_part_states(b, name),
            ),
            warn=False,
        )
