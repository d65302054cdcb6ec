"""A folder of truths read for scoring, tolerant of the files a truth writer left unfinished.

Why not ``tools.draft_score.load_truths``: that reader is for folders that must be complete (one
bad file stops it). A second expert's folder (issue 30's agreement study,
``tests/data/blind_truth_second/``) may hold a file with only a comment (``# could not load:
...``) for a robot its writer could not load, and is read while it is being written: each such
file is skipped with a message naming it, and the rest is scored.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from tools.draft_score import Truth

__all__ = ["load_truth_folder"]


def load_truth_folder(folder: Path) -> tuple[dict[str, Truth], list[str]]:
    """The truths of ``folder`` by robot id, and messages about the files skipped.

    A file holding only a comment (``# could not load: ...``: its writer could not load the
    robot) is skipped with a message, and so is one without ``robot: <id>`` or missing a key the
    counting reads (a chain's root and tip, a manipulator's type and tool frame, ...).
    """
    import yaml

    out: dict[str, Truth] = {}
    skipped: list[str] = []
    for path in sorted(folder.glob("*.yaml")):
        data = yaml.safe_load(path.read_text(encoding="utf-8"))
        if data is None:
            skipped.append(f"{path.name}: no truth (a comment only)")
        elif not isinstance(data, dict) or not isinstance(data.get("robot"), str):
            skipped.append(f"{path.name}: a truth needs 'robot: <id>'")
        elif (problem := _truth_problem(data)) is not None:
            skipped.append(f"{path.name}: {problem}")
        else:
            out[data["robot"]] = Truth(path.stem, data["robot"], data)
    return out, skipped


def _truth_problem(data: dict[str, Any]) -> str | None:
    """What keeps ``data`` from being scored (a key the counting reads is missing), or None."""
    for name, c in (data.get("chains") or {}).items():
        if not isinstance(c, dict) or not {"root", "tip"} <= set(c):
            return f"chain {name} needs root and tip"
    for name, m in (data.get("manipulators") or {}).items():
        if not isinstance(m, dict) or not {"type", "tool_frame"} <= set(m):
            return f"manipulator {name} needs type and tool_frame"
        if m["type"] in ("parallel_gripper", "hand") and not m.get("fingers"):
            return f"manipulator {name} ({m['type']}) needs fingers"
    for key in ("torso", "neck"):
        part = data.get(key)
        if part is not None and (not isinstance(part, dict) or not {"root", "tip"} <= set(part)):
            return f"{key} needs root and tip"
    drive = data.get("drive")
    if drive is not None and (not isinstance(drive, dict) or "type" not in drive):
        return "drive needs a type"
    return None
