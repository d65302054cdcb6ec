"""``robotspec drive``: run the simulated robot driver, optionally through a scenario script."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Annotated

import typer

from robotspec.cli.options import PackagePath
from robotspec.cli.physics import Physics

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
    physics: Annotated[
        Physics,
        typer.Option(
            "--physics",
            help="What moves the arm: the kinematic profile (default) or MuJoCo under position "
            "servos following it (needs --spec and the mujoco extra).",
        ),
    ] = Physics.kinematic,
    gravity_compensation: Annotated[
        bool,
        typer.Option(
            "--gravity-compensation",
            help="With --physics mujoco: cancel gravity on every body (a counterbalanced arm).",
        ),
    ] = False,
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
    _check_options(
        sim=sim,
        spec=spec,
        chain=chain,
        physics=physics,
        gravity_compensation=gravity_compensation,
        log=log,
        serve=serve,
        port=port,
        public=public,
        node_name=node_name,
        state_dir=state_dir,
        script=script,
        virtual_time=virtual_time,
    )
    from robotspec.cli.driving import drive_target, run_driver

    plant = None
    if physics is Physics.mujoco:
        from robotspec.cli.physics import physics_target

        assert spec is not None and chain is not None  # checked above
        target = physics_target(
            spec, chain, package_path or (), gravity_compensation=gravity_compensation
        )
        for note in target.exported.notes:
            sys.stderr.write(f"note: {note}\n")
        info, fallback_name, plant = target.exported.info, f"{spec}_{chain}", target.plant
    else:
        info, fallback_name = drive_target(sim, spec, chain, package_path)
    run_driver(
        info,
        fallback_name,
        plant=plant,
        rate=rate,
        duration=duration,
        script=script,
        log=log,
        plot=plot,
        virtual_time=virtual_time,
        serve=serve,
        port=port,
        public=public,
        node_name=node_name,
        state_dir=state_dir,
    )


def _check_options(
    *,
    sim: Path | None,
    spec: str | None,
    chain: str | None,
    physics: Physics,
    gravity_compensation: bool,
    log: Path | None,
    serve: bool,
    port: int | None,
    public: bool,
    node_name: str | None,
    state_dir: Path | None,
    script: Path | None,
    virtual_time: bool,
) -> None:
    """Refuse combinations of options that cannot run (a usage error, exit code 2)."""
    if sim is None and spec is None:
        raise typer.BadParameter("give --sim ROBOTINFO.yaml (or --spec SPEC --chain NAME)")
    if sim is not None and spec is not None:
        raise typer.BadParameter("give either --sim or --spec, not both")
    if spec is not None and chain is None:
        raise typer.BadParameter("--spec needs --chain NAME")
    if physics is Physics.mujoco and spec is None:
        raise typer.BadParameter(
            "--physics mujoco needs --spec SPEC --chain NAME: a RobotInfo file has no model "
            "for MuJoCo to simulate",
            param_hint="--physics",
        )
    if gravity_compensation and physics is not Physics.mujoco:
        raise typer.BadParameter(
            "--gravity-compensation needs --physics mujoco", param_hint="--gravity-compensation"
        )
    from robotspec.driver.statelog import LOG_SUFFIXES

    if log is not None and log.suffix.lower() not in LOG_SUFFIXES:
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
