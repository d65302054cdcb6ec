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
    root: yaml.Node,
    loader: yaml.SafeLoader,
    marks: dict[Loc, tuple[int, int]],
    key_marks: dict[Loc, tuple[int, int]],
    file: str,
    max_depth: int,
) -> Any:
    """Plain data from a node tree, with an explicit stack (no recursion, whatever the depth)."""
    holder: list[Any] = [None]
    # (node, its path, depth, container to write into, index or key there)
    work: list[tuple[yaml.Node, Loc, int, Any, Any]] = [(root, (), 0, holder, 0)]
    while work:
        node, path, depth, into, slot = work.pop()
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
            children: list[tuple[yaml.Node, Loc, int, Any, Any]] = []
            for key_node, value_node in node.value:
                key = (
                    _scalar(key_node, loader, file)
                    if isinstance(key_node, yaml.ScalarNode)
                    else None
                )
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
                out[key] = None  # keeps the document's key order
                children.append((value_node, child, depth + 1, out, key))
            into[slot] = out
            work.extend(reversed(children))
        elif isinstance(node, yaml.SequenceNode):
            items: list[Any] = [None] * len(node.value)
            into[slot] = items
            work.extend(
                (item, (*path, i), depth + 1, items, i)
                for i, item in reversed(list(enumerate(node.value)))
            )
        else:
            into[slot] = _scalar(node, loader, file)  # type: ignore[arg-type]
    return holder[0]


def _compose_node(loader: yaml.SafeLoader) -> yaml.Node | None:
    """The single document's node tree, composed from events with an explicit stack.

    Why not PyYAML's composer: both its Python and its libyaml composer recurse once per
    nesting level, so a deep document ends in a RecursionError (or kills the process) before
    any depth check of ours could run. Events come from a parser that keeps its own stack.
    """
    loader.get_event()  # type: ignore[no-untyped-call]  # stream start
    if loader.check_event(yaml.StreamEndEvent):
        return None
    loader.get_event()  # type: ignore[no-untyped-call]  # document start
    anchors: dict[str, Any] = {}
    stack: list[list[Any]] = []  # [collection node, pending mapping key or None]
    root: yaml.Node | None = None
    resolve: Any = loader.resolve
    while True:
        event: Any = loader.get_event()  # type: ignore[no-untyped-call]
        start: Any = event.start_mark
        end: Any = event.end_mark
        node: Any
        if isinstance(event, (yaml.SequenceEndEvent, yaml.MappingEndEvent)):
            stack.pop()[0].end_mark = end
            if not stack:
                break
            continue
        if isinstance(event, yaml.AliasEvent):
            if event.anchor not in anchors:
                raise yaml.composer.ComposerError(
                    None, None, f"found undefined alias {event.anchor!r}", start
                )
            node = anchors[event.anchor]
        else:
            anchor = event.anchor
            if anchor is not None and anchor in anchors:
                raise yaml.composer.ComposerError(
                    f"found duplicate anchor {anchor!r}; first occurrence",
                    anchors[anchor].start_mark,
                    "second occurrence",
                    start,
                )
            tag = event.tag
            if isinstance(event, yaml.ScalarEvent):
                if tag is None or tag == "!":
                    tag = resolve(yaml.ScalarNode, event.value, event.implicit)
                node = yaml.ScalarNode(tag, event.value, start, end, style=event.style)
            else:
                kind: Any = (
                    yaml.SequenceNode
                    if isinstance(event, yaml.SequenceStartEvent)
                    else yaml.MappingNode
                )
                if tag is None or tag == "!":
                    tag = resolve(kind, None, event.implicit)
                node = kind(tag, [], start, None, flow_style=event.flow_style)
            if anchor is not None:
                anchors[anchor] = node
        if not stack:
            root = node
        else:
            parent = stack[-1]
            if isinstance(parent[0], yaml.SequenceNode):
                parent[0].value.append(node)
            elif parent[1] is None:
                parent[1] = node
            else:
                parent[0].value.append((parent[1], node))
                parent[1] = None
        if isinstance(node, (yaml.SequenceNode, yaml.MappingNode)) and not isinstance(
            event, yaml.AliasEvent
        ):
            stack.append([node, None])
        elif not stack:
            break
    loader.get_event()  # type: ignore[no-untyped-call]  # document end
    if not loader.check_event(yaml.StreamEndEvent):
        extra: Any = loader.get_event()  # type: ignore[no-untyped-call]
        raise yaml.composer.ComposerError(
            "expected a single document in the stream",
            None if root is None else root.start_mark,
            "but found another document",
            extra.start_mark,
        )
    return root


def load_yaml_text(text: str, file: str = "<string>") -> LocatedYaml:
    """Parse one YAML document from ``text`` safely, keeping node positions.

    Nothing on this path recurses per nesting level (events are read with the parser's own
    stack, nodes composed and built with explicit ones), so a deep document is refused by the
    depth limit with its line and column, whichever parser PyYAML bundles.
    """
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
        error = fast_error
    # libyaml refuses some documents by itself (nesting past its own limit of 1,000 flow
    # levels) and words its syntax errors tersely ("did not find expected ','"). The
    # pure-Python parser runs the same shape check (our depth limit, located) and says what
    # it found instead. Outside the except clause: whatever it raises is raised plainly.
    try:
        _check_shape(_PySafeComposer, text, file)
        return _compose(_PySafeComposer, text, file)  # deeper than libyaml goes, but allowed
    except yaml.YAMLError as slow_error:
        error = slow_error
    raise _yaml_error(error, file) from None


def _compose(loader_type: type[yaml.SafeLoader], text: str, file: str) -> LocatedYaml:
    loader: yaml.SafeLoader | None = None
    try:
        loader = loader_type(text)  # the reader checks characters as it is made
        node = _compose_node(loader)
        if node is None:
            return LocatedYaml(data=None, file=file)
        marks: dict[Loc, tuple[int, int]] = {}
        key_marks: dict[Loc, tuple[int, int]] = {}
        try:
            data = _build(node, loader, marks, key_marks, file, limits().max_yaml_depth)
        except RecursionError:
            # PyYAML's merge of '<<' keys recurses once per merged mapping
            error = RobotSpecError("YAML merge keys ('<<') chained too deeply", file=file)
            raise error from None
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
