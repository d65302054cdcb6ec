"""What the assistant starts from: a URDF (drafted as ``init`` does) or a spec (read back).

A spec is read back into the draft's form, its DECIDE marks found at their parts.

Why one form for both: the assistant edits a :class:`~robotspec.spec.draft.Draft`. A URDF's
draft is saved with the draft's writer (what ``init`` writes). A spec is saved as its own text
with the session's changes made in it (:class:`~robotspec.setup.round_trip.SpecText`), so what a
draft cannot hold (``parts:``, ``extends:``, generic sensors, rotated frames, comments, settings
the page does not edit) stays exactly as written.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from robotspec.model.world import World
from robotspec.setup.round_trip import SpecText
from robotspec.spec.draft.model import Draft

__all__ = ["KEPT_KEYS", "Source", "is_spec_file", "open_source"]

#: Top-level spec keys the assistant keeps as read (it does not edit them).
KEPT_KEYS = (
    "velocity_limits",
    "controlled_joints",
    "collision",
    "import_srdf_group_states",
    "accept_warnings",
)


@dataclass(frozen=True)
class Source:
    """A draft to edit, the robot's kinematic tree, and what of the input is kept as read."""

    draft: Draft
    world: World
    origin: str
    kept: dict[str, Any] = field(default_factory=dict)
    presets: tuple[str, ...] = ()
    #: The robot's own files (URDF or xacro, SRDF, meshes, the spec read), each with what it
    #: is: no save replaces one (``robotspec.setup.targets``).
    inputs: dict[Path, str] = field(default_factory=dict)
    #: A spec's own text, which saving edits (None: a URDF's draft, written by the drafter).
    written: SpecText | None = None


def _text(path: Path) -> str:
    """The spec's text, byte for byte (no newline translation), read within the YAML cap."""
    from robotspec.files.limits import limits
    from robotspec.files.reading import read_bounded

    cap = limits().max_yaml_bytes
    return read_bounded(path, cap=cap, cap_name="max_yaml_bytes", what="a YAML file").decode()


def is_spec_file(ref: str) -> bool:
    """Whether ``ref`` names a spec (a YAML file, a shipped robot) rather than a URDF or xacro."""
    from robotspec.shipped import shipped_spec_files

    if ref.lower().endswith((".yaml", ".yml")):
        return True
    return not Path(ref).exists() and ref.lower() in shipped_spec_files()


def open_source(
    ref: str,
    *,
    srdf: str | None = None,
    output: Path,
    package_paths: Sequence[str | Path] = (),
) -> Source:
    """Open ``ref`` for editing; its problems raise the errors ``init`` or ``validate`` raise."""
    from robotspec.setup.targets import robot_inputs
    from robotspec.spec.draft.render import camera_presets

    presets = camera_presets()
    if is_spec_file(ref):
        from robotspec.compiler import resolve_spec
        from robotspec.files.yamlio import load_yaml_text
        from robotspec.setup.from_spec import draft_of_spec

        folder = output.resolve().parent
        read = draft_of_spec(ref, package_paths=package_paths, folder=folder)
        draft, world = read.draft, read.world
        named = draft.srdf if draft.srdf and "://" not in draft.srdf else None
        path = resolve_spec(ref)
        inputs = robot_inputs(world, srdf=[named and folder / named], spec=path.absolute())
        text = _text(path)
        doc = load_yaml_text(text, str(path))  # checked as validate checks it
        composed = isinstance(doc.data, dict) and bool(doc.data.get("parts"))
        written = SpecText.read(
            text, str(path), read.as_read, presets, others=read.others, composed=composed
        )
        return Source(draft, world, ref, read.kept, presets, inputs, written)
    from robotspec.spec.draft.run import draft_from_files

    folder = output.resolve().parent
    draft, desc = draft_from_files(ref, srdf, folder=folder, package_paths=package_paths)
    inputs = robot_inputs(desc.world, srdf=[desc.srdf.file if desc.srdf else None, srdf])
    return Source(draft, desc.world, ref, {}, presets, inputs)
