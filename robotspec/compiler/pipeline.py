"""The compiler's pipeline: a loaded spec to a robot, every problem of the spec at once.

Steps: compose parts (``parts:``), read the description files (``description``), cross-check the
SRDF against the URDF, add the spec's frames and the base connection to the world, then resolve
and check every part (``build``). :mod:`robotspec.compiler` is the face users call.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from robotspec.compiler.arm_sides import check_arm_sides
from robotspec.compiler.build import Build, build_robot
from robotspec.description.srdf import Srdf
from robotspec.diagnostics import Diagnostics, Loc
from robotspec.errors import RobotSpecError
from robotspec.model.world import ConnectionType, World
from robotspec.semantic import AbstractRobot
from robotspec.shipped import package_data
from robotspec.spec.load import LoadedSpec
from robotspec.spec.models import RobotSpec

if TYPE_CHECKING:
    from robotspec.compose.assembly import Composition
    from robotspec.files.packages import PackageResolver

__all__ = ["CompileResult", "compile_loaded", "load_camera_presets"]


@dataclass(frozen=True)
class CompileResult:
    """What ``robotspec validate`` reports: the robot (if it compiled) and every warning."""

    loaded: LoadedSpec
    robot: AbstractRobot
    warnings: tuple[RobotSpecError, ...]


_PRESETS: dict[tuple[str, int], dict[str, dict[str, Any]]] = {}


def load_camera_presets() -> dict[str, dict[str, Any]]:
    """Camera models from ``templates/cameras.yaml`` (a fresh copy for each caller).

    Parsed once per version of the file: every compilation needs them, and parsing the YAML
    again cost more than the compiler's own checks.
    """
    from robotspec.files.yamlio import load_yaml

    file = package_data("templates", "cameras.yaml")
    key = (str(file), file.stat().st_mtime_ns)
    if key not in _PRESETS:
        _PRESETS.clear()
        _PRESETS[key] = dict(load_yaml(file).data or {})
    return copy.deepcopy(_PRESETS[key])


def _prepare_world(
    loaded: LoadedSpec, world: World, srdf: Any, diag: Diagnostics, *, add_drive: bool
) -> World:
    """Add the spec's frames and the base connection (drive or SRDF virtual joint)."""
    spec = loaded.spec
    frames = []
    for name, f in spec.files.frames.items():
        loc = ("description", "frames", name)
        if f.rpy is not None and f.quaternion is not None:
            diag.error(loc, "give rpy or quaternion, not both")
            continue
        if f.quaternion is not None:
            n = math.sqrt(sum(x * x for x in f.quaternion))
            if abs(n - 1.0) > 1e-3:
                diag.error((*loc, "quaternion"), f"must be a unit quaternion, its norm is {n:.4g}")
                continue
        if world.has_body(name):
            if add_drive:  # loading our own files: a clash is a mistake
                diag.error(loc, f"frame '{name}' already exists in the URDF")
            continue  # from_world: the user's world already has it
        if not world.has_body(f.parent):
            diag.not_found(
                (*loc, "parent"),
                "link",
                f.parent,
                world.body_names,
                (world.source or world.name).rsplit("/", 1)[-1],
            )
            continue
        frames.append((name, f.parent, f.pose()))
    if frames:
        world = world.add_frames(frames)
    if add_drive and spec.drive is not None:
        from robotspec.compiler.base_joint import base_joint_above_root, check_urdf_base_joint

        above = base_joint_above_root(world, spec.root_link)
        if above is not None:
            check_urdf_base_joint(spec, above, world, diag)
            return world
        if spec.drive.joints is not None:
            return _urdf_drive(spec, world, diag)
    if not add_drive or world.parent_connection(world.root) is not None:
        return world
    drive = spec.drive
    vj = None
    if srdf is not None:
        vj = next((v for v in srdf.virtual_joints if v.child_link == world.root.name), None)
    if drive is not None:
        if drive.type == "fixed":
            return world
        if spec.root_link != world.root.name:
            diag.error(
                ("drive",),
                f"a drive moves the URDF's root link '{world.root.name}', "
                f"but the robot's root is '{spec.root}'",
            )
            return world
        kind = ConnectionType.FLOATING if drive.type == "floating" else ConnectionType.PLANAR
        parent = drive.parent_frame
        joint = drive.joint or f"{parent}_T_{world.root.name}"
        try:
            return world.with_base_connection(joint, parent, kind)
        except RobotSpecError as exc:
            at = "parent_frame" if exc.detail.kind == "link" else "joint"
            hint = _own_base_hint(world) if at == "parent_frame" else ""
            diag.error(("drive", at), exc.message + hint, name=exc.detail.name)
            return world
    if vj is not None:
        kind = {"planar": ConnectionType.PLANAR, "floating": ConnectionType.FLOATING}.get(
            vj.type, ConnectionType.FIXED
        )
        try:
            return world.with_base_connection(vj.name, vj.parent_frame, kind)
        except RobotSpecError as exc:
            srdf_file = getattr(srdf, "file", None)
            diag.add(
                exc.located(file=srdf_file, line=getattr(vj, "line", None)), ("description", "srdf")
            )
            return world
    return world


def _own_base_hint(world: World) -> str:
    """How to declare a base the URDF moves itself: its planar joint's child as the root."""
    planar = next((c for c in world.connections if c.type is ConnectionType.PLANAR), None)
    if planar is not None:
        child = world.bodies[planar.child].name
        return (
            f"; the URDF's planar joint '{planar.name}' moves the base: make its child "
            f"'{child}' the robot's root, and that joint is the drive"
        )
    return (
        "; if the URDF models the base's motion itself, name its x, y and theta joints "
        "in drive.joints"
    )


def _urdf_drive(spec: RobotSpec, world: World, diag: Diagnostics) -> World:
    """The drive made of the URDF's own x, y and theta joints (``drive.joints``)."""
    from robotspec.model.planar_drive import collapse_planar_joints

    drive = spec.drive
    assert drive is not None and drive.joints is not None
    loc: Loc = ("drive", "joints")
    if drive.type not in ("omni", "differential"):
        diag.error(
            ("drive", "type"),
            f"a drive of URDF joints is planar: omni or differential, not {drive.type}",
        )
        return world
    missing = [(i, n) for i, n in enumerate(drive.joints) if not world.has_connection(n)]
    for i, name in missing:
        diag.not_found((*loc, i), "joint", name, world.connection_names, _file_name(world))
    if missing:
        return world
    theta = world.get_connection_by_name(drive.joints[2])
    child = world.bodies[theta.child].name
    if spec.root_link != child:
        diag.error(
            ("root",),
            f"the drive's theta joint '{theta.name}' moves '{child}': that is the robot's "
            f"root, not '{spec.root_link}'",
            name=spec.root_link,
        )
        return world
    try:
        return collapse_planar_joints(world, drive.joints, drive.joint)
    except RobotSpecError as exc:
        diag.add(exc, loc)
        return world


def _file_name(world: World) -> str:
    return (world.source or world.name).rsplit("/", 1)[-1]


def _check_srdf(
    srdf: Srdf, world: World, urdf_name: str, diag: Diagnostics, *, own_file: bool
) -> Srdf:
    """The SRDF as the compiler uses it: prefixed names read as the URDF's, problems recorded.

    A composed robot's SRDF was renamed part by part already (``own_file`` is false for it).
    """
    from robotspec.description.srdf_checks import check_srdf_against, check_srdf_references
    from robotspec.description.srdf_names import map_prefixed_names, self_pair_warnings

    ambiguous: frozenset[tuple[int | None, str]] = frozenset()
    if own_file:
        mapping = map_prefixed_names(srdf, world.body_names, world.connection_names)
        srdf, ambiguous = mapping.srdf, mapping.ambiguous
        for err in (*mapping.warnings, *mapping.errors):
            diag.add(err)
    for err in [
        *check_srdf_references(srdf),
        *check_srdf_against(srdf, world.body_names, world.connection_names, urdf_name=urdf_name),
    ]:
        if (err.line, err.name) in ambiguous:
            continue  # its error already says what to change
        # An SRDF often outlives its URDF (HSRB's names odom_x/y/t); like MoveIt, warn and
        # ignore the element. A spec that *uses* a stale name still fails on its own line.
        diag.add(_at_srdf(err.with_severity("warning"), own_file=own_file))
    for err in [*srdf.warnings, *self_pair_warnings(srdf)]:
        diag.add(_at_srdf(err, own_file=own_file))
    return srdf


def _at_srdf(err: RobotSpecError, *, own_file: bool) -> RobotSpecError:
    """An SRDF warning also placed at the spec's ``description.srdf`` (file and line kept).

    Why: ``accept_warnings`` accepts a warning by its spec path; one from the robot's own SRDF
    (a group_state without a group) had none, so no spec naming that SRDF could be warning-free.
    """
    if not own_file or err.severity != "warning" or err.detail.location:
        return err
    return err.located(
        file=err.file, line=err.line, column=err.column, location=("description", "srdf")
    )


def compile_loaded(
    loaded: LoadedSpec,
    *,
    package_paths: Sequence[str | Path] = (),
    world: World | None = None,
    robot_class: type[AbstractRobot] = AbstractRobot,
    strict: bool = False,
) -> CompileResult:
    """The compiler proper: a loaded spec (and optionally the caller's world) to a robot.

    Composes the parts first if the spec has ``parts:``, reads the description (or takes
    ``world``), cross-checks the SRDF, adds the spec's frames and base connection, then resolves
    and checks every part; all problems of the spec are raised together.
    """
    from robotspec.description.load import resolve_file
    from robotspec.spec.load import check_package_paths

    check_package_paths(loaded, package_paths)
    composition = None
    if loaded.spec.parts:
        from robotspec.compose import compose

        composition = compose(loaded, package_paths=package_paths)
        loaded = composition.loaded
    spec = loaded.spec
    desc_spec = spec.files
    diag = Diagnostics(loaded)
    paths = [*desc_spec.package_paths, *map(str, package_paths)]
    base_world, resolver, urdf_name = _base_world(loaded, composition, world, paths, diag)
    srdf = None if composition is None else composition.srdf
    if composition is None and desc_spec.srdf is not None:
        from robotspec.description.srdf_reader import load_srdf

        try:
            srdf = load_srdf(resolve_file(desc_spec.srdf, loaded.folder, resolver), strict=False)
        except RobotSpecError as exc:
            diag.add_all(exc, ("description", "srdf"))
    if srdf is not None:
        srdf = _check_srdf(srdf, base_world, urdf_name, diag, own_file=composition is None)
    prepared = _prepare_world(loaded, base_world, srdf, diag, add_drive=world is None)
    build = Build(
        loaded=loaded, world=prepared, diag=diag, srdf=srdf, presets=load_camera_presets()
    )
    robot = build_robot(build, robot_class)
    check_arm_sides(robot, loaded.spec.chains, diag)
    diag.accept(loaded.spec.accept_warnings)
    diag.raise_if_failed(strict=strict)
    return CompileResult(
        loaded=loaded, robot=robot, warnings=tuple(diag.in_file_order(diag.warnings))
    )


def _base_world(
    loaded: LoadedSpec,
    composition: Composition | None,
    world: World | None,
    paths: list[str],
    diag: Diagnostics,
) -> tuple[World, PackageResolver, str]:
    """The world the spec describes, its package resolver and the URDF's file name.

    From the composed parts' joined tree, from the spec's URDF, or the caller's ``world``
    (``from_world``: the spec's URDF is not read again, and the SRDF is found next to the
    world's source file or on the package path).
    """
    from robotspec.description.load import load_description

    desc_spec = loaded.spec.files
    if world is None and composition is not None:
        from robotspec.description.urdf import world_from_urdf_xml

        issues: list[RobotSpecError] = []
        base_world = world_from_urdf_xml(
            copy.deepcopy(composition.urdf),
            composition.source,
            resolver=composition.resolver,
            meshes="report",
            issues=issues,
            checked=True,  # each part's file was checked; composition checked the joins
        )
        for w in issues:
            diag.add(w)
        resolver, urdf_name = composition.resolver, composition.source
    elif world is None:
        try:
            desc = load_description(
                desc_spec.urdf,
                srdf=None,
                package_paths=paths,
                xacro_args=desc_spec.xacro_args,
                base_folder=loaded.folder,
            )
        except RobotSpecError as exc:
            diag.add_all(exc, ("description", "urdf"))
            diag.raise_if_failed()
            raise
        for w in desc.warnings:
            diag.add(w)
        base_world, resolver, urdf_name = desc.world, desc.resolver, desc.urdf_file.name
    else:
        # from_world: the caller's world is the description; the spec's URDF is not read
        # again (it may not even be on this machine's package path). The SRDF is found next
        # to the world's source file or on the package path.
        from robotspec.files.packages import PackageResolver as Resolver

        source = Path(world.source) if world.source else None
        folder = loaded.folder
        extra = [p if Path(p).is_absolute() else folder / p for p in paths]
        resolver = Resolver.create(
            source if source is not None and source.is_file() else None, extra_paths=extra
        )
        base_world, urdf_name = world, (world.source or world.name).rsplit("/", 1)[-1]
    return base_world, resolver, urdf_name
