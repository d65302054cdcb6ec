"""Arms, legs and hands from the kinematic tree alone.

An arm is a serial run of at least three actuated joints from a branching point of the tree to a
hand (or to the end of the run); a leg is the same run ending on the ground. What is not a limb:
fingers (short runs inside a hand, or runs whose links are named as fingers), and runs shorter
than a forearm, pan/tilt runs pointing cameras (necks). The hand starts at the first link named
as a hand (``gripper``, ``hand``, ``palm``) below which only fingers or jaws move, or where the
run splits into fingers; the joint turning it is the arm's last, the joints below it the hand's.
"""

from __future__ import annotations

from robotspec.model.entities import Body, Connection
from robotspec.model.world import World
from robotspec.spec.draft.ends import chain_end
from robotspec.spec.draft.head_runs import eyes, head_on_top, pan_tilt
from robotspec.spec.draft.jaws import one_jaw
from robotspec.spec.draft.limb_kinds import (
    ARM_WORDS,
    FINGER_WORDS,
    HAND_WORDS,
    HEAD_WORDS,
    INNER_WORDS,
    LEG_WORDS,
    MAX_HAND_SPAN,
    WORLD_WORDS,
    Limb,
    carried_runs,
    count,
    hand_span,
    is_named,
    named,
    paired_arms,
    standing_runs,
    without_digits,
)
from robotspec.spec.draft.tree import Segment, Tree, words

__all__ = [
    "ARM_WORDS",
    "FINGER_WORDS",
    "HAND_WORDS",
    "HEAD_WORDS",
    "INNER_WORDS",
    "LEG_WORDS",
    "MAX_HAND_SPAN",
    "Limb",
    "beside_branch",
    "chain_end",
    "group_end",
    "eyes",
    "find_limbs",
    "hand_cut",
    "hand_span",
    "is_named",
]

#: Fewest actuated joints of a limb.
MIN_LIMB_JOINTS = 3
#: Shortest limb (sum of joint offsets, m): fingers are shorter.
MIN_LIMB_LENGTH = 0.2
#: A leg's end is this close to the lowest point of the robot (m) ...
FOOT_CLEARANCE = 0.1
#: ... and this far below where the leg starts (m).
LEG_DROP = 0.15


def hand_cut(tree: Tree, seg: Segment) -> int | None:
    """Where the hand starts in a run: the first body named as a hand below which only fingers move.

    Why not the first body named as a hand: wrists are often named after the hand they turn
    (GR1T2's ``l_hand_yaw``, ``l_hand_roll``, ``l_hand_pitch``); a joint below the cut that moves
    a link not named as a finger or jaw is still the arm's.
    """
    world = tree.world
    # From the bottom up: the lowest index below which every joint is the hand's (linear).
    first_hand_only = len(seg.bodies)
    for i in range(len(seg.bodies) - 1, 0, -1):
        c = world.parent_connection(seg.bodies[i])
        if c is not None and not c.is_fixed and not _hand_joint(tree, c):
            break
        first_hand_only = i
    for i in range(max(first_hand_only - 1, 1), len(seg.bodies)):
        if words(seg.bodies[i].name) & HAND_WORDS:
            return i
    return None


#: Words of a wrist's links and joints (an arm's), even when they are named after the hand.
AXIS_WORDS = frozenset({"yaw", "roll", "pitch", "wrist", "flex", "rotate", "rotation"})


def _hand_joint(tree: Tree, c: Connection) -> bool:
    """Whether a joint below a hand-named link moves the hand's own parts (a finger, a jaw)."""
    child = tree.world.bodies[c.child].name
    if is_named(child, FINGER_WORDS):
        return True
    named = words(child) | words(c.name)
    return bool(named & HAND_WORDS) and not named & (AXIS_WORDS | ARM_WORDS)


def _limb(
    tree: Tree,
    seg: Segment,
    low: float,
    base: Body | None,
    wheels: frozenset[str],
    paired: bool = False,
    rolling: bool = True,
    stands: bool = True,
    afoot: bool = False,
) -> Limb | None:
    """The arm or leg a run is, or None (``paired``: one of a mirrored pair beside legs).

    ``stands=False``: reaching the ground does not make the run a leg (a lone one, see
    ``_find_limbs``). ``afoot``: one of several runs from one trunk whose ends are on the
    ground (a small quadruped's short legs, whatever their names).
    """
    world = tree.world
    cut, jaw = _hand_cut(tree, seg)
    # The joint that moves the hand is the arm's last (a wrist roll turning 'gripper_link').
    into_hand = None if cut is None else world.parent_connection(seg.bodies[cut])
    upto = None if cut is None else cut + int(into_hand is not None and not into_hand.is_fixed)
    bodies = seg.bodies[:upto]
    moving: list[Connection] = []
    for b in bodies:
        c = world.parent_connection(b)
        if c is not None and not c.is_fixed:
            moving.append(c)
    actuated = [c for c in moving if c.is_active]
    while actuated and actuated[-1].name in wheels:
        actuated.pop()  # a wheel at a leg's end rolls the robot: the leg ends at its axle
    # Two joints make a leg when its links say so (Solo-8's hip and knee: 'FL_upperleg'), and
    # an arm (Quori's shoulder pitch and roll: 'l_arm_upper', 'l_arm_lower').
    # A mirrored pair of short runs (``paired``) may be a single shoulder each (Bolt's arms), a
    # quadruped's mirrored runs standing on the ground (``afoot``) a hip and a knee (Solo-8's).
    named_limb = count(bodies, LEG_WORDS) >= 2 or count(bodies, ARM_WORDS) >= 2
    fewest = 1 if paired else MIN_LIMB_JOINTS - int(named_limb or afoot)
    # The link where the run splits into fingers is a palm whatever its name (xArm7's Ability
    # hand: 'thumb_base' carries every finger); only the links above it must not be fingers'.
    palm = cut is None and bodies[-1] is seg.end and len(tree.moving_children(seg.end)) >= 2
    # Only the links the run's joints move can be a finger's: those fixed above its first
    # joint are what it stands on (KMR's 'base_link_middle', named after a chassis layer).
    moved = bodies[next((i for i, b in enumerate(bodies) if _moved(world, b)), len(bodies)) :]
    if len(actuated) < fewest or named(moved[:-1] if palm else moved, FINGER_WORDS):
        return None
    reach = tree.length(seg, None if jaw else upto)  # with its jaw, as far as it reaches
    # Shorter is a finger, unless named as a leg and reaching the ground (Mini Pupper's legs).
    below = tuple(world.subtree(seg.end))  # with the foot fixed at its end ('lffoot')
    on_ground = tree.position(seg.end)[2] - low < FOOT_CLEARANCE
    footed = (afoot or count(below, LEG_WORDS) > 0) and on_ground
    if reach < MIN_LIMB_LENGTH and not (footed or paired):
        return None
    root = _root(tree, seg, base)
    lifts = _lifts(tree, actuated)
    if lifts and len(actuated) - lifts >= MIN_LIMB_JOINTS:
        # A lift under the arm (HSR-B's arm lift) is a torso: the arm starts on top of it.
        root, actuated = world.bodies[actuated[lifts - 1].child], actuated[lifts:]
    tip = world.bodies[actuated[-1].child]
    hand, trunk = (seg.bodies[cut], False) if cut is not None else _end_hand(tree, seg)
    if trunk:
        return None  # limbs branch off here: a trunk (simple_humanoid's waist), not an arm
    if hand is not None and eyes(tree, hand):
        return None  # a head whose cameras turn on their own (eyes): not a hand's fingers
    if hand is None and named(bodies, HEAD_WORDS) and not named(bodies, ARM_WORDS):
        return None  # a head (see sensors.find_neck)
    if hand is None and len(actuated) <= 3 and pan_tilt(tree, seg):
        return None  # a pan/tilt unit pointing cameras: a neck (see sensors.find_neck)
    if hand is None and len(actuated) <= 3 and head_on_top(tree, seg):
        return None  # a head between limbs, on top of the robot (see parts._add_head)
    joints = frozenset(c.name for c in actuated)
    # Where the limb ends up: the lowest frame it carries (a foot fixed past the knee, a wheel),
    # not the last moving link's origin (a knee, 20 cm above the ground it stands on).
    z_tip = min(float(tree.position(b)[2]) for b in world.subtree(tip))
    # How far it drops from where it starts: its root's frame, or for a run of a leg's joints
    # its first joint if higher (a maker's root frame may sit on the ground under a pelvis).
    starts = (root, world.bodies[actuated[0].child])[: 2 if len(actuated) >= MIN_LIMB_JOINTS else 1]
    z_root = max(float(tree.position(b)[2]) for b in starts)
    legs_named = footed or count(bodies, LEG_WORDS) > count(bodies, ARM_WORDS)
    grounded = (
        stands and hand is None and z_tip - low < FOOT_CLEARANCE and z_root - z_tip > LEG_DROP
    )
    if legs_named or grounded:
        why = "its links are named as a leg's" if legs_named else "it ends on the ground"
        wheel = None
        if rolling and len(actuated) > MIN_LIMB_JOINTS and _rolls(tree, actuated[-1]):
            # A leg ending on a wheel (a wheel-legged robot's, whatever its joint's name): the
            # leg ends at the link carrying the axle, the wheel rolls the robot.
            wheel = actuated.pop()
            tip, joints = world.bodies[actuated[-1].child], joints - {wheel.name}
            why += f"; '{wheel.name}' turns its wheel"
        tip = chain_end(tree, tip, None, leg=True)
        why = f"{len(actuated)} joints; {why}"
        return Limb("leg", root, tip, None, joints, seg, why, wheel, not legs_named)
    ends = f"a hand at '{hand.name}'" if hand is not None else "the end of the branch"
    n = len(actuated)
    why = f"{n} joint{'s' if n > 1 else ''} in series from '{root.name}' to {ends}"
    tip = chain_end(tree, tip, hand)
    return Limb("arm", root, tip, hand, joints, seg, why)


def _moved(world: World, body: Body) -> bool:
    """Whether ``body`` hangs on a moving joint."""
    c = world.parent_connection(body)
    return c is not None and not c.is_fixed


def _hand_cut(tree: Tree, seg: Segment) -> tuple[int | None, bool]:
    """Where a run's hand starts (an index into its bodies, or None) and whether it is a jaw."""
    cut = hand_cut(tree, seg)
    jaw = cut is not None and one_jaw(tree, seg, cut)
    if cut is None and len(seg.bodies) >= 2 and one_jaw(tree, seg, len(seg.bodies) - 1, False):
        cut, jaw = len(seg.bodies) - 1, True  # a jaw by its shape and swing (Spot's 'fngr')
    if cut is not None and jaw:
        cut -= 1  # the moving jaw is the hand's; the link carrying both jaws is the hand
    return cut, jaw


def _root(tree: Tree, seg: Segment, base: Body | None) -> Body:
    """The limb starts where it branches off (PR2's torso_lift_link), or below a world frame."""
    root = seg.start if base is None else base
    top = tree.world.parent_connection(seg.bodies[0])
    if root.index == tree.root.index and words(root.name) & WORLD_WORDS and top and top.is_fixed:
        root = seg.bodies[0]
    return root


def _end_hand(tree: Tree, seg: Segment) -> tuple[Body | None, bool]:
    """The hand at a run's end where branches split (else None), and whether it is a trunk."""
    if len(tree.moving_children(seg.end)) < 2:
        return None, False
    # How far the branches reach from where each starts, not from the end's frame: a link
    # frame may lie far from its geometry (Alicia-M's 'grasp_base', 70 cm out of the wrist).
    branches = tree.moving_children(seg.end)
    if max(hand_span(tree, k) for k in branches) > MAX_HAND_SPAN:
        return None, True
    return seg.end, False


def _rolls(tree: Tree, c: Connection) -> bool:
    """Whether ``c`` turns without end about a level axis and nothing moves below it (a wheel).

    Why not a knee or an ankle: those turn within limits; a continuous joint at a leg's end
    turns a wheel (Unitree B2W's 'FL_foot_joint'), whatever it is named or its mesh.
    """
    wheel = tree.world.bodies[c.child]
    if c.type.value != "continuous" or tree.world.child_bodies(wheel):
        return False  # a knee carrying its foot frame (Mini Cheetah's) is no wheel
    return abs(float(tree.axis_in_root(c)[2])) < LEVEL


#: How level (the cosine of its angle to z, at most) a wheel's axis is in the default pose.
LEVEL = 0.3


def _lifts(tree: Tree, actuated: list[Connection]) -> int:
    """How many of a run's first joints lift it: prismatic along the vertical, in a row."""
    n = 0
    for c in actuated:
        if c.type.value != "prismatic" or abs(float(tree.axis_in_root(c)[2])) < VERTICAL:
            break
        n += 1
    return n


#: How vertical a lift's axis is (the cosine of its angle to z, in the default pose).
VERTICAL = 0.9


def find_limbs(tree: Tree, wheels: frozenset[str] = frozenset()) -> list[Limb]:
    """Every arm and leg of the tree, top-down; runs inside a found hand are fingers, not limbs.

    Legs end on wheels (a continuous joint past the leg's last link) only when at least
    ``MIN_ROLLING_LEGS`` of them do: a biped's continuous toes (Cassie's) are its feet.
    """
    limbs = _find_limbs(tree, wheels, rolling=True)
    if 0 < sum(1 for lb in limbs if lb.wheel is not None) < MIN_ROLLING_LEGS:
        limbs = _find_limbs(tree, wheels, rolling=False)
    return limbs


#: The fewest legs ending on wheels that make a wheel-legged robot (B2W's four).
MIN_ROLLING_LEGS = 3


def _find_limbs(tree: Tree, wheels: frozenset[str], rolling: bool) -> list[Limb]:
    world = tree.world
    low = tree.lowest_z()
    limbs: list[Limb] = []
    bases: list[Body | None] = []
    ending = {s.end.index: s for s in tree.segments}
    afoot = standing_runs(tree, low, FOOT_CLEARANCE, LEG_DROP)
    for seg, carried in carried_runs(tree):
        if carried:  # an arm a leg carries past its foot: its size need not be an arm's
            limb = _limb(tree, seg, low, None, wheels, paired=True, stands=False)
            if limb is not None and limb.kind == "arm":
                limbs.append(limb)
                bases.append(None)
            continue
        if any(world.is_ancestor(lb.tip, seg.start) for lb in limbs):
            continue  # inside a hand (fingers) or hanging below a limb's end
        above = ending.get(seg.start.index)
        joined = above is not None and _beside_heads(tree, above, seg)
        if above is not None and joined:
            # A shoulder that also turns a camera head (Sawyer's 'head' on 'right_l0'): the
            # run above the branch is the arm's first joint, not a torso.
            seg = Segment(above.start, above.bodies + seg.bodies, above.joints + seg.joints)
        # Joined, it starts at its own base: the link above its first joint, not above mounts.
        base = world.bodies[seg.joints[0].parent] if joined else None
        on_foot = seg.bodies[0].index in afoot
        limb = _limb(tree, seg, low, base, wheels, rolling=rolling, afoot=on_foot)
        if limb is not None:
            limbs.append(limb)
            bases.append(base)
    legs = [i for i, lb in enumerate(limbs) if lb.kind == "leg"]
    if len(legs) == 1 and limbs[legs[0]].grounded:
        # A robot stands on two legs or more: one run alone reaching the ground, no name
        # calling it a leg, hangs from a base whose frame sits above it (a UR arm whose
        # 'base_link' a maker placed higher): an arm, whatever the ground says.
        i = legs[0]
        arm = _limb(tree, limbs[i].segment, low, bases[i], wheels, rolling=rolling, stands=False)
        limbs[i : i + 1] = [] if arm is None else [arm]
    limbs += paired_arms(tree, limbs, lambda s: _limb(tree, s, low, None, wheels, paired=True))
    return without_digits(tree, limbs)


#: Most joints of a run above a branch that still make an arm's shoulder (a camera head beside).
MAX_SHOULDER_JOINTS = 2


def _beside_heads(tree: Tree, above: Segment, seg: Segment) -> bool:
    """Whether ``seg`` continues ``above``: every other branch where they meet is a camera head.

    Why: a head mounted on an arm's first link (Sawyer's) splits the arm's run in two; the run
    above the split (one or two turning joints, no lift: a lift is a torso) is the shoulder.
    """
    if not 1 <= len(above.actuated) <= MAX_SHOULDER_JOINTS:
        return False
    if any(c.type.value not in ("revolute", "continuous") for c in above.joints):
        return False
    others = [s for s in tree.segments if s.start is seg.start and s is not seg]
    if not others or len(others) + 1 != len(tree.moving_children(seg.start)):
        return False
    if pan_tilt(tree, seg):
        return False
    return all(len(s.actuated) <= 3 and pan_tilt(tree, s) for s in others)


def beside_branch(world: World, body: Body, tip: Body | str) -> bool:
    """Whether a moving branch leaves ``body`` off the path down to ``tip`` (a head beside it)."""
    for k in world.child_bodies(body):
        if world.is_ancestor(k, tip):
            continue
        if any(not c.is_fixed for b in world.subtree(k) if (c := world.parent_connection(b))):
            return True
    return False


def group_end(world: World, tip: Body, limb: Limb | None, joints: frozenset[str]) -> str:
    """Where a chain drafted from an SRDF group ends: past the group's tip where the files say.

    Why: a group lists what a planner moves, often ending at the last moving link (Panda's
    ``panda_link7``); the chain ends at the flange beyond it (``panda_link8``) as the tree's
    limb of the same joints does, found past fixed joints only (never another moving one).
    """
    if limb is None or limb.joints != joints or limb.tip is tip:
        return tip.name
    if not world.is_ancestor(tip, limb.tip):
        return tip.name
    path = world.compute_chain_of_connections(tip, limb.tip)
    return limb.tip.name if all(c.is_fixed for c in path) else tip.name
