"""The kinematics core in numpy: what ``_kincore.c`` computes, for a Python without the C build.

Why a second implementation: the C core is an accelerator, not a requirement. A user whose
install could not compile it (no compiler, an unusual platform) or who turns it off
(``ROBOTSPEC_NO_ACCEL=1``) still gets every answer, the same to floating-point rounding, only
slower (see benchmarks/bench_fallback.py). The entry points, their arguments and their errors
are the C core's (see ``_kincore.pyi``): each argument is read as the C core reads it
(:mod:`robotspec.model._core_args`), in the C core's order, so a mistake raises the same
exception with the same message whichever core runs. :mod:`robotspec.model.kincore` chooses.

One configuration and a batch run the same code (a batch of one): ``fk(q)`` and
``fk_batch(Q)[i]`` agree bit for bit, as in the C core, where both run one loop per sample.

How it stays vectorised: a tree program's rows are grouped by depth (a row's parent slot is
written by a shallower row), so one numpy call per depth moves every body of that depth, for
every sample of a batch at once; products are written out term by term in the C core's order,
so the collision broad phase keeps exactly the C core's candidates.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from robotspec.arrays import F64, I64
from robotspec.model._core_args import from_any, index, real, table, truth

KIND_FIXED = 0
KIND_REVOLUTE = 1
KIND_PRISMATIC = 2

#: Samples per step of a batch: bounds the per-row motion arrays (a few MB) on long batches.
_CHUNK = 256


# ----------------------------------------------------------------------------------- helpers
def _copy_i64(obj: object, want: int, what: str) -> I64:
    """The C core's ``copy_i64``: exactly one dimension, ``want`` int64 values."""
    return _sized(from_any(obj, np.int64, 1, 1), want, what)


def _copy_f64(obj: object, want: int, what: str) -> F64:
    """The C core's ``copy_f64``: any shape holding ``want`` float64 values."""
    return _sized(from_any(obj, np.float64), want, what)


def _sized(a: np.ndarray[Any, Any], want: int, what: str) -> np.ndarray[Any, Any]:
    if a.size != want:
        raise ValueError(f"{what}: expected {want} values, got {a.size}")
    return a.reshape(-1).copy()


def _config(obj: object, ndim: int, width: int) -> F64:
    """The C core's ``as_config``: a configuration (ndim 1) or batch (ndim 2) of finite values."""
    a = from_any(obj, np.float64, ndim, ndim)
    if a.shape[-1] != width:
        raise ValueError("configuration has the wrong number of values")
    if not np.isfinite(a).all():
        raise ValueError("configuration contains NaN or infinite values")
    return a


def _motions(kind: I64, axis: F64, v: F64) -> F64:
    """Each row's motion (..., R, 3, 4) at values ``v`` (..., R): a rotation, translation or 1.

    Every row is computed alike: a row that does not rotate gets angle 0 (the identity,
    exactly), one that does not slide gets offset 0. Poses here drop the last row (0 0 0 1).
    """
    vr = np.where(kind == KIND_REVOLUTE, v, 0.0)
    vp = np.where(kind == KIND_PRISMATIC, v, 0.0)
    x, y, z = axis[:, 0], axis[:, 1], axis[:, 2]
    s, c = np.sin(vr), np.cos(vr)
    t = 1.0 - c
    m = np.empty((*v.shape, 3, 4))
    m[..., 0, 0] = c + x * x * t
    m[..., 0, 1] = x * y * t - z * s
    m[..., 0, 2] = x * z * t + y * s
    m[..., 1, 0] = y * x * t + z * s
    m[..., 1, 1] = c + y * y * t
    m[..., 1, 2] = y * z * t - x * s
    m[..., 2, 0] = z * x * t - y * s
    m[..., 2, 1] = z * y * t + x * s
    m[..., 2, 2] = c + z * z * t
    m[..., 3] = axis * vp[..., None]
    return m


def _compose(a: F64, b: F64) -> F64:
    """``a @ b`` of stacked poses without their last row (..., 3, 4), term by term.

    Why not ``np.matmul``: on a batch it is one small product per pose (tens of thousands of
    calls inside numpy); six whole-array operations are several times cheaper.
    """
    out = a[..., :, 0:1] * b[..., 0:1, :]
    out += a[..., :, 1:2] * b[..., 1:2, :]
    out += a[..., :, 2:3] * b[..., 2:3, :]
    out[..., 3] += a[..., 3]
    return out


def _full(m: F64) -> F64:
    """Poses (..., 3, 4) with their last row 0 0 0 1 put back: (..., 4, 4)."""
    out = np.empty((*m.shape[:-2], 4, 4))
    out[..., :3, :] = m
    out[..., 3, :] = (0.0, 0.0, 0.0, 1.0)
    return out


# -------------------------------------------------------------------------------- the tree
@dataclass(frozen=True)
class Tree:
    """A tree program (see ``_kincore.c``), its rows sorted by depth.

    Row k sets slot child[k] = slot parent[k] times origin[k] times the row's motion. The rows
    of one depth, ``levels`` (first, end), only read slots that shallower rows wrote, so each
    depth is one step over every sample.
    """

    n_slots: int
    n_out: int
    n_dof: int
    parent: I64
    child: I64
    kind: I64
    dof: I64  # the DOF each row reads; n_dof (a column of zeros) for a fixed row
    origin: F64
    axis: F64
    mul: F64
    off: F64
    levels: tuple[tuple[int, int], ...]


def tree(
    parent: Any,
    child: Any,
    kind: Any,
    origin: Any,
    axis: Any,
    dof: Any,
    mul: Any,
    off: Any,
    n_slots: int,
    n_out: int,
    n_dof: int,
) -> object:
    # In the C core's order: the counts (parsed first), the rows' number, the arrays, each row.
    n_slots, n_out, n_dof = index(n_slots), index(n_out), index(n_dof)
    n = len(parent)  # TypeError as PyObject_Length raises
    if not 1 <= n_out <= n_slots or n_slots > n_out + n or n_dof < 0:
        raise ValueError("tree program: slot or DOF counts out of range")
    p = _copy_i64(parent, n, "parent")
    c = _copy_i64(child, n, "child")
    k = _copy_i64(kind, n, "kind")
    d = _copy_i64(dof, n, "dof")
    o = _copy_f64(origin, 16 * n, "origin").reshape(n, 4, 4)
    a = _copy_f64(axis, 3 * n, "axis").reshape(n, 3)
    m = _copy_f64(mul, n, "mul")
    f = _copy_f64(off, n, "off")
    for r in range(n):
        pr, ch = int(p[r]), int(c[r])
        if (
            not 0 <= pr < n_slots
            or not 0 < ch < n_slots
            or pr == ch
            or (k[r] != KIND_FIXED and not 0 <= d[r] < n_dof)
        ):
            raise ValueError("tree program refers to a slot or DOF out of range")
        if not KIND_FIXED <= k[r] <= KIND_PRISMATIC:
            raise ValueError("tree program has a motion kind out of range")
    depth = np.full(n_slots, -1, dtype=np.int64)
    depth[0] = 0
    row_depth = np.zeros(n, dtype=np.int64)
    for r in range(n):
        pr, ch = int(p[r]), int(c[r])
        if depth[pr] < 0:
            raise ValueError("tree program reads a slot before a row writes it")
        depth[ch] = row_depth[r] = depth[pr] + 1
    if (depth[1:n_out] < 0).any():
        raise ValueError("tree program leaves a body's pose unset")
    reads = np.where(k == KIND_FIXED, n_dof, d)  # a fixed row's DOF is never read, nor checked
    order = np.argsort(row_depth, kind="stable")
    ends = np.searchsorted(row_depth[order], np.arange(1, int(row_depth.max(initial=0)) + 2))
    levels = tuple((int(lo), int(hi)) for lo, hi in zip(ends[:-1], ends[1:], strict=True))
    return Tree(
        n_slots,
        n_out,
        n_dof,
        p[order],
        c[order],
        k[order],
        reads[order],
        o[order],
        a[order],
        m[order],
        f[order],
        levels,
    )


def _tree_of(obj: object) -> Tree:
    return table(obj, Tree, "a tree program (from tree())")


def tree_size(tree: object) -> tuple[int, int]:
    """(bodies returned, degrees of freedom) of a tree program."""
    t = _tree_of(tree)
    return t.n_out, t.n_dof


def _run_tree(t: Tree, q: F64, out: F64) -> None:
    """Every output pose of the samples of ``q`` (N, D) into ``out`` (N, B, 4, 4)."""
    n = q.shape[0]
    slots = np.empty((n, t.n_slots, 3, 4))
    slots[:, 0] = np.eye(4)[:3]
    row = _compose(t.origin[:, :3], _motions(t.kind, t.axis, _values(t, q)))
    for lo, hi in t.levels:
        slots[:, t.child[lo:hi]] = _compose(slots[:, t.parent[lo:hi]], row[:, lo:hi])
    out[..., :3, :] = slots[:, : t.n_out]
    out[..., 3, :] = (0.0, 0.0, 0.0, 1.0)


def _values(t: Tree, q: F64) -> F64:
    """Each row's motion value (N, R) for the samples of ``q`` (N, D); 0 for a fixed row."""
    padded = np.zeros((q.shape[0], t.n_dof + 1))
    padded[:, : t.n_dof] = q
    v: F64 = padded[:, t.dof] * t.mul + t.off
    return v


def fk(tree: object, q: object) -> F64:
    t = _tree_of(tree)
    qa = _config(q, 1, t.n_dof)
    # A batch of one, by the batch's own operations: np.matmul (BLAS, whose sums may fuse or
    # reorder) would differ from fk_batch in the last bit.
    poses: F64 = np.empty((1, t.n_out, 4, 4))
    _run_tree(t, qa[None, :], poses)
    pose: F64 = poses[0]
    return pose


def fk_batch(tree: object, q: object, out: Any = None, stream: bool = False) -> F64:
    """Every pose of a batch; ``stream`` is the C core's choice of stores, meaningless here."""
    truth(stream)  # read as the C core reads it (an array of several values is an error)
    t = _tree_of(tree)
    qa = _config(q, 2, t.n_dof)
    n = qa.shape[0]
    shape = (n, t.n_out, 4, 4)
    if out is None:
        out = np.empty(shape)
    else:
        check_out(out, shape)
    for lo in range(0, n, _CHUNK):
        _run_tree(t, qa[lo : lo + _CHUNK], out[lo : lo + _CHUNK])
    result: F64 = out
    return result


def check_out(out: object, shape: tuple[int, ...]) -> None:
    """Check a caller's array for poses of ``shape`` as the C core does.

    TypeError for the wrong type, byte order or alignment (the core writes native float64 in
    place), ValueError for the wrong shape.
    """
    what = "out must be a writeable, aligned, native-order C-contiguous float64 array (N, B, 4, 4)"
    if not (
        isinstance(out, np.ndarray)
        and out.dtype.type is np.float64
        and out.dtype.isnative
        and out.flags.aligned
        and out.flags.c_contiguous
        and out.flags.writeable
    ):
        raise TypeError(what)
    if out.shape != shape:
        raise ValueError(what)


# --------------------------------------------------------------------------------- a chain
@dataclass(frozen=True)
class Chain:
    """A chain program: T = pre[0] m_0(q) pre[1] m_1(q) ... m_{n-1}(q) post."""

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
    c = Chain(
        n_cols,
        n_dof,
        _copy_f64(pre, 16 * n, "pre").reshape(n, 4, 4),
        _copy_f64(post, 16, "post").reshape(4, 4),
        _copy_i64(kind, n, "kind"),
        _copy_f64(axis, 3 * n, "axis").reshape(n, 3),
        _copy_i64(dof, n, "dof"),
        _copy_f64(mul, n, "mul"),
        _copy_f64(off, n, "off"),
        _copy_i64(col, n, "col"),
    )
    bad = (
        (c.dof < 0)
        | (c.dof >= n_dof)
        | (c.col < 0)
        | (c.col >= n_cols)
        | ((c.kind != KIND_REVOLUTE) & (c.kind != KIND_PRISMATIC))
    )
    if bad.any():
        raise ValueError("chain program refers to a DOF out of range")
    return c


def _chain_of(obj: object) -> Chain:
    return table(obj, Chain, "a chain program (from chain())")


def _chain_run(c: Chain, q: F64) -> F64:
    """root_T_tip (N, 4, 4) of the samples of ``q`` (N, D)."""
    v = q[:, c.dof] * c.mul + c.off
    steps = _compose(c.pre[:, :3], _motions(c.kind, c.axis, v))
    t = np.broadcast_to(np.eye(4)[:3], (q.shape[0], 3, 4))
    for i in range(steps.shape[1]):
        t = _compose(t, steps[:, i])
    return _full(_compose(t, c.post[:3]))


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
    motion = _full(_motions(c.kind, c.axis, qa[c.dof] * c.mul + c.off))
    z = np.empty((n, 3))
    p = np.empty((n, 3))
    t = np.eye(4)
    for i in range(n):
        u = t @ c.pre[i]
        z[i] = u[:3, :3] @ c.axis[i]
        p[i] = u[:3, 3]
        t = u @ motion[i]
    tip = (t @ c.post)[:3, 3]
    m = c.mul[:, None]
    rev = (c.kind == KIND_REVOLUTE)[:, None]
    d = tip - p
    x, y = [1, 2, 0], [2, 0, 1]  # the cross product z x d, written out (np.cross costs more)
    lin = np.where(rev, z[:, x] * d[:, y] - z[:, y] * d[:, x], z) * m
    ang = np.where(rev, z, 0.0) * m
    jac = np.zeros((6, c.n_cols))
    np.add.at(jac.T, c.col, np.hstack([lin, ang]))
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


def _obb_separated(fa: F64, ha: F64, fb: F64, hb: F64) -> np.ndarray[Any, np.dtype[np.bool_]]:
    """Per candidate: whether one of fifteen separating axes parts the two oriented boxes.

    Frames fa, fb (K, 4, 4), half extents ha, hb (K, 3): the C core's test, term by term.
    """
    d = fb[:, :3, 3] - fa[:, :3, 3]
    a, b = fa[:, :3, :3], fb[:, :3, :3]
    r = (
        a[:, 0, :, None] * b[:, 0, None, :]
        + a[:, 1, :, None] * b[:, 1, None, :]
        + a[:, 2, :, None] * b[:, 2, None, :]
    )
    ar = np.abs(r) + 1e-9
    t = a[:, 0, :] * d[:, 0, None] + a[:, 1, :] * d[:, 1, None] + a[:, 2, :] * d[:, 2, None]
    rhs = ha + ar[:, :, 0] * hb[:, 0, None] + ar[:, :, 1] * hb[:, 1, None]
    sep = (np.abs(t) > rhs + ar[:, :, 2] * hb[:, 2, None]).any(axis=1)
    tb = t[:, 0, None] * r[:, 0, :] + t[:, 1, None] * r[:, 1, :] + t[:, 2, None] * r[:, 2, :]
    rhs = ha[:, 0, None] * ar[:, 0, :] + ha[:, 1, None] * ar[:, 1, :]
    sep |= (np.abs(tb) > rhs + ha[:, 2, None] * ar[:, 2, :] + hb).any(axis=1)
    y1, y2 = [1, 2, 0], [2, 0, 1]
    for x in range(3):
        x1, x2 = (x + 1) % 3, (x + 2) % 3
        lhs = np.abs(t[:, x2, None] * r[:, x1, :] - t[:, x1, None] * r[:, x2, :])
        rhs = ha[:, x1, None] * ar[:, x2, :] + ha[:, x2, None] * ar[:, x1, :]
        rhs = rhs + hb[:, y1] * ar[:, x][:, y2] + hb[:, y2] * ar[:, x][:, y1]
        sep |= (lhs > rhs).any(axis=1)
    return np.asarray(sep, dtype=np.bool_)


def broad(geoms: object, body_poses: Any, margin: float, mask: Any) -> tuple[Any, Any, Any]:
    margin = real(margin)
    g = table(geoms, Geoms, "a geometry table (from geoms())")
    bp = from_any(body_poses, np.float64, 3, 4)
    if bp.ndim == 3:
        bp = bp[None]
    if bp.shape[1:] != (g.n_body, 4, 4):
        raise ValueError("body poses have the wrong shape")
    keep = np.ones(len(g.g1), dtype=np.bool_)
    if mask is not None:
        m = from_any(mask, np.uint8, 1, 1)
        if m.size != len(g.g1):
            raise ValueError("pair mask has the wrong size")
        keep = m != 0
    bodies = bp[:, g.body]  # (N, G, 4, 4)
    poses = _full(_compose(bodies[..., :3, :], g.body_T_geom[:, :3]))  # the C core's terms
    rot = bodies[..., :3, :3]
    c, h = g.center, g.half
    cen = rot[..., 0] * c[:, 0, None] + rot[..., 1] * c[:, 1, None] + rot[..., 2] * c[:, 2, None]
    cen = cen + bodies[..., :3, 3]
    hw = (
        np.abs(rot[..., 0]) * h[:, 0, None]
        + np.abs(rot[..., 1]) * h[:, 1, None]
        + np.abs(rot[..., 2]) * h[:, 2, None]
    )
    lo, hi = cen - hw - margin, cen + hw
    i, j = g.g1[keep], g.g2[keep]
    meet = ((lo[:, i] <= hi[:, j]) & (lo[:, j] <= hi[:, i])).all(axis=2)  # (N, P kept)
    rows, at = np.nonzero(meet)
    i, j = i[at], j[at]
    frames = bodies[rows[:, None], np.stack([i, j], axis=1)].copy()  # (K, 2, 4, 4)
    frames[..., :3, 3] = cen[rows[:, None], np.stack([i, j], axis=1)]
    sep = _obb_separated(frames[:, 0], h[i] + margin / 2.0, frames[:, 1], h[j] + margin / 2.0)
    pairs = np.flatnonzero(keep)[at]
    return rows[~sep].astype(np.int64), pairs[~sep].astype(np.int64), poses
