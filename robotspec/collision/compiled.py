"""A checker's built form: its geometries, the geometry pairs to test, and per-thread coal objects.

Why a module of its own: what is built once (meshes read, coal functors, the broad phase's table,
the meshes' box trees) and only read afterwards is apart from what a query writes (each thread's
:class:`Scratch`). The checker builds one :class:`Compiled` on its first query, under its lock,
and shares it between threads.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from robotspec.arrays import I64
from robotspec.collision import meshcore
from robotspec.collision.shapes import (
    CollisionGeometry,
    GeometryModel,
    MeshLibrary,
    MissingMeshPolicy,
    build_geometry_model,
    import_coal,
)
from robotspec.model import kincore
from robotspec.model.world import World

__all__ = ["Compiled", "Scratch", "compile_pairs"]


@dataclass(frozen=True)
class Compiled:
    """Arrays of the built checker: geometries and the pairs to test, in flat index form."""

    model: GeometryModel
    pair_geom1: I64  # (Q,) geometry indices of each geometry pair
    pair_geom2: I64
    pair_of: I64  # (Q,) index of the body pair each geometry pair belongs to
    collide: tuple[Any, ...]  # coal.ComputeCollision per geometry pair
    broad: object  # the C core's table of geometries and pairs (_kincore.geoms)
    meshes: object | None  # box trees of the mesh geometries (_meshcore.mesh_set), if any pair
    two_meshes: list[bool]  # per geometry pair: both are meshes (so `meshes` can prove them apart)

    # Python lists for the per-pair loop (indexing a list is several times cheaper).
    pair_geom1_list: list[int] = field(init=False)
    pair_geom2_list: list[int] = field(init=False)
    pair_of_list: list[int] = field(init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "pair_geom1_list", self.pair_geom1.tolist())
        object.__setattr__(self, "pair_geom2_list", self.pair_geom2.tolist())
        object.__setattr__(self, "pair_of_list", self.pair_of.tolist())


class Scratch:
    """One thread's coal objects that a query writes: transforms, a request and a result.

    Why per thread: a query writes every geometry's pose into its transform and then asks coal,
    and reads coal's answer from the result after the call; a second thread writing the same
    transforms, or clearing the same result, in between changes the first one's answer (a shared
    checker gave wrong distances and missed collisions). Kept rather than made per query: the
    PR2's 32 transforms cost more to create than a whole ``in_collision``.
    """

    def __init__(self, coal: Any, n_geometries: int) -> None:
        self.transforms = tuple(coal.Transform3s() for _ in range(n_geometries))
        self.margin = math.nan
        self.request = coal.CollisionRequest()
        self.result = coal.CollisionResult()
        #: The fallback's free balls (:mod:`.free_balls`), made on their first use.
        self.free_balls: Any = None

    def collision(self, margin: float) -> tuple[Any, Any]:
        """Coal's collision request for ``margin`` and the result to reuse."""
        if margin != self.margin:
            self.request.security_margin = margin
            self.margin = margin
        return self.request, self.result


def compile_pairs(
    world: World,
    pairs: Sequence[tuple[str, str]],
    bodies: Sequence[str],
    *,
    meshes: MeshLibrary,
    on_missing_mesh: MissingMeshPolicy,
) -> Compiled:
    """The built form of checking ``pairs`` of ``world`` (``bodies``: theirs, in world order)."""
    coal = import_coal()
    model = build_geometry_model(world, bodies, meshes=meshes, on_missing_mesh=on_missing_mesh)
    geoms = model.geometries
    g1, g2, owner = model.pair_indices(pairs)
    pair_geom1 = np.array(g1, dtype=np.int64)
    pair_geom2 = np.array(g2, dtype=np.int64)
    return Compiled(
        model=model,
        pair_geom1=pair_geom1,
        pair_geom2=pair_geom2,
        pair_of=np.array(owner, dtype=np.int64),
        collide=tuple(
            coal.ComputeCollision(geoms[i].geometry, geoms[j].geometry)
            for i, j in zip(g1, g2, strict=True)
        ),
        broad=kincore.core().geoms(
            np.array([g.body_index for g in geoms], dtype=np.int64),
            np.array([g.body_T_geometry for g in geoms], dtype=np.float64).reshape(-1, 4, 4),
            np.array([g.aabb_center for g in geoms], dtype=np.float64).reshape(-1, 3),
            np.array([g.aabb_half for g in geoms], dtype=np.float64).reshape(-1, 3),
            pair_geom1,
            pair_geom2,
            len(world.bodies),
        ),
        meshes=_mesh_trees(geoms, g1, g2),
        two_meshes=[
            geoms[i].triangles is not None and geoms[j].triangles is not None
            for i, j in zip(g1, g2, strict=True)
        ],
    )


def _mesh_trees(geoms: Sequence[CollisionGeometry], g1: list[int], g2: list[int]) -> object | None:
    """Box trees of the meshes in some pair (None if no pair has a mesh)."""
    used = {k for k in (*g1, *g2) if geoms[k].triangles is not None}
    if not used:
        return None
    # The triangles are finite and in range: MeshLibrary refused any mesh that is not.
    trees: object = meshcore.core().mesh_set(
        [g.triangles if k in used else None for k, g in enumerate(geoms)]
    )
    return trees
