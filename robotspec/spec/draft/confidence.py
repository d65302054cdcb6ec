"""When a drafted item carries a ``DECIDE`` mark: the one rule, in one place (issue 30, item 3).

Why one module: a mark is a question to the person finishing the spec, and it only means
something when it is dropped for one reason, everywhere: **a file states the answer**. Every
decision resting on names, geometry heuristics or defaults keeps its mark, saying what to check.
The detectors find; this module says whether what they found is stated. What states an answer:

=================  ===========================================================================
item               unmarked only when
=================  ===========================================================================
chain              an SRDF group states its joints, the tree finds an arm or a leg of exactly
                   those joints, and an SRDF end effector hangs on it (names the group as its
                   group or parent group, or its tip as parent link): the SRDF says it carries
                   a hand or a foot
tool frame         the SRDF end effector's parent link is a bare frame on the hand; or a bare
                   frame named as a TCP (``tool0``, ``*_tcp``, ``ee_link``, ``grasp_frame``,
                   ``tool_frame``, ``end_effector_link``...) at the manipulator's end: on the
                   part that carries the fingers (or below it), or, without a hand, below the
                   chain's tip with no moving joint below it
parallel gripper   its two fingers are coupled by a ``mimic`` tag (one driven, one mimicking it)
                   and each finger ends at one link with a shape (a linkage's several ends,
                   or a bare frame past the pad: which is the tip?)
hand (3+ fingers)  never: which branch is the thumb rests on names and geometry
camera             a Gazebo camera sensor names its frame (and nothing about its axis is odd)
torso, neck        never: both are found by where arms branch and what carries cameras
drive              a Gazebo drive plugin names it (an Ackermann one is asked: no such kind),
                   or an SRDF virtual joint states ``floating`` on a robot with legs, wheels
                   or rotors (``fixed`` on one without); a
                   floating one on a robot nothing moves is drafted ``fixed``, asked; a planar
                   virtual joint says the base moves in the plane, not whether sideways: asked
forward            never
=================  ===========================================================================

Each row is narrowed to what its evidence proves: after every part is drafted, ``whole`` gives
an item its mark back wherever the rule's files state only part of it (a Gazebo sensor states a
device, not which of its frames or eyes a spec names; a mimic tag states coupled fingers, not
where their tips are; a TCP name states a frame, not that it is the only one or that nothing is
bolted past it; a fixed virtual joint states what a planner assumes, not that the base has no
wheels; a ``planar_move`` plugin fakes any drive). Drafts of robots seen for the first time
left wrong items unmarked exactly there.

How each row could still be wrong on a robot nobody here has seen (round 10's audit; where the
case is plausible, ``whole`` keeps the mark, and the rest is what a mark cannot catch):

* chain: a planner's group cut otherwise than a spec's (a waist joint inside the arm's group on
  a one-armed robot the tree cannot split; a lift is asked); a group named as a leg the tree
  reads as an arm (asked);
* tool frame: a TCP name on a flange or on a finger rather than between the tips (asked when it
  moves with a finger or lies less than halfway out to the tips); an SRDF parent link at the
  flange with a tool bolted past it (asked when a shape lies farther out); a TCP name the
  spec's author does not take although it is the only one (not caught);
* gripper: a mimic pair that is two fingers of a hand with a third driven on its own (asked);
  tips the author puts on a pad or a bare frame the tree does not reach (asked where the two
  sides end differently, not where both do alike);
* camera: a sensor naming a body link whose optical child is the camera, or a channel beside it
  (asked when the device holds other frames looking its way), a frame looking away from its
  sensor (asked), an author who lists no camera for a simulated one (not caught);
* drive: a floating virtual joint on a robot whose legs the tree misread (arms hanging down:
  the legs' own marks ask); a fixed one on a base whose wheels the file does not model at all
  (not caught: nothing in the files says it moves).

Each row that leaves an item unmarked has a code (``CHAIN_SRDF``, ``TOOL_SRDF``...): the draft
item records it (``stated``, never written into the spec), so that the corpus measure counts,
per rule, how many items it left unmarked and how many of those were wrong. A rule that leaves
wrong items unmarked on robots seen for the first time is too broad.

A manipulator's ``front_facing_orientation`` follows from its tool frame and fingers (the way
from the hand's root to its tips, in the tool frame): it is written with that reason as a plain
comment, and marked only when the hand gives no way to face (a default).
"""

from __future__ import annotations

from robotspec.description.srdf import Srdf
from robotspec.model.entities import Body
from robotspec.model.world import World
from robotspec.spec.draft.tool_frames import is_bare_frame, is_named_tcp
from robotspec.spec.draft.tree import Tree

__all__ = [
    "CAMERA_GAZEBO",
    "CHAIN_SRDF",
    "DRIVE_FIXED",
    "DRIVE_FLOATING",
    "DRIVE_PLUGIN",
    "GRIPPER_MIMIC",
    "RULES",
    "TOOL_AT_END",
    "TOOL_ON_HAND",
    "TOOL_SRDF",
    "camera_question",
    "chain_question",
    "drive_plugin_question",
    "drive_question",
    "drive_rule",
    "gripper_question",
    "srdf_carries",
    "tool_frame_verdict",
]

# The rules that leave an item unmarked, one code per row of the table above.
CHAIN_SRDF = "chain: SRDF group the tree confirms, an end effector on it"
TOOL_SRDF = "tool frame: the SRDF end effector's parent link"
TOOL_ON_HAND = "tool frame: a TCP name on the hand"
TOOL_AT_END = "tool frame: a TCP name at the chain's end"
GRIPPER_MIMIC = "gripper: fingers a mimic tag couples"
CAMERA_GAZEBO = "camera: a Gazebo sensor"
DRIVE_PLUGIN = "drive: a Gazebo drive plugin"
DRIVE_FLOATING = "drive: a floating SRDF virtual joint, a robot that moves"
DRIVE_FIXED = "drive: a fixed SRDF virtual joint, a robot that does not move"
#: Every rule, in the table's order.
RULES = (
    CHAIN_SRDF,
    TOOL_SRDF,
    TOOL_ON_HAND,
    TOOL_AT_END,
    GRIPPER_MIMIC,
    CAMERA_GAZEBO,
    DRIVE_PLUGIN,
    DRIVE_FLOATING,
    DRIVE_FIXED,
)


def srdf_carries(srdf: Srdf | None, group: str, tip: str) -> str | None:
    """The SRDF end effector that hangs on ``group`` (ending at ``tip``), if one does."""
    if srdf is None:
        return None
    for ee in srdf.end_effectors:
        if group in (ee.parent_group, ee.group) or ee.parent_link == tip:
            return ee.name
    return None


def chain_question(srdf: Srdf | None, group: str | None, tip: str, tree_agrees: bool) -> str | None:
    """Why a drafted chain is a question, or ``None`` when the files state it (see the table)."""
    if group is None:
        return "by the tree's shape"
    if not tree_agrees:
        return None  # the caller says how the tree disagrees
    if srdf_carries(srdf, group, tip) is None:
        return f"the SRDF groups these joints ('{group}'), but no end effector hangs on the group"
    return None


def tool_frame_verdict(
    world: World,
    tool: Body,
    *,
    hand: Body | None,
    tip: Body,
    srdf_parent: Body | None,
    tree: Tree,
) -> tuple[str | None, str | None]:
    """(question, rule): why a tool frame the URDF has is asked, or the rule that states it.

    ``hand``: where the hand's fingers hang (the gripper's root, or the hand the tree found);
    ``tip``: the chain's tip; ``srdf_parent``: the SRDF end effector's parent link.
    """
    if srdf_parent is not None and tool is srdf_parent and is_bare_frame(world, tool):
        return None, TOOL_SRDF
    if not is_named_tcp(world, tool):
        return f"the tool frame '{tool.name}': by its name or where it lies", None
    if hand is not None:
        if world.is_ancestor(hand, tool):
            return None, TOOL_ON_HAND
        return f"the tool frame '{tool.name}' is named as a TCP but hangs beside the hand", None
    if world.is_ancestor(tip, tool) and not tree.moves_below(tip):
        return None, TOOL_AT_END
    return f"the tool frame '{tool.name}' is named as a TCP but is not at the chain's end", None


def gripper_question(coupled: bool, one_driven: bool) -> str | None:
    """Why a parallel gripper's fingers are a question, or ``None`` when a mimic tag pairs them."""
    if coupled and one_driven:
        return None
    if not coupled:
        return "the two finger branches move on joints no mimic tag couples: a gripper?"
    return "both fingers are driven; the thumb is the one on the hand's +y side"


def camera_question(stated: bool, found_by: str) -> str | None:
    """Why a camera is a question (``found_by``: how the tree found it), ``None`` when stated."""
    return None if stated else found_by


#: Why a floating virtual joint on a robot nothing moves is drafted fixed, and asked.
_STILL = (
    "the SRDF's virtual joint is floating, but no wheels, legs or rotors move the robot: fixed?"
)


def drive_question(virtual: str, moves: bool) -> str | None:
    """Why a drive taken from an SRDF virtual joint of type ``virtual`` is a question.

    ``moves``: whether the tree has wheels, legs or rotors (a base that may move).
    """
    if virtual == "floating":
        # An arm bolted down is often given a floating virtual joint by its MoveIt config.
        return None if moves else _STILL
    if virtual == "fixed":
        return (
            "the SRDF's virtual joint is fixed, but the robot has wheels, legs or rotors"
            if moves
            else None
        )
    return f"the SRDF's {virtual} virtual joint moves the base in the plane: omni, or differential?"


def drive_rule(virtual: str, moves: bool) -> str | None:
    """The rule that states a drive from an SRDF virtual joint (``None``: it is asked)."""
    if drive_question(virtual, moves) is not None:
        return None
    return DRIVE_FLOATING if virtual == "floating" else DRIVE_FIXED


def drive_plugin_question(plugin: str) -> str | None:
    """Why a drive a Gazebo drive plugin names is a question (an Ackermann one: no such kind)."""
    if "ackerman" in plugin.lower():
        return "an Ackermann (car-like) drive: differential is the nearest kind"
    return None
