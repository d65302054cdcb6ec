"""Safe YAML loading that remembers where every value came from.

Why: every user-facing error must name the file and line of the offending YAML node, but pydantic
only knows a location path (``("chains", 0, "tip")``). :func:`load_yaml` composes the document
with PyYAML's *safe* loader (no arbitrary tags, no object construction), builds plain Python data
from the node tree, and records the start mark of each node under its path, so a pydantic error
location maps back to ``file:line:column``.
"""

from __future__ import annotations

import math
import types
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Annotated, Any, Union, get_args, get_origin

import yaml
from pydantic import BaseModel, ValidationError

from robotspec.diagnostics import loc_text
from robotspec.errors import RobotSpecError, RobotSpecErrors, closest_names, missing_file

__all__ = ["LocatedYaml", "load_yaml", "load_yaml_text", "validation_errors"]

Loc = tuple[str | int, ...]

#: Refuse documents larger than this; a spec or RobotInfo is a few kB.
MAX_YAML_BYTES = 8 * 1024 * 1024


@dataclass(frozen=True)
class LocatedYaml:
    """Plain data of one YAML document plus the ``(line, column)`` of each node, 1-based."""

    data: Any
    file: str
    marks: Mapping[Loc, tuple[int, int]] = field(default_factory=dict)
    key_marks: Mapping[Loc, tuple[int, int]] = field(default_factory=dict)

    def position(self, loc: Sequence[str | int]) -> tuple[int | None, int | None]:
        """The line and column of the node at ``loc``, or of its nearest existing ancestor."""
        path = tuple(loc)
        while True:
            if path in self.marks:
                return self.marks[path]
            if not path:
                return (None, None)
            path = path[:-1]

    def key_position(self, loc: Sequence[str | int]) -> tuple[int | None, int | None]:
        """Where the *key* of a mapping entry is written (for unknown-key errors)."""
        path = tuple(loc)
        if path in self.key_marks:
            return self.key_marks[path]
        return self.position(path)


_PLAIN_TAGS = frozenset(
    f"tag:yaml.org,2002:{t}"
    for t in ("map", "seq", "str", "int", "float", "bool", "null", "timestamp", "merge")
)


# libyaml's loader when PyYAML was built with it (ten times faster; same marks), else pure Python.
_BaseLoader: type[yaml.SafeLoader] = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


class _SafeComposer(_BaseLoader):  # type: ignore[valid-type,misc]
    """SafeLoader used only to compose nodes; no Python objects are constructed from tags."""


class _PySafeComposer(yaml.SafeLoader):
    """The pure-Python loader, for its clearer syntax-error messages."""


def _scalar(node: yaml.ScalarNode, loader: yaml.SafeLoader) -> Any:
    return loader.construct_object(node, deep=True)


def _build(
    node: yaml.Node,
    loader: yaml.SafeLoader,
    path: Loc,
    marks: dict[Loc, tuple[int, int]],
    key_marks: dict[Loc, tuple[int, int]],
    file: str,
    depth: int,
) -> Any:
    if depth > 100:
        raise RobotSpecError("YAML nested too deeply", file=file, line=node.start_mark.line + 1)
    marks[path] = (node.start_mark.line + 1, node.start_mark.column + 1)
    if node.tag not in _PLAIN_TAGS:
        raise RobotSpecError(
            f"unsupported YAML tag '{node.tag}' (only plain YAML data is read)",
            file=file,
            line=node.start_mark.line + 1,
            column=node.start_mark.column + 1,
            name=node.tag,
        )
    if isinstance(node, yaml.MappingNode):
        loader.flatten_mapping(node)
        out: dict[Any, Any] = {}
        for key_node, value_node in node.value:
            key = _scalar(key_node, loader) if isinstance(key_node, yaml.ScalarNode) else None
            if not isinstance(key, (str, int, float, bool)) or key is None:
                raise RobotSpecError(
                    "mapping keys must be plain scalars",
                    file=file,
                    line=key_node.start_mark.line + 1,
                    column=key_node.start_mark.column + 1,
                )
            if isinstance(key, bool) or not isinstance(key, str):
                key = str(key)
            if key in out:
                raise RobotSpecError(
                    f"duplicate key '{key}'",
                    file=file,
                    line=key_node.start_mark.line + 1,
                    column=key_node.start_mark.column + 1,
                    name=key,
                )
            child = (*path, key)
            key_marks[child] = (key_node.start_mark.line + 1, key_node.start_mark.column + 1)
            out[key] = _build(value_node, loader, child, marks, key_marks, file, depth + 1)
        return out
    if isinstance(node, yaml.SequenceNode):
        return [
            _build(item, loader, (*path, i), marks, key_marks, file, depth + 1)
            for i, item in enumerate(node.value)
        ]
    value = _scalar(node, loader)  # type: ignore[arg-type]
    return value


def load_yaml_text(text: str, file: str = "<string>") -> LocatedYaml:
    """Parse one YAML document from ``text`` safely, keeping node positions."""
    if len(text.encode("utf-8", errors="replace")) > MAX_YAML_BYTES:
        raise RobotSpecError(f"YAML file larger than {MAX_YAML_BYTES} bytes", file=file)
    try:
        return _compose(_SafeComposer, text, file)
    except yaml.YAMLError as fast_error:
        if _SafeComposer.__mro__[1] is yaml.SafeLoader:
            raise _yaml_error(fast_error, file) from None
        # libyaml's messages are terser ("did not find expected ','"); the pure-Python parser
        # says what it found instead. Errors are rare, so parse again for the better message.
        try:
            _compose(_PySafeComposer, text, file)
        except yaml.YAMLError as slow_error:
            raise _yaml_error(slow_error, file) from None
        raise _yaml_error(fast_error, file) from None
    except RecursionError:
        raise RobotSpecError("YAML nested too deeply", file=file) from None


def _compose(loader_type: type[yaml.SafeLoader], text: str, file: str) -> LocatedYaml:
    loader: yaml.SafeLoader | None = None
    try:
        loader = loader_type(text)  # the reader checks characters as it is made
        node = loader.get_single_node()
        if node is None:
            return LocatedYaml(data=None, file=file)
        marks: dict[Loc, tuple[int, int]] = {}
        key_marks: dict[Loc, tuple[int, int]] = {}
        data = _build(node, loader, (), marks, key_marks, file, 0)
    finally:
        if loader is not None:
            loader.dispose()
    return LocatedYaml(data=data, file=file, marks=marks, key_marks=key_marks)


def _yaml_error(exc: yaml.YAMLError, file: str) -> RobotSpecError:
    if isinstance(exc, yaml.MarkedYAMLError):
        mark = exc.problem_mark or exc.context_mark
        problem = exc.problem or exc.context or "invalid YAML"
        return RobotSpecError(
            f"invalid YAML: {problem}",
            file=file,
            line=None if mark is None else mark.line + 1,
            column=None if mark is None else mark.column + 1,
        )
    return RobotSpecError(f"invalid YAML: {exc}", file=file)


def load_yaml(path: str | Path) -> LocatedYaml:
    """Read and parse a YAML file safely; a missing or unreadable file is a RobotSpecError."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise missing_file(path) from None
    except IsADirectoryError:
        raise RobotSpecError("is a directory, not a YAML file", file=str(path)) from None
    except UnicodeDecodeError as exc:
        raise RobotSpecError(f"not UTF-8 text ({exc.reason})", file=str(path)) from None
    except OSError as exc:
        raise RobotSpecError(f"cannot read file: {exc.strerror}", file=str(path)) from None
    return load_yaml_text(text, file=str(path))


def _leaves(annotation: Any) -> list[Any]:
    """An annotation without its wrappers: Annotated, Optional and unions flattened."""
    origin = get_origin(annotation)
    if origin is Annotated:
        return _leaves(get_args(annotation)[0])
    if origin is Union or origin is types.UnionType:
        return [leaf for arg in get_args(annotation) for leaf in _leaves(arg)]
    return [annotation]


def _is_model(ann: Any) -> bool:
    return isinstance(ann, type) and issubclass(ann, BaseModel)


def _model_fields_at(model: type[BaseModel], loc: Sequence[str | int]) -> list[str]:
    """The keys valid in the mapping at ``loc`` (for unknown-key suggestions).

    Why the walk by annotation: a part's name (``chains.left_arm``) is a dict key, not a field,
    so each step either names a field of the current models or enters a dict value or list item.
    """
    current: list[Any] = [model]
    for part in loc:
        step: list[Any] = []
        for ann in (leaf for a in current for leaf in _leaves(a)):
            if _is_model(ann):
                for name, fld in ann.model_fields.items():
                    if part in (name, fld.alias):
                        step.append(fld.annotation)
            elif get_origin(ann) in (dict, Mapping) and get_args(ann):
                step.append(get_args(ann)[-1])
            elif get_origin(ann) in (list, tuple, Sequence) and isinstance(part, int):
                step.extend(get_args(ann)[:1])
        current = step
    names: list[str] = []
    for ann in (leaf for a in current for leaf in _leaves(a)):
        if _is_model(ann):
            for name, fld in ann.model_fields.items():
                key = fld.alias or name
                if key not in names:
                    names.append(key)
    return names


def validation_errors(
    exc: ValidationError,
    doc: LocatedYaml,
    model: type[BaseModel],
    error_type: type[RobotSpecError] = RobotSpecError,
    loc_prefix: Sequence[str | int] = (),
) -> RobotSpecError:
    """Turn a pydantic ValidationError into located RobotSpecErrors (one per problem)."""
    errors: list[RobotSpecError] = []
    for err in exc.errors(include_url=False):
        loc = tuple(p for p in err["loc"] if isinstance(p, (str, int)))  # drop discriminator tags
        # Pydantic appends union member names and function tags to locs; keep real keys only.
        real_loc = _strip_to_document(loc, doc)
        full_loc = (*loc_prefix, *real_loc)
        where = loc_text(full_loc) or "(document)"
        kind = err["type"]
        if kind == "extra_forbidden":
            key = str(real_loc[-1]) if real_loc else "?"
            valid = _model_fields_at(model, real_loc[:-1])
            suggestions = closest_names(key, valid)
            hint = ""
            if suggestions:
                hint = f"; did you mean '{suggestions[0]}'?"
            elif valid:
                hint = f"; valid keys: {', '.join(valid)}"
            line, col = doc.key_position(real_loc)
            errors.append(
                error_type(
                    f"unknown key '{key}' at {where}{hint}",
                    file=doc.file,
                    line=line,
                    column=col,
                    kind="key",
                    name=key,
                    suggestions=suggestions,
                    location=full_loc,
                )
            )
            continue
        line, col = doc.position(real_loc)
        if kind == "missing" and real_loc:
            parent = loc_text((*loc_prefix, *real_loc[:-1])) or "(document)"
            errors.append(
                error_type(
                    f"{parent}: missing required key '{real_loc[-1]}'",
                    file=doc.file,
                    line=line,
                    column=col,
                    kind="key",
                    name=str(real_loc[-1]),
                    location=full_loc,
                )
            )
            continue
        msg = str(err["msg"])
        if msg.startswith("Value error, "):
            msg = msg[len("Value error, ") :]
        given = err.get("input")
        shown = ""
        if kind not in ("missing",) and _is_short_scalar(given):
            shown = f" (got {given!r})"
        errors.append(
            error_type(
                f"{where}: {msg}{shown}",
                file=doc.file,
                line=line,
                column=col,
                location=full_loc,
            )
        )
    errors.sort(key=lambda e: (e.line or 0, e.column or 0))
    if len(errors) == 1:
        return errors[0]
    return RobotSpecErrors(errors, summary=f"{doc.file}: {len(errors)} problems")


def _is_short_scalar(value: Any) -> bool:
    if isinstance(value, float) and not math.isfinite(value):
        return True
    return isinstance(value, (str, int, float, bool)) and len(repr(value)) <= 60


def _strip_to_document(loc: Loc, doc: LocatedYaml) -> Loc:
    """Drop pydantic's union/validator tags that are not keys of the document.

    Every part but the last exists in the document (validation reached it); a part that does
    not is a tag, such as a discriminated union's member name ('parallel_gripper'). The last
    part may be a key the document lacks (a missing key), so only tag-shaped ones go.
    """
    out: list[str | int] = []
    for i, part in enumerate(loc):
        candidate = (*out, part)
        last = i == len(loc) - 1
        if candidate in doc.marks or candidate in doc.key_marks or isinstance(part, int):
            out.append(part)
        elif last and not _is_tag(part):
            out.append(part)
    return tuple(out)


def _is_tag(part: str) -> bool:
    # Pydantic union member tags look like 'function-after[...]', 'list[...]', 'ModelName'.
    return "[" in part or (part[:1].isupper() and part.isidentifier())
