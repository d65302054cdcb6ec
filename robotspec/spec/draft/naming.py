"""Names in the robot's own words: its SRDF's, else ``left_arm``, ``right_gripper``, ...

Sides come from where limbs are in the default pose (seen from the root, x forward and z up: left
is +y); when the pose cannot tell (shoulders at one point), from the limbs' own link names.
"""

from __future__ import annotations

import numpy as np

from robotspec.spec.draft.limbs import LEG_WORDS, Limb, is_named
from robotspec.spec.draft.tree import Tree, words

__all__ = ["join", "named_side", "role_by_name", "side_labels", "side_of", "unique"]


def unique(name: str, taken: set[str]) -> str:
    """``name``, or ``name_2``, ``name_3``... if taken; the result is taken from then on."""
    out, i = name, 2
    while out in taken:
        out = f"{name}_{i}"
        i += 1
    taken.add(out)
    return out


#: Two limbs whose mean lateral positions differ by less than this (m) have no side by position
#: (the compiler's rule for ``left_arm`` / ``right_arm``, robotspec.semantic.sides).
SIDE_TOLERANCE = 1e-6


def _mean_position(tree: Tree, limb: Limb) -> np.ndarray:
    """Mean position of a limb's bodies below its root, in the root's frame, default pose."""
    bodies = tree.world.compute_chain_of_kinematic_structure_entities(limb.root, limb.tip)[1:]
    mean: np.ndarray = np.mean([tree.position(b) for b in bodies or [limb.tip]], axis=0)
    return mean


def side_labels(tree: Tree, limbs: list[Limb]) -> tuple[list[str], bool]:
    """Labels by position in the default pose, and whether they came from names instead.

    ``left``/``right`` for two limbs (left: +y of the root, as the compiler decides), ``front``/
    ``hind`` too for four legs; when the pose cannot tell two limbs apart, ``left``/``right`` from
    their links' names (and the draft then declares ``side:``); else numbers.
    """
    if len(limbs) == 1:
        return [""], False
    pos = [_mean_position(tree, lb) for lb in limbs]
    ys = [float(p[1]) for p in pos]
    if len(limbs) == 2 and abs(ys[0] - ys[1]) >= SIDE_TOLERANCE:
        return (["left", "right"] if ys[0] > ys[1] else ["right", "left"]), False
    if len(limbs) == 4:
        xs = [float(p[0]) for p in pos]
        mx, my = sum(xs) / 4, sum(ys) / 4
        labels = [
            ("front" if x > mx else "hind") + ("_left" if y > my else "_right")
            for x, y in zip(xs, ys, strict=True)
        ]
        if len(set(labels)) == 4:
            return labels, False
    if len(limbs) == 2:  # no side by position: the robot's own words, if it has them
        sides = [named_side(lb) for lb in limbs]
        if sorted(s for s in sides if s) == ["left", "right"]:
            return [s or "" for s in sides], True
    order = sorted(range(len(limbs)), key=lambda i: -ys[i])
    return [str(order.index(i) + 1) for i in range(len(limbs))], False


def role_by_name(group: str) -> str:
    """An SRDF group the tree found no limb for: a leg or an arm if its name says so."""
    if is_named(group, LEG_WORDS):
        return "leg"
    return "arm" if "arm" in words(group) else "chain"


def named_side(limb: Limb) -> str | None:
    """``left`` or ``right`` when the limb's links say so (``left_hand``, ``l_wrist``)."""
    for b in limb.segment.bodies:
        w = words(b.name)
        first = next(iter(sorted(w)), "")
        if "left" in w or b.name.lower().startswith("l_") or first == "l":
            return "left"
        if "right" in w or b.name.lower().startswith("r_") or first == "r":
            return "right"
    return None


def join(label: str, noun: str) -> str:
    """``left`` + ``arm`` -> ``left_arm``; ``2`` + ``arm`` -> ``arm_2``."""
    if not label:
        return noun
    return f"{noun}_{label}" if label.isdigit() else f"{label}_{noun}"


def side_of(name: str) -> str:
    """The side prefix a chain's name carries (``left_arm`` -> ``left``, ``r_arm`` -> ``r``)."""
    for noun in ("_arm", "_leg"):
        if name.endswith(noun):
            return name[: -len(noun)]
    for noun in ("arm_", "leg_"):
        if name.startswith(noun):
            return name[len(noun) :]
    return ""
