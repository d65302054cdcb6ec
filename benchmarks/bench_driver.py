"""The driver loop at 1 kHz on a real clock, against the reference ``AbstractRobot``.

Run: ``python benchmarks/bench_driver.py [--seconds 10] [--rate 1000]``. The reference part needs
``pip install robotraconteur-abstract-robot robotraconteur robotraconteurcompanion`` (not a
robotspec dependency); without it the output says why and only robotspec's figures are printed.

Both drivers run the same workload in the same process, one after the other: a simulated 6-joint
ABB IRB1200 (``../shared/robotinfo``; the exported PR2 right arm when that folder is absent),
jogging back and forth for the first half of the run and following trajectories for the second,
with the loop in its own thread as in production. Measured identically for both, by wrapping the
timestep:

* period: the interval between successive timestep starts (``time.perf_counter``);
* period error: ``|period - 1/rate|``, p50 / p99 / max;
* CPU per step: ``time.thread_time`` delta around the step (the loop thread's CPU only, so time
  spent waiting for the GIL or sleeping is not counted).

The reference subclass is the minimal simulated robot of the reference note: perfect tracking,
feedback filled in ``_run_timestep`` before the base step, endpoint pose and velocity from the
toolbox (``fwdkin`` and ``robotjacobian``, as its drivers do), no service registered (so no wire
packing; the note measured 1.45 ms per step once registered). Robot Raconteur's node directories
are redirected to a temporary folder so nothing is written outside it.
"""

from __future__ import annotations

import argparse
import contextlib
import math
import os
import statistics
import sys
import tempfile
import threading
import time
import traceback
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from rows import Row, add_json_flag, erd_share, print_rows

SHARED = Path(__file__).resolve().parents[2] / "shared"
ABB = SHARED / "robotinfo" / "abb_irb1200_5_90.yml"


@dataclass(frozen=True)
class LoopStats:
    """What one run measured."""

    name: str
    steps: int
    period_mean: float
    err_p50: float
    err_p99: float
    err_max: float
    missed: int
    cpu_mean: float
    cpu_p99: float
    cpu_max: float
    process_cpu_fraction: float
    note: str = ""


class Recorder:
    """Timestep start times and CPU per step, preallocated (no allocation in the loop)."""

    def __init__(self, capacity: int) -> None:
        self.starts = np.zeros(capacity)
        self.cpu = np.zeros(capacity)
        self.n = 0

    def wrap(self, step: Callable[[float], None], now: float) -> None:
        t = time.perf_counter()
        c = time.thread_time()
        step(now)
        c1 = time.thread_time()
        if self.n < self.starts.shape[0]:
            self.starts[self.n] = t
            self.cpu[self.n] = c1 - c
            self.n += 1

    def stats(self, name: str, period: float, cpu_fraction: float, note: str = "") -> LoopStats:
        starts = self.starts[: self.n]
        cpu = self.cpu[: self.n]
        # Skip the first 100 steps: thread start-up and first allocations.
        skip = min(100, max(0, self.n - 10))
        periods = np.diff(starts[skip:])
        err = np.abs(periods - period)
        return LoopStats(
            name=name,
            steps=self.n,
            period_mean=float(periods.mean()),
            err_p50=float(np.percentile(err, 50)),
            err_p99=float(np.percentile(err, 99)),
            err_max=float(err.max()),
            missed=int(np.sum(periods > 1.5 * period)),
            cpu_mean=float(cpu[skip:].mean()),
            cpu_p99=float(np.percentile(cpu[skip:], 99)),
            cpu_max=float(cpu[skip:].max()),
            process_cpu_fraction=cpu_fraction,
            note=note,
        )


def _targets(lower: np.ndarray, upper: np.ndarray, q0: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two jog/trajectory end points 0.3 rad either side of ``q0`` (within the limits)."""
    a = np.clip(q0 - 0.3, lower + 0.05, upper - 0.05)
    b = np.clip(q0 + 0.3, lower + 0.05, upper - 0.05)
    return a, b


# ---------------------------------------------------------------------------------- robotspec


def run_robotspec(info: Any, seconds: float, rate: float) -> LoopStats:
    from robotspec.driver.clock import RealClock
    from robotspec.driver.sim import SimRobot
    from robotspec.driver.state import CommandMode
    from robotspec.driver.trajectory import JointTrajectory
    from robotspec.errors import RobotSpecError

    period = 1.0 / rate
    rec = Recorder(int(seconds * rate * 1.2) + 1000)

    class TimedSim(SimRobot):
        def _run_timestep(self, now: float) -> None:
            rec.wrap(super()._run_timestep, now)

    robot = TimedSim(info, clock=RealClock(), update_period=period)
    note = ""
    lim = robot.limits
    robot.step()
    robot.step()
    q0 = np.asarray(robot.robot_state.joint_position)
    a, b = _targets(lim.lower, lim.upper, q0)
    cpu0, wall0 = time.process_time(), time.perf_counter()
    robot._start_robot()
    end = wall0 + seconds
    half = wall0 + seconds / 2
    try:
        robot.command_mode = CommandMode.jog
        k = 0
        while time.perf_counter() < half:
            robot.jog_freespace(a if k % 2 else b, lim.velocity * 0.5, wait=False)
            k += 1
            time.sleep(min(0.6, max(0.0, half - time.perf_counter())))
        robot.command_mode = CommandMode.halt
        # The halt brakes at the acceleration limits: start trajectories from rest.
        while np.any(np.abs(robot.robot_state.joint_velocity) > 1e-9):
            time.sleep(0.01)
        robot.command_mode = CommandMode.trajectory
        failures = 0
        while time.perf_counter() < end - 1.1:
            q = np.asarray(robot.robot_state.joint_position)
            goal = a if np.linalg.norm(q - a) > np.linalg.norm(q - b) else b
            gen = robot.execute_trajectory(JointTrajectory.smooth_move(q, goal, 1.0, 0.05))
            try:
                while True:
                    gen.Next()
            except StopIteration:
                pass
            except RobotSpecError as exc:
                failures += 1
                note = f"{failures} trajectories failed, last: {exc.message}"
                robot.command_mode = CommandMode.trajectory
        time.sleep(max(0.0, end - time.perf_counter()))
    finally:
        robot._stop_robot()
    cpu_fraction = (time.process_time() - cpu0) / (time.perf_counter() - wall0)
    return rec.stats("robotspec SimRobot", period, cpu_fraction, note)


def step_cost_simulated(info: Any, rate: float, steps: int = 3000) -> tuple[float, float]:
    """CPU per step (jog, trajectory) with no scheduling at all: a simulated clock, one thread.

    Why: on a loaded 2-core machine the real-clock figures include cache and scheduler effects
    of other processes; this isolates what one step of the loop itself costs.
    """
    from robotspec.driver.clock import SimClock
    from robotspec.driver.sim import SimRobot
    from robotspec.driver.state import CommandMode
    from robotspec.driver.trajectory import JointTrajectory

    robot = SimRobot(info, clock=SimClock(), update_period=1.0 / rate)
    lim = robot.limits
    robot.step()
    robot.step()
    q0 = np.asarray(robot.robot_state.joint_position)
    a, b = _targets(lim.lower, lim.upper, q0)
    robot.command_mode = CommandMode.jog
    robot.jog_freespace(b, lim.velocity * 0.5)
    c = time.thread_time()
    for _ in range(steps):
        robot.step()
    jog = (time.thread_time() - c) / steps
    robot.command_mode = CommandMode.halt
    robot.run_for(1.0)
    robot.command_mode = CommandMode.trajectory
    q = np.asarray(robot.robot_state.joint_position)
    gen = robot.execute_trajectory(JointTrajectory.smooth_move(q, a, steps / rate + 1.0, 0.05))
    gen._task.next_called = True  # started without blocking in Next()
    c = time.thread_time()
    for _ in range(steps):
        robot.step()
    traj = (time.thread_time() - c) / steps
    return jog, traj


# ---------------------------------------------------------------------------------- reference


def run_reference(yaml_text: str, seconds: float, rate: float) -> LoopStats | str:
    """Run the reference; a string says why it could not run."""
    tmp = tempfile.mkdtemp(prefix="rr_bench_")
    for kind in ("USER", "SYSTEM"):
        for what in ("DATA", "STATE", "CACHE", "CONFIG", "RUN"):
            os.environ[f"ROBOTRACONTEUR_{kind}_{what}_DIR"] = os.path.join(tmp, kind, what)
    try:
        import general_robotics_toolbox as rox  # type: ignore[import-untyped]
        import RobotRaconteur as RR  # type: ignore[import-untyped]
        from robotraconteur_abstract_robot import (  # type: ignore[import-untyped]
            AbstractRobot,
        )
        from RobotRaconteurCompanion.InfoParser import (  # type: ignore[import-untyped]
            InfoParser,
        )
        from RobotRaconteurCompanion.StdRobDef import (  # type: ignore[import-untyped]
            RegisterStdRobDefServiceTypes,
        )
        from RobotRaconteurCompanion.Util.GeometryUtil import (  # type: ignore[import-untyped]
            GeometryUtil,
        )
    except ImportError as exc:
        return (
            f"not installed ({exc}); pip install robotraconteur-abstract-robot robotraconteur "
            "robotraconteurcompanion"
        )

    try:
        node = RR.RobotRaconteurNode()
        node.SetLogLevelFromString("ERROR")
        node.Init()
        RegisterStdRobDefServiceTypes(node)
        info = InfoParser(node).ParseInfoString(
            yaml_text, "com.robotraconteur.robotics.robot.RobotInfo"
        )
    except Exception as exc:  # noqa: BLE001 - report why, do not crash the benchmark
        return f"could not set up a Robot Raconteur node: {type(exc).__name__}: {exc}"

    period = 1.0 / rate
    rec = Recorder(int(seconds * rate * 1.2) + 1000)

    class RefSim(AbstractRobot):  # type: ignore[misc]
        """The reference note's minimal simulated subclass: perfect tracking, toolbox FK."""

        def __init__(self) -> None:
            super().__init__(info, 0, node)
            self._update_period = period
            self._geom = GeometryUtil(node)
            n = self._joint_count
            self._q = np.array([j.joint_limits.home for j in info.joint_info], dtype=float)
            self._qd = np.zeros(n)
            self._pending: np.ndarray | None = None

        def _run_timestep(self, now: float) -> None:
            rec.wrap(self._timestep, now)

        def _timestep(self, now: float) -> None:
            with self._lock:
                if self._pending is not None:
                    self._qd = (self._pending - self._q) / period
                    self._q = self._pending.copy()
                else:
                    self._qd = np.zeros_like(self._q)
                self._joint_position = self._q.copy()
                self._joint_velocity = self._qd.copy()
                self._joint_effort = np.zeros_like(self._q)
                r = self._rox_robots[0]
                tf = rox.fwdkin(r, self._q)
                jac = rox.robotjacobian(r, self._q)
                self._endpoint_pose = [self._geom.rox_transform_to_pose(tf)]
                vel = np.zeros((1,), dtype=self._spatial_velocity_dtype)
                twist = jac @ self._qd
                vel[0]["angular"]["x"], vel[0]["angular"]["y"], vel[0]["angular"]["z"] = twist[:3]
                vel[0]["linear"]["x"], vel[0]["linear"]["y"], vel[0]["linear"]["z"] = twist[3:]
                self._endpoint_vel = [vel[0]]
                self._ready = self._enabled = True
                self._stopped = self._error = False
                self._last_robot_state = self._last_joint_state = self._last_endpoint_state = now
            super()._run_timestep(now)

        def _send_robot_command(self, now: float, pos: Any, vel: Any) -> None:
            self._pending = None if pos is None else np.array(pos, dtype=float)
            self._position_command = pos

        def _send_enable(self, handler: Any) -> None:
            handler(None)

        def _send_disable(self, handler: Any) -> None:
            handler(None)

        def _send_reset_errors(self, handler: Any) -> None:
            handler(None)

    note = ""
    try:
        robot = RefSim()
    except Exception as exc:  # noqa: BLE001
        node.Shutdown()
        return f"could not construct the reference driver: {type(exc).__name__}: {exc}"
    modes = robot._robot_command_mode
    lim_lo = np.array([j.joint_limits.lower for j in info.joint_info])
    lim_hi = np.array([j.joint_limits.upper for j in info.joint_info])
    vmax = np.array([j.joint_limits.velocity for j in info.joint_info])
    a, b = _targets(lim_lo, lim_hi, robot._q)
    cpu0, wall0 = time.process_time(), time.perf_counter()
    robot._start_robot()
    end = wall0 + seconds
    half = wall0 + seconds / 2
    try:
        time.sleep(0.05)
        robot.command_mode = modes["jog"]
        k = 0
        while time.perf_counter() < half:
            robot.async_jog_freespace(a if k % 2 else b, vmax * 0.5, False, lambda *_: None)
            k += 1
            time.sleep(min(0.6, max(0.0, half - time.perf_counter())))
        robot.command_mode = modes["halt"]
        time.sleep(0.05)  # the reference stops dead on halt (no braking ramp)
        robot.command_mode = modes["trajectory"]
        try:
            _reference_trajectories(node, robot, a, b, end, period)
        except Exception as exc:  # noqa: BLE001 - report, keep the timing of the run
            note = f"trajectory phase failed: {type(exc).__name__}: {exc}"
            traceback.print_exc()
        time.sleep(max(0.0, end - time.perf_counter()))
    finally:
        robot._close()
        node.Shutdown()
    cpu_fraction = (time.process_time() - cpu0) / (time.perf_counter() - wall0)
    return rec.stats("reference AbstractRobot 0.2.2", period, cpu_fraction, note)


def _reference_trajectories(
    node: Any, robot: Any, a: np.ndarray, b: np.ndarray, end: float, period: float
) -> None:
    """Follow 1 s trajectories (21 waypoints, 50 ms apart) until ``end``, through AsyncNext."""
    import RobotRaconteur as RR

    # execute_trajectory records the calling client's endpoint, which only exists inside a
    # service call; in process there is none, so report endpoint 0 ("no client").
    RR.ServerEndpoint.GetCurrentEndpoint = staticmethod(lambda: 0)
    traj_type = node.GetStructureType("com.robotraconteur.robotics.trajectory.JointTrajectory")
    wp_type = node.GetStructureType(
        "com.robotraconteur.robotics.trajectory.JointTrajectoryWaypoint"
    )
    while time.perf_counter() < end - 1.2:
        with robot._lock:
            q = np.array(robot._joint_position)
        goal = a if np.linalg.norm(q - a) > np.linalg.norm(q - b) else b
        traj = traj_type()
        traj.joint_names = list(robot._joint_names)
        wps = []
        for t in np.linspace(0.0, 1.0, 21):
            s = 10 * t**3 - 15 * t**4 + 6 * t**5
            wp = wp_type()
            wp.joint_position = q + s * (goal - q)
            wp.joint_velocity = np.zeros(len(q))
            wp.position_tolerance = np.zeros(0)
            wp.velocity_tolerance = np.zeros(0)
            wp.time_from_start = float(t)
            wps.append(wp)
        traj.waypoints = wps
        gen = robot.execute_trajectory(traj)
        while True:
            done = threading.Event()
            result: list[Any] = []

            def handler(
                res: Any, err: Any, done: threading.Event = done, out: list[Any] = result
            ) -> None:
                out.append((res, err))
                done.set()

            try:
                gen.AsyncNext(handler)
            except RR.StopIterationException:
                break
            done.wait(6.0)
            if not result or result[0][1] is not None:
                break
            if result[0][0].action_status == 3:  # complete
                break


# ---------------------------------------------------------------------------------- main


def _us(x: float) -> str:
    return f"{x * 1e6:9.1f}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--seconds", type=float, default=10.0, help="run length per driver")
    parser.add_argument("--rate", type=float, default=1000.0, help="loop rate in Hz")
    parser.add_argument("--skip-reference", action="store_true")
    add_json_flag(parser)
    args = parser.parse_args()
    if args.json:  # the report goes to stderr, stdout gets one JSON object per row
        with contextlib.redirect_stdout(sys.stderr):
            rows = run(args)
        print_rows(rows, True)
        return
    run(args)


def run(args: argparse.Namespace) -> list[Row]:
    """Measure, print the report, and return its rows."""

    from robotspec.driver.export import dump_robot_info_yaml
    from robotspec.driver.robot_info import load_robot_info, read_robot_info_text

    if ABB.exists():
        yaml_text = ABB.read_text()
        robot_name = "ABB IRB1200 (6 joints)"
    else:
        from robotspec.description.urdf import load_urdf
        from robotspec.driver.export import robot_info_from_chain

        share = erd_share()
        world = load_urdf(share / "robots/pr2_description/urdf/pr2.urdf", meshes="keep")
        exported = robot_info_from_chain(
            world, "torso_lift_link", "r_wrist_roll_link", device_name="pr2_right_arm"
        )
        yaml_text = dump_robot_info_yaml(exported)
        robot_name = "PR2 right arm, exported (7 joints)"
    info = read_robot_info_text(yaml_text).info if not ABB.exists() else load_robot_info(ABB)

    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(
        f"load average before the run: {load:.2f} (on {os.cpu_count()} CPUs; the figures below "
        "include whatever else the machine is running)"
    )
    print(
        f"driver loop at {args.rate:g} Hz for {args.seconds:g} s per driver, {robot_name}; "
        f"jog for the first half, trajectories for the second (python {sys.version.split()[0]}, "
        f"{os.cpu_count()} CPUs)"
    )
    results: list[LoopStats] = [run_robotspec(info, args.seconds, args.rate)]
    reason = ""
    if args.skip_reference:
        reason = "skipped (--skip-reference)"
    else:
        ref = run_reference(yaml_text, args.seconds, args.rate)
        if isinstance(ref, str):
            reason = ref
        else:
            results.append(ref)

    period = 1.0 / args.rate
    header = (
        f"{'driver':<30} {'steps':>6} {'period ms':>9} {'err p50 us':>10} {'err p99 us':>10} "
        f"{'err max us':>10} {'missed':>6} {'cpu/step us':>11} {'cpu p99 us':>10} "
        f"{'cpu max us':>10} {'proc cpu':>8}"
    )
    print(header)
    print("-" * len(header))
    for r in results:
        print(
            f"{r.name:<30} {r.steps:>6} {r.period_mean * 1e3:>9.4f} {_us(r.err_p50):>10} "
            f"{_us(r.err_p99):>10} {_us(r.err_max):>10} {r.missed:>6} {_us(r.cpu_mean):>11} "
            f"{_us(r.cpu_p99):>10} {_us(r.cpu_max):>10} {r.process_cpu_fraction:>7.0%}"
        )
        if r.note:
            print(f"  note: {r.note}")
    ours = results[0]
    if len(results) > 1:
        ref_s = results[1]
        print(
            "ratios (reference / robotspec, above 1 means robotspec is better): "
            f"period error p99 {ref_s.err_p99 / ours.err_p99:.1f}x, "
            f"max {ref_s.err_max / ours.err_max:.1f}x, "
            f"cpu/step {ref_s.cpu_mean / ours.cpu_mean:.1f}x; "
            f"achieved period {ref_s.period_mean * 1e3:.3f} ms vs {ours.period_mean * 1e3:.3f} ms"
        )
    else:
        print(f"reference: not measured: {reason}")
    jog_cost, traj_cost = step_cost_simulated(info, args.rate)
    print(
        f"robotspec step cost on a simulated clock (one thread, no scheduling): "
        f"jog {jog_cost * 1e6:.1f} us, trajectory {traj_cost * 1e6:.1f} us per step"
    )
    ok_p99 = ours.err_p99 < 0.25e-3
    ok_cpu = ours.cpu_mean < 100e-6
    print(
        f"targets: p99 period error < 250 us: {'met' if ok_p99 else 'MISSED'} "
        f"({ours.err_p99 * 1e6:.1f} us); CPU per step < 100 us: {'met' if ok_cpu else 'MISSED'} "
        f"({ours.cpu_mean * 1e6:.1f} us mean)"
    )
    _ = (math, statistics, period)
    ref_r = results[1] if len(results) > 1 else None
    ref_name = "reference AbstractRobot driver" if ref_r else f"reference not run: {reason}"
    return [
        Row(
            f"driver loop {args.rate:g} Hz, p99 period error",
            ours.err_p99,
            ref_name,
            ref_r.err_p99 if ref_r else None,
        ),
        Row(
            f"driver loop {args.rate:g} Hz, CPU per step (loop thread)",
            ours.cpu_mean,
            ref_name,
            ref_r.cpu_mean if ref_r else None,
        ),
    ]


if __name__ == "__main__":
    main()
