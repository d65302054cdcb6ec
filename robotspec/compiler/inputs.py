"""The files a robot is read from, so that no file robotspec writes replaces one of them.

Why: an output named after an input (``collisions generate robot.yaml -o robot.srdf``, the
setup assistant writing ``<spec>.srdf`` beside a spec whose SRDF has that name) used to replace
the robot's own hand-written file. :func:`robotspec.files.writing.write_file` refuses a target
that is one of these files; this module lists them, each with what it is, for the message.

Listing is best effort and never raises: a file that cannot be found cannot be overwritten, and
a write must not fail because an input was unreadable. The xacro files a URDF includes are not
recorded by the compiler, so only the top description file stands for them.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from pathlib import Path

from robotspec.errors import RobotSpecError
from robotspec.model.geometry import Mesh
from robotspec.semantic import AbstractRobot

__all__ = ["description_inputs", "robot_inputs", "spec_inputs"]

#: Nested parts deeper than this are not followed (a cycle is the compiler's error to report).
_MAX_PART_DEPTH = 32


def _resolve(ref: str, base: Path, package_paths: Sequence[str | Path]) -> Path | None:
    """Where a description reference points, or None if it cannot be resolved."""
    from robotspec.description.load import resolve_file
    from robotspec.files.packages import PackageResolver

    try:
        if "://" not in ref:
            p = Path(ref)
            return p if p.is_absolute() else base / p
        resolver = PackageResolver.create(None, extra_paths=list(package_paths))
        return resolve_file(ref, base, resolver)
    except (RobotSpecError, OSError, ValueError):
        return None


def _kind(path: Path) -> str:
    return "xacro" if path.suffix == ".xacro" else "URDF"


def description_inputs(
    urdf: str | None,
    srdf: str | None = None,
    *,
    base: Path | None = None,
    package_paths: Sequence[str | Path] = (),
    whose: str = "its {}",
) -> dict[Path, str]:
    """The URDF/xacro and SRDF named on a command line (``init``, ``migrate``), resolved.

    ``whose`` words the role of each (``"its {}"`` makes ``its SRDF``).
    """
    out: dict[Path, str] = {}
    folder = base if base is not None else Path.cwd()
    if urdf:
        p = _resolve(urdf, folder, package_paths)
        if p is not None:
            out[p] = whose.format(_kind(p))
    if srdf:
        p = _resolve(srdf, folder, package_paths)
        if p is not None:
            out[p] = whose.format("SRDF")
    return out


def spec_inputs(
    ref: str | Path,
    *,
    package_paths: Sequence[str | Path] = (),
    robot: AbstractRobot | None = None,
) -> dict[Path, str]:
    """A spec's files: itself, the specs it extends, its description files and parts' files.

    ``robot``: the robot compiled from it, whose SRDF and meshes are added (see
    :func:`robot_inputs`).
    """
    from robotspec.compiler import resolve_spec

    out: dict[Path, str] = {}
    try:
        path = resolve_spec(ref)
    except (RobotSpecError, OSError):
        path = None
    if path is not None:
        _add_spec(out, path, package_paths, "its {}", 0)
    if robot is not None:
        for p, role in robot_inputs(robot).items():
            out.setdefault(p, role)
    return out


def _add_spec(
    out: dict[Path, str], path: Path, package_paths: Sequence[str | Path], whose: str, depth: int
) -> None:
    from robotspec.compose.parts import spec_path
    from robotspec.spec.load import load_spec

    out.setdefault(path, whose.format("spec"))
    try:
        loaded = load_spec(path, allowed=package_paths)
    except (RobotSpecError, OSError, RecursionError):
        return
    for doc in loaded.documents[1:]:
        out.setdefault(Path(doc.file), "a spec that " + whose.format("spec") + " extends")
    folder = loaded.folder
    spec = loaded.spec
    if spec.description is not None:
        extra = [*package_paths, *(folder / p for p in spec.description.package_paths)]
        out.update(
            (p, role)
            for p, role in description_inputs(
                spec.description.urdf,
                spec.description.srdf,
                base=folder,
                package_paths=extra,
                whose=whose,
            ).items()
            if p not in out
        )
    if depth >= _MAX_PART_DEPTH:
        return
    for name, part in spec.parts.items():
        extra = [*package_paths, *(folder / p for p in part.package_paths)]
        of = f"the {{}} of its part '{name}'"
        for p, role in description_inputs(
            part.urdf, part.srdf, base=folder, package_paths=extra, whose=of
        ).items():
            out.setdefault(p, role)
        if part.spec:
            sub = spec_path(part.spec, folder)
            if sub is not None and sub not in out:
                _add_spec(out, sub, package_paths, of, depth + 1)


def robot_inputs(robot: AbstractRobot) -> dict[Path, str]:
    """What a compiled robot remembers of its files: its SRDF and every mesh it resolved."""
    out: dict[Path, str] = {}
    if robot.srdf is not None and robot.srdf.file:
        out[Path(robot.srdf.file)] = "its SRDF"
    for p in _meshes(robot):
        out.setdefault(p, "one of its meshes")
    return out


def _meshes(robot: AbstractRobot) -> Iterable[Path]:
    for body in robot.world.bodies:
        for shape in (*body.visuals, *body.collisions):
            if isinstance(shape.geometry, Mesh) and shape.geometry.path is not None:
                yield Path(shape.geometry.path)
