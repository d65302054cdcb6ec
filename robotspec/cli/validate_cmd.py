"""``robotspec validate``: every problem of every spec, as ``file:line:col: severity: message``."""

from __future__ import annotations

from enum import StrEnum
from typing import Annotated

import typer

from robotspec.cli.options import PackagePath, complete_spec

#: This module's commands; robotspec.cli.app adds them to the root app.
app = typer.Typer()


class Format(StrEnum):
    """Output formats of validate."""

    text = "text"
    json = "json"


@app.command()
def validate(
    specs: Annotated[
        list[str],
        typer.Argument(help="Spec files or shipped robot names.", autocompletion=complete_spec),
    ],
    strict: Annotated[bool, typer.Option("--strict", help="Treat warnings as errors.")] = False,
    format: Annotated[Format, typer.Option("--format", help="text or json.")] = Format.text,
    package_path: PackagePath = None,
) -> None:
    """Check specs against their robot files; exit 0 if valid, 1 if not."""
    from robotspec.cli.validation_report import report_validation

    n_err = report_validation(
        specs,
        strict=strict,
        as_json=format is Format.json,
        package_paths=package_path or (),
    )
    if n_err:
        raise typer.Exit(1)
