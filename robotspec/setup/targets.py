"""Where the setup assistant may write: inside the output's folder, never over the robot's files.

Why a fence of its own: "save as" takes a path typed into a page, and the robot being set up was
perhaps downloaded from a stranger, with its spec, URDF, SRDF and meshes in the folder the spec
is saved to. The assistant's saves therefore

* stay inside the folder of ``-o`` (and the folders the command line adds with
  ``--allow-save``), checked on the path as written and on the path with links resolved;
* are specs (``.yaml``/``.yml``): no save can take a URDF's, SRDF's or mesh's name;
* never replace a file of the robot (its URDF or xacro, its SRDF, its meshes, the spec it was
  opened from unless that is the output itself), compared by device and inode;
* never replace an existing file other than the output, or a file this session wrote (another
  spec in the folder, a YAML file a xacro reads, is not the assistant's to overwrite);
* name the generated SRDF ``<spec>.srdf``, or ``<spec>.collisions.srdf`` when the former is the
  robot's own SRDF (or another file the session may not replace).

The write itself goes through :func:`robotspec.files.writing.write_file`: no link followed
below the folder, an exclusive temporary file renamed into place, nothing left by a refusal.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path

from robotspec.errors import RobotSpecError
from robotspec.model.world import World

__all__ = ["SPEC_SUFFIXES", "SaveFence", "robot_inputs"]

SPEC_SUFFIXES = (".yaml", ".yml")
#: What the spec a session was opened from is among the robot's files.
_OPENED = "the spec it was opened from"


def _key(path: Path) -> tuple[int, int] | None:
    try:
        st = os.stat(path)
    except (OSError, ValueError):
        return None
    return (st.st_dev, st.st_ino)


def robot_inputs(
    world: World,
    *,
    srdf: Iterable[str | Path | None] = (),
    spec: Path | None = None,
) -> dict[Path, str]:
    """The robot's own files, each with what it is: URDF (or xacro), SRDF, meshes, the spec."""
    out: dict[Path, str] = {}
    if spec is not None:
        out[Path(spec)] = _OPENED
    if world.source:
        out[Path(world.source)] = "its URDF"
    for f in srdf:
        if f:
            out[Path(f)] = "its SRDF"
    for body in world.bodies:
        for shape in (*body.visuals, *body.collisions):
            mesh = getattr(shape.geometry, "path", None)
            if mesh:
                out.setdefault(Path(mesh), "a mesh of it")
    return out


def _inside(path: Path, folder: Path) -> Path | None:
    """``path`` relative to ``folder`` (as written, else with links resolved), or None."""
    full = Path(os.path.normpath(path.absolute()))
    base = Path(os.path.normpath(folder.absolute()))
    if full.is_relative_to(base) and full != base:
        return full.relative_to(base)
    real, real_base = full.resolve(), base.resolve()
    if real.is_relative_to(real_base) and real != real_base:
        return real.relative_to(real_base)
    return None


@dataclass
class SaveFence:
    """The folders saves may go to, the robot's files, and what this session wrote."""

    output: Path
    allowed: tuple[Path, ...] = ()
    inputs: dict[Path, str] = field(default_factory=dict)
    written: set[tuple[int, int]] = field(default_factory=set)

    @property
    def folders(self) -> tuple[Path, ...]:
        """The output's folder first, then the folders ``--allow-save`` added."""
        return (self.output.absolute().parent, *(Path(f).absolute() for f in self.allowed))

    def _is_output(self, path: Path) -> bool:
        a, b = os.path.normpath(path.absolute()), os.path.normpath(self.output.absolute())
        return a == b or (_key(path) is not None and _key(path) == _key(self.output))

    def _input_role(self, path: Path) -> str | None:
        key = _key(path)
        if key is None:
            return None
        for p, role in self.inputs.items():
            if _key(p) == key:
                return role
        return None

    def place(self, target: Path, *, what: str = "the spec") -> tuple[Path, Path, bool]:
        """Where ``target`` is written: (the path, the allowed folder it is under, overwrite).

        Raises a located error for a target outside the folders, one of the robot's files or
        an existing file this session may not replace; nothing is created.
        """
        shown = str(target)
        for folder in self.folders:
            rel = _inside(target, folder)
            if rel is not None:
                break
        else:
            names = ", ".join(str(f) for f in self.folders)
            raise RobotSpecError(
                f"not saved: {what} is saved inside {names}; start robotspec setup with "
                "--allow-save DIR to save in another folder",
                file=shown,
                kind="output",
            )
        path = Path(os.path.normpath(folder.absolute())) / rel
        if what == "the spec" and path.suffix.lower() not in SPEC_SUFFIXES:
            raise RobotSpecError(
                "not saved: a spec is a .yaml or .yml file", file=shown, kind="output"
            )
        role = self._input_role(path)
        if role is not None and not (role == _OPENED and self._is_output(path)):
            raise RobotSpecError(
                f"not saved: this is {role}, a file of the robot; robotspec setup never writes "
                "over a robot's own files; name another file",
                file=shown,
                kind="output",
            )
        ours = self._is_output(path) or _key(path) in self.written
        if os.path.lexists(path) and not ours:
            raise RobotSpecError(
                f"not saved: the file exists and is not {what} this session writes (-o "
                f"{self.output}); name a new file",
                file=shown,
                kind="output",
            )
        return path, Path(os.path.normpath(folder.absolute())), ours

    def srdf_name(self, spec: Path) -> str:
        """The generated SRDF's name beside ``spec``: never the robot's own SRDF."""
        stem = spec.name.rsplit(".", 1)[0]
        tried: list[str] = []
        for name in (f"{stem}.srdf", f"{stem}.collisions.srdf"):
            try:
                self.place(spec.parent / name, what="the SRDF")
                return name
            except RobotSpecError as exc:
                tried.append(exc.message)
        raise RobotSpecError(
            f"no name for the generated SRDF beside the spec: {'; '.join(tried)}",
            file=str(spec),
            kind="output",
        )

    def remember(self, path: Path) -> None:
        """A file this session wrote (it may replace it again)."""
        key = _key(path)
        if key is not None:
            self.written.add(key)

    def input_map(self) -> Mapping[Path, str]:
        """The files no write may replace (the opened spec is the output's to replace)."""
        return {
            p: role
            for p, role in self.inputs.items()
            if not (role == _OPENED and self._is_output(p))
        }
