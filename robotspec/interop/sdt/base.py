"""The body SDT's mobile base starts at: the robot's base body, read off the robot's files.

Why it matters: coraplex plans with the mobile base's root body (its collision box is the
base's footprint and height in its costmaps and pose checks), so that body must be the base
itself, not the torso's first link (the Stretch's mast) nor a frame without geometry (the PR2's
``base_footprint``).

Why no spec field for it: the body is a fact of the URDF, the robot's root when the root
carries collision geometry, else the body nearest to it, welded below it by fixed joints, that
does. That is the body every wheeled robot class of SDT 26.7 names (``base_link`` of the PR2,
HSR-B, Stretch, TIAGo, Justin and MMP Dresden) and the Unitree G1's ``pelvis``, so a spec
migrated from any of them keeps it without saying it. Where two bodies are equally near, or
none has geometry, the root is the base. SDT's iCub 3 class roots its base at ``l_hip_1``, one
leg's hip, which no rule finds and a spec should not copy; ``migrate sdt`` notes it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from robotspec.model.entities import ConnectionType

if TYPE_CHECKING:
    from robotspec.model.world import World

__all__ = ["base_body"]


def base_body(world: World, root: str) -> str:
    """The name of the mobile base's body of a robot rooted at ``root`` (module docstring)."""
    level = [world.get_body_by_name(root)]
    while level:
        found = [b for b in level if b.collisions]
        if found:
            return found[0].name if len(found) == 1 else root
        level = [
            child
            for body in level
            for child in world.child_bodies(body)
            if (c := world.parent_connection(child)) is not None and c.type is ConnectionType.FIXED
        ]
    return root
