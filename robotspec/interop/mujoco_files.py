"""Which files a user's MJCF makes MuJoCo read, checked before MuJoCo reads any.

Why: ``annotate mjcf`` hands the user's model to MuJoCo, which opens every file the model names
(includes, meshes, textures, height fields, skins) wherever it points: a downloaded model naming
``../../.ssh/id_rsa`` as a mesh, or a planted link in its asset folder, would make robotspec
read it. The same fence as a robot description's (:mod:`robotspec.files.fences`): the model's
folder, or the marked project around it (a repository keeping ``robots/`` and ``meshes/``
apart), never a hidden or system folder, every path judged after its links are resolved.
"""

from __future__ import annotations

import os
from pathlib import Path

from robotspec.errors import RobotSpecError
from robotspec.files.fences import marked_project, refusal
from robotspec.files.xmlsafe import parse_xml_file

__all__ = ["check_model_files"]

#: The folder attribute of ``<compiler>`` each file-naming element is read from.
_FOLDER_OF = {"mesh": "meshdir", "skin": "meshdir", "texture": "texturedir", "hfield": "assetdir"}
#: How deep includes may nest, and how many files one model may name (bounded work).
_MAX_DEPTH, _MAX_FILES = 8, 100_000


def check_model_files(path: Path) -> None:
    """Refuse ``path`` when it (or a file it includes) names a file outside its fence."""
    folder = Path(os.path.realpath(path)).parent
    allowed = marked_project(folder) or folder
    seen: list[int] = [0]
    _check(Path(path), folder, allowed, {}, 0, seen)


def _check(
    path: Path, folder: Path, allowed: Path, dirs: dict[str, str], depth: int, seen: list[int]
) -> None:
    root = parse_xml_file(path, RobotSpecError, what="an MJCF file")
    dirs = dict(dirs)
    for compiler in root.iter("compiler"):
        for attr in ("meshdir", "texturedir", "assetdir"):
            if compiler.get(attr) is not None:
                dirs[attr] = compiler.get(attr, "")
    for el in root.iter():
        name = el.get("file") if isinstance(el.tag, str) else None
        if not name:
            continue
        seen[0] += 1
        if seen[0] > _MAX_FILES:
            raise RobotSpecError(f"the model names more than {_MAX_FILES:,} files", file=str(path))
        tag = str(el.tag)
        sub = dirs.get(_FOLDER_OF.get(tag, ""), "") or dirs.get("assetdir", "")
        target = folder / name if tag in ("include", "model") else folder / sub / name
        real = os.path.realpath(target)
        why = refusal(real, allowed)
        if why is not None:
            line = el.sourceline if isinstance(el.sourceline, int) else None
            raise RobotSpecError(
                f"<{tag} file='{name}'> resolves to {real}, which a model may not name: "
                f"{why.replace('the spec', 'the model')}",
                file=str(path),
                line=line,
                kind="mjcf",
            )
        if tag == "include" and os.path.isfile(real):
            if depth >= _MAX_DEPTH:
                raise RobotSpecError(
                    f"includes nest deeper than {_MAX_DEPTH}", file=str(path), kind="mjcf"
                )
            _check(Path(real), folder, allowed, dirs, depth + 1, seen)
