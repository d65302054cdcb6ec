"""A compiled robot handed to pinocchio: model, collision model, semantic frame ids.

The world's part is :mod:`robotspec.model.pinocchio`; this room adds what needs the robot and
its collision rules: the coal geometries with exactly the pairs robotspec checks, and the frame
ids of every chain tip, tool frame and camera.
"""

from __future__ import annotations

from collections.abc import Sequence
from types import MappingProxyType
from typing import TYPE_CHECKING, Protocol

import numpy as np

from robotspec.collision.checker import SelfCollisionChecker
from robotspec.collision.robot_view import CollisionRobot
from robotspec.collision.rules import pair_key
from robotspec.model.pinocchio import (
    PinocchioRobot,
    import_pinocchio,
    set_limits,
    to_se3,
    world_to_pinocchio,
)

if TYPE_CHECKING:
    from robotspec.collision.shapes import MeshLibrary, MissingMeshPolicy
    from robotspec.model.world import Body

__all__ = ["PinocchioSubject", "robot_to_pinocchio"]


class _Chain(Protocol):
    @property
    def name(self) -> str: ...
    @property
    def tip(self) -> Body: ...


class _Tool(Protocol):
    @property
    def name(self) -> str: ...
    @property
    def tool_frame(self) -> Body: ...


class _Mounted(Protocol):
    @property
    def name(self) -> str: ...
    @property
    def root(self) -> Body: ...


class PinocchioSubject(CollisionRobot, Protocol):
    """A robot as the hand-off reads it: collision's view, plus its semantic frames.

    Why a protocol: this room builds on collision, and the semantic robot's ``to_pinocchio()``
    calls it; naming the semantic class here would close an import cycle.
    """

    @property
    def all_chains(self) -> Sequence[_Chain]:
        """Every kinematic chain (each tip gets a frame id)."""
        ...

    @property
    def manipulators(self) -> Sequence[_Tool]:
        """Every manipulator (each tool frame gets a frame id)."""
        ...

    @property
    def cameras(self) -> Sequence[_Mounted]:
        """Every camera (each root gets a frame id)."""
        ...


def robot_to_pinocchio(
    robot: PinocchioSubject,
    *,
    meshes: MeshLibrary | None = None,
    on_missing_mesh: MissingMeshPolicy = "error",
) -> PinocchioRobot:
    """``robot`` as pinocchio objects: see :class:`PinocchioRobot`."""
    pin = import_pinocchio()
    world = robot.world
    model, frames, order = world_to_pinocchio(world)
    set_limits(model, world, order)
    checker = SelfCollisionChecker.from_robot(robot, meshes=meshes, on_missing_mesh=on_missing_mesh)
    gmodel = pin.GeometryModel()
    geoms = checker.geometry.geometries
    index_of: list[int] = []
    for g in geoms:
        frame = model.frames[frames[g.body]]
        joint_to_geom = frame.placement.homogeneous @ np.asarray(g.body_T_geometry)
        obj = pin.GeometryObject(
            f"{g.body}_{g.element}",
            frame.parentJoint,
            frames[g.body],
            to_se3(pin, joint_to_geom),
            g.geometry,
        )
        index_of.append(gmodel.addGeometryObject(obj))
    pair_bodies: list[tuple[str, str]] = []
    pairs = checker.active_pairs
    for i, j, k in zip(*checker.geometry.pair_indices(pairs), strict=True):
        a, b = index_of[i], index_of[j]
        gmodel.addCollisionPair(pin.CollisionPair(min(a, b), max(a, b)))
        pair_bodies.append(pair_key(*pairs[k]))
    return PinocchioRobot(
        model=model,
        collision_model=gmodel,
        frames=MappingProxyType(dict(frames)),
        chain_tips=MappingProxyType({c.name: frames[c.tip.name] for c in robot.all_chains}),
        tool_frames=MappingProxyType(
            {m.name: frames[m.tool_frame.name] for m in robot.manipulators}
        ),
        cameras=MappingProxyType({s.name: frames[s.root.name] for s in robot.cameras}),
        pair_bodies=tuple(pair_bodies),
        q_index=order,
    )
