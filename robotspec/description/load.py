"""A robot's description files loaded together: URDF/xacro world, SRDF, and the base connection.

Why one place: the URDF, the SRDF and the spec's extra frames all change the same world (the SRDF
virtual joint becomes the base connection, spec frames become fixed bodies), and every caller (the
compiler, the CLI, tests) must get the same world from the same files.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from robotspec.description.urdf import MeshPolicy, read_description_xml, world_from_urdf_xml
from robotspec.errors import DescriptionError, RobotSpecError, missing_file
from robotspec.model.world import World

if TYPE_CHECKING:
    from lxml import etree

    from robotspec.description.srdf import Srdf
    from robotspec.files.packages import PackageResolver

__all__ = ["Description", "load_description", "read_urdf_tree"]


@dataclass(frozen=True)
class Description:
    """The loaded files of one robot and the world they make."""

    world: World
    urdf_file: Path
    srdf: Srdf | None
    resolver: PackageResolver = field(repr=False)
    warnings: tuple[RobotSpecError, ...] = ()
    #: The URDF's element tree (xacro run): what the world does not keep (``<gazebo>`` sensors,
    #: transmissions), read by ``robotspec init`` as evidence.
    urdf_xml: etree._Element | None = field(default=None, repr=False, compare=False)


def resolve_file(
    ref: str, base: Path, resolver: PackageResolver, *, file: str | None = None
) -> Path:
    """A description path from a spec or CLI: ``package://``, ``file://``, relative or absolute."""
    if "://" in ref:
        return resolver.resolve(ref, relative_to=base, file=file)
    p = Path(ref)
    return p if p.is_absolute() else (base / p)


def read_urdf_tree(
    urdf: str | Path,
    *,
    package_paths: Sequence[str | Path] = (),
    xacro_args: Mapping[str, str] | None = None,
    base_folder: Path,
    share_crawls_with: PackageResolver | None = None,
) -> tuple[etree._Element, Path, PackageResolver]:
    """The element tree of a URDF reference (xacro run), its file and its resolver.

    Relative paths and ``package_paths`` start at ``base_folder``. ``share_crawls_with``: a
    resolver of the same compilation whose package-folder crawls are reused.
    """
    from robotspec.files.packages import PackageResolver

    extra = [p if Path(p).is_absolute() else base_folder / p for p in map(str, package_paths)]
    urdf_ref = str(urdf)
    share = share_crawls_with
    if "://" in urdf_ref:
        share = PackageResolver.create(None, extra_paths=extra, share_crawls_with=share)
        urdf_path = share.resolve(urdf_ref, relative_to=base_folder)
    else:
        urdf_path = Path(urdf_ref) if Path(urdf_ref).is_absolute() else base_folder / urdf_ref
    if not urdf_path.is_file():
        raise missing_file(urdf_path, DescriptionError)
    resolver = PackageResolver.create(urdf_path, extra_paths=extra, share_crawls_with=share)
    return read_description_xml(urdf_path, resolver, xacro_args), urdf_path, resolver


def load_description(
    urdf: str | Path,
    *,
    srdf: str | Path | None = None,
    package_paths: Sequence[str | Path] = (),
    xacro_args: Mapping[str, str] | None = None,
    meshes: MeshPolicy = "report",
    base_folder: Path | None = None,
) -> Description:
    """Load a URDF (or xacro) and optionally its SRDF; URIs resolve through one resolver."""
    base = base_folder or Path.cwd()
    root, urdf_path, resolver = read_urdf_tree(
        urdf, package_paths=package_paths, xacro_args=xacro_args, base_folder=base
    )
    issues: list[RobotSpecError] = []
    world = world_from_urdf_xml(
        root, str(urdf_path), resolver=resolver, meshes=meshes, issues=issues
    )
    srdf_data = None
    if srdf is not None:
        from robotspec.description.srdf_names import map_prefixed_names, self_pair_warnings
        from robotspec.description.srdf_reader import load_srdf

        srdf_path = resolve_file(str(srdf), base, resolver)
        srdf_data = load_srdf(srdf_path, strict=False)
        mapping = map_prefixed_names(srdf_data, world.body_names, world.connection_names)
        srdf_data = mapping.srdf
        issues += [*mapping.warnings, *mapping.errors, *self_pair_warnings(srdf_data)]
    return Description(
        world=world,
        urdf_file=urdf_path,
        srdf=srdf_data,
        resolver=resolver,
        warnings=tuple(issues),
        urdf_xml=root,
    )
