"""Accepting a warning with its reason: an ``accept_warnings`` entry written as new lines.

Why the assistant writes the entry itself, and exactly as the compiler matches it: a warning
that is right for this robot (a group_state without a group in the robot's own SRDF) otherwise
keeps a spec from ever validating clean, and a hand-typed entry whose ``says`` misses one word
accepts nothing. The entry's ``at`` is the warning's spec path and ``says`` its message after
that path, the two things ``Diagnostics.accept`` compares. Why as lines added to the text (and
never a re-rendered list): the spec is read as a diff; an entry is three new lines at the end of
the file's ``accept_warnings`` list (or a new list at the end of the file), nothing else moves.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import yaml

from robotspec.diagnostics import loc_text
from robotspec.errors import closest_names
from robotspec.setup.edits import SetupError
from robotspec.setup.text_edit import TextEditError, _last_line
from robotspec.setup.text_render import style_of
from robotspec.setup.validation import Problem, Validation
from robotspec.spec.draft.model import Draft
from robotspec.spec.draft.render import scalar

if TYPE_CHECKING:
    from robotspec.setup.session import Snapshot

__all__ = ["AcceptEdits", "Acceptance", "acceptance_of", "with_accepted"]


@dataclass(frozen=True)
class Acceptance:
    """One warning as an ``accept_warnings`` entry would name it: its path and its words."""

    at: str
    says: str

    @property
    def label(self) -> str:
        """How the page lists it (one line)."""
        return f"{self.at}: {self.says}"


def acceptance_of(p: Problem) -> Acceptance | None:
    """The entry that accepts warning ``p`` (None: it points at no spec path, or is an error)."""
    if p.severity != "warning" or not p.location:
        return None
    at = loc_text(p.location)
    says = p.message[len(at) + 2 :] if p.message.startswith(f"{at}: ") else p.message
    return Acceptance(at, says.strip())


def acceptances(v: Validation) -> tuple[Acceptance, ...]:
    """Every warning of ``v`` that an entry can accept, in validate's order, once each."""
    out = (acceptance_of(p) for p in v.warnings)
    return tuple(dict.fromkeys(a for a in out if a is not None))


def _lines(entries: Sequence[tuple[str, str, str]], indent: int) -> list[str]:
    pad = " " * indent
    out: list[str] = []
    for at, says, because in entries:
        out += [f"{pad}- at: {scalar(at)}", f"{pad}  says: {scalar(says)}"]
        out.append(f"{pad}  because: {scalar(because)}")
    return out


def with_accepted(text: str, entries: Sequence[tuple[str, str, str]]) -> str:
    """``text`` with ``entries`` added at the end of its ``accept_warnings`` list, as new lines.

    No entries: ``text`` itself (so opening and saving a spec stays byte-identical).
    """
    if not entries:
        return text
    newline = "\r\n" if "\r\n" in text else "\n"
    lines = text.splitlines(keepends=True)
    if lines and not lines[-1].endswith("\n"):
        lines[-1] += newline
    root = yaml.compose(text, Loader=yaml.SafeLoader)
    node = None
    if isinstance(root, yaml.MappingNode):
        node = next((v for k, v in root.value if k.value == "accept_warnings"), None)
    if node is None:  # a new list at the end of the file, its dashes where the file has them
        new = ["accept_warnings:", *_lines(entries, style_of(root).dash)]
        return "".join(lines) + "".join(line + newline for line in new)
    if isinstance(node, yaml.SequenceNode) and not node.flow_style and node.value:
        at = _last_line(node) + 1
        new = _lines(entries, node.start_mark.column)
        return "".join([*lines[:at], *(line + newline for line in new), *lines[at:]])
    raise TextEditError(
        f"accept_warnings (line {node.start_mark.line + 1}) is not a list of entries the "
        "assistant can add to (write it as a block list: '- at: ...')",
        kind="value",
    )


class AcceptEdits:
    """The session's edit that accepts a warning (mixed into ``SetupSession``)."""

    _snapshot: Snapshot

    def edit(self, change: Callable[[Draft], None]) -> Validation:
        """Apply ``change`` as the session's state (:meth:`SetupSession.edit`)."""
        raise NotImplementedError

    def accept_warning(self, warning: str, because: str) -> Validation:
        """Accept the warning the page lists as ``warning`` (``at: says``), for ``because``.

        Refused: an empty reason (an acceptance is a reviewed exception: its reason is the
        point), or a warning validate does not print now (closest listed ones named).
        """
        reason = " ".join(because.split())
        if not reason:
            raise SetupError(
                "give the reason this warning does not apply to this robot: accept_warnings "
                "keeps it beside the entry, for whoever reads the spec next",
                kind="value",
            )
        listed = {a.label: a for a in acceptances(self._snapshot.validation)}
        if warning not in listed:
            raise SetupError(
                f"no warning '{warning}' to accept now",
                kind="warning",
                name=warning,
                suggestions=closest_names(warning, listed),
            )
        a = listed[warning]

        def change(d: Draft) -> None:
            d.accepted.append((a.at, a.says, reason))

        return self.edit(change)
