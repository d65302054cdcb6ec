"""``robotspec export``: write what a compiled spec means in other formats (a RobotInfo, ...)."""

from __future__ import annotations

import os
import sys
from collections.abc import Callable
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from robotspec.cli.options import (
    Force,
    OutputFile,
    PackagePath,
    SpecArg,
    write_output,
)
from robotspec.files.writing import check_writable

if TYPE_CHECKING:
    from robotspec.semantic import AbstractRobot

#: This module's commands; robotspec.cli.app adds them to the root app.
app = typer.Typer()


export_app = typer.Typer(help="Export a compiled robot to other formats.", no_args_is_help=True)
app.add_typer(export_app, name="export")


def _inputs(
    spec: str, package_path: list[Path] | None, robot: AbstractRobot | None = None
) -> dict[Path, str]:
    """The robot's own files, which an export may never replace (``-o robot.urdf``)."""
    from robotspec.compiler.inputs import spec_inputs

    return spec_inputs(spec, package_paths=package_path or (), robot=robot)


@export_app.command("robotinfo")
def robotinfo(
    spec: SpecArg,
    chain: Annotated[
        str, typer.Option("--chain", "-c", help="The chain to export (see `inspect chains`).")
    ],
    output: OutputFile = None,
    force: Force = False,
    package_path: PackagePath = None,
) -> None:
    """A Robot Raconteur RobotInfo YAML of one chain: H/P kinematics, limits, flange pose.

    URDF has no acceleration limits, so they default to 5 x the velocity limit; continuous joints
    become revolute within +-2 pi. Each default used is reported on stderr.
    """
    from robotspec.driver.export import dump_robot_info_yaml
    from robotspec.export.robotinfo import export_spec_chain

    if output is not None:
        check_writable(output, force=force)  # before the work, as the write refuses it again
    ex = export_spec_chain(spec, chain, package_path)
    header = (
        f"RobotInfo of chain '{chain}' of {spec}, exported by robotspec.\n"
        "H/P in the frame of the chain root at q = 0; flange_pose holds the tip rotation."
    )
    text = dump_robot_info_yaml(ex.info, header=header)
    for note in ex.notes:
        sys.stderr.write(f"note: {note}\n")
    inputs = _inputs(spec, package_path) if output is not None else {}
    if not write_output(text, output, force=force, inputs=inputs):
        return
    sys.stderr.write(
        f"wrote {output} ({len(ex.info.joint_info)} joints, chain "
        f"{ex.info.chains[0].kin_chain_identifier.name})\n"
    )


@export_app.command("srdf")
def srdf(
    spec: SpecArg,
    output: OutputFile = None,
    force: Force = False,
    package_path: PackagePath = None,
) -> None:
    """A MoveIt SRDF of the compiled robot: a group per chain, end effectors, group states.

    Disabled collision pairs keep the reason of the SRDF they came from; the drive becomes the
    virtual joint.
    """
    from robotspec.compiler import compile_robot
    from robotspec.export.srdf import srdf_from_robot, write_srdf

    if output is not None:
        check_writable(output, force=force)
    robot = compile_robot(spec, package_paths=package_path or ())
    exported = srdf_from_robot(robot)
    inputs = _inputs(spec, package_path, robot) if output is not None else {}
    if not write_output(write_srdf(exported), output, force=force, inputs=inputs):
        return
    sys.stderr.write(
        f"wrote {output}: {len(exported.groups)} groups, {len(exported.end_effectors)} end "
        f"effectors, {len(exported.group_states)} group states, "
        f"{len(exported.disabled_collisions)} disabled pairs\n"
    )


@export_app.command("urdf")
def urdf(
    spec: SpecArg,
    output: OutputFile = None,
    force: Force = False,
    package_path: PackagePath = None,
) -> None:
    """One URDF of the robot: a composed robot's parts joined, welds as fixed joints.

    For any spec, xacro is run and the spec's extra frames become links. Relative mesh paths
    become absolute; package:// URIs are kept.
    """
    from robotspec.compiler import resolve_spec
    from robotspec.export.urdf import joined_urdf, urdf_text
    from robotspec.spec.load import load_spec

    if output is not None:
        check_writable(output, force=force)
    loaded = load_spec(resolve_spec(spec), allowed=package_path or ())
    tree = joined_urdf(loaded, package_paths=package_path or ())
    text = urdf_text(tree, comment=f"{loaded.spec.name}: exported by robotspec from {spec}")
    inputs = _inputs(spec, package_path) if output is not None else {}
    if not write_output(text, output, force=force, inputs=inputs):
        return
    links = sum(1 for _ in tree.iterfind("link"))
    joints = sum(1 for _ in tree.iterfind("joint"))
    sys.stderr.write(f"wrote {output}: {links} links, {joints} joints\n")


def _plain_name(value: str | None) -> str | None:
    """``--name`` must be a file stem: no folder, no ``..``, nothing a file name cannot hold.

    Why: the stem is joined to ``--output``; ``--name ../../x`` wrote outside it.
    """
    if value is None:
        return None
    seps = {"/", "\\", os.sep, *([os.altsep] if os.altsep else [])}
    bad = (
        not value.strip()
        or ".." in value
        or value == "."
        or any(sep in value for sep in seps)
        or any(ord(ch) < 0x20 or ord(ch) == 0x7F for ch in value)
    )
    if bad:
        raise typer.BadParameter(
            f"{value!r} is not a plain file name (no folders, no '..', no control characters)"
        )
    return value


@export_app.command("bundle")
def bundle_cmd(
    spec: SpecArg,
    output: Annotated[
        Path, typer.Option("--output", "-o", help="Folder to write NAME.urdf/.srdf/.yaml into.")
    ],
    name: Annotated[
        str | None,
        typer.Option(
            "--name",
            help="File stem (default: the spec's file stem); a plain name, no folders.",
            callback=_plain_name,
        ),
    ] = None,
    force: Force = False,
    package_path: PackagePath = None,
) -> None:
    """URDF + SRDF + a flat spec naming them: the same robot without the source files.

    `robotspec validate FOLDER/NAME.yaml` then compiles to the same robot (a composed one too).
    Existing files are kept unless --force; a symbolic link is never written through, nor one
    of the robot's own files.
    """
    from robotspec.cli.output import plural
    from robotspec.compiler import check_spec, resolve_spec
    from robotspec.compiler.inputs import spec_inputs
    from robotspec.export.urdf import bundle
    from robotspec.files.meshes import read_mesh_bytes
    from robotspec.files.writing import write_files

    path = resolve_spec(spec)
    stem = name or path.stem
    targets = [output / f"{stem}{suffix}" for suffix in (".urdf", ".srdf", ".yaml")]
    for target in targets:  # before the work; all three are checked again before any is written
        check_writable(target, under=output, force=force)
    result = check_spec(path, package_paths=package_path or ())
    out = bundle(result, name=stem, package_paths=package_path or ())
    inputs = spec_inputs(path, package_paths=package_path or (), robot=result.robot)
    copies = [(output / target, source) for target, source in out.meshes]
    files: list[tuple[Path, str | Callable[[], bytes]]] = [
        *zip(targets, (out.urdf, out.srdf, out.spec), strict=True),
        *((target, partial(read_mesh_bytes, source)) for target, source in copies),
    ]
    # Every file, the mesh folder too, below --output without a link followed: checked first.
    write_files(files, under=output, force=force, inputs=inputs)
    carried = f" and {plural(len(copies), 'mesh file')} in {stem}_meshes/" if copies else ""
    sys.stderr.write(f"wrote {output}/{stem}.urdf, .srdf and .yaml{carried}\n")


@export_app.command("mjcf")
def mjcf_cmd(
    spec: SpecArg,
    output: Annotated[
        Path,
        typer.Option("--output", "-o", help="The MJCF file; meshes go to STEM_meshes/ beside it."),
    ],
    gravity_compensation: Annotated[
        bool,
        typer.Option(
            "--gravity-compensation",
            help="Cancel gravity on every body (counterbalanced arms, gravity feed-forward).",
        ),
    ] = False,
    force: Force = False,
    package_path: PackagePath = None,
) -> None:
    """MuJoCo's MJCF of the compiled robot, with its semantics and position servos.

    Every body is kept (fixed links too); tool frames become sites, cameras cameras, disabled
    pairs excludes, mimic joints equality couplings, named states keyframes; each commanded
    joint gets a position servo within its limits and effort. Meshes are written as binary STL
    (COLLADA converted). Velocity limits, which MJCF cannot hold, are listed in a comment.
    """
    from robotspec.cli.output import plural
    from robotspec.compiler import check_spec, resolve_spec
    from robotspec.compiler.inputs import spec_inputs
    from robotspec.export.mjcf import mjcf_export
    from robotspec.export.urdf import joined_urdf
    from robotspec.files.writing import write_files
    from robotspec.spec.load import load_spec

    if output.suffix.lower() != ".xml":
        raise typer.BadParameter(f"{output} must end in .xml (MuJoCo's MJCF)", param_hint="-o")
    folder = output.parent
    check_writable(output, under=folder, force=force)
    path = resolve_spec(spec)
    result = check_spec(path, package_paths=package_path or ())
    robot = result.robot
    assert robot is not None
    paths = package_path or ()
    tree = joined_urdf(load_spec(path, allowed=paths), package_paths=paths)
    out = mjcf_export(robot, tree, name=output.stem, gravity_compensation=gravity_compensation)
    inputs = spec_inputs(path, package_paths=package_path or (), robot=robot)
    files: list[tuple[Path, str | Callable[[], bytes]]] = [
        (output, out.xml),
        *((folder / rel, produce) for rel, produce in out.meshes),
    ]
    write_files(files, under=folder, force=force, inputs=inputs)
    for note in out.notes:
        sys.stderr.write(f"note: {note}\n")
    carried = f" and {plural(len(out.meshes), 'mesh file')} in {output.stem}_meshes/"
    sys.stderr.write(
        f"wrote {output}: {len(robot.world.bodies)} bodies, "
        f"{plural(len(out.joints), 'joint')}, {plural(len(out.actuated), 'position servo')}"
        f"{carried if out.meshes else ''}\n"
    )
