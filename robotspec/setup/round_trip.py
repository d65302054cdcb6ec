"""The text a spec opened for editing saves as: the file as read, with the session's changes.

Why a diff of drafts applied to the text, not the draft written anew: the assistant edits a
:class:`~robotspec.spec.draft.Draft` (parts, questions, states), but a person's spec holds more
than a draft does (comments, ``# FIX:`` notes, ``extends:``, ``parts:``, generic sensors,
rotated frames, settings the page does not edit). The draft the file was read as and the draft
now are both stated as plain data by the draft's own writer; what differs between the two is all
that changed, and only that is written into the file's text (:mod:`robotspec.setup.text_edit`).
What the draft cannot hold is in neither, so it is never touched. An answered ``# DECIDE:``
question removes its mark and nothing else. With no change, the text is the file, byte for byte.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import yaml

from robotspec.files.yamlio import LocatedYaml
from robotspec.setup.text_edit import edit_text, remove_mark
from robotspec.spec.draft.model import Draft
from robotspec.spec.draft.render import render_draft

__all__ = ["SpecText", "data_of", "open_marks"]

Path_ = tuple[str | int, ...]


def _top_paths(text: str) -> set[Path_]:
    """The part paths (``("chains", "arm")``, ``("torso",)``) the text itself writes."""
    data = yaml.safe_load(text)
    out: set[Path_] = set()
    if isinstance(data, dict):
        for key, value in data.items():
            out.add((str(key),))
            if isinstance(value, dict):
                out.update((str(key), str(k)) for k in value)
    return out


def data_of(draft: Draft, presets: tuple[str, ...] = ()) -> Any:
    """The draft as the spec's data, stated by the draft's writer (parsed back, safely)."""
    return yaml.safe_load(render_draft(draft, presets=presets))


def open_marks(d: Draft) -> frozenset[Path_]:
    """The spec paths whose line carries an open ``# DECIDE:`` mark, by the draft's reasons."""
    out: set[Path_] = set()
    if d.drive is not None and d.drive.decide:
        out.add(("drive",))
    if d.forward is not None and d.forward_decide != "":
        out.add(("forward",))
    for key in ("torso", "neck"):
        part = getattr(d, key)
        if part is not None and part.decide:
            out.add((key,))
    out.update(("chains", c.name) for c in d.chains if c.decide)
    out.update(("manipulators", m.name) for m in d.manipulators if m.decide)
    for cam in d.cameras:
        if cam.decide:
            out.add(("sensors", cam.name))
        if cam.preset is None and cam.field_of_view is None:
            out.add(("sensors", cam.name, "field_of_view"))
    out.update(("description", "frames", f.name) for f in d.frames if f.reason)
    return frozenset(out)


@dataclass(frozen=True)
class SpecText:
    """A spec file as read, the draft it was read as, and the files it takes values from."""

    text: str
    file: str
    base: Any
    base_marks: frozenset[Path_]
    #: The other files whose values the spec takes (parts of a composed robot, bases it
    #: extends), each with where its values are written, by the spec's (renamed) paths.
    others: tuple[LocatedYaml, ...] = field(default=(), repr=False)
    composed: bool = False

    @classmethod
    def read(
        cls,
        text: str,
        file: str,
        draft: Draft,
        presets: tuple[str, ...] = (),
        *,
        others: Sequence[LocatedYaml] = (),
        composed: bool = False,
    ) -> SpecText:
        """The spec ``file`` (its ``text``) as read into ``draft``."""
        return cls(text, file, data_of(draft, presets), open_marks(draft), tuple(others), composed)

    def elsewhere(self, path: Path_) -> tuple[str, int | None, int] | None:
        """The other file defining the longest prefix of ``path``: (file, line, prefix length)."""
        for n in range(len(path), 0, -1):
            for doc in self.others:
                if path[:n] in doc.marks:
                    line, _ = doc.marks[path[:n]]
                    return doc.file, line, n
        return None

    def defined_in(self, part: str) -> str | None:
        """``file:line`` of the other file defining ``part`` (``chains.X``), if not this one."""
        path = tuple(part.split(".", 1))
        if path[0] == "drive" or path in _top_paths(self.text):
            return None
        other = self.elsewhere(path)
        if other is None or other[2] < len(path):
            return None
        file, line, _ = other
        return f"{file}:{line}" if line is not None else file

    def text_of(self, draft: Draft, presets: tuple[str, ...] = ()) -> str:
        """The file's text with every change from the draft as read to ``draft``.

        Raises :class:`~robotspec.setup.text_edit.TextEditError` for a change the file cannot
        take (a value another file defines, one shared through an alias).
        """
        written = render_draft(draft, presets=presets)
        text = edit_text(
            self.text,
            self.base,
            yaml.safe_load(written),
            elsewhere=self.elsewhere,
            fixed=("description",) if self.composed else (),
            written=written,
        )
        for path in sorted(self.base_marks - open_marks(draft), key=str):
            text = remove_mark(text, path)
        return text
