"""A spec read back into a draft, so the assistant edits a spec a person (or ``init``) wrote.

Why marks by position: a DECIDE mark is a comment, which the spec's data does not hold, but its
loader knows the line of every node; a mark on the line of a part is that part's open question.
"""

from __future__ import annotations

import copy
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from robotspec.files.yamlio import LocatedYaml
from robotspec.model.world import World
from robotspec.spec.draft.model import (
    Draft,
    DraftCamera,
    DraftChain,
    DraftDrive,
    DraftFinger,
    DraftFrame,
    DraftManipulator,
)
from robotspec.spec.draft.render import PLACEHOLDER_FOV
from robotspec.spec.load import LoadedSpec
from robotspec.spec.models import RobotSpec

if TYPE_CHECKING:
    from robotspec.compose.assembly import Composition

__all__ = ["ReadSpec", "draft_of_spec"]

_MARK = "# DECIDE:"
#: The camera axes a draft writes without ``axis`` (optical +z, body +x); another is its axis.
_AXES = (None, (0.0, 0.0, 1.0), (1.0, 0.0, 0.0))
_FROM = "# from "


class _Marks:
    """The DECIDE mark and the ``# from`` note on the line of a spec node."""

    def __init__(self, loaded: LoadedSpec) -> None:
        self.loaded = loaded
        self.lines = loaded.file.read_text(encoding="utf-8").splitlines()

    def _line(self, loc: tuple[str | int, ...]) -> str:
        doc = self.loaded.documents[0]
        line = doc.key_marks.get(loc, doc.marks.get(loc, (None, None)))[0]
        return self.lines[line - 1] if line is not None and 0 < line <= len(self.lines) else ""

    def decide(self, loc: tuple[str | int, ...]) -> list[str]:
        text = self._line(loc)
        at = text.find(_MARK)
        return [text[at + len(_MARK) :].strip()] if at >= 0 else []

    def notes(self) -> list[str]:
        """The ``# Note:`` lines of the header (a draft's notes)."""
        out: list[str] = []
        for text in self.lines:
            if not text.startswith("#"):
                break
            if text.startswith("# Note: "):
                out.append(text.removeprefix("# Note: ").removesuffix("."))
        return out

    def ends(self, loc: tuple[str | int, ...]) -> tuple[str, str]:
        """The ``# root -> tip`` comment a draft writes after a ``group:``."""
        text = self._line(loc)
        at = text.find("#")
        root, sep, tip = text[at + 1 :].partition(" -> ") if at >= 0 else ("", "", "")
        return (root.strip(), tip.strip()) if sep else ("", "")

    def source(self, loc: tuple[str | int, ...]) -> str:
        text = self._line(loc)
        at = text.find(_FROM)
        if at < 0:
            return "the spec"
        rest = text[at + len(_FROM) :]
        return rest.split("  # DECIDE:")[0].strip()


def _rebase(ref: str, loaded: LoadedSpec, folder: Path | None) -> str:
    """A file reference of the spec as the saved spec in ``folder`` must write it."""
    from robotspec.spec.draft.paths import relative_path

    if folder is None or "://" in ref or Path(ref).is_absolute():
        return ref
    return relative_path(loaded.folder / ref, folder)


@dataclass(frozen=True)
class ReadSpec:
    """A spec read for editing (see :func:`draft_of_spec`)."""

    #: The draft, its file paths as the spec saved in the output's folder must write them.
    draft: Draft
    world: World
    #: Top-level keys kept as read.
    kept: dict[str, Any]
    #: The other files its values come from (its parts' specs, the specs it extends).
    others: tuple[LocatedYaml, ...]
    #: The draft with its paths as the file writes them.
    as_read: Draft


def draft_of_spec(
    ref: str, *, package_paths: Sequence[str | Path] = (), folder: Path | None = None
) -> ReadSpec:
    """The draft a spec amounts to, with the robot's tree and what else it was read with.

    What a draft cannot hold (a generic sensor, a frame's rotation, ``parts:``, ``extends:``)
    is left out of the draft: the saved text keeps it as
    written (:mod:`robotspec.setup.round_trip`). A composed robot's parts are its tree and its
    parts' chains, hands and sensors, each still written in its own file.
    """
    from robotspec.compiler import resolve_spec
    from robotspec.setup.source import KEPT_KEYS
    from robotspec.spec.load import check_package_paths, load_spec

    loaded = load_spec(resolve_spec(ref), allowed=package_paths)
    # The page opens downloaded specs too: the same fence as validate, before any file is read.
    check_package_paths(loaded, package_paths)
    top = loaded
    composition = None
    if loaded.spec.parts:
        from robotspec.compose import compose

        composition = compose(loaded, package_paths=package_paths)
        loaded = composition.loaded  # the flat spec: the parts' semantics, then the spec's own
    spec = loaded.spec
    marks = _Marks(top)
    files = spec.files
    world = _world(loaded, composition, package_paths)
    draft = Draft(
        name=spec.name,
        urdf=_rebase(files.urdf, loaded, folder),
        srdf=None if files.srdf is None else _rebase(files.srdf, loaded, folder),
        root=spec.root_link,
        drive=None,
        chains=[],
        manipulators=[],
        cameras=[],
        package_paths=[_rebase(p, loaded, folder) for p in files.package_paths],
        xacro_args={str(k): str(v) for k, v in (files.xacro_args or {}).items()},
        states={k: dict(v) for k, v in spec.states.items()},
        notes=marks.notes(),
    )
    _add_base(draft, spec, marks)
    _add_chains(draft, spec, marks)
    _add_manipulators(draft, spec, marks)
    _add_cameras(draft, spec, marks)
    raw = top.documents[0].data
    kept = {k: raw[k] for k in KEPT_KEYS if isinstance(raw, dict) and k in raw}
    # The draft as the file states it (paths as written): saving elsewhere rewrites them.
    as_read = copy.copy(draft)
    as_read.urdf, as_read.srdf = files.urdf, files.srdf
    as_read.package_paths = [*files.package_paths]
    return ReadSpec(draft, world, kept, tuple(loaded.documents[1:]), as_read)


def _world(
    loaded: LoadedSpec, composition: Composition | None, package_paths: Sequence[str | Path]
) -> World:
    """The robot's tree as the spec reads it: the composed URDF, or the spec's own files."""
    if composition is not None:
        from robotspec.description.urdf import world_from_urdf_xml

        return world_from_urdf_xml(
            copy.deepcopy(composition.urdf),
            composition.source,
            resolver=composition.resolver,
            meshes="keep",
            issues=[],
            checked=True,
        )
    from robotspec.description.load import load_description

    files = loaded.spec.files
    paths = [*(_rebase(p, loaded, None) for p in files.package_paths), *map(str, package_paths)]
    absolute = [p if Path(p).is_absolute() else str(loaded.folder / p) for p in paths]
    return load_description(
        files.urdf,
        package_paths=absolute,
        xacro_args=files.xacro_args or None,
        meshes="keep",
        base_folder=loaded.folder,
    ).world


def _add_base(draft: Draft, spec: RobotSpec, marks: _Marks) -> None:
    """The facing, the drive, the spec's own frames, the torso and the neck."""
    forward = getattr(spec, "forward", None)
    if forward is not None:
        draft.forward = (float(forward[0]), float(forward[1]), float(forward[2]))
        draft.forward_decide = next(iter(marks.decide(("forward",))), "")
    if spec.drive is not None:
        d = spec.drive
        draft.drive = DraftDrive(
            type=d.type,
            joint=d.joint,
            parent_frame=d.parent_frame if d.type != "fixed" else None,
            source=marks.source(("drive",)),
            decide=next(iter(marks.decide(("drive",))), None),
        )
    for name, f in spec.files.frames.items():
        loc: tuple[str | int, ...] = ("description", "frames", name)
        draft.frames.append(DraftFrame(name, f.parent, f.xyz, (marks.decide(loc) or [""])[0]))
    for key in ("torso", "neck"):
        part = getattr(spec, key)
        if part is None:
            continue
        c = DraftChain(
            name=key,
            root=part.root,
            tip=part.tip,
            source=marks.source((key,)),
            role=key,
            decide=marks.decide((key,)),
            states={k: dict(v) for k, v in part.states.items()},
        )
        if key == "neck":
            c.yaw_body, c.pitch_body, c.sensors = part.yaw_body, part.pitch_body, [*part.sensors]
        setattr(draft, key, c)


def _add_chains(draft: Draft, spec: RobotSpec, marks: _Marks) -> None:
    for name, ch in spec.chains.items():
        ends = marks.ends(("chains", name, "group")) if ch.group else ("", "")
        draft.chains.append(
            DraftChain(
                name=name,
                root=ch.root or ends[0],
                tip=ch.tip or ends[1],
                source=marks.source(("chains", name)),
                role=ch.kind if ch.kind != "chain" else "chain",
                group=ch.group,
                decide=marks.decide(("chains", name)),
                manipulator=ch.manipulator,
                sensors=[*ch.sensors],
                states={k: dict(v) for k, v in ch.states.items()},
                side=ch.side,
            )
        )


def _add_manipulators(draft: Draft, spec: RobotSpec, marks: _Marks) -> None:
    for name, m in spec.manipulators.items():
        dm = DraftManipulator(
            name=name,
            root=m.root,
            tool_frame=m.tool_frame,
            source=marks.source(("manipulators", name)),
            decide=marks.decide(("manipulators", name)),
            states={k: dict(v) for k, v in m.states.items()},
            front_facing=m.front_facing_orientation,
        )
        if m.type == "parallel_gripper":
            dm.finger = DraftFinger(m.finger.root, m.finger.tip)
            dm.thumb = DraftFinger(m.thumb.root, m.thumb.tip)
        elif m.type == "hand":
            dm.thumb = DraftFinger(m.thumb.root, m.thumb.tip)
            dm.fingers = {k: DraftFinger(f.root, f.tip) for k, f in m.fingers.items()}
        draft.manipulators.append(dm)


def _add_cameras(draft: Draft, spec: RobotSpec, marks: _Marks) -> None:
    """The spec's cameras; a generic sensor is edited as text (setup/edits_more.py), kept as is."""
    for name, s in spec.sensors.items():
        if s.type != "camera":
            continue
        axis = s.forward_facing_axis
        fov = s.field_of_view
        angles = None if fov is None else (fov.horizontal, fov.vertical)
        placeholder = angles == PLACEHOLDER_FOV and marks.decide(("sensors", name, "field_of_view"))
        draft.cameras.append(
            DraftCamera(
                name=name,
                body=s.body,
                optical=axis in (None, (0.0, 0.0, 1.0)),
                axis=None if axis in _AXES else axis,
                decide=marks.decide(("sensors", name)),
                preset=s.preset,
                field_of_view=None if placeholder else angles,
                minimal_height=s.minimal_height,
                maximal_height=s.maximal_height,
                default=s.default,
            )
        )
