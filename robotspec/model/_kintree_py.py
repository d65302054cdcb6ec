"""The tree program of the kinematics core in numpy: every body pose, vectorised over samples.

Why a module of its own: this is the fallback's hot path (``forward``, ``forward_batch`` and
the collision checker's poses without the C core), laid out for numpy rather than for C.
:mod:`robotspec.model._kincore_py` re-exports its entry points (``tree``, ``tree_size``, ``fk``,
``fk_batch``), whose arguments and errors are the C core's (see ``_kincore.pyi``).

How it stays fast: only moving rows cost per sample. The program is evaluated symbolically once
(:mod:`robotspec.model._kintree_build`), in the C core's row order: a slot's pose is some
*node*'s pose times a constant, so a fixed row (51 of the PR2's 84: sensor frames, links welded
on) only multiplies constants, and a chain of fixed rows and a moving row's origin fold into that
moving row's weights. Each moving row is a node: ``node = parent node @ W @ motion(v)``. A turn
about frame axis k mixes two columns, which numpy sees as ONE complex multiplication by
``exp(-iv)`` for a whole group (x: columns 1 and 2, z: 0 and 1; about y the columns are stored
permuted, exactly, and the constant after it undoes that); a slide along frame axis k adds ``v``
times column k to column 3; any other axis keeps Rodrigues' terms ``W0 + sin v W1 +
(1 - cos v) W2``. The cosine and sine of every turn come from one vectorised ``tan`` per batch.
Nodes are grouped by depth and kind; a group is one stacked matrix product (``(k, 4n, 4) @ (k,
4, 4)``, samples and rows as the long side, so BLAS sees tall matrices; parents read as slices
or broadcast, not gathered) written in place, and one motion operation. A body fixed to a node
is the node's pose times a constant: one product per node for all its fixed bodies. Then one
gather in body order and one copy into the result's layout.

Poses are stored sample-major per node, (node, sample, 4, 4), so the last copy moves whole
128-byte poses; a batch runs in steps of ``_CHUNK`` samples whose buffers stay in the caches.
One configuration is a batch of one (the same operations), so ``fk(q)`` and ``fk_batch(Q)[i]``
agree bit for bit; against the C core they agree to rounding (about 1e-15 on the PR2 and Talos,
see tests/test_fallback_batch.py), the products being summed in another order.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from robotspec.arrays import F64
from robotspec.model._core_args import table, truth
from robotspec.model._kintree_build import (
    GENERAL,
    KIND_FIXED,
    KIND_PRISMATIC,
    KIND_REVOLUTE,
    TURN,
    Layout,
    Tree,
    config,
    copy_f64,
    copy_i64,
    motion_terms,
    tree,
)

__all__ = [
    "KIND_FIXED",
    "KIND_PRISMATIC",
    "KIND_REVOLUTE",
    "check_out",
    "config",
    "copy_f64",
    "copy_i64",
    "fk",
    "fk_batch",
    "motion_terms",
    "tree",
    "tree_size",
]

#: Fewer samples than this: a step's constant products gather their nodes (two numpy calls),
#: not one product per node (fewer copies, more calls).
_GATHER_BELOW = 32
#: Samples per step of a batch: the step's buffers (node poses, gathered and final body poses:
#: about 3 MB on the PR2) stay in the caches.
_CHUNK = 256


def _tree_of(obj: object) -> Tree:
    return table(obj, Tree, "a tree program (from tree())")


def tree_size(tree: object) -> tuple[int, int]:
    """(bodies returned, degrees of freedom) of a tree program."""
    t = _tree_of(tree)
    return t.n_out, t.n_dof


def _buffers(t: Tree, n: int) -> tuple[F64, F64, Any]:
    """A step's store (node poses, root set to the identity, then extra poses) and gathers.

    The last is the body poses in body order (B, n), whole 128-byte poses, made once for every
    step: a fresh array of that size per step is fresh pages, which the kernel clears first.
    """
    store = np.empty((t.n_nodes + len(t.extra_node), n, 4, 4))
    store[0] = np.eye(4)
    return store, np.empty((len(t.extra_node), n, 4, 4)), np.empty((t.n_out, n), dtype="V128")


def _cos_sin(v: F64, cos: F64, sin: F64) -> None:
    """The cosine and sine of v from t = tan(v / 2): (1 - t^2) / (1 + t^2), 2 t / (1 + t^2).

    Why: numpy vectorises ``tan`` (SIMD, about 2 ns a value here) but not ``sin`` and ``cos``
    (about 15 ns each), and this is the one transcendental per turn. Near v = pi, t is large
    and both quotients stay accurate (sin v is about 2 / t); the results agree with the C
    core's ``sincos`` to a few units in the last place.
    """
    t = np.multiply(v, 0.5)
    np.tan(t, out=t)
    t2 = np.multiply(t, t)
    np.subtract(1.0, t2, out=cos)
    t2 += 1.0
    cos /= t2
    np.multiply(t, 2.0, out=sin)
    sin /= t2


def _motions(t: Tree, q: F64) -> tuple[F64, Any]:
    """Every motion row's value (rows, N) and every turn's ``exp(-i angle)``, for all samples.

    Made once for the whole batch (a few whole-array operations), not once per step.
    """
    n = q.shape[0]
    v = q[:, t.dof].T.copy() if n < _GATHER_BELOW else np.ascontiguousarray(q.T)[t.dof]
    v *= t.mul[:, None]  # (motion rows, N)
    v += t.off[:, None]
    turns = np.empty((t.n_turn, n), dtype=np.complex128)
    if n < _GATHER_BELOW:
        _cos_sin(v[: t.n_turn], turns.real, turns.imag)
        return v, turns
    # A batch: the quotients in whole rows, then one copy each into the complex parts (their
    # views interleave; computing in them costs twice as much). The same operations, so the
    # same bits as a single configuration's.
    cos, sin = np.empty((2, t.n_turn, n))
    _cos_sin(v[: t.n_turn], cos, sin)
    turns.real, turns.imag = cos, sin
    return v, turns


def _run(
    t: Tree, v: F64, turns: Any, out: F64, bufs: tuple[F64, F64, Any], layout: Layout | None
) -> None:
    """Every output pose of one step into ``out`` (n, B, 4, 4), from its motions (see above).

    ``layout`` (a batch's steps): where each extra pose goes among the bodies, so the products
    write them there and only the nodes' poses are gathered; None (a few samples): everything is
    gathered.
    """
    n = v.shape[1]
    store, gathered, ordered = bufs
    for g in t.groups:
        k = g.nodes.stop - g.nodes.start
        dst = store[g.nodes]
        if g.how == GENERAL:
            src = np.take(store, g.parents, axis=0)
            x = np.matmul(src.reshape(k, 4 * n, 4), g.weights).reshape(k, n, 4, 3, 4)
            val = v[g.motion][:, :, None, None]
            first = np.where(g.turning, np.sin(val), val)
            second = np.where(g.turning, 1.0 - np.cos(val), 0.0)
            np.add(x[..., 0, :], x[..., 1, :] * first, out=dst)
            dst += x[..., 2, :] * second
            continue
        for part, src in g.reads:
            width = part.stop - part.start
            if isinstance(src, slice | int):
                lhs = store[src].reshape(-1, 4 * n, 4)
            else:
                lhs = np.take(store, src, axis=0).reshape(width, 4 * n, 4)
            np.matmul(lhs, g.weights[part], out=dst[part].reshape(width, 4 * n, 4))
        if g.how == TURN:  # the two columns as one complex number, turned at once
            cols = dst[..., g.column : g.column + 2].view(np.complex128)[..., 0]
            cols *= turns[g.motion][:, :, None]
        else:  # a slide: column 3 += v column k
            dst[..., 3] += dst[..., g.column] * v[g.motion][:, :, None]
    poses = store.reshape(len(store), n, 16).view("V128")[..., 0]
    if layout is None:  # a few samples: one gather and one product for all extra poses
        n_extra = len(t.extra_node)
        extra = store[t.n_nodes :].reshape(n_extra, 4 * n, 4)
        np.take(store, t.extra_node, axis=0, out=gathered, mode="clip")
        np.matmul(gathered.reshape(n_extra, 4 * n, 4), t.extra_pose, out=extra)
        np.take(poses, t.at, axis=0, out=ordered, mode="clip")  # (t.at is in range: no check)
    else:  # a product per node, its poses broadcast, written at the bodies' places in order
        in_order = ordered.view(np.float64).reshape(t.n_out, 4 * n, 4)
        for node, run, at in layout.runs:
            np.matmul(store[node].reshape(4 * n, 4), t.extra_pose[run], out=in_order[at])
        ordered[layout.node_out] = poses[layout.node_at]
    # Whole poses (128 bytes) moved at once into the result's layout.
    out.reshape(n, t.n_out, 16).view("V128")[..., 0][...] = ordered.T


def fk(tree: object, q: object) -> F64:
    t = _tree_of(tree)
    qa = config(q, 1, t.n_dof)
    poses: F64 = np.empty((1, t.n_out, 4, 4))
    v, turns = _motions(t, qa[None, :])
    _run(t, v, turns, poses, _buffers(t, 1), None)  # a batch of one: fk_batch's operations
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
    bufs = _buffers(t, min(n, _CHUNK))  # one set for every full step, reused
    v, turns = _motions(t, qa)
    for lo in range(0, n, _CHUNK):
        hi = min(n, lo + _CHUNK)
        fits = hi - lo == bufs[0].shape[1]
        step = v[:, lo:hi], turns[:, lo:hi]
        where = None if hi - lo < _GATHER_BELOW else t.layout
        _run(t, *step, out[lo:hi], bufs if fits else _buffers(t, hi - lo), where)
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
