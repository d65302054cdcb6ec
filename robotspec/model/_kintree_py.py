"""The tree program of the kinematics core in numpy: every body pose, vectorised over samples.

Why a module of its own: this is the fallback's hot path (``forward``, ``forward_batch`` and
the collision checker's poses without the C core), laid out for numpy rather than for C.
:mod:`robotspec.model._kincore_py` re-exports its entry points (``tree``, ``tree_size``, ``fk``,
``fk_batch``), whose arguments and errors are the C core's (see ``_kincore.pyi``).

How it stays fast: only moving rows cost per sample. The program is evaluated symbolically once,
in the C core's row order: a slot's pose is some *node*'s pose times a constant, so a fixed row
(51 of the PR2's 84: sensor frames, links welded on) only multiplies constants, and a chain of
fixed rows and a moving row's origin fold into that moving row's weights. Each moving row is a
node: ``node = parent node @ W @ motion(v)``. A motion about or along a frame axis (almost
every joint) is stored with its columns permuted so that the axis is the stored z (the
permutation, exact, goes into the constants after it): then a turn mixes stored columns 0 and 1,
which numpy sees as ONE complex multiplication by ``exp(-iv)`` over the whole group, and a slide
adds ``v`` times column 2 to column 3. Any other axis keeps the Rodrigues terms
``W0 + sin(v) W1 + (1 - cos v) W2``. Nodes are grouped by depth and kind; one group is one
stacked matrix product (``(k, 4n, 4) @ (k, 4, 4)``, samples and rows as the long side, so BLAS
sees tall matrices) written in place and one motion operation. The bodies are then one gather
and one stacked product by their constants, and one copy into the result's layout.

Poses are stored sample-major per node, (node, sample, 4, 4), so the last copy moves whole
128-byte poses; a batch runs in steps of ``_CHUNK`` samples whose buffers stay in the caches.
One configuration is a batch of one (the same operations), so ``fk(q)`` and ``fk_batch(Q)[i]``
agree bit for bit; against the C core they agree to rounding (about 1e-15 on the PR2 and Talos,
see tests/test_fallback_batch.py), the products being summed in another order.
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

#: How a node moves: about its stored z axis (a frame axis), along it, or by Rodrigues' terms.
TURN, SLIDE, GENERAL = 0, 1, 2

#: Samples per step of a batch: the step's buffers (node poses, gathered and final body poses:
#: about 3 MB on the PR2) stay in the caches.
_CHUNK = 256


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


@dataclass(frozen=True)
class Group:
    """The nodes of one depth that move one way: one matrix product and one motion for all."""

    how: int  # TURN, SLIDE or GENERAL
    nodes: slice  # the node slots written
    reads: slice | I64  # their parents' node slots (a slice when consecutive: a view)
    weights: F64  # (k, 4, 4); GENERAL: (k, 4, 12), [W0 W1 W2]
    motion: slice  # their rows of the motion values (Tree.dof)
    turning: Any  # GENERAL only: (k, 1, 1, 1) whether each turns (else it slides)


@dataclass(frozen=True)
class Tree:
    """A tree program (see ``_kincore.c``), rearranged for numpy (module docstring).

    Node 0 is the root (the identity); ``groups`` compute the others, in depth order. Motion
    rows (``dof``, ``mul``, ``off``: value ``q[dof] * mul + off``) are the turns first (their
    value is minus the C core's angle), then the slides, then the general motions. Body ``b`` is
    node ``out_node[b]`` times ``out_pose[b]``.
    """

    n_slots: int
    n_out: int
    n_dof: int
    n_nodes: int
    dof: I64
    mul: F64
    off: F64
    n_turn: int
    groups: tuple[Group, ...]
    out_node: I64
    out_pose: F64


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
    return _program(n_slots, n_out, n_dof, (p, c, k, d, o, a, m, f), row_depth)


def _frame_axis(u: F64) -> tuple[int, float] | None:
    """(k, sign) when ``u`` is +-e_k exactly (the C core's ``motion_code`` test), else None."""
    for k in range(3):
        if u[k] in (1.0, -1.0) and u[(k + 1) % 3] == 0.0 and u[(k + 2) % 3] == 0.0:
            return k, float(u[k])
    return None


def _program(n_slots: int, n_out: int, n_dof: int, rows: tuple[Any, ...], row_depth: I64) -> Tree:
    """The checked rows, evaluated symbolically in the C core's order, as groups of nodes."""
    p, c, k, d, o, a, m, f = rows
    o = o.copy()
    o[:, 3] = (0.0, 0.0, 0.0, 1.0)  # the C core reads an origin's three first rows only
    on_node = np.zeros(n_slots, dtype=np.int64)  # slot = node pose @ times[slot]
    times = np.tile(np.eye(4), (n_slots, 1, 1))
    # per node: parent, depth, how, weights, dof, mul, off, turns
    nodes: list[tuple[int, int, int, F64, int, float, float, bool]] = []
    depth = [0]
    for r in range(len(p)):
        parent, lead = int(on_node[p[r]]), times[p[r]] @ o[r]
        if k[r] == KIND_FIXED:
            on_node[c[r]], times[c[r]] = parent, lead
            continue
        frame = _frame_axis(a[r])
        if frame is None:
            m1, m2 = motion_terms(k[r : r + 1], a[r : r + 1])
            w = np.concatenate([lead, lead @ m1[0], lead @ m2[0]], axis=1)
            how, mul, off, back = GENERAL, m[r], f[r], np.eye(4)
        else:
            ax, sign = frame
            perm = np.eye(4)[:, [(ax + 1) % 3, (ax + 2) % 3, ax, 3]]  # stored = body @ perm
            w, back = lead @ perm, perm.T
            turn = k[r] == KIND_REVOLUTE
            s = -sign if turn else sign  # a turn's value is minus its angle: exp(-i angle)
            how, mul, off = (TURN if turn else SLIDE), s * m[r], s * f[r]
        nodes.append(
            (parent, depth[parent] + 1, how, w, int(d[r]), mul, off, k[r] == KIND_REVOLUTE)
        )
        depth.append(depth[parent] + 1)
        on_node[c[r]], times[c[r]] = len(nodes), back
    # Nodes sorted by (depth, how): each group one block of node slots and of motion rows.
    order = sorted(range(len(nodes)), key=lambda i: (nodes[i][1], nodes[i][2]))
    new_id = np.zeros(len(nodes) + 1, dtype=np.int64)
    new_id[np.asarray(order, dtype=np.int64) + 1] = np.arange(1, len(nodes) + 1)
    by_how = [[i for i in order if nodes[i][2] == h] for h in (TURN, SLIDE, GENERAL)]
    motion_rows = by_how[0] + by_how[1] + by_how[2]
    row_of = {i: r for r, i in enumerate(motion_rows)}
    groups: list[Group] = []
    lo = 0
    while lo < len(order):
        hi = lo
        key = nodes[order[lo]][1:3]
        while hi < len(order) and nodes[order[hi]][1:3] == key:
            hi += 1
        members = order[lo:hi]
        how = key[1]
        turning = np.array([nodes[i][7] for i in members])[:, None, None, None]
        groups.append(
            Group(
                how,
                slice(lo + 1, hi + 1),
                _reads(new_id[[nodes[i][0] for i in members]]),
                np.ascontiguousarray(np.stack([nodes[i][3] for i in members])),
                slice(row_of[members[0]], row_of[members[0]] + len(members)),
                turning if how == GENERAL else None,
            )
        )
        lo = hi
    return Tree(
        n_slots,
        n_out,
        n_dof,
        len(nodes) + 1,
        np.array([nodes[i][4] for i in motion_rows], dtype=np.int64),
        np.array([nodes[i][5] for i in motion_rows], dtype=np.float64),
        np.array([nodes[i][6] for i in motion_rows], dtype=np.float64),
        len(by_how[0]),
        tuple(groups),
        new_id[on_node[:n_out]],
        np.ascontiguousarray(times[:n_out]),
    )


def _reads(parents: I64) -> slice | I64:
    """The node slots a group reads: a slice when they are consecutive (a view, not a copy)."""
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


def _buffers(t: Tree, n: int) -> tuple[F64, F64, F64]:
    """A step's node poses (root set to the identity), gathered and final body poses."""
    nodes = np.empty((t.n_nodes, n, 4, 4))
    nodes[0] = np.eye(4)
    return nodes, np.empty((t.n_out, n, 4, 4)), np.empty((t.n_out, n, 4, 4))


def _run(t: Tree, q: F64, out: F64, bufs: tuple[F64, F64, F64]) -> None:
    """Every output pose of the samples of ``q`` (n, D) into ``out`` (n, B, 4, 4)."""
    n = q.shape[0]
    nodes, gathered, bodies = bufs
    v = np.take(q.T, t.dof, axis=0)  # (motion rows, n)
    v *= t.mul[:, None]
    v += t.off[:, None]
    turns = np.empty((t.n_turn, n), dtype=np.complex128)  # exp(-i angle) of every turn
    np.cos(v[: t.n_turn], out=turns.real)
    np.sin(v[: t.n_turn], out=turns.imag)
    for g in t.groups:
        k = g.nodes.stop - g.nodes.start
        src = nodes[g.reads] if isinstance(g.reads, slice) else np.take(nodes, g.reads, axis=0)
        dst = nodes[g.nodes]
        if g.how == GENERAL:
            x = np.matmul(src.reshape(k, 4 * n, 4), g.weights).reshape(k, n, 4, 3, 4)
            val = v[g.motion][:, :, None, None]
            first = np.where(g.turning, np.sin(val), val)
            second = np.where(g.turning, 1.0 - np.cos(val), 0.0)
            np.add(x[..., 0, :], x[..., 1, :] * first, out=dst)
            dst += x[..., 2, :] * second
            continue
        np.matmul(src.reshape(k, 4 * n, 4), g.weights, out=dst.reshape(k, 4 * n, 4))
        if g.how == TURN:  # stored columns 0 and 1 as one complex number, turned at once
            cols = dst.view(np.complex128)[..., 0]
            cols *= turns[g.motion][:, :, None]
        else:  # a slide along stored z: column 3 += v column 2
            dst[..., 3] += dst[..., 2] * v[g.motion][:, :, None]
    np.take(nodes, t.out_node, axis=0, out=gathered, mode="clip")
    np.matmul(
        gathered.reshape(t.n_out, 4 * n, 4), t.out_pose, out=bodies.reshape(t.n_out, 4 * n, 4)
    )
    out[...] = bodies.transpose(1, 0, 2, 3)


def fk(tree: object, q: object) -> F64:
    t = _tree_of(tree)
    qa = config(q, 1, t.n_dof)
    poses: F64 = np.empty((1, t.n_out, 4, 4))
    _run(t, qa[None, :], poses, _buffers(t, 1))  # a batch of one: fk_batch's operations
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
    for lo in range(0, n, _CHUNK):
        step = qa[lo : lo + _CHUNK]
        fits = len(step) == bufs[0].shape[1]
        _run(t, step, out[lo : lo + _CHUNK], bufs if fits else _buffers(t, len(step)))
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
