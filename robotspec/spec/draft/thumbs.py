"""Which of a hand's fingers is the thumb, told by the joints where names do not say.

Why: a thumb named ``thumb`` is found by its name (``fingers.find_fingers``); with the names
gone (numbered links, another maker's words), what is left is structure. A hand's fingers are
often copies of one part (Leap's three, Allegro's): the same joints at the same offsets,
turning about the same axes within the same ranges, only placed apart on the palm; the thumb is
the one branch that is no copy of them. A guess all the same: the draft marks it.
"""

from __future__ import annotations

import numpy as np

from robotspec.model.entities import Body
from robotspec.model.world import World

__all__ = ["ALIKE", "odd_by_shape"]

#: Offsets (m), rotation entries, axes and ranges this close make two joints copies.
ALIKE = 1e-4


def odd_by_shape(world: World, branches: list[Body]) -> int | None:
    """The one branch that is no copy of the others, which are all copies of each other."""
    if len(branches) < 3:
        return None
    sigs = [_signature(world, k) for k in branches]
    alike = [[_same(a, b) for b in sigs] for a in sigs]
    for i in range(len(branches)):
        others = [j for j in range(len(branches)) if j != i]
        if any(alike[i][j] for j in others):
            continue
        if all(alike[a][b] for a in others for b in others):
            return i
    return None


def _signature(world: World, branch: Body) -> tuple[tuple[str, ...], np.ndarray]:
    """The kinds of ``branch``'s joints and their numbers, the first joint's place left out.

    Every joint below the branch's first: its type, origin (offset and rotation), axis and
    range; the first joint: its type, axis and range only (where a finger sits on the palm and
    how it is turned there is what differs between copies).
    """
    kinds: list[str] = []
    values: list[float] = []
    for b in world.subtree(branch):
        c = world.parent_connection(b)
        if c is None:
            continue
        kinds.append(c.type.value)
        if b is not branch:
            values += [float(v) for v in c.origin[:3, :].ravel()]
        values += [float(v) for v in c.axis]
        for d in c.dofs:
            dof = world.degrees_of_freedom[d]
            values += [dof.lower, dof.upper] if dof.is_bounded else [0.0, 0.0]
        if c.is_mimic and c.mimic is not None:
            values += [c.mimic.multiplier, c.mimic.offset]
    return tuple(kinds), np.asarray(values, dtype=np.float64)


def _same(a: tuple[tuple[str, ...], np.ndarray], b: tuple[tuple[str, ...], np.ndarray]) -> bool:
    return a[0] == b[0] and a[1].shape == b[1].shape and bool(np.allclose(a[1], b[1], atol=ALIKE))
