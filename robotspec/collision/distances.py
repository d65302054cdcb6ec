"""Minimum distances between a checker's body pairs: convex hulls first, coal's meshes when needed.

Why a module of its own: distances are the checker's second query family, with their own coal
functors (``ComputeDistance``, on the meshes and on their convex hulls), their own tolerances and
the qhull guard; collision queries share only the built geometry (:mod:`.compiled`) with them.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np

from robotspec.arrays import F64
from robotspec.collision import meshcore
from robotspec.collision.compiled import Compiled
from robotspec.collision.shapes import CollisionGeometry, import_coal

__all__ = ["PairDistance", "distance_functors", "distance_rows", "hull_functors"]

#: Samples per block: bounds the memory of the pose arrays (~10 MB).
_BLOCK = 512
#: Hull distances: GJK's tolerance (polytopes end exactly; curved primitives need it tight to agree
#: with coal's exact mesh distances), the gap below which hulls count as touching (coal answers,
#: with its conventions for contact), and how near a hull's closest point must be to the mesh.
_HULL_TOLERANCE = 1e-10
_HULL_GAP = 1e-5
_ON_SURFACE = 1e-9
#: Relative thickness below which a mesh counts as flat and gets no hull (see ``_solid``).
_FLAT = 1e-6

Rows = Iterator[tuple[list[float], list[tuple[list[float], list[float]] | None]]]


@dataclass(frozen=True)
class PairDistance:
    """The minimum distance between two bodies and the closest points (world root frame, m).

    ``distance`` is coal's: negative for penetrating primitives, 0 or coal's estimate for meshes
    in contact; ``inf`` when a body has no geometry left (a skipped mesh).
    """

    link1: str
    link2: str
    distance: float
    point1: tuple[float, float, float]
    point2: tuple[float, float, float]


def distance_functors(c: Compiled) -> tuple[Any, ...]:
    """Coal's distance functor per geometry pair."""
    coal = import_coal()
    geoms = c.model.geometries
    return tuple(
        coal.ComputeDistance(geoms[i].geometry, geoms[j].geometry)
        for i, j in zip(c.pair_geom1_list, c.pair_geom2_list, strict=True)
    )


def hull_functors(c: Compiled) -> tuple[Any, ...]:
    """Per geometry pair with a mesh: coal's distance with each mesh replaced by its hull."""
    coal = import_coal()
    geoms = c.model.geometries
    hulls = {
        k: h
        for k in {*c.pair_geom1_list, *c.pair_geom2_list}
        if geoms[k].triangles is not None and (h := _hull(geoms[k])) is not None
    }

    def hulled(i: int, j: int) -> bool:
        """The pair has a mesh, and every mesh of it has a hull."""
        mesh = [k for k in (i, j) if geoms[k].triangles is not None]
        return bool(mesh) and all(k in hulls for k in mesh)

    return tuple(
        coal.ComputeDistance(hulls.get(i, geoms[i].geometry), hulls.get(j, geoms[j].geometry))
        if hulled(i, j)
        else None
        for i, j in zip(c.pair_geom1_list, c.pair_geom2_list, strict=True)
    )


def distance_rows(
    c: Compiled,
    functors: tuple[tuple[Any, ...], tuple[Any, ...]],
    transforms: tuple[Any, ...],
    n_pairs: int,
    place: Callable[[F64], F64],
    qs: F64,
    with_points: bool,
) -> Rows:
    """Per configuration of ``qs``: each pair's distance and (``with_points``) closest points.

    ``functors`` are the pairs' mesh and hull functors, ``transforms`` the calling thread's coal
    transforms (one per geometry), ``place(block)`` every geometry's pose (n, G, 4, 4).

    A pair with a mesh asks coal first for the distance of the meshes' convex hulls (GJK on
    two convex sets: a few microseconds, where the meshes' own distance costs coal 50-600).
    The hulls enclose the meshes, so their distance is at most the meshes'; when both closest
    points lie on the meshes themselves (checked in the C core, within ``_ON_SURFACE``), the
    meshes are no nearer than those two points, so the hulls' answer is the meshes' (to a
    nanometre). Otherwise (a closest point across a concavity, or hulls that touch) coal
    computes the meshes' distance. Everything per pair stays in Python lists: numpy scalar
    indexing and small arrays per pair cost more than coal's own time on robots with many
    small pairs.
    """
    coal = import_coal()
    fns, hulls = functors
    req = coal.DistanceRequest()  # coal >= 3 always fills the nearest points
    res = coal.DistanceResult()
    hreq = coal.DistanceRequest()
    hreq.gjk_tolerance = _HULL_TOLERANCE
    hres = coal.DistanceResult()
    tf = transforms
    geoms = c.model.geometries
    # The transforms are updated in place, so each pair's functors and transforms are bound once.
    work = tuple(
        zip(
            fns,
            hulls,
            (tf[i] for i in c.pair_geom1_list),
            (tf[j] for j in c.pair_geom2_list),
            c.pair_of_list,
            c.pair_geom1_list,
            c.pair_geom2_list,
            (geoms[i].triangles is not None for i in c.pair_geom1_list),
            (geoms[j].triangles is not None for j in c.pair_geom2_list),
            strict=True,
        )
    )
    clear, near1, near2 = res.clear, res.getNearestPoint1, res.getNearestPoint2
    hclear, hnear1, hnear2 = hres.clear, hres.getNearestPoint1, hres.getNearestPoint2
    meshes, on_surface = c.meshes, meshcore.core().on_surface
    for start in range(0, qs.shape[0], _BLOCK):
        poses = place(qs[start : start + _BLOCK])
        for r in range(poses.shape[0]):
            for g, pose in enumerate(poses[r]):
                tf[g].setRotation(pose[:3, :3])
                tf[g].setTranslation(pose[:3, 3])
            best = [math.inf] * n_pairs
            near: list[tuple[list[float], list[float]] | None] = [None] * n_pairs
            for fn, hull, t1, t2, p, i, j, mesh1, mesh2 in work:
                if hull is not None:
                    hclear()
                    d = hull(t1, t2, hreq, hres)
                    if d > _HULL_GAP:
                        x1, x2 = hnear1(), hnear2()
                        if (not mesh1 or on_surface(meshes, poses, r, i, x1, _ON_SURFACE)) and (
                            not mesh2 or on_surface(meshes, poses, r, j, x2, _ON_SURFACE)
                        ):
                            if d < best[p]:
                                best[p] = d
                                if with_points:
                                    near[p] = (x1.tolist(), x2.tolist())
                            continue
                clear()
                d = fn(t1, t2, req, res)
                if d < best[p]:
                    best[p] = d
                    if with_points:
                        near[p] = (near1().tolist(), near2().tolist())
            yield best, near


def _hull(geom: CollisionGeometry) -> Any:
    """The convex hull of a mesh geometry as a coal convex, or None (a flat mesh has none).

    A mesh with no volume (a plate, a sliver, collinear or repeated points) never reaches qhull:
    coal 3.0 does not turn qhull's refusal of a flat point set into an exception but crashes the
    process (SIGSEGV). Such a mesh gets no hull, so its pairs use coal's mesh distance.
    """
    model = geom.geometry
    if getattr(model, "convex", None) is None and (
        geom.triangles is None or not _solid(geom.triangles[0])
    ):
        return None
    try:
        if getattr(model, "convex", None) is None:
            model.buildConvexHull(False, "Qt")  # qhull: the hull's vertices are mesh vertices
        return model.convex
    except Exception:  # noqa: BLE001 - qhull refuses flat or degenerate point sets
        return None


def _solid(vertices: F64) -> bool:
    """Whether qhull can hull ``vertices`` (V, 3): at least four points, not (nearly) flat.

    The test: the points' extent across their plane of best fit (the last principal axis) must
    exceed ``_FLAT`` times their size (their largest extent, or their distance from the origin
    if larger: qhull's rounding grows with the coordinates). Random near-flat point sets crash
    qhull up to about 1e-8 and never from 1e-7 on, so ``_FLAT`` keeps a factor of ten.
    """
    points = np.unique(np.asarray(vertices, dtype=np.float64).reshape(-1, 3), axis=0)
    if len(points) < 4:
        return False
    centred = points - points.mean(axis=0)
    axes = np.linalg.svd(centred, full_matrices=False)[2]
    along = centred @ axes.T
    extent = along.max(axis=0) - along.min(axis=0)
    size = max(float(extent[0]), float(np.abs(points).max()))
    return bool(extent[2] > _FLAT * size)
