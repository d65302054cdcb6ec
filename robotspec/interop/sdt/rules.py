"""SDT collision rules from a recipe: what a robot's ``_setup_collision_rules`` does, once.

Why a module of its own: two routes set a robot up, the generated robot class's own method and
:func:`robotspec.interop.sdt.identity.build` for a robot of SDT's own class (whose hand-written
method reads an SRDF SDT's wheel does not ship); both give SDT the spec's rules the same way.

Why the avoidance rules go first: SDT records each change of the collision manager in the
world's history by serialising the whole manager before and after it (krrood's ``to_json``,
which looks up a serialiser for each pair's body ids by walking a class tree). Added last, the
matrix of disabled pairs (257 on the PR2) is serialised once, not three times; added first it
was serialised again around the avoidance rules' change (the PR2's later ``to_sdt`` calls spent
about a third of their time there). The rules themselves, and the world a replayed history
gives, are the same in either order: SDT keeps the two kinds in separate lists.
"""

from __future__ import annotations

from typing import Any

from robotspec.interop.sdt.recipe import RobotRecipe

__all__ = ["setup_collision_rules"]


def setup_collision_rules(sdt: Any, recipe: RobotRecipe, robot: Any) -> None:
    """The spec's avoidance distances, and its disabled pairs and bodies, on ``robot``'s world."""
    world = robot._world
    manager = world.collision_manager
    if not recipe.collisions_disabled:
        distances = {
            "buffer_zone_distance": recipe.buffer_zone_distance,
            "violated_distance": recipe.violated_distance,
        }
        manager.extend_default_rules(
            [
                sdt.AvoidExternalCollisions(robot=robot, **distances),
                sdt.AvoidSelfCollisions(robot=robot, **distances),
            ]
        )

    def body(n: str) -> Any:
        return world.get_body_in_branch_by_name(robot.root, n)

    # SDT counts a body as colliding only above its size thresholds (a 1 mm box is not);
    # like SDT's own SRDF reader, pairs with a body it does not count are left out.
    pairs = [(body(a), body(b)) for a, b in recipe.disabled_pairs]
    manager.add_ignore_collision_rule(
        sdt.SelfCollisionMatrixRule(
            allowed_collision_pairs={
                sdt.CollisionCheck.create_and_validate(a, b)
                for a, b in pairs
                if a.has_collision() and b.has_collision()
            },
            allowed_collision_bodies={body(n) for n in recipe.disabled_bodies},
        )
    )
