"""A change to a spec written as an edit of its text: only the lines the change needs.

Why edit the text in place rather than re-render it, or round-trip it through ruamel.yaml: a
spec kept in git is read as a diff. Re-rendering the draft (what the assistant did first) turned
a one-number change into a 110-line diff that dropped every comment. ruamel.yaml keeps most of a
file, but re-emits what it holds: indentation it did not detect, the spaces in a flow mapping,
long lines and comments between keys move, so "byte-identical when nothing changed" would be a
hope rather than a fact, and it is one more dependency. Here the file's own text is the
state: PyYAML's safe composer (no tags constructed, aliases not expanded) gives where every node
starts and ends, and a change replaces exactly the characters of the value it changes, deletes
the lines of a key it removes, or inserts lines at the end of the mapping a key is added to.
What nothing changed is never touched, so comments, key order, quoting, flow style and blank
lines survive by construction, and no change at all is the file itself.

Changes come as a diff of two plain data trees (the draft before and after, as the draft's
writer states them): a value set, a key added (with what is missing above it), a key deleted.
A value reached through an alias or a merge key is shared with another place: editing it would
change both, so it is refused, as is a value the file does not hold because another file (a
part of a composed robot, the spec it ``extends``) defines it: :class:`Elsewhere` says where.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import yaml

from robotspec.setup.text_render import (
    TextEditError,
    as_part,
    block_lines,
    flow,
    nested,
    restep,
    style_of,
)

__all__ = ["Elsewhere", "Op", "TextEditError", "diff_ops", "edit_paths", "edit_text", "remove_mark"]

Path_ = tuple[str | int, ...]
#: Where another file defines the longest prefix of a path it defines: (file, line, prefix
#: length), or None when no other file does.
Elsewhere = Callable[[Path_], "tuple[str, int | None, int] | None"]
#: Sections whose entries each file may add to (a composed robot's own chain beside its parts').
_SECTIONS = ("chains", "manipulators", "sensors", "states")

_MARK = "  # DECIDE:"


@dataclass(frozen=True)
class Op:
    """One change: ``set`` a value at ``path`` (added when missing), or ``delete`` the key."""

    kind: str
    path: Path_
    value: Any = None


def diff_ops(old: Any, new: Any, path: Path_ = ()) -> list[Op]:
    """The changes that make ``old`` into ``new``, as deep as both are mappings."""
    if old == new and type(old) is type(new):
        return []
    if isinstance(old, Mapping) and isinstance(new, Mapping):
        ops = [Op("delete", (*path, k)) for k in old if k not in new]
        for k, v in new.items():
            ops += diff_ops(old[k], v, (*path, k)) if k in old else [Op("set", (*path, k), v)]
        return ops
    return [Op("set", path, new)]


# ---------------------------------------------------------------------------- the file's nodes
@dataclass(frozen=True)
class _Entry:
    key: yaml.Node | None
    node: yaml.Node
    parent: yaml.Node | None


class _Index:
    """Every node of the text by path, once (an alias is a place it is reached again)."""

    def __init__(self, text: str) -> None:
        self.root: yaml.Node | None = yaml.compose(text, Loader=yaml.SafeLoader)
        self.entries: dict[Path_, _Entry] = {}
        #: Paths reached through an alias or a merge key: editing them would edit another place.
        self.shared: set[Path_] = set()
        if self.root is None:
            return
        first: dict[int, Path_] = {}  # each node's first path: an alias reaches it again
        todo: list[tuple[Path_, _Entry]] = [((), _Entry(None, self.root, None))]
        while todo:
            path, entry = todo.pop()
            self.entries[path] = entry
            node = entry.node
            if id(node) in first:
                self.shared.update((path, first[id(node)]))  # the anchor's place and the alias's
                continue
            first[id(node)] = path
            if isinstance(node, yaml.MappingNode):
                for k, v in node.value:
                    if k.tag == "tag:yaml.org,2002:merge":
                        self.shared.add(path)  # its keys may come from elsewhere
                        continue
                    todo.append(((*path, self._key(k)), _Entry(k, v, node)))
            elif isinstance(node, yaml.SequenceNode):
                for i, v in enumerate(node.value):
                    todo.append(((*path, i), _Entry(None, v, node)))

    @staticmethod
    def _key(k: yaml.Node) -> str:
        return str(k.value) if isinstance(k, yaml.ScalarNode) else repr(k)

    def through_shared(self, path: Path_) -> bool:
        return any(path[:n] in self.shared for n in range(len(path) + 1))


def _last_line(node: yaml.Node) -> int:
    """The 0-based line of the last character a node's value takes."""
    if isinstance(node, yaml.MappingNode | yaml.SequenceNode) and not node.flow_style:
        items = [v for _, v in node.value] if isinstance(node, yaml.MappingNode) else node.value
        return _last_line(items[-1]) if items else node.start_mark.line
    end = node.end_mark
    return end.line - 1 if end.column == 0 and end.line > node.start_mark.line else end.line


def _eol(text: str, at: int) -> int:
    """Where the line holding ``at`` ends, before its line break (LF or CR LF)."""
    end = text.find("\n", at)
    end = len(text) if end < 0 else end
    return end - 1 if end > at and text[end - 1] == "\r" else end


def _indent_of(node: yaml.MappingNode) -> int:
    return node.value[0][0].start_mark.column if node.value else node.start_mark.column


class _Text:
    """The spec's text being edited, indexed again after each change."""

    def __init__(self, text: str, model: _Index | None = None, model_text: str | None = None):
        self.text = text
        self.index = _Index(text)
        #: How the file nests (measured once: new lines follow the file as it was opened).
        self.style = style_of(self.index.root)
        #: The new data as the drafter writes it: a new part's lines come from there.
        self._model, self._model_text = model, model_text

    def _model_lines(self, path: Path_, value: Any, indent: int) -> list[str] | None:
        """The lines of a new part ``path: value`` as the drafter writes them, at ``indent``.

        Only when they state exactly ``value`` (a section the drafter writes whole may hold
        entries this file does not gain).
        """
        if self._model is None or self._model_text is None or not as_part(path):
            return None
        entry = self._model.entries.get(path)
        if entry is None or entry.key is None:
            return None
        first, last = entry.key.start_mark.line, _last_line(entry.node)
        lines = self._model_text.splitlines()[first : last + 1]
        shift = entry.key.start_mark.column
        if any(line[:shift].strip() for line in lines):
            return None  # not a block of its own
        lines = [line[shift:] for line in lines]
        if yaml.safe_load("\n".join(lines)) != {path[-1]: value}:
            return None
        lines = restep(lines, self.style.step)
        return [" " * indent + line if line.strip() else "" for line in lines]

    def _replace(self, start: int, end: int, new: str) -> None:
        self.text = self.text[:start] + new + self.text[end:]
        self.index = _Index(self.text)

    def _line_start(self, line: int) -> int:
        at = 0
        for _ in range(line):
            nl = self.text.find("\n", at)
            if nl < 0:
                return len(self.text)
            at = nl + 1
        return at

    def _lines(self, first: int, last: int, new: list[str]) -> None:
        """Replace lines ``first..last`` (inclusive; ``last = first - 1``: insert)."""
        start, end = self._line_start(first), self._line_start(last + 1)
        nl = "\r\n" if "\r\n" in self.text else "\n"  # the file's own line breaks
        body = "".join(line + nl for line in new)
        if end == len(self.text) and last >= first and not self.text.endswith("\n"):
            body = body.removesuffix(nl)
        if start == len(self.text) and self.text and not self.text.endswith("\n"):
            body = nl + body
        self._replace(start, end, body)

    def set(self, path: Path_, value: Any) -> None:
        entries = self.index.entries
        cut = len(path)
        while path[:cut] not in entries:
            cut -= 1
        have = path[:cut]
        entry = entries[have]
        node = entry.node
        if cut < len(path):  # add the missing key, with what is missing below it
            for k in reversed(path[cut + 1 :]):
                value = {k: value}
            self._add(have, node, path[cut], value)
            return
        if isinstance(value, Mapping) and isinstance(entry.parent, yaml.MappingNode):
            if entry.key is not None and not entry.parent.flow_style and (value and nested(value)):
                self._as_block(path, entry, value)
                return
        if isinstance(node, yaml.MappingNode | yaml.SequenceNode) and not node.flow_style:
            self._as_block(path, entry, value)
            return
        self._replace(node.start_mark.index, node.end_mark.index, flow(value))

    def _as_block(self, path: Path_, entry: _Entry, value: Any) -> None:
        """A value written as the lines below its key (its key's line and comment kept)."""
        key, node = entry.key, entry.node
        if key is None or not isinstance(entry.parent, yaml.MappingNode):
            raise TextEditError("cannot rewrite a list item as a block", kind="value")
        block = not node.flow_style if isinstance(node, yaml.CollectionNode) else False
        indent = key.start_mark.column
        lines: list[str] = []
        if (
            isinstance(value, Mapping)
            and value
            and len(block_lines(path[-1], value, indent, path[:-1])) > 1
        ):
            step = self.style.step
            for k, v in value.items():  # each entry as the drafter writes it, if it is a part
                lines += self._model_lines((*path, k), v, indent + step) or block_lines(
                    k, v, indent + step, path, step
                )
        if not lines:  # one flow line after all
            if block:  # the block's lines go; the value follows its key
                colon = self.text.find(":", key.end_mark.index)
                end = _eol(self.text, self._line_start(_last_line(node)))
                self._replace(colon + 1, end, " " + flow(value))
            else:
                self._replace(node.start_mark.index, node.end_mark.index, flow(value))
            return
        last = _last_line(node)
        if block:
            self._lines(max(node.start_mark.line, key.start_mark.line + 1), last, lines)
            return
        # A flow value or scalar on the key's line: the line keeps its key and comment.
        line_end = _eol(self.text, node.end_mark.index)
        tail = self.text[node.end_mark.index : line_end]
        start = self.text.rfind(":", key.end_mark.index, node.start_mark.index) + 1
        rest = tail if tail.strip().startswith("#") else ""
        self._replace(start, line_end, rest.rstrip() if rest else "")
        self._lines(last + 1, last, lines)

    def _add(self, have: Path_, node: yaml.Node, key: str | int, value: Any) -> None:
        if isinstance(node, yaml.MappingNode) and not node.flow_style and node.value:
            indent = _indent_of(node)
            lines = self._model_lines((*have, key), value, indent)
            lines = lines or block_lines(key, value, indent, have, self.style.step)
            self._lines(_last_line(node) + 1, _last_line(node), lines)
            return
        if isinstance(node, yaml.MappingNode) or (
            isinstance(node, yaml.ScalarNode) and node.tag == "tag:yaml.org,2002:null"
        ):
            start, end = node.start_mark.index, node.end_mark.index
            current = yaml.safe_load(self.text[start:end]) if end > start else None
            merged = dict(current or {})
            merged[key] = value
            self.set(have, merged)
            return
        where = ".".join(map(str, have)) or "the spec"
        raise TextEditError(f"cannot add '{key}' to {where}: it is not a mapping", kind="value")

    def delete(self, path: Path_) -> None:
        entry = self.index.entries.get(path)
        if entry is None or entry.parent is None:
            return
        parent = entry.parent
        start, end = parent.start_mark.index, parent.end_mark.index
        if isinstance(parent, yaml.SequenceNode):  # a list item: its lines, or the list anew
            if parent.flow_style:
                items = list(yaml.safe_load(self.text[start:end]) or [])
                del items[int(path[-1])]
                self.set(path[:-1], items)
            elif len(parent.value) == 1:
                self.set(path[:-1], [])
            else:
                self._lines(entry.node.start_mark.line, _last_line(entry.node), [])
            return
        if not isinstance(parent, yaml.MappingNode) or entry.key is None:  # pragma: no cover
            raise TextEditError(f"cannot delete {path[-1]!r}: not a key", kind="value")
        if parent.flow_style or len(parent.value) == 1:
            current = dict(yaml.safe_load(self.text[start:end]) or {})
            current.pop(path[-1], None)
            self.set(path[:-1], current)
            return
        self._lines(entry.key.start_mark.line, _last_line(entry.node), [])


def remove_mark(text: str, path: Path_) -> str:
    """``text`` without the ``# DECIDE:`` comment on the line of ``path``'s key."""
    entry = _Index(text).entries.get(path)
    if entry is None:
        return text
    mark = (entry.key or entry.node).start_mark
    start = mark.index - mark.column  # the line's start
    end = _eol(text, start)
    at = text.find(_MARK, start, end)
    return text if at < 0 else text[:at] + text[end:]


def edit_text(
    text: str,
    old: Any,
    new: Any,
    *,
    elsewhere: Elsewhere = lambda path: None,
    fixed: tuple[str, ...] = (),
    written: str | None = None,
) -> str:
    """``text`` with the changes from ``old`` to ``new`` (data as the spec states them) made.

    ``elsewhere(path)``: where a value the text does not hold is defined (another file), which
    refuses the change; ``fixed``: top-level keys this file may not gain or change (a composed
    robot's ``description``); ``written``: ``new`` as the drafter writes it, whose lines (and
    comments: ``# from``, ``# DECIDE:``) a new part takes. No change returns ``text`` itself.
    """
    t = _Text(text, None if written is None else _Index(written), written)
    return apply_ops(t, _kept_entries(t, old, diff_ops(old, new)), elsewhere, fixed)


def _kept_entries(t: _Text, old: Any, ops: list[Op]) -> list[Op]:
    """A section the data lost, dropped entry by entry when the text holds others there.

    Why: the draft states a section's cameras, not a generic sensor the text also holds there;
    its last camera removed must not take the lidar with it.
    """
    data = yaml.safe_load(t.text)
    out: list[Op] = []
    for op in ops:
        key = op.path[0] if op.kind == "delete" and len(op.path) == 1 else None
        here = data.get(key) if isinstance(data, dict) and key in _SECTIONS else None
        gone = old.get(key) if isinstance(old, Mapping) and key is not None else None
        if isinstance(here, Mapping) and isinstance(gone, Mapping) and set(here) - set(gone):
            out += [Op("delete", (op.path[0], k)) for k in gone]
        else:
            out.append(op)
    return out


def edit_paths(
    text: str,
    ops: list[Op],
    *,
    elsewhere: Elsewhere = lambda path: None,
    fixed: tuple[str, ...] = (),
) -> str:
    """``text`` with ``ops`` made, each at its spec path (a list item by its index)."""
    return apply_ops(_Text(text), ops, elsewhere, fixed)


def apply_ops(t: _Text, ops: list[Op], elsewhere: Elsewhere, fixed: tuple[str, ...]) -> str:
    """Make ``ops`` in ``t``; refused where the value is shared or defined in another file."""
    for op in ops:
        where = ".".join(map(str, op.path))
        if op.path and op.path[0] in fixed:
            raise TextEditError(
                f"{where}: a composed robot's description is its parts; edit the parts' files",
                kind="part",
                name=where,
            )
        if t.index.through_shared(op.path):
            raise TextEditError(
                f"{where} is written through a YAML alias or merge key, shared with another "
                "place; edit it in a text editor",
                kind="part",
                name=where,
            )
        have = len(op.path)
        while op.path[:have] not in t.index.entries:
            have -= 1
        other = elsewhere(op.path) if have < len(op.path) else None
        if other is not None and other[2] > have and (other[2] > 1 or op.path[0] not in _SECTIONS):
            file, line, _ = other
            at = f"{file}:{line}" if line is not None else file
            raise TextEditError(
                f"{where} is defined in {at}, not in this spec; robotspec setup edits only "
                "the spec it opened: change it in that file",
                kind="part",
                name=where,
            )
        if op.kind == "delete":
            t.delete(op.path)
        else:
            t.set(op.path, op.value)
    return t.text
