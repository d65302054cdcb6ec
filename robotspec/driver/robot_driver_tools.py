"""The client API's tools and payloads: what hangs on each chain's flange, and its checks.

Why apart from :mod:`robotspec.driver.robot_driver`: attaching a tool changes the published
TCP and the configuration's sequence number, never the command mode; these members and the
frame checks they share are one job. A Cartesian jog uses :meth:`ToolCommands._check_chain`.
"""

from __future__ import annotations

import math

import numpy as np

from robotspec.arrays import F64
from robotspec.driver.conversions import as_lists, tool_transform
from robotspec.driver.errors import InvalidArgumentError
from robotspec.driver.loop import DriverLoop
from robotspec.driver.robot_info import (
    MAX_OFFSET_M,
    QUAT_TOL,
    PayloadInfo,
    Pose,
    Quaternion,
    ToolInfo,
)
from robotspec.model.rotations import quat_wxyz_to_matrix

__all__ = ["ToolCommands"]


class ToolCommands(DriverLoop):
    """Tools and payloads attached to and detached from the robot's chains."""

    def _check_chain(self, chain: int, what: str) -> None:
        if not (isinstance(chain, int) and 0 <= chain < len(self._hp)):
            raise InvalidArgumentError(f"Invalid kinematic chain {chain} for {what}")

    def tool_attached(self, chain: int, tool: ToolInfo | None) -> None:
        """A tool was attached to ``chain``: its TCP now defines the endpoint."""
        if tool is None:
            raise InvalidArgumentError("Tool cannot be null")
        with self._lock:
            self._check_chain(chain, "tool")
            if self._current_tool[chain] is not None:
                raise InvalidArgumentError(f"Tool already attached to kinematic chain {chain}")
            tf = tool_transform(tool)
            _check_frame(f"tool '{tool.name}' tcp", tool.tcp.rotation, tf)
            self._current_tool[chain] = tool
            self._tool_tf[chain] = tf
            self._tool_tf_lists[chain] = as_lists(self._tool_tf[chain])
            self._config_seqno += 1
            self.events.append(("tool_changed", chain, tool.name))

    def tool_detached(self, chain: int, tool_name: str) -> None:
        """The tool named ``tool_name`` (or "" for any) was detached from ``chain``."""
        with self._lock:
            self._check_chain(chain, "tool")
            tool = self._current_tool[chain]
            if tool is None:
                raise InvalidArgumentError(f"Tool not attached to kinematic chain {chain}")
            if self._current_payload[chain] is not None:
                raise InvalidArgumentError("Cannot remove tool while payload attached")
            if tool_name not in ("", tool.name):
                raise InvalidArgumentError(
                    f"Invalid tool name to detach: '{tool_name}' (attached: '{tool.name}')"
                )
            self._current_tool[chain] = None
            self._tool_tf[chain] = None
            self._tool_tf_lists[chain] = None
            self._config_seqno += 1
            self.events.append(("tool_changed", chain, ""))

    def payload_attached(self, chain: int, payload: PayloadInfo | None, pose: Pose | None) -> None:
        """A payload was attached to the tool of ``chain`` at ``pose`` relative to the TCP."""
        if payload is None:
            raise InvalidArgumentError("Payload cannot be null")
        with self._lock:
            self._check_chain(chain, "payload")
            if self._current_tool[chain] is None:
                raise InvalidArgumentError(
                    f"No tool attached to kinematic chain {chain}, cannot attach payload"
                )
            if self._current_payload[chain] is not None:
                raise InvalidArgumentError(f"Payload already attached to kinematic chain {chain}")
            if pose is not None:
                p = pose.position
                tf_p = (quat_wxyz_to_matrix(pose.orientation.as_tuple()), np.array([p.x, p.y, p.z]))
                _check_frame(f"payload '{payload.name}' pose", pose.orientation, tf_p)
            self._current_payload[chain] = payload
            self._current_payload_pose[chain] = pose or Pose()
            self._config_seqno += 1
            self.events.append(("payload_changed", chain, payload.name))

    def payload_detached(self, chain: int, payload_name: str) -> None:
        """The payload named ``payload_name`` (or "") was detached from ``chain``."""
        with self._lock:
            self._check_chain(chain, "payload")
            payload = self._current_payload[chain]
            if payload is None:
                raise InvalidArgumentError(f"Payload not attached to kinematic chain {chain}")
            if payload_name not in ("", payload.name):
                raise InvalidArgumentError(
                    f"Invalid payload name to detach: '{payload_name}' (attached: '{payload.name}')"
                )
            self._current_payload[chain] = None
            self._current_payload_pose[chain] = None
            self._config_seqno += 1
            self.events.append(("payload_changed", chain, ""))


def _check_frame(what: str, rotation: Quaternion, frame: tuple[F64, F64] | None) -> None:
    """Refuse a tool TCP or payload pose with NaN, infinity, bad rotation or absurd offset.

    Why here as well as in the models: a ``ToolInfo`` built with ``model_construct`` (or by
    another front end) skips validation, and a NaN TCP would be published as a NaN pose.
    """
    q = rotation.as_tuple()
    if frame is None:
        return
    values = [*q, *frame[1].tolist()]
    if not all(math.isfinite(v) for v in values):
        raise InvalidArgumentError(f"{what} must not contain NaN or infinite values")
    if abs(math.hypot(*q) - 1.0) > QUAT_TOL:
        raise InvalidArgumentError(f"{what}: rotation must be a unit quaternion")
    if max(abs(v) for v in frame[1].tolist()) > MAX_OFFSET_M:
        raise InvalidArgumentError(f"{what}: offset beyond {MAX_OFFSET_M:g} m")
