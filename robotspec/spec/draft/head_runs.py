"""Runs of the tree that are heads, not arms: what turns cameras or carries the robot's top.

Split from ``limbs`` (which finds each run's limb): a head's run (a pan and a tilt, a neck's
pitch, roll and yaw) has the shape of a short arm; these checks tell it apart before a run is
taken for an arm, by the cameras it carries or, without them, by where it is on the robot.
"""

from __future__ import annotations

from robotspec.model.entities import Body
from robotspec.spec.draft.limb_kinds import FINGER_WORDS, HAND_WORDS, is_named
from robotspec.spec.draft.tree import Segment, Tree, words

__all__ = ["LOOK_WORDS", "eyes", "head_on_top", "pan_tilt"]

#: How vertical a pan's axis is (the cosine of its angle to z, in the default pose).
UPRIGHT = 0.9


#: Words of a camera's frames (a run carrying one and nothing else is a neck, not an arm).
LOOK_WORDS = frozenset({"camera", "cam", "optical", "rgb", "rgbd", "depth", "stereo", "kinect"})


def eyes(tree: Tree, hand: Body) -> bool:
    """Whether every moving branch below where ``hand`` splits carries a camera and no finger.

    Why: a head whose eyes turn on their own (iCub's, a humanoid's stereo pair) splits into
    branches like a hand into fingers; the cameras they carry say they are eyes.
    """
    world = tree.world
    body = hand
    while len(kids := tree.moving_children(body)) == 1:
        body = kids[0]
    if len(kids) < 2:
        return False
    for k in kids:
        inside = world.subtree(k)
        if not any(words(b.name) & LOOK_WORDS for b in inside):
            return False
        if any(is_named(b.name, FINGER_WORDS | HAND_WORDS) for b in inside):
            return False
    return True


def pan_tilt(tree: Tree, seg: Segment) -> bool:
    """Whether a run's joints all turn (no lift) and its end carries a camera frame and no limb."""
    world = tree.world
    if any(c.type.value not in ("revolute", "continuous") for c in seg.joints):
        return False
    if tree.moving_children(seg.end):
        return False
    return any(_camera_frame(tree, b) for b in world.subtree(seg.end))


def _camera_frame(tree: Tree, body: Body) -> bool:
    """Whether ``body`` is a camera's frame: named so, or the link or frame of a Gazebo camera.

    Why not its rotation too: a wrist's bare end frame is turned as an optical frame as often
    as a head's camera frame is (Wolfgang-OP's 'l_wrist'); a run is a head by what the files
    state of its cameras, or by their names.
    """
    if words(body.name) & LOOK_WORDS:
        return True
    facts = tree.memo.get("facts")
    return facts is not None and any(body.name in (cam.link, cam.frame) for cam in facts.cameras)


def head_on_top(tree: Tree, seg: Segment) -> bool:
    """Whether a run is a head: turning joints, one about the vertical, carrying the robot's top.

    Why: a head's links named nothing a reader knows (a humanoid's neck pitch, roll and yaw)
    make a short run like a 3-joint arm; but it rises from a trunk that carries at least two
    other limbs' runs, pans about the vertical, and the highest frame of the robot is on it.
    """
    world = tree.world
    if any(c.type.value != "revolute" for c in seg.joints) or tree.moving_children(seg.end):
        return False
    if not any(abs(float(tree.axis_in_root(c)[2])) > UPRIGHT for c in seg.joints):
        return False
    if float(tree.position(seg.end)[2]) <= float(tree.position(seg.start)[2]):
        return False
    if sum(1 for s in tree.segments if s.start is seg.start and s is not seg) < 2:
        return False
    top = max(float(tree.position(b)[2]) for b in world.bodies if b.index in tree.inside)
    return max(float(tree.position(b)[2]) for b in world.subtree(seg.bodies[0])) >= top - 1e-6
