"""What the session holds beside the draft: edits the draft cannot state, the kept SRDF's choices.

Why beside the draft and not in it: the draft (``robotspec.spec.draft``) is what ``init`` decides
about a robot; a spec says more (a frame's rotation, a lidar, the reasons of accepted warnings)
and the SRDF the session keeps until save carries a person's collision pairs and passive joints.
All of it is one frozen value the session's history keeps with the draft, so *undo* takes back a
frame's rotation or a pair toggled by hand exactly as it takes back a chain's tip.

The text edits are made, in order, on the text the draft's changes gave, each through the
round-trip editor (:func:`robotspec.setup.text_edit.apply_ops`), so each changes only its own
lines. An ``accept_warnings`` entry is named by its ``at`` and ``says`` (:class:`Entry`), not
its place in the list, which removing another entry changes.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

import yaml

from robotspec.setup.text_edit import Elsewhere, Op, _Text, apply_ops

__all__ = ["DELETE", "Edit", "Entry", "Extras", "apply_edits"]

#: The kind of an :class:`Edit` that removes its key (or list item).
DELETE = "delete"


@dataclass(frozen=True)
class Entry:
    """An ``accept_warnings`` item, by the warning it accepts."""

    at: str
    says: str


Step = str | int | Entry


@dataclass(frozen=True)
class Edit:
    """Set ``value`` at ``path`` (added where missing), or delete it (``kind`` DELETE)."""

    kind: str
    path: tuple[Step, ...]
    value: Any = None


@dataclass(frozen=True)
class Extras:
    """The session's state besides its draft (see the module's docstring)."""

    #: Text edits the draft cannot state, made in order after the draft's.
    edits: tuple[Edit, ...] = ()
    #: A generated SRDF kept until save: (its name beside the spec, its text).
    srdf: tuple[str, str] | None = None
    #: Collision pairs a person disabled (True) or checks again (False), by hand.
    pairs: tuple[tuple[frozenset[str], bool], ...] = ()
    #: Joints a person made passive (True) or actuated again (False).
    passive: tuple[tuple[str, bool], ...] = field(default=())

    def with_edit(self, edit: Edit) -> Extras:
        """These extras with ``edit`` made last (an earlier edit of the same path dropped)."""
        kept = tuple(e for e in self.edits if e.path != edit.path)
        return replace(self, edits=(*kept, edit))

    def with_pair(self, pair: frozenset[str], disabled: bool) -> Extras:
        """A pair chosen by hand (replacing an earlier choice of it)."""
        kept = tuple(p for p in self.pairs if p[0] != pair)
        return replace(self, pairs=(*kept, (pair, disabled)))

    def with_passive(self, joint: str, passive: bool) -> Extras:
        """A joint made passive or actuated by hand (replacing an earlier choice of it)."""
        kept = tuple(p for p in self.passive if p[0] != joint)
        return replace(self, passive=(*kept, (joint, passive)))


def _resolve(data: Any, path: tuple[Step, ...]) -> tuple[str | int, ...] | None:
    """``path`` with each :class:`Entry` as its index now; None when the text lacks one."""
    out: list[str | int] = []
    node = data
    for step in path:
        if isinstance(step, Entry):
            items = node if isinstance(node, list) else []
            at = next(
                (
                    i
                    for i, x in enumerate(items)
                    if isinstance(x, dict) and x.get("at") == step.at and x.get("says") == step.says
                ),
                None,
            )
            if at is None:
                return None
            out.append(at)
            node = items[at]
            continue
        out.append(step)
        node = node.get(step) if isinstance(node, dict) else None
    return tuple(out)


_MISSING = object()


def _get(data: Any, path: tuple[str | int, ...]) -> Any:
    """The value at ``path``, or ``_MISSING``."""
    node = data
    for step in path:
        if isinstance(node, dict) and step in node:
            node = node[step]
        elif isinstance(node, list) and isinstance(step, int) and 0 <= step < len(node):
            node = node[step]
        else:
            return _MISSING
    return node


def _has(data: Any, path: tuple[str | int, ...]) -> bool:
    return _get(data, path) is not _MISSING


def apply_edits(
    text: str,
    edits: tuple[Edit, ...],
    *,
    elsewhere: Elsewhere = lambda path: None,
    fixed: tuple[str, ...] = (),
) -> str:
    """``text`` with ``edits`` made, in order, each only where its place still is.

    A value set below a part (a frame's rotation) is made only while the part is in the text:
    a frame the draft removed since takes its rotation with it. No edits: ``text`` itself.
    """
    t = _Text(text)  # one text, indexed again after each edit it takes
    for edit in edits:
        root = t.index.root
        data = None if root is None else yaml.SafeLoader("").construct_document(root)
        path = _resolve(data, edit.path)
        if path is None:
            continue
        if edit.kind == DELETE:
            if _has(data, path):
                apply_ops(t, [Op("delete", path)], elsewhere, fixed)
            continue
        if len(path) > 2 and not _has(data, path[:-1]):
            continue
        now = _get(data, path)
        if now == edit.value or (isinstance(edit.value, tuple) and list(edit.value) == now):
            continue  # as written already: its text stays
        apply_ops(t, [Op("set", path, edit.value)], elsewhere, fixed)
    return t.text
