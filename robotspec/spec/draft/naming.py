"""Names in the robot's own words: its SRDF's, else ``left_arm``, ``right_gripper``, ...

Sides come from where limbs are in the default pose (seen from the root, x forward and z up: left
is +y); when the pose cannot tell (shoulders at one point), from the limbs' own link names.
"""

from __future__ import annotations

import re

import numpy as np

from robotspec.spec.draft.limbs import LEG_WORDS, Limb, is_named
from robotspec.spec.draft.tree import Tree, words

__all__ = [
    "facing",
    "join",
    "leg_code",
    "named_side",
    "ordered_words",
    "role_by_name",
    "side_labels",
    "side_of",
    "unique",
]


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


_UP = np.array([0.0, 0.0, 1.0])


def facing(tree: Tree, limbs: list[Limb]) -> tuple[tuple[float, float, float], str | None]:
    """The direction the robot faces, and why when it is not +x (REP 103's default).

    Evidence: limbs named left and right (``l_arm``, ``LegR``) lie to the robot's left and
    right; their offset, left minus right, is the robot's left (``up x forward``), so the robot
    faces ``left x up``. Snapped to the root's axes; +x unless the names say otherwise
    (ARMAR-4 and Stretch are modelled facing -y).
    """
    ahead = _ahead_by_codes(tree, limbs)
    if ahead is not None:
        return ahead
    lateral = np.zeros(3)
    for kind in ("arm", "leg"):
        named: dict[str, list[np.ndarray]] = {"left": [], "right": []}
        for lb in limbs:
            side = named_side(lb)
            if lb.kind == kind and side is not None:
                named[side].append(_mean_position(tree, lb))
        if named["left"] and named["right"]:
            lateral += np.mean(named["left"], axis=0) - np.mean(named["right"], axis=0)
    lateral[2] = 0.0
    norm = float(np.linalg.norm(lateral))
    if norm < 0.02:
        return _looking(tree, limbs)
    axis = int(np.argmax(np.abs(lateral)))
    if abs(lateral[axis]) < 0.8 * norm:
        return (1.0, 0.0, 0.0), None  # diagonal: no clear evidence
    left = np.zeros(3)
    left[axis] = 1.0 if lateral[axis] > 0 else -1.0
    fwd = np.cross(left, _UP)
    out = (float(fwd[0]) + 0.0, float(fwd[1]) + 0.0, float(fwd[2]) + 0.0)
    if out == (1.0, 0.0, 0.0):
        return out, None
    names = "xyz"
    sign = "+" if left[axis] > 0 else "-"
    return out, f"its left and right limbs lie along {sign}{names[axis]}: it faces this way"


def leg_code(limb: Limb) -> tuple[str | None, str | None]:
    """Fore or hind, and left or right, from a leg's code (``FL_``, ``lh_``, ``RR_``, ``BL_``).

    Codes put the end first (Solo's ``HL``, Unitree's ``RL``: rear left, a quadruped's ``BL``)
    or the side first (ANYmal's and HyQ's ``LH``).
    """
    first = ordered_words(limb.segment.bodies[0].name)[:1]
    code = first[0] if first else ""
    if len(code) != 2 or limb.kind != "leg":
        return None, None
    end, side = code[0], code[1]
    if end in "lr" and side in "fh":
        end, side = side, end
    if end not in "fhbr" or side not in "lr":
        return None, None
    return ("fore" if end == "f" else "hind"), ("left" if side == "l" else "right")


def _ahead_by_codes(
    tree: Tree, limbs: list[Limb]
) -> tuple[tuple[float, float, float], str | None] | None:
    """The facing from legs coded fore and hind: from the hind legs towards the fore ones."""
    ends: dict[str, list[np.ndarray]] = {"fore": [], "hind": []}
    for lb in limbs:
        end, _ = leg_code(lb)
        if end is not None:
            ends[end].append(_mean_position(tree, lb))
    if not (ends["fore"] and ends["hind"]):
        return None
    toward = np.mean(ends["fore"], axis=0) - np.mean(ends["hind"], axis=0)
    toward[2] = 0.0
    norm = float(np.linalg.norm(toward))
    axis = int(np.argmax(np.abs(toward)))
    if norm < 0.02 or abs(toward[axis]) < 0.8 * norm:
        return None
    out = [0.0, 0.0, 0.0]
    out[axis] = 1.0 if toward[axis] > 0 else -1.0
    if out == [1.0, 0.0, 0.0]:
        return (1.0, 0.0, 0.0), None
    where = f"{'+' if out[axis] > 0 else '-'}{'xyz'[axis]}"
    return (out[0], out[1], out[2]), f"its fore legs lie along {where} of its hind legs"


def _looking(tree: Tree, limbs: list[Limb]) -> tuple[tuple[float, float, float], str | None]:
    """The facing from the optical frames on the body and head (not on a limb), if they agree.

    A robot looks where it faces; only frames optical by their rotation count (a body frame's
    axis is a guess of its own), and only when every such camera looks, in the default pose,
    mostly horizontally along one axis of the root.
    """
    from robotspec.spec.draft.sensors import find_cameras

    world = tree.world
    tops = [world.bodies[lb.segment.joints[0].child] for lb in limbs if lb.segment.joints]
    seen: set[tuple[int, int]] = set()
    for cam in find_cameras(tree):
        if not cam.optical or any(world.is_ancestor(t, cam.body) for t in tops):
            continue
        view = tree.pose(cam.body)[:3, 2]
        view = np.array([view[0], view[1], 0.0])
        norm = float(np.linalg.norm(view))
        axis = int(np.argmax(np.abs(view)))
        if norm < 0.5 or abs(view[axis]) < 0.8 * norm:
            return (1.0, 0.0, 0.0), None
        seen.add((axis, 1 if view[axis] > 0 else -1))
    if len(seen) != 1:
        return (1.0, 0.0, 0.0), None
    ((axis, sign),) = seen
    out = [0.0, 0.0, 0.0]
    out[axis] = float(sign)
    if out == [1.0, 0.0, 0.0]:
        return (1.0, 0.0, 0.0), None
    where = f"{'+' if sign > 0 else '-'}{'xyz'[axis]}"
    return (out[0], out[1], out[2]), f"its head's cameras look along {where}: it faces this way"


def side_labels(
    tree: Tree, limbs: list[Limb], forward: tuple[float, float, float] = (1.0, 0.0, 0.0)
) -> tuple[list[str], bool]:
    """Labels by position in the default pose, and whether they came from names instead.

    ``left``/``right`` for two limbs (left: the robot's left, ``up x forward``, +y of the root
    for a robot facing +x, as the compiler decides), ``front``/``hind`` too for four legs; when
    the pose cannot tell two limbs apart, ``left``/``right`` from their links' names (and the
    draft then declares ``side:``); else numbers.
    """
    if len(limbs) == 1:
        return [""], False
    ahead = np.asarray(forward, dtype=np.float64)
    left = np.cross(_UP, ahead)
    pos = [_mean_position(tree, lb) for lb in limbs]
    ys = [float(p @ left) for p in pos]
    if len(limbs) == 2 and abs(ys[0] - ys[1]) >= SIDE_TOLERANCE:
        return (["left", "right"] if ys[0] > ys[1] else ["right", "left"]), False
    if len(limbs) == 4:
        xs = [float(p @ ahead) for p in pos]
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
        for w in ordered_words(b.name):
            if w in ("left", "l"):
                return "left"
            if w in ("right", "r"):
                return "right"
    return None


def ordered_words(name: str) -> list[str]:
    """The words of a name in order (``LegL_Hip1`` -> leg, l, hip, 1; ``l_wrist`` -> l, wrist)."""
    spaced = re.sub(r"(?<=[a-z])(?=[A-Z])", "_", name)
    return [w for w in re.split(r"[^a-z0-9]+|(?<=[a-z])(?=[0-9])", spaced.lower()) if w]


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
