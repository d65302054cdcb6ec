"""Options shared by several commands, declared once."""

from __future__ import annotations

import math
import os
import sys
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


def write_output(text: str, output: Path | None) -> bool:
    """Write ``text`` to ``output``, or to stdout when it is None; True if a file was written."""
    if output is None:
        sys.stdout.write(text)
        return False
    write_file(output, text)
    return True


def write_file(path: Path, text: str) -> None:
    """Write a file the user named; a folder that is missing or read-only is their error."""
    from robotspec.errors import RobotSpecError

    try:
        if path.parent != Path(""):
            path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")
    except OSError as exc:
        raise RobotSpecError(
            f"cannot write file: {exc.strerror or exc}", file=str(path), kind="file"
        ) from None


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
