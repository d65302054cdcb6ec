"""New lines of a spec written the way the file already writes its own.

Why a file's own style: a line the assistant adds to a spec kept in git is read in a diff beside
the lines around it. A file nested by four spaces, or whose lists' dashes sit at their key's
column, would otherwise gain lines nested by two and indented lists, a style no one there wrote.
So the text's own steps are measured first (the most common step between a key and the keys
below it, and between a key and its block list's dashes), and every new line is written with
them; a file with neither keeps the drafter's (two spaces, lists indented).
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import yaml

from robotspec.errors import RobotSpecError
from robotspec.spec.draft.render import scalar

__all__ = ["Style", "TextEditError", "block_lines", "flow", "nested", "style_of"]

Path_ = tuple[str | int, ...]


class TextEditError(RobotSpecError):
    """A change the text of the spec cannot take (shared, defined in another file)."""


@dataclass(frozen=True)
class Style:
    """How a file nests: the spaces per mapping level, and where a block list's dashes sit."""

    #: Columns a nested mapping's keys sit right of their parent key.
    step: int = 2
    #: Columns a block list's dashes sit right of their key (0: a dash at its key's column).
    dash: int = 2


def _most(counts: Counter[int], default: int) -> int:
    """The most common value (the smaller on a tie), or ``default`` when there is none."""
    if not counts:
        return default
    top = max(counts.values())
    return min(v for v, n in counts.items() if n == top)


def style_of(root: yaml.Node | None) -> Style:
    """The steps the file's own block mappings and block lists use."""
    steps: Counter[int] = Counter()
    dashes: Counter[int] = Counter()
    todo = [root] if root is not None else []
    seen: set[int] = set()
    while todo:
        node = todo.pop()
        if id(node) in seen:
            continue
        seen.add(id(node))
        if isinstance(node, yaml.MappingNode):
            for k, v in node.value:
                todo.append(v)
                if getattr(v, "flow_style", True) or not v.value:
                    continue
                if isinstance(v, yaml.MappingNode) and v.start_mark.line > k.start_mark.line:
                    steps[v.value[0][0].start_mark.column - k.start_mark.column] += 1
                elif isinstance(v, yaml.SequenceNode) and v.start_mark.line > k.start_mark.line:
                    dashes[v.start_mark.column - k.start_mark.column] += 1
        elif isinstance(node, yaml.SequenceNode):
            todo.extend(node.value)
    step = _most(Counter({s: n for s, n in steps.items() if s > 0}), 2)
    return Style(step, _most(Counter({d: n for d, n in dashes.items() if d >= 0}), step))


def number(v: float) -> str:
    """A number as YAML reads it back (a NaN or an infinity refused)."""
    if not math.isfinite(v):
        raise TextEditError(f"not a finite number: {v}", kind="value")
    return str(v) if isinstance(v, int) else repr(float(v))


def flow(v: Any) -> str:
    """``v`` as one flow-style YAML value."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if v is None:
        return "null"
    if isinstance(v, int | float):
        return number(v)
    if isinstance(v, str):
        return scalar(v)
    if isinstance(v, Mapping):
        return "{" + ", ".join(f"{flow(str(k))}: {flow(x)}" for k, x in v.items()) + "}"
    if isinstance(v, list | tuple):
        return "[" + ", ".join(flow(x) for x in v) + "]"
    raise TextEditError(f"cannot write a {type(v).__name__} in a spec", kind="value")


def nested(v: Any) -> bool:
    """Whether a mapping holds mappings of mappings (written as a block, not one flow line)."""
    return isinstance(v, Mapping) and any(
        isinstance(x, Mapping) and any(isinstance(y, Mapping) for y in x.values())
        for x in v.values()
    )


def as_part(path: Path_) -> bool:
    """Whether the drafter writes the mapping at ``path`` as a block (a part, a section)."""
    if len(path) == 1:
        return path[0] != "drive"
    if path[-1] in ("states", "fingers", "frames"):
        return True  # one line per entry
    return len(path) == 2 and path[0] in ("chains", "manipulators", "sensors")


def block_lines(key: Any, v: Any, indent: int, path: Path_ = (), step: int = 2) -> list[str]:
    """``key: value`` at ``indent``: parts and nested mappings as blocks, leaves as one line."""
    pad = " " * indent
    here = (*path, key)
    if isinstance(v, Mapping) and v and (nested(v) or as_part(here) or len(flow(v)) > 90):
        out = [f"{pad}{flow(str(key))}:"]
        for k, x in v.items():
            out += block_lines(k, x, indent + step, here, step)
        return out
    return [f"{pad}{flow(str(key))}: {flow(v)}"]


def restep(lines: list[str], step: int) -> list[str]:
    """Lines the drafter nested by two spaces, nested by ``step`` instead."""
    if step == 2:
        return lines
    out = []
    for line in lines:
        body = line.lstrip(" ")
        lead = len(line) - len(body)
        out.append(" " * (lead // 2 * step + lead % 2) + body if body else line)
    return out
