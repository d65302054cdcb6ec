"""Options shared by several commands, declared once."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

PackagePath = Annotated[
    list[Path] | None,
    typer.Option(
        "--package-path",
        "-P",
        help="Extra folder to search for ROS packages (repeatable).",
        show_default=False,
    ),
]
JsonFlag = Annotated[bool, typer.Option("--json", help="Print JSON instead of a table.")]
SpecArg = Annotated[
    str, typer.Argument(help="A spec file, or the name of a shipped robot (see `robotspec list`).")
]
