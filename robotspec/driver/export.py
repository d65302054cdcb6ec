"""A RobotInfo for any serial chain of a world: H/P kinematics, joint limits and the flange pose.

Why: the driver runs from a RobotInfo, and only a handful of real robots ship one. Deriving it
from the world model lets ``robotspec drive --spec SPEC --chain NAME`` drive every robot robotspec
can load, with kinematics that agree with the world's own forward kinematics (tested to 1e-9).

The conversion follows the general-robotics-toolbox / standard_robdef ``urdf_to_robotinfo.py``
recipe (robotraconteur_standard_robdef ``tools/urdf_to_robotinfo.py``):

* walk the connections from ``root`` to the flange body, keeping the accumulated rotation ``R``
  (the frame orientation at q = 0) and the current offset ``P[k]``;
* every connection adds ``R · origin.translation`` to ``P[k]`` and then turns ``R`` by the origin
  rotation; a movable joint then records ``H[k] = R · axis`` and opens ``P[k + 1]``;
* fixed connections therefore fold into ``P`` (and into the flange rotation when they follow the
  last joint); what remains of ``R`` at the end is the flange orientation, emitted as
  ``flange_pose`` with a zero position (the offset is already in ``P[n]``).

Choices where URDF and RobotInfo disagree, all documented in :func:`export_chain`'s arguments:

* URDF has no acceleration limit; RobotInfo requires one > 0. The default is
  :data:`DEFAULT_ACCELERATION_FACTOR` times the velocity limit (full speed in 0.2 s).
* Continuous joints become ``revolute`` with limits of ``±continuous_limit`` (the Robot Raconteur
  Companion rejects the ``continuous`` type), unless ``keep_continuous`` is set.
* A missing (infinite or zero) velocity limit becomes ``default_velocity``; an unknown effort
  limit becomes 0, the robdef's "not given".
* Mimic joints have no H/P form, and floating or planar joints no single axis: a chain containing
  one is refused with a :class:`~robotspec.errors.RobotInfoError` naming the joint and its line.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

import yaml

from robotspec.arrays import F64
from robotspec.driver.hp_form import HPForm, clean, hp_form, refuse
from robotspec.driver.robot_info import (
    DeviceClass,
    DeviceInfo,
    Identifier,
    JointEffortUnits,
    JointInfo,
    JointLimits,
    JointPositionUnits,
    JointType,
    KinChainInfo,
    Pose,
    Quaternion,
    RobotCapability,
    RobotInfo,
    RobotTypeCode,
    Vector3,
)
from robotspec.errors import RobotInfoError
from robotspec.model.rotations import matrix_to_quat_wxyz
from robotspec.model.world import Body, Connection, ConnectionType, World

__all__ = [
    "DEFAULT_ACCELERATION_FACTOR",
    "DEFAULT_CAPABILITIES",
    "ExportedRobotInfo",
    "dump_robot_info_yaml",
    "export_chain",
    "robot_info_from_chain",
]


#: Default acceleration limit = this factor times the velocity limit (full speed in 0.2 s).
DEFAULT_ACCELERATION_FACTOR = 5.0
#: What the simulated driver can do with an exported chain (it has no homing routine to export).
DEFAULT_CAPABILITIES: tuple[RobotCapability, ...] = (
    RobotCapability.jog_command,
    RobotCapability.trajectory_command,
    RobotCapability.position_command,
    RobotCapability.velocity_command,
)
#: The Robot Raconteur standard UUID of the ``robot`` device class (as in the real files).
_ROBOT_CLASS_UUID = "39b513e7-21b9-4b49-8654-7537473030eb"


@dataclass(frozen=True)
class ExportedRobotInfo:
    """The RobotInfo of a chain, and notes on every default that stood in for missing data.

    Why the notes: a user driving an exported robot should learn that its acceleration limits
    were invented, not discover it from a jog that is too gentle or too violent.
    """

    info: RobotInfo
    notes: tuple[str, ...] = ()


def _body(world: World, body: Body | str) -> Body:
    return world.get_body_by_name(body) if isinstance(body, str) else body


def _vec(v: F64) -> Vector3:
    return Vector3(x=float(v[0]), y=float(v[1]), z=float(v[2]))


def _positive(value: float, what: str) -> float:
    if not (math.isfinite(value) and value > 0.0):
        raise RobotInfoError(f"{what} must be a positive finite number, got {value!r}")
    return float(value)


def _per_joint(
    value: float | Mapping[str, float] | None, names: Iterable[str], what: str
) -> dict[str, float]:
    """A per-joint override table; an unknown joint name is an error (not a silent no-op)."""
    if value is None:
        return {}
    names = list(names)
    if isinstance(value, Mapping):
        unknown = sorted(set(value) - set(names))
        if unknown:
            raise RobotInfoError(
                f"{what} names joints not in the chain: {', '.join(unknown)} "
                f"(chain joints: {', '.join(names)})"
            )
        return {k: _positive(float(v), f"{what}['{k}']") for k, v in value.items()}
    x = _positive(float(value), what)
    return dict.fromkeys(names, x)


def export_chain(
    world: World,
    root: Body | str,
    tip: Body | str,
    *,
    device_name: str,
    flange: Body | str | None = None,
    chain_name: str | None = None,
    acceleration: float | Mapping[str, float] | None = None,
    default_velocity: float = 1.0,
    continuous_limit: float = 2.0 * math.pi,
    keep_continuous: bool = False,
    capabilities: Iterable[RobotCapability | str] = DEFAULT_CAPABILITIES,
    description: str = "",
) -> ExportedRobotInfo:
    """Build the RobotInfo of the serial chain ``root`` → ``tip`` of ``world``.

    Args:
        world: the kinematic tree.
        root: the chain's base body; the RobotInfo base frame is its frame.
        tip: the last body the chain's joints move.
        device_name: ``device_info.device.name`` (the driver's identity).
        flange: the flange body, at or below ``tip`` and joined to it by fixed connections only
            (e.g. a ``tool0`` frame); default ``tip``.
        chain_name: ``kin_chain_identifier`` (default: the device name).
        acceleration: acceleration limit for every joint, or per joint name (others default);
            default :data:`DEFAULT_ACCELERATION_FACTOR` × the velocity limit.
        default_velocity: velocity limit for joints whose description gives none (rad/s, m/s).
        continuous_limit: continuous joints get position limits ``±continuous_limit``.
        keep_continuous: emit the ``continuous`` joint type instead of ``revolute`` (the
            Robot Raconteur Companion refuses it; robotspec's driver accepts it with a warning).
        capabilities: ``robot_capabilities`` to declare.
        description: the chain's ``description``.

    Returns:
        The RobotInfo and notes on the defaults used.

    Raises:
        RobotInfoError: a mimic, floating or planar joint inside the chain, a moving joint between
            ``tip`` and ``flange``, a chain without joints, or bad limits (each names the joint).
        KinematicsError: ``root`` is not an ancestor of ``tip`` (or of ``flange``).
    """
    root_b = _body(world, root)
    tip_b = _body(world, tip)
    flange_b = tip_b if flange is None else _body(world, flange)
    _positive(default_velocity, "default_velocity")
    _positive(continuous_limit, "continuous_limit")
    form = hp_form(world, root_b, tip_b, flange_b)
    names = [world.degrees_of_freedom[c.dofs[0]].name for c in form.movable]
    accel = _per_joint(acceleration, names, "acceleration")
    notes: list[str] = []
    joints = [
        _joint_info(
            world, c, accel.get(name), default_velocity, continuous_limit, keep_continuous, notes
        )
        for c, name in zip(form.movable, names, strict=True)
    ]
    defaulted_accel = [name for name in names if name not in accel]
    if defaulted_accel:
        notes.append(
            f"the description gives no acceleration limits: {DEFAULT_ACCELERATION_FACTOR:g} x "
            f"the velocity limit used for {', '.join(defaulted_accel)}"
        )
    chain = _chain_info(world, form, root_b, flange_b, chain_name or device_name, description)
    info = RobotInfo(
        device_info=_device_info(world, device_name, root_b, flange_b),
        robot_type=RobotTypeCode.serial,
        robot_capabilities=tuple(RobotCapability(x) for x in capabilities),
        joint_info=tuple(joints),
        chains=(chain,),
    )
    return ExportedRobotInfo(info=info, notes=tuple(notes))


def _joint_info(
    world: World,
    c: Connection,
    acceleration: float | None,
    default_velocity: float,
    continuous_limit: float,
    keep_continuous: bool,
    notes: list[str],
) -> JointInfo:
    """One movable joint as a RobotInfo joint; each default that stands in adds to ``notes``."""
    dof = world.degrees_of_freedom[c.dofs[0]]
    name = dof.name
    prismatic = c.type is ConnectionType.PRISMATIC
    lower, upper = float(dof.lower), float(dof.upper)
    jtype = JointType.prismatic if prismatic else JointType.revolute
    if c.type is ConnectionType.CONTINUOUS or not (math.isfinite(lower) and math.isfinite(upper)):
        if prismatic:
            raise refuse(world, c, "has no position limits; a RobotInfo joint needs them")
        if c.type is ConnectionType.CONTINUOUS and keep_continuous:
            jtype = JointType.continuous
        lower = max(lower, -continuous_limit)
        upper = min(upper, continuous_limit)
        notes.append(
            f"joint '{name}' ({c.type.value}) has no position limits: "
            f"[{lower:.6g}, {upper:.6g}] used"
        )
    velocity = float(dof.velocity)
    if not (math.isfinite(velocity) and velocity > 0.0):
        notes.append(
            f"joint '{name}' has no velocity limit: {default_velocity:g} "
            f"{'m/s' if prismatic else 'rad/s'} used"
        )
        velocity = default_velocity
    if acceleration is None:
        acceleration = float(f"{DEFAULT_ACCELERATION_FACTOR * velocity:.12g}")
    effort = float(dof.effort) if math.isfinite(dof.effort) and dof.effort > 0 else 0.0
    try:
        limits = JointLimits(
            lower=lower,
            upper=upper,
            home=min(max(0.0, lower), upper),
            velocity=velocity,
            acceleration=acceleration,
            effort=effort,
        )
    except ValueError as exc:  # pydantic's ValidationError is a ValueError
        raise refuse(world, c, f"has unusable limits: {exc}") from None
    return JointInfo(
        joint_identifier=Identifier(name=name),
        joint_type=jtype,
        joint_limits=limits,
        default_units=JointPositionUnits.meter if prismatic else JointPositionUnits.radian,
        default_effort_units=JointEffortUnits.newton
        if prismatic
        else JointEffortUnits.newton_meter,
    )


def _chain_info(
    world: World, form: HPForm, root: Body, flange: Body, name: str, description: str
) -> KinChainInfo:
    """The chain's H/P record, with its flange pose (rotation only: the offset is ``P[n]``)."""
    q = matrix_to_quat_wxyz(form.flange_rotation)
    flange_pose = Pose(
        orientation=Quaternion(w=float(q[0]), x=float(q[1]), y=float(q[2]), z=float(q[3])),
        position=Vector3(x=0.0, y=0.0, z=0.0),
    )
    link_ids = (
        Identifier(name=root.name),
        *(Identifier(name=world.bodies[c.child].name) for c in form.movable),
    )
    return KinChainInfo(
        kin_chain_identifier=Identifier(name=name),
        H=tuple(_vec(h) for h in form.h),
        P=tuple(_vec(clean(p)) for p in form.p),
        link_identifiers=link_ids,
        joint_numbers=tuple(range(len(form.movable))),
        flange_pose=flange_pose,
        flange_identifier=Identifier(name=flange.name),
        description=description,
    )


def _device_info(world: World, device_name: str, root: Body, flange: Body) -> DeviceInfo:
    return DeviceInfo(
        device=Identifier(name=device_name),
        model=Identifier(name=world.name),
        user_description=f"{world.name}: chain {root.name} -> {flange.name}, exported by robotspec",
        device_classes=(
            DeviceClass(
                class_identifier=Identifier.model_validate(
                    {"name": "robot", "uuid": _ROBOT_CLASS_UUID}
                ),
                subclasses=("serial",),
            ),
        ),
        implemented_types=("com.robotraconteur.robotics.robot.Robot",),
    )


def robot_info_from_chain(
    world: World,
    root: Body | str,
    tip: Body | str,
    *,
    device_name: str,
    flange: Body | str | None = None,
    **options: Any,
) -> RobotInfo:
    """The RobotInfo of ``root`` → ``tip`` (see :func:`export_chain` for the options)."""
    return export_chain(world, root, tip, device_name=device_name, flange=flange, **options).info


#: Joint limit keys the real files never write; left out when zero (zero means "not given").
_ZERO_LIMIT_KEYS = frozenset(
    {"jerk", "reduced_velocity", "reduced_acceleration", "reduced_jerk", "reduced_effort"}
)


def _prune(value: Any, key: str = "") -> Any:
    """Drop empty strings, lists and maps, and unset optional limits, recursively."""
    if isinstance(value, dict):
        out: dict[str, Any] = {}
        for k, v in value.items():
            if key == "joint_limits" and k in _ZERO_LIMIT_KEYS and v == 0:
                continue
            if k == "config_seqno" and v == 0:
                continue
            pv = _prune(v, k)
            if pv is None or pv == "" or pv == [] or pv == {}:
                continue
            out[k] = pv
        return out
    if isinstance(value, list):
        return [_prune(v, key) for v in value]
    return value


def dump_robot_info_yaml(info: RobotInfo, *, header: str = "") -> str:
    """The RobotInfo as YAML that :func:`~robotspec.driver.robot_info.load_robot_info` reads back.

    Why not ``exclude_defaults``: the reference parser fills a missing key with the robdef's zero
    value, not with robotspec's default, so ``joint_type``, ``default_units``, ``lower`` and
    ``upper`` are always written (a missing ``joint_type`` would read as ``unknown`` there). Only
    empty values and unset optional limits are left out. Floats are written with ``repr``
    precision, so the round trip is exact. ``header`` becomes ``#`` comment lines at the top
    (where the real files say where they come from).
    """
    data = _prune(info.model_dump(mode="json", exclude_none=True))
    text = yaml.safe_dump(data, sort_keys=False, default_flow_style=False, width=100)
    if header:
        lines = "".join(f"# {line}\n".replace("# \n", "#\n") for line in header.splitlines())
        text = lines + text
    return text
