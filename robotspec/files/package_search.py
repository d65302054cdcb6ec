"""Where ROS packages are: crawling folders for ``package.xml``, and the user's search folders.

Why separate from the resolver: finding packages (bounded crawls, manifests read by their head,
``ROS_PACKAGE_PATH``/``AMENT_PREFIX_PATH``, the folders around a description, the
``example-robot-data`` wheel) is one job; resolving and fencing URIs is
:class:`~robotspec.files.packages.PackageResolver`'s.
"""

from __future__ import annotations

import importlib.metadata
import os
import re
from collections.abc import Mapping, Sequence
from pathlib import Path

from robotspec.files.reading import read_head

__all__ = [
    "PACKAGE_NAME",
    "enclosing_packages",
    "example_robot_data_folders",
    "folder_packages",
    "user_roots",
    "walk_up",
]

#: How deep below a search folder the crawl looks for ``package.xml`` (rospack crawls without a
#: bound; a bound keeps a stray ``/`` or home folder on the path from scanning the disk).
MAX_CRAWL_DEPTH = 3

#: How many folders above the description's folder are checked for enclosing packages.
MAX_WALK_UP = 4

#: Marker files that make colcon, catkin and ament skip a folder; the crawl honours them too.
IGNORE_MARKERS = ("CATKIN_IGNORE", "COLCON_IGNORE", "AMENT_IGNORE")

_MANIFEST_NAME = re.compile(rb"<name>\s*([^<]*?)\s*</name>")
_MANIFEST_HEAD = 16384
_XML_COMMENT = re.compile(rb"<!--.*?-->", re.S)
#: What a ROS package name may be (REP 144, with the dots and dashes real packages use).
PACKAGE_NAME = re.compile(r"^[A-Za-z0-9_][A-Za-z0-9_.\-]*$")


def declared_name(folder: Path) -> str:
    """The ``<name>`` a ``package.xml`` declares, or the folder name when it cannot be read.

    Why the fallback: a broken manifest should not hide a package whose folder is named right,
    which is the usual case.
    """
    data = read_head(folder / "package.xml", _MANIFEST_HEAD)  # never a FIFO or a device
    if data is None:
        return folder.name
    # A text search, not an XML parse: every search folder's manifests are read on each load,
    # and the name is plain text near the top (no entities are expanded either way).
    match = _MANIFEST_NAME.search(_XML_COMMENT.sub(b"", data))
    text = match.group(1).decode("utf-8", "replace").strip() if match else ""
    return text if PACKAGE_NAME.match(text) else folder.name


def _listing(folder: Path) -> list[os.DirEntry[str]] | None:
    try:
        with os.scandir(folder) as it:
            return sorted(it, key=lambda e: e.name)
    except OSError:
        return None


def crawl(
    folder: Path,
    entries: list[os.DirEntry[str]],
    depth: int,
    declared: dict[str, Path],
    named: dict[str, Path],
    *,
    bare: bool,
    flat: bool = False,
) -> None:
    """Collect packages below ``folder``: ``declared`` by manifest name, ``named`` by folder name.

    ``named`` holds every package folder's own name and, when ``bare``, the direct children
    without a manifest (``example-robot-data``'s ``robots/pr2_description``); they rank below
    declared names.

    Why not descend into packages: rospack stops at a package too, so a package's test data or
    vendored copies never shadow real packages. Each folder is listed once (no per-marker
    ``stat``): the crawl runs for every description loaded.
    """
    for entry in entries:
        if entry.name.startswith("."):
            continue
        try:
            if not entry.is_dir():
                continue
        except OSError:
            continue
        child = Path(entry.path)
        listing = _listing(child)
        if listing is None:
            continue
        names = {e.name for e in listing}
        if names.intersection(IGNORE_MARKERS):
            continue
        if "package.xml" in names:
            declared.setdefault(declared_name(child), child)
            # The folder name is an alias too: pinocchio and example-robot-data's URDFs use
            # ``package://example-robot-data`` for a manifest named ``example_robot_descriptions``.
            named.setdefault(entry.name, child)
            continue
        if bare and depth == 1 and PACKAGE_NAME.match(entry.name):
            named.setdefault(entry.name, child)
            if flat:
                continue  # a flat folder's children are its packages; nothing nests in them
        if depth < MAX_CRAWL_DEPTH:
            crawl(child, listing, depth + 1, declared, named, bare=bare, flat=flat)


def folder_packages(folder: Path, *, bare: bool, flat: bool = False) -> dict[str, Path]:
    """The packages one search folder provides, declared names before bare folder names."""
    if (folder / "package.xml").is_file():
        return {declared_name(folder): folder, folder.name: folder}
    declared: dict[str, Path] = {}
    named: dict[str, Path] = {}
    crawl(folder, _listing(folder) or [], 1, declared, named, bare=bare, flat=flat)
    for name, path in named.items():
        declared.setdefault(name, path)
    return declared


def split_path_list(value: str | None) -> list[Path]:
    if not value:
        return []
    return [Path(p) for p in value.split(os.pathsep) if p.strip()]


def example_robot_data_folders() -> list[Path]:
    """The ``example-robot-data`` wheel's robots folder and cmeel share folder, if installed."""
    try:
        dist = importlib.metadata.distribution("example-robot-data")
    except importlib.metadata.PackageNotFoundError:
        return []
    share = Path(str(dist.locate_file("cmeel.prefix/share/example-robot-data")))
    if not share.is_dir():
        return []
    return [share / "robots", share.parent]


def walk_up(description_folder: Path) -> tuple[list[Path], list[Path]]:
    """Search folders and package roots found around a description file.

    Why walk up: a description usually sits inside its own package (``pkg/urdf/robot.urdf``)
    whose siblings (``pkg_meshes``) are what ``package://`` names, exactly as in a catkin
    ``src`` folder. The enclosing package becomes readable, its parent folder only searched:
    a ``package.xml`` never widens the roots beyond its own package (the packages found beside
    it are readable each on its own, see :meth:`PackageResolver.is_allowed`).
    """
    home = Path(os.path.normpath(Path.home().absolute()))
    search = [description_folder]
    roots: list[Path] = []
    folder = description_folder
    for _ in range(MAX_WALK_UP):
        if folder == home or folder.parent == folder:
            break
        if (folder / "package.xml").is_file():
            roots.append(folder)
            if folder.parent not in (home, Path(folder.anchor)):
                search.append(folder.parent)
        folder = folder.parent
    return search, roots


#: Folders a robot description keeps its URDF in, inside the description's own folder (whose
#: ``meshes/`` beside it the URDF names as ``../meshes/...``), lower case.
DESCRIPTION_SUBFOLDERS = frozenset({"urdf", "xacro"})


def description_root(description: Path) -> list[Path]:
    """The robot description's own folder when it is no ROS package: the one above ``urdf/``.

    Why: the most common layout outside ROS is ``robot/urdf/robot.urdf`` with ``robot/meshes/``
    named as ``../meshes/...``; the folder holding both is the description, as a package folder
    is. Only one level: ``urdf/`` of the filesystem root or of the home folder widens nothing.
    """
    folder = Path(os.path.normpath(description.parent))
    if folder.name.lower() not in DESCRIPTION_SUBFOLDERS:
        return []
    parent = folder.parent
    home = Path(os.path.normpath(Path.home().absolute()))
    if parent == home or parent.parent == parent:
        return []
    return [parent]


#: How many folders above the description's folder may be packages enclosing it by name.
MAX_ENCLOSING = 8


def enclosing_packages(
    description_folder: Path, own_roots: Sequence[Path]
) -> list[tuple[str, Path]]:
    """The packages that hold the description, nearest first: (name, folder) pairs.

    Why first of all: the file being read belongs to the package around it, so its
    ``package://kinova_description/...`` and ``$(find my_robot)`` mean that package, not an
    installed one of the same name (example-robot-data's ``kinova_description``) nor one on the
    user's path. A folder counts by its ``package.xml`` name and by its own name (a description
    kept without a manifest: ``my_robot/urdf/robot.urdf`` naming ``package://my_robot/...``).
    Only folders the description may read anyway are walked (``own_roots``: its folder, its
    package, the folder above ``urdf/``, its marked project), so no name widens the reads.
    """
    out: list[tuple[str, Path]] = []
    folder = description_folder
    for _ in range(MAX_ENCLOSING):
        if folder != description_folder and not any(
            folder == r or folder.is_relative_to(r) for r in own_roots
        ):
            break
        if (folder / "package.xml").is_file():
            out.append((declared_name(folder), folder))
        if PACKAGE_NAME.match(folder.name):
            out.append((folder.name, folder))
        if folder.parent == folder:
            break
        folder = folder.parent
    return out


def user_roots(
    extra_paths: Sequence[str | Path] = (),
    *,
    use_environment: bool = True,
    use_example_robot_data: bool = True,
    environ: Mapping[str, str] | None = None,
) -> list[Path]:
    """The folders the *user* allows: ``-P`` folders, the ROS environment, installed data.

    Why a function of its own: allowed roots come from the user, never from the input, so a
    spec's ``package_paths`` are checked against exactly these (see
    :func:`robotspec.spec.load.check_package_paths`).
    """
    env = os.environ if environ is None else environ
    folders: list[Path] = [Path(p).absolute() for p in extra_paths]
    if use_environment:
        folders += [p.absolute() for p in split_path_list(env.get("ROS_PACKAGE_PATH"))]
        folders += [p.absolute() / "share" for p in split_path_list(env.get("AMENT_PREFIX_PATH"))]
    if use_example_robot_data:
        folders += example_robot_data_folders()
    return [Path(os.path.normpath(f)) for f in folders]
