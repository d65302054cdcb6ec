"""Reading a spec file: YAML with line marks, ``extends`` merged, Pydantic validation.

``LoadedSpec`` keeps every document's marks so the compiler can point at ``file:line:col`` of
any node, in the extending file first; the JSON Schema for editors is produced here too.
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from pydantic import ValidationError

from robotspec.errors import NotFoundError, SpecError
from robotspec.files.limits import env_name, limits
from robotspec.files.validation import validation_errors
from robotspec.files.yamlio import LocatedYaml, load_yaml, load_yaml_text
from robotspec.shipped import package_data, shipped_spec_files
from robotspec.spec.fences import (
    ForeignPath,
    check_package_paths,
    check_spec_path,
    foreign_paths,
    spec_may_name,
)
from robotspec.spec.models import RobotSpec

__all__ = [
    "ForeignPath",
    "LoadedSpec",
    "check_package_paths",
    "json_schema",
    "json_schema_text",
    "load_spec",
    "merge_data",
    "spec_may_name",
]


@dataclass(frozen=True)
class LoadedSpec:
    """A validated spec with where it came from, for located errors and relative paths."""

    spec: RobotSpec
    file: Path
    documents: tuple[LocatedYaml, ...]
    #: ``package_paths`` entries (of this file and the files it extends) outside their spec's
    #: folder tree; :func:`check_package_paths` refuses them unless the user allowed the folder.
    foreign_paths: tuple[ForeignPath, ...] = ()

    def position(self, loc: tuple[str | int, ...]) -> tuple[str, int | None, int | None]:
        """``(file, line, column)`` of a spec node, looking in the extending file first."""
        for doc in self.documents:
            if loc in doc.marks:
                line, col = doc.marks[loc]
                return doc.file, line, col
        # Fall back to the nearest ancestor that exists in some document.
        for cut in range(len(loc) - 1, -1, -1):
            for doc in self.documents:
                if loc[:cut] in doc.marks:
                    line, col = doc.marks[loc[:cut]]
                    return doc.file, line, col
        return str(self.file), None, None

    @property
    def folder(self) -> Path:
        """The folder relative paths in the spec are resolved against."""
        return self.file.parent


def merge_data(base: Any, child: Any) -> Any:
    """``child`` over ``base``, mapping by mapping (``extends`` and composed specs' overrides)."""
    if isinstance(base, Mapping) and isinstance(child, Mapping):
        out = dict(base)
        for k, v in child.items():
            out[k] = merge_data(base[k], v) if k in base else v
        return out
    return child


def _absolute_paths(desc: dict[str, Any], folder: Path, keys: tuple[str, ...]) -> None:
    for key in keys:
        value = desc.get(key)
        if isinstance(value, str) and "://" not in value and not Path(value).is_absolute():
            if key == "spec" and not (folder / value).is_file():
                continue  # a shipped robot's name, not a path
            desc[key] = str((folder / value).resolve())
    paths = desc.get("package_paths")
    if isinstance(paths, list):
        desc["package_paths"] = [
            str((folder / v).resolve()) if not Path(v).is_absolute() else v for v in paths
        ]


def _absolutize(data: dict[str, Any], folder: Path) -> None:
    """Rewrite a base spec's relative file paths so they stay right inside the child spec."""
    desc = data.get("description")
    if isinstance(desc, dict):
        _absolute_paths(desc, folder, ("urdf", "srdf"))
    parts = data.get("parts")
    if isinstance(parts, dict):
        for part in parts.values():
            if isinstance(part, dict):
                _absolute_paths(part, folder, ("urdf", "srdf", "spec"))


def load_spec(
    path: str | Path, *, allowed: Sequence[str | Path] = (), text: str | None = None
) -> LoadedSpec:
    """Read, merge (``extends``) and validate a spec file; every problem raised at once.

    ``allowed``: folders the user allows besides the spec's project (``-P``), for ``extends``.
    ``text``: the spec's text, read as if it were the file ``path`` (which need not exist):
    ``robotspec setup`` validates what it would save without writing anything.
    The chain of ``extends`` is followed in a loop (each file read once, a cycle or a chain
    deeper than ``ROBOTSPEC_MAX_EXTENDS_DEPTH`` refused at the ``extends`` line that goes too
    far), then validated from the last base up, each file over the one it extends.
    """
    loaded: LoadedSpec | None = None
    for file, doc in reversed(_extends_chain(path, allowed, text)):
        data: Any = doc.data
        documents: tuple[LocatedYaml, ...] = (doc,)
        foreign = foreign_paths(doc, file.parent)
        if loaded is not None:
            base_data = loaded.spec.model_dump(mode="json", exclude_unset=True, by_alias=True)
            base_data.pop("extends", None)
            _absolutize(base_data, loaded.folder)
            data = merge_data(base_data, {k: v for k, v in data.items() if k != "extends"})
            data["extends"] = doc.data["extends"]
            documents = (doc, *loaded.documents)
            foreign += loaded.foreign_paths
        try:
            spec = RobotSpec.model_validate(data)
        except ValidationError as exc:
            raise validation_errors(exc, doc, RobotSpec, SpecError) from None
        loaded = LoadedSpec(spec=spec, file=file, documents=documents, foreign_paths=tuple(foreign))
    assert loaded is not None  # the chain holds the spec itself
    return loaded


def _extends_chain(
    path: str | Path, allowed: Sequence[str | Path], text: str | None = None
) -> list[tuple[Path, LocatedYaml]]:
    """The spec and the files it extends, in order, each read once (a loop, not recursion).

    Why a loop: a chain 1,100 files deep ran out of Python's stack; now a chain longer than the
    cap, or one that comes back to a file, is an error at the ``extends`` line that goes on.
    """
    cap = limits().max_extends_depth
    file, given = Path(path).resolve(), str(path)
    chain: list[tuple[Path, LocatedYaml]] = []
    while True:
        doc = load_yaml(given) if text is None or chain else load_yaml_text(text, given)
        if not isinstance(doc.data, Mapping):
            raise SpecError("a spec must be a YAML mapping", file=doc.file, line=1)
        chain.append((file, doc))
        base_file = doc.data.get("extends")
        if not isinstance(base_file, str):
            return chain
        base_path = _base_path(base_file, file, doc, allowed)
        problem = None
        if any(base_path == seen for seen, _ in chain):
            names = " -> ".join(f.name for f in (*(f for f, _ in chain), base_path))
            problem = f"'extends' forms a cycle: {names}"
        elif len(chain) > cap:
            problem = (
                f"'extends' chain longer than {cap} files (set "
                f"{env_name('max_extends_depth')} to raise it)"
            )
        if problem is not None:
            line, col = doc.position(("extends",))
            raise SpecError(problem, file=doc.file, line=line, column=col, location=("extends",))
        file, given = base_path, str(base_path)


def _base_path(base_file: str, file: Path, doc: LocatedYaml, allowed: Sequence[str | Path]) -> Path:
    """The file ``extends: base_file`` names in the spec ``file`` (fenced before it is read)."""
    base_path = (file.parent / base_file).resolve()
    shipped = shipped_spec_files()
    if not base_path.is_file() and base_file.lower() in shipped:
        base_path = shipped[base_file.lower()]  # a shipped robot, by name
    line, col = doc.position(("extends",))
    if not base_path.is_file():
        siblings = [f.name for f in file.parent.glob("*.y*ml")]
        raise NotFoundError(
            "spec",
            base_file,
            [*siblings, *shipped],
            where="this folder or the shipped robots",
            file=doc.file,
            line=line,
            column=col,
            location=("extends",),
        )
    if base_path.parent != package_data("specs"):
        # Fenced before it is read: a base outside the spec's project is the user's to allow.
        check_spec_path(
            str(base_path),
            file.parent,
            key="extends",
            file=doc.file,
            line=line,
            column=col,
            location=("extends",),
            allowed=allowed,
            given=base_file,
        )
    return base_path


def json_schema() -> dict[str, Any]:
    """The JSON Schema of the spec format, for editors (the YAML language server)."""
    schema = RobotSpec.model_json_schema()
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    schema["title"] = "robotspec robot spec"
    return schema


def json_schema_text() -> str:
    """The schema as stable, pretty JSON text (what ships in the package)."""
    return json.dumps(json_schema(), indent=2, sort_keys=True) + "\n"
