"""The tree program of the kinematics core in numpy: every body pose, vectorised over samples.

Why a module of its own: this is the fallback's hot path (``forward``, ``forward_batch`` and
the collision checker's poses without the C core), laid out for numpy rather than for C.
:mod:`robotspec.model._kincore_py` re-exports its entry points (``tree``, ``tree_size``, ``fk``,
``fk_batch``), whose arguments and errors are the C core's (see ``_kincore.pyi``).

How it stays fast: a row sets ``child = parent @ origin @ motion(v)``. Its motion is Rodrigues'
``I + s K + t (u u^T - I)`` (revolute: s = sin v, t = 1 - cos v) or ``I + v [0 | u]``
(prismatic), so ``origin @ motion`` is ``W0 + s W1 + t W2`` with three constant 4x4 matrices per
row, made once when the program is built. The rows are grouped by depth; for one depth, the
parents of every sample are multiplied by the rows' stacked ``[W0 W1 W2]`` in ONE matrix product
(samples and pose rows side by side in the columns, so BLAS sees wide matrices), then combined
with the samples' ``s`` and ``t`` in three whole-array operations. A fixed row (most of a
humanoid's or the PR2's: sensor frames, links welded on) needs ``W0`` only: a depth's fixed rows
are one product written straight into their slots. A pose is stored transposed,
(column, row, sample), so every elementwise operation runs along the samples. Slots are
renumbered at build time so that each depth writes one contiguous block: no scatter.

One configuration is a batch of one (the same operations), so ``fk(q)`` and ``fk_batch(Q)[i]``
agree bit for bit; against the C core they agree to rounding (about 1e-15 on the PR2 and
Talos, see tests/test_fallback_batch.py), the products being summed in another order.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from robotspec.arrays import F64, I64
from robotspec.model._core_args import from_any, index, table, truth

KIND_FIXED = 0
KIND_REVOLUTE = 1
KIND_PRISMATIC = 2

#: Samples per step of a batch: the per-depth products of a step stay in the CPU's caches
#: (measured on the PR2: 512 to 2,000 samples are equally fast, 128 is a third slower).
_CHUNK = 1024


def copy_i64(obj: object, want: int, what: str) -> I64:
    """The C core's ``copy_i64``: exactly one dimension, ``want`` int64 values."""
    return _sized(from_any(obj, np.int64, 1, 1), want, what)


def copy_f64(obj: object, want: int, what: str) -> F64:
    """The C core's ``copy_f64``: any shape holding ``want`` float64 values."""
    return _sized(from_any(obj, np.float64), want, what)


def _sized(a: np.ndarray[Any, Any], want: int, what: str) -> np.ndarray[Any, Any]:
    if a.size != want:
        raise ValueError(f"{what}: expected {want} values, got {a.size}")
    return a.reshape(-1).copy()


def config(obj: object, ndim: int, width: int) -> F64:
    """The C core's ``as_config``: a configuration (ndim 1) or batch (ndim 2) of finite values."""
    a = from_any(obj, np.float64, ndim, ndim)
    if a.shape[-1] != width:
        raise ValueError("configuration has the wrong number of values")
    if not np.isfinite(a).all():
        raise ValueError("configuration contains NaN or infinite values")
    return a


def motion_terms(kind: I64, axis: F64) -> tuple[F64, F64]:
    """Each row's motion as ``I + a M1 + b M2`` (4x4 each, (R, 4, 4)): M1 and M2.

    Revolute (a = sin v, b = 1 - cos v): M1 = [u]x, M2 = u u^T - I, which is the C core's
    ``c I + s [u]x + t u u^T`` rearranged. Prismatic (a = v): M1 moves along u. Fixed: zeros.
    """
    n = len(kind)
    m1, m2 = np.zeros((n, 4, 4)), np.zeros((n, 4, 4))
    rev, pris = kind == KIND_REVOLUTE, kind == KIND_PRISMATIC
    x, y, z = axis[:, 0], axis[:, 1], axis[:, 2]
    for (r, c), v in {(0, 1): -z, (0, 2): y, (1, 0): z, (1, 2): -x, (2, 0): -y, (2, 1): x}.items():
        m1[:, r, c] = np.where(rev, v, 0.0)
    m2[:, :3, :3] = np.where(
        rev[:, None, None], axis[:, :, None] * axis[:, None, :] - np.eye(3), 0.0
    )
    m1[:, :3, 3] = np.where(pris[:, None], axis, 0.0)
    return m1, m2


#: One depth of a tree program: its moving rows (rows, slots read, weights (k, 12, 4), slots
#: written) and its fixed rows (slots read, W0^T (k, 4, 4), slots written), either None.
Step = tuple[tuple[slice, Any, F64, slice] | None, tuple[Any, F64, slice] | None]


@dataclass(frozen=True)
class Tree:
    """A tree program (see ``_kincore.c``), rearranged for numpy.

    Rows are sorted by depth (``levels``: (first, end) per depth); row k writes slot k + 1 (slot
    0 is the root), ``parent`` is the renumbered slot it reads, ``outputs`` the slot of each
    returned body. ``weights`` (R, 12, 4) is ``[W0 W1 W2]^T`` per row (module docstring).
    """

    n_slots: int
    n_out: int
    n_dof: int
    parent: I64
    outputs: I64
    dof: I64  # the DOF each row reads; n_dof (a row of zeros) for a fixed row
    mul: F64
    off: F64
    weights: F64
    revolute: I64  # rows that turn
    prismatic: I64  # rows that slide
    levels: tuple[tuple[int, int], ...]
    steps: tuple[Step, ...]  # per depth: (rows, reads, weights, writes) moving, fixed


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
    p = copy_i64(parent, n, "parent")
    c = copy_i64(child, n, "child")
    k = copy_i64(kind, n, "kind")
    d = copy_i64(dof, n, "dof")
    o = copy_f64(origin, 16 * n, "origin").reshape(n, 4, 4)
    a = copy_f64(axis, 3 * n, "axis").reshape(n, 3)
    m = copy_f64(mul, n, "mul")
    f = copy_f64(off, n, "off")
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
    return _arranged(n_slots, n_out, n_dof, p, c, k, d, o, a, m, f, row_depth)


def _arranged(
    n_slots: int,
    n_out: int,
    n_dof: int,
    p: I64,
    c: I64,
    k: I64,
    d: I64,
    o: F64,
    a: F64,
    m: F64,
    f: F64,
    row_depth: I64,
) -> Tree:
    """The checked rows sorted by depth, slots renumbered, each row's weights made."""
    # Within a depth, the moving rows first: the fixed ones need one product and no motion
    # (unless a slot is written twice, where C's row order decides which write stays).
    fixed = k == KIND_FIXED
    unique = len(np.unique(c)) == len(c)
    order = np.lexsort((fixed, row_depth)) if unique else np.argsort(row_depth, kind="stable")
    ends = np.searchsorted(row_depth[order], np.arange(1, int(row_depth.max(initial=0)) + 2))
    levels = tuple((int(lo), int(hi)) for lo, hi in zip(ends[:-1], ends[1:], strict=True))
    p, c, k = p[order], c[order], k[order]
    o, a, m, f = o[order], a[order], m[order], f[order]
    # Rows in depth order: a row's parent slot is final when the row runs (C's row order
    # within a depth is kept, so a slot written twice ends as in C).
    last = np.zeros(n_slots, dtype=np.int64)
    parent = np.empty(len(c), dtype=np.int64)
    for r in range(len(c)):
        parent[r] = last[p[r]]
        last[c[r]] = r + 1
    m1, m2 = motion_terms(k, a)
    weights = np.ascontiguousarray(np.concatenate([o, o @ m1, o @ m2], axis=2).transpose(0, 2, 1))
    steps = tuple(_step(lo, hi, parent, weights, k[lo:hi] == KIND_FIXED) for lo, hi in levels)
    return Tree(
        n_slots,
        n_out,
        n_dof,
        parent,
        last[:n_out].copy(),
        np.where(k == KIND_FIXED, n_dof, d[order]),
        m,
        f,
        weights,
        np.flatnonzero(k == KIND_REVOLUTE),
        np.flatnonzero(k == KIND_PRISMATIC),
        levels,
        steps,
    )


def _step(lo: int, hi: int, parent: I64, weights: F64, fixed: Any) -> Step:
    """One depth's work: its moving rows (all three terms) and its fixed ones (W0 only)."""
    n_move = int((~fixed).sum())
    if not fixed[n_move:].all():  # not sorted moving-first (see _arranged): all run as moving
        n_move = hi - lo
    mid = lo + n_move
    move = None
    if mid > lo:
        move = (slice(lo, mid), _reads(parent[lo:mid]), weights[lo:mid], slice(lo + 1, mid + 1))
    fix = None
    if hi > mid:
        w0 = np.ascontiguousarray(weights[mid:hi, :4])
        fix = (_reads(parent[mid:hi]), w0, slice(mid + 1, hi + 1))
    return move, fix


def _reads(parents: I64) -> slice | I64:
    """The slots one depth reads: a slice when they are consecutive (a view, not a copy)."""
    lo = int(parents[0])
    if (parents == np.arange(lo, lo + len(parents))).all():
        return slice(lo, lo + len(parents))
    return parents


def _tree_of(obj: object) -> Tree:
    return table(obj, Tree, "a tree program (from tree())")


def tree_size(tree: object) -> tuple[int, int]:
    """(bodies returned, degrees of freedom) of a tree program."""
    t = _tree_of(tree)
    return t.n_out, t.n_dof


def _run(t: Tree, q: F64, out: F64) -> None:
    """Every output pose of the samples of ``q`` (N, D) into ``out`` (N, B, 4, 4)."""
    n, rows = q.shape[0], len(t.mul)
    qt = np.zeros((t.n_dof + 1, n))
    qt[: t.n_dof] = q.T
    v = qt[t.dof] * t.mul[:, None] + t.off[:, None]  # (R, N): each row's motion value
    ab = np.zeros((rows, 2, n))  # per row and sample: a (sin v, or v sliding), b (1 - cos v)
    turn = v[t.revolute]
    ab[t.revolute, 0] = np.sin(turn)
    ab[t.revolute, 1] = 1.0 - np.cos(turn)
    ab[t.prismatic, 0] = v[t.prismatic]
    ab5 = ab[:, :, None, None, :]
    slots = np.empty((rows + 1, 4, 3, n))  # slot[column, row, sample]
    slots[0] = np.eye(4)[:, :3, None]
    flat = slots.reshape(rows + 1, 4, 3 * n)
    for move, fix in t.steps:
        if move is not None:
            rows_of, reads, weights, writes = move
            x = np.matmul(weights, flat[reads]).reshape(-1, 3, 4, 3, n)  # W0, W1, W2 terms
            moved = x[:, 1:]
            moved *= ab5[rows_of]  # a W1 and b W2 at once
            dst = slots[writes]
            np.add(x[:, 0], moved[:, 0], out=dst)
            dst += moved[:, 1]
        if fix is not None:
            reads, w0, writes = fix
            np.matmul(w0, flat[reads], out=flat[writes])
    out[:, :, :3, :] = slots[t.outputs].transpose(3, 0, 2, 1)
    out[:, :, 3, :] = (0.0, 0.0, 0.0, 1.0)


def fk(tree: object, q: object) -> F64:
    t = _tree_of(tree)
    qa = config(q, 1, t.n_dof)
    poses: F64 = np.empty((1, t.n_out, 4, 4))
    _run(t, qa[None, :], poses)  # a batch of one: fk_batch's operations, so its bits
    pose: F64 = poses[0]
    return pose


def fk_batch(tree: object, q: object, out: Any = None, stream: bool = False) -> F64:
    """Every pose of a batch; ``stream`` is the C core's choice of stores, meaningless here."""
    truth(stream)  # read as the C core reads it (an array of several values is an error)
    t = _tree_of(tree)
    qa = config(q, 2, t.n_dof)
    n = qa.shape[0]
    shape = (n, t.n_out, 4, 4)
    if out is None:
        out = np.empty(shape)
    else:
        check_out(out, shape)
    for lo in range(0, n, _CHUNK):
        _run(t, qa[lo : lo + _CHUNK], out[lo : lo + _CHUNK])
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
