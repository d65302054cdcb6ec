"""Crossing proofs in numpy for the fallback mesh core: meshes whose surfaces must intersect.

Why: without the C core, coal decides every broad-phase candidate, and a colliding pair of meshes
costs coal about six times a free one (on the PR2's batch of 64, most of coal's time). Coal's
mesh-mesh test reports surface contact only (a triangle of A within the margin of a triangle of
B; a mesh wholly inside another is free), so a proof must show that the two *surfaces* meet.

The proof, by continuity: let A be closed and consistently oriented (every edge shared by exactly
two triangles, once in each direction, vertices merged where their coordinates are equal). Its
winding number is then an integer, constant off its surface: non-zero in a ball inside A that
does not touch the surface, zero outside any box holding A. If one connected piece of B's surface
has a vertex in such a ball and another outside the box (each by more than ``eps``, which covers
the rounding of poses), a path along that piece joins points of different winding numbers, so it
meets A's surface: some triangle of B touches some triangle of A, and coal reports a collision
whatever the margin. Both directions are tried (B's vertices against A's balls and box, A's
against B's). A mesh that is not closed and oriented gets no balls and is never the proof's A.

Everything a proof reads is made once per mesh (:func:`prepare`): a few balls inside the mesh
(chosen on a grid: largest covering first), its oriented box, and a fixed spread subset of its
vertices with their connected piece. A call tests every candidate of a block in one vectorised
numpy pass (:func:`crossing`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from robotspec.arrays import F64, I64

__all__ = ["MeshProof", "Proofs", "crossing", "prepare", "stack"]

#: Vertices of a mesh tested per candidate (spread over its surface by farthest-point sampling).
SAMPLES = 32
#: Cells (about) of the grid that marks where a closed mesh's inside is (cubic cells).
CELLS = 4096
#: How far (m) a cell marked inside is at least from the surface (so a query's ``eps`` beyond it
#: proves nothing inside: coal decides).
CLEARANCE = 1e-4
#: Connected pieces of a mesh's surface told apart (31 bits inside, 31 outside, of an int64);
#: smaller ones unsampled.
PIECES = 31
#: The mesh core's code of a candidate proven crossing (robotspec.collision.narrow.CROSS).
CROSS = 2
#: Cell codes: wholly inside the surface, wholly outside the box (both by CLEARANCE at least).
INSIDE, OUTSIDE = 1, 2
#: Relative slack on a box's half extents: the rounding of their computation.
_SLACK = 1e-9


@dataclass(frozen=True)
class MeshProof:
    """What the crossing proof needs of one mesh, in the mesh's frame.

    ``points`` (K, 3) spread vertices and ``bits`` (K,) ``1 << piece`` of the connected piece of
    the surface each lies on. A grid of cubic cells over an oriented box holding the mesh (and
    :data:`CLEARANCE` more), with one layer more all round: ``to_grid`` (4, 4) maps the mesh
    frame to cell units from the grid's corner, ``dims`` (3,) cells, ``codes`` (flat, C order)
    ``INSIDE`` for a cell at least :data:`CLEARANCE` inside the surface (none when the mesh is
    not closed and oriented), ``OUTSIDE`` for the outer layer (at least that far outside the
    box), 0 otherwise.
    """

    points: F64
    bits: I64
    to_grid: F64
    dims: I64
    codes: NDArray[np.uint8]


@dataclass(frozen=True)
class Proofs:
    """Every geometry's :class:`MeshProof` stacked and padded, indexed by geometry (G first)."""

    points: F64  # (G, K, 4) homogeneous
    bits: I64  # (G, K)
    to_grid: F64  # (G, 3, 4)
    top: F64  # (G, 3) the last cell's index per axis
    strides: I64  # (G, 3) of the flat codes
    codes: NDArray[np.uint8]  # (G, C)
    closed: NDArray[np.bool_]  # (G,): some cell is inside
    lut: I64  # (G, K, 3) per point and cell code: 0, its piece's bit, that bit << 31
    inside_lo: F64  # (G, 3) the inside cells' bounding box, in cells
    inside_hi: F64  # (G, 3)
    ball: F64  # (G, 4) a ball around the points: centre (homogeneous, mesh frame)
    radius: F64  # (G,) its radius (m)
    cell: F64  # (G,) the cell's side (m)
    core: F64  # (G, 4) a ball around the inside cells: centre (homogeneous, mesh frame)
    core_radius: F64  # (G,) its radius (m); -inf where no cell is inside


def _merged(vertices: F64, faces: I64) -> tuple[F64, I64]:
    """Vertices with equal coordinates made one (the same point), and faces re-indexed.

    Compared as bytes (``+ 0.0`` makes -0.0 and 0.0 one); two points left apart only cost
    proofs (a surface that looks open), never a wrong one.
    """
    v = np.ascontiguousarray(vertices + 0.0)
    keys = v.view(np.dtype((np.void, 24))).reshape(-1)
    _, first, inverse = np.unique(keys, return_index=True, return_inverse=True)
    return v[first], inverse.reshape(-1)[faces]


def _closed_oriented(faces: I64) -> bool:
    """Every edge is shared by two triangles, once in each direction (a 2-cycle)."""
    start = faces.reshape(-1)
    end = faces[:, [1, 2, 0]].reshape(-1)
    if (start == end).any():
        return False
    n = int(faces.max()) + 1
    code = np.sort(start * n + end)
    if (code[1:] == code[:-1]).any():
        return False  # a directed edge twice
    # Each directed edge once; its reverse must be there too.
    reverse = end * n + start
    return bool(np.isin(reverse, code, assume_unique=True).all())


def _pieces(n_vertices: int, faces: I64) -> I64:
    """The connected piece of the surface (triangles sharing a vertex) of each vertex.

    Labels spread as minima over each triangle's corners, with pointer jumping, until stable.
    """
    label = np.arange(n_vertices, dtype=np.int64)
    corners = faces.reshape(-1)
    while True:
        least = label[faces].min(axis=1)
        new = label.copy()
        np.minimum.at(new, corners, np.repeat(least, 3))
        new = new[new]  # a label's own label: jumps along chains
        if (new == label).all():
            break
        label = new
    _, out = np.unique(label, return_inverse=True)
    return out.astype(np.int64)


def _spread(points: F64, k: int) -> I64:
    """Indices of ``k`` spread points (farthest-point sampling from the first extreme)."""
    if len(points) <= k:
        return np.arange(len(points), dtype=np.int64)
    chosen = [int(np.argmax(points[:, 0]))]
    d = ((points - points[chosen[0]]) ** 2).sum(axis=1)
    for _ in range(k - 1):
        nxt = int(np.argmax(d))
        chosen.append(nxt)
        d = np.minimum(d, ((points - points[nxt]) ** 2).sum(axis=1))
    return np.array(chosen, dtype=np.int64)


def _box(points: F64) -> tuple[F64, F64, F64]:
    """An oriented box holding ``points``: along their principal axes, or the frame's if smaller."""
    best: tuple[float, F64, F64, F64] | None = None
    mean = points.mean(axis=0)
    _, vecs = np.linalg.eigh(np.cov((points - mean).T) if len(points) > 1 else np.eye(3))
    for axes in (np.eye(3), vecs.T):
        proj = points @ axes.T
        lo, hi = proj.min(axis=0), proj.max(axis=0)
        half = (hi - lo) / 2.0
        volume = float(np.prod(half + 1e-12))
        if best is None or volume < best[0]:
            half = half * (1.0 + _SLACK) + _SLACK * (np.abs(lo) + np.abs(hi))
            best = (volume, ((lo + hi) / 2.0) @ axes, axes, half)
    assert best is not None  # two boxes were tried
    return best[1], best[2], best[3]


def _winding(points: F64, tri: F64) -> F64:
    """The winding number of the closed surface ``tri`` (T, 3, 3) around each point (P, 3)."""
    a = tri[None, :, 0, :] - points[:, None, :]
    b = tri[None, :, 1, :] - points[:, None, :]
    c = tri[None, :, 2, :] - points[:, None, :]
    la, lb, lc = (np.sqrt((x * x).sum(axis=2)) for x in (a, b, c))
    det = (a * np.cross(b, c)).sum(axis=2)
    den = la * lb * lc + (a * b).sum(axis=2) * lc + (b * c).sum(axis=2) * la
    den += (c * a).sum(axis=2) * lb
    out: F64 = np.arctan2(det, den).sum(axis=1) / (2.0 * np.pi)
    return out


def _flood(free: NDArray[np.bool_], seed: NDArray[np.bool_]) -> NDArray[np.bool_]:
    """The cells of ``free`` (a 3-D bool grid) joined to ``seed`` through faces of free cells."""
    reached = seed & free
    while True:
        grown = reached.copy()
        grown[1:] |= reached[:-1]
        grown[:-1] |= reached[1:]
        grown[:, 1:] |= reached[:, :-1]
        grown[:, :-1] |= reached[:, 1:]
        grown[:, :, 1:] |= reached[:, :, :-1]
        grown[:, :, :-1] |= reached[:, :, 1:]
        grown &= free
        if (grown == reached).all():
            return reached
        reached = grown


def _inside_cells(tri: F64, dims: I64, clearance: float) -> NDArray[np.bool_]:
    """Cells (a bool grid) wholly inside the closed surface ``tri`` (cells from the grid's corner).

    A cell no triangle's bounding box (grown by ``clearance``) reaches is at least ``clearance``
    from the surface; face-joined such cells form regions the surface does not cut, so one
    winding number (of any cell centre) holds in a whole region. The grid has one free layer all
    round, which is outside.
    """
    free = np.ones(tuple(int(x) for x in dims), dtype=np.bool_)
    lo = np.floor(tri.min(axis=1) - clearance).astype(np.int64)
    hi = np.floor(tri.max(axis=1) + clearance).astype(np.int64)
    lo = np.clip(lo, 0, dims - 1)
    hi = np.clip(hi, 0, dims - 1) + 1
    for (x0, y0, z0), (x1, y1, z1) in zip(lo.tolist(), hi.tolist(), strict=True):
        free[x0:x1, y0:y1, z0:z1] = False
    border = np.zeros_like(free)
    border[[0, -1]] = border[:, [0, -1]] = border[:, :, [0, -1]] = True
    left = free & ~_flood(free, border)
    inside = np.zeros_like(free)
    while left.any():
        first = np.unravel_index(int(np.argmax(left)), left.shape)
        seed = np.zeros_like(left)
        seed[first] = True
        region = _flood(left, seed)
        left &= ~region
        centre = np.array(first, dtype=np.float64) + 0.5
        if abs(float(_winding(centre[None, :], tri)[0])) > 0.5:
            inside |= region
    return inside


def prepare(vertices: F64, faces: I64) -> MeshProof:
    """The crossing proof's data of one mesh (vertices (V, 3), triangles (T, 3), finite)."""
    merged, tris = _merged(np.asarray(vertices, dtype=np.float64), np.asarray(faces))
    used = np.unique(tris)
    centre, axes, half = _box(merged[used])
    label = _pieces(len(merged), tris)[used]
    pieces, sizes = np.unique(label, return_counts=True)
    kept = pieces[np.argsort(-sizes, kind="stable")[:PIECES]]
    keep = np.isin(label, kept)
    candidates = merged[used][keep]
    pick = _spread(candidates, SAMPLES)
    rank = np.zeros(int(label.max()) + 1, dtype=np.int64)
    rank[kept] = np.arange(len(kept))
    bits = np.left_shift(np.int64(1), rank[label[keep][pick]])
    # The box grown by CLEARANCE, in cubic cells, and one outer layer (OUTSIDE) all round.
    span = 2.0 * (half + CLEARANCE)
    size = np.maximum(span, float(span.max()) * 1e-3)
    cell = float(np.prod(size) / CELLS) ** (1 / 3)
    dims = np.ceil(span / cell).astype(np.int64) + 2
    to_grid = np.eye(4)
    to_grid[:3, :3] = axes / cell
    to_grid[:3, 3] = (half + CLEARANCE + cell - axes @ centre) / cell
    codes = np.zeros(tuple(int(x) for x in dims), dtype=np.uint8)
    codes[[0, -1]] = codes[:, [0, -1]] = codes[:, :, [0, -1]] = OUTSIDE
    if _closed_oriented(tris):
        local = merged[tris] @ to_grid[:3, :3].T + to_grid[:3, 3]
        codes[_inside_cells(local, dims, CLEARANCE / cell)] = INSIDE
    return MeshProof(candidates[pick], bits, to_grid, dims, codes.reshape(-1))


def stack(proofs: list[MeshProof | None]) -> Proofs:
    """One padded array per field, indexed by geometry (None: not a mesh, never proven)."""
    g = len(proofs)
    real = [p for p in proofs if p is not None]
    k = max([len(p.points) for p in real] + [1])
    c = max([len(p.codes) for p in real] + [1])
    points = np.zeros((g, k, 4))
    points[:, :, 3] = 1.0
    bits = np.zeros((g, k), dtype=np.int64)
    to_grid = np.zeros((g, 3, 4))
    top = np.zeros((g, 3))
    strides = np.zeros((g, 3), dtype=np.int64)
    codes = np.zeros((g, c), dtype=np.uint8)
    for x, p in enumerate(proofs):
        if p is None:
            continue
        n = len(p.points)
        # Padded by repeating the first point (same piece): the answer does not change.
        points[x, :n, :3], points[x, n:, :3] = p.points, p.points[0]
        bits[x, :n], bits[x, n:] = p.bits, p.bits[0]
        to_grid[x] = p.to_grid[:3]
        top[x] = p.dims - 1
        strides[x] = (p.dims[1] * p.dims[2], p.dims[2], 1)
        codes[x, : len(p.codes)] = p.codes
    inside_lo = np.full((g, 3), np.inf)
    inside_hi = np.full((g, 3), -np.inf)
    cell = np.ones(g)
    core = np.ones((g, 4))
    core_radius = np.full(g, -np.inf)
    for x, p in enumerate(proofs):
        if p is None:
            continue
        cells = np.argwhere(p.codes.reshape(tuple(p.dims)) == INSIDE)
        if len(cells):
            inside_lo[x], inside_hi[x] = cells.min(axis=0), cells.max(axis=0) + 1
            side = 1.0 / float(np.linalg.norm(p.to_grid[0, :3]))
            cell[x] = side
            # The inside cells' box, back in the mesh frame: its centre and half diagonal.
            mid = (inside_lo[x] + inside_hi[x]) / 2.0
            rot, shift = p.to_grid[:3, :3] * side, p.to_grid[:3, 3]  # rot is orthonormal
            core[x, :3] = rot.T @ ((mid - shift) * side)
            core_radius[x] = float(np.linalg.norm(inside_hi[x] - inside_lo[x])) * side / 2.0
    pts = points[:, :, :3]
    ball = np.ones((g, 4))
    ball[:, :3] = (pts.max(axis=1) + pts.min(axis=1)) / 2.0
    radius = np.sqrt(((pts - ball[:, None, :3]) ** 2).sum(axis=2).max(axis=1))
    closed = np.isfinite(inside_lo[:, 0])
    lut = np.stack([np.zeros_like(bits), bits, bits << 31], axis=2)
    return Proofs(
        points,
        bits,
        to_grid,
        top,
        strides,
        codes,
        closed,
        lut,
        inside_lo,
        inside_hi,
        ball,
        radius,
        cell,
        core,
        core_radius * (1.0 + _SLACK),
    )


def _one_way(s: Proofs, pa: F64, pb: F64, a: I64, b: I64) -> NDArray[np.bool_]:
    """Per candidate: a piece of B's surface reaches a cell inside A and one outside A's box.

    ``pa``, ``pb`` (n, 4, 4) are the poses of A and B.
    """
    rt = pa[:, :3, :3].transpose(0, 2, 1)
    rel = np.matmul(rt, pb[:, :3, :])  # B's frame -> A's (3, 4)
    rel[:, :, 3] -= np.matmul(rt, pa[:, :3, 3:])[..., 0]
    g = s.to_grid[a]
    m = np.matmul(g[:, :, :3], rel)  # B's frame -> A's grid
    m[:, :, 3] += g[:, :, 3]
    u = np.matmul(s.points[b], m.transpose(0, 2, 1))  # (n, K, 3) in cells
    np.maximum(u, 0.0, out=u)  # beyond the grid: its outer layer
    np.minimum(u, s.top[a][:, None, :], out=u)
    flat = np.matmul(u.astype(np.int64), s.strides[a][:, :, None])[..., 0]
    code = s.codes[a[:, None], flat]
    seen = np.bitwise_or.reduce(s.lut[b[:, None], np.arange(code.shape[1]), code], axis=1)
    out: NDArray[np.bool_] = (seen & (seen >> 31)) != 0
    return out


def crossing(s: Proofs, poses: F64, rows: I64, g1: I64, g2: I64, eps: float) -> NDArray[np.bool_]:
    """Per candidate (row, geometries g1, g2): the two meshes' surfaces are proven to meet.

    Every cell the proof reads is :data:`CLEARANCE` inside A's surface or outside its box, so
    an ``eps`` (the margin and the rounding room, as the C core's proofs take it) of that or
    more proves nothing.
    """
    n = len(rows)
    if not eps < CLEARANCE or not n:
        return np.zeros(n, dtype=np.bool_)
    # Both directions in one pass: (A, B) = (g1, g2) where g1 is closed, then (g2, g1).
    one, two = np.flatnonzero(s.closed[g1]), np.flatnonzero(s.closed[g2])
    at = np.concatenate([one, two])
    a = np.concatenate([g1[one], g2[two]])
    b = np.concatenate([g2[one], g1[two]])
    r = rows[at]
    # Where B's ball cannot reach A's inside cells, nothing is proven: B's ball centre taken
    # into A's grid alone (elementwise, no stacked matrix products), the rest only after.
    pa, pb = poses[r, a, :3], poses[r, b, :3]
    d = (pb * s.ball[b][:, None, :]).sum(axis=2) - pa[:, :, 3]
    local = (pa[:, :, :3] * d[:, :, None]).sum(axis=1)  # A's frame
    g = s.to_grid[a]
    mid = (g[:, :, :3] * local[:, None, :]).sum(axis=2) + g[:, :, 3]
    gap = np.maximum(np.maximum(s.inside_lo[a] - mid, mid - s.inside_hi[a]), 0.0)
    reach = s.radius[b] / s.cell[a]  # cells
    near = np.flatnonzero((gap * gap).sum(axis=1) < reach * reach)
    proven = np.zeros(n, dtype=np.bool_)
    if len(near):
        a, b, r = a[near], b[near], r[near]
        proven[at[near[_one_way(s, poses[r, a], poses[r, b], a, b)]]] = True
    return proven
