"""Collision geometry: a world's collision elements as coal objects, built lazily and once.

Why trimesh for meshes: it reads STL, OBJ and (with pycollada) DAE from Python, so a mesh that
cannot be read becomes a :class:`~robotspec.errors.CollisionError` naming the body and the file,
rather than a crash inside a C++ loader. Triangles are taken as the file stores them (no merging,
no repair), which is what coal's own assimp loader (and so pinocchio) does, so distances agree to
rounding; the one exception is a triangle without area (a needle or a point), which is left out:
coal answers wrongly for a mesh that has one (see :func:`_with_area`). Each mesh file is read once
per :class:`MeshLibrary`, however many bodies use it.

Every geometry also gets an axis-aligned box in its body's frame: the checker's broad phase moves
those boxes with the body poses in numpy and calls coal only for pairs whose boxes overlap.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Literal

import numpy as np

from robotspec.arrays import F64, I64
from robotspec.errors import CollisionError, RobotSpecError
from robotspec.extras import Extra, require
from robotspec.files.meshes import read_triangles
from robotspec.model.geometry import Box, Capsule, Cylinder, Mesh, Shape, Sphere
from robotspec.model.world import Body, World

if TYPE_CHECKING:
    import coal

__all__ = [
    "CollisionGeometry",
    "GeometryModel",
    "MeshLibrary",
    "MissingMeshPolicy",
    "build_geometry_model",
    "import_coal",
]


MissingMeshPolicy = Literal["error", "skip"]
"""``error``: a missing or unreadable mesh raises a CollisionError naming the body and the path.
``skip``: the element is left out and the error is kept (as a warning) in
:attr:`GeometryModel.skipped`, for the caller to report; never a silent skip."""


#: coal, a dependency of robotspec, imported only by the collision queries.
COAL = Extra("coal", "coal")


def import_coal() -> Any:
    """The ``coal`` module, or a CollisionError saying how to install it.

    Why lazily: the rest of robotspec (validation, inspection, the driver) must work without the
    collision library installed.
    """
    return require(COAL, "collision checking", CollisionError)


@dataclass(frozen=True)
class CollisionGeometry:
    """One collision element of a body, ready for coal.

    ``body_T_geometry`` is the element's origin in its body frame; ``aabb_center`` and
    ``aabb_half`` bound the element in the body frame (a box that moves with the body).
    """

    body: str
    body_index: int
    element: int
    geometry: Any = field(repr=False, compare=False)
    body_T_geometry: F64 = field(repr=False, compare=False)  # noqa: N815 - a_T_b notation
    aabb_center: F64 = field(repr=False, compare=False)
    aabb_half: F64 = field(repr=False, compare=False)
    kind: str = "mesh"
    #: A mesh's vertices (V, 3, in the geometry's frame) and triangles (T, 3); None otherwise.
    triangles: tuple[F64, I64] | None = field(default=None, repr=False, compare=False)


@dataclass(frozen=True)
class GeometryModel:
    """All collision geometries of a world, body by body, with what was skipped and why."""

    geometries: tuple[CollisionGeometry, ...]
    skipped: tuple[RobotSpecError, ...] = ()

    @property
    def bodies(self) -> tuple[str, ...]:
        """Names of the bodies that have at least one geometry, in world order."""
        return tuple(dict.fromkeys(g.body for g in self.geometries))

    def of_body(self, body: str) -> tuple[CollisionGeometry, ...]:
        """The geometries of one body (empty if it has none)."""
        return tuple(g for g in self.geometries if g.body == body)

    def pair_indices(
        self, pairs: Sequence[tuple[str, str]]
    ) -> tuple[list[int], list[int], list[int]]:
        """The geometry pairs of body ``pairs``: first and second geometry, and the body pair.

        Every geometry of the first body against every geometry of the second, pair by pair in
        the given order (the order the checker's and pinocchio's pair lists share).
        """
        by_body: dict[str, list[int]] = {}
        for i, g in enumerate(self.geometries):
            by_body.setdefault(g.body, []).append(i)
        g1: list[int] = []
        g2: list[int] = []
        owner: list[int] = []
        for k, (a, b) in enumerate(pairs):
            for i in by_body.get(a, ()):
                for j in by_body.get(b, ()):
                    g1.append(i)
                    g2.append(j)
                    owner.append(k)
        return g1, g2, owner


class MeshLibrary:
    """Mesh files read into coal BVH models, each (file, scale) once.

    Why an object rather than a module cache: no global state; a caller that builds several
    checkers (tests, the matrix generator's workers) passes one library to share the loads.
    """

    def __init__(self) -> None:
        self._cache: dict[tuple[str, tuple[float, float, float]], tuple[Any, F64, I64]] = {}

    def __len__(self) -> int:
        return len(self._cache)

    def load(self, path: str, scale: tuple[float, float, float]) -> tuple[Any, F64, I64]:
        """The BVH model of ``path`` scaled by ``scale``, its vertices (V, 3) and triangles (T, 3).

        Raises a bare CollisionError (the caller adds the body) when the file cannot be read or
        holds no triangles with an area (triangles without one are left out: :func:`_with_area`).
        """
        key = (path, scale)
        hit = self._cache.get(key)
        if hit is not None:
            return hit
        vertices, faces = read_triangles(path, CollisionError)
        with np.errstate(over="ignore", invalid="ignore"):
            vertices = vertices * np.asarray(scale, dtype=np.float64)
        if not np.all(np.isfinite(vertices)):
            # Checked before coal sees them: its tree builder has no answer for infinities.
            raise CollisionError(
                f"mesh scaled by {scale} has vertices beyond the float range", kind="mesh"
            )
        faces = _with_area(vertices, np.asarray(faces, dtype=np.int64).reshape(-1, 3))
        if not len(faces):
            raise CollisionError(
                "mesh has no triangle with an area (the corners of each lie on one line)",
                kind="mesh",
            )
        coal = import_coal()
        model = coal.BVHModelOBBRSS()
        model.beginModel(len(faces), len(vertices))
        model.addVertices(vertices)
        model.addTriangles(faces)
        model.endModel()
        model.computeLocalAABB()
        triangles = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
        self._cache[key] = (model, vertices, triangles)
        return model, vertices, triangles


#: A triangle whose doubled area is at most this fraction of its longest edge squared has none.
_NEEDLE = 1e-12


def _with_area(vertices: F64, faces: I64) -> I64:
    """The triangles of ``faces`` (T, 3) that have an area: needles and points left out.

    Why: coal's distance between a sphere and a triangle divides by the triangle's normal; one
    triangle without area anywhere in a mesh made the mesh's distance to a sphere read minus the
    radius wherever the sphere was (and its collision test report contact 2 cm away). Real files
    have them: 688 of the 7865 triangles of example-robot-data's UR3 shoulder collision mesh,
    wrong at 79 of 200 random sphere positions. A needle's points lie within ``_NEEDLE`` times its
    size of its longest edge, which its neighbours share in a closed mesh, so leaving it out
    moves the surface by no more than that; an isolated needle (a wire) has no surface to keep.
    """
    size = float(np.abs(vertices).max()) if len(vertices) else 0.0
    unit = vertices / size if size > 0.0 else vertices  # no overflow or underflow when squared
    a, b, c = unit[faces[:, 0]], unit[faces[:, 1]], unit[faces[:, 2]]
    doubled = np.linalg.norm(np.cross(b - a, c - a), axis=1)
    longest = np.max(
        [((b - a) ** 2).sum(axis=1), ((c - b) ** 2).sum(axis=1), ((a - c) ** 2).sum(axis=1)], axis=0
    )
    kept: I64 = faces[doubled > _NEEDLE * longest]
    return kept


def _primitive(shape: Shape, coal: Any) -> tuple[Any, F64, str]:
    """A coal primitive and its half extents in its own frame."""
    g = shape.geometry
    if isinstance(g, Box):
        sx, sy, sz = g.size
        return coal.Box(sx, sy, sz), np.array([sx, sy, sz]) / 2.0, "box"
    if isinstance(g, Cylinder):
        r = g.radius
        return coal.Cylinder(r, g.length), np.array([r, r, g.length / 2.0]), "cylinder"
    if isinstance(g, Sphere):
        r = g.radius
        return coal.Sphere(r), np.array([r, r, r]), "sphere"
    if isinstance(g, Capsule):
        r = g.radius
        return coal.Capsule(r, g.length), np.array([r, r, g.length / 2.0 + r]), "capsule"
    raise TypeError(f"not a primitive: {g!r}")  # pragma: no cover


def _check_dimensions(shape: Shape, body: Body, file: str | None) -> bool:
    """Whether the element has a body; a negative or non-finite dimension is refused.

    A zero dimension (a sphere of radius 0, a flat box) is common in real files (ARMAR-4 has
    six): such an element has no volume to collide with, so it is left out (the caller lists
    every one in a warning) rather than stopping every collision command at the first.
    """
    g = shape.geometry
    values: Sequence[float]
    if isinstance(g, Box):
        values = g.size
    elif isinstance(g, Cylinder | Capsule):
        values = (g.radius, g.length)
    elif isinstance(g, Sphere):
        values = (g.radius,)
    else:
        # A negative mesh scale mirrors the mesh (Talos's right arm reuses the left arm's
        # meshes with scale 1 -1 1), as in every URDF reader; only zero flattens it.
        values = tuple(abs(v) for v in g.scale)
    if all(math.isfinite(v) and v >= 0 for v in values) and not isinstance(g, Mesh):
        return all(v > 0 for v in values)
    if not all(math.isfinite(v) and v > 0 for v in values):
        shown = g.scale if isinstance(g, Mesh) else values
        raise CollisionError(
            f"link '{body.name}': collision {type(g).__name__.lower()} has a non-positive or "
            f"non-finite dimension {tuple(shown)}",
            file=file,
            line=shape.line,
            kind="link",
            name=body.name,
        )
    return True


def _degenerate_warning(
    degenerate: Sequence[tuple[Body, Shape]], file: str | None
) -> CollisionError:
    """One warning listing every zero-sized primitive left out, at the first one's line."""
    listed = ", ".join(
        f"'{body.name}' ({type(shape.geometry).__name__.lower()}"
        f"{'' if shape.line is None else f', line {shape.line}'})"
        for body, shape in degenerate
    )
    n = len(degenerate)
    return CollisionError(
        f"{n} collision element{'s' if n != 1 else ''} of zero size left out (no volume to "
        f"collide with): {listed}",
        file=file,
        line=degenerate[0][1].line,
        kind="link",
        name=degenerate[0][0].name,
        severity="warning",
    )


def build_geometry_model(
    world: World,
    bodies: Sequence[str] | None = None,
    *,
    meshes: MeshLibrary | None = None,
    on_missing_mesh: MissingMeshPolicy = "error",
) -> GeometryModel:
    """Coal geometries of the collision elements of ``bodies`` (default: every body).

    A mesh that is unresolved (``Mesh.path is None``), missing or unreadable raises a
    CollisionError naming the body and the file; with ``on_missing_mesh="skip"`` it is left out
    and listed in ``skipped`` instead.
    """
    coal = import_coal()
    library = meshes if meshes is not None else MeshLibrary()
    wanted = None if bodies is None else set(bodies)
    out: list[CollisionGeometry] = []
    skipped: list[RobotSpecError] = []
    degenerate: list[tuple[Body, Shape]] = []
    for body in world.bodies:
        if not body.collisions or (wanted is not None and body.name not in wanted):
            continue
        for k, shape in enumerate(body.collisions):
            if not _check_dimensions(shape, body, world.source):
                degenerate.append((body, shape))
                continue
            origin = np.asarray(shape.origin, dtype=np.float64)
            rot, trans = origin[:3, :3], origin[:3, 3]
            triangles: tuple[F64, I64] | None = None
            if isinstance(shape.geometry, Mesh):
                try:
                    geom, vertices, faces = _load_mesh(library, shape.geometry, body)
                except CollisionError as exc:
                    if on_missing_mesh == "error":
                        raise
                    skipped.append(exc.with_severity("warning"))
                    continue
                in_body = vertices @ rot.T + trans
                lo, hi = in_body.min(axis=0), in_body.max(axis=0)
                center, half, kind = (lo + hi) / 2.0, (hi - lo) / 2.0, "mesh"
                triangles = (vertices, faces)
            else:
                geom, local_half, kind = _primitive(shape, coal)
                center, half = trans.copy(), np.abs(rot) @ local_half
            out.append(
                CollisionGeometry(
                    body=body.name,
                    body_index=body.index,
                    element=k,
                    geometry=geom,
                    body_T_geometry=origin.copy(),
                    aabb_center=center,
                    aabb_half=half,
                    kind=kind,
                    triangles=triangles,
                )
            )
    if degenerate:
        skipped.insert(0, _degenerate_warning(degenerate, world.source))
    return GeometryModel(geometries=tuple(out), skipped=tuple(skipped))


def _load_mesh(
    library: MeshLibrary, mesh: Mesh, body: Body
) -> tuple[coal.BVHModelOBBRSS, F64, I64]:
    if mesh.path is None:
        raise CollisionError(
            f"link '{body.name}': collision mesh '{mesh.uri}' was not resolved to a file",
            kind="mesh",
            name=body.name,
            file=mesh.uri,
        )
    try:
        return library.load(mesh.path, mesh.scale)
    except CollisionError as exc:
        raise CollisionError(
            f"link '{body.name}': {exc.message} ('{mesh.path}')",
            file=mesh.path,
            kind="mesh",
            name=body.name,
        ) from None
