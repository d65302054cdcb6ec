"""``robotspec demo``: the main job on a shipped robot, end to end, for a first look."""

from __future__ import annotations

import sys
from typing import Annotated

import typer

from robotspec.cli.app import app
from robotspec.cli.options import PackagePath


@app.command()
def demo(
    robot: Annotated[str, typer.Argument(help="A shipped robot or a spec file.")] = "pr2",
    package_path: PackagePath = None,
) -> None:
    """Validate a robot's spec, then show its chains and its kinematic tree."""
    from robotspec.cli.inspect_cmd import chains, tree
    from robotspec.cli.validate_cmd import validate

    def head(text: str) -> None:
        sys.stdout.write(f"\n== {text}\n")

    head(f"robotspec validate {robot}")
    validate([robot], package_path=package_path)
    head(f"robotspec inspect chains {robot}")
    chains(robot, package_path=package_path)
    head(f"robotspec inspect tree {robot}")
    tree(robot, package_path=package_path)
