"""The body SDT's mobile base starts at: the robot's base body, read off the robot's files.

Why it matters: coraplex plans with the mobile base's root body (its collision box is the
base's footprint and height in its costmaps and pose checks), so that body must be the base
itself, not the torso's first link (the Stretch's mast) nor a frame without geometry (the PR2's
``base_footprint``).

The rule: the robot's root when it carries collision geometry, else the body nearest to it,
welded below it by fixed joints, that does; two equally near, or none, leave the root.
"Carries" is SDT's own ``Body.has_collision``: a mesh, or a primitive above SDT's volume and
area thresholds, so the 1 mm placeholder boxes some URDFs put on ``base_footprint`` (Justin,
iCub 3) do not count. On the URDFs of SDT 26.7's classes it gives the body the PR2, HSR-B,
Stretch, TIAGo and Justin classes name (``base_link``); it differs where SDT's iCub 3 roots its
base at ``l_hip_1`` (one leg's hip) and its G1 at ``pelvis`` (which has no collision geometry,
so SDT's base box there is empty): ``migrate sdt`` notes those, and a spec does not copy them.
Why no spec field: the body is a fact of the robot's files, and the classes' other choices
are not facts a spec should repeat.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from robotspec.model.entities import ConnectionType
from robotspec.model.geometry import Box, Capsule, Cylinder, Mesh, Sphere

if TYPE_CHECKING:
    from robotspec.model.world import Body, World

#: SDT 26.7's ``Body.has_collision`` thresholds: a primitive below both does not count.
VOLUME_THRESHOLD = 1.001e-6  # m^3
AREA_THRESHOLD = 0.00061  # m^2

__all__ = ["base_body", "has_collision"]


def base_body(world: World, root: str) -> str:
    """The name of the mobile base's body of a robot rooted at ``root`` (module docstring)."""
    level = [world.get_body_by_name(root)]
    while level:
        found = [b for b in level if has_collision(b)]
        if found:
            return found[0].name if len(found) == 1 else root
        level = [
            child
            for body in level
            for child in world.child_bodies(body)
            if (c := world.parent_connection(child)) is not None and c.type is ConnectionType.FIXED
        ]
    return root


def _volume_area(geo: object) -> tuple[float, float]:
    if isinstance(geo, Box):
        a, b, c = geo.size
        return a * b * c, 2 * (a * b + b * c + c * a)
    if isinstance(geo, Sphere):
        r = geo.radius
        return 4 / 3 * math.pi * r**3, 4 * math.pi * r**2
    if isinstance(geo, (Cylinder, Capsule)):  # a capsule is SDT's enclosing cylinder
        r = geo.radius
        h = geo.length + (2 * r if isinstance(geo, Capsule) else 0.0)
        return math.pi * r * r * h, 2 * math.pi * r * (r + h)
    return 0.0, 0.0


def has_collision(body: Body) -> bool:
    """Whether SDT counts ``body`` as having collision geometry (a mesh, or a big primitive)."""
    for shape in body.collisions:
        if isinstance(shape.geometry, Mesh):
            return True
        volume, area = _volume_area(shape.geometry)
        if volume > VOLUME_THRESHOLD or area > AREA_THRESHOLD:
            return True
    return False
