"""The typer application object and the entry point that renders robotspec errors."""

from __future__ import annotations

import os
import sys
from typing import Annotated

import typer

from robotspec.cli import (
    annotate_cmd,
    collisions_cmd,
    demo_cmd,
    doctor_cmd,
    drive_cmd,
    export_cmd,
    init_cmd,
    inspect_cmd,
    migrate_cmd,
    misc_cmd,
    output,
    render_cmd,
    setup_cmd,
    validate_cmd,
)

app = typer.Typer(
    name="robotspec",
    help="Robot semantics as data: load, validate, inspect and drive robots.",
    no_args_is_help=True,
    add_completion=True,
    pretty_exceptions_enable=False,
)


@app.callback()
def _root(
    verbose: Annotated[
        bool, typer.Option("--verbose", "-v", help="Show a traceback on errors (for bug reports).")
    ] = False,
    version: Annotated[
        bool,
        typer.Option(
            "--version",
            is_eager=True,
            callback=doctor_cmd.print_version,
            help="Print the version and which cores answer queries (C or fallback), and exit.",
        ),
    ] = False,
) -> None:
    """Robot semantics as data: load, validate, inspect and drive robots."""
    if verbose:
        os.environ["ROBOTSPEC_VERBOSE"] = "1"


# Each command module owns its typer app; they import nothing heavy at module level, so
# registering them all keeps `robotspec --help` fast. Commands never import each other.
for _module in (  # in the order a user meets them: check, look, start, write, drive
    validate_cmd,
    inspect_cmd,
    init_cmd,
    setup_cmd,
    migrate_cmd,
    misc_cmd,
    export_cmd,
    annotate_cmd,
    collisions_cmd,
    render_cmd,
    drive_cmd,
    demo_cmd,
    doctor_cmd,
):
    app.add_typer(_module.app)


def main(argv: list[str] | None = None) -> None:
    """Console-script entry point: run the app, render package errors, never leak a traceback."""
    code = output.run_app(app, argv)
    sys.exit(code)
