"""``robotspec init``: draft a spec from a robot's URDF (and SRDF)."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Annotated

import typer

from robotspec.cli.options import PackagePath, write_output
from robotspec.cli.output import plural

#: This module's commands; robotspec.cli.app adds them to the root app.
app = typer.Typer()


@app.command()
def init(
    urdf: Annotated[str, typer.Argument(help="The robot's URDF or xacro (path or package://).")],
    srdf: Annotated[
        str | None, typer.Option("--srdf", help="Its MoveIt SRDF (path or package://).")
    ] = None,
    output: Annotated[
        Path | None, typer.Option("--output", "-o", help="Write the spec here (default: stdout).")
    ] = None,
    name: Annotated[
        str | None, typer.Option("--name", help="The robot's name (default: the URDF's).")
    ] = None,
    force: Annotated[bool, typer.Option("--force", help="Overwrite an existing file.")] = False,
    package_path: PackagePath = None,
) -> None:
    """Draft a spec: arms, grippers, cameras, neck, torso and drive, from the SRDF and the tree.

    SRDF groups become chains, its end effectors manipulators and its group states named states;
    the kinematic tree adds what the SRDF does not say. The draft validates as written; lines
    marked DECIDE are guesses a person should check.
    """
    from robotspec.errors import RobotSpecError
    from robotspec.spec.draft import render_draft
    from robotspec.spec.draft.render import camera_presets
    from robotspec.spec.draft.run import draft_from_files
    from robotspec.spec.load import spec_may_name

    if output is not None and output.exists() and not force:
        raise RobotSpecError(
            "the file exists; pass --force to overwrite it", file=str(output), kind="output"
        )
    folder = (output.parent if output is not None else Path.cwd()).resolve()
    draft, _ = draft_from_files(
        urdf, srdf, folder=folder, package_paths=package_path or (), name=name
    )
    text = render_draft(draft, presets=camera_presets())
    if write_output(text, output):
        sys.stderr.write(
            f"wrote {output}: {plural(len(draft.chains), 'chain')}, "
            f"{plural(len(draft.manipulators), 'manipulator')}, "
            f"{plural(len(draft.cameras), 'camera')}"
            + (", a torso" if draft.torso is not None else "")
            + (", a neck" if draft.neck is not None else "")
            + "; check the lines marked DECIDE, then run "
            f"`robotspec validate {output}`\n"
        )
    outside = [p for p in draft.package_paths if not spec_may_name(p, folder)]
    if outside:
        # A spec may name such package folders (absolute, or too wide) only with the user's leave.
        allow = " ".join(f"-P {(folder / p).resolve()}" for p in outside)
        sys.stderr.write(
            f"note: package_paths outside the spec's folder are read only when allowed: "
            f"pass {allow} (or set ROS_PACKAGE_PATH)\n"
        )
