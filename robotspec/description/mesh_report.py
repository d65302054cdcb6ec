"""Meshes that cannot be found: one warning per missing package, and the bodies they leave bare.

Why a module of its own: a robot whose mesh package is not on the search path names that package
in dozens of meshes (93 on Talos). Reported once per mesh, the one fact that matters (which
package, and how to make it findable) drowns in repeats. Kinematics, semantics and validation
never need a mesh, so a missing one is a warning while loading; only the commands that draw or
collide geometry (render, view, collisions) need the files, and they say which bodies lose it.

A mesh that exists but lies outside the folders robotspec may read is no "not found": it is a
fence the user set (or did not widen), so it is reported apart, at its URDF line, naming the
allowed folders and the flag that widens them (``-P``, ``ROS_PACKAGE_PATH``), never the spec's
own ``package_paths``, which a downloaded spec must not be able to widen past its project.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

from robotspec.errors import (
    DescriptionError,
    PackageNotFoundError,
    PathOutsideRootsError,
    RobotSpecError,
)
from robotspec.model.geometry import Mesh
from robotspec.model.world import World

__all__ = [
    "FIX_HINT",
    "OUTSIDE_HINT",
    "MissingMesh",
    "UnresolvedMesh",
    "mesh_group",
    "missing_geometry_message",
    "missing_geometry_problems",
    "summarize_missing_meshes",
    "unresolved_meshes",
]

#: What makes a package findable, in the words of each place a user can say it.
FIX_HINT = (
    "to fix, add the folder that holds it with -P FOLDER, to ROS_PACKAGE_PATH, "
    "or to description.package_paths in the spec"
)

#: What lets robotspec read a file outside the allowed folders: only the user can say it.
OUTSIDE_HINT = "allow a folder that holds it with -P FOLDER or ROS_PACKAGE_PATH"

#: How many body names a message lists before it says "and N more".
SHOWN_BODIES = 6

_PACKAGE_URI = re.compile(r"^(?:package|model)://([^/]*)/*([^/]*)", re.IGNORECASE)


@dataclass(frozen=True)
class MissingMesh:
    """One mesh element of a body that did not resolve to a file, and why."""

    uri: str
    body: str
    error: RobotSpecError


def mesh_group(uri: str) -> str:
    """The package a mesh URI names (the first segment of ``package:///a/...``), else its folder.

    Why: meshes are missing together, because their package is; one warning per group.
    """
    match = _PACKAGE_URI.match(uri.strip())
    if match is not None:
        return match.group(1) or match.group(2)
    folder, _, _ = uri.rpartition("/")
    return folder or uri


def _names(bodies: Sequence[str]) -> str:
    shown = ", ".join(bodies[:SHOWN_BODIES])
    more = len(bodies) - SHOWN_BODIES
    return shown + (f" and {more} more" if more > 0 else "")


_PLURALS = {"mesh": "meshes", "body": "bodies", "more mesh": "more meshes"}


def _plural(n: int, word: str) -> str:
    return f"{n} {word if n == 1 else _PLURALS.get(word, word + 's')}"


def summarize_missing_meshes(missing: Iterable[MissingMesh]) -> list[RobotSpecError]:
    """One warning per missing package (or folder): how many meshes, which bodies, the fix.

    The warning keeps the position of the first mesh of the group. A mesh outside the allowed
    folders is not a "not found": it keeps its own message (and count), never merged with others.
    """
    groups: dict[tuple[str, bool], list[MissingMesh]] = {}
    for m in missing:
        kind = isinstance(m.error, PackageNotFoundError)
        groups.setdefault((mesh_group(m.uri), kind), []).append(m)
    out: list[RobotSpecError] = []
    for (group, package_missing), items in groups.items():
        first = items[0].error
        bodies = list(dict.fromkeys(m.body for m in items))
        extent = (
            f"{_plural(len(items), 'mesh')} of {_plural(len(bodies), 'body')} "
            f"({_names(bodies)}) have no geometry"
        )
        if len(items) == 1:
            extent = f"body '{bodies[0]}' has no mesh geometry"
        if package_missing:
            message = f"{first.message}; {extent}; {FIX_HINT}"
        elif isinstance(first, PathOutsideRootsError):
            message = f"{first.message}; {extent}; {OUTSIDE_HINT}"
        elif first.detail.kind == "mesh":
            message = (
                f"{_plural(len(items), 'mesh')} of '{group}' not found "
                f"(first: {first.message}); {extent}"
            )
            if len(items) == 1:
                message = f"{first.message}; {extent}"
        else:
            message = f"{first.message}; {extent}"
        out.append(
            DescriptionError(
                message,
                file=first.file,
                line=first.line,
                kind="package" if package_missing else first.detail.kind,
                name=group if package_missing else first.name,
                suggestions=first.suggestions,
                severity="warning",
            )
        )
    return out


@dataclass(frozen=True)
class UnresolvedMesh:
    """One mesh element of a loaded world that has no file, where it is written, and why."""

    body: str
    uri: str
    #: The URDF (or xacro output) that names it, and the line of its element.
    file: str | None
    line: int | None
    #: Why it did not resolve (``None``: the world was loaded without resolving meshes).
    problem: RobotSpecError | None

    @property
    def outside(self) -> bool:
        """Whether the file exists as far as the name goes but lies outside the allowed folders."""
        return isinstance(self.problem, PathOutsideRootsError)


def unresolved_meshes(
    world: World, *, collision: bool, bodies: Iterable[str] | None = None
) -> list[UnresolvedMesh]:
    """The meshes (visual, or collision) of ``bodies`` that did not resolve to a file."""
    wanted = None if bodies is None else set(bodies)
    out: list[UnresolvedMesh] = []
    for body in world.bodies:
        if wanted is not None and body.name not in wanted:
            continue
        for shape in body.collisions if collision else body.visuals:
            g = shape.geometry
            if isinstance(g, Mesh) and g.path is None:
                p = g.problem
                file = p.file if p is not None and p.file is not None else world.source
                line = p.line if p is not None and p.line is not None else shape.line
                out.append(UnresolvedMesh(body.name, g.uri, file, line, p))
    return out


def missing_geometry_problems(
    meshes: Sequence[UnresolvedMesh], *, command: str, skip: bool
) -> list[RobotSpecError]:
    """What a geometry command says about ``meshes`` before it draws or collides anything.

    Meshes that are missing (package not found, file absent) are one problem, as before: the
    bodies that lose geometry and how to make the package findable. Meshes outside the allowed
    folders are another, located at the first one's URDF line, naming the mesh, the folders and
    the flags that allow it. Errors, or with ``skip`` (``--skip-missing-meshes``) warnings saying
    the command goes on without them.
    """
    severity = "warning" if skip else "error"
    out: list[RobotSpecError] = []
    missing: dict[str, list[str]] = {}
    for m in meshes:
        if not m.outside:
            missing.setdefault(m.body, []).append(m.uri)
    if missing:
        what = (
            f"{command} goes on without them"
            if skip
            else f"pass --skip-missing-meshes to {command} without them, or make the package "
            "findable: -P FOLDER, ROS_PACKAGE_PATH, or description.package_paths in the spec"
        )
        out.append(
            RobotSpecError(
                missing_geometry_message(missing, what=what), kind="mesh", severity=severity
            )
        )
    outside = [m for m in meshes if m.outside]
    if outside:
        out.append(_outside_problem(outside, command=command, skip=skip))
    return out


def _outside_problem(
    outside: Sequence[UnresolvedMesh], *, command: str, skip: bool
) -> RobotSpecError:
    """One problem for every mesh outside the allowed folders, at the first one's line."""
    first = outside[0]
    reason = first.problem.message if first.problem is not None else ""
    quoted = f"'{first.uri}' "
    if reason.startswith(quoted):  # "'URI' resolves to PATH, outside the allowed folders (...)"
        reason = reason[len(quoted) :]
    else:
        reason = f"lies outside the allowed folders ({reason})"
    head = f"mesh '{first.uri}' of body '{first.body}' {reason}"
    n = len(outside)
    it = "it" if n == 1 else "them"
    if n > 1:
        bodies = list(dict.fromkeys(m.body for m in outside[1:]))
        head += (
            f"; so do {_plural(n - 1, 'more mesh')} of {_plural(len(bodies), 'body')} "
            f"({_names(bodies)})"
        )
    hint = OUTSIDE_HINT if n == 1 else OUTSIDE_HINT.replace("holds it", "holds them")
    tail = (
        f"{command} goes on without {it} ({hint})"
        if skip
        else f"robotspec reads no file outside those folders: {hint}, or pass "
        f"--skip-missing-meshes to {command} without {it}"
    )
    return DescriptionError(
        f"{head}; {tail}",
        file=first.file,
        line=first.line,
        kind="path",
        name=first.uri,
        severity="warning" if skip else "error",
    )


def missing_geometry_message(missing: dict[str, list[str]], *, what: str) -> str:
    """'N bodies lose their geometry (a, b, ...; meshes of 'x')' for the geometry commands."""
    groups = list(dict.fromkeys(mesh_group(u) for uris in missing.values() for u in uris))
    named = ", ".join(f"'{g}'" for g in groups)
    bodies = list(missing)
    verb = "loses its" if len(bodies) == 1 else "lose their"
    return (
        f"{_plural(len(bodies), 'body')} {verb} geometry, mesh files not found "
        f"({_names(bodies)}; meshes of {named}); {what}"
    )
