"""Finger branches of a hand whose shapes are missing: told by mass, coupling and range.

Why: a hand's fingers are found by their geometry (``fingers.hand_branches``), but another
maker's file may carry no shape there (mesh packages missing, a file written for dynamics or
kinematics only). What the file still states is enough to tell a finger from the helpers beside
it: a finger is a part (it has a shape or a mass; in a hand with neither, every moving branch
is one), its joints have a finger's range (a screw or a wheel turns without end), and it is not
the actuator's stand-in (a one-joint leaf that the fingers' mimic tags follow, HSR-B's motor
link). A branch with a shape keeps its answer: these rules decide only the shapeless ones
(beside no finger at all, or beside fingers whose primitives were kept, Ability's thumb).
"""

from __future__ import annotations

from robotspec.model.entities import Body
from robotspec.model.world import World
from robotspec.spec.draft.linkages import ball_joint, moving_joints, turns_freely
from robotspec.spec.draft.tree import Tree

__all__ = ["bare_branches", "massive", "shapeless"]


def shapeless(world: World, branch: Body) -> bool:
    """Whether no link of ``branch``'s subtree has a shape (visual or collision)."""
    return not any(b.collisions or b.visuals for b in world.subtree(branch))


def massive(world: World, branch: Body) -> bool:
    """Whether some link of ``branch``'s subtree has a mass."""
    return any(b.mass for b in world.subtree(branch))


def bare_branches(tree: Tree, kids: list[Body]) -> list[Body]:
    """The moving branches ``kids`` of a split that are fingers, in their order.

    A branch with a shape is one (``fingers.hand_branches``' rule); two such are a gripper's
    fingers, and nothing beside them is. Else a shapeless one is a finger when it has a mass
    (or when no branch has a mass or a shape: the joints alone say it), turns within a
    finger's range and is not the actuator's stand-in. None holds a ball joint.
    """
    world = tree.world
    kids = [k for k in kids if not ball_joint(world, k)]  # a linkage's rod (``linkages``)
    shaped = [k for k in kids if not shapeless(world, k)]
    bare = [k for k in kids if shapeless(world, k) and massive(world, k)]
    if not shaped and not bare:
        bare = list(kids)
    bare = [k for k in bare if not turns_freely(world, k)]
    if len(shaped) == 2:
        return shaped  # a gripper's two fingers with their shapes: what lies beside is a helper
    parts = shaped + bare
    stand_ins = {k.index for k in bare if _stand_in(world, k, parts)}
    return [k for k in kids if k in shaped or (k in bare and k.index not in stand_ins)]


def _stand_in(world: World, branch: Body, parts: list[Body]) -> bool:
    """Whether ``branch`` is an actuator's stand-in: a shapeless one-joint leaf others mimic.

    Why: a linkage gripper's URDF may hang its motor as a link of its own beside the fingers
    (HSR-B's 'hand_motor_dummy_link'); the fingers' joints are mimic tags following its joint,
    so two or more other branches move with it while it carries nothing.
    """
    moving = moving_joints(world, branch)
    if len(moving) != 1 or not moving[0].is_active or not shapeless(world, branch):
        return False
    if any(b.mass for b in world.subtree(branch) if b is not branch):
        return False  # a link carried on it (Robotiq's outer finger on its knuckle): a finger
    dof = set(moving[0].dofs)
    followers = [
        k
        for k in parts
        if k is not branch
        and any(c.is_mimic and set(c.dofs) & dof for c in moving_joints(world, k))
    ]
    return len(followers) >= 2
