"""``robotspec annotate``: a spec's semantics added to a model of the user's own."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Annotated

import typer

from robotspec.cli.options import Force, PackagePath, SpecArg

#: This module's commands; robotspec.cli.app adds them to the root app.
app = typer.Typer()

annotate_app = typer.Typer(
    help="Add a spec's semantics to a model of your own (MuJoCo MJCF).", no_args_is_help=True
)
app.add_typer(annotate_app, name="annotate")


@annotate_app.command("mjcf")
def mjcf_cmd(
    spec: SpecArg,
    model: Annotated[
        Path, typer.Argument(help="Your MJCF (Menagerie's, robosuite's, MuJoCo's from a URDF).")
    ],
    output: Annotated[
        Path, typer.Option("--output", "-o", help="The annotated MJCF to write (.xml).")
    ],
    map_: Annotated[
        list[str] | None,
        typer.Option(
            "--map",
            metavar="THEIRS=OURS",
            help="A joint or body of the model that is the robot's OURS (repeatable).",
        ),
    ] = None,
    excludes: Annotated[
        bool,
        typer.Option(
            "--excludes", help="Add the disabled collision pairs as <exclude> of matched bodies."
        ),
    ] = False,
    tolerance: Annotated[
        float,
        typer.Option(
            "--tolerance",
            help="How far (m, rad) their bodies and the sites may stray from the robot's "
            "kinematics (a hand-rounded model needs more than the default).",
        ),
    ] = 1e-6,
    force: Force = False,
    package_path: PackagePath = None,
) -> None:
    """Tool frames as sites, cameras, named states as keyframes, on YOUR MuJoCo model.

    Joints and bodies are matched by name, then by name without a common prefix (Menagerie's
    `joint1` is the URDF's `panda_joint1`), then by --map; the match is proved by forward
    kinematics at random configurations (bodies may be framed differently; a joint turning
    the other way is refused). Nothing of the model is changed; a name already taken gets a
    `_robotspec` suffix. Needs the mujoco extra.
    """
    from robotspec.cli.output import plural
    from robotspec.compiler import check_spec, resolve_spec
    from robotspec.compiler.inputs import spec_inputs
    from robotspec.driver.mujoco_model import require_mujoco
    from robotspec.files.writing import check_writable, write_file
    from robotspec.interop.mujoco_annotate import annotate_mjcf
    from robotspec.interop.mujoco_names import parse_map

    require_mujoco("robotspec annotate mjcf")
    if output.suffix.lower() != ".xml":
        raise typer.BadParameter(f"{output} must end in .xml (MuJoCo's MJCF)", param_hint="-o")
    mapping = parse_map(map_ or [])
    inputs = {Path(model): "the model being annotated"}
    check_writable(output, force=force, inputs=inputs)
    path = resolve_spec(spec)
    result = check_spec(path, package_paths=package_path or ())
    robot = result.robot
    assert robot is not None
    out = annotate_mjcf(
        robot, model, mapping=mapping, excludes=excludes, output=output, tolerance=tolerance
    )
    inputs.update(spec_inputs(path, package_paths=package_path or (), robot=robot))
    write_file(output, out.xml, force=force, inputs=inputs)
    site_error = out.check_file(output)  # the file as written, read back by MuJoCo
    for note in out.notes:
        sys.stderr.write(f"note: {note}\n")
    how = ", ".join(
        f"{n} {label}"
        for label, n in (
            ("by name", out.joints.count("name")),
            ("without a prefix", out.joints.count("prefix")),
            ("by --map", out.joints.count("map")),
        )
        if n
    )
    bodies = len(out.bodies.pairs)
    excluded = f", {plural(len(out.excludes), 'exclude')}" if excludes else ""
    sys.stderr.write(
        f"matched {plural(len(out.joints.pairs), 'joint')} ({how or 'none'}) and {bodies} "
        f"{'body' if bodies == 1 else 'bodies'} by their names; root '{out.root[0]}' is their "
        f"'{out.root[1]}'; bodies fit within {out.body_error:.1g} m/rad\n"
    )
    sites = ", ".join(f"{s.name} on {s.body}" for s in out.sites) or "none"
    sys.stderr.write(
        f"wrote {output}: sites {sites}, {plural(len(out.cameras), 'camera')}, "
        f"{plural(len(out.keys), 'keyframe')}{excluded}; read back, the sites and cameras are "
        f"within {site_error:.1g} m/rad of the spec's frames\n"
    )
