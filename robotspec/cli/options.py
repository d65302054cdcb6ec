"""Options shared by several commands, declared once."""

from __future__ import annotations

import math
import os
import sys
from collections.abc import Iterable
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from robotspec.errors import CollisionError

if TYPE_CHECKING:
    from robotspec.semantic import AbstractRobot


def _package_folders(values: list[Path] | None) -> list[Path] | None:
    """``-P`` folders made absolute against the current folder; a missing one is a usage error.

    Why here: relative ``-P`` paths mean what the shell means (the current folder, not the
    spec's), and a typo must not be searched silently as nothing.
    """
    if not values:
        return values
    out: list[Path] = []
    missing: list[str] = []
    for value in values:
        folder = Path(os.path.normpath(Path(value).absolute()))
        if not folder.is_dir():
            missing.append(str(folder))
        out.append(folder)
    if missing:
        raise typer.BadParameter(
            "folder does not exist: "
            + ", ".join(missing)
            + f" (searched: {', '.join(map(str, out))})",
            param_hint="'--package-path' / '-P'",
        )
    return out


PackagePath = Annotated[
    list[Path] | None,
    typer.Option(
        "--package-path",
        "-P",
        help="Extra folder to search for ROS packages (repeatable); it may also be read. "
        "Relative to the current folder; it must exist.",
        show_default=False,
        callback=_package_folders,
    ),
]
OutputFile = Annotated[
    Path | None, typer.Option("--output", "-o", help="Write to FILE instead of stdout.")
]


def write_output(
    text: str, output: Path | None, *, force: bool = True, inputs: Iterable[Path] = ()
) -> bool:
    """Write ``text`` to ``output``, or to stdout when it is None; True if a file was written.

    ``force=False``: an existing ``output`` is an error (the command's ``--force`` lifts it).
    ``inputs``: the robot's own files, which the output may never replace.
    """
    if output is None:
        sys.stdout.write(text)
        return False
    write_file(output, text, force=force, inputs=inputs)
    return True


Force = Annotated[bool, typer.Option("--force", help="Overwrite existing files.")]


def write_file(
    path: Path, text: str | bytes, *, force: bool = True, inputs: Iterable[Path] = ()
) -> None:
    """Write a file the user named: :func:`robotspec.files.writing.write_file` does the work.

    Never through a symbolic link (a link planted in an output folder, ``robot.urdf`` pointing
    at ``~/.bashrc``, would have its target overwritten), never into anything but a regular
    file, never over one of ``inputs`` (the robot's own files), through a temporary file renamed
    into place. Without ``force`` an existing file is refused, atomically.
    """
    from robotspec.files.writing import write_file as write

    write(path, text, force=force, inputs=inputs)


JsonFlag = Annotated[bool, typer.Option("--json", help="Print JSON instead of a table.")]


def complete_spec(incomplete: str) -> list[str]:
    """Shell completion of a spec argument: shipped robot names, then YAML files here."""
    from robotspec.shipped import shipped_spec_files

    names = sorted(shipped_spec_files())
    head = os.path.dirname(incomplete)
    try:
        files = sorted(
            os.path.join(head, p.name) + ("/" if p.is_dir() else "")
            for p in Path(head or ".").iterdir()
            if p.suffix in (".yaml", ".yml") or p.is_dir()
        )
    except OSError:
        files = []
    return [c for c in (*names, *files) if c.startswith(incomplete)]


SpecArg = Annotated[
    str,
    typer.Argument(
        help="A spec file, or the name of a shipped robot (see `robotspec list`).",
        autocompletion=complete_spec,
    ),
]

SkipMeshes = Annotated[
    bool,
    typer.Option(
        "--skip-missing-meshes",
        help="Leave out missing or unreadable meshes (each is reported) instead of failing.",
    ),
]


def load_robot(spec: str, package_path: list[Path] | None) -> AbstractRobot:
    """Compile a spec (or shipped robot, as its class) for a command; imports lazily."""
    from robotspec.robots import load

    return load(spec, package_paths=package_path or ())


StateOpt = Annotated[
    list[str] | None,
    typer.Option(
        "--state",
        "-s",
        help="A named joint state (left_arm.park, park = every part's park, or an SRDF group "
        "state); repeatable, applied in order over the default pose.",
        show_default=False,
    ),
]

QOpt = Annotated[
    list[str] | None,
    typer.Option(
        "--q",
        help="A joint value JOINT=VALUE (rad or m), applied after the states; repeatable.",
        show_default=False,
    ),
]


def joint_values(items: list[str] | None) -> dict[str, float]:
    """``--q JOINT=VALUE`` options as a mapping; a malformed or non-finite value is an error."""
    out: dict[str, float] = {}
    for item in items or ():
        name, sep, text = item.partition("=")
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        if not sep or not name.strip() or not math.isfinite(value):
            raise CollisionError(
                f"--q '{item}': expected JOINT=VALUE with a finite number", kind="option"
            )
        out[name.strip()] = value
    return out
