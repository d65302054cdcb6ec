"""Step 5 of the timestep: state flags, each chain's TCP pose and twist, the published snapshot."""

from __future__ import annotations

import struct

import numpy as np

from robotspec.arrays import F64
from robotspec.driver.modes import ModeMachine
from robotspec.driver.state import (
    ESTOP_SOURCE_FLAGS,
    StateFlags,
    TcpPose,
    frozen_array,
    robot_state_snapshot,
    tcp_pose_snapshot,
)
from robotspec.model.rotations import matrix_to_quat_wxyz_tuple

__all__ = ["StateFill"]


class StateFill(ModeMachine):
    """Step 5: what the loop publishes each step."""

    def _fill_state_flags(self, now: float) -> None:
        """The ``robot_state_flags`` word; communication failure is reported alone."""
        if self._communication_failure:
            self._flags = StateFlags.communication_failure
            self._flags_int = int(StateFlags.communication_failure)
            return
        f = 0
        if self._error or self._fault_message:
            f |= _F_ERROR
        if self._stopped:
            f |= _F_ESTOP | int(ESTOP_SOURCE_FLAGS.get(self._estop_source, 0))
        if self._enabled:
            f |= _F_ENABLED
        if self._ready:
            f |= _F_READY
        if self._uses_homing:
            f |= _F_HOMED if self._homed else _F_HOMING_REQUIRED
        f |= int(self._stream_valid)
        if self._traj_active is not None and not self._traj_failed_this_step:
            f |= _F_TRAJ
        if f != self._flags_int:
            self._flags_int = f
            self._flags = StateFlags(f)

    def _calc_endpoint_poses(self) -> list[TcpPose]:
        """TCP pose of every chain (tool applied), base frame; also the TCP velocities.

        Cached on (q, qd, tools): an idle robot costs nothing here.
        """
        q = self._joint_position
        qd = self._joint_velocity
        key = (q.tobytes(), qd.tobytes(), self._config_seqno)
        if key == self._endpoint_key and self._endpoint_cache is not None:
            poses, vels = self._endpoint_cache
            self._endpoint_vel = vels
            return poses
        poses = []
        vels = []
        q_list = q.tolist()
        qd_list = qd.tolist() if qd.shape[0] == self._joint_count else None
        for c, hp in enumerate(self._hp):
            tf = self._tool_tf_lists[c]
            if self._chain_is_all[c]:  # one chain of every joint, in order: no gather
                q_c, qd_c = q_list, qd_list
            else:
                idx = self._chain_idx_list[c]
                q_c = [q_list[i] for i in idx]
                qd_c = None if qd_list is None else [qd_list[i] for i in idx]
            rot, pos, twist = hp.tcp_state(
                q_c, qd_c, None if tf is None else tf[0], None if tf is None else tf[1]
            )
            # One read-only array per chain, sliced into position, orientation and twist
            # (views of a read-only buffer stay read-only): one allocation instead of three.
            tcp = np.frombuffer(
                _PACK_TCP(*pos, *matrix_to_quat_wxyz_tuple(rot), *twist)
            )  # read-only
            poses.append(tcp_pose_snapshot(tcp[0:3], tcp[3:7]))
            vels.append(tcp[7:13])
        self._endpoint_key = key
        self._endpoint_cache = (poses, vels)
        self._endpoint_vel = vels
        return poses

    def _calc_endpoint_pose(self, chain: int) -> TcpPose:
        """TCP pose of ``chain`` (tool applied)."""
        poses = self._endpoint_pose or self._calc_endpoint_poses()
        return poses[chain]

    def _calc_endpoint_vels(self) -> list[F64]:
        """TCP spatial velocity ``[angular, linear]`` of every chain."""
        if self._endpoint_vel is None:
            self._calc_endpoint_poses()
        return list(self._endpoint_vel or [])

    def _calc_endpoint_vel(self, chain: int) -> F64:
        """TCP spatial velocity of ``chain``."""
        return self._calc_endpoint_vels()[chain]

    def _fill_states(self, now: float) -> None:
        """Step 5: flags, endpoint poses and velocities, and the published snapshot."""
        self._fill_state_flags(now)
        comm_ok = not self._communication_failure
        have_q = self._joint_position.shape[0] == self._joint_count
        if comm_ok and have_q:
            self._endpoint_pose = self._calc_endpoint_poses()
        else:
            self._endpoint_pose = None
            self._endpoint_vel = None
        task = self._traj_active
        self._state = robot_state_snapshot(
            ts=now,
            seqno=self._state_seqno,
            command_mode=self._command_mode,
            operational_mode=self._operational_mode,
            controller_state=self._controller_state,
            flags=self._flags,
            joint_position=frozen_array(self._joint_position),
            joint_velocity=frozen_array(self._joint_velocity),
            joint_effort=frozen_array(self._joint_effort),
            position_command=frozen_array(self._position_command),
            velocity_command=frozen_array(self._velocity_command),
            kin_chain_tcp=tuple(self._endpoint_pose or ()),
            kin_chain_tcp_vel=tuple(self._endpoint_vel or ()),
            trajectory_running=bool(self._flags_int & _F_TRAJ),
            trajectory_time=0.0 if task is None else task.time,
            trajectory_max_time=0.0 if task is None else task.interp.max_time,
            trajectory_current_waypoint=0 if task is None else task.waypoint,
            trajectory_stretch=1.0 if task is None else task.interp.stretch_at(task.waypoint),
            config_seqno=self._config_seqno,
            speed_ratio=self._speed_ratio,
            error_message=self._fault_message,
        )


#: Position, orientation and twist of one TCP as packed bytes (a read-only array's buffer).
_PACK_TCP = struct.Struct("13d").pack

_F_ERROR = int(StateFlags.error)
_F_ESTOP = int(StateFlags.estop)
_F_ENABLED = int(StateFlags.enabled)
_F_READY = int(StateFlags.ready)
_F_HOMED = int(StateFlags.homed)
_F_HOMING_REQUIRED = int(StateFlags.homing_required)
_F_TRAJ = int(StateFlags.trajectory_running)
