"""A draft's DECIDE marks as questions: the guess, the alternatives, the reason.

Why from the draft's data and not its text: every guess of ``robotspec init`` keeps its reason in
the draft (``decide``); the writer only turns it into a comment. A question's first choice keeps
the guess; answering removes the mark, choosing an alternative also applies it.
"""

from __future__ import annotations

from dataclasses import dataclass

from robotspec.spec.draft.model import Draft

__all__ = ["FACINGS", "FORWARDS", "KEEP", "REMOVE", "Question", "questions_of"]

#: The choice that keeps the guess; always a question's first.
KEEP = "keep the guess"
#: The choice that drops the part.
REMOVE = "remove it"
#: A tool's front-facing axis (in its tool frame) by name.
FACINGS: dict[str, tuple[float, float, float]] = {
    "tool faces +x": (1.0, 0.0, 0.0),
    "tool faces +z": (0.0, 0.0, 1.0),
    "tool faces +y": (0.0, 1.0, 0.0),
    "tool faces -x": (-1.0, 0.0, 0.0),
    "tool faces -y": (0.0, -1.0, 0.0),
    "tool faces -z": (0.0, 0.0, -1.0),
}
DRIVES = ("fixed", "omni", "differential", "floating")
#: The robot's facing (``forward:``, in its root link's frame) by name; +x is the default.
FORWARDS: dict[str, tuple[float, float, float]] = {
    "faces +x": (1.0, 0.0, 0.0),
    "faces -x": (-1.0, 0.0, 0.0),
    "faces +y": (0.0, 1.0, 0.0),
    "faces -y": (0.0, -1.0, 0.0),
}
ROLES = {"arm": "an arm", "leg": "a leg", "chain": "another chain (a lift, a tail)"}
OPTICAL = "an optical frame: looks along +z"
BODY_FRAME = "a body frame: looks along +x"


@dataclass(frozen=True)
class Question:
    """One open decision: which part, what was guessed, what else it could be, and why."""

    id: str
    part: str
    guess: str
    choices: tuple[str, ...]
    reason: str

    @property
    def alternatives(self) -> tuple[str, ...]:
        """The choices other than keeping the guess."""
        return self.choices[1:]


def _chain_questions(draft: Draft) -> list[Question]:
    out: list[Question] = []
    for key, c in (("torso", draft.torso), ("neck", draft.neck)):
        if c is not None and c.decide:
            out.append(
                Question(key, key, f"{c.root} -> {c.tip}", (KEEP, REMOVE), "; ".join(c.decide))
            )
    for c in draft.chains:
        if c.decide:
            roles = tuple(f"make it {w}" for r, w in ROLES.items() if r != c.role)
            part = f"chains.{c.name}"
            guess = f"{ROLES.get(c.role, c.role)} {c.root} -> {c.tip}"
            out.append(Question(part, part, guess, (KEEP, *roles, REMOVE), "; ".join(c.decide)))
    return out


def questions_of(draft: Draft, presets: tuple[str, ...] = ()) -> tuple[Question, ...]:
    """Every DECIDE mark the draft would write, in the order the spec lists its parts."""
    out: list[Question] = []
    for f in draft.frames:
        if f.reason:
            part = f"frames.{f.name}"
            guess = f"a frame on {f.parent} at {list(f.xyz)}"
            out.append(Question(part, part, guess, (KEEP, REMOVE), f.reason))
    if draft.forward is not None and draft.forward_decide != "":
        guess = f"faces {list(draft.forward)} in {draft.root}'s frame"
        reason = draft.forward_decide or "the robot's facing"
        out.append(Question("forward", "forward", guess, (KEEP, *FORWARDS), reason))
    d = draft.drive
    if d is not None and d.decide:
        others = tuple(f"drive: {t}" for t in DRIVES if t != d.type)
        out.append(Question("drive", "drive", f"drive: {d.type}", (KEEP, *others), d.decide))
    out += _chain_questions(draft)
    for m in draft.manipulators:
        if m.decide:
            part = f"manipulators.{m.name}"
            kind = (
                "a parallel gripper"
                if m.is_gripper
                else f"a hand of {len(m.fingers) + 1} fingers"
                if m.is_hand
                else "a generic tool"
            )
            extra = ("make it generic",) if m.is_gripper or m.is_hand else ()
            choices = (KEEP, *FACINGS, *extra, REMOVE)
            guess = f"{kind}, tool frame {m.tool_frame}"
            out.append(Question(part, part, guess, choices, "; ".join(m.decide)))
    for cam in draft.cameras:
        part = f"sensors.{cam.name}"
        if cam.decide:
            other = BODY_FRAME if cam.optical else OPTICAL
            guess = OPTICAL if cam.optical else BODY_FRAME
            models: tuple[str, ...] = ()
            if cam.preset is not None:  # a model guessed from the frame's name
                guess += f", preset {cam.preset}"
                models = tuple(f"preset: {p}" for p in presets if p != cam.preset)
            choices = (KEEP, other, *models, REMOVE)
            out.append(Question(part, part, guess, choices, "; ".join(cam.decide)))
        if cam.preset is None and cam.field_of_view is None:
            choices = (KEEP, *(f"preset: {p}" for p in presets))
            out.append(
                Question(
                    f"{part}.field_of_view",
                    part,
                    "placeholder angles 1.0 x 0.75 rad",
                    choices,
                    "the camera's angles or a preset",
                )
            )
    return tuple(out)
