"""One pass from a YAML parser's events to plain data, with the place of every value.

Why our own pass instead of PyYAML's composer and constructor:

* **one parse, bounded work.** The parser's events are read once; the depth and the size with
  aliases expanded are checked on them as they come, before anything recurses (PyYAML's
  composers recurse once per nesting level: 50,000 ``[`` kill the process).
* **aliases are shared, not copied.** An alias is the anchored value itself (as
  ``yaml.safe_load`` gives it), so nine aliases of nine aliases of ... cost the text they are
  written in; the expanded size is only *counted*, against ``ROBOTSPEC_MAX_YAML_NODES`` and
  ``ROBOTSPEC_MAX_YAML_ALIAS_NODES``, for the work later readers of the data do (validation
  walks every value an alias stands for).
* **merge keys as YAML 1.1 states them** (https://yaml.org/type/merge.html): ``<<: *base`` or
  ``<<: [*a, *b]`` inserts the keys the mapping does not give itself, the earlier source winning
  (PyYAML 6.0.4 lets the later win for keys longer than one character: yaml/pyyaml#953); an
  explicit key may follow a merge and override it; a key written twice is still an error.
* **recursion is an error**: an alias inside the collection it names (``c: &c {<<: *c}``,
  ``a: &a [*a]``) is refused at its line, where ``safe_load`` builds a cycle or an empty map.
"""

from __future__ import annotations

from typing import Any

import yaml

from robotspec.errors import RobotSpecError
from robotspec.files.limits import Limits, env_name
from robotspec.files.yaml_errors import nesting_error
from robotspec.files.yaml_marks import Loc, Marks, pack, unpack

__all__ = ["MAX_INT_BITS", "MERGE_SLOT", "Document", "read_document"]

#: Integers wider than this many bits are refused (a spec or RobotInfo never needs more; a
#: 5,000-digit integer would otherwise stop Python's int() with an internal error).
MAX_INT_BITS = 64

#: The path step under which a mapping's ``<<`` value is recorded (a key is always a string, so
#: an integer in a mapping's place can never clash with one).
MERGE_SLOT = -1

_TAG = "tag:yaml.org,2002:"
_STR, _MAP, _SEQ = f"{_TAG}str", f"{_TAG}map", f"{_TAG}seq"
_MERGE_TAG, _VALUE_TAG = f"{_TAG}merge", f"{_TAG}value"
_SCALAR_TAGS = frozenset(f"{_TAG}{t}" for t in ("str", "int", "float", "bool", "null", "timestamp"))
_NO_KEY = object()  # a mapping waits for its next key
_MERGE = object()  # the key just read is '<<'
_NO_MERGE = object()
_SKIPPED = object()  # a key read without building (a shape check)


class _Anchor:
    """What an ``&name`` stands for.

    The value, where it is written, its size with aliases expanded, and whether it is still
    open (an alias to it now would be recursive).
    """

    __slots__ = ("line", "open", "path", "scalar", "size", "tag", "value")

    def __init__(self, value: Any, path: Loc | None, line: int, *, scalar: bool, tag: str) -> None:
        self.value = value
        self.path = path
        self.line = line
        self.scalar = scalar
        self.tag = tag
        self.size = 1
        self.open = not scalar


class _Frame:
    """One open collection.

    Its value, path, anchor, size so far and, for a mapping, the key waiting for its value and
    the ``<<`` value.
    """

    __slots__ = ("anchor", "count", "is_map", "key", "key_path", "merge", "path", "value")

    def __init__(self, value: Any, path: Loc, anchor: str | None, *, is_map: bool) -> None:
        self.value = value
        self.path = path
        self.anchor = anchor
        self.is_map = is_map
        self.count = 1
        self.key: Any = _NO_KEY
        self.key_path: Loc = ()
        self.merge: Any = _NO_MERGE


class Document:
    """A document's data and marks (``None`` data for an empty stream)."""

    __slots__ = ("data", "key_marks", "marks")

    def __init__(self, data: Any, marks: Marks, key_marks: Marks) -> None:
        self.data = data
        self.marks = marks
        self.key_marks = key_marks


def read_document(
    loader: yaml.SafeLoader, text: str, file: str, cap: Limits, *, build: bool = True
) -> Document | None:
    """Read the single document of ``loader``'s stream (made from ``text``); None if empty.

    ``build=False`` checks only the shape (depth, expanded size, recursion), for texts another
    loader reads afterwards (xacro's ``load_yaml``, with its unit tags).
    """
    reader = _Reader(loader, file, cap, build=build)
    try:
        return reader.read()
    except yaml.MarkedYAMLError as exc:
        if exc.problem != "exceeded maximum nesting depth":
            raise
        # libyaml looks ahead up to 1,024 characters for a key, so a dense run of '[' reaches
        # its own limit of 1,000 levels before the events reach the depth cap.
        start = reader.last.end_mark.index if reader.last is not None else 0
        depth = len(reader.stack)
        raise nesting_error(text, start, depth, cap.max_yaml_depth, file, exc) from None


class _Reader:
    def __init__(self, loader: yaml.SafeLoader, file: str, cap: Limits, *, build: bool) -> None:
        self.loader = loader
        self.last: Any = None  # the last event read
        self.file = file
        self.cap = cap
        self.build = build
        self.stack: list[_Frame] = []
        self.alias_nodes = 0  # nodes the aliases read so far stand for
        self.anchors: dict[str, _Anchor] = {}
        self.root: Any = None
        self.marks: dict[Loc, int] = {}  # packed (line, column) of each value
        self.key_marks: dict[Loc, int] = {}  # ... and of each mapping key
        self.aliases: dict[Loc, Loc] = {}
        self.merges: dict[Loc, list[tuple[Loc, dict[str, Any]]]] = {}
        self.resolve: Any = loader.resolve
        self.constructors: Any = loader.yaml_constructors

    # ------------------------------------------------------------------ the event loop
    def read(self) -> Document | None:
        get: Any = self.loader.get_event
        get()  # stream start
        if self.loader.check_event(yaml.StreamEndEvent):
            return None
        get()  # document start
        while True:
            event: Any = get()
            self.last = event
            kind = type(event)
            if kind is yaml.ScalarEvent:
                self._scalar(event)
            elif kind is yaml.AliasEvent:
                self._alias(event)
            elif kind is yaml.MappingStartEvent or kind is yaml.SequenceStartEvent:
                self._start(event, is_map=kind is yaml.MappingStartEvent)
            else:  # a collection's end
                self._end(event)
            if not self.stack:
                break
        get()  # document end
        if not self.loader.check_event(yaml.StreamEndEvent):
            extra: Any = get()
            raise yaml.composer.ComposerError(
                "expected a single document in the stream",
                None,
                "but found another document",
                extra.start_mark,
            )
        marks = Marks(self.marks, self.marks, self.aliases, self.merges)
        key_marks = Marks(self.key_marks, self.marks, self.aliases, self.merges)
        return Document(self.root, marks, key_marks)

    # ------------------------------------------------------------------ events
    def _scalar(self, event: Any) -> None:
        line, col = event.start_mark.line + 1, event.start_mark.column + 1
        tag = event.tag
        if tag is None or tag == "!":
            tag = self.resolve(yaml.ScalarNode, event.value, event.implicit)
        frame = self.stack[-1] if self.stack else None
        value: Any = None
        path: Loc | None = None
        if frame is not None and frame.is_map and frame.key is _NO_KEY:
            if self.build:
                value = self._key(frame, event, tag, line, col)
            else:
                _skip_key(frame)
        elif self.build:
            value = self._construct(event, tag, line, col)
            path = self._place(value, line, col)
        else:
            self._skip_value()
        if event.anchor is not None:
            self._anchor(event, _Anchor(value, path, line, scalar=True, tag=tag))
        self._count(1, event)

    def _alias(self, event: Any) -> None:
        line, col = event.start_mark.line + 1, event.start_mark.column + 1
        anchor = self.anchors.get(event.anchor)
        if anchor is None:
            raise yaml.composer.ComposerError(
                None, None, f"found undefined alias {event.anchor!r}", event.start_mark
            )
        if anchor.open:
            raise self._error(
                f"recursive alias '*{event.anchor}': it stands for a collection it is part of "
                f"(anchored '&{event.anchor}' at line {anchor.line})",
                line,
                col,
            )
        self.alias_nodes += anchor.size
        if self.alias_nodes > self.cap.max_yaml_alias_nodes:
            raise self._error(
                f"YAML aliases stand for too many nodes (more than "
                f"{self.cap.max_yaml_alias_nodes} in all; set "
                f"{env_name('max_yaml_alias_nodes')} to raise it)",
                line,
                col,
            )
        frame = self.stack[-1] if self.stack else None
        if frame is not None and frame.is_map and frame.key is _NO_KEY:
            if not anchor.scalar:
                raise self._error("mapping keys must be plain scalars", line, col)
            if self.build:
                self._set_key(frame, anchor.value, anchor.tag, line, col)
            else:
                _skip_key(frame)
        elif self.build:
            path = self._place(anchor.value, line, col)
            if anchor.path is not None:
                self.aliases[path] = anchor.path
        else:
            self._skip_value()
        self._count(anchor.size, event)

    def _start(self, event: Any, *, is_map: bool) -> None:
        line, col = event.start_mark.line + 1, event.start_mark.column + 1
        frame = self.stack[-1] if self.stack else None
        if frame is not None and frame.is_map and frame.key is _NO_KEY:
            raise self._error("mapping keys must be plain scalars", line, col)
        if len(self.stack) >= self.cap.max_yaml_depth:
            raise self._error(
                f"YAML nested too deeply (more than {self.cap.max_yaml_depth} levels; "
                f"set {env_name('max_yaml_depth')} to raise it)",
                line,
                col,
            )
        value: Any = None
        path: Loc = ()
        if self.build:
            tag = event.tag
            node_kind = yaml.MappingNode if is_map else yaml.SequenceNode
            if tag is None or tag == "!":
                tag = self.resolve(node_kind, None, event.implicit)
            if tag != (_MAP if is_map else _SEQ):
                raise self._unsupported(tag, line, col)
            value = {} if is_map else []
            path = self._place(value, line, col)
        else:
            self._skip_value()
        self.stack.append(_Frame(value, path, event.anchor, is_map=is_map))
        if event.anchor is not None:
            anchored = path if self.build else None
            self._anchor(event, _Anchor(value, anchored, line, scalar=False, tag=""))

    def _end(self, event: Any) -> None:
        frame = self.stack.pop()
        if self.build and frame.is_map and frame.merge is not _NO_MERGE:
            self._merge(frame)
        if frame.anchor is not None:
            anchor = self.anchors[frame.anchor]
            anchor.open = False
            anchor.size = frame.count
        self._count(frame.count, event)

    # ------------------------------------------------------------------ helpers
    def _anchor(self, event: Any, anchor: _Anchor) -> None:
        name = event.anchor
        if name in self.anchors:
            first = self.anchors[name]
            raise yaml.composer.ComposerError(
                f"found duplicate anchor {name!r}; first occurrence (line {first.line})",
                None,
                "second occurrence",
                event.start_mark,
            )
        self.anchors[name] = anchor

    def _count(self, nodes: int, event: Any) -> None:
        """Add ``nodes`` to the innermost open collection; refuse it past the node cap."""
        if not self.stack:
            total = nodes
        else:
            top = self.stack[-1]
            top.count += nodes
            total = top.count
        if total > self.cap.max_yaml_nodes:
            mark = event.start_mark
            raise self._error(
                f"YAML document too large with its aliases expanded (more than "
                f"{self.cap.max_yaml_nodes} nodes; set {env_name('max_yaml_nodes')} to raise it)",
                mark.line + 1,
                mark.column + 1,
            )

    def _place(self, value: Any, line: int, col: int) -> Loc:
        """Put a value into the open collection (or make it the root); its path."""
        if not self.stack:
            self.root = value
            path: Loc = ()
        else:
            frame = self.stack[-1]
            if not frame.is_map:
                path = (*frame.path, len(frame.value))
                frame.value.append(value)
            elif frame.key is _MERGE:
                frame.merge = value
                path = frame.key_path
            else:
                frame.value[frame.key] = value
                path = frame.key_path
            frame.key = _NO_KEY
        self.marks[path] = pack(line, col)
        return path

    def _skip_value(self) -> None:
        """A value read without building (a shape check): the mapping waits for a key again."""
        if self.stack and self.stack[-1].is_map:
            self.stack[-1].key = _NO_KEY

    def _key(self, frame: _Frame, event: Any, tag: str, line: int, col: int) -> Any:
        """Read a mapping key; the value it stands for (for an anchor on it)."""
        if tag == _MERGE_TAG or tag == _VALUE_TAG:
            value: Any = event.value
        else:
            value = self._construct(event, tag, line, col)
        self._set_key(frame, value, tag, line, col)
        return value

    def _set_key(self, frame: _Frame, value: Any, tag: str, line: int, col: int) -> None:
        if tag == _MERGE_TAG:
            if frame.merge is not _NO_MERGE:
                raise self._error(
                    "duplicate key '<<' (merge several mappings with '<<: [*a, *b]')",
                    line,
                    col,
                    name="<<",
                )
            frame.key = _MERGE
            frame.key_path = (*frame.path, MERGE_SLOT)
            self.key_marks[frame.key_path] = pack(line, col)
            return
        if value is None or not isinstance(value, (str, int, float, bool)):
            raise self._error("mapping keys must be plain scalars", line, col)
        key = value if isinstance(value, str) else str(value)
        if key in frame.value:
            raise self._error(f"duplicate key '{key}'", line, col, name=key)
        frame.key = key
        frame.key_path = (*frame.path, key)
        self.key_marks[frame.key_path] = pack(line, col)

    def _construct(self, event: Any, tag: str, line: int, col: int) -> Any:
        """The value of a scalar.

        A tag other than plain data, or a value its tag cannot hold, is a located error.
        """
        text = event.value
        if tag == _STR:
            return text
        if tag not in _SCALAR_TAGS:
            if tag == _MERGE_TAG:
                raise self._error(
                    "'<<' is YAML's merge key and only stands as a key (quote it for the text)",
                    line,
                    col,
                )
            raise self._unsupported(tag, line, col)
        if tag.endswith(":int") and len(text) > 40:  # before int() works on it
            raise self._error(
                f"integer '{_clip(text)}' is too large (more than {MAX_INT_BITS} bits)", line, col
            )
        node = yaml.ScalarNode(tag, text, event.start_mark, event.end_mark, style=event.style)
        try:
            value = self.constructors[tag](self.loader, node)
        except (ValueError, OverflowError, TypeError, KeyError, yaml.YAMLError) as exc:
            reason = str(exc).split("\n")[0]
            kind = tag.rsplit(":", 1)[-1]
            raise self._error(f"invalid {kind} '{_clip(text)}': {reason}", line, col) from None
        if isinstance(value, int) and not isinstance(value, bool):
            if value.bit_length() > MAX_INT_BITS:
                raise self._error(
                    f"integer '{_clip(text)}' is too large (more than {MAX_INT_BITS} bits)",
                    line,
                    col,
                )
        return value

    def _merge(self, frame: _Frame) -> None:
        """Give the mapping the keys of its ``<<`` sources it does not give itself."""
        slot = (*frame.path, MERGE_SLOT)
        value = frame.merge
        if isinstance(value, dict):
            sources = [(slot, value)]
        elif isinstance(value, list):
            sources = []
            for i, item in enumerate(value):
                if not isinstance(item, dict):
                    line, col = unpack(self.marks[(*slot, i)])
                    raise self._error(
                        f"the merge key '<<' takes mappings, but item {i} is {_kind(item)}",
                        line,
                        col,
                    )
                sources.append(((*slot, i), item))
        else:
            line, col = unpack(self.marks[slot])
            raise self._error(
                f"the merge key '<<' takes a mapping or a list of mappings, not {_kind(value)}",
                line,
                col,
            )
        merged: dict[str, Any] = {}
        for _, source in sources:
            for key, item in source.items():
                if key not in merged:
                    merged[key] = item
        merged.update(frame.value)
        frame.value.clear()
        frame.value.update(merged)
        self.merges[frame.path] = sources

    def _unsupported(self, tag: str, line: int, col: int) -> RobotSpecError:
        return RobotSpecError(
            f"unsupported YAML tag '{tag}' (only plain YAML data is read)",
            file=self.file,
            line=line,
            column=col,
            name=tag,
        )

    def _error(self, message: str, line: int, col: int, name: str | None = None) -> RobotSpecError:
        return RobotSpecError(message, file=self.file, line=line, column=col, name=name)


def _skip_key(frame: _Frame) -> None:
    frame.key = _SKIPPED


def _kind(value: Any) -> str:
    if isinstance(value, list):
        return "a list"
    if value is None:
        return "null"
    return f"the scalar {_clip(str(value))!r}"


def _clip(text: str, keep: int = 40) -> str:
    return text if len(text) <= keep else f"{text[:keep]}... ({len(text)} characters)"
