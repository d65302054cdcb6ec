"""``robotspec setup``: the setup assistant, a page where a draft becomes a valid spec."""

from __future__ import annotations

import os
import sys
from pathlib import Path
from typing import Annotated

import typer

from robotspec.cli.options import PackagePath

#: This module's commands; robotspec.cli.app adds them to the root app.
app = typer.Typer()


def _default_output(robot: str) -> Path:
    """A URDF's spec beside the current folder (``pr2.urdf`` -> ``pr2.yaml``); a spec itself."""
    if robot.lower().endswith((".yaml", ".yml")):
        return Path(robot)
    name = Path(robot.split("://")[-1]).name
    for suffix in (".xacro", ".urdf"):
        name = name.removesuffix(suffix)
    return Path(f"{name or 'robot'}.yaml")


@app.command("setup")
def setup(
    robot: Annotated[
        str, typer.Argument(help="The robot's URDF or xacro (drafted first), or a spec to edit.")
    ],
    srdf: Annotated[
        str | None, typer.Option("--srdf", help="Its MoveIt SRDF (with a URDF).")
    ] = None,
    output: Annotated[
        Path | None,
        typer.Option("--output", "-o", help="Where save writes the spec (default: NAME.yaml)."),
    ] = None,
    host: Annotated[
        str, typer.Option("--host", help="Interface to serve on (loopback by default).")
    ] = "127.0.0.1",
    port: Annotated[
        int, typer.Option("--port", min=0, max=65535, help="TCP port (0 picks a free one).")
    ] = 8080,
    force: Annotated[
        bool, typer.Option("--force", help="Start a new draft over an existing output file.")
    ] = False,
    allow_save: Annotated[
        list[Path] | None,
        typer.Option(
            "--allow-save",
            help="A folder 'save as' may also write in (repeatable; default: -o's folder only).",
        ),
    ] = None,
    package_path: PackagePath = None,
) -> None:
    """A setup assistant in the browser: answer the draft's guesses, pick parts, save a spec.

    The robot in 3D beside its kinematic tree; every DECIDE of the draft as a question; chains,
    hands, cameras and the drive set by picking links; named states by sliders; validation live;
    the self-collision matrix and its audit; save writes a spec validate accepts. Ctrl-C stops.
    """
    from robotspec.errors import RobotSpecError
    from robotspec.render.deps import require
    from robotspec.setup.source import is_spec_file

    require("viser", "viser", "setup")
    from robotspec.cli.audit_report import audit_text
    from robotspec.setup.access import is_loopback
    from robotspec.setup.page import SetupPage
    from robotspec.setup.session import SetupSession
    from robotspec.setup.targets import SPEC_SUFFIXES

    out = output if output is not None else _default_output(robot)
    if out.suffix.lower() not in SPEC_SUFFIXES:
        raise typer.BadParameter(f"a spec is a .yaml or .yml file, not {out}", param_hint="-o")
    folders = [Path(os.path.normpath(Path(f).absolute())) for f in allow_save or ()]
    missing = [str(f) for f in folders if not f.is_dir()]
    if missing:
        raise typer.BadParameter(
            f"folder does not exist: {', '.join(missing)}", param_hint="--allow-save"
        )
    if not is_spec_file(robot) and out.exists() and not force:
        raise RobotSpecError(
            f"the file exists; continue editing it with `robotspec setup {out}`, "
            "or pass --force to start a new draft over it",
            file=str(out),
            kind="output",
        )
    if srdf is not None and is_spec_file(robot):
        raise typer.BadParameter("a spec names its SRDF itself", param_hint="--srdf")
    session = SetupSession.open(
        robot, output=out, srdf=srdf, package_paths=package_path or (), allow_save=folders
    )
    page = SetupPage(session, host=host, port=port, audit_report=audit_text)
    v = session.validation
    where = ", ".join(str(f) for f in session.fence.folders)
    sys.stdout.write(
        f"setting up {session.source.draft.name}; saves to {out} "
        f"({len(session.snapshot.questions)} open questions, {len(v.errors)} errors); "
        f"'save as' writes only in {where}. Ctrl-C stops.\n"
        "Open the page at this address (its token lets only you in; do not share it):\n"
        f"    {page.url}\n"
    )
    if not is_loopback(host):
        sys.stdout.write(
            f"note: serving on {host}, so other machines can reach the page; the token is "
            "required of every connection, and the address travels unencrypted (http)\n"
        )
    sys.stdout.flush()
    try:
        page.viewer.wait()
    except KeyboardInterrupt:
        sys.stdout.write("stopped" + ("" if session.snapshot.saved else " (not saved)") + "\n")
    finally:
        page.stop()
