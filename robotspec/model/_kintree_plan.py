"""A batch's steps of the numpy tree program: buffers and numpy calls bound once, run per step.

Why a module of its own: :mod:`robotspec.model._kintree_py` runs a configuration, or a few, by
walking the program's groups (finding each call's operands as it goes); a batch of thousands
runs the same calls on every step of a few hundred samples, so :func:`plan` finds the operands
once and binds each call to them (``functools.partial``), and a step is then the calls alone
(some 70 on the PR2: about 70 us a step fixed, against 130 us when the walk found them each
step; binding them costs about 200 us once a batch). The operations per sample are
the walk's (the same BLAS products of the same matrices, the same ufuncs on the same columns),
so a row of a batch is the single call's answer bit for bit.

Layout: a plan's ``rows`` (R, n, 4, 4) hold the bodies' poses in body order, a node's pose in
its body's row and each extra pose (a node's pose times a constant) in its own, then the nodes
that are no body's pose. A group's nodes are one strided view where their rows are evenly
spaced (the PR2's left and right arms), else a view each. So the step's poses are in the
result's order when the calls are done: one copy of whole 128-byte poses moves them into the
result (sample-major), with no gather in between.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from typing import Any

import numpy as np

from robotspec.arrays import F64, I64
from robotspec.model._kintree_build import GENERAL, TURN, Group, Tree

__all__ = ["Plan", "cos_sin", "general", "plan"]


def cos_sin(v: F64, cos: F64, sin: F64, half: Any = None, square: Any = None) -> None:
    """The cosine and sine of v from t = tan(v / 2): (1 - t^2) / (1 + t^2), 2 t / (1 + t^2).

    Why: numpy vectorises ``tan`` (SIMD, about 2 ns a value here) but not ``sin`` and ``cos``
    (about 15 ns each), and this is the one transcendental per turn. Near v = pi, t is large
    and both quotients stay accurate (sin v is about 2 / t); the results agree with the C
    core's ``sincos`` to a few units in the last place. ``half`` and ``square``: scratch
    arrays shaped like ``v`` (a plan's, reused), or None for new ones.
    """
    t = np.multiply(v, 0.5, out=half)
    np.tan(t, out=t)
    t2 = np.multiply(t, t, out=square)
    np.subtract(1.0, t2, out=cos)
    t2 += 1.0
    cos /= t2
    np.multiply(t, 2.0, out=sin)
    sin /= t2


def _motion_calls(
    g: Group, dst: F64, motion: slice, v: F64, turns: Any
) -> list[Callable[[], object]]:
    """A group's motion on its nodes' poses ``dst`` (k, n, 4, 4), as numpy calls to make.

    The walk's operations (``_kintree_py._run_few``), bound: a turn multiplies two columns,
    seen as one complex number, by ``exp(-i angle)`` (``turns``: (turns, n, 4), a factor per
    row of a pose); a slide adds ``v`` times column k to column 3.
    """
    c = g.column
    if g.how == TURN:
        cols = dst[..., c : c + 2].view(np.complex128)[..., 0]
        return [partial(np.multiply, cols, turns[motion], out=cols)]
    col3, moved = dst[..., 3], np.empty(dst.shape[:3])
    return [
        partial(np.multiply, dst[..., c], v[motion][:, :, None], out=moved),
        partial(np.add, col3, moved, out=col3),
    ]


def general(g: Group, store: F64, parents: Any, dst: F64, v: F64) -> None:
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
class Plan:
    """A batch's steps: one set of buffers, and the numpy calls bound to them, made once.

    Why: a step is some 50 numpy calls, and finding their operands (views, reshapes, slices)
    costs as much again in Python; bound once per batch, a step is the calls alone. ``rows``
    (R, n, 4, 4) holds the bodies' poses in body order (a node's pose in its body's row, each
    extra pose written in its own), then the nodes that are no body's pose: the step's poses
    are then in the result's order, with nothing to gather.
    """

    dof: I64  # per motion row: the index of its configuration value
    v: F64  # (motion rows, n): a step's configuration values, then its motion values
    calls: tuple[Callable[[], object], ...]
    bodies: Any  # (B, n): the first B rows as whole 128-byte poses

    def run(self, q_t: F64, out: F64) -> None:
        """One step: the first samples (up to n) of ``q_t`` (D, N), their poses into ``out``.

        A last step of fewer samples reuses the calls on zeros past its samples, and only its
        samples' poses are copied out.
        """
        m = min(self.v.shape[1], len(out))
        if m == self.v.shape[1]:
            np.take(q_t[:, :m], self.dof, axis=0, out=self.v, mode="clip")
        else:
            self.v[:, m:] = 0.0
            self.v[:, :m] = np.take(q_t[:, :m], self.dof, axis=0, mode="clip")
        for call in self.calls:
            call()
        # Whole poses (128 bytes) moved at once into the result's layout.
        n_out = self.bodies.shape[0]
        out[:m].reshape(m, n_out, 16).view("V128")[..., 0][...] = self.bodies[:, :m].T


def plan(t: Tree, n: int) -> Plan:
    """The calls of a batch's steps of ``n`` samples: nodes by depth, then extra poses."""
    row, n_rows = _node_rows(t)
    rows = np.empty((n_rows, n, 4, 4))
    rows[row[0]] = np.eye(4)
    v = np.empty((len(t.dof), n))
    turns = np.empty((t.n_turn, n, 4), dtype=np.complex128)  # a factor per row of a pose
    calls = _motion_value_calls(t, v, turns)
    for g in t.groups:
        calls += _group_calls(g, rows, row, v, turns)
    flat = _view(rows, (n_rows, 4 * n, 4))
    for node, run, at in t.layout.runs:  # a product per node, written at the bodies' rows
        calls.append(_product(flat[row[node]], t.extra_pose[run], flat[at]))
    whole = rows.reshape(n_rows, n, 16).view("V128")[..., 0]  # (R, n) whole poses
    pairs = [
        (body, row[node])
        for body, node in zip(t.layout.node_out.tolist(), t.layout.node_at.tolist(), strict=True)
        if row[node] != body  # a second body at a node's pose: a copy of the first's
    ]
    if pairs:
        seconds, firsts = (np.array(side, dtype=np.int64) for side in zip(*pairs, strict=True))
        calls.append(partial(_copy_rows, _view(rows, (n_rows, 16 * n)), seconds, firsts))
    bodies = whole[: t.n_out]
    return Plan(t.dof, v, tuple(calls), bodies)


def _motion_value_calls(t: Tree, v: F64, turns: Any) -> list[Callable[[], object]]:
    """A step's motion values and turns from its configuration values, as the walk's.

    The quotients in whole rows, as the walk computes them (the same bits), then copied into
    the complex parts of ``turns`` (turns, n, 4), once per row of a pose. Why four copies: a
    turn's multiplication then runs over a node's rows and samples as one long loop, where a
    factor broadcast over the rows makes numpy loop four values at a time (PR2, 250 samples:
    the turns 120 -> 50 us a step, the copies 10 -> 50 us).
    """
    cos, sin, half, square = np.empty((4, t.n_turn, v.shape[1]))
    return [
        partial(np.multiply, v, t.mul[:, None], out=v),
        partial(np.add, v, t.off[:, None], out=v),
        partial(cos_sin, v[: t.n_turn], cos, sin, half, square),
        partial(np.copyto, turns.real, cos[:, :, None]),
        partial(np.copyto, turns.imag, sin[:, :, None]),
    ]


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
    parent_rows = [row[p] for p in g.parents.tolist()]
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
    b = a.reshape(shape)
    if not np.may_share_memory(a, b):
        raise ValueError(f"a plan's view {a.shape} -> {shape} would be a copy")
    return b


def _product(lhs: F64, weights: F64, out: F64) -> Callable[[], object]:
    """``out = lhs @ weights`` as a call: ``np.dot`` for one matrix (less fixed cost)."""
    if len(weights) == 1 and lhs.ndim == 2:
        return partial(np.dot, lhs, weights[0], out[0])
    return partial(np.matmul, lhs, weights, out)


def _copy_rows(flat: F64, dst: I64, src: I64) -> None:
    """Rows ``src`` of ``flat`` (R, 16 n) copied to rows ``dst``: whole rows, one block each."""
    flat[dst] = flat[src]


def _general_rows(g: Group, rows: F64, parents: list[int], dst: list[int], v: F64) -> None:
    """:func:`general` for a plan's rows, which need not be evenly spaced."""
    poses = np.empty((len(dst),) + rows.shape[1:])
    general(g, rows, parents, poses, v)
    rows[dst] = poses
