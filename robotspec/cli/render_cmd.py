"""``robotspec render`` and ``robotspec view``: a picture and a live 3D view of a compiled robot."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Annotated

import typer

from robotspec.cli.geometry import check_missing_geometry, report_skipped
from robotspec.cli.options import (
    PackagePath,
    QOpt,
    SkipMeshes,
    SpecArg,
    StateOpt,
    joint_values,
    load_robot,
    write_file,
)

#: This module's commands; robotspec.cli.app adds them to the root app.
app = typer.Typer()


@app.command("render")
def render(
    spec: SpecArg,
    state: StateOpt = None,
    q: QOpt = None,
    output: Annotated[Path, typer.Option("--output", "-o", help="The PNG file to write.")] = Path(
        "robot.png"
    ),
    size: Annotated[
        str, typer.Option("--size", help="Image size in pixels, WIDTHxHEIGHT.")
    ] = "800x600",
    view: Annotated[
        str,
        typer.Option(
            "--view",
            help="front (from the robot's front), side (from its right), top, or iso.",
        ),
    ] = "front",
    skip_missing_meshes: SkipMeshes = False,
    package_path: PackagePath = None,
) -> None:
    """Draw the robot at a joint state into a PNG: chains coloured, tool frames, cameras, drive.

    Needs no display: the picture is rasterized in software (numpy) and written with Pillow.
    """
    from robotspec.compiler.inputs import spec_inputs
    from robotspec.render import VIEWS, RenderOptions, build_scene, parse_size, render_scene
    from robotspec.render.deps import require
    from robotspec.semantic.states import state_configuration

    require("PIL", "Pillow", "render")
    width, height = parse_size(size)
    if view not in VIEWS:
        raise typer.BadParameter(f"'{view}' is not one of {', '.join(VIEWS)}", param_hint="--view")
    robot = load_robot(spec, package_path)
    config = state_configuration(robot, state or (), joint_values(q))
    reported = check_missing_geometry(
        robot, skip=skip_missing_meshes, collision=False, command="render"
    )
    scene = build_scene(robot, on_missing_mesh="skip" if skip_missing_meshes else "error")
    report_skipped(scene.skipped, reported)
    title = robot.name + (f" · {', '.join(state)}" if state else "")
    picture = render_scene(
        scene, config, RenderOptions(width=width, height=height, view=view, title=title)
    )
    # Never through a link planted at the output path, never over the robot's own files.
    write_file(
        output,
        picture.png(),
        inputs=spec_inputs(spec, package_paths=package_path or (), robot=robot),
    )
    sys.stdout.write(f"wrote {output} ({width}x{height}, {view} view)\n")


@app.command("view")
def view(
    spec: SpecArg,
    state: StateOpt = None,
    host: Annotated[
        str, typer.Option("--host", help="Interface to serve on (loopback by default).")
    ] = "127.0.0.1",
    port: Annotated[
        int, typer.Option("--port", min=0, max=65535, help="TCP port (0 picks a free one).")
    ] = 8080,
    skip_missing_meshes: SkipMeshes = False,
    package_path: PackagePath = None,
) -> None:
    """A live 3D view in the browser: joint sliders, states, collision geometry and pairs.

    Serves on localhost and prints the URL to open; Ctrl-C stops.
    """
    from robotspec.render.deps import require
    from robotspec.semantic.states import state_configuration

    require("viser", "viser", "view")
    from robotspec.render.viewer import RobotViewer

    robot = load_robot(spec, package_path)
    q = state_configuration(robot, state or ())
    reported = check_missing_geometry(
        robot, skip=skip_missing_meshes, collision=False, command="view"
    )
    viewer = RobotViewer(
        robot,
        q,
        host=host,
        port=port,
        on_missing_mesh="skip" if skip_missing_meshes else "error",
    )
    report_skipped(viewer.skipped, reported)
    sys.stdout.write(f"viewing {robot.name} at {viewer.url} ; Ctrl-C stops\n")
    sys.stdout.flush()
    try:
        viewer.wait()
    except KeyboardInterrupt:
        sys.stdout.write("stopped\n")
    finally:
        viewer.stop()
