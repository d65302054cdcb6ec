"""What a limb is: its record, the words that name limbs' links, and checks on the set found.

Split from ``limbs`` (which finds each run's limb): the checks here look at the limbs found
together: four or more short arms from one link are a hand's digits, and a mirrored pair of
short runs beside two legs is a small humanoid's arms.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from robotspec.model.entities import Body, Connection
from robotspec.spec.draft.tree import Segment, Tree, words

__all__ = [
    "ARM_WORDS",
    "FINGER_WORDS",
    "HAND_WORDS",
    "HEAD_WORDS",
    "INNER_WORDS",
    "LEG_WORDS",
    "MAX_HAND_SPAN",
    "WORLD_WORDS",
    "Limb",
    "count",
    "hand_span",
    "is_named",
    "mirrored",
    "named",
    "paired_arms",
    "carried_runs",
    "standing_runs",
    "without_digits",
]

HAND_WORDS = frozenset({"gripper", "hand", "palm", "eef", "jaw", "claw", "effector"})
FINGER_WORDS = frozenset(
    {"finger", "thumb", "knuckle", "phalanx", "index", "middle", "ring", "pinky", "little"}
    | {"fingertip", "digit", "jaw", "claw"}
)
LEG_WORDS = frozenset(
    {"leg", "foot", "feet", "knee", "ankle", "thigh", "calf", "shank", "shin", "sole", "toe"}
    | {"haa", "hfe", "kfe"}  # ANYmal's hip abduction / hip flexion / knee flexion
)
#: Words also recognised inside longer words (``upperleg``, ``lowerleg``).
INNER_WORDS = frozenset({"leg", "foot", "knee", "ankle", "thigh", "calf", "shank"})
ARM_WORDS = frozenset({"arm", "shoulder", "elbow", "wrist", "forearm"})
WORLD_WORDS = frozenset({"world", "map", "odom"})
HEAD_WORDS = frozenset({"head", "neck", "eye", "eyes", "gaze"})
#: A hand reaches no farther than this from where it splits into fingers (m).
MAX_HAND_SPAN = 0.3


@dataclass(frozen=True)
class Limb:
    """An arm or a leg: ``root`` (above its first joint) to ``tip`` (below its last)."""

    kind: str  # "arm" | "leg"
    root: Body
    tip: Body
    hand: Body | None
    joints: frozenset[str]
    segment: Segment
    why: str
    #: The wheel a leg ends on (a continuous joint past its last link), not one of its joints.
    wheel: Connection | None = None
    #: A leg only because it ends on the ground (no name says so): see ``limbs.find_limbs``.
    grounded: bool = False


def hand_span(tree: Tree, body: Body) -> float:
    """How far the subtree of ``body`` reaches from it in the default pose (m)."""
    here = tree.position(body)
    return max(
        (float(np.linalg.norm(tree.position(b) - here)) for b in tree.world.subtree(body)),
        default=0.0,
    )


def named(bodies: tuple[Body, ...], vocabulary: frozenset[str]) -> bool:
    """Whether a link of ``bodies`` has a word of ``vocabulary``."""
    return any(words(b.name) & vocabulary for b in bodies)


def count(bodies: tuple[Body, ...], vocabulary: frozenset[str]) -> int:
    """How many of ``bodies`` are named with a word of ``vocabulary``."""
    return sum(1 for b in bodies if is_named(b.name, vocabulary))


def is_named(name: str, vocabulary: frozenset[str]) -> bool:
    """Whether a name holds one of the words (long words also inside others: ``upperleg``)."""
    low = name.lower()
    return bool(words(name) & vocabulary) or any(w in low for w in vocabulary & INNER_WORDS)


#: Arms from one link that, each within a hand's span, are a hand's digits (a five-finger hand).
MIN_DIGIT_ARMS = 4


def without_digits(tree: Tree, limbs: list[Limb]) -> list[Limb]:
    """``limbs`` less the arms that are a hand's fingers: four or more from one link, each short.

    Why: a hand whose fingers have four joints each (Tesollo's DG-5F) looks like a star of
    arms; no robot carries four arms or more from one link that each stay within a hand's
    span and none of whose links is named as an arm's.
    """
    world = tree.world
    by_start: dict[int, list[Limb]] = {}
    for lb in limbs:
        if lb.kind == "arm":
            by_start.setdefault(lb.segment.start.index, []).append(lb)
    drop: set[int] = set()
    for group in by_start.values():
        if len(group) < MIN_DIGIT_ARMS:
            continue
        firsts = [world.bodies[lb.segment.joints[0].child] for lb in group]
        if all(hand_span(tree, b) <= MAX_HAND_SPAN for b in firsts) and not any(
            named(lb.segment.bodies, ARM_WORDS) for lb in group
        ):
            drop |= {id(lb) for lb in group}
    return [lb for lb in limbs if id(lb) not in drop]


#: How far (m) a mirrored run's first joint may lie from its twin's mirror image.
MIRROR = 0.01


def paired_arms(
    tree: Tree, limbs: list[Limb], make: Callable[[Segment], Limb | None]
) -> list[Limb]:
    """Short arms of a legged robot: mirrored runs of one or two turning joints from its trunk.

    Why: a small humanoid's arms (a shoulder and an elbow, 15 cm: a kid-size soccer robot's; a
    single shoulder on a biped's trunk) are shorter and have fewer joints than an arm is asked
    to have, and may be named after muscles ('bicep'); beside two legs, a mirrored pair of such
    runs from the trunk they hang from, or from a link a waist turns above it, is its arms,
    whatever the names (a head is one run, not a mirrored pair). Without legs such a pair is
    not taken (a social robot's two-joint shoulders and a pair of antennas have one shape:
    only names tell them, ``limbs._limb``). ``make``: the limb a run is, asked as one of such
    a pair.
    """
    legs = [lb for lb in limbs if lb.kind == "leg"]
    if len(legs) < 2 or any(lb.kind == "arm" for lb in limbs):
        return []
    trunks = _trunks(tree, legs)
    used = {lb.segment.bodies[0].index for lb in limbs}
    runs = [
        s
        for s in tree.segments
        if s.start.index in trunks
        and s.bodies[0].index not in used
        and 1 <= len(s.actuated) <= 2
        and len(s.actuated) == len(s.joints)
        and not tree.moving_children(s.end)
        and all(c.type.value == "revolute" for c in s.joints)
    ]
    out: list[Limb] = []
    for i, a in enumerate(runs):
        for b in runs[i + 1 :]:
            if a.start is not b.start or not mirrored(tree, a, b):
                continue
            pair = [make(s) for s in (a, b)]
            if all(lb is not None and lb.kind == "arm" and lb.hand is None for lb in pair):
                out += [lb for lb in pair if lb is not None]
    return out


#: Most joints of a waist between the legs' trunk and the link carrying the arms.
MAX_WAIST_JOINTS = 2


def _trunks(tree: Tree, legs: list[Limb]) -> set[int]:
    """The legs' trunks, and each link a short waist turns above one where runs branch."""
    trunks = {lb.root.index for lb in legs}
    for s in tree.segments:
        if s.start.index in trunks and 1 <= len(s.actuated) <= MAX_WAIST_JOINTS:
            if len(tree.moving_children(s.end)) >= 2:
                trunks.add(s.end.index)
    return trunks


def mirrored(tree: Tree, a: Segment, b: Segment) -> bool:
    """Whether two runs from one link are mirror images across a plane of their start's x-z.

    The plane is the one halfway between the two runs' first joints (a maker's trunk frame need
    not sit on the robot's middle: a root link placed at a hip); every link of one run lies on
    the mirror image of its twin's, to ``MIRROR``, and the first joints lie apart.
    """
    if len(a.bodies) != len(b.bodies):
        return False
    inv = np.linalg.inv(tree.poses[a.start.index])
    pas = [(inv @ tree.poses[x.index])[:3, 3] for x in a.bodies]
    pbs = [(inv @ tree.poses[x.index])[:3, 3] for x in b.bodies]
    mid = (float(pas[0][1]) + float(pbs[0][1])) / 2
    if abs(float(pas[0][1]) - mid) < MIRROR:
        return False
    flip = np.array([1.0, -1.0, 1.0])
    shift = np.array([0.0, 2 * mid, 0.0])
    return all(
        float(np.linalg.norm(pa - (pb * flip + shift))) < MIRROR
        for pa, pb in zip(pas, pbs, strict=True)
    )


def standing_runs(tree: Tree, low: float, clearance: float, drop: float) -> set[int]:
    """The runs that are legs by where they end (by their first link's index).

    Four or more runs from one trunk, each of at least ``MIN_STANDING_JOINTS`` joints (one
    more unless it ends at least ``drop`` below the trunk; no wheel's joint counted), ending
    within ``clearance`` of the ground, in mirrored pairs: each foot has a partner across the
    feet's middle x-z plane (the same x and height, the opposite side, both well off the
    middle; the middle is the feet's, not the trunk frame's, which a maker may place at a hip).

    Why: a small quadruped's legs are shorter than an arm must be (Mini Pupper's, 12 cm) and
    only their names said so; a robot stands on mirrored runs from its trunk that reach the
    ground, which no maker's naming changes. A hand's fingers hanging down are side by side
    or turned about the palm (three, or a thumb against four), never all in mirrored pairs.
    """
    by_start: dict[int, list[Segment]] = {}
    for seg in tree.segments:
        low_end = min(float(tree.position(b)[2]) for b in tree.world.subtree(seg.end))
        # A wheel's joint (continuous: a caster's steer and wheel) is no leg's.
        n = sum(1 for c in seg.actuated if c.type.value != "continuous")
        # Two joints stand only well below the trunk (a hexapod's longer legs lie flat).
        dropped = float(tree.position(seg.start)[2]) - low_end > drop
        if n >= MIN_STANDING_JOINTS + int(not dropped) and low_end - low < clearance:
            by_start.setdefault(seg.start.index, []).append(seg)
    out: set[int] = set()
    for runs in by_start.values():
        if len(runs) < MIN_STANDING_RUNS:
            continue
        inv = np.linalg.inv(tree.poses[runs[0].start.index])
        feet = [(inv @ tree.poses[s.end.index])[:3, 3] for s in runs]
        mid = np.array([0.0, float(np.mean([f[1] for f in feet])), 0.0])
        feet = [f - mid for f in feet]
        paired = all(
            abs(float(f[1])) > MIRROR_OFF
            and any(
                float(np.linalg.norm(g - f * np.array([1.0, -1.0, 1.0]))) < MIRROR_TOLERANCE
                for g in feet
            )
            for f in feet
        )
        if paired:
            out |= {s.bodies[0].index for s in runs}
    return out


#: The fewest joints of a leg found by where it stands (Solo-8's: a hip and a knee).
MIN_STANDING_JOINTS = 2
#: The fewest runs from one trunk that stand a robot up by their shape alone (a quadruped).
MIN_STANDING_RUNS = 4
#: How far off the trunk's middle (m) a foot of a mirrored pair is, at least.
MIRROR_OFF = 0.03
#: How far (m) a foot may lie from its partner's mirror image.
MIRROR_TOLERANCE = 0.01


def carried_runs(tree: Tree) -> list[tuple[Segment, bool]]:
    """The tree's runs, a leg carrying an arm cut in two where its twins end at their feet.

    Each run comes with whether it is carried by a leg (the part past the cut). Why: a
    quadruped with a small arm on each front calf (a loco-manipulator) makes one run of the
    leg's and the arm's joints; its rear legs, from the same trunk with the same first
    joints, end at the link carrying their foot. A run that passes such a link, a foot
    fixed on it too, and goes on with two or more joints, is that leg up to the foot and a
    limb the leg carries past it (not a leg of six joints).
    """
    world = tree.world
    out: list[tuple[Segment, bool]] = []
    by_start: dict[int, list[Segment]] = {}
    for seg in tree.segments:
        by_start.setdefault(seg.start.index, []).append(seg)
    for seg in tree.segments:
        n = _twins_end(tree, seg, by_start[seg.start.index])
        if n is None:
            out.append((seg, False))
            continue
        at = world.bodies[seg.joints[n - 1].child]
        i = seg.bodies.index(at)
        out.append((Segment(seg.start, seg.bodies[: i + 1], seg.joints[:n]), False))
        out.append((Segment(at, seg.bodies[i + 1 :], seg.joints[n:]), True))
    return out


#: The fewest joints past a twin's end that make a limb the leg carries.
MIN_CARRIED_JOINTS = 2


def _twins_end(tree: Tree, seg: Segment, beside: list[Segment]) -> int | None:
    """How many of ``seg``'s joints its shorter twins have, where it carries a foot too.

    ``beside``: the runs from ``seg``'s start (itself among them).
    """
    world = tree.world
    for twin in beside:
        n = len(twin.joints)
        if twin is seg or tree.moving_children(twin.end):
            continue
        if n < 2 or len(seg.joints) - n < MIN_CARRIED_JOINTS:
            continue
        if not all(_same_joint(a, b) for a, b in zip(seg.joints[:n], twin.joints, strict=False)):
            continue
        at = world.bodies[seg.joints[n - 1].child]
        if _foot(tree, at) and _foot(tree, twin.end):
            return n
    return None


def _same_joint(a: Connection, b: Connection) -> bool:
    """Whether two joints are alike: one type, one axis in their own frames."""
    ax, bx = np.asarray(a.axis, dtype=np.float64), np.asarray(b.axis, dtype=np.float64)
    return a.type == b.type and bool(np.allclose(ax, bx, atol=1e-3))


def _foot(tree: Tree, body: Body) -> bool:
    """Whether a fixed leaf with collision geometry (a foot) hangs on ``body``."""
    world = tree.world
    return any(
        (c := world.parent_connection(k)) is not None
        and c.is_fixed
        and not world.child_bodies(k)
        and bool(k.collisions)
        for k in world.child_bodies(body)
    )
