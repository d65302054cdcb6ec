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
(1 - cos v) W2``. The cosine and sine of every turn come from one vectorised ``tan`` per step.
Nodes are grouped by depth and kind; a group is a stacked matrix product (``(k, 4n, 4) @ (k,
4, 4)``, samples and rows as the long side, so BLAS sees tall matrices; parents read as slices
or broadcast, not gathered) written in place, and one motion operation. A body fixed to a node
is the node's pose times a constant: one product per node for all its fixed bodies.

Poses are stored sample-major per node, (node, sample, 4, 4), so the last copy into the result
moves whole 128-byte poses. A batch runs in equal steps of at most ``_CHUNK`` samples whose
buffers stay in the caches, each step the same numpy calls, bound once per batch to the step's
buffers and with every body's pose written in body order (:mod:`robotspec.model._kintree_plan`).
A few samples (one configuration) are walked group by group instead (:func:`_run_few`): binding
costs more than it saves there. Both do the same operations per sample, so ``fk(q)`` and
``fk_batch(Q)[i]`` agree bit for bit; against the C core they agree to rounding (about 1e-15 on
the PR2 and Talos, see tests/test_fallback_batch.py), the products being summed in another order.
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
    Tree,
    config,
    copy_f64,
    copy_i64,
    motion_terms,
    tree,
)
from robotspec.model._kintree_plan import cos_sin, general, plan

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

#: Fewer samples than this: a batch runs as one step of a few samples (:func:`_run_few`), whose
#: constant products gather their nodes (two numpy calls), not one product per node.
_GATHER_BELOW = 32
#: Samples per step of a batch, at most: the steps are made equal (2,000 samples: 8 of 250), so
#: that one plan (:mod:`robotspec.model._kintree_plan`) serves them all. Its rows (about 2.9 MB
#: on the PR2 for 250) stay in the caches, and the fixed cost of a step (some 70 numpy calls,
#: about 70 us) is paid 8 times. Measured (PR2, 2,000 samples, interleaved): steps of 128 and
#: 160 samples cost 5-10 % more, 192 to 384 the same within the noise, 512 10 % more.
_CHUNK = 256


def _tree_of(obj: object) -> Tree:
    return table(obj, Tree, "a tree program (from tree())")


def tree_size(tree: object) -> tuple[int, int]:
    """(bodies returned, degrees of freedom) of a tree program."""
    t = _tree_of(tree)
    return t.n_out, t.n_dof


def _motions(t: Tree, q: F64) -> tuple[F64, Any]:
    """Every motion row's value (rows, N) and every turn's ``exp(-i angle)``, for a few samples.

    A batch's steps compute theirs in their plan, with the same operations.
    """
    v = q[:, t.dof].T.copy()
    v *= t.mul[:, None]  # (motion rows, N)
    v += t.off[:, None]
    turns = np.empty((t.n_turn, q.shape[0]), dtype=np.complex128)
    cos_sin(v[: t.n_turn], turns.real, turns.imag)
    return v, turns


def _run_few(t: Tree, v: F64, turns: Any, out: F64) -> None:
    """Every output pose of a few samples (one configuration) into ``out`` (n, B, 4, 4).

    The nodes' poses into a store (node, n, 4, 4), the extra poses gathered with one product,
    then one gather in body order. The same operations per sample as a batch's plan (a product
    is one BLAS product of the same matrices, a motion the same ufunc on the same columns), so
    a configuration and its row in a batch agree bit for bit.
    """
    n = v.shape[1]
    store = np.empty((t.n_nodes + len(t.extra_node), n, 4, 4))
    store[0] = np.eye(4)
    for g in t.groups:
        dst = store[g.nodes]
        if g.how == GENERAL:
            general(g, store, g.parents, dst, v)
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
    n_extra = len(t.extra_node)
    extra = store[t.n_nodes :].reshape(n_extra, 4 * n, 4)
    gathered = np.take(store, t.extra_node, axis=0).reshape(n_extra, 4 * n, 4)
    np.matmul(gathered, t.extra_pose, out=extra)
    poses = store.reshape(len(store), n, 16).view("V128")[..., 0]
    ordered = np.take(poses, t.at, axis=0)  # (B, n)
    out.reshape(n, t.n_out, 16).view("V128")[..., 0][...] = ordered.T


def fk(tree: object, q: object) -> F64:
    t = _tree_of(tree)
    qa = config(q, 1, t.n_dof)
    poses: F64 = np.empty((1, t.n_out, 4, 4))
    _run_few(t, *_motions(t, qa[None, :]), poses)  # a batch of one: fk_batch's operations
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
    if 0 < n < _GATHER_BELOW:
        _run_few(t, *_motions(t, qa), out)
    elif n:
        steps = -(-n // _CHUNK)
        steps_of = plan(t, -(-n // steps))
        q_t = np.ascontiguousarray(qa.T)
        for lo in range(0, n, steps_of.v.shape[1]):
            steps_of.run(q_t[:, lo:], out[lo:])
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
