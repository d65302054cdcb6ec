"""The kinematic tree as the detectors see it: moving branches, serial segments, the default pose.

Why segments: an arm, a leg, a finger and a neck are all serial runs of moving joints between two
branching points of the tree. Cutting the tree there once, and measuring each run (joints, length,
where it ends up in the default pose), lets every detector ask simple questions instead of walking
the tree again.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any

import numpy as np

from robotspec.model.entities import Body, Connection
from robotspec.model.kinematics import Kinematics
from robotspec.model.world import World

__all__ = ["Segment", "Tree", "solid", "words"]

_SPLIT = re.compile(r"[^a-z0-9]+|(?<=[a-z])(?=[0-9])|(?<=[0-9])(?=[a-z])")


def words(name: str) -> set[str]:
    """The lower-case words of a name (``arm_left_7_link`` -> arm, left, 7, link)."""
    out: set[str] = set()
    # camelCase and CAPS prefixes (FL_hip) split too.
    spaced = re.sub(r"(?<=[a-z])(?=[A-Z])", "_", name)
    for w in _SPLIT.split(spaced.lower()):
        if w:
            out.add(w)
    return out


def solid(world: World, body: Body) -> bool:
    """Whether ``body`` is a part of the robot rather than a bare frame.

    A part has a shape (visual or collision). Why a mass too: a file written for kinematics or
    dynamics only (no shape anywhere, as when meshes were stripped or never made) still tells
    parts from frames by their inertia; there a link with a mass is a part. Only in such a file:
    elsewhere a massive link without a shape is a linkage helper (PR2's parallel links).
    """
    if body.collisions or body.visuals:
        return True
    if not body.mass:
        return False
    return not any(b.collisions or b.visuals for b in world.bodies)


@dataclass(frozen=True)
class Segment:
    """A serial run of the tree below a branching body ``start``, ending at ``end``.

    ``bodies`` run from the first body below ``start`` down to ``end``; every body but the last
    has exactly one moving branch below it. ``end`` has none (a leaf run) or several (a branch).
    """

    start: Body
    bodies: tuple[Body, ...]
    joints: tuple[Connection, ...]  # the moving connections along it, top to bottom

    @property
    def end(self) -> Body:
        """The last body of the run."""
        return self.bodies[-1]

    @property
    def actuated(self) -> tuple[Connection, ...]:
        """Moving connections with their own degree of freedom (no mimics)."""
        return tuple(c for c in self.joints if c.is_active)


class Tree:
    """A world below ``root``, with the facts every detector needs, computed once."""

    def __init__(self, world: World, root: Body) -> None:
        self.world = world
        self.root = root
        n = len(world.bodies)
        moves_below = [False] * n
        # Connections are in topological order (parents first): children are done first here.
        for c in reversed(world.connections):
            if not c.is_fixed or moves_below[c.child]:
                moves_below[c.parent] = True
        self._moves_below = moves_below
        self.inside = {b.index for b in world.subtree(root)}
        self.poses = Kinematics(world).forward(world.default_configuration())
        self._root_inv = np.linalg.inv(self.poses[root.index])
        self.segments = self._segments()
        #: What detectors found once and ask again (the cameras), by name.
        self.memo: dict[str, Any] = {}

    # ------------------------------------------------------------------------------ queries
    def parent_joint(self, body: Body) -> Connection | None:
        """The connection above ``body`` (``None`` at the world's root)."""
        return self.world.parent_connection(body)

    def rigid_root(self, body: Body) -> Body:
        """The link a frame is rigidly fixed to: up through fixed joints to a moving one.

        Why one place: cameras, devices, tool frames and the questions all ask "which link does
        this frame move with", and each answer must be the same.
        """
        b = body
        while (c := self.world.parent_connection(b)) is not None and c.is_fixed:
            if b is self.root:
                break
            b = self.world.bodies[c.parent]
        return b

    def moving_children(self, body: Body) -> list[Body]:
        """Children whose branch moves: a moving joint to them, or one somewhere below them."""
        out = []
        for k in self.world.child_bodies(body):
            c = self.world.parent_connection(k)
            if c is not None and (not c.is_fixed or self._moves_below[k.index]):
                out.append(k)
        return out

    def moves_below(self, body: Body) -> bool:
        """Whether any joint below ``body`` moves."""
        return self._moves_below[body.index]

    def position(self, body: Body | str) -> np.ndarray:
        """Where ``body`` is in the default pose, in the robot root's frame (x forward, z up)."""
        b = self.world.get_body_by_name(body) if isinstance(body, str) else body
        p: np.ndarray = (self._root_inv @ self.poses[b.index])[:3, 3]
        return p

    def pose(self, body: Body) -> np.ndarray:
        """Where ``body`` is and how it is turned in the default pose, in the root's frame (4x4)."""
        p: np.ndarray = self._root_inv @ self.poses[body.index]
        return p

    def axis_in_root(self, c: Connection) -> np.ndarray:
        """A joint's axis in the root frame, in the default pose."""
        rot = (self._root_inv @ self.poses[c.child])[:3, :3]
        a: np.ndarray = rot @ np.asarray(c.axis, dtype=np.float64)
        return a

    def length(self, seg: Segment, upto: int | None = None) -> float:
        """Sum of the joint offsets along a segment (its reach when straightened)."""
        total = 0.0
        for b in seg.bodies[:upto]:
            c = self.world.parent_connection(b)
            if c is not None:
                total += float(np.linalg.norm(c.origin[:3, 3]))
        return total

    def lowest_z(self) -> float:
        """The height of the lowest body in the default pose (the ground for a standing robot)."""
        zs = [self.position(b)[2] for b in self.world.bodies if b.index in self.inside]
        return float(min(zs)) if zs else 0.0

    def actuated_between(self, root: Body, tip: Body) -> frozenset[str]:
        """Names of the actuated joints on the path from ``root`` down to ``tip``."""
        return frozenset(
            c.name for c in self.world.compute_chain_of_connections(root, tip) if c.is_active
        )

    # ----------------------------------------------------------------------- segmenting
    def _segments(self) -> list[Segment]:
        out: list[Segment] = []
        stack = [self.root]
        while stack:
            start = stack.pop()
            for first in self.moving_children(start):
                bodies = [first]
                body = first
                while True:
                    kids = self.moving_children(body)
                    if len(kids) != 1:
                        break
                    body = kids[0]
                    bodies.append(body)
                joints = []
                for b in bodies:
                    c = self.world.parent_connection(b)
                    if c is not None and not c.is_fixed:
                        joints.append(c)
                seg = Segment(start, tuple(bodies), tuple(joints))
                out.append(seg)
                if len(self.moving_children(body)) >= 2:
                    stack.append(body)
        out.sort(key=lambda s: (self.world.depth(s.start), s.bodies[0].index))
        return out
