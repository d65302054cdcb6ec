"""What the geometry commands (render, view, collisions) say about meshes that were not found.

Why: loading a robot treats a missing mesh package as a warning (kinematics need no mesh), so
the commands that do need the files are the ones that must say which bodies lose their geometry,
all at once, and either stop (telling the user how to go on) or, with
``--skip-missing-meshes``, carry on without them.
"""

from __future__ import annotations

import sys
from collections.abc import Iterable
from typing import TYPE_CHECKING

from robotspec.errors import ErrorDetail, RobotSpecError

if TYPE_CHECKING:
    from robotspec.semantic import AbstractRobot

__all__ = ["check_missing_geometry", "report_skipped", "require_collision_geometry"]


def check_missing_geometry(
    robot: AbstractRobot, *, skip: bool, collision: bool, command: str
) -> frozenset[str]:
    """Refuse (or, with ``skip``, warn once) when robot bodies have meshes that did not resolve.

    Returns the URIs already reported, so the per-element skips of the geometry builders are
    not printed again.
    """
    from robotspec.description.mesh_report import missing_geometry_problems, unresolved_meshes
    from robotspec.errors import raise_collected

    meshes = unresolved_meshes(
        robot.world, collision=collision, bodies=[b.name for b in robot.bodies]
    )
    problems = missing_geometry_problems(meshes, command=command, skip=skip)
    if not skip:
        raise_collected(problems, summary=f"{command}: bodies lose their geometry")
    for problem in problems:
        _print(problem.detail)
    return frozenset(m.uri for m in meshes)


def report_skipped(skipped: Iterable[RobotSpecError], reported: frozenset[str]) -> None:
    """Print the elements a geometry builder left out, except meshes already reported."""
    for err in skipped:
        if err.file in reported:
            continue
        for detail in err.details:
            _print(detail)


def _print(detail: ErrorDetail) -> None:
    from robotspec.cli.output import styled

    sys.stderr.write(styled(detail, sys.stderr) + "\n")


def require_collision_geometry(robot: AbstractRobot, command: str) -> None:
    """Refuse plainly when fewer than two bodies have collision geometry with a volume.

    Why: without it every collision command "succeeded" with 0 pairs (or checked pairs of
    bodies that have nothing to collide), which reads as a clean bill of health.
    """
    from robotspec.errors import CollisionError
    from robotspec.model.geometry import Mesh

    def solid(body: object) -> bool:
        for shape in getattr(body, "collisions", ()):
            g = shape.geometry
            if isinstance(g, Mesh):
                return True
            size = getattr(g, "size", ())
            dims = [*size, *(getattr(g, k) for k in ("radius", "length") if hasattr(g, k))]
            if all(x > 0 for x in dims):
                return True
        return False

    bodies = [b.name for b in robot.world.bodies if solid(b)]
    source = robot.world.source
    where = f" in {source.rsplit('/', 1)[-1]}" if source else ""
    if not bodies:
        raise CollisionError(
            f"robot '{robot.name}' has no collision geometry (no <collision> element with a "
            f"volume{where}): nothing to {command}",
            file=source,
            kind="collision",
        )
    if len(bodies) == 1:
        raise CollisionError(
            f"robot '{robot.name}' has collision geometry on one body only ('{bodies[0]}'"
            f"{where}): no pair to {command}",
            file=source,
            kind="collision",
        )
