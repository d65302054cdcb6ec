"""Conversions between the driver's typed values and Robot Raconteur structures.

The driver core (:mod:`robotspec.driver`) knows nothing about Robot Raconteur; this module turns
its snapshots and models into the standard robdef structures and back. Everything on the RR side
is ``Any`` (no stubs); the driver side stays typed.

Why RobotInfo goes through the Companion ``InfoParser``: it is what every reference driver uses, so
the structure clients receive is built exactly as theirs is. robotspec validates the YAML first
(strictly, with located errors), then hands the parser a cleaned dict: non-empty maps
(``extended``, ``associated_devices``, ``tags``), which the parser cannot read, are left out, and a
missing ``flange_pose`` becomes the identity the driver uses (the parser would leave an all-zero
quaternion).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from pydantic import ValidationError

from robotspec.driver.errors import InvalidArgumentError
from robotspec.driver.loop import RobotJointCommand, TrajectoryStatus
from robotspec.driver.robot_info import (
    DeviceInfo,
    Identifier,
    JointType,
    PayloadInfo,
    Pose,
    Quaternion,
    RobotInfo,
    ToolInfo,
    Transform,
    Vector3,
)
from robotspec.driver.state import RobotState
from robotspec.driver.trajectory import CHUNK, JointTrajectory, TrajectoryColumns, pause
from robotspec.service.node import rr

__all__ = [
    "ROBOT_INFO_TYPE",
    "StateStructs",
    "from_varvalue",
    "payload_from_rr",
    "pose_from_rr",
    "release_waypoints",
    "robot_info_dict",
    "joint_command_from_rr",
    "to_varvalue",
    "tool_from_rr",
    "trajectory_from_rr",
]


ROBOT_INFO_TYPE = "com.robotraconteur.robotics.robot.RobotInfo"
_MAP_KEYS = frozenset({"extended", "associated_devices", "tags"})
_IDENTITY_POSE = {
    "orientation": {"w": 1.0, "x": 0.0, "y": 0.0, "z": 0.0},
    "position": {"x": 0.0, "y": 0.0, "z": 0.0},
}


def _prune(value: Any, dropped: list[str], path: str) -> Any:
    if isinstance(value, dict):
        out = {}
        for k, v in value.items():
            where = f"{path}.{k}" if path else str(k)
            if k in _MAP_KEYS:
                if v:
                    dropped.append(where)
                continue
            if isinstance(v, dict | list) and not v:
                continue
            out[k] = _prune(v, dropped, where)
        return out
    if isinstance(value, list):
        return [_prune(v, dropped, f"{path}[{i}]") for i, v in enumerate(value)]
    return value


def robot_info_dict(info: RobotInfo) -> tuple[dict[str, Any], list[str]]:
    """The RobotInfo as the dict the Companion parser reads, and the map fields left out."""
    data = info.model_dump(mode="json", exclude_none=True)
    for chain, model in zip(data.get("chains", []), info.chains, strict=True):
        if model.flange_pose is None:
            chain["flange_pose"] = _IDENTITY_POSE
    dropped: list[str] = []
    return _prune(data, dropped, ""), dropped


# ---------------------------------------------------------------------------- client -> driver


def trajectory_from_rr(traj: Any, n: int) -> JointTrajectory | TrajectoryColumns:
    """A ``JointTrajectory`` structure as the driver's columns for ``n`` joints.

    Straight into arrays (:class:`~robotspec.driver.trajectory.TrajectoryColumns`), a chunk of
    waypoints at a time, making no object per waypoint: a 35,000-waypoint upload used to become
    35,000 ``Waypoint`` objects with their tuples and floats first, work that held the
    interpreter the driver loop needs. The checks themselves are the driver's (the reference's
    order and messages). A null waypoint list is handed on as such (the driver refuses it in
    the reference's order); null fields are refused.
    """
    if traj is None:
        raise InvalidArgumentError("Trajectory must not be null")
    names = tuple(traj.joint_names or ())
    wps = traj.waypoints
    if wps is None:
        return JointTrajectory(joint_names=names, waypoints=None)
    m = len(wps)
    cols = TrajectoryColumns.empty(m, n, names)
    velocities: Any = None
    for start in range(0, m, CHUNK):
        for i in range(start, min(m, start + CHUNK)):
            w = wps[i]
            if w is None:
                raise InvalidArgumentError(f"Waypoint {i} must not be null")
            jp = _array(w.joint_position, i, "joint_position")
            jv = _array(w.joint_velocity, i, "joint_velocity")
            cols.lengths[i] = jp.shape[0]
            cols.option_sizes[i] = (
                jv.shape[0],
                _array(w.position_tolerance, i, "tolerance").shape[0],
                _array(w.velocity_tolerance, i, "tolerance").shape[0],
            )
            cols.times[i] = float(w.time_from_start)
            if jp.shape[0] == n:
                cols.positions[i] = jp
            if jv.shape[0] == n:
                if velocities is None:
                    velocities = np.full((m, n), np.nan)
                velocities[i] = jv
        pause()
    if velocities is None:
        return cols
    return TrajectoryColumns(
        cols.joint_names, cols.times, cols.positions, cols.lengths, cols.option_sizes, velocities
    )


def release_waypoints(traj: Any) -> None:
    """Empty a decoded ``JointTrajectory``'s waypoint list a chunk at a time.

    Why: once converted, the decoded waypoints (one structure and four arrays each) are
    garbage, and Robot Raconteur drops them all at once when the call returns: for 35,000
    waypoints one deallocation cascade of 26 ms that holds the interpreter, two or more of the
    loop's periods. Emptied here from the end, a chunk at a time with a pause between, no
    single step holds it for more than a fraction of a millisecond. Harmless for the caller's
    structure: Robot Raconteur's own copy is the message, already decoded.
    """
    wps = getattr(traj, "waypoints", None)
    if not isinstance(wps, list):
        return
    while wps:
        del wps[-CHUNK:]
        pause()


def _array(values: Any, i: int, what: str) -> Any:
    """A waypoint's array as float64, 1-D (Robot Raconteur already decodes ``double[]`` so)."""
    if isinstance(values, np.ndarray) and values.dtype == np.float64 and values.ndim == 1:
        return values  # what Robot Raconteur hands over: no copy, no check
    try:
        return np.asarray(values if values is not None else (), dtype=np.float64).reshape(-1)
    except (TypeError, ValueError):
        raise InvalidArgumentError(f"waypoint {i} {what} must be an array of numbers") from None


def joint_command_from_rr(cmd: Any, unit_names: dict[int, str]) -> RobotJointCommand:
    """A ``RobotJointCommand`` with its numeric units named (unknown codes stay unknown)."""
    units = tuple(unit_names.get(int(u), f"unknown_{int(u)}") for u in cmd.units)
    return RobotJointCommand(
        seqno=int(cmd.seqno),
        state_seqno=int(cmd.state_seqno),
        command=np.asarray(cmd.command, dtype=np.float64).reshape(-1),  # RR's array, no copy
        units=units,
    )


def _quaternion(w: float, x: float, y: float, z: float) -> Quaternion:
    # An all-zero quaternion is a structure nobody filled in: the reference (the toolbox's
    # q2R) treats it as the identity, and so does this adapter.
    if w == 0.0 and x == 0.0 and y == 0.0 and z == 0.0:
        w = 1.0
    return Quaternion(w=w, x=x, y=y, z=z)


def _named(value: Any) -> Any:
    """A named-array element (``value[0]`` of a 1-element array, or the scalar itself)."""
    arr = np.asarray(value)
    return arr.reshape(-1)[0] if arr.shape else arr[()]


def pose_from_rr(pose: Any) -> Pose:
    """A ``com.robotraconteur.geometry.Pose`` named array as a :class:`Pose`."""
    if pose is None:
        return Pose()
    p = _named(pose)
    o, t = p["orientation"], p["position"]
    try:
        return Pose(
            orientation=_quaternion(float(o["w"]), float(o["x"]), float(o["y"]), float(o["z"])),
            position=Vector3(x=float(t["x"]), y=float(t["y"]), z=float(t["z"])),
        )
    except ValidationError as exc:
        raise InvalidArgumentError(f"invalid pose: {exc.errors()[0]['msg']}") from None


def _transform(tf: Any) -> Transform:
    if tf is None:
        return Transform()
    t = _named(tf)
    r, p = t["rotation"], t["translation"]
    try:
        return Transform(
            rotation=_quaternion(float(r["w"]), float(r["x"]), float(r["y"]), float(r["z"])),
            translation=Vector3(x=float(p["x"]), y=float(p["y"]), z=float(p["z"])),
        )
    except ValidationError as exc:
        raise InvalidArgumentError(f"invalid tool tcp: {exc.errors()[0]['msg']}") from None


def _device_name(device_info: Any) -> str:
    if device_info is None or device_info.device is None:
        return ""
    return str(device_info.device.name or "")


def tool_from_rr(tool: Any) -> ToolInfo | None:
    """A ``ToolInfo`` structure as the driver's ToolInfo: its name and TCP (what it uses)."""
    if tool is None:
        return None
    name = _device_name(tool.device_info)
    return ToolInfo(device_info=DeviceInfo(device=Identifier(name=name)), tcp=_transform(tool.tcp))


def payload_from_rr(payload: Any) -> PayloadInfo | None:
    """A ``PayloadInfo`` structure as the driver's PayloadInfo (its name)."""
    if payload is None:
        return None
    name = _device_name(payload.device_info)
    return PayloadInfo(device_info=DeviceInfo(device=Identifier(name=name)))


def spatial_velocity_from_rr(value: Any) -> list[float]:
    """A ``SpatialVelocity`` named array as ``[wx, wy, wz, vx, vy, vz]``."""
    v = _named(value)
    a, lin = v["angular"], v["linear"]
    return [
        float(a["x"]),
        float(a["y"]),
        float(a["z"]),
        float(lin["x"]),
        float(lin["y"]),
        float(lin["z"]),
    ]


def from_varvalue(value: Any) -> Any:
    """The data of a ``varvalue`` (RR hands the server a VarValue; its data may be an array)."""
    return getattr(value, "data", value)


# ---------------------------------------------------------------------------- driver -> client


def to_varvalue(value: Any) -> Any:
    """A driver value (bool, int, float, str, or a float array) as a ``varvalue``.

    Raises:
        TypeError: a value of another type (a driver bug, reported to the client as such).
    """
    rrmod = rr()
    if isinstance(value, bool | np.bool_):
        return rrmod.VarValue(bool(value), "bool")
    if isinstance(value, int | np.integer):
        return rrmod.VarValue(int(value), "int64")
    if isinstance(value, float | np.floating):
        return rrmod.VarValue(float(value), "double")
    if isinstance(value, str):
        return rrmod.VarValue(value, "string")
    if isinstance(value, np.ndarray):
        return rrmod.VarValue(np.asarray(value, dtype=np.float64).reshape(-1), "double[]")
    raise TypeError(f"no varvalue for a {type(value).__name__}")


class StateStructs:
    """Builds the state structures clients read, reusing one instance of each.

    Why reuse: the loop publishes every period, and a structure is packed into a message the
    moment it is assigned to a wire, so one instance per type is enough; allocating none keeps
    the per-step cost (the benchmark's figure) down.

    Args:
        node: the RR node whose registered types are used.
        info: the robot, for joint units and chain count.
        wall_epoch: wall-clock seconds (Unix time) at loop time zero, for ``ts``.
    """

    def __init__(self, node: Any, info: RobotInfo, wall_epoch: float) -> None:
        robot = "com.robotraconteur.robotics.robot."
        self._rs = node.GetStructureType(robot + "RobotState")()
        self._ars = node.GetStructureType(robot + "AdvancedRobotState")()
        self._pose_dtype = node.GetNamedArrayDType("com.robotraconteur.geometry.Pose")
        self._vel_dtype = node.GetNamedArrayDType("com.robotraconteur.geometry.SpatialVelocity")
        self._ts_dtype = node.GetNamedArrayDType("com.robotraconteur.datetime.TimeSpec3")
        joints = node.GetConstants("com.robotraconteur.robotics.joints")
        pos_units = joints["JointPositionUnits"]
        eff_units = joints["JointEffortUnits"]
        prismatic = [j.joint_type is JointType.prismatic for j in info.joint_info]
        # Deviation: the reference reports radian / newton_meter for every joint, prismatic too.
        self._pos_units = np.array(
            [pos_units["meter"] if p else pos_units["radian"] for p in prismatic], dtype=np.uint8
        )
        self._eff_units = np.array(
            [eff_units["newton"] if p else eff_units["newton_meter"] for p in prismatic],
            dtype=np.uint8,
        )
        self._no_units = np.zeros(0, dtype=np.uint8)
        self._wall_epoch = wall_epoch
        self._n_chains = len(info.chains)
        self._ts = np.zeros(1, dtype=self._ts_dtype)
        self._poses = np.zeros(self._n_chains, dtype=self._pose_dtype)
        self._pose_view = self._poses.view(np.float64).reshape(self._n_chains, 7)
        self._vels = np.zeros(self._n_chains, dtype=self._vel_dtype)
        self._vel_view = self._vels.view(np.float64).reshape(self._n_chains, 6)
        self._no_poses = np.zeros(0, dtype=self._pose_dtype)
        self._no_vels = np.zeros(0, dtype=self._vel_dtype)

    def timestamp_us(self, st: RobotState) -> int:
        """Microseconds since the Unix epoch of the step that produced ``st``."""
        return int(round((self._wall_epoch + st.ts) * 1e6))

    def _fill(self, s: Any, st: RobotState) -> None:
        self._ts[0]["microseconds"] = self.timestamp_us(st)
        s.ts = self._ts
        s.seqno = st.seqno
        s.command_mode = int(st.command_mode)
        s.operational_mode = int(st.operational_mode)
        s.controller_state = int(st.controller_state)
        s.robot_state_flags = int(st.flags)
        s.joint_position = st.joint_position
        s.joint_velocity = st.joint_velocity
        s.joint_effort = st.joint_effort
        s.joint_position_command = st.position_command
        s.joint_velocity_command = st.velocity_command
        tcp = st.kin_chain_tcp
        if len(tcp) == self._n_chains:
            pv = self._pose_view
            for i, pose in enumerate(tcp):
                pv[i, :4] = pose.orientation
                pv[i, 4:] = pose.position
            s.kin_chain_tcp = self._poses
        else:
            s.kin_chain_tcp = self._no_poses
        vel = st.kin_chain_tcp_vel
        if len(vel) == self._n_chains:
            vv = self._vel_view
            for i, twist in enumerate(vel):
                vv[i, :] = twist
            s.kin_chain_tcp_vel = self._vels
        else:
            s.kin_chain_tcp_vel = self._no_vels
        s.trajectory_running = st.trajectory_running

    def robot_state(self, st: RobotState) -> Any:
        """The ``RobotState`` structure of ``st`` (the same instance every call)."""
        self._fill(self._rs, st)
        return self._rs

    def advanced_robot_state(self, st: RobotState) -> Any:
        """The ``AdvancedRobotState`` structure of ``st`` (the same instance every call)."""
        s = self._ars
        self._fill(s, st)
        have_q = st.joint_position.shape[0] > 0
        s.joint_position_units = self._pos_units if have_q else self._no_units
        s.joint_effort_units = self._eff_units if have_q else self._no_units
        s.trajectory_time = st.trajectory_time
        s.trajectory_max_time = st.trajectory_max_time
        s.trajectory_current_waypoint = st.trajectory_current_waypoint
        s.config_seqno = st.config_seqno
        return s


def trajectory_status(node: Any, status: TrajectoryStatus) -> Any:
    """A ``TrajectoryStatus`` structure."""
    s = node.GetStructureType("com.robotraconteur.robotics.trajectory.TrajectoryStatus")()
    s.seqno = status.seqno
    s.action_status = int(status.action_status)
    s.current_waypoint = status.current_waypoint
    s.trajectory_time = status.trajectory_time
    return s


def event_log_messages(node: Any, device: Any, messages: Sequence[str], utc_now: Any) -> list[Any]:
    """``EventLogMessage`` structures (level error) for the driver's current errors."""
    msg_type = node.GetStructureType("com.robotraconteur.eventlog.EventLogMessage")
    hdr_type = node.GetStructureType("com.robotraconteur.eventlog.EventLogMessageHeader")
    levels = node.GetConstants("com.robotraconteur.eventlog")["EventLogLevel"]
    out = []
    for i, text in enumerate(messages):
        hdr = hdr_type()
        hdr.level = levels["error"]
        hdr.source_device = device
        hdr.source_component = "robotspec.driver"
        hdr.message_number = i + 1
        hdr.timestamp = utc_now
        m = msg_type()
        m.header = hdr
        m.title = text.split(":")[0]
        m.message = text
        out.append(m)
    return out
