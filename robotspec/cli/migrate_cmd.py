"""``robotspec migrate sdt``: an SDT robot class (hand-written, one class per part) as a spec."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Annotated

import typer

from robotspec.cli.options import PackagePath, write_output

#: This module's commands; robotspec.cli.app adds them to the root app.
app = typer.Typer()
migrate = typer.Typer(
    name="migrate",
    help="Turn another library's robot description into a spec.",
    no_args_is_help=True,
)
app.add_typer(migrate)


@migrate.command("sdt")
def sdt(
    target: Annotated[
        str,
        typer.Argument(
            help="The SDT robot class, MODULE:CLASS (semantic_digital_twin.robots.pr2:PR2)."
        ),
    ],
    urdf: Annotated[str, typer.Option("--urdf", help="The robot's URDF or xacro.")],
    srdf: Annotated[
        str | None, typer.Option("--srdf", help="Its MoveIt SRDF (collision rules).")
    ] = None,
    output: Annotated[
        Path | None, typer.Option("--output", "-o", help="Write the spec here (default: stdout).")
    ] = None,
    force: Annotated[bool, typer.Option("--force", help="Overwrite an existing file.")] = False,
    package_path: PackagePath = None,
) -> None:
    """Read an SDT robot class back into a spec (needs the sdt extra).

    SDT's own steps build the class's parts on the robot of the URDF (read by robotspec);
    every part, state, hardware interface and velocity limit becomes spec data. What a spec
    cannot say is printed and kept as NOTE comments. Run `robotspec validate` on the result.
    """
    from robotspec.compiler.inputs import description_inputs
    from robotspec.files.writing import check_writable
    from robotspec.interop.sdt.migrate import migrate_files, render

    # The robot's own files are never replaced (``-o robot.urdf``); checked before the work.
    inputs = description_inputs(urdf, srdf, package_paths=package_path or ())
    if output is not None:
        check_writable(output, force=force, inputs=inputs)
    folder = (output.parent if output is not None else Path.cwd()).resolve()
    migration = migrate_files(
        target, urdf, srdf=srdf, folder=folder, package_paths=package_path or ()
    )
    for note in migration.notes:
        sys.stderr.write(f"note: {note}\n")
    if write_output(render(migration, source=target), output, force=force, inputs=inputs):
        sys.stderr.write(f"wrote {output}; run `robotspec validate {output}`\n")
