"""The fence model: which folders a file may make robotspec read without the user's leave.

Why one module: a spec and a robot description are input like any downloaded file. What the
*user* allows (``-P``, ``ROS_PACKAGE_PATH``/``AMENT_PREFIX_PATH``, the installed data package)
may be anything; what an *input* may widen the reads to is decided here, from where the input
lies and nothing it says:

* the **project** that holds a spec: the nearest folder at or above the spec's folder that holds
  a version-control folder (``.git``, ``.hg``, ``.svn``) or a project file (``pyproject.toml``,
  ``setup.py``, ``setup.cfg``, ``package.xml``); without one, the spec's own folder (or the folder
  above it when that is called ``specs``, the layout ``robotspec init`` documents). Never the
  home folder, a folder above it, the filesystem root or a top-level folder.
* never a **hidden** folder or file below that project (``.ssh``, ``.git``, ``.config``);
* never the **system** folders (``/etc``, ``/proc``, ``/sys``, ``/dev``, ``/boot``, ``/run``);

all checked on real paths, after every symbolic link is resolved. The same hidden and system
rules hold for the folders a description widens the reads to (its own folder, its package, and
the *marked* project around it: :func:`marked_project`).
"""

from __future__ import annotations

import os
from pathlib import Path

__all__ = [
    "PROJECT_FILES",
    "SYSTEM_FOLDERS",
    "hidden_part",
    "inside",
    "marked_project",
    "project_root",
    "refusal",
    "system_folder",
    "too_wide",
]

#: Files or folders whose presence makes a folder a project root (version control, packaging).
PROJECT_FILES = (".git", ".hg", ".svn", "pyproject.toml", "setup.py", "setup.cfg", "package.xml")

#: Folders no input may make readable, whatever link or path leads there: the machine's
#: configuration, its processes, devices and boot files. The user may still allow one with -P.
SYSTEM_FOLDERS = ("/etc", "/proc", "/sys", "/dev", "/boot", "/run")

#: Folder names whose parent is the project when no project file is found (``specs/arm.yaml``
#: beside ``robots/``).
SPEC_FOLDER_NAMES = frozenset({"specs"})

#: How many folders above a spec are searched for a project file.
MAX_PROJECT_DEPTH = 32


def inside(path: str, folder: str) -> bool:
    """Whether ``path`` is ``folder`` or below it (both real, absolute, normalised strings)."""
    return path == folder or path.startswith(folder.rstrip(os.sep) + os.sep)


def _home() -> str:
    return os.path.realpath(Path.home())


def too_wide(folder: str, home: str | None = None) -> bool:
    """Whether a real folder holds the whole machine or a user's files.

    The filesystem root, a top-level folder (``/home``, ``/tmp``), the home folder and every
    folder above it are too wide to be one robot project's. ``home``: the real home folder, when
    the caller tests many folders (a walk up resolves it once, not per level).
    """
    path = Path(folder)
    if len(path.parts) <= 2:
        return True
    return inside(home if home is not None else _home(), folder)


def system_folder(real: str) -> str | None:
    """The system folder ``real`` lies in, if any."""
    for folder in SYSTEM_FOLDERS:
        if inside(real, folder):
            return folder
    return None


def hidden_part(real: str, root: str) -> str | None:
    """The first hidden component of ``real`` below ``root`` (``.ssh``), if any."""
    if not inside(real, root) or real == root:
        return None
    below = real[len(root.rstrip(os.sep)) + 1 :]
    for part in below.split(os.sep):
        if part.startswith(".") and part not in (".", ".."):
            return part
    return None


def project_root(folder: str | Path) -> Path | None:
    """The project a spec in ``folder`` belongs to (real path), or None when it has none.

    Why markers: a spec and its robot files are kept together (``specs/``, ``../robots``) in a
    project the user checked out or created; a download folder has no such mark above the
    downloaded tree. The walk stops below the home folder and the top-level folders, so no
    marker (a dotfiles repository in the home folder) can widen a project to them.
    """
    start = os.path.realpath(folder)
    marked = _marked(start)
    if marked is not None:
        return marked
    home = _home()
    if too_wide(start, home):
        return None
    parent = os.path.dirname(start)
    if os.path.basename(start) in SPEC_FOLDER_NAMES and not too_wide(parent, home):
        return Path(parent)
    return Path(start)


#: Folders an installer fills: a project marker above them (the virtual environment's project)
#: does not make the installed files one project with it.
INSTALL_FOLDERS = frozenset({"site-packages", "dist-packages"})


def _marked(start: str, *, stop_at_installs: bool = False) -> Path | None:
    """The nearest folder at or above the real folder ``start`` holding a project marker."""
    current = start
    home = _home()
    for _ in range(MAX_PROJECT_DEPTH):
        if too_wide(current, home):
            break
        if stop_at_installs and os.path.basename(current) in INSTALL_FOLDERS:
            break
        if any(os.path.lexists(os.path.join(current, name)) for name in PROJECT_FILES):
            return Path(current)
        parent = os.path.dirname(current)
        if parent == current:
            break
        current = parent
    return None


def marked_project(folder: str | Path) -> Path | None:
    """The project a robot description in ``folder`` reads inside (real path), if it has one.

    Why only a marked one: a description may read the project that holds it (``robots/arm``
    naming ``../../hands/meshes`` beside it, in a repository keeping both), which its user
    checked out or created; a download has no marker above its own folder, so it stays
    confined to its folder and package. Never the home folder or anything above it, and never
    across a ``site-packages`` folder (an installed wheel is no part of the virtual
    environment's project).
    """
    return _marked(os.path.realpath(folder), stop_at_installs=True)


def refusal(real: str, project: Path | None) -> str | None:
    """Why an input inside ``project`` may not name the real path ``real``; None if it may."""
    system = system_folder(real)
    if system is not None:
        return f"it lies in the system folder {system}"
    if project is None:
        return "the spec lies in a folder too wide to be a project (the home or a top-level folder)"
    root = str(project)
    if not inside(real, root):
        return f"it lies outside the spec's project {root}"
    hidden = hidden_part(real, root)
    if hidden is not None:
        return f"it lies in the hidden folder or file '{hidden}'"
    return None
