"""Safe YAML loading that remembers where every value came from.

Why: every user-facing error must name the file and line of the offending YAML node, but pydantic
only knows a location path (``("chains", 0, "tip")``). :func:`load_yaml` reads the document's
events from PyYAML's *safe* parser (no arbitrary tags, no object construction), builds plain
Python data from them (:mod:`robotspec.files.yaml_build`), and records where each value is
written under its path (:mod:`robotspec.files.yaml_marks`), so a pydantic error location maps
back to ``file:line:column``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from robotspec.errors import RobotSpecError
from robotspec.files.limits import Limits, env_name, limits
from robotspec.files.reading import read_bounded
from robotspec.files.yaml_build import MAX_INT_BITS, Document, read_document
from robotspec.files.yaml_errors import parse_error, unicode_error

__all__ = [
    "MAX_INT_BITS",
    "LocatedYaml",
    "check_yaml_shape",
    "load_yaml",
    "load_yaml_text",
]

Loc = tuple[str | int, ...]


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


# libyaml's loader when PyYAML was built with it (ten times faster; same marks), else pure Python.
_BaseLoader: type[yaml.SafeLoader] = getattr(yaml, "CSafeLoader", yaml.SafeLoader)

#: libyaml refuses nesting past 1,000 levels by itself; a depth cap raised that far is read with
#: the Python parser (slower, but it goes as deep as the cap allows).
_LIBYAML_DEPTH = 1_000


class _SafeComposer(_BaseLoader):  # type: ignore[valid-type,misc]
    """The parser that reads YAML here: events only, no Python objects built from tags."""


class _PySafeComposer(yaml.SafeLoader):
    """The pure-Python parser, for depth caps beyond libyaml's own nesting limit."""


def _parser(cap: Limits) -> type[yaml.SafeLoader]:
    if cap.max_yaml_depth >= _LIBYAML_DEPTH - 10:
        return _PySafeComposer
    return _SafeComposer


def _read(text: str, file: str, *, build: bool) -> Document | None:
    """Parse ``text`` once: a located error for anything wrong with it, whichever the parser."""
    cap = limits()
    loader: yaml.SafeLoader | None = None
    try:
        loader = _parser(cap)(text)  # the reader checks characters as it is made
        return read_document(loader, text, file, cap, build=build)
    except yaml.YAMLError as exc:
        raise parse_error(exc, text, file) from None
    except UnicodeEncodeError as exc:  # libyaml takes UTF-8: a lone surrogate cannot be
        raise unicode_error(exc, text, file) from None
    finally:
        if loader is not None:
            loader.dispose()


def load_yaml_text(text: str, file: str = "<string>") -> LocatedYaml:
    """Parse one YAML document from ``text`` safely, keeping node positions.

    One pass over the parser's events builds the data (aliases shared, merge keys applied) and
    checks the depth and the expanded size as it goes, so time and memory follow the text,
    whichever parser PyYAML bundles; nothing on the way recurses per nesting level.
    """
    cap = limits().max_yaml_bytes
    if len(text) > cap or len(text.encode("utf-8", errors="replace")) > cap:
        raise RobotSpecError(
            f"YAML document larger than {cap} bytes (set {env_name('max_yaml_bytes')} to raise it)",
            file=file,
            kind="size",
        )
    document = _read(text, file, build=True)
    if document is None:
        return LocatedYaml(data=None, file=file)
    return LocatedYaml(
        data=document.data, file=file, marks=document.marks, key_marks=document.key_marks
    )


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
    """Refuse a YAML text too deep, too large with aliases expanded, or recursive.

    For texts another loader reads afterwards (xacro's ``load_yaml``, with its unit tags): the
    shape is checked on the parser's events before that loader recurses through them.
    """
    _read(text, file, build=False)
