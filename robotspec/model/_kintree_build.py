"""The tree program of the kinematics core, built for numpy: nodes, groups and constants.

Why a module of its own: building is done once per program and reads the C core's rows as
they come (checks in the C core's order, the same errors); the hot path that runs the built
program for every sample is :mod:`robotspec.model._kintree_py`, whose docstring says how the
rows become nodes (moving rows), constants (fixed rows) and groups (one depth, one motion).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from robotspec.arrays import F64, I64
from robotspec.model._core_args import from_any, index

KIND_FIXED = 0
KIND_REVOLUTE = 1
KIND_PRISMATIC = 2

#: How a node moves: about its stored z axis (a frame axis), along it, or by Rodrigues' terms.
TURN, SLIDE, GENERAL = 0, 1, 2


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
    reads: tuple[tuple[slice, Any], ...]  # (its nodes, their parents): parents' slots as a
    # slice (consecutive: a view), an int (one parent for all: broadcast) or an index array
    parents: I64  # their parents' node slots
    weights: F64  # (k, 4, 4); GENERAL: (k, 4, 12), [W0 W1 W2]
    motion: slice  # their rows of the motion values (Tree.dof)
    column: int  # TURN: the first of the two columns turned; SLIDE: the column slid along
    turning: Any  # GENERAL only: (k, 1, 1, 1) whether each turns (else it slides)


@dataclass(frozen=True)
class Layout:
    """Where a step's poses go among the bodies (body order, the result's).

    ``runs``: per node with extra poses, (node, its extra poses, their bodies) for each stretch
    of consecutive bodies; ``node_out`` and ``node_at``: the bodies that are a node's pose, and
    that node's slot. Why: the extra poses (49 of the PR2's 83 bodies) are written straight into
    the bodies' order instead of into the store and gathered from it, one pass over the
    memory fewer (a batch's step moves megabytes: it is bound by memory, not arithmetic).
    """

    runs: tuple[tuple[int, slice, slice], ...]
    node_out: Any
    node_at: Any


def _layout(
    n_nodes: int, n_extra: int, at: I64, extra_runs: tuple[tuple[int, slice], ...]
) -> Layout:
    """The :class:`Layout` of a tree's parts (made once, with the tree)."""
    body_of = np.zeros(n_nodes + n_extra, dtype=np.int64)
    body_of[at] = np.arange(len(at))  # slot -> body (read for the extra slots: one body each)
    runs: list[tuple[int, slice, slice]] = []
    for node, run in extra_runs:
        bodies = body_of[n_nodes + np.arange(run.start, run.stop)].tolist()
        first = 0
        for k in range(1, len(bodies) + 1):
            if k == len(bodies) or bodies[k] != bodies[k - 1] + 1:
                extras = slice(run.start + first, run.start + k)
                runs.append((node, extras, slice(bodies[first], bodies[k - 1] + 1)))
                first = k
    node_out = np.flatnonzero(at < n_nodes)
    return Layout(tuple(runs), node_out, at[node_out])


@dataclass(frozen=True)
class Tree:
    """A tree program (see ``_kincore.c``), rearranged for numpy (module docstring).

    Node 0 is the root (the identity); ``groups`` compute the others, in depth order. Motion
    rows (``dof``, ``mul``, ``off``: value ``q[dof] * mul + off``) are the turns first (their
    value is minus the C core's angle), then the slides, then the general motions. A body is
    a node's pose as it is (``at``: its slot), or a node's pose times a constant (``extra_node``
    times ``extra_pose``, stored after the nodes, at ``n_nodes + i``).
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
    at: I64  # per body: its slot in the step's store (nodes, then extra poses)
    extra_node: I64
    extra_pose: F64
    extra_runs: tuple[tuple[int, slice], ...]  # (node, its extra poses): sorted by node
    layout: Layout  # a batch's steps: where the extra poses go among the bodies


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
    nodes: list[_Node] = []
    depth = [0]
    for r in range(len(p)):
        parent, lead = int(on_node[p[r]]), times[p[r]] @ o[r]
        if k[r] == KIND_FIXED:
            on_node[c[r]], times[c[r]] = parent, lead
            continue
        node, back = _node(parent, depth[parent] + 1, lead, k[r], a[r], int(d[r]), m[r], f[r])
        nodes.append(node)
        depth.append(node.depth)
        on_node[c[r]], times[c[r]] = len(nodes), back
    # Nodes sorted by (depth, how, column): each group one block of node slots, of motion rows.
    order = sorted(range(len(nodes)), key=lambda i: nodes[i].key)
    new_id = np.zeros(len(nodes) + 1, dtype=np.int64)
    new_id[np.asarray(order, dtype=np.int64) + 1] = np.arange(1, len(nodes) + 1)
    motion_rows = sorted(order, key=lambda i: nodes[i].how)  # turns, slides, general (stable)
    row_of = {i: r for r, i in enumerate(motion_rows)}
    groups: list[Group] = []
    lo = 0
    while lo < len(order):
        hi = lo
        while hi < len(order) and nodes[order[hi]].key == nodes[order[lo]].key:
            hi += 1
        members = [nodes[i] for i in order[lo:hi]]
        first = row_of[order[lo]]
        how = members[0].how
        turning = np.array([n.revolute for n in members])[:, None, None, None]
        groups.append(
            Group(
                how,
                slice(lo + 1, hi + 1),
                _parts(new_id[[n.parent for n in members]]),
                new_id[[n.parent for n in members]],
                np.ascontiguousarray(np.stack([n.weights for n in members])),
                slice(first, first + len(members)),
                members[0].column,
                turning if how == GENERAL else None,
            )
        )
        lo = hi
    # A body whose constant is the identity is its node's pose; the others are computed after.
    plain = (times[:n_out] == np.eye(4)).all(axis=(1, 2))
    at = new_id[on_node[:n_out]]
    extra = np.flatnonzero(~plain)
    extra = extra[np.argsort(at[extra], kind="stable")]  # by node: one product per node
    at[extra] = len(nodes) + 1 + np.arange(len(extra))
    extra_node = new_id[on_node[extra]]
    starts = np.flatnonzero(np.diff(extra_node, prepend=-1))
    ends = np.append(starts[1:], len(extra))[: len(starts)]
    runs = tuple(
        (int(extra_node[i]), slice(int(i), int(j))) for i, j in zip(starts, ends, strict=True)
    )
    return Tree(
        n_slots,
        n_out,
        n_dof,
        len(nodes) + 1,
        np.array([nodes[i].dof for i in motion_rows], dtype=np.int64),
        np.array([nodes[i].mul for i in motion_rows], dtype=np.float64),
        np.array([nodes[i].off for i in motion_rows], dtype=np.float64),
        sum(n.how == TURN for n in nodes),
        tuple(groups),
        at,
        extra_node,
        np.ascontiguousarray(times[extra]),
        runs,
        _layout(len(nodes) + 1, len(extra), at, runs),
    )


@dataclass(frozen=True)
class _Node:
    """A moving row at build time: ``node = parent @ weights @ motion(q[dof] * mul + off)``."""

    parent: int
    depth: int
    how: int
    column: int
    weights: F64
    dof: int
    mul: float
    off: float
    revolute: bool

    @property
    def key(self) -> tuple[int, int, int]:
        return self.depth, self.how, self.column


def _node(
    parent: int, depth: int, lead: F64, kind: Any, u: F64, dof: int, mul: float, off: float
) -> tuple[_Node, F64]:
    """A moving row as a node, and the constant its child slot's pose is the node's pose times.

    A turn about frame axis k mixes columns i = k+1, j = k+2 (mod 3), as one complex number
    ``col_i + i col_j`` when they are neighbours (x: 1 and 2, z: 0 and 1); about y the columns
    are stored as (2, 0, 1), an exact permutation undone by the constant. A slide along frame
    axis k adds ``v`` times column k to column 3. Any other axis: Rodrigues' terms.
    """
    revolute = bool(kind == KIND_REVOLUTE)
    frame = _frame_axis(u)
    if frame is None:
        m1, m2 = motion_terms(np.array([kind]), u[None, :])
        w = np.concatenate([lead, lead @ m1[0], lead @ m2[0]], axis=1)
        return _Node(parent, depth, GENERAL, 0, w, dof, mul, off, revolute), np.eye(4)
    ax, sign = frame
    if not revolute:
        return _Node(parent, depth, SLIDE, ax, lead, dof, sign * mul, sign * off, False), np.eye(4)
    # a turn's value is minus its angle: its complex factor is exp(-i angle)
    if ax == 1:
        perm = np.eye(4)[:, [2, 0, 1, 3]]  # stored = body @ perm
        return _Node(
            parent, depth, TURN, 0, lead @ perm, dof, -sign * mul, -sign * off, True
        ), perm.T
    col = (ax + 1) % 3
    return _Node(parent, depth, TURN, col, lead, dof, -sign * mul, -sign * off, True), np.eye(4)


def _parts(parents: I64) -> tuple[tuple[slice, Any], ...]:
    """A group's reads as few products as possible, none of them a gathered copy if it can be.

    Runs of consecutive parents are a slice (a view), runs of one parent an int (broadcast
    against the run's weights); more than two runs are one gather of every parent.
    """
    parts: list[tuple[slice, Any]] = []
    lo = 0
    while lo < len(parents):
        hi, first = lo + 1, int(parents[lo])
        same = hi < len(parents) and parents[hi] == first
        while hi < len(parents) and parents[hi] == (first if same else first + hi - lo):
            hi += 1
        parts.append((slice(lo, hi), first if same else slice(first, first + hi - lo)))
        lo = hi
    if len(parts) > 2:
        return ((slice(0, len(parents)), parents),)
    return tuple(parts)
