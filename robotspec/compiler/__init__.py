"""The compiler's face: a spec file (or a shipped robot's name) to an ``AbstractRobot``.

``check_spec`` (what ``validate`` runs), ``compile_robot`` and ``compile_spec_for_world`` (the
seed's ``from_world``) resolve the reference and hand the loaded spec to
:mod:`~robotspec.compiler.pipeline`; all problems of one spec are reported together.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from robotspec.compiler.pipeline import CompileResult, compile_loaded, load_camera_presets
from robotspec.errors import NotFoundError, SpecError, missing_file
from robotspec.model.world import World
from robotspec.semantic import AbstractRobot
from robotspec.shipped import shipped_spec_files
from robotspec.spec.load import load_spec

__all__ = [
    "CompileResult",
    "check_spec",
    "compile_robot",
    "compile_spec_for_world",
    "load_camera_presets",
    "resolve_spec",
    "shipped_specs",
]


def shipped_specs() -> dict[str, Path]:
    """The robots shipped with robotspec: name -> spec file."""
    return shipped_spec_files()


def resolve_spec(ref: str | Path) -> Path:
    """A spec path, or the spec of a shipped robot named ``ref`` (``pr2``, ``hsrb``, ...)."""
    p = Path(ref)
    if p.is_file():
        return p
    shipped = shipped_specs()
    key = str(ref).lower()
    if key in shipped:
        return shipped[key]
    if p.suffix in (".yaml", ".yml") or "/" in str(ref):
        raise missing_file(ref, SpecError)
    raise NotFoundError("robot or spec file", str(ref), shipped, where="the shipped robots")


def check_spec(
    ref: str | Path, *, package_paths: Sequence[str | Path] = (), strict: bool = False
) -> CompileResult:
    """Compile a spec and return its warnings; every error is raised together."""
    return compile_loaded(
        load_spec(resolve_spec(ref), allowed=package_paths),
        package_paths=package_paths,
        strict=strict,
    )


def compile_robot(
    ref: str | Path,
    *,
    package_paths: Sequence[str | Path] = (),
    robot_class: type[AbstractRobot] = AbstractRobot,
) -> AbstractRobot:
    """Compile a spec file, or a shipped robot by name, into an ``AbstractRobot``.

    ``robot_class`` is the class built; :func:`robotspec.robots.load` picks the shipped robot's
    own class (the compiler does not know the registry of shipped robots).
    """
    result = compile_loaded(
        load_spec(resolve_spec(ref), allowed=package_paths),
        package_paths=package_paths,
        robot_class=robot_class,
    )
    return result.robot


def compile_spec_for_world(
    ref: str | Path,
    world: World,
    *,
    robot_class: type[AbstractRobot] = AbstractRobot,
    package_paths: Sequence[str | Path] = (),
) -> AbstractRobot:
    """Build the spec's robot over an existing world (the seed's ``from_world``).

    The world must hold the spec's names; frames the spec adds are added if missing (which
    makes a new world: the robot's ``world`` is then that one). The SRDF, if any, is read from
    the spec's files for its collision rules.
    """
    result = compile_loaded(
        load_spec(resolve_spec(ref), allowed=package_paths),
        package_paths=package_paths,
        world=world,
        robot_class=robot_class,
    )
    return result.robot
