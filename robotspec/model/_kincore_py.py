"""The kinematics core in numpy: what ``_kincore.c`` computes, for a Python without the C build.

Why a second implementation: the C core is an accelerator, not a requirement. A user whose
install could not compile it (no compiler, an unusual platform) or who turns it off
(``ROBOTSPEC_NO_ACCEL=1``) still gets every answer, the same to floating-point rounding, only
slower (see benchmarks/bench_fallback.py). The entry points, their arguments and their errors
are the C core's (see ``_kincore.pyi``): each argument is read as the C core reads it
(:mod:`robotspec.model._core_args`), in the C core's order, so a mistake raises the same
exception with the same message whichever core runs. :mod:`robotspec.model.kincore` chooses.

The tree program (every body pose: ``tree``, ``fk``, ``fk_batch``) is
:mod:`robotspec.model._kintree_py`, laid out for numpy (one matrix product per depth for all
samples); the chain programs, Jacobians and the collision broad phase are here. One configuration
and a batch run the same code (a batch of one), so ``fk(q)`` and ``fk_batch(Q)[i]`` agree bit for
bit, as in the C core. The broad phase writes its products term by term in the C core's order,
so it keeps exactly the C core's candidates for the same body poses.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from robotspec.arrays import F64, I64
from robotspec.model._core_args import from_any, index, real, table
from robotspec.model._kintree_py import (
    KIND_FIXED,
    KIND_PRISMATIC,
    KIND_REVOLUTE,
    check_out,
    fk,
    fk_batch,
    tree,
    tree_size,
)
from robotspec.model._kintree_py import config as _config
from robotspec.model._kintree_py import copy_f64 as _copy_f64
from robotspec.model._kintree_py import copy_i64 as _copy_i64
from robotspec.model._kintree_py import motion_terms as _motion_terms

__all__ = [
    "KIND_FIXED",
    "KIND_PRISMATIC",
    "KIND_REVOLUTE",
    "broad",
    "chain",
    "chain_fk",
    "chain_fk_batch",
    "chain_jacobian",
    "check_out",
    "fk",
    "fk_batch",
    "geoms",
    "tree",
    "tree_size",
]

#: Samples per step of a chain's batch: bounds its per-step arrays (a few MB) on long batches.
_CHUNK = 256


# ----------------------------------------------------------------------------------- helpers
def _placed(rows4: F64, b: F64) -> F64:
    """Poses (N, G, 4, 4) from body rows ``rows4`` (3, 4, N, G) times ``b`` (G, 4, 4).

    The C core's ``mul34``, term by term in its order (so the same bits), computed row and column
    first, so that every operation runs along the samples and geometries; one copy puts the
    poses in their layout.
    """
    bt = b[:, :3].transpose(1, 2, 0)[:, :, None, :]  # (3, 4, 1, G)
    out = rows4[:, 0, None] * bt[0] + rows4[:, 1, None] * bt[1] + rows4[:, 2, None] * bt[2]
    out[:, 3] += rows4[:, 3]
    poses = np.empty((*rows4.shape[2:], 4, 4))
    poses[..., :3, :] = out.transpose(2, 3, 0, 1)
    poses[..., 3, :] = (0.0, 0.0, 0.0, 1.0)
    return poses


# --------------------------------------------------------------------------------- a chain
@dataclass(frozen=True)
class Chain:
    """A chain program: T = pre[0] m_0(q) pre[1] m_1(q) ... m_{n-1}(q) post.

    ``terms`` (n, 3, 4, 4) is each step ``pre[i] m_i`` as ``pre + a pre M1 + b pre M2`` (see
    :func:`robotspec.model._kintree_py.motion_terms`); ``columns`` (n, n_cols) adds each step's
    Jacobian column into its DOF's (a mimic joint's into its leader's), as one product.
    """

    n_cols: int
    n_dof: int
    pre: F64
    post: F64
    kind: I64
    axis: F64
    dof: I64
    mul: F64
    off: F64
    col: I64
    terms: F64
    revolute: I64
    prismatic: I64
    columns: F64


def chain(
    pre: Any,
    post: Any,
    kind: Any,
    axis: Any,
    dof: Any,
    mul: Any,
    off: Any,
    col: Any,
    n_cols: int,
    n_dof: int,
) -> object:
    n_cols, n_dof = index(n_cols), index(n_dof)
    n = len(kind)  # TypeError as PyObject_Length raises
    if n_cols < 0 or n_dof < 0:
        raise ValueError("chain program: column or DOF count out of range")
    p = _copy_f64(pre, 16 * n, "pre").reshape(n, 4, 4)
    post_ = _copy_f64(post, 16, "post").reshape(4, 4)
    k = _copy_i64(kind, n, "kind")
    ax = _copy_f64(axis, 3 * n, "axis").reshape(n, 3)
    d = _copy_i64(dof, n, "dof")
    m = _copy_f64(mul, n, "mul")
    f = _copy_f64(off, n, "off")
    cols = _copy_i64(col, n, "col")
    bad = (
        (d < 0)
        | (d >= n_dof)
        | (cols < 0)
        | (cols >= n_cols)
        | ((k != KIND_REVOLUTE) & (k != KIND_PRISMATIC))
    )
    if bad.any():
        raise ValueError("chain program refers to a DOF out of range")
    m1, m2 = _motion_terms(k, ax)
    columns = np.zeros((n, n_cols))
    columns[np.arange(n), cols] = m
    return Chain(
        n_cols,
        n_dof,
        p,
        post_,
        k,
        ax,
        d,
        m,
        f,
        cols,
        np.stack([p, p @ m1, p @ m2], axis=1),
        np.flatnonzero(k == KIND_REVOLUTE),
        np.flatnonzero(k == KIND_PRISMATIC),
        columns,
    )


def _chain_of(obj: object) -> Chain:
    return table(obj, Chain, "a chain program (from chain())")


def _prefix(c: Chain, q: F64) -> F64:
    """``pre[0] m_0 ... pre[i] m_i`` for every step i (N, n, 4, 4) of the samples of ``q``.

    Every step's matrix at once, then the running products by doubling (step i takes the
    product ending 2^k steps before it): log2(n) stacked products instead of n small ones.
    """
    v = q[:, c.dof] * c.mul + c.off  # (N, n)
    a, b = np.zeros_like(v), np.zeros_like(v)
    a[:, c.revolute] = np.sin(v[:, c.revolute])
    b[:, c.revolute] = 1.0 - np.cos(v[:, c.revolute])
    a[:, c.prismatic] = v[:, c.prismatic]
    t = c.terms
    run: F64 = t[:, 0] + a[..., None, None] * t[:, 1] + b[..., None, None] * t[:, 2]
    d, n = 1, run.shape[1]
    while d < n:
        run[:, d:] = np.matmul(run[:, :-d], run[:, d:])
        d *= 2
    return run


def _chain_run(c: Chain, q: F64) -> F64:
    """root_T_tip (N, 4, 4) of the samples of ``q`` (N, D)."""
    if not len(c.kind):
        return np.broadcast_to(c.post, (q.shape[0], 4, 4)).copy()
    ends: F64 = np.matmul(_prefix(c, q)[:, -1], c.post)
    ends[:, 3] = (0.0, 0.0, 0.0, 1.0)
    return ends


def chain_fk(chain: object, q: object) -> F64:
    c = _chain_of(chain)
    qa = _config(q, 1, c.n_dof)
    pose: F64 = _chain_run(c, qa[None, :])[0]  # a batch of one: chain_fk_batch's bits
    return pose


def chain_fk_batch(chain: object, q: object) -> F64:
    c = _chain_of(chain)
    qa = _config(q, 2, c.n_dof)
    out = np.empty((qa.shape[0], 4, 4))
    for lo in range(0, qa.shape[0], _CHUNK):
        out[lo : lo + _CHUNK] = _chain_run(c, qa[lo : lo + _CHUNK])
    return out


def chain_jacobian(chain: object, q: object) -> F64:
    c = _chain_of(chain)
    qa = _config(q, 1, c.n_dof)
    n = len(c.kind)
    if not n:
        return np.zeros((6, c.n_cols))
    run = _prefix(c, qa[None, :])[0]
    before = np.empty_like(run)  # the frame each step starts from, its pre included
    before[0] = c.pre[0]
    np.matmul(run[:-1], c.pre[1:], out=before[1:])
    z = np.matmul(before[:, :3, :3], c.axis[:, :, None])[:, :, 0]
    d = (run[-1, :3, :3] @ c.post[:3, 3] + run[-1, :3, 3]) - before[:, :3, 3]
    rev = (c.kind == KIND_REVOLUTE)[:, None]
    x, y = [1, 2, 0], [2, 0, 1]  # the cross product z x d, written out (np.cross costs more)
    lin = np.where(rev, z[:, x] * d[:, y] - z[:, y] * d[:, x], z)
    ang = np.where(rev, z, 0.0)
    jac: F64 = np.concatenate([lin, ang], axis=1).T @ c.columns
    return jac


# ------------------------------------------------------------------ collision broad phase
@dataclass(frozen=True)
class Geoms:
    """Geometries (each on a body, with a body-frame box) and the geometry pairs to test."""

    n_body: int
    body: I64
    body_T_geom: F64  # noqa: N815 - the C core's name
    center: F64
    half: F64
    g1: I64
    g2: I64


def geoms(
    body: Any, body_to_geom: Any, center: Any, half: Any, g1: Any, g2: Any, n_body: int
) -> object:
    n_body = index(n_body)
    ng, npair = len(body), len(g1)
    g = Geoms(
        n_body,
        _copy_i64(body, ng, "body"),
        _copy_f64(body_to_geom, 16 * ng, "body_T_geom").reshape(ng, 4, 4),
        _copy_f64(center, 3 * ng, "center").reshape(ng, 3),
        _copy_f64(half, 3 * ng, "half").reshape(ng, 3),
        _copy_i64(g1, npair, "g1"),
        _copy_i64(g2, npair, "g2"),
    )
    if ((g.body < 0) | (g.body >= n_body)).any():
        raise ValueError("geometry on a body out of range")
    if ((g.g1 < 0) | (g.g1 >= ng) | (g.g2 < 0) | (g.g2 >= ng)).any():
        raise ValueError("geometry pair out of range")
    return g


def _obb_separated(a: F64, ca: F64, ha: F64, b: F64, cb: F64, hb: F64) -> Any:
    """Per candidate: whether one of fifteen separating axes parts the two oriented boxes.

    Rotations a, b (3, 3, K), centres ca, cb and half extents ha, hb (3, K): the C core's test,
    term by term, candidates last (so every operation runs along them).
    """
    d = cb - ca
    r = a[0][:, None] * b[0][None] + a[1][:, None] * b[1][None] + a[2][:, None] * b[2][None]
    ar = np.abs(r) + 1e-9
    t = a[0] * d[0] + a[1] * d[1] + a[2] * d[2]
    rhs = ha + ar[:, 0] * hb[0] + ar[:, 1] * hb[1]
    far = np.abs(t) > rhs + ar[:, 2] * hb[2]
    sep = far[0] | far[1] | far[2]
    tb = t[0] * r[0] + t[1] * r[1] + t[2] * r[2]
    rhs = ha[0] * ar[0] + ha[1] * ar[1]
    far = np.abs(tb) > rhs + ha[2] * ar[2] + hb
    sep |= far[0] | far[1] | far[2]
    y1, y2 = [1, 2, 0], [2, 0, 1]
    for x in range(3):
        x1, x2 = (x + 1) % 3, (x + 2) % 3
        lhs = np.abs(t[x2] * r[x1] - t[x1] * r[x2])
        rhs = ha[x1] * ar[x2] + ha[x2] * ar[x1]
        rhs = rhs + hb[y1] * ar[x][y2] + hb[y2] * ar[x][y1]
        far = lhs > rhs
        sep |= far[0] | far[1] | far[2]
    return sep


def broad(geoms: object, body_poses: Any, margin: float, mask: Any) -> tuple[Any, Any, Any]:
    margin = real(margin)
    g = table(geoms, Geoms, "a geometry table (from geoms())")
    bp = from_any(body_poses, np.float64, 3, 4)
    if bp.ndim == 3:
        bp = bp[None]
    if bp.shape[1:] != (g.n_body, 4, 4):
        raise ValueError("body poses have the wrong shape")
    keep = None
    if mask is not None:
        m = from_any(mask, np.uint8, 1, 1)
        if m.size != len(g.g1):
            raise ValueError("pair mask has the wrong size")
        keep = m != 0
    bodies = bp[:, g.body]  # (N, G, 4, 4)
    rows4 = bodies[..., :3, :].transpose(2, 3, 0, 1)  # (row, column, N, G), a view
    poses = _placed(rows4, g.body_T_geom)
    # Box bounds, axis first: (3, N, G), the C core's sums in its order.
    c, h = g.center, g.half
    cen = rows4[:, 0] * c[:, 0] + rows4[:, 1] * c[:, 1] + rows4[:, 2] * c[:, 2] + rows4[:, 3]
    hw = np.abs(rows4[:, 0]) * h[:, 0] + np.abs(rows4[:, 1]) * h[:, 1]
    hw += np.abs(rows4[:, 2]) * h[:, 2]
    lo, hi = cen - hw - margin, cen + hw
    pairs = np.arange(len(g.g1)) if keep is None else np.flatnonzero(keep)
    i, j = g.g1[pairs], g.g2[pairs]
    meet = (lo[:, :, i] <= hi[:, :, j]) & (lo[:, :, j] <= hi[:, :, i])  # (3, N, P kept)
    rows, at = np.nonzero(meet[0] & meet[1] & meet[2])
    if not len(rows):  # no bounds meet: no box test to run
        return rows.astype(np.int64), at.astype(np.int64), poses
    i, j = i[at], j[at]
    frame_a = bodies[rows, i, :3, :3].transpose(1, 2, 0)  # (3, 3, K)
    frame_b = bodies[rows, j, :3, :3].transpose(1, 2, 0)
    half = margin / 2.0
    sep = _obb_separated(
        frame_a, cen[:, rows, i], (h[i] + half).T, frame_b, cen[:, rows, j], (h[j] + half).T
    )
    return rows[~sep].astype(np.int64), pairs[at][~sep].astype(np.int64), poses
