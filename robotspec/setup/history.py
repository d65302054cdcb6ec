"""Undo and redo of the assistant's changes, each said in words from the lines it changed.

Why described from the text: every change (whichever tab, whichever control made it) ends as
lines of the spec that would be saved, so the lines it changed say what it did in the spec's
own words ("line 12: mid: 0.15 -> mid: 0.2"), the same for a slider, a pick or an answer.
Why a failed action stops undo once: a person who pressed a button that failed and then
presses undo means that action, which changed nothing; undoing the change before it without
a word once undid a good edit. So the first undo after a failure says so and undoes nothing.
"""

from __future__ import annotations

import difflib
from dataclasses import dataclass, field
from typing import Generic, TypeVar

__all__ = ["History", "describe"]

T = TypeVar("T")

#: How many changes undo reaches back.
DEPTH = 50


def _short(line: str, width: int = 60) -> str:
    line = line.strip()
    return line if len(line) <= width else line[: width - 1] + "…"


def describe(before: str, after: str) -> str:
    """What changed between two texts of the spec, in one line of words."""
    old, new = before.splitlines(), after.splitlines()
    removed: list[tuple[int, str]] = []
    added: list[tuple[int, str]] = []
    for tag, i1, i2, j1, j2 in difflib.SequenceMatcher(a=old, b=new, autojunk=False).get_opcodes():
        if tag != "equal":
            removed += [(i + 1, old[i]) for i in range(i1, i2)]
            added += [(j + 1, new[j]) for j in range(j1, j2)]
    if not removed and not added:
        return "no change to the text"
    more = max(len(removed), len(added)) - 1
    tail = f" (and {more} more line{'s' if more > 1 else ''})" if more > 0 else ""
    if removed and added:
        return f"line {added[0][0]}: {_short(removed[0][1])} -> {_short(added[0][1])}{tail}"
    if added:
        return f"line {added[0][0]} added: {_short(added[0][1])}{tail}"
    return f"line {removed[0][0]} removed: {_short(removed[0][1])}{tail}"


@dataclass(frozen=True)
class Step(Generic[T]):
    """One change: the state before and after it, and what it did."""

    before: T
    after: T
    what: str


@dataclass
class History(Generic[T]):
    """The changes undo and redo walk; the session holds it under its lock."""

    undo_steps: list[Step[T]] = field(default_factory=list)
    redo_steps: list[Step[T]] = field(default_factory=list)
    #: The action that failed last, until the next undo or change.
    failed: str | None = None

    def record(self, before: T, after: T, what: str) -> None:
        """A change made: undo reaches it, and nothing undone before can be redone."""
        self.undo_steps = [*self.undo_steps[-DEPTH + 1 :], Step(before, after, what)]
        self.redo_steps = []
        self.failed = None

    def fail(self, what: str) -> None:
        """An action that changed nothing because it failed."""
        self.failed = what

    def undo(self) -> tuple[Step[T] | None, str]:
        """The step to go back to (None: stay) and what to say."""
        if self.failed is not None:
            what, self.failed = self.failed, None
            nxt = f"; undo again undoes {self.undo_steps[-1].what}" if self.undo_steps else ""
            return None, f"nothing undone: the last action ({what}) failed and changed nothing{nxt}"
        if not self.undo_steps:
            return None, "nothing to undo"
        step = self.undo_steps.pop()
        self.redo_steps.append(step)
        return step, f"undone: {step.what}"

    def redo(self) -> tuple[Step[T] | None, str]:
        """The step to make again (None: stay) and what to say."""
        self.failed = None
        if not self.redo_steps:
            return None, "nothing to redo"
        step = self.redo_steps.pop()
        self.undo_steps.append(step)
        return step, f"redone: {step.what}"
