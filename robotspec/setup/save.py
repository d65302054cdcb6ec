"""A URDF's draft as the assistant writes it (the draft's own writer), and the atomic write.

Why the draft's writer: it is what ``robotspec init`` writes, so a saved spec reads like a
draft (its header, its ``# from`` notes, the DECIDE marks still open) and answered marks are
simply gone. A spec the assistant opened is not written here but edited in its own text
(:mod:`robotspec.setup.round_trip`).
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path
from typing import Any

import yaml

from robotspec.spec.draft.model import Draft
from robotspec.spec.draft.render import render_draft

__all__ = ["spec_text", "write_spec"]


def spec_text(draft: Draft, kept: dict[str, Any], presets: tuple[str, ...] = ()) -> str:
    """The text of the spec: the draft, then the kept top-level keys."""
    text = render_draft(draft, presets=presets)
    if kept:
        text += "# Kept as read (robotspec setup does not edit these).\n"
        text += yaml.safe_dump(kept, sort_keys=False, allow_unicode=True, width=100)
    return text


def write_spec(
    path: Path,
    text: str,
    *,
    under: Path | None = None,
    force: bool = True,
    inputs: Iterable[Path] = (),
) -> Path:
    """Write the spec atomically: a crash mid-write never leaves half a spec.

    Through :func:`robotspec.files.writing.write_file`: an exclusive temporary file renamed into
    place (a link planted at any name the save uses is never followed), no link below ``under``
    (the folder the user named, default the spec's own), never over one of ``inputs`` (the
    robot's URDF, SRDF, ...). ``force`` defaults to True: the assistant saves its spec again and
    again.
    """
    from robotspec.files.writing import write_file

    return write_file(path, text, under=under, force=force, inputs=inputs)
