"""The mesh core's entry points without its proofs: every candidate is left to coal.

Why this is enough: ``_meshcore.c`` only accelerates. A pair it proves apart or crossing is one
coal answers the same way (that is what its proofs are checked against), and a hull's closest
point it finds on the mesh only lets the checker skip coal's exact mesh distance. So a fallback
that proves nothing and finds no point on a surface gives every answer, from coal, the same to
coal's tolerance, only slower on nearly touching meshes (see benchmarks/bench_fallback.py).

Crossing proofs in numpy were measured here and not kept (issue 34, commits f9e2470 and 5678a2a:
``_crossing_py.py`` and its tests against coal). By continuity, a piece of one mesh's surface
with a vertex in a grid cell inside the other, closed and oriented mesh and a vertex outside its
box must meet its surface, so coal reports a collision: never wrong on PR2, Talos and random
poses, they prove a third of the PR2's colliding candidates of a batch of 64 (27-33 of 80-93;
Talos 127 of 286), but half the PR2's meshes are open, the deep crossings they catch are not the
ones coal is slowest on, and one vectorised pass over a block costs numpy about as much as the
coal calls it spares (PR2: 1.1 ms for 0.6 ms of coal; Talos: 5.2 ms for 2.1 ms). Interleaved,
the fallback's ``collisions_batch`` of 64 ran at 0.97x, ``in_collision_batch`` 0.78x.

The arguments are read and checked as the C core reads and checks them, in its order (see
``_meshcore.pyi`` and :mod:`robotspec.model._core_args`), so a caller's mistake raises the same
exception with the same message whichever core runs; :mod:`robotspec.collision.meshcore` chooses.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from robotspec.model._core_args import from_any, index, real, table

_INT32_MAX = 2**31 - 1


@dataclass(frozen=True)
class MeshSet:
    """How many geometries a checker has, and which are meshes."""

    n: int
    is_mesh: tuple[bool, ...]


def _mesh(item: object) -> None:
    """Check one (vertices (V, 3), triangles (T >= 1, 3)) mesh as the C core's ``tree_new`` does."""
    if not isinstance(item, tuple) or len(item) != 2:
        raise TypeError("mesh_set: each mesh is (vertices, triangles) or None")
    v = from_any(item[0], np.float64, 2, 2)
    f = from_any(item[1], np.int64, 2, 2)
    if v.shape[1] != 3 or f.shape[1] != 3 or not 1 <= f.shape[0] <= _INT32_MAX // 4:
        raise ValueError("a mesh needs vertices (V, 3) and triangles (T >= 1, 3)")
    # Corner by corner, as the C core reads them: the first bad one says what is wrong.
    corners = f.reshape(-1)
    out = (corners < 0) | (corners >= v.shape[0])
    if out.all():  # (no vertex at all, or none in range: nothing to read)
        raise ValueError("a triangle refers to a vertex out of range")
    infinite = ~np.isfinite(v[np.where(out, 0, corners)]).all(axis=1) & ~out
    bad = np.flatnonzero(out | infinite)
    if bad.size:
        if out[bad[0]]:
            raise ValueError("a triangle refers to a vertex out of range")
        raise ValueError("a mesh vertex is not finite")


def mesh_set(meshes: Any) -> object:
    try:
        items = list(meshes)
    except TypeError:
        raise TypeError("mesh_set needs a sequence") from None
    for item in items:
        if item is not None:
            _mesh(item)
    return MeshSet(len(items), tuple(item is not None for item in items))


def _set_of(obj: object) -> MeshSet:
    return table(obj, MeshSet, "a mesh set (from mesh_set())")


def _eps(eps: float) -> None:
    if not (eps >= 1e-9 and math.isfinite(eps)):
        raise ValueError("eps must be finite and >= 1e-9")


def apart(meshes: object, poses: Any, rows: Any, pairs: Any, g1: Any, g2: Any, eps: float) -> Any:
    eps = real(eps)
    s = _set_of(meshes)
    _eps(eps)
    p = from_any(poses, np.float64, 4, 4)
    r, k = from_any(rows, np.int64, 1, 1), from_any(pairs, np.int64, 1, 1)
    a, b = from_any(g1, np.int64, 1, 1), from_any(g2, np.int64, 1, 1)
    n, ng = p.shape[0], p.shape[1]
    if ng != s.n or p.shape[2:] != (4, 4) or len(k) != len(r) or len(b) != len(a):
        raise ValueError("apart: arrays of the wrong shape")
    if len(r):
        bad = (r < 0) | (r >= n) | (k < 0) | (k >= len(a))
        if not bad.any():
            i, j = a[k], b[k]
            bad = (i < 0) | (i >= ng) | (j < 0) | (j >= ng)
        if bad.any():
            raise ValueError("apart: a candidate is out of range")
    return np.zeros(len(r), dtype=np.uint8)  # nothing proven: coal decides every candidate


def _borrowable(obj: object, who: str, what: str) -> np.ndarray[Any, Any]:
    """The array the C core would read in place (see ``borrowable`` in ``_meshcore.c``)."""
    if not isinstance(obj, np.ndarray) or obj.dtype.type is not np.float64:
        raise TypeError(f"{who}: {what} must be a float64 numpy array")
    if not (obj.dtype.isnative and obj.flags.aligned and obj.flags.c_contiguous):
        raise TypeError(f"{who}: {what} must be native-order, aligned and C-contiguous")
    return obj


def _poses(obj: object, s: MeshSet, who: str) -> np.ndarray[Any, Any]:
    p = _borrowable(obj, who, "poses")
    if p.ndim != 4 or p.shape[1:] != (s.n, 4, 4):
        raise ValueError(f"{who}: poses of the wrong shape (N, G, 4, 4)")
    return p


def apart_one(meshes: object, poses: Any, row: int, i: int, j: int, eps: float) -> int:
    row, i, j, eps = index(row), index(i), index(j), real(eps)
    s = _set_of(meshes)
    p = _poses(poses, s, "apart_one")
    if not (0 <= row < p.shape[0] and 0 <= i < s.n and 0 <= j < s.n):
        raise ValueError("apart_one: a candidate is out of range")
    _eps(eps)
    return 0


def on_surface(meshes: object, poses: Any, row: int, g: int, point: Any, tol: float) -> bool:
    row, g, tol = index(row), index(g), real(tol)
    s = _set_of(meshes)
    p = _poses(poses, s, "on_surface")
    x = _borrowable(point, "on_surface", "point")
    if x.size != 3:
        raise ValueError("on_surface: point of the wrong shape (3 values)")
    if not (0 <= row < p.shape[0] and 0 <= g < s.n and tol >= 0.0 and math.isfinite(tol)):
        raise ValueError("on_surface: row, geometry or tolerance out of range")
    return False  # not found: the checker asks coal for the meshes' own distance
