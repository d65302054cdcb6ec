"""What a client's call gets back: completions of blocking calls and trajectory generators.

Kept apart from the loop so the service adapter and tests can name these without the loop's
internals; the generator's methods step or wait on the driver that made it.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterator
from contextlib import AbstractContextManager
from dataclasses import dataclass
from typing import Protocol

from robotspec.arrays import F64
from robotspec.driver.errors import (
    OperationAbortedError,
)
from robotspec.driver.state import ActionStatus
from robotspec.driver.stretch import Stretch
from robotspec.driver.trajectory import TrajectoryInterpolator
from robotspec.errors import DriverError

__all__ = [
    "Completion",
    "HomingDriver",
    "HomingGenerator",
    "TrajectoryDriver",
    "TrajectoryGenerator",
    "TrajectoryStatus",
]


#: ``Next()`` returns ``running`` after this long without an outcome (reference: 5 s).
NEXT_TIMEOUT_S = 5.0


class _Locked(Protocol):
    @property
    def _lock(self) -> AbstractContextManager[object]: ...
    def _wait_for(self, predicate: Callable[[], bool], timeout: float) -> None: ...


class TrajectoryDriver(_Locked, Protocol):
    """What a trajectory generator needs of its driver (the driver's motion commands).

    Why a protocol: the driver module makes generators; naming its class here would tie this
    module and the driver's into a loop.
    """

    @property
    def _traj_active(self) -> TrajectoryTask | None: ...
    @property
    def _state_seqno(self) -> int: ...
    def _abort_trajectory(self, task: TrajectoryTask) -> None: ...
    def _cancel_trajectory(self, task: TrajectoryTask) -> None: ...


class HomingDriver(_Locked, Protocol):
    """What a homing generator needs of its driver: start homing, and halt."""

    def home(self, wait: bool = True) -> Completion:
        """Start homing; with ``wait``, return when homed."""
        ...

    def halt(self) -> None:
        """Stop motion (command mode ``halt``)."""
        ...


@dataclass(frozen=True)
class TrajectoryStatus:
    """What ``Next()`` returns: action status, trajectory time and current waypoint.

    ``stretch`` (not in the robdef) says how the trajectory was slowed to stay within the joint
    limits, None when it runs as planned: a client learns it from the first ``Next()``.
    """

    action_status: ActionStatus
    trajectory_time: float = 0.0
    current_waypoint: int = 0
    seqno: int = 0
    stretch: Stretch | None = None


class Completion:
    """The outcome of an asynchronous driver operation (a jog, homing), set exactly once."""

    def __init__(self) -> None:
        self._event = threading.Event()
        self.error: DriverError | None = None

    @property
    def done(self) -> bool:
        """Whether the operation has finished (either way)."""
        return self._event.is_set()

    def succeed(self) -> None:
        """Finish successfully (ignored if already finished)."""
        if not self._event.is_set():
            self._event.set()

    def fail(self, error: DriverError) -> None:
        """Finish with ``error`` (ignored if already finished)."""
        if not self._event.is_set():
            self.error = error
            self._event.set()


class TrajectoryTask:
    """One trajectory's life: queued, ready (awaiting the first Next), running, finished."""

    def __init__(self, interp: TrajectoryInterpolator) -> None:
        self.interp = interp
        self.next_called = False
        self.started = False
        self.start_time = 0.0
        self.time = 0.0
        self.waypoint = 0
        self.last_setpoint: F64 | None = None
        self.complete = False
        self.error: DriverError | None = None
        self.outcome_reported = False
        self.reported_queued = False

    @property
    def finished(self) -> bool:
        return self.complete or self.error is not None

    def fail(self, error: DriverError) -> None:
        if not self.finished:
            self.error = error


class TrajectoryGenerator:
    """The generator ``execute_trajectory`` returns: call ``Next()`` until StopIteration.

    ``Next()`` blocks until the trajectory completes, fails, or 5 s pass (then ``running``).
    ``Abort()`` stops the robot (mode ``halt``); ``Close()`` cancels this trajectory only.
    Also a Python iterator: ``for status in gen: ...``.
    """

    def __init__(self, driver: TrajectoryDriver, task: TrajectoryTask) -> None:
        self._driver = driver
        self._task = task

    def Next(self) -> TrajectoryStatus:  # noqa: N802 - the Robot Raconteur generator API
        """Advance: start (first call), then wait for an outcome; StopIteration when done."""
        d = self._driver
        task = self._task
        with d._lock:
            if task.outcome_reported:
                raise StopIteration
            if task.error is not None:
                task.outcome_reported = True
                raise task.error
            if task.complete:
                task.outcome_reported = True
                return self._status(ActionStatus.complete)
            queued = task is not d._traj_active
            first = not task.next_called
            task.next_called = True
            if queued and first:
                task.reported_queued = True
                return TrajectoryStatus(
                    ActionStatus.queued, 0.0, 0, d._state_seqno, task.interp.stretch
                )
            if task.reported_queued and not queued:
                # It started since the client last heard "queued": say so at once.
                task.reported_queued = False
                return self._status(ActionStatus.running)

        def outcome() -> bool:
            # A queued task reports ``running`` as soon as it becomes active (as the reference).
            return task.finished or (queued and task is d._traj_active)

        d._wait_for(outcome, NEXT_TIMEOUT_S)
        with d._lock:
            if task.outcome_reported:
                # Another Next() waiting beside this one delivered the outcome: one completion
                # per generator, so this caller gets the end of the iteration.
                raise StopIteration
            if task.error is not None:
                task.outcome_reported = True
                raise task.error
            if task.complete:
                task.outcome_reported = True
                return self._status(ActionStatus.complete)
            if task is not d._traj_active:
                return TrajectoryStatus(
                    ActionStatus.queued, 0.0, 0, d._state_seqno, task.interp.stretch
                )
            task.reported_queued = False
            return self._status(ActionStatus.running)

    def _status(self, status: ActionStatus) -> TrajectoryStatus:
        t = self._task
        return TrajectoryStatus(
            status, t.time, t.waypoint, self._driver._state_seqno, t.interp.stretch
        )

    def Abort(self) -> None:  # noqa: N802
        """Stop the robot: mode becomes ``halt``; ``Next()`` fails with OperationAborted."""
        d = self._driver
        with d._lock:
            if self._task.finished:
                return
            self._task.fail(OperationAbortedError("Trajectory execution aborted"))
            d._abort_trajectory(self._task)

    def Close(self) -> None:  # noqa: N802
        """Cancel this trajectory (the whole queue if it is active); the mode stays."""
        d = self._driver
        with d._lock:
            if self._task.finished:
                return
            self._task.fail(OperationAbortedError("Trajectory execution cancelled"))
            d._cancel_trajectory(self._task)

    def __iter__(self) -> Iterator[TrajectoryStatus]:
        return self

    def __next__(self) -> TrajectoryStatus:
        return self.Next()


class HomingGenerator:
    """The generator ``home()`` returns over Robot Raconteur (``ActionStatusCode{generator}``).

    The first ``Next()`` starts homing (the robot must be in ``homing`` mode); each ``Next()``
    answers ``complete`` once homed, or ``running`` every 5 s until then; the outcome (complete
    or the error) is delivered to exactly one caller, however many wait concurrently, and every
    later ``Next()`` raises StopIteration. ``Abort()`` and ``Close()`` stop homing (mode
    ``halt``): a waiting ``Next()`` then fails with OperationAborted.
    """

    def __init__(self, driver: HomingDriver) -> None:
        self._driver = driver
        self._completion: Completion | None = None
        self._reported = False
        self._lock = threading.Lock()

    def Next(self) -> ActionStatus:  # noqa: N802 - the Robot Raconteur generator API
        """Start homing (first call), then wait up to 5 s for it to end."""
        d = self._driver
        with self._lock:
            if self._reported:
                raise StopIteration
            if self._completion is None:
                self._completion = d.home(wait=False)
            completion = self._completion
        d._wait_for(lambda: completion.done, NEXT_TIMEOUT_S)
        if not completion.done:
            return ActionStatus.running
        with self._lock:
            if self._reported:
                raise StopIteration
            self._reported = True
        if completion.error is not None:
            raise completion.error
        return ActionStatus.complete

    def Abort(self) -> None:  # noqa: N802
        """Stop homing: mode ``halt``."""
        self._driver.halt()

    def Close(self) -> None:  # noqa: N802
        """Stop homing if it is still going, as :meth:`Abort`."""
        if self._completion is not None and not self._completion.done:
            self._driver.halt()
