"""How a draft refers to files: portable (``package://`` or relative), never this machine's path.

Why: a spec is shared (committed, sent to a colleague); an absolute path of the author's machine
works nowhere else, so ``init`` writes a ``package://`` URI when a file is inside a known package
and a path relative to the spec otherwise.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path

__all__ = ["package_candidates", "portable_ref", "relative_path"]


def portable_ref(
    path: Path, spec_folder: Path, packages: Mapping[str, Path]
) -> tuple[str, Path | None]:
    """A path as the spec should write it, and the package folder the URI relies on.

    Why: a ``package://`` URI works on another machine, a relative path only in this checkout;
    so a file inside a known package is written as a URI (the caller makes sure the spec can
    find that package).
    """
    real = path.resolve()
    best: tuple[int, str, Path] | None = None
    for name, folder in packages.items():
        root = folder.resolve()
        if real.is_relative_to(root):
            depth = len(root.parts)
            if best is None or depth > best[0]:
                best = (depth, f"package://{name}/{real.relative_to(root).as_posix()}", root)
    if best is not None:
        return best[1], best[2]
    return relative_path(real, spec_folder), None


def package_candidates(path: Path, packages: Mapping[str, Path]) -> list[tuple[str, Path]]:
    """Every ``package://`` URI naming ``path`` through a known package, innermost first.

    Why all of them: the innermost package is the natural name, but it may be one the spec
    cannot find where it is read (a sub-folder known only by its name beside the robot file);
    the caller takes the first that resolves as the spec will resolve it.
    """
    real = path.resolve()
    found: list[tuple[int, str, Path]] = []
    for name, folder in packages.items():
        root = folder.resolve()
        if real.is_relative_to(root):
            uri = f"package://{name}/{real.relative_to(root).as_posix()}"
            found.append((len(root.parts), uri, root))
    found.sort(key=lambda f: -f[0])  # stable: the index's order (declared names first)
    return [(uri, root) for _, uri, root in found]


def relative_path(path: Path, spec_folder: Path) -> str:
    """``path`` relative to the spec's folder (absolute when on another drive)."""
    try:
        return Path(os.path.relpath(path.resolve(), spec_folder.resolve())).as_posix()
    except ValueError:  # another drive (Windows)
        return path.resolve().as_posix()
