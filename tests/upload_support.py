"""Helpers for the trajectory-upload tests: a clock that counts the loop thread's own work.

Issue 31: a long trajectory uploaded to a running driver stalled its loop. Whether the loop
*itself* does work proportional to the trajectory is a property of the code, not of the
machine, so it is tested with :class:`WorkClock`: simulated time that advances by a fixed cost
for every function the loop thread calls (a profile hook installed on that thread only), and by
the sleeps the loop asks for. The loop's own counters (:meth:`DriverLoop.loop_stats`) then count
a missed period exactly when the loop thread did more than a period's worth of calls in a step:
a busy or loaded machine changes nothing, and a loop that decoded, checked or planned 20,000
waypoints in a step (tens of thousands of calls) would miss dozens.
"""

from __future__ import annotations

import sys
import threading
import time
from types import FrameType
from typing import Any

import numpy as np

from robotspec.driver.clock import SimClock
from robotspec.driver.sim import SimRobot

#: Simulated seconds charged per function call on the loop thread (a generous 1 us).
CALL_COST_S = 1e-6

#: Functions whose work is proportional to the trajectory: none may run on the loop thread.
PLANNING = frozenset(
    {
        "load_trajectory",
        "_check_and_plan",
        "columns_of",
        "_rows",
        "_floats",
        "time_scale",
        "TrajectoryInterpolator.__init__",
        "trajectory_from_rr",
        "release_waypoints",
        "UnpackMessageElement",
        "_CallFunction",
    }
)


class WorkClock(SimClock):
    """Simulated time charged by the loop thread's calls; sleeps jump (and yield a moment).

    Only the loop thread moves it (its profile hook charges, its sleeps jump), so it needs no
    lock; a lock here would be taken again by the hook on the lock's own ``__exit__`` call.
    """

    def charge(self, seconds: float) -> None:
        self._t += seconds

    def sleep_until(self, deadline: float) -> None:
        time.sleep(0.0002)  # let the other threads run: the loop thread never really sleeps
        if deadline > self._t:
            self._t = deadline


class LoopThreadProfile:
    """A profile hook for the loop thread: charges the clock and records what ran there."""

    def __init__(self, clock: WorkClock) -> None:
        self.clock = clock
        self.names: set[str] = set()
        self.installed = threading.Event()
        self.thread: threading.Thread | None = None

    def __call__(self, frame: FrameType, event: str, arg: Any) -> None:
        if event == "call":
            self.names.add(frame.f_code.co_qualname)
            self.clock.charge(CALL_COST_S)
        elif event == "c_call":
            self.names.add(getattr(arg, "__qualname__", getattr(arg, "__name__", "?")))
            self.clock.charge(CALL_COST_S)

    def install(self, robot: SimRobot) -> None:
        """Install the hook on the running loop thread (from inside it) and wait for it."""

        def on_loop_thread() -> None:
            self.thread = threading.current_thread()
            sys.setprofile(self)
            self.installed.set()

        robot.at(robot._stopwatch_ellapsed_s(), on_loop_thread)
        assert self.installed.wait(30), "the loop thread never ran the hook's installation"

    def remove(self, robot: SimRobot) -> None:
        """Remove the hook from the loop thread."""
        done = threading.Event()

        def on_loop_thread() -> None:
            sys.setprofile(None)
            done.set()

        robot.at(robot._stopwatch_ellapsed_s(), on_loop_thread)
        assert done.wait(30)

    def planning_on_loop_thread(self) -> set[str]:
        """The functions proportional to the trajectory that ran on the loop thread."""
        return {name for name in self.names if name.split(".")[-1] in PLANNING or name in PLANNING}


def sway(q0: np.ndarray, lower: np.ndarray, upper: np.ndarray, m: int) -> tuple[Any, Any]:
    """Times and positions of a slow ``m``-waypoint sway around ``q0`` at 10 ms spacing."""
    t = np.arange(m) * 0.01
    amp = np.minimum(0.2, 0.4 * np.minimum(upper - q0, q0 - lower))
    q = q0[None, :] + amp[None, :] * np.sin(2 * np.pi * t[:, None] / 20.0)
    return t, q


def wait_steps(robot: SimRobot, count: int, timeout: float = 60.0) -> None:
    """Wait (real time, bounded) until the loop has run ``count`` more steps."""
    target = robot.loop_stats().steps + count
    end = time.monotonic() + timeout
    while robot.loop_stats().steps < target:
        assert time.monotonic() < end, f"the loop did not run {count} steps in {timeout} s"
        time.sleep(0.005)
