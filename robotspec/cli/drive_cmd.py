"""``robotspec drive``: run the simulated robot driver, optionally through a scenario script."""

from __future__ import annotations

import sys
import time
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from robotspec.cli.options import PackagePath

if TYPE_CHECKING:
    from robotspec.driver.state import RobotState


#: This module's commands; robotspec.cli.app adds them to the root app.
app = typer.Typer()


@app.command()
def drive(
    sim: Annotated[
        Path | None,
        typer.Option("--sim", help="Simulate the robot described by this RobotInfo YAML."),
    ] = None,
    spec: Annotated[
        str | None, typer.Option("--spec", help="Drive a compiled robot spec (with --chain).")
    ] = None,
    chain: Annotated[
        str | None, typer.Option("--chain", help="The spec chain to drive (with --spec).")
    ] = None,
    rate: Annotated[
        float, typer.Option("--rate", min=1.0, max=10000.0, help="Loop rate in Hz.")
    ] = 100.0,
    duration: Annotated[
        float | None,
        typer.Option(
            "--duration",
            min=0.0,
            help="Seconds to run (default: until Ctrl-C; with --script: until it ends).",
        ),
    ] = None,
    script: Annotated[
        Path | None,
        typer.Option("--script", help="A YAML scenario of client calls with expected outcomes."),
    ] = None,
    log: Annotated[
        Path | None, typer.Option("--log", help="Write every state to FILE (.csv or .jsonl).")
    ] = None,
    plot: Annotated[
        Path | None,
        typer.Option("--plot", help="After the run, plot joint positions and commands to a PNG."),
    ] = None,
    virtual_time: Annotated[
        bool,
        typer.Option("--virtual-time", help="Run on a simulated clock, as fast as possible."),
    ] = False,
    package_path: PackagePath = None,
    serve: Annotated[
        bool,
        typer.Option("--serve", help="Serve the robot over Robot Raconteur (loopback only)."),
    ] = False,
    port: Annotated[
        int | None,
        typer.Option("--port", help="TCP port for --serve (default 58660; 0 picks a free one)."),
    ] = None,
    public: Annotated[
        bool, typer.Option("--public", help="With --serve: listen on all interfaces, discoverable.")
    ] = False,
    node_name: Annotated[
        str | None, typer.Option("--node-name", help="With --serve: the RR node name.")
    ] = None,
    state_dir: Annotated[
        Path | None,
        typer.Option("--state-dir", help="With --serve: folder for the node's UUID and locks."),
    ] = None,
) -> None:
    """Run a simulated robot driver loop (Robot Raconteur AbstractRobot semantics)."""
    if sim is None and spec is None:
        raise typer.BadParameter("give --sim ROBOTINFO.yaml (or --spec SPEC --chain NAME)")
    if sim is not None and spec is not None:
        raise typer.BadParameter("give either --sim or --spec, not both")
    if spec is not None and chain is None:
        raise typer.BadParameter("--spec needs --chain NAME")
    if log is not None and log.suffix.lower() not in (".csv", ".jsonl", ".json", ".ndjson"):
        raise typer.BadParameter(
            f"unknown log format '{log.suffix}' (use .csv or .jsonl)", param_hint="--log"
        )
    from robotspec.service.serve import serve_option_problem

    problem = serve_option_problem(
        serve=serve,
        port=port,
        public=public,
        node_name=node_name,
        state_dir=state_dir,
        script=script,
        virtual_time=virtual_time,
    )
    if problem:
        raise typer.BadParameter(problem)

    from robotspec.driver.clock import RealClock, SimClock
    from robotspec.driver.script import load_scenario, mismatch_errors, run_scenario
    from robotspec.driver.sim import SimRobot
    from robotspec.driver.statelog import StateLog
    from robotspec.errors import RobotSpecError, RobotSpecErrors

    if spec is not None:
        # Export the chain in memory (H/P, limits, flange) and drive that: every robot
        # robotspec can compile can be driven, not only those that ship a RobotInfo.
        from robotspec.export.robotinfo import export_spec_chain

        assert chain is not None
        exported = export_spec_chain(spec, chain, package_path)
        for note in exported.notes:
            sys.stderr.write(f"note: {note}\n")
        info = exported.info
        fallback_name = f"{spec}_{chain}"
    else:
        from robotspec.driver.robot_info import read_robot_info

        assert sim is not None
        loaded_info = read_robot_info(sim)
        for w in loaded_info.warnings:
            sys.stderr.write(w.detail.render() + "\n")
        info = loaded_info.info
        fallback_name = sim.stem
    scenario = load_scenario(script) if script is not None else None
    clock = SimClock() if virtual_time else RealClock()
    driver = SimRobot(info, clock=clock, update_period=1.0 / rate)
    statelog = None
    if log is not None:
        statelog = StateLog(log, info.joint_names, len(info.chains))
        driver.add_state_listener(statelog)
    tty = sys.stdout.isatty()
    status = _StatusLine(tty)
    driver.add_state_listener(status)
    trace = None
    if plot is not None:
        from robotspec.render.deps import require
        from robotspec.render.plot import JointTrace

        require("matplotlib", "matplotlib", "--plot")
        trace = JointTrace(info.joint_names)
        driver.add_state_listener(trace)
    name = info.device_info.device.name or fallback_name
    sys.stderr.write(
        f"driving {name} ({len(info.joint_info)} joints, {len(info.chains)} "
        f"chain{'s' if len(info.chains) != 1 else ''}) in simulation at {rate:g} Hz"
        f"{' (virtual time)' if virtual_time else ''}; Ctrl-C stops\n"
    )
    results = []
    interrupted = False
    stopped_by = "Ctrl-C"
    wall0 = time.perf_counter()
    try:
        driver.step()
        if serve:
            from robotspec.service.serve import serve_driver

            stop_signal = serve_driver(
                driver,
                info,
                port=port,
                public=public,
                node_name=node_name,
                state_dir=state_dir,
                duration=duration,
                fallback_name=fallback_name,
            )
            if stop_signal is not None:
                interrupted, stopped_by = True, stop_signal
        elif scenario is not None:

            def report(r: object) -> None:
                from robotspec.driver.script import StepResult

                assert isinstance(r, StepResult)
                status.clear()
                mark = "ok  " if r.ok else "FAIL"
                extra = f": {r.detail}" if r.detail else ""
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
        interrupted = True
    finally:
        status.clear()
        if statelog is not None:
            statelog.close()
    st = driver.robot_state
    sim_s = driver._stopwatch_ellapsed_s()
    wall = time.perf_counter() - wall0
    summary = (
        f"{f'stopped by {stopped_by} after' if interrupted else 'ran'} {st.seqno} steps, "
        f"{sim_s:.2f} s{' simulated' if virtual_time else ''} in {wall:.2f} s; "
        f"final mode {st.command_mode.name}, flags 0x{int(st.flags):x}"
    )
    sys.stdout.write(summary + "\n")
    if statelog is not None:
        sys.stdout.write(f"wrote {statelog.rows} states to {log}\n")
    if trace is not None and plot is not None:
        from robotspec.render.plot import plot_joint_trace

        drawn = plot_joint_trace(trace, plot, title=f"{name}: positions (solid), commands (dashed)")
        sys.stdout.write(f"wrote {plot} ({drawn.lines} lines, {drawn.samples} samples)\n")
    if scenario is not None:
        failed = mismatch_errors(scenario, results)
        n_run = len(results)
        n_steps = len(scenario.scenario.steps)
        sys.stdout.write(
            f"scenario: {n_run - len(failed)} of {n_steps} steps as expected"
            f"{'' if n_run == n_steps else f' ({n_steps - n_run} not run)'}\n"
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
