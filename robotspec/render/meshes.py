"""Triangles of a body's visual (or collision) elements, in the body's frame.

Why our own tessellation of primitives: both the software rasterizer and the browser view need
plain ``(vertices, faces)`` arrays, and a box, cylinder, sphere or capsule becomes one in a few
lines of numpy; only mesh files go through trimesh. Each (file, scale) is read once per
:class:`TriangleLibrary`, and meshes above a face budget are thinned by vertex clustering (pure
numpy, no optional decimation package), which keeps the silhouette a picture needs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from robotspec.arrays import F64, I64
from robotspec.errors import DescriptionError, RobotSpecError
from robotspec.files.meshes import read_triangles
from robotspec.model.geometry import Box, Capsule, Cylinder, Mesh, Shape, Sphere
from robotspec.model.world import Body

__all__ = ["MissingMeshPolicy", "Triangles", "TriangleLibrary", "cluster_decimate"]


MissingMeshPolicy = Literal["error", "skip"]
"""``error``: an unreadable mesh raises a DescriptionError naming the body and the file.
``skip``: the element is left out and the error kept as a warning for the caller to print."""

#: Faces above which a mesh file is thinned; PR2's meshes are far below, scans are not.
FACE_BUDGET = 20_000
_SEGMENTS = 24


@dataclass(frozen=True)
class Triangles:
    """A triangle soup in some frame: vertices (V, 3) and faces (F, 3) indexing them."""

    vertices: F64 = field(repr=False, compare=False)
    faces: I64 = field(repr=False, compare=False)

    def transformed(self, pose: F64) -> Triangles:
        """The same triangles moved by a 4x4 pose."""
        return Triangles(self.vertices @ pose[:3, :3].T + pose[:3, 3], self.faces)

    @property
    def count(self) -> int:
        """How many faces."""
        return int(len(self.faces))


class TriangleLibrary:
    """Mesh files read into triangles, each (file, scale) once (no global cache)."""

    def __init__(self, face_budget: int = FACE_BUDGET) -> None:
        self.face_budget = face_budget
        self._cache: dict[tuple[str, tuple[float, ...]], Triangles] = {}

    def shape(self, shape: Shape, body: Body) -> Triangles:
        """The triangles of one element in the body frame (its origin applied)."""
        g = shape.geometry
        if isinstance(g, Mesh):
            local = self._mesh(g, body)
        elif isinstance(g, Box):
            local = box(g.size)
        elif isinstance(g, Cylinder):
            local = cylinder(g.radius, g.length)
        elif isinstance(g, Sphere):
            local = sphere(g.radius)
        elif isinstance(g, Capsule):
            local = capsule(g.radius, g.length)
        else:  # pragma: no cover - GeometryShape is closed
            raise TypeError(f"unknown geometry {g!r}")
        return local.transformed(np.asarray(shape.origin, dtype=np.float64))

    def _mesh(self, mesh: Mesh, body: Body) -> Triangles:
        if mesh.path is None:
            # Why the reason: "not resolved" alone does not tell a missing package from a file
            # outside the allowed folders, which only -P or ROS_PACKAGE_PATH can allow.
            why = f": {mesh.problem.message}" if mesh.problem is not None else ""
            raise DescriptionError(
                f"link '{body.name}': mesh '{mesh.uri}' was not resolved to a file{why}",
                file=mesh.uri,
                kind="mesh",
                name=body.name,
            )
        key = (mesh.path, tuple(float(s) for s in mesh.scale))
        hit = self._cache.get(key)
        if hit is None:
            try:
                vertices, faces = read_triangles(mesh.path, DescriptionError)
            except RobotSpecError as exc:
                raise DescriptionError(
                    f"link '{body.name}': {exc.message}", file=exc.file, kind="mesh", name=body.name
                ) from None
            if len(faces) > self.face_budget:
                vertices, faces = cluster_decimate(vertices, faces, self.face_budget)
            hit = Triangles(vertices * np.asarray(mesh.scale, dtype=np.float64), faces)
            self._cache[key] = hit
        return hit


def cluster_decimate(vertices: F64, faces: I64, budget: int) -> tuple[F64, I64]:
    """Thin a mesh to about ``budget`` faces by merging vertices on a grid.

    Why clustering: it needs nothing beyond numpy and never fails on a non-manifold mesh; the
    grid is refined until the face count fits, then collapsed faces are dropped.
    """
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    extent = float(np.max(hi - lo)) or 1.0
    cells = max(8, int(math.sqrt(budget)))
    best = (vertices, faces)
    while cells >= 2:
        key = np.floor((vertices - lo) / extent * cells).astype(np.int64)
        _, cluster, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
        inverse = inverse.reshape(-1)
        counts = np.bincount(inverse)
        merged = np.zeros((len(cluster), 3))
        np.add.at(merged, inverse, vertices)
        merged /= counts[:, None]
        f = inverse[faces]
        keep = (f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2])
        f = f[keep]
        # Faces that collapsed onto the same three clusters are drawn once.
        _, first = np.unique(np.sort(f, axis=1), axis=0, return_index=True)
        best = (merged, f[np.sort(first)])
        if len(best[1]) <= budget:
            break
        cells = int(cells * 0.7)
    return best


def box(size: tuple[float, float, float]) -> Triangles:
    """A box centred on its frame: 12 triangles."""
    h = np.asarray(size, dtype=np.float64) / 2.0
    corners = np.array(
        [[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=np.float64
    )
    faces = np.array(
        [
            [0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5],  # -x, +x
            [0, 4, 5], [0, 5, 1], [2, 3, 7], [2, 7, 6],  # -y, +y
            [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3],  # -z, +z
        ],
        dtype=np.int64,
    )  # fmt: skip
    return Triangles(corners * h, faces)


def _lathe(profile: F64, segments: int = _SEGMENTS) -> Triangles:
    """A surface of revolution about z from a (K, 2) profile of (radius, z), end to end."""
    angles = np.linspace(0.0, 2.0 * math.pi, segments, endpoint=False)
    k = len(profile)
    r, z = profile[:, 0], profile[:, 1]
    xs = r[:, None] * np.cos(angles)[None, :]
    ys = r[:, None] * np.sin(angles)[None, :]
    zs = np.broadcast_to(z[:, None], xs.shape)
    vertices = np.stack([xs, ys, zs], axis=-1).reshape(-1, 3)
    ring = np.arange(segments)
    nxt = (ring + 1) % segments
    faces: list[I64] = []
    for i in range(k - 1):
        a, b = i * segments + ring, i * segments + nxt
        c, d = (i + 1) * segments + ring, (i + 1) * segments + nxt
        faces.append(np.stack([a, b, d], axis=1))
        faces.append(np.stack([a, d, c], axis=1))
    return Triangles(vertices, np.concatenate(faces).astype(np.int64))


def cylinder(radius: float, length: float) -> Triangles:
    """A capped cylinder along z, centred on its frame."""
    h = length / 2.0
    profile = np.array([[0.0, -h], [radius, -h], [radius, h], [0.0, h]])
    return _lathe(profile)


def sphere(radius: float) -> Triangles:
    """A UV sphere centred on its frame."""
    t = np.linspace(-math.pi / 2.0, math.pi / 2.0, _SEGMENTS // 2 + 1)
    profile = np.stack([radius * np.cos(t), radius * np.sin(t)], axis=1)
    return _lathe(profile)


def capsule(radius: float, length: float) -> Triangles:
    """A capsule along z: a cylinder of ``length`` with hemispherical caps."""
    h = length / 2.0
    t = np.linspace(0.0, math.pi / 2.0, _SEGMENTS // 4 + 1)
    low = np.stack([radius * np.sin(t), -h - radius * np.cos(t)], axis=1)
    high = np.stack([radius * np.cos(t), h + radius * np.sin(t)], axis=1)
    return _lathe(np.concatenate([low, high]))
