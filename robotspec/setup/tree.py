"""The kinematic tree as the assistant shows it and picks in it: rows, chains' joints, limits.

Why here and not in the page: which joints a chain moves and what range a state's slider spans
are what the session checks picks against, with or without a browser.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

from robotspec.model.entities import Connection
from robotspec.model.world import World

__all__ = ["TreeRow", "chain_joints", "joint_range", "subtree_joints", "tree_rows"]


@dataclass(frozen=True)
class TreeRow:
    """One link of the tree: its depth and the joint that carries it (None at the root)."""

    link: str
    depth: int
    joint: str | None
    joint_type: str | None


def tree_rows(world: World) -> tuple[TreeRow, ...]:
    """Every link, depth first from the root, children in the URDF's order."""
    rows: list[TreeRow] = []
    stack = [(world.root, 0)]
    while stack:
        body, depth = stack.pop()
        conn = world.parent_connection(body)
        rows.append(
            TreeRow(
                body.name,
                depth,
                None if conn is None else conn.name,
                None if conn is None else conn.type.value,
            )
        )
        stack += [(c, depth + 1) for c in reversed(world.child_bodies(body))]
    return tuple(rows)


def _actuated(conns: Iterable[Connection | None]) -> tuple[str, ...]:
    return tuple(c.name for c in conns if c is not None and c.is_active and not c.is_mimic)


def chain_joints(world: World, root: str, tip: str) -> tuple[str, ...]:
    """The actuated, non-mimic joints from ``root`` down to ``tip`` (empty if not a chain)."""
    if not (world.has_body(root) and world.has_body(tip)) or not world.is_ancestor(root, tip):
        return ()
    return _actuated(world.compute_chain_of_connections(root, tip))


def subtree_joints(world: World, root: str) -> tuple[str, ...]:
    """The actuated, non-mimic joints below ``root`` (a hand's joints)."""
    if not world.has_body(root):
        return ()
    top = world.get_body_by_name(root)
    return _actuated(world.parent_connection(b) for b in world.subtree(top) if b is not top)


def joint_range(world: World, joint: str) -> tuple[float, float]:
    """A joint's limits; one turn (or two metres) each way where it has none."""
    conn = world.get_connection_by_name(joint)
    dof = world.degrees_of_freedom[conn.dofs[0]]
    lo, hi = float(dof.lower), float(dof.upper)
    half = math.pi if conn.type.value in ("revolute", "continuous") else 2.0
    return (lo if math.isfinite(lo) else -half), (hi if math.isfinite(hi) else half)
