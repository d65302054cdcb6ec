"""Safe YAML loading that remembers where every value came from.

Why: every user-facing error must name the file and line of the offending YAML node, but pydantic
only knows a location path (``("chains", 0, "tip")``). :func:`load_yaml` composes the document
with PyYAML's *safe* loader (no arbitrary tags, no object construction), builds plain Python data
from the node tree, and records the start mark of each node under its path, so a pydantic error
location maps back to ``file:line:column``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from robotspec.errors import RobotSpecError
from robotspec.files.limits import env_name, limits
from robotspec.files.reading import read_bounded

__all__ = [
    "LocatedYaml",
    "check_yaml_shape",
    "load_yaml",
    "load_yaml_text",
]

Loc = tuple[str | int, ...]

#: Integers wider than this many bits are refused (a spec or RobotInfo never needs more; a
#: 5,000-digit integer would otherwise stop Python's int() with an internal error).
MAX_INT_BITS = 64


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


def _scalar(node: yaml.ScalarNode, loader: yaml.SafeLoader, file: str) -> Any:
    """The value of a plain scalar; a value its tag cannot hold is a located error."""
    if node.tag.endswith(":int") and len(node.value) > 40:  # before int() works on it
        raise RobotSpecError(
            f"integer '{_clip(node.value)}' is too large (more than {MAX_INT_BITS} bits)",
            file=file,
            line=node.start_mark.line + 1,
            column=node.start_mark.column + 1,
        )
    try:
        value = loader.construct_object(node, deep=True)
    except (ValueError, OverflowError, TypeError, yaml.YAMLError) as exc:
        kind = node.tag.rsplit(":", 1)[-1]
        reason = str(exc).split("\n")[0]
        raise RobotSpecError(
            f"invalid {kind} '{_clip(node.value)}': {reason}",
            file=file,
            line=node.start_mark.line + 1,
            column=node.start_mark.column + 1,
        ) from None
    if isinstance(value, int) and not isinstance(value, bool):
        if value.bit_length() > MAX_INT_BITS:
            raise RobotSpecError(
                f"integer '{_clip(node.value)}' is too large (more than {MAX_INT_BITS} bits)",
                file=file,
                line=node.start_mark.line + 1,
                column=node.start_mark.column + 1,
            )
    return value


def _clip(text: str, keep: int = 40) -> str:
    return text if len(text) <= keep else f"{text[:keep]}... ({len(text)} characters)"


def _check_shape(loader_type: type[yaml.SafeLoader], text: str, file: str) -> None:
    """Refuse deep nesting and alias bombs by reading events, before any node is composed.

    Why events: libyaml's composer recurses once per nesting level (50,000 ``[`` kill the
    process) and an alias is a shared node that the data builder would copy each time it is
    met (nine aliases of nine aliases of ... use gigabytes). The event parser keeps its own
    stack, so it can count the depth and the size every alias stands for first.
    """
    cap = limits()
    loader = loader_type(text)
    try:
        sizes: dict[str, int] = {}  # anchor -> nodes it stands for, aliases expanded
        stack: list[list[Any]] = []  # [anchor, nodes so far] per open collection
        while True:
            event: Any = loader.get_event()  # type: ignore[no-untyped-call]
            if event is None or isinstance(event, yaml.StreamEndEvent):
                return
            if isinstance(event, yaml.DocumentEndEvent):
                sizes.clear()
                continue
            mark: Any = event.start_mark
            if isinstance(event, (yaml.SequenceStartEvent, yaml.MappingStartEvent)):
                if len(stack) >= cap.max_yaml_depth:
                    raise RobotSpecError(
                        f"YAML nested too deeply (more than {cap.max_yaml_depth} levels; "
                        f"set {env_name('max_yaml_depth')} to raise it)",
                        file=file,
                        line=mark.line + 1,
                        column=mark.column + 1,
                    )
                stack.append([event.anchor, 1])
                continue
            if isinstance(event, (yaml.SequenceEndEvent, yaml.MappingEndEvent)):
                anchor, count = stack.pop()
            elif isinstance(event, yaml.ScalarEvent):
                anchor, count = event.anchor, 1
            elif isinstance(event, yaml.AliasEvent):
                anchor, count = None, sizes.get(event.anchor or "", 1)
            else:
                continue
            if anchor:
                sizes[anchor] = count
            if stack:
                stack[-1][1] += count
                count = stack[-1][1]
            if count > cap.max_yaml_nodes:
                raise RobotSpecError(
                    f"YAML document too large with its aliases expanded (more than "
                    f"{cap.max_yaml_nodes} nodes; set {env_name('max_yaml_nodes')} to raise it)",
                    file=file,
                    line=mark.line + 1,
                    column=mark.column + 1,
                )
    finally:
        loader.dispose()


def _build(
    node: yaml.Node,
    loader: yaml.SafeLoader,
    path: Loc,
    marks: dict[Loc, tuple[int, int]],
    key_marks: dict[Loc, tuple[int, int]],
    file: str,
    depth: int,
    max_depth: int,
) -> Any:
    if depth > max_depth:  # _check_shape refused such documents already
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
            key = _scalar(key_node, loader, file) if isinstance(key_node, yaml.ScalarNode) else None
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
            out[key] = _build(
                value_node, loader, child, marks, key_marks, file, depth + 1, max_depth
            )
        return out
    if isinstance(node, yaml.SequenceNode):
        return [
            _build(item, loader, (*path, i), marks, key_marks, file, depth + 1, max_depth)
            for i, item in enumerate(node.value)
        ]
    value = _scalar(node, loader, file)  # type: ignore[arg-type]
    return value


def load_yaml_text(text: str, file: str = "<string>") -> LocatedYaml:
    """Parse one YAML document from ``text`` safely, keeping node positions."""
    cap = limits().max_yaml_bytes
    if len(text) > cap or len(text.encode("utf-8", errors="replace")) > cap:
        raise RobotSpecError(
            f"YAML document larger than {cap} bytes (set {env_name('max_yaml_bytes')} to raise it)",
            file=file,
            kind="size",
        )
    try:
        _check_shape(_SafeComposer, text, file)
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
        data = _build(node, loader, (), marks, key_marks, file, 0, limits().max_yaml_depth)
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
    data = read_bounded(
        path, cap=limits().max_yaml_bytes, cap_name="max_yaml_bytes", what="a YAML file"
    )
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise RobotSpecError(f"not UTF-8 text ({exc.reason})", file=str(path)) from None
    return load_yaml_text(text, file=str(path))


def check_yaml_shape(text: str, file: str) -> None:
    """Refuse a YAML text too deep or too large with aliases expanded (before composing it)."""
    try:
        _check_shape(_SafeComposer, text, file)
    except yaml.YAMLError as exc:
        raise _yaml_error(exc, file) from None
