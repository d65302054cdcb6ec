"""What a spec may name without the user's leave: files and folders inside its own project.

Why: a spec is input like any robot file (it is downloaded with the robot), so the folders it
names (``description.package_paths``, a part's ``package_paths``) and the files it names by
path (``urdf``, ``srdf``, a part's ``spec``) widen the reads only inside the project that holds
the spec, never into a hidden or system folder, links resolved (:mod:`robotspec.files.fences`).
Anything else is read only when the user allows the folder (``-P``, ``ROS_PACKAGE_PATH``,
``AMENT_PREFIX_PATH``, the installed ``example-robot-data``). URIs (``package://``,
``file://``) are fenced where they are resolved, by the same roots.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from robotspec.errors import RobotSpecError, SpecError, raise_collected
from robotspec.files.fences import hidden_part, inside, project_root, refusal, system_folder
from robotspec.files.yamlio import LocatedYaml

__all__ = [
    "ForeignPath",
    "check_package_paths",
    "check_spec_path",
    "foreign_paths",
    "spec_may_name",
]

#: What each kind of entry is called in messages.
_WHAT = {
    "package_paths": "package path",
    "urdf": "URDF",
    "srdf": "SRDF",
    "spec": "part spec",
    "extends": "extended spec",
}


@dataclass(frozen=True)
class ForeignPath:
    """A path a spec names that it may not name on its own; the user may allow it."""

    given: str
    path: Path
    folder: Path
    file: str
    line: int | None
    column: int | None
    location: tuple[str | int, ...]
    #: Why the spec may not name it (outside its project, hidden, a system folder).
    reason: str = ""
    #: Which entry: ``package_paths``, ``urdf``, ``srdf``, ``spec`` or ``extends``.
    key: str = "package_paths"


def _named_target(value: str, folder: Path) -> str:
    """The real path a spec entry names (``~`` is not expanded: it is a folder name then)."""
    return os.path.realpath(folder / value)


def spec_may_name(value: str, folder: Path, project: Path | None = None) -> bool:
    """Whether a spec in ``folder`` may name the path ``value`` without the user's leave."""
    real = _named_target(value, folder)
    return refusal(real, project if project is not None else project_root(folder)) is None


def _is_path(key: str, value: str, folder: Path) -> bool:
    """Whether an entry is a file path the spec reads (not a URI or a shipped robot's name)."""
    if "://" in value:
        return False  # fenced where it is resolved
    if key == "spec":
        return (folder / value).is_file() or os.sep in value or value.endswith((".yaml", ".yml"))
    return True


def _entries(data: Any) -> list[tuple[tuple[str | int, ...], str, str]]:
    """Every path entry of a spec document: (location, key, value)."""
    out: list[tuple[tuple[str | int, ...], str, str]] = []

    def take(loc: tuple[str | int, ...], block: Any, keys: tuple[str, ...]) -> None:
        if not isinstance(block, Mapping):
            return
        for key in keys:
            value = block.get(key)
            if isinstance(value, str):
                out.append(((*loc, key), key, value))
        paths = block.get("package_paths")
        if isinstance(paths, list):
            for i, value in enumerate(paths):
                if isinstance(value, str):
                    out.append(((*loc, "package_paths", i), "package_paths", value))

    if not isinstance(data, Mapping):
        return out
    take(("description",), data.get("description"), ("urdf", "srdf"))
    parts = data.get("parts")
    if isinstance(parts, Mapping):
        for name, part in parts.items():
            take(("parts", name), part, ("urdf", "srdf", "spec"))
    return out


def foreign_paths(doc: LocatedYaml, folder: Path) -> list[ForeignPath]:
    """The paths a spec document names that the user must allow (links resolved)."""
    project = project_root(folder)
    out: list[ForeignPath] = []
    for loc, key, value in _entries(doc.data):
        if not _is_path(key, value, folder):
            continue
        real = _named_target(value, folder)
        why = refusal(real, project)
        if why is None:
            continue
        line, col = doc.position(loc)
        out.append(ForeignPath(value, Path(real), folder, doc.file, line, col, loc, why, key))
    return out


def check_spec_path(
    value: str,
    folder: Path,
    *,
    key: str,
    file: str,
    line: int | None,
    column: int | None,
    location: tuple[str | int, ...],
    allowed: Sequence[str | Path] = (),
    given: str | None = None,
) -> None:
    """Refuse one path a spec names (``extends``) before it is read, unless allowed."""
    real = _named_target(value, folder)
    why = refusal(real, project_root(folder))
    if why is None:
        return
    shown = value if given is None else given
    fp = ForeignPath(shown, Path(real), folder, file, line, column, location, why, key)
    problem = _problem(fp, [os.path.realpath(r) for r in _user_roots(allowed)])
    if problem is not None:
        raise problem


def _user_roots(package_paths: Sequence[str | Path]) -> list[Path]:
    """The folders the user allows, and the robots and parts shipped with robotspec."""
    from robotspec.files.package_search import user_roots
    from robotspec.shipped import package_data

    return [*user_roots(package_paths), package_data("specs")]


def _allow_hint(fp: ForeignPath) -> str:
    folder = fp.path if fp.key == "package_paths" else fp.path.parent
    return f"allow it with -P/--package-path {folder}, or ROS_PACKAGE_PATH"


def _problem(fp: ForeignPath, roots: Sequence[str]) -> RobotSpecError | None:
    """The error for a foreign path, or None when a folder the user allowed holds it."""
    real = str(fp.path)
    for root in roots:
        if inside(real, root) and hidden_part(real, root) is None:
            if system_folder(real) is None or system_folder(root) is not None:
                return None  # the user named this folder (or one around it) themselves
    what = _WHAT.get(fp.key, fp.key)
    return SpecError(
        f"{what} '{fp.given}' resolves to {real}, which a spec may not name: {fp.reason} "
        f"(a spec may name files and folders inside its own project, never hidden or system "
        f"ones; {_allow_hint(fp)})",
        file=fp.file,
        line=fp.line,
        column=fp.column,
        kind=what,
        name=fp.given,
        location=fp.location,
    )


def check_package_paths(loaded: Any, package_paths: Sequence[str | Path] = ()) -> None:
    """Refuse the paths a loaded spec names outside its project that the user did not allow.

    The user allows a folder with ``-P``/``package_paths`` (``package_paths`` here), the
    ``ROS_PACKAGE_PATH``/``AMENT_PREFIX_PATH`` environment or an installed data package; a spec
    entry inside one of those (not in a hidden folder below it) is accepted. Every refused
    entry is reported at once, at its line.
    """
    foreign: tuple[ForeignPath, ...] = loaded.foreign_paths
    if not foreign:
        return
    roots = [os.path.realpath(r) for r in _user_roots(package_paths)]
    problems = [p for p in (_problem(fp, roots) for fp in foreign) if p is not None]
    raise_collected(problems)
