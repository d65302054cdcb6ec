"""``robotspec init``: draft a spec from a robot's URDF (and SRDF)."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Annotated

import typer

from robotspec.cli.options import PackagePath, write_output

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
    """Draft a spec: SRDF groups become chains, end effectors manipulators, optical frames cameras.

    The draft validates as written; lines marked DECIDE are guesses a person should check.
    """
    from robotspec.description.load import load_description
    from robotspec.errors import RobotSpecError
    from robotspec.files.packages import PackageResolver
    from robotspec.shipped import shipped_schema_path
    from robotspec.spec.draft import draft_spec, portable_ref, relative_path, render_draft

    if output is not None and output.exists() and not force:
        raise RobotSpecError(
            "the file exists; pass --force to overwrite it", file=str(output), kind="output"
        )
    folder = (output.parent if output is not None else Path.cwd()).resolve()
    desc = load_description(
        urdf, srdf=srdf, package_paths=package_path or (), meshes="keep", base_folder=Path.cwd()
    )
    # Packages the spec will find without help (example-robot-data, -P, environment); others
    # (found next to the URDF) get their parent folder written into the spec's package_paths.
    findable = PackageResolver.create(None, extra_paths=package_path or ()).packages()
    packages = desc.resolver.packages()
    extra_paths: list[str] = []

    def ref(given: str) -> str:
        if "://" in given:
            return given
        text, pkg_root = portable_ref(Path(given), folder, packages)
        if pkg_root is not None and pkg_root not in {p.resolve() for p in findable.values()}:
            entry = relative_path(pkg_root.parent, folder)
            if entry not in extra_paths:
                extra_paths.append(entry)
        return text

    urdf_ref = ref(urdf)
    srdf_ref = None if srdf is None else ref(srdf)
    draft = draft_spec(
        desc.world,
        urdf_ref=urdf_ref,
        srdf=desc.srdf,
        srdf_ref=srdf_ref,
        name=name or desc.world.name,
    )
    draft.package_paths = extra_paths
    text = render_draft(draft, schema_hint=shipped_schema_path().as_uri())
    if write_output(text, output):
        sys.stderr.write(
            f"wrote {output}: {len(draft.chains)} chains, {len(draft.manipulators)} manipulators, "
            f"{len(draft.cameras)} cameras; check the lines marked DECIDE, then run "
            f"`robotspec validate {output}`\n"
        )
