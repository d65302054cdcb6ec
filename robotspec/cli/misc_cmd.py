"""``robotspec list`` and ``robotspec schema``."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Annotated

import typer

from robotspec.cli.options import Force, write_output
from robotspec.cli.table import render_table

#: This module's commands; robotspec.cli.app adds them to the root app.
app = typer.Typer()


@app.command("list")
def list_robots() -> None:
    """The robots shipped with robotspec and the description each is built from."""
    from robotspec.shipped import shipped_spec_files
    from robotspec.spec.load import load_spec

    rows = []
    for name, path in shipped_spec_files().items():
        spec = load_spec(path).spec
        if spec.description is not None:
            source = spec.description.urdf
        else:
            source = "parts: " + ", ".join(
                f"{k} ({p.spec or Path(p.urdf or '').name})" for k, p in spec.parts.items()
            )
        rows.append([name, spec.name, source])
    sys.stdout.write(render_table(["name", "robot", "description"], rows) + "\n")


@app.command()
def schema(
    output: Annotated[
        Path | None, typer.Option("--output", "-o", help="Write to this file instead of stdout.")
    ] = None,
    force: Force = False,
) -> None:
    """The JSON Schema of the spec format, for editors (YAML language server)."""
    from robotspec.spec.load import json_schema_text

    text = json_schema_text()
    write_output(text, output, force=force)
