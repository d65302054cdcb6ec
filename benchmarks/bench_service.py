"""CPU per loop step while serving one Robot Raconteur client at 250 Hz, robotspec vs reference.

Run: ``python benchmarks/bench_service.py [--seconds 10] [--rate 250] [--robotinfo FILE]``
(needs the ``robotraconteur`` extra; the reference side also needs
``robotraconteur-abstract-robot`` from PyPI and ``general-robotics-toolbox``, and is skipped with
the reason printed when they are missing).

Both servers run in this process on a loopback node (no discovery, state in a temporary folder);
the client is a separate process that connects to the ``robot_state`` wire and counts what
arrives, so its CPU is not charged to the server. Per step we record the wall time and the loop
thread's CPU time (``time.thread_time``) spent in the step including handing the state to the
wires (the reference packs and sends them in its loop; robotspec queues the snapshot for its
publisher thread, whose whole CPU time, read from its thread CPU clock, is reported per step
beside it); over the run, the whole server process's CPU (all threads) divided by the steps.

The reference is a minimal simulated ``AbstractRobot`` subclass (perfect tracking, toolbox FK
and Jacobian in its feedback step, as in the reference note's measurement).
"""

from __future__ import annotations

import argparse
import contextlib
import gc
import json
import os
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from rows import Row, add_json_flag, print_rows

HERE = Path(__file__).resolve()
SHARED_INFO = HERE.parents[2] / "shared" / "robotinfo" / "abb_irb1200_5_90.yml"
LOCAL_INFO = HERE.parents[1] / "tests" / "data" / "driver_rrp.yml"


# ---------------------------------------------------------------------------- client process


def client_main(url: str, seconds: float) -> None:
    """Connect to ``url``, read the robot_state wire for ``seconds``, print JSON stats."""
    from robotspec.service.node import start_client_node

    with tempfile.TemporaryDirectory(prefix="rr-bench-client") as tmp:
        node = start_client_node(Path(tmp))
        robot = node.ConnectService(url)
        wire = robot.robot_state.Connect()
        stamps: list[float] = []
        seqnos: list[int] = []

        def on_value(_w: Any, value: Any, _ts: Any) -> None:
            stamps.append(time.perf_counter())
            seqnos.append(int(value.seqno))

        wire.WireValueChanged += on_value
        print("ready", flush=True)
        time.sleep(seconds)
        wire.WireValueChanged -= on_value
        wire.Close()
        node.DisconnectService(robot)
        node.Shutdown()
    gaps = np.diff(stamps) * 1e3 if len(stamps) > 1 else np.zeros(1)
    lost = int(seqnos[-1] - seqnos[0] + 1 - len(seqnos)) if seqnos else 0
    print(
        json.dumps(
            {
                "received": len(stamps),
                "rate_hz": len(stamps) / seconds,
                "mean_gap_ms": float(np.mean(gaps)),
                "max_gap_ms": float(np.max(gaps)),
                "lost": lost,
            }
        ),
        flush=True,
    )


def run_client(
    url: str, seconds: float
) -> tuple[subprocess.Popen[str], Callable[[], dict[str, Any]]]:
    proc = subprocess.Popen(
        [sys.executable, str(HERE), "--client", url, "--seconds", str(seconds)],
        stdout=subprocess.PIPE,
        text=True,
    )
    assert proc.stdout is not None
    line = proc.stdout.readline()
    if line.strip() != "ready":
        proc.kill()
        raise RuntimeError(f"client failed to start: {line!r}")

    def result() -> dict[str, Any]:
        out, _ = proc.communicate(timeout=seconds + 30)
        data: dict[str, Any] = json.loads(out.strip().splitlines()[-1])
        return data

    return proc, result


# ---------------------------------------------------------------------------- step timing


class StepTimer:
    """Wraps an object's ``_run_timestep`` to record wall and thread-CPU time per step."""

    def __init__(self, obj: Any) -> None:
        self.wall: list[float] = []
        self.cpu: list[float] = []
        self.recording = False
        inner = obj._run_timestep

        def timed(now: float) -> None:
            w0 = time.perf_counter()
            c0 = time.thread_time()
            inner(now)
            if self.recording:
                self.cpu.append(time.thread_time() - c0)
                self.wall.append(time.perf_counter() - w0)

        obj._run_timestep = timed

    def summary(self) -> dict[str, float]:
        cpu = np.array(self.cpu) * 1e3
        wall = np.array(self.wall) * 1e3
        return {
            "steps": float(len(cpu)),
            "cpu_mean_ms": float(cpu.mean()),
            "cpu_p99_ms": float(np.percentile(cpu, 99)),
            "cpu_max_ms": float(cpu.max()),
            "wall_mean_ms": float(wall.mean()),
            "wall_p99_ms": float(np.percentile(wall, 99)),
        }


def _thread_cpu(thread: threading.Thread | None) -> float:
    """Total CPU seconds of ``thread`` so far (its own CPU clock: waking, waiting, all of it)."""
    if thread is None or thread.ident is None:
        return 0.0
    return time.clock_gettime(time.pthread_getcpuclockid(thread.ident))


def measure(
    timer: StepTimer,
    url: str,
    seconds: float,
    warmup: float,
    publisher: threading.Thread | None = None,
) -> dict[str, Any]:
    _proc, result = run_client(url, seconds + warmup)
    gc.collect()
    gc.freeze()  # as ``robotspec drive --serve`` does; applied to both servers alike
    time.sleep(warmup)
    t0 = os.times()
    p0 = _thread_cpu(publisher)
    timer.recording = True
    time.sleep(seconds)
    timer.recording = False
    p1 = _thread_cpu(publisher)
    t1 = os.times()
    out: dict[str, Any] = dict(timer.summary())
    steps = max(1.0, out["steps"])
    proc_cpu = (t1.user - t0.user) + (t1.system - t0.system)
    out["process_cpu_per_step_ms"] = proc_cpu / steps * 1e3
    out["publisher_cpu_per_step_ms"] = (p1 - p0) / steps * 1e3 if publisher is not None else None
    out["client"] = result()
    gc.unfreeze()
    return out


# ---------------------------------------------------------------------------- the two servers


def bench_robotspec(info_path: Path, rate: float, seconds: float, warmup: float) -> dict[str, Any]:
    from robotspec.driver.robot_info import load_robot_info
    from robotspec.driver.sim import SimRobot
    from robotspec.service.server import RobotServer, ServeOptions

    info = load_robot_info(info_path)
    driver = SimRobot(info, update_period=1.0 / rate)
    timer = StepTimer(driver)
    with tempfile.TemporaryDirectory(prefix="rr-bench") as tmp:
        with RobotServer(driver, info, ServeOptions(port=0, state_dir=Path(tmp))) as server:
            assert server.service is not None
            publisher = server.service.publisher.thread
            return measure(timer, server.url, seconds, warmup, publisher)


def bench_reference(info_path: Path, rate: float, seconds: float, warmup: float) -> dict[str, Any]:
    import general_robotics_toolbox as rox
    from robotraconteur_abstract_robot import AbstractRobot
    from RobotRaconteurCompanion.StdRobDef import RegisterStdRobDefServiceTypes
    from RobotRaconteurCompanion.Util.InfoFileLoader import InfoFileLoader

    from robotspec.service.node import start_server_node

    class RefSim(AbstractRobot):  # type: ignore[misc]
        """Minimal simulated reference driver: perfect tracking, FK and Jacobian per step."""

        def __init__(self, robot_info: Any, node: Any, period: float) -> None:
            super().__init__(robot_info, 0, node)
            self._update_period = period
            self._q = np.zeros(self._joint_count)
            self._qd = np.zeros(self._joint_count)
            self._rox = self._rox_robots[0]

        def _run_timestep(self, now: float) -> None:
            with self._lock:
                q = self._q.copy()
                self._joint_position = q
                self._joint_velocity = self._qd.copy()
                self._joint_effort = np.zeros(self._joint_count)
                tf = rox.fwdkin(self._rox, q)
                jac = rox.robotjacobian(self._rox, q)
                self._endpoint_pose = [self._geometry_util.rox_transform_to_pose(tf)]
                self._endpoint_vel = [self._geometry_util.array_to_spatial_velocity(jac @ self._qd)]
                self._ready = self._enabled = True
                self._stopped = self._error = False
                self._last_robot_state = self._last_joint_state = now
                self._last_endpoint_state = now
            super()._run_timestep(now)

        def _send_robot_command(self, now: float, pos: Any, vel: Any) -> None:
            if pos is not None:
                self._qd = (pos - self._q) / self._update_period
                self._q = np.array(pos)
                self._position_command = pos
            else:
                self._qd = np.zeros(self._joint_count)
                self._position_command = None

        def _send_enable(self, handler: Any) -> None:
            handler(None)

        def _send_disable(self, handler: Any) -> None:
            handler(None)

        def _send_reset_errors(self, handler: Any) -> None:
            handler(None)

    with tempfile.TemporaryDirectory(prefix="rr-bench-ref") as tmp:
        server = start_server_node(
            node_name="reference_robot", port=0, public=False, state_dir=Path(tmp)
        )
        try:
            node = server.node
            RegisterStdRobDefServiceTypes(node)
            info, _lock = InfoFileLoader(node).LoadInfoFile(
                str(info_path), "com.robotraconteur.robotics.robot.RobotInfo", "device"
            )
            robot = RefSim(info, node, 1.0 / rate)
            timer = StepTimer(robot)
            robot._start_robot()
            node.RegisterService("robot", "com.robotraconteur.robotics.robot.Robot", robot)
            try:
                return measure(timer, server.url("robot"), seconds, warmup)
            finally:
                robot._stop_robot()
        finally:
            server.shutdown()


def reference_unavailable() -> str:
    import importlib.util

    for mod, pip in (
        ("robotraconteur_abstract_robot", "robotraconteur-abstract-robot"),
        ("general_robotics_toolbox", "general-robotics-toolbox"),
    ):
        if importlib.util.find_spec(mod) is None:
            return f"{pip} is not installed (pip install {pip})"
    return ""


def report(name: str, r: dict[str, Any]) -> None:
    c = r["client"]
    pub = r["publisher_cpu_per_step_ms"]
    publisher = (
        f"publisher thread CPU/step {pub:.3f} ms  "
        if pub is not None
        else "publisher thread: none (wires packed in the loop)  "
    )
    print(
        f"{name:<10} steps {int(r['steps']):5d}  loop CPU/step mean {r['cpu_mean_ms']:.3f} ms "
        f"p99 {r['cpu_p99_ms']:.3f} max {r['cpu_max_ms']:.3f}  "
        f"(wall mean {r['wall_mean_ms']:.3f} p99 {r['wall_p99_ms']:.3f})  "
        f"{publisher}process CPU/step {r['process_cpu_per_step_ms']:.3f} ms  "
        f"client {c['rate_hz']:.1f} Hz, lost {c['lost']}, max gap {c['max_gap_ms']:.1f} ms"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--warmup", type=float, default=1.5)
    parser.add_argument("--rate", type=float, default=250.0)
    parser.add_argument("--robotinfo", type=Path, default=None)
    parser.add_argument("--only", choices=["robotspec", "reference"], default=None)
    parser.add_argument("--client", help=argparse.SUPPRESS)
    add_json_flag(parser)
    args = parser.parse_args()
    if args.client:
        client_main(args.client, args.seconds)
        return
    if args.json:  # the report goes to stderr, stdout gets one JSON object per row
        with contextlib.redirect_stdout(sys.stderr):
            rows = run(args)
        print_rows(rows, True)
        return
    run(args)


def run(args: argparse.Namespace) -> list[Row]:
    """Measure, print the report, and return its rows."""
    info_path = args.robotinfo or (SHARED_INFO if SHARED_INFO.exists() else LOCAL_INFO)
    print(f"robot {info_path.name}, {args.rate:g} Hz, {args.seconds:g} s, one robot_state client")
    results: dict[str, Any] = {}
    if args.only in (None, "robotspec"):
        results["robotspec"] = bench_robotspec(info_path, args.rate, args.seconds, args.warmup)
        report("robotspec", results["robotspec"])
    if args.only in (None, "reference"):
        why = reference_unavailable()
        if why:
            print(f"reference  not run: {why}")
        else:
            results["reference"] = bench_reference(info_path, args.rate, args.seconds, args.warmup)
            report("reference", results["reference"])
    if "robotspec" in results and "reference" in results:
        ours, ref = results["robotspec"], results["reference"]
        ratio = ref["cpu_mean_ms"] / ours["cpu_mean_ms"]
        with_pub = ours["cpu_mean_ms"] + (ours["publisher_cpu_per_step_ms"] or 0.0)
        proc = ref["process_cpu_per_step_ms"] / ours["process_cpu_per_step_ms"]
        print(
            f"reference / robotspec: loop CPU per step {ratio:.1f}x; loop + publisher "
            f"{ref['cpu_mean_ms'] / with_pub:.1f}x; process CPU per step {proc:.1f}x"
        )
    if "robotspec" in results:
        loop = results["robotspec"]["cpu_mean_ms"]
        print(
            f"target loop CPU per step < 0.5 ms: {'met' if loop < 0.5 else 'MISSED'} "
            f"({loop:.3f} ms)"
        )
    rows: list[Row] = []
    if "robotspec" in results:
        ours = results["robotspec"]
        ref = results.get("reference")
        peer = "reference loop" if ref else "reference not run"
        rows.append(
            Row(
                f"serving one RR client at {args.rate:g} Hz, CPU per step: loop thread",
                ours["cpu_mean_ms"] / 1e3,
                peer,
                ref["cpu_mean_ms"] / 1e3 if ref else None,
            )
        )
        rows.append(
            Row(
                f"serving one RR client at {args.rate:g} Hz, CPU per step: whole process",
                ours["process_cpu_per_step_ms"] / 1e3,
                peer,
                ref["process_cpu_per_step_ms"] / 1e3 if ref else None,
            )
        )
    return rows


if __name__ == "__main__":
    main()
