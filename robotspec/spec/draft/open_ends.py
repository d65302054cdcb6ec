"""Questions about a drafted chain's end that nothing drafted covers (issue 30, item 3).

Why: a wrong item is worth little to a user unless something in the draft points at it. A
drafted arm always gets a manipulator, and a head carries its camera; but a chain the tree
could not name (``kind: chain``: a head without a known camera, an arm too short or too odd to
call one) gets neither, and what is fixed at its end (a bare frame at a head's front, a tool
flange, a camera with a generic name) is then named by nothing: the chain's own mark asks
about its joints, not about what it carries. One question per such chain names the frames
fixed at its end: a camera? a tool frame?

A drafted neck carries its camera, but a head often carries more than one: a bare frame fixed
on the head, away from every drafted camera's device (more than 10 cm, or on another link), is
what a second camera with a generic name looks like, and nothing else names it.

Only an end nothing moves below counts (joints moving there belong to a drafted part or are
asked about by ``unassigned``), and only when something besides the chain's last link is
there: an end with nothing fixed to it has nothing to ask about.
"""

from __future__ import annotations

import re
from typing import TYPE_CHECKING

import numpy as np

from robotspec.model.entities import Body
from robotspec.spec.draft.model import DraftQuestion
from robotspec.spec.draft.sensors import IMAGE_KINDS, NOT_CAMERA_WORDS
from robotspec.spec.draft.stated_cameras import DEVICE_SPAN
from robotspec.spec.draft.tree import words

if TYPE_CHECKING:
    from robotspec.spec.draft.build import Drafter

__all__ = ["open_end_questions"]

#: The chain roles whose end may carry a tool or a camera nothing drafted covers.
_ROLES = frozenset({"arm", "chain"})
#: Frames named in a question's text at most (all are in its subject).
_SHOWN = 3


def _fixed_below(d: Drafter, end: Body) -> list[Body]:
    """The bodies fixed below ``end`` (fixed or mimic joints), but another sensor's frames.

    A frame named as a sensor that is no camera (an IMU, a laser), or that a Gazebo sensor of
    such a kind sees from, is accounted for: neither a camera nor a tool frame.
    """
    world, kinds = d.world, d.facts.sensor_links
    out: list[Body] = []
    level = [end]
    while level:
        level = [
            k
            for b in level
            for k in world.child_bodies(b)
            if (c := world.parent_connection(k)) is not None and (c.is_fixed or c.is_mimic)
        ]
        out += [
            b
            for b in level
            if not (words(b.name) | set(re.split(r"[^a-z0-9]+", b.name.lower()))) & NOT_CAMERA_WORDS
            and (b.name not in kinds or any(k in kinds[b.name] for k in IMAGE_KINDS))
        ]
    return out


def open_end_questions(d: Drafter) -> list[DraftQuestion]:
    """One question per drafted chain whose end carries frames no drafted part accounts for."""
    world, draft = d.world, d.draft
    cams = [world.get_body_by_name(c.body) for c in draft.cameras if world.has_body(c.body)]
    roots = [world.get_body_by_name(m.root) for m in draft.manipulators if world.has_body(m.root)]
    tools = {m.tool_frame for m in draft.manipulators}
    out: list[DraftQuestion] = []
    for chain in draft.chains:
        if chain.role not in _ROLES or not world.has_body(chain.tip):
            continue
        end = d.tree.rigid_root(world.get_body_by_name(chain.tip))
        if any(world.is_ancestor(end, r) or world.is_ancestor(r, end) for r in roots):
            continue  # a manipulator at (or around) its end: its own marks ask
        if any(world.is_ancestor(end, k) for k in cams):
            continue  # it carries a drafted camera (a head): the camera's mark asks
        if any(
            (c := world.parent_connection(b)) is not None and c.is_active and not c.is_mimic
            for b in world.subtree(end)
            if b is not end
        ):
            continue  # joints move below its end: a part, or ``unassigned``'s question
        fixed = [b for b in _fixed_below(d, end) if b.name not in tools]
        if not fixed:
            continue
        names = [end.name, *(b.name for b in fixed)]
        shown = ", ".join(b.name for b in fixed[:_SHOWN]) + (" ..." if len(fixed) > _SHOWN else "")
        text = (
            f"nothing is drafted at the end of chain '{chain.name}' ({end.name}), which carries "
            f"{shown}: a camera? a tool frame?"
        )
        out.append(DraftQuestion("manipulators", text, frozenset(), frozenset(names)))
    return out + _head_questions(d, cams)


def _head_questions(d: Drafter, cams: list[Body]) -> list[DraftQuestion]:
    """Bare frames on a drafted neck's head, away from every drafted camera: a second camera?"""
    world, tree, neck = d.world, d.tree, d.draft.neck
    if neck is None or not world.has_body(neck.tip):
        return []
    head = d.tree.rigid_root(world.get_body_by_name(neck.tip))
    seen = [tree.position(k) for k in cams]
    bare = [
        b
        for b in _fixed_below(d, head)
        if not world.child_bodies(b)
        and not b.visuals
        and not b.collisions
        and all(float(np.linalg.norm(tree.position(b) - p)) > DEVICE_SPAN for p in seen)
    ]
    if not bare:
        return []
    names = [b.name for b in bare]
    shown = ", ".join(names[:_SHOWN]) + (" ..." if len(names) > _SHOWN else "")
    text = (
        f"the head ({head.name}) carries {shown}, away from its drafted cameras: "
        "another camera? a marker?"
    )
    return [DraftQuestion("sensors", text, frozenset(), frozenset(names))]
