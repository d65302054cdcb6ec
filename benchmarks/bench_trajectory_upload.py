"""The driver loop's missed periods while a client uploads a long trajectory.

Run: ``python benchmarks/bench_trajectory_upload.py [--waypoints 35000 20000] [--uploads K]
[--rate HZ] [--transport rr|local]``.

A simulated ABB IRB1200 (``../shared/robotinfo``; the tests' self-made RRP arm when that folder is
absent) runs its loop in its own thread on the real clock, in trajectory mode, as in production.

* ``--transport rr`` (the default, issue 31's case): the driver is served over Robot Raconteur in
  this process, set up as ``robotspec drive --serve`` sets up its process, and a client in a
  child process uploads the trajectory ``--uploads`` times through ``execute_trajectory``: the
  server receives it, Robot Raconteur decodes it into Python, the service converts and checks it,
  and the driver plans it. Needs the ``robotraconteur`` extra.
* ``--transport local``: the same trajectory handed to ``SimRobot.execute_trajectory`` by this
  process's main thread (no decoding).

Measured by the loop's own clock (the ``ts`` of every state it publishes): the periods it missed
while an upload was in flight (deadlines it skipped) and its longest interval between two steps,
as a multiple of the period (target: at most 2 periods missed per upload), and the upload's time
as the client saw it. After each upload an idle window as long follows, as a control: on a loaded
machine the operating system alone delays the loop, and the control shows by how much.

To compare with older code, run this file with the older package first on the path:
``git worktree add /tmp/old <commit>`` then ``PYTHONPATH=/tmp/old python
benchmarks/bench_trajectory_upload.py`` (the child client inherits the path).
"""

from __future__ import annotations

import argparse
import contextlib
import gc
import math
import os
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from rows import Row, add_json_flag, print_rows

from robotspec.driver.robot_info import load_robot_info
from robotspec.driver.sim import SimRobot
from robotspec.driver.state import CommandMode, RobotState
from robotspec.driver.trajectory import JointTrajectory, Waypoint

ROOT = Path(__file__).resolve().parents[1]
ABB = ROOT.parent / "shared" / "robotinfo" / "abb_irb1200_5_90.yml"
RRP = ROOT / "tests" / "data" / "driver_rrp.yml"
#: Target: an upload costs the loop at most this many periods.
TARGET_MISSED = 2


def sway(q0: np.ndarray, lower: np.ndarray, upper: np.ndarray, m: int) -> tuple[Any, Any]:
    """Times and positions of a slow ``m``-waypoint sway around ``q0`` at 10 ms spacing."""
    t = np.arange(m) * 0.01
    amp = np.minimum(0.2, 0.4 * np.minimum(upper - q0, q0 - lower))
    q = q0[None, :] + amp[None, :] * np.sin(2 * math.pi * t[:, None] / 20.0)
    return t, q


# ---------------------------------------------------------------------------- the loop's clock


class StepTimes:
    """The ``ts`` (loop clock) of every step, collected by a state listener."""

    def __init__(self) -> None:
        self.ts: list[float] = []
        self._lock = threading.Lock()

    def __call__(self, st: RobotState) -> None:
        with self._lock:
            self.ts.append(st.ts)

    def mark(self) -> int:
        with self._lock:
            return len(self.ts)

    def window(self, first: int, last: int) -> np.ndarray:
        """The step times from the step before ``first`` to step ``last`` (exclusive)."""
        with self._lock:
            return np.array(self.ts[max(first - 1, 0) : last])


@dataclass
class Window:
    """What the loop did during one upload (or one idle control window)."""

    missed: int
    worst_interval: float  # periods
    steps: int


def judge(ts: np.ndarray, period: float) -> Window:
    """Missed deadlines and the longest step interval, from the steps' own clock times.

    The loop's deadlines lie on a grid of its period from its epoch (``ts`` 0); between two steps
    it skipped every grid deadline strictly between the ones it woke for.
    """
    if ts.size < 2:
        return Window(0, 0.0, int(ts.size))
    grid = np.floor(ts / period + 1e-6)
    missed = int(np.maximum(np.diff(grid) - 1, 0).sum())
    return Window(missed, float(np.diff(ts).max() / period), int(ts.size - 1))


# ---------------------------------------------------------------------------- the client side


def client_main(url: str, waypoints: int, uploads: int) -> None:
    """The child process: connect, select trajectory mode, upload; stdout marks each upload."""
    from robotspec.service.node import start_client_node

    node = start_client_node(Path(tempfile.mkdtemp(prefix="rsbench")))
    robot = node.ConnectService(url)
    try:
        robot.command_mode = int(CommandMode.trajectory)
        state, _ = robot.robot_state.PeekInValue()
        info = robot.robot_info
        lower = np.array([j.joint_limits.lower for j in info.joint_info])
        upper = np.array([j.joint_limits.upper for j in info.joint_info])
        t, q = sway(np.array(state.joint_position), lower, upper, waypoints)
        traj_t = "com.robotraconteur.robotics.trajectory.JointTrajectory"
        wp_t = "com.robotraconteur.robotics.trajectory.JointTrajectoryWaypoint"
        new_wp = node.GetStructureType(wp_t, robot)
        traj = node.GetStructureType(traj_t, robot)()
        traj.joint_names = [j.joint_identifier.name for j in info.joint_info]
        wps = []
        for i in range(waypoints):
            w = new_wp()
            w.joint_position = q[i]
            w.time_from_start = float(t[i])
            wps.append(w)
        traj.waypoints = wps
        for _ in range(uploads):
            print("begin", flush=True)
            t0 = time.perf_counter()
            gen = robot.execute_trajectory(traj)
            took = time.perf_counter() - t0
            print(f"end {took:.6f}", flush=True)
            gen.Close()
            print("idle", flush=True)
            time.sleep(max(took, 0.3))
            print("done", flush=True)
    finally:
        node.DisconnectService(robot)
        node.Shutdown()


# ---------------------------------------------------------------------------- the server side


@contextlib.contextmanager
def served(robot: SimRobot, path: Path) -> Iterator[str]:
    """Serve ``robot`` over Robot Raconteur in this process, as ``drive --serve`` does; the url."""
    from robotspec.service.server import RobotServer, ServeOptions

    info = load_robot_info(path)
    state = Path(tempfile.mkdtemp(prefix="rsb", dir="/tmp" if os.path.isdir("/tmp") else None))
    server = RobotServer(robot, info, ServeOptions(port=0, state_dir=state))
    with server:
        try:  # what serve_driver does once serving
            from robotspec.service.realtime import prepare_process
        except ImportError:  # older code: it only froze the collector's generations
            gc.collect()
            gc.freeze()
        else:
            prepare_process(robot.update_period)
        yield server.url


def upload_rr(robot: SimRobot, path: Path, steps: StepTimes, m: int, k: int) -> list[Any]:
    """Uploads over Robot Raconteur from a child process; per upload (window, idle, seconds)."""
    out = []
    with served(robot, path) as url:
        child = subprocess.Popen(
            [sys.executable, __file__, "--client", url, "--waypoints", str(m), "--uploads", str(k)],
            stdout=subprocess.PIPE,
            text=True,
        )
        assert child.stdout is not None
        marks: dict[str, int] = {}
        took = 0.0
        for line in child.stdout:
            word, *rest = line.split()
            marks[word] = steps.mark()
            if word == "end":
                took = float(rest[0])
            elif word == "done":
                period = robot.update_period
                busy = judge(steps.window(marks["begin"], marks["end"] + 1), period)
                idle = judge(steps.window(marks["idle"], marks["done"] + 1), period)
                out.append((busy, idle, took))
        if child.wait() != 0:
            raise SystemExit(f"the client failed (exit {child.returncode})")
    return out


def upload_local(robot: SimRobot, steps: StepTimes, m: int, k: int) -> list[Any]:
    """Uploads by this process's main thread; per upload (window, idle, seconds)."""
    lim = robot.limits
    t, q = sway(np.array(robot.robot_state.joint_position), lim.lower, lim.upper, m)
    traj = JointTrajectory(
        waypoints=tuple(
            Waypoint(joint_position=tuple(map(float, q[i])), time_from_start=float(t[i]))
            for i in range(m)
        )
    )
    out = []
    for _ in range(k):
        first = steps.mark()
        t0 = time.perf_counter()
        gen = robot.execute_trajectory(traj)
        took = time.perf_counter() - t0
        last = steps.mark()
        gen.Close()
        time.sleep(max(took, 0.3))
        busy = judge(steps.window(first, last + 1), robot.update_period)
        idle = judge(steps.window(last + 1, steps.mark()), robot.update_period)
        out.append((busy, idle, took))
    return out


def run(args: argparse.Namespace) -> list[Row]:
    """Upload, print the report, and return its rows."""
    path = ABB if ABB.exists() else RRP
    info = load_robot_info(path)
    period = 1.0 / args.rate
    rows: list[Row] = []
    print(
        f"{info.device_info.device.name} ({path.name}): loop at {args.rate:g} Hz, uploads over "
        f"{'Robot Raconteur from a child process' if args.transport == 'rr' else 'no transport'}"
        f"; load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} CPUs"
    )
    for m in args.waypoints:
        robot = SimRobot(info, update_period=period)
        steps = StepTimes()
        robot.add_state_listener(steps)
        robot._start_robot()  # serving starts it too (once)
        try:
            time.sleep(0.3)
            if args.transport == "rr":
                results = upload_rr(robot, path, steps, m, args.uploads)
            else:
                robot.command_mode = CommandMode.trajectory
                time.sleep(0.1)
                results = upload_local(robot, steps, m, args.uploads)
        finally:
            robot._stop_robot()
        busy_missed = [b.missed for b, _, _ in results]
        busy_worst = max(b.worst_interval for b, _, _ in results)
        idle_missed = [i.missed for _, i, _ in results]
        idle_worst = max(i.worst_interval for _, i, _ in results)
        times = [s for _, _, s in results]
        verdict = "met" if max(busy_missed) <= TARGET_MISSED else "MISSED"
        print(f"  {m} waypoints, {args.uploads} uploads:")
        print(f"    upload time (client): {', '.join(f'{s * 1e3:.0f} ms' for s in times)}")
        print(
            f"    periods missed per upload: {busy_missed}; longest step interval "
            f"{busy_worst:.2f} periods ({busy_worst * period * 1e3:.1f} ms)"
        )
        print(
            f"    idle control windows: missed {idle_missed}; longest interval "
            f"{idle_worst:.2f} periods"
        )
        print(f"    target: at most {TARGET_MISSED} periods missed per upload: {verdict}")
        rows.append(
            Row(
                f"upload of {m} waypoints over {args.transport} (median of {args.uploads})",
                float(np.median(times)),
                f"target: <= {TARGET_MISSED} periods missed per upload: {verdict}",
                None,
            )
        )
        rows.append(
            Row(
                f"longest loop step interval at {args.rate:g} Hz during a {m}-waypoint upload",
                busy_worst * period,
                "longest interval in the idle control windows",
                idle_worst * period,
            )
        )
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--waypoints", type=int, nargs="+", default=[35_000, 20_000])
    ap.add_argument("--rate", type=float, default=100.0)
    ap.add_argument("--uploads", type=int, default=3)
    ap.add_argument("--transport", choices=("rr", "local"), default="rr")
    ap.add_argument("--client", metavar="URL", help=argparse.SUPPRESS)
    add_json_flag(ap)
    args = ap.parse_args()
    if args.client:
        client_main(args.client, args.waypoints[0], args.uploads)
        return
    if args.json:  # the report goes to stderr, stdout gets one JSON object per row
        with contextlib.redirect_stdout(sys.stderr):
            rows = run(args)
        print_rows(rows, True)
        return
    run(args)


if __name__ == "__main__":
    main()
