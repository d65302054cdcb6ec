"""The driver loop's worst period while a client uploads a 50,000-waypoint trajectory.

Run: ``python benchmarks/bench_trajectory_upload.py [--waypoints N] [--rate HZ] [--uploads K]``.

A simulated ABB IRB1200 (``../shared/robotinfo``; the tests' self-made RRP arm when that folder is
absent) runs its loop in its own thread on the real clock, in trajectory mode, as in production.
The main thread plays the client: it uploads a trajectory of ``--waypoints`` waypoints
(``execute_trajectory``: every waypoint checked, the interpolation set up) ``--uploads`` times.
Measured: the interval between successive timestep starts during the uploads, as a multiple of
the nominal period (target: the worst below 2, i.e. no period missed), and each upload's time.
An idle window of the same length follows each upload, as a control: on a loaded machine the
operating system alone delays the loop, and the control shows by how much.

Why it matters: the checks used to run under the lock the loop needs every step, so a 35,000-point
upload froze the loop for 0.6 s (issue 17). The checks now run outside the lock, vectorised.
"""

from __future__ import annotations

import argparse
import contextlib
import math
import os
import sys
import threading
import time
from pathlib import Path

import numpy as np
from rows import Row, add_json_flag, print_rows

from robotspec.driver.robot_info import load_robot_info
from robotspec.driver.sim import SimRobot
from robotspec.driver.state import CommandMode, RobotState
from robotspec.driver.trajectory import JointTrajectory, Waypoint

ROOT = Path(__file__).resolve().parents[1]
ABB = ROOT.parent / "shared" / "robotinfo" / "abb_irb1200_5_90.yml"
RRP = ROOT / "tests" / "data" / "driver_rrp.yml"


def build(q0: np.ndarray, lower: np.ndarray, upper: np.ndarray, m: int) -> JointTrajectory:
    """A slow ``m``-waypoint sway around ``q0`` at 10 ms spacing, within the limits."""
    t = np.arange(m) * 0.01
    amp = np.minimum(0.2, 0.4 * np.minimum(upper - q0, q0 - lower))
    q = q0[None, :] + amp[None, :] * np.sin(2 * math.pi * t[:, None] / 20.0)
    return JointTrajectory(
        waypoints=tuple(
            Waypoint(joint_position=tuple(map(float, q[i])), time_from_start=float(t[i]))
            for i in range(m)
        )
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--waypoints", type=int, default=50_000)
    ap.add_argument("--rate", type=float, default=100.0)
    ap.add_argument("--uploads", type=int, default=3)
    add_json_flag(ap)
    args = ap.parse_args()
    if args.json:  # the report goes to stderr, stdout gets one JSON object per row
        with contextlib.redirect_stdout(sys.stderr):
            rows = run(args)
        print_rows(rows, True)
        return
    run(args)


def run(args: argparse.Namespace) -> list[Row]:
    """Upload, print the report, and return its rows."""
    path = ABB if ABB.exists() else RRP
    info = load_robot_info(path)
    period = 1.0 / args.rate
    robot = SimRobot(info, update_period=period)
    starts: list[float] = []
    lock = threading.Lock()

    def listener(state: RobotState) -> None:
        with lock:
            starts.append(time.perf_counter())

    robot.add_state_listener(listener)
    robot._start_robot()
    try:
        time.sleep(0.3)
        robot.command_mode = CommandMode.trajectory
        time.sleep(0.1)
        q0 = np.array(robot.robot_state.joint_position)
        lim = robot.limits
        traj = build(q0, lim.lower, lim.upper, args.waypoints)
        upload_s: list[float] = []
        windows: dict[str, list[np.ndarray]] = {"uploading": [], "idle (control)": []}
        for _ in range(args.uploads):
            # Interleaved: an upload, then an idle window as long, so machine load hits both.
            with lock:
                first = len(starts)
            t0 = time.perf_counter()
            gen = robot.execute_trajectory(traj)
            took = time.perf_counter() - t0
            upload_s.append(took)
            gen.Close()
            with lock:
                windows["uploading"].append(np.diff(np.array(starts[first - 1 :])))
                first = len(starts)
            time.sleep(max(took, 0.2))
            with lock:
                windows["idle (control)"].append(np.diff(np.array(starts[first - 1 :])))
    finally:
        robot._stop_robot()
    print(
        f"{info.device_info.device.name}: loop at {args.rate:g} Hz while uploading "
        f"{args.waypoints} waypoints {args.uploads} times ({path.name}); "
        f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} CPUs"
    )
    print(f"  upload time per trajectory: {', '.join(f'{x * 1e3:.0f} ms' for x in upload_s)}")
    worst = {}
    for name, parts in windows.items():
        periods = np.concatenate(parts) / period
        worst[name] = float(periods.max())
        print(
            f"  loop periods {name} ({periods.size}): worst {periods.max():.2f} x nominal, "
            f"p99 {np.percentile(periods, 99):.2f} x, mean {periods.mean():.3f} x"
        )
    periods = np.concatenate(windows["uploading"]) / period
    verdict = "met" if periods.max() < 2.0 else "MISSED"
    print(f"  target: worst period < 2 periods: {verdict}")
    return [
        Row(
            f"upload of {args.waypoints} waypoints (median of {args.uploads})",
            float(np.median(upload_s)),
            f"target: worst loop period while uploading < 2 periods: {verdict}",
            None,
        ),
        Row(
            f"worst loop period at {args.rate:g} Hz while uploading",
            worst["uploading"] * period,
            "worst period while idle (control window)",
            worst["idle (control)"] * period,
        ),
    ]


if __name__ == "__main__":
    main()
