"""Stand-in for giskardpy's one helper SDT 26.7.0 imports (see ../../README.md)."""

from __future__ import annotations

import os


def create_path(path: str) -> None:
    """Create the folders above ``path`` (giskardpy's ``create_path``)."""
    folder = os.path.dirname(path)
    if folder:
        os.makedirs(folder, exist_ok=True)
