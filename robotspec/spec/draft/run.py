"""Drafting from files: load the robot, write portable references, decide, render.

Shared by ``robotspec init`` and the robot zoo (``tools/zoo.py``), so the zoo checks the
very drafts users get.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

from robotspec.description.load import Description, load_description
from robotspec.spec.draft.build import draft_spec
from robotspec.spec.draft.facts import read_facts
from robotspec.spec.draft.model import Draft
from robotspec.spec.draft.paths import package_candidates, relative_path

__all__ = ["draft_from_files"]


def _named_packages(desc: Description) -> dict[str, Path]:
    """The packages a draft may write ``package://`` URIs of.

    Why not all the resolver knows: around the description, a folder counts as a package by
    its name alone so that the robot's own references resolve (``package://my_robot/...``
    from ``my_robot/urdf/``), but ``package://urdf/robot.urdf`` would be no reference a person
    writes or another tool finds; there a package needs its ``package.xml``.
    """
    resolver = desc.resolver
    here = None if resolver.description is None else resolver.description.parent
    listed = {f for f in resolver.bare_name_folders if f != here}  # -P, environment, installed
    return {
        name: folder
        for name, folder in resolver.packages().items()
        if (folder / "package.xml").is_file()
        or (folder.parent in listed and not (folder == here and _layout_name(folder)))
    }


def _layout_name(folder: Path) -> bool:
    """A folder named for what it holds (``urdf/``), not for the robot: no package name to write.

    Why: ``-P my_robot`` makes ``my_robot/urdf`` findable as ``package://urdf``, which resolves
    but names nothing a person or another tool would look for; the relative path is clearer.
    """
    from robotspec.files.package_search import DESCRIPTION_SUBFOLDERS

    return folder.name.lower() in DESCRIPTION_SUBFOLDERS


def draft_from_files(
    urdf: str,
    srdf: str | None,
    *,
    folder: Path,
    package_paths: Sequence[str | Path] = (),
    name: str | None = None,
    base_folder: Path | None = None,
    xacro_args: Mapping[str, str] | None = None,
) -> tuple[Draft, Description]:
    """The draft of a spec to be written in ``folder``, and the files it was drafted from.

    References are ``package://`` URIs where the file is in a package the spec can find, else
    paths relative to ``folder``; packages found only beside the URDF get their parent folder
    written into ``description.package_paths`` (relative too), so the spec works elsewhere;
    so are the folders given as ``package_paths`` (``-P``), which the spec needs as written.
    ``xacro_args`` are passed to xacro and written into ``description.xacro_args``.
    """
    from robotspec.files.packages import PackageResolver

    base = base_folder or Path.cwd()
    desc = load_description(
        urdf,
        srdf=srdf,
        package_paths=package_paths,
        xacro_args=xacro_args,
        meshes="keep",
        base_folder=base,
    )
    # What a spec finds: the user's -P (written into package_paths below), the environment and
    # the installed data; a URI is written only when it resolves that way, to the very file.
    allowed = [Path(p) if Path(p).is_absolute() else base / p for p in map(str, package_paths)]
    packages = _named_packages(desc)
    extra_paths: list[str] = []

    def resolves(uri: str, path: Path, extra: list[Path]) -> bool:
        from robotspec.errors import RobotSpecError

        resolver = PackageResolver.create(
            None, extra_paths=[*allowed, *extra], share_crawls_with=desc.resolver
        )
        try:
            return resolver.resolve(uri, relative_to=folder).resolve() == path.resolve()
        except (RobotSpecError, OSError, ValueError):
            return False

    def ref(given_ref: str) -> str:
        if "://" in given_ref:
            return given_ref
        path = Path(given_ref) if Path(given_ref).is_absolute() else base / given_ref
        for uri, pkg_root in package_candidates(path, packages):
            if resolves(uri, path, []):
                return uri
            if resolves(uri, path, [pkg_root.parent]):
                entry = relative_path(pkg_root.parent, folder)
                if entry not in extra_paths:
                    extra_paths.append(entry)
                return uri
        return relative_path(path, folder)

    draft = draft_spec(
        desc.world,
        urdf_ref=ref(urdf),
        srdf=desc.srdf,
        srdf_ref=None if srdf is None else ref(srdf),
        name=name or desc.world.name,
        facts=read_facts(desc.urdf_xml),
    )
    for given in package_paths:
        if Path(given).is_dir():
            entry = relative_path(Path(given), folder)
            if entry not in extra_paths:
                extra_paths.append(entry)
    draft.package_paths = extra_paths
    draft.xacro_args = dict(xacro_args or {})
    if desc.srdf is not None:  # what the SRDF reader passed over as MoveIt does (a repeat)
        draft.notes += [
            f"{Path(w.file or '').name}:{w.line}: {w.message}" for w in desc.srdf.warnings
        ]
    return draft, desc
