"""Where generated classes' recipes are kept for a fresh process: the user's folder, or nowhere.

Why apart from :mod:`robotspec.interop.sdt.classes`: the classes live in memory and pickle
with their recipe; a file is written only where the user names a folder (``to_sdt(...,
class_store=...)`` or ``$ROBOTSPEC_SDT_CLASSES``; docs/sdt.md, "Where class recipes are
kept"), and this module is that folder's one reader and writer. The classes module asks it
(:func:`stores`, :func:`stored`) when a fresh process meets a class by its path alone.
"""

from __future__ import annotations

import json
import os
import tempfile
import threading
from pathlib import Path

from robotspec.errors import RobotSpecError
from robotspec.interop.sdt.recipe import RobotRecipe

__all__ = ["class_store", "remember", "stored", "stores"]

#: Folders recipes were stored in by this process (``to_sdt(..., class_store=...)``).
_STORES: list[Path] = []
#: Guards ``_STORES`` and the writes.
_LOCK = threading.Lock()


def class_store(folder: str | os.PathLike[str] | None = None) -> Path | None:
    """Where recipes are kept: ``folder``, else ``$ROBOTSPEC_SDT_CLASSES``, else nowhere."""
    if folder is not None:
        return Path(folder)
    env = os.environ.get("ROBOTSPEC_SDT_CLASSES")
    return Path(env) if env else None


def remember(recipe: RobotRecipe, folder: str | os.PathLike[str] | None = None) -> Path | None:
    """Store ``recipe`` (once, atomically) where :func:`class_store` says; None: nowhere."""
    store = class_store(folder)
    if store is None:
        return None
    path = store / f"{recipe.digest()}.json"
    with _LOCK:
        if folder is not None and store not in _STORES:
            _STORES.append(store)
        if not path.is_file():
            store.mkdir(parents=True, exist_ok=True)
            fd, tmp = tempfile.mkstemp(dir=store, suffix=".tmp")
            with os.fdopen(fd, "w", encoding="utf-8") as f:
                json.dump(recipe.to_json(), f)
            os.replace(tmp, path)
    return path


def stored(path: Path) -> RobotRecipe:
    """The recipe stored at ``path``, or a RobotSpecError naming the damaged file."""
    try:
        return RobotRecipe.from_json(json.loads(path.read_text(encoding="utf-8")))
    except (OSError, ValueError, KeyError, TypeError, IndexError) as exc:
        raise RobotSpecError(
            f"the stored SDT class recipe {path} is damaged ({type(exc).__name__}: {exc}); "
            "delete it, and to_sdt(robot, class_store=...) writes it again",
            file=path,
            kind="file",
        ) from exc


def stores() -> list[Path]:
    """The folders a class may be found in: those this process stored in, then the variable's."""
    env = class_store()
    with _LOCK:
        return [*_STORES, *([env] if env is not None else [])]
