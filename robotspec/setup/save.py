"""The spec as the assistant writes it: the draft's own writer, then what was kept as read.

Why the draft's writer: it is what ``robotspec init`` writes, so a saved spec reads like a
draft (its header, its ``# from`` notes, the DECIDE marks still open) and answered marks are
simply gone. Keys the assistant does not edit follow, as read from the input spec.
"""

from __future__ import annotations

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


def write_spec(path: Path, text: str) -> None:
    """Write the spec atomically: a crash mid-write never leaves half a spec."""
    from robotspec.errors import RobotSpecError

    tmp = path.with_name(f".{path.name}.saving")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp.write_text(text, encoding="utf-8")
        tmp.replace(path)
    except OSError as exc:
        tmp.unlink(missing_ok=True)
        raise RobotSpecError(
            f"cannot write file: {exc.strerror or exc}", file=str(path), kind="file"
        ) from None
