"""Running the simulated driver for the CLI: the target RobotInfo, the loop, the summary.

Shared by ``robotspec drive`` and ``robotspec demo`` (commands never call each other). The
driver itself is library code (:mod:`robotspec.driver`); this module is its terminal front:
status line, log, plot, scenario report and the summary line.
"""

from __future__ import annotations

import signal
import sys
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import ExitStack, contextmanager
from functools import partial
from pathlib import Path
from types import FrameType
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from robotspec.driver.mujoco_model import PlantModel
    from robotspec.driver.robot_info import RobotInfo
    from robotspec.driver.script import LoadedScenario, StepResult
    from robotspec.driver.sim import SimRobot
    from robotspec.driver.state import RobotState
    from robotspec.render.plot import JointTrace

__all__ = ["drive_target", "run_driver"]


class _StopSignals:
    """Ctrl-C and SIGTERM end the run, but never inside a state's logging.

    Why: Python raises ``KeyboardInterrupt`` between any two bytecodes, so a signal could land
    inside the state log's listener, after a row was counted and before it was written (the
    summary said 21 states, the log held 20), or cut a row short. Here both signals only set a
    flag inside a critical section and raise once it is left; outside one they raise at once, as
    before. The default SIGTERM killed the process on the spot (no summary, a log cut mid-line);
    now a run stopped by a process manager ends like one stopped by hand. The served path has its
    own handlers (:mod:`robotspec.service.serve`). Handlers can only be set from the main thread;
    elsewhere nothing is changed.
    """

    def __init__(self) -> None:
        self.received: list[str] = []
        self._pending = False
        self._depth = 0
        self._previous: dict[int, object] = {}

    def __enter__(self) -> _StopSignals:
        if threading.current_thread() is threading.main_thread():
            for sig in (signal.SIGINT, signal.SIGTERM):
                self._previous[sig] = signal.getsignal(sig)
                signal.signal(sig, self._on_signal)
        return self

    def __exit__(self, *_exc: object) -> None:
        for sig, previous in self._previous.items():
            signal.signal(sig, previous)  # type: ignore[arg-type]
        self._previous.clear()

    def _on_signal(self, signum: int, _frame: FrameType | None) -> None:
        self.received.append("SIGTERM" if signum == signal.SIGTERM else "Ctrl-C")
        if signum == signal.SIGTERM:
            # the first one is honoured gracefully; a second one kills, as SIGTERM does
            signal.signal(signal.SIGTERM, signal.SIG_DFL)
        if self._depth:
            self._pending = True
        else:
            raise KeyboardInterrupt

    @contextmanager
    def critical(self) -> Iterator[None]:
        """A stretch no stop signal cuts: one raised inside is raised when it is left."""
        self._depth += 1
        try:
            yield
        finally:
            self._depth -= 1
        if not self._depth and self._pending:
            self._pending = False
            raise KeyboardInterrupt


class _Guarded:
    """A state listener run as a critical section of :class:`_StopSignals`."""

    def __init__(self, listener: Callable[[RobotState], None], signals: _StopSignals) -> None:
        self._listener = listener
        self._signals = signals

    def __call__(self, st: RobotState) -> None:
        with self._signals.critical():
            self._listener(st)


def drive_target(
    sim: Path | None, spec: str | None, chain: str | None, package_path: list[Path] | None
) -> tuple[RobotInfo, str]:
    """The RobotInfo to simulate (a file, or a spec's chain exported in memory) and a name."""
    if spec is not None:
        # Export the chain in memory (H/P, limits, flange) and drive that: every robot
        # robotspec can compile can be driven, not only those that ship a RobotInfo.
        from robotspec.export.robotinfo import export_spec_chain

        exported = export_spec_chain(spec, chain or "", package_path)
        for note in exported.notes:
            sys.stderr.write(f"note: {note}\n")
        info = exported.info
        fallback_name = f"{spec}_{chain}"
    else:
        from robotspec.driver.robot_info import read_robot_info

        if sim is None:  # the command's option checks make this unreachable
            raise ValueError("give a RobotInfo file or a spec")
        loaded_info = read_robot_info(sim)
        for w in loaded_info.warnings:
            sys.stderr.write(w.detail.render() + "\n")
        info = loaded_info.info
        fallback_name = sim.stem
    return info, fallback_name


def run_driver(
    info: RobotInfo,
    fallback_name: str,
    *,
    rate: float = 100.0,
    duration: float | None = None,
    script: Path | None = None,
    log: Path | None = None,
    plot: Path | None = None,
    virtual_time: bool = False,
    serve: bool = False,
    port: int | None = None,
    public: bool = False,
    node_name: str | None = None,
    state_dir: Path | None = None,
    plant: PlantModel | None = None,
) -> None:
    """Run the simulated robot until the scenario ends, ``duration`` passes or Ctrl-C.

    With ``plant`` the arm is MuJoCo's (:class:`~robotspec.driver.mujoco_plant.MujocoSimRobot`),
    else the kinematic simulation's. Raises the scenario's mismatches (located at the script)
    after printing the summary.
    """
    from robotspec.driver.script import load_scenario
    from robotspec.driver.statelog import StateLog

    scenario = load_scenario(script) if script is not None else None
    driver, where = _make_driver(info, plant, rate=rate, virtual_time=virtual_time)
    signals = _StopSignals()
    statelog = None
    if log is not None:
        statelog = StateLog(log, info.joint_names, len(info.chains))
        driver.add_state_listener(_Guarded(statelog, signals))
    tty = sys.stdout.isatty()
    status = _StatusLine(tty)
    driver.add_state_listener(status)
    trace = _joint_trace(driver, info) if plot is not None else None
    name = info.device_info.device.name or fallback_name
    sys.stderr.write(
        f"driving {name} ({len(info.joint_info)} joints, {len(info.chains)} "
        f"chain{'s' if len(info.chains) != 1 else ''}) {where} at {rate:g} Hz"
        f"{' (virtual time)' if virtual_time else ''}; Ctrl-C stops\n"
    )

    served = None
    if serve:
        from robotspec.service.serve import serve_driver

        served = partial(
            serve_driver,
            info=info,
            port=port,
            public=public,
            node_name=node_name,
            state_dir=state_dir,
            duration=duration,
            fallback_name=fallback_name,
        )
    wall0 = time.perf_counter()
    try:
        results, interrupted, stopped_by = _run(
            driver, scenario, signals, status, duration=duration, served=served
        )
    finally:
        status.clear()
        if statelog is not None:
            statelog.close()
    ran = f"stopped by {stopped_by} after" if interrupted else "ran"
    sys.stdout.write(_summary(driver, ran, time.perf_counter() - wall0, virtual_time) + "\n")
    if statelog is not None:
        sys.stdout.write(f"wrote {statelog.rows} states to {log}\n")
    if trace is not None and plot is not None:
        from robotspec.render.plot import plot_joint_trace

        drawn = plot_joint_trace(trace, plot, title=f"{name}: positions (solid), commands (dashed)")
        sys.stdout.write(f"wrote {plot} ({drawn.lines} lines, {drawn.samples} samples)\n")
    if scenario is not None and script is not None:
        _report_scenario(scenario, results, interrupted=interrupted, script=script)


def _joint_trace(driver: SimRobot, info: RobotInfo) -> JointTrace:
    """A listener that keeps every joint's position and command, for ``--plot``."""
    from robotspec.render.deps import require
    from robotspec.render.plot import JointTrace

    require("matplotlib", "matplotlib", "--plot")
    trace = JointTrace(info.joint_names)
    driver.add_state_listener(trace)
    return trace


def _summary(driver: SimRobot, ran: str, wall: float, virtual_time: bool) -> str:
    """The run's last line: steps, simulated and wall time, final mode and flags."""
    st = driver.robot_state
    sim_s = driver._stopwatch_ellapsed_s()
    return (
        f"{ran} {st.seqno} steps, "
        f"{sim_s:.2f} s{' simulated' if virtual_time else ''} in {wall:.2f} s; "
        f"final mode {st.command_mode.name}, flags 0x{int(st.flags):x}"
    )


def _make_driver(
    info: RobotInfo, plant: PlantModel | None, *, rate: float, virtual_time: bool
) -> tuple[SimRobot, str]:
    """The simulated robot (kinematic, or MuJoCo's with ``plant``) and where it runs, in words."""
    from robotspec.driver.clock import RealClock, SimClock
    from robotspec.driver.sim import SimRobot

    clock = SimClock() if virtual_time else RealClock()
    if plant is None:
        return SimRobot(info, clock=clock, update_period=1.0 / rate), "in simulation"
    from robotspec.driver.mujoco_plant import MujocoSimRobot

    gravity = "gravity compensated" if plant.gravity_compensation else "gravity on"
    driver = MujocoSimRobot(info, plant, clock=clock, update_period=1.0 / rate)
    return driver, f"on MuJoCo physics ({gravity})"


def _run(
    driver: SimRobot,
    scenario: LoadedScenario | None,
    signals: _StopSignals,
    status: _StatusLine,
    *,
    duration: float | None,
    served: Callable[[SimRobot], str | None] | None,
) -> tuple[list[StepResult], bool, str]:
    """Drive until the scenario ends, ``duration`` passes, or a stop signal.

    ``served``: serve the driver over Robot Raconteur instead (it returns the stop signal).
    Returns the scenario's step results, whether a signal stopped the run, and which.
    """
    from robotspec.driver.script import run_scenario

    results: list[StepResult] = []
    try:
        with ExitStack() as guard:
            if served is None:  # the served path handles its signals itself
                guard.enter_context(signals)
            driver.step()
            if served is not None:
                stop_signal = served(driver)
                if stop_signal is not None:
                    return results, True, stop_signal
            elif scenario is not None:

                def report(r: StepResult) -> None:
                    status.clear()
                    mark = "ok  " if r.ok else "FAIL"
                    extra = f": {r.detail or r.note}" if r.detail or r.note else ""
                    sys.stdout.write(f"{mark} step {r.index} {r.description}{extra}\n")

                results = run_scenario(driver, scenario, on_result=report)
                if duration is not None:
                    driver.run_for(max(0.0, duration - driver._stopwatch_ellapsed_s()))
            elif duration is not None:
                driver.run_for(duration)
            else:
                while True:
                    driver.step()
    except KeyboardInterrupt:
        return results, True, signals.received[0] if signals.received else "Ctrl-C"
    return results, False, "Ctrl-C"


def _report_scenario(
    scenario: LoadedScenario, results: list[StepResult], *, interrupted: bool, script: Path
) -> None:
    """Print how many steps went as expected; raise the mismatches, located at the script."""
    from robotspec.driver.script import mismatch_errors
    from robotspec.errors import RobotSpecError, RobotSpecErrors

    failed = mismatch_errors(scenario, results)
    n_run = len(results)
    n_steps = len(scenario.scenario.steps)
    slowed = [str(r.index) for r in results if r.note]
    sys.stdout.write(
        f"scenario: {n_run - len(failed)} of {n_steps} steps as expected"
        f"{'' if n_run == n_steps else f' ({n_steps - n_run} not run)'}"
        + (
            f"; {len(slowed)} trajector{'y' if len(slowed) == 1 else 'ies'} slowed to stay "
            f"within the joint limits (step{'' if len(slowed) == 1 else 's'} "
            f"{', '.join(slowed)})"
            if slowed
            else ""
        )
        + "\n"
    )
    if interrupted and n_run < n_steps:
        failed.append(
            RobotSpecError(f"scenario interrupted before step {n_run + 1}", file=str(script))
        )
    if failed:
        if len(failed) == 1:
            raise failed[0]
        raise RobotSpecErrors(failed, summary=f"{script}: {len(failed)} steps not as expected")


class _StatusLine:
    """A live one-line status on a terminal, about 10 times a second; silent when piped."""

    def __init__(self, enabled: bool) -> None:
        self.enabled = enabled
        self._last = 0.0
        self._shown = False

    def __call__(self, st: RobotState) -> None:
        if not self.enabled:
            return
        now = time.monotonic()
        if now - self._last < 0.1:
            return
        self._last = now
        q = " ".join(f"{x:+.3f}" for x in st.joint_position[:8])
        line = (
            f"t={st.ts:8.2f}s  mode={st.command_mode.name:<16} flags=0x{int(st.flags):07x}  q=[{q}]"
        )
        if st.error_message:
            line += f"  error: {st.error_message}"
        sys.stdout.write("\r" + line[:160] + "\x1b[K")
        sys.stdout.flush()
        self._shown = True

    def clear(self) -> None:
        if self._shown:
            sys.stdout.write("\r\x1b[K")
            sys.stdout.flush()
            self._shown = False
