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

from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
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
    Group,
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

#: Fewer samples than this: a batch runs as one step of a few samples (:func:`_run_few`), whose
#: constant products gather their nodes (two numpy calls), not one product per node.
_GATHER_BELOW = 32
#: Samples per step of a batch, at most: the steps are made equal (2,000 samples: 8 of 250), so
#: that one :class:`_Plan` serves them all. Its rows (about 2.7 MB on the PR2 for 250) stay in
#: the caches; the fixed cost of a step (some 50 numpy calls, 50 us) is paid 8 times.
_CHUNK = 256

#: Rows 0-2 of a pose: the last row of every node's pose is (0, 0, 0, 1) after its product (an
#: affine constant times an affine pose), which a turn or a slide leaves as it is.
_ROWS = slice(0, 3)


def _tree_of(obj: object) -> Tree:
    return table(obj, Tree, "a tree program (from tree())")


def tree_size(tree: object) -> tuple[int, int]:
    """(bodies returned, degrees of freedom) of a tree program."""
    t = _tree_of(tree)
    return t.n_out, t.n_dof


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


def _run_few(t: Tree, v: F64, turns: Any, out: F64) -> None:
    """Every output pose of a few samples (one configuration) into ``out`` (n, B, 4, 4).

    The nodes' poses into a store (node, n, 4, 4), the extra poses gathered with one product,
    then one gather in body order. The same operations per sample as a :class:`_Plan`'s (a
    product is one BLAS product of the same matrices, a motion the same ufunc on rows 0-2), so
    a configuration and its row in a batch agree bit for bit.
    """
    n = v.shape[1]
    store = np.empty((t.n_nodes + len(t.extra_node), n, 4, 4))
    store[0] = np.eye(4)
    for g in t.groups:
        dst = store[g.nodes]
        if g.how == GENERAL:
            _general(g, store, g.parents, dst, v)
            continue
        for part, src in g.reads:
            width = part.stop - part.start
            if isinstance(src, slice | int):
                lhs = store[src].reshape(-1, 4 * n, 4)
            else:
                lhs = np.take(store, src, axis=0).reshape(width, 4 * n, 4)
            np.matmul(lhs, g.weights[part], out=dst[part].reshape(width, 4 * n, 4))
        for call in _motion_calls(g, dst, g.motion, v, turns):
            call()
    n_extra = len(t.extra_node)
    extra = store[t.n_nodes :].reshape(n_extra, 4 * n, 4)
    gathered = np.take(store, t.extra_node, axis=0).reshape(n_extra, 4 * n, 4)
    np.matmul(gathered, t.extra_pose, out=extra)
    poses = store.reshape(len(store), n, 16).view("V128")[..., 0]
    ordered = np.take(poses, t.at, axis=0)  # (B, n)
    out.reshape(n, t.n_out, 16).view("V128")[..., 0][...] = ordered.T


def _motion_calls(
    g: Group, dst: F64, motion: slice, v: F64, turns: Any
) -> list[Callable[[], object]]:
    """A group's motion on its nodes' poses ``dst`` (k, n, 4, 4), as numpy calls to make.

    Rows 0-2 of the moved columns are viewed as (node, row, sample), and ``order="C"`` makes
    numpy's inner loop run over the samples rather than over a pose's rows.
    """
    c, n = g.column, dst.shape[1]
    if g.how == TURN:  # the two columns as one complex number, turned at once
        cols = dst[:, :, _ROWS, c : c + 2].view(np.complex128)[..., 0].transpose(0, 2, 1)
        return [partial(np.multiply, cols, turns[motion][:, None, :], out=cols, order="C")]
    # a slide: column 3 += v column k
    col3 = dst[:, :, _ROWS, 3].transpose(0, 2, 1)
    along = dst[:, :, _ROWS, c].transpose(0, 2, 1)
    moved = np.empty((len(dst), 3, n))
    return [
        partial(np.multiply, along, v[motion][:, None, :], out=moved, order="C"),
        partial(np.add, col3, moved, out=col3, order="C"),
    ]


def _general(g: Group, store: F64, parents: Any, dst: F64, v: F64) -> None:
    """A group about axes that are not frame axes: Rodrigues' terms (see the docstring).

    ``parents``: the parents' rows of ``store``; ``dst`` (k, n, 4, 4): where the poses go.
    """
    k, n = len(dst), store.shape[1]
    src = np.take(store, parents, axis=0)
    x = np.matmul(src.reshape(k, 4 * n, 4), g.weights).reshape(k, n, 4, 3, 4)
    val = v[g.motion][:, :, None, None]
    first = np.where(g.turning, np.sin(val), val)
    second = np.where(g.turning, 1.0 - np.cos(val), 0.0)
    np.add(x[..., 0, :], x[..., 1, :] * first, out=dst)
    dst += x[..., 2, :] * second


@dataclass(frozen=True)
class _Plan:
    """A batch's steps: one set of buffers, and the numpy calls bound to them, made once.

    Why: a step is some 50 numpy calls, and finding their operands (views, reshapes, slices)
    costs as much again in Python; bound once per batch, a step is the calls alone. ``rows``
    (R, n, 4, 4) holds the bodies' poses in body order (a node's pose in its body's row, each
    extra pose written in its own), then the nodes that are no body's pose: the step's poses
    are then in the result's order, with nothing to gather.
    """

    v: F64  # (motion rows, n): a step's motion values, copied in by run()
    turns: Any  # (turns, n) complex: a step's exp(-i angle)
    calls: tuple[Callable[[], object], ...]
    bodies: Any  # (B, n): the first B rows as whole 128-byte poses

    def run(self, v: F64, turns: Any, out: F64) -> None:
        """One step: the first samples of ``v`` and ``turns`` (up to n), their poses into ``out``.

        A last step of fewer samples reuses the calls: the columns past them keep the previous
        step's values (finite), and only the samples' poses are copied out.
        """
        m = min(self.v.shape[1], len(out))
        self.v[:, :m] = v[:, :m]
        self.turns[:, :m] = turns[:, :m]
        for call in self.calls:
            call()
        # Whole poses (128 bytes) moved at once into the result's layout.
        n_out = self.bodies.shape[0]
        out[:m].reshape(m, n_out, 16).view("V128")[..., 0][...] = self.bodies[:, :m].T


def _plan(t: Tree, n: int) -> _Plan:
    """The calls of a batch's steps of ``n`` samples: nodes by depth, then extra poses."""
    row, n_rows = _node_rows(t)
    rows = np.empty((n_rows, n, 4, 4))
    rows[row[0]] = np.eye(4)
    v = np.empty((len(t.dof), n))
    turns = np.empty((t.n_turn, n), dtype=np.complex128)
    calls: list[Callable[[], object]] = []
    for g in t.groups:
        calls += _group_calls(g, rows, row, v, turns)
    flat = _view(rows, (n_rows, 4 * n, 4))
    for node, run, at in t.layout.runs:  # a product per node, written at the bodies' rows
        calls.append(_product(flat[row[node]], t.extra_pose[run], flat[at]))
    for body, node in zip(t.layout.node_out.tolist(), t.layout.node_at.tolist(), strict=True):
        if row[node] != body:  # a second body at a node's pose
            calls.append(partial(np.copyto, rows[body], rows[row[node]]))
    bodies = rows[: t.n_out].reshape(t.n_out, n, 16).view("V128")[..., 0]
    return _Plan(v, turns, tuple(calls), bodies)


def _node_rows(t: Tree) -> tuple[list[int], int]:
    """Each node's row in a plan: its (first) body's, or one after the bodies; the row count."""
    row = [-1] * t.n_nodes
    for body, node in zip(t.layout.node_out.tolist(), t.layout.node_at.tolist(), strict=True):
        if row[node] < 0:
            row[node] = body
    n_rows = t.n_out
    for i in range(t.n_nodes):
        if row[i] < 0:
            row[i], n_rows = n_rows, n_rows + 1
    return row, n_rows


def _group_calls(
    g: Group, rows: F64, row: list[int], v: F64, turns: Any
) -> list[Callable[[], object]]:
    """A group's products and motions, one of each per run of evenly spaced rows (see _runs)."""
    dst_rows = [row[i] for i in range(g.nodes.start, g.nodes.stop)]
    parent_rows = [row[int(p)] for p in g.parents]
    if g.how == GENERAL:
        return [partial(_general_rows, g, rows, parent_rows, dst_rows, v)]
    n = rows.shape[1]
    calls: list[Callable[[], object]] = []
    for lo, hi in _runs(dst_rows, parent_rows):
        dst = rows[_span(dst_rows[lo:hi])]
        parents = parent_rows[lo:hi]
        if parents[-1] == parents[0]:  # one parent: its poses broadcast
            lhs = _view(rows[parents[0]], (4 * n, 4))
        else:
            lhs = _view(rows[_span(parents)], (hi - lo, 4 * n, 4))
        calls.append(_product(lhs, g.weights[lo:hi], _view(dst, (hi - lo, 4 * n, 4))))
        motion = slice(g.motion.start + lo, g.motion.start + hi)
        calls += _motion_calls(g, dst, motion, v, turns)
    return calls


def _runs(dst: list[int], parents: list[int]) -> list[tuple[int, int]]:
    """A group's members as runs, each a strided view of the rows (start, stop in the group).

    A run ends where its rows, or its parents' rows, stop being evenly spaced (rows increasing,
    parents increasing or all one parent).
    """
    runs: list[tuple[int, int]] = []
    lo = 0
    while lo < len(dst):
        hi = lo + 1
        if hi < len(dst) and dst[hi] > dst[lo] and parents[hi] >= parents[lo]:
            step, p_step = dst[hi] - dst[lo], parents[hi] - parents[lo]
            while (
                hi < len(dst)
                and dst[hi] - dst[hi - 1] == step
                and parents[hi] - parents[hi - 1] == p_step
            ):
                hi += 1
        runs.append((lo, hi))
        lo = hi
    return runs


def _span(r: list[int]) -> slice:
    """Evenly spaced increasing rows as a slice."""
    return slice(r[0], r[-1] + 1, r[1] - r[0] if len(r) > 1 else 1)


def _view(a: F64, shape: tuple[int, ...]) -> F64:
    """``a`` reshaped without a copy (an error if that needs one: the calls write through it)."""
    b = a.view()
    b.shape = shape
    return b


def _product(lhs: F64, weights: F64, out: F64) -> Callable[[], object]:
    """``out = lhs @ weights`` as a call: ``np.dot`` for one matrix (less fixed cost)."""
    if len(weights) == 1 and lhs.ndim == 2:
        return partial(np.dot, lhs, weights[0], out[0])
    return partial(np.matmul, lhs, weights, out)


def _general_rows(g: Group, rows: F64, parents: list[int], dst: list[int], v: F64) -> None:
    """:func:`_general` for a plan's rows, which need not be evenly spaced."""
    poses = np.empty((len(dst),) + rows.shape[1:])
    _general(g, rows, parents, poses, v)
    rows[dst] = poses


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
    v, turns = _motions(t, qa)
    if 0 < n < _GATHER_BELOW:
        _run_few(t, v, turns, out)
    elif n:
        steps = -(-n // _CHUNK)
        plan = _plan(t, -(-n // steps))
        for lo in range(0, n, plan.v.shape[1]):
            plan.run(v[:, lo:], turns[:, lo:], out[lo:])
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
