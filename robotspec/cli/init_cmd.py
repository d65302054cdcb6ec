"""``robotspec init``: draft a spec from a robot's URDF (and SRDF)."""

from __future__ import annotations

import os
import sys
from pathlib import Path
from typing import Annotated

import typer

from robotspec.cli.options import PackagePath, write_output
from robotspec.cli.output import plural

#: This module's commands; robotspec.cli.app adds them to the root app.
app = typer.Typer()


def _xacro_args(values: list[str]) -> dict[str, str]:
    """``--xacro-arg NAME=VALUE`` options as a map (a later repeat of a name wins)."""
    out: dict[str, str] = {}
    for value in values:
        key, eq, val = value.partition("=")
        if not eq or not key.strip():
            raise typer.BadParameter(f"{value!r} is not NAME=VALUE", param_hint="'--xacro-arg'")
        out[key.strip()] = val
    return out


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
    xacro_arg: Annotated[
        list[str] | None,
        typer.Option(
            "--xacro-arg",
            help="A xacro argument NAME=VALUE (repeatable); written into the draft's "
            "description.xacro_args.",
            show_default=False,
        ),
    ] = None,
) -> None:
    """Draft a spec: arms, grippers, cameras, neck, torso and drive, from the SRDF and the tree.

    SRDF groups become chains, its end effectors manipulators and its group states named states;
    the kinematic tree adds what the SRDF does not say. The draft validates as written; lines
    marked DECIDE are guesses a person should check.
    """
    from robotspec.compiler.inputs import description_inputs
    from robotspec.files.fences import inside, project_root, refusal
    from robotspec.files.package_search import user_roots
    from robotspec.files.writing import check_writable
    from robotspec.spec.draft import render_draft
    from robotspec.spec.draft.render import camera_presets
    from robotspec.spec.draft.run import draft_from_files

    xacro_args = _xacro_args(xacro_arg or [])
    # The robot's own files are never replaced (``-o robot.urdf``); checked before the work.
    inputs = description_inputs(urdf, srdf, package_paths=package_path or ())
    if output is not None:
        check_writable(output, force=force, inputs=inputs)
    folder = (output.parent if output is not None else Path.cwd()).resolve()
    draft, _ = draft_from_files(
        urdf,
        srdf,
        folder=folder,
        package_paths=package_path or (),
        name=name,
        xacro_args=xacro_args,
    )
    text = render_draft(draft, presets=camera_presets())
    if write_output(text, output, force=force, inputs=inputs):
        sys.stderr.write(
            f"wrote {output}: {plural(len(draft.chains), 'chain')}, "
            f"{plural(len(draft.manipulators), 'manipulator')}, "
            f"{plural(len(draft.cameras), 'camera')}"
            + (", a torso" if draft.torso is not None else "")
            + (", a neck" if draft.neck is not None else "")
            + "; check the lines marked DECIDE, then run "
            f"`robotspec validate {output}`\n"
        )
    # A spec may name files and folders outside its project only with the user's leave.
    project = project_root(folder)  # once: every entry is judged against the same project
    outside = []
    for ref in (*draft.package_paths, draft.urdf, draft.srdf):
        if ref is None or "://" in ref:
            continue
        real = Path(os.path.realpath(folder / ref))
        if refusal(str(real), project) is not None:
            outside.append(real if ref in draft.package_paths else real.parent)
    # Not this run's -P: the spec is validated later, where the user must pass it again.
    allowed = [os.path.realpath(r) for r in user_roots(())]
    outside = [p for p in dict.fromkeys(outside) if not any(inside(str(p), r) for r in allowed)]
    if outside:
        allow = " ".join(f"-P {p}" for p in outside)
        sys.stderr.write(
            f"note: the spec names files outside its project ({folder}), read only when "
            f"allowed: pass {allow} to validate and the other commands (or set "
            "ROS_PACKAGE_PATH; docs/security.md)\n"
        )
