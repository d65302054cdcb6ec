"""The publisher thread: packs each step's state into the robdef structures and sends it.

Why a thread of its own: Robot Raconteur packs a structure the moment it is assigned to a wire,
about 0.15 ms or more per structure on a small VM, most of a step's cost. The control loop only
queues the (immutable) snapshot through :meth:`StatePublisher.publish`; it never waits for
serialisation or for the network, and its timing does not depend on how many clients read.

The wires and the pipe belong to the service object (Robot Raconteur creates them when the object
is registered); the publisher reads them from it once :meth:`StatePublisher.attach` says they
exist.
"""

from __future__ import annotations

import queue
import threading
from typing import Any

from robotspec.driver.robot_info import RobotInfo
from robotspec.driver.state import RobotState
from robotspec.service import convert
from robotspec.service.node import companion, rr

__all__ = [
    "CONNECTION_CHECK_STEPS",
    "IDLE_REFRESH_S",
    "PUBLISH_BACKLOG",
    "StatePublisher",
]

#: How often (loop steps) the publisher asks RR which streams have clients connected.
CONNECTION_CHECK_STEPS = 8
#: Streams nobody is connected to are still refreshed this often (s), for ``PeekInValue()``.
IDLE_REFRESH_S = 0.1
#: Steps the publisher thread may fall behind before the oldest are dropped (wires only ever
#: carry the latest value; the sensor-data pipe loses those samples, counted).
PUBLISH_BACKLOG = 8


def _ignore(*_: Any) -> None:
    """Completion handler for fire-and-forget pipe packets."""


class StatePublisher:
    """Sends every queued state to the service's wires and pipe, from a thread of its own.

    Args:
        wires: the service object whose ``robot_state``, ``advanced_robot_state``,
            ``robot_state_sensor_data`` and ``device_clock_now`` members RR created.
        node: the RR node (its registered types build the structures).
        info: the robot (joint units, chain count).
        device_info: the RR DeviceInfo structure, for the sensor-data and clock headers.
        wall_epoch: Unix time of the driver loop's time zero (for timestamps).
    """

    def __init__(
        self, wires: Any, node: Any, info: RobotInfo, device_info: Any, wall_epoch: float
    ) -> None:
        self._wires = wires
        self._device_info = device_info
        self._structs = convert.StateStructs(node, info, wall_epoch)
        self._datetime_util = companion("Util.DateTimeUtil").DateTimeUtil(node)
        self._sensor_data_util = companion("Util.SensorDataUtil").SensorDataUtil(node)
        self._sensor_data_type = node.GetStructureType(
            "com.robotraconteur.robotics.robot.RobotStateSensorData"
        )
        self._lock = threading.Lock()
        self._context: Any = None
        self._downsampler: Any = None
        self._ready = False
        self._steps_since_check = CONNECTION_CHECK_STEPS
        self._ars_connected = self._pipe_connected = self._clock_connected = False
        self._last_idle_refresh = -float("inf")
        #: Steps that failed to publish, and the last such failure (kept for diagnosis).
        self.errors = 0
        self.last_error = ""
        #: States handed to the thread, and those it dropped because it fell behind.
        self.published = 0
        self.dropped = 0
        self._queue: queue.SimpleQueue[RobotState | None] = queue.SimpleQueue()
        #: The thread that packs and sends the states (its CPU time is the publishing cost).
        self.thread = threading.Thread(target=self._run, name="robotspec-rr-publisher", daemon=True)
        self.thread.start()

    def attach(self, context: Any) -> None:
        """The wires exist (called from ``RRServiceObjectInit``): start sending."""
        self._context = context
        self._ready = True

    def close(self) -> None:
        """Stop sending and end the thread (idempotent)."""
        self._ready = False
        self._queue.put(None)
        if self.thread is not threading.current_thread():
            self.thread.join(timeout=2.0)

    def downsampler(self) -> Any:
        """The broadcast downsampler, created when a client first asks for downsampling.

        Why lazily: stepping it costs every loop step, and until somebody sets
        ``isoch_downsample`` every client receives every step anyway.
        """
        with self._lock:
            if self._downsampler is None:
                w = self._wires
                ds = rr().BroadcastDownsampler(self._context, 0)
                ds.AddWireBroadcaster(w.robot_state)
                ds.AddWireBroadcaster(w.advanced_robot_state)
                ds.AddPipeBroadcaster(w.robot_state_sensor_data)
                ds.AddWireBroadcaster(w.device_clock_now)
                self._downsampler = ds
            return self._downsampler

    @property
    def current_downsampler(self) -> Any:
        """The downsampler if one was created, else None."""
        return self._downsampler

    def publish(self, st: RobotState) -> None:
        """Queue one step's state (a driver state listener, called by the loop thread)."""
        if self._ready:
            self._queue.put(st)

    def _run(self) -> None:
        """Thread body: send every queued state in order; wires get only the latest."""
        q = self._queue
        while True:
            batch = [q.get()]
            while True:
                try:
                    batch.append(q.get_nowait())
                except queue.Empty:
                    break
            states = [st for st in batch if st is not None]
            closing = len(states) != len(batch)  # the close() sentinel was among them
            if len(states) > PUBLISH_BACKLOG:
                # Fallen behind (a CPU hiccup): the oldest are dropped, and publishing goes on.
                self.dropped += len(states) - PUBLISH_BACKLOG
                states = states[-PUBLISH_BACKLOG:]
            for i, st in enumerate(states):
                self._publish_step(st, latest=i == len(states) - 1)
            self.published += len(states)
            if closing:
                return

    def _publish_step(self, st: RobotState, latest: bool) -> None:
        """Send one step's state to the clients (never raises).

        ``robot_state`` is set every step. ``advanced_robot_state`` and ``device_clock_now`` are
        set every step while a client is connected to them, and otherwise refreshed at
        :data:`IDLE_REFRESH_S` intervals so that ``PeekInValue()`` still answers; the sensor
        data pipe is fed only while connected. Who is connected is asked every
        :data:`CONNECTION_CHECK_STEPS` steps. Why: packing a structure is most of the cost, so
        only what somebody reads is packed. When the publisher has fallen behind, wires are set
        for the ``latest`` state only (a wire carries the latest value anyway), unless a client
        asked for downsampling.
        """
        if not self._ready:
            return
        try:
            ds = self._downsampler
            if ds is not None:
                ds.BeginStep()
            try:
                # With a downsampler every step counts (each client gets every n-th): none of
                # the wires may be skipped then.
                self._send(st, latest or ds is not None)
            finally:
                if ds is not None:
                    ds.EndStep()
        except Exception as exc:  # noqa: BLE001 - the publisher must keep going
            # Counted and kept for diagnosis; the next step tries again.
            self.errors += 1
            self.last_error = f"{type(exc).__name__}: {exc}"

    def _send(self, st: RobotState, latest: bool = True) -> None:
        w = self._wires
        if latest:
            w.robot_state.OutValue = self._structs.robot_state(st)
        self._steps_since_check += 1
        if self._steps_since_check >= CONNECTION_CHECK_STEPS:
            self._steps_since_check = 0
            self._ars_connected = w.advanced_robot_state.ActiveWireConnectionCount > 0
            self._pipe_connected = w.robot_state_sensor_data.ActivePipeEndpointCount > 0
            self._clock_connected = w.device_clock_now.ActiveWireConnectionCount > 0
        idle_refresh = latest and st.ts - self._last_idle_refresh >= IDLE_REFRESH_S
        if idle_refresh:
            self._last_idle_refresh = st.ts
        ars_wire = (self._ars_connected or idle_refresh) and latest
        if ars_wire or self._pipe_connected:
            ars = self._structs.advanced_robot_state(st)
            if ars_wire:
                w.advanced_robot_state.OutValue = ars
            if self._pipe_connected:
                data = self._sensor_data_type()
                data.data_header = self._sensor_data_util.FillSensorDataHeader(
                    self._device_info, st.seqno
                )
                data.robot_state = ars
                w.robot_state_sensor_data.AsyncSendPacket(data, _ignore)
        if (self._clock_connected or idle_refresh) and latest:
            w.device_clock_now.OutValue = self._datetime_util.FillDeviceTime(
                self._device_info, st.seqno
            )
