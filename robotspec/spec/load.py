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
from robotspec.files.validation import validation_errors
from robotspec.files.yamlio import LocatedYaml, load_yaml
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
    path: str | Path, *, _seen: tuple[Path, ...] = (), allowed: Sequence[str | Path] = ()
) -> LoadedSpec:
    """Read, merge (``extends``) and validate a spec file; every problem raised at once.

    ``allowed``: folders the user allows besides the spec's project (``-P``), for ``extends``.
    """
    p = Path(path).resolve()
    if p in _seen:
        chain = " -> ".join(x.name for x in (*_seen, p))
        raise SpecError(f"'extends' forms a cycle: {chain}", file=str(path))
    doc = load_yaml(path)
    if not isinstance(doc.data, Mapping):
        raise SpecError("a spec must be a YAML mapping", file=doc.file, line=1)
    data: Any = doc.data
    documents: tuple[LocatedYaml, ...] = (doc,)
    foreign = foreign_paths(doc, p.parent)
    base_file = data.get("extends")
    if isinstance(base_file, str):
        base_path = (p.parent / base_file).resolve()
        shipped = shipped_spec_files()
        if not base_path.is_file() and base_file.lower() in shipped:
            base_path = shipped[base_file.lower()]  # a shipped robot, by name
        if not base_path.is_file():
            line, col = doc.position(("extends",))
            siblings = [f.name for f in p.parent.glob("*.y*ml")]
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
            line, col = doc.position(("extends",))
            check_spec_path(
                str(base_path),
                p.parent,
                key="extends",
                file=doc.file,
                line=line,
                column=col,
                location=("extends",),
                allowed=allowed,
                given=base_file,
            )
        base = load_spec(base_path, _seen=(*_seen, p), allowed=allowed)
        base_data = base.spec.model_dump(mode="json", exclude_unset=True, by_alias=True)
        base_data.pop("extends", None)
        _absolutize(base_data, base.folder)
        data = merge_data(base_data, {k: v for k, v in data.items() if k != "extends"})
        data["extends"] = base_file
        documents = (doc, *base.documents)
        foreign += base.foreign_paths
    try:
        spec = RobotSpec.model_validate(data)
    except ValidationError as exc:
        raise validation_errors(exc, doc, RobotSpec, SpecError) from None
    return LoadedSpec(spec=spec, file=p, documents=documents, foreign_paths=tuple(foreign))


def json_schema() -> dict[str, Any]:
    """The JSON Schema of the spec format, for editors (the YAML language server)."""
    schema = RobotSpec.model_json_schema()
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    schema["title"] = "robotspec robot spec"
    return schema


def json_schema_text() -> str:
    """The schema as stable, pretty JSON text (what ships in the package)."""
    return json.dumps(json_schema(), indent=2, sort_keys=True) + "\n"
