"""Forward kinematics and Jacobians over a :class:`~robotspec.model.world.World`, in numpy.

Why this shape: the world is parsed once into flat arrays (one row per connection, in topological
order), and every query is a handful of vectorised numpy operations over those arrays. Batched FK
composes all samples at once level by level (all bodies of one tree depth in one ``matmul``), so
there is no Python loop over samples. Multi-DOF connections (planar, floating) are expanded into
elementary one-axis motions, so the same code paths handle a mobile base and an arm.

Conventions: configurations are vectors over ``world.degrees_of_freedom`` (radians and metres);
poses are 4x4 homogeneous transforms ``root_T_body``; a Jacobian is 6 x n with the linear part on
top, expressed in the chain root's frame, for the velocity of the tip frame's origin.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from robotspec.errors import KinematicsError
from robotspec.model.world import Body, Connection, ConnectionType, World

__all__ = ["ChainKinematics", "Kinematics"]

F64 = NDArray[np.float64]

_REVOLUTE = 1
_PRISMATIC = 2

#: Below this many samples the level-by-level path (fewer numpy calls) is faster.
_SMALL_BATCH = 16
_FIXED_PLAN = 0
_MULTI_PLAN = 3
_AXIS_REVOLUTE = 4
_AXIS_PRISMATIC = 5


@dataclass(frozen=True)
class _Motion:
    """One elementary motion of a connection: a rotation about or translation along ``axis``."""

    kind: int
    axis: tuple[float, float, float]
    dof: int
    multiplier: float
    offset: float


def _in_plane_axes(normal: Sequence[float]) -> tuple[F64, F64]:
    n = np.asarray(normal, dtype=np.float64)
    n = n / np.linalg.norm(n)
    ref = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    u = ref - n * float(ref @ n)
    u /= np.linalg.norm(u)
    w = np.cross(n, u)
    return u, w


def _motions(c: Connection) -> tuple[_Motion, ...]:
    """Expand a connection into elementary motions applied after its origin, in order."""
    mult = c.mimic.multiplier if c.mimic else 1.0
    off = c.mimic.offset if c.mimic else 0.0
    t = c.type
    if t is ConnectionType.FIXED:
        return ()
    if t in (ConnectionType.REVOLUTE, ConnectionType.CONTINUOUS):
        return (_Motion(_REVOLUTE, c.axis, c.dofs[0], mult, off),)
    if t is ConnectionType.PRISMATIC:
        return (_Motion(_PRISMATIC, c.axis, c.dofs[0], mult, off),)
    if t is ConnectionType.PLANAR:
        u, w = _in_plane_axes(c.axis)
        x, y, th = c.dofs
        return (
            _Motion(_PRISMATIC, (float(u[0]), float(u[1]), float(u[2])), x, 1.0, 0.0),
            _Motion(_PRISMATIC, (float(w[0]), float(w[1]), float(w[2])), y, 1.0, 0.0),
            _Motion(_REVOLUTE, c.axis, th, 1.0, 0.0),
        )
    # Floating: translation, then fixed-axis roll/pitch/yaw = Rz(yaw) Ry(pitch) Rx(roll).
    x, y, z, roll, pitch, yaw = c.dofs
    return (
        _Motion(_PRISMATIC, (1.0, 0.0, 0.0), x, 1.0, 0.0),
        _Motion(_PRISMATIC, (0.0, 1.0, 0.0), y, 1.0, 0.0),
        _Motion(_PRISMATIC, (0.0, 0.0, 1.0), z, 1.0, 0.0),
        _Motion(_REVOLUTE, (0.0, 0.0, 1.0), yaw, 1.0, 0.0),
        _Motion(_REVOLUTE, (0.0, 1.0, 0.0), pitch, 1.0, 0.0),
        _Motion(_REVOLUTE, (1.0, 0.0, 0.0), roll, 1.0, 0.0),
    )


def _skew(axes: F64) -> F64:
    k = np.zeros((*axes.shape[:-1], 3, 3))
    k[..., 0, 1], k[..., 0, 2] = -axes[..., 2], axes[..., 1]
    k[..., 1, 0], k[..., 1, 2] = axes[..., 2], -axes[..., 0]
    k[..., 2, 0], k[..., 2, 1] = -axes[..., 1], axes[..., 0]
    return k


class Kinematics:
    """Forward kinematics of every body of a world, for one configuration or a batch."""

    def __init__(self, world: World) -> None:
        self.world = world
        conns = world.connections
        nb = len(world.bodies)
        self._nb = nb
        self._nd = len(world.degrees_of_freedom)
        # Small batches work on the moving joints only, fixed joints above each folded into its
        # origin (see _plan_fixed_collapse); index arrays below are positions among them.
        moving = self._plan_fixed_collapse(world)
        self._origin = np.stack([o for _, o in moving]) if moving else np.zeros((0, 4, 4))
        position = {c.index: i for i, (c, _) in enumerate(moving)}
        one = [c for c, _ in moving if c.type.dof_count == 1]
        rev = [c for c in one if c.type is not ConnectionType.PRISMATIC]
        pri = [c for c in one if c.type is ConnectionType.PRISMATIC]
        self._rev_idx = np.array([position[c.index] for c in rev], dtype=np.int64)
        self._rev_dof = np.array([c.dofs[0] for c in rev], dtype=np.int64)
        self._rev_mul = np.array([c.mimic.multiplier if c.mimic else 1.0 for c in rev])
        self._rev_off = np.array([c.mimic.offset if c.mimic else 0.0 for c in rev])
        axes = np.array([c.axis for c in rev], dtype=np.float64).reshape(-1, 3)
        k = _skew(axes)
        # Rodrigues, pre-multiplied by the origin rotation: O_R @ (I + sin K + (1-cos) K^2).
        o_r = self._origin[self._rev_idx, :3, :3]
        self._rev_o = o_r
        self._rev_ok = o_r @ k
        self._rev_okk = o_r @ k @ k
        self._pri_idx = np.array([position[c.index] for c in pri], dtype=np.int64)
        self._pri_dof = np.array([c.dofs[0] for c in pri], dtype=np.int64)
        self._pri_mul = np.array([c.mimic.multiplier if c.mimic else 1.0 for c in pri])
        self._pri_off = np.array([c.mimic.offset if c.mimic else 0.0 for c in pri])
        pri_axes = np.array([c.axis for c in pri], dtype=np.float64).reshape(-1, 3)
        self._pri_dir = np.einsum("cij,cj->ci", self._origin[self._pri_idx, :3, :3], pri_axes)
        self._multi = [
            (position[c.index], _MultiMotion.of(c)) for c, _ in moving if c.type.dof_count > 1
        ]
        self._plan = [_plan_entry(c) for c in conns]
        self._chains: dict[tuple[int, int], ChainKinematics] = {}

    def _plan_fixed_collapse(self, world: World) -> list[tuple[Connection, F64]]:
        """Plan the small-batch path: fixed joints folded away, moving ones level by level.

        Why: most bodies of a real robot hang on fixed joints (PR2: 82 bodies, 20 moving
        joints). Each body's pose is its *anchor*'s pose (the nearest body at or above it that
        a moving joint or the root starts) times a constant. So only moving joints are composed
        level by level, each with the constant of the fixed joints above it folded into its
        local transform, and every other body follows in one batched product at the end.
        Returns the moving joints with their folded origins (anchor frame to joint frame).
        """
        nb = len(world.bodies)
        anchor = np.zeros(nb, dtype=np.int64)
        const = np.broadcast_to(np.eye(4), (nb, 4, 4)).copy()
        moving_depth = np.zeros(nb, dtype=np.int64)
        for b in world.bodies:  # topological order: parents first
            conn = world.parent_connection(b)
            if conn is None:
                anchor[b.index] = b.index
                continue
            if conn.is_fixed:
                anchor[b.index] = anchor[conn.parent]
                const[b.index] = const[conn.parent] @ conn.origin
                moving_depth[b.index] = moving_depth[conn.parent]
            else:
                anchor[b.index] = b.index
                moving_depth[b.index] = moving_depth[conn.parent] + 1
        moving = [c for c in world.connections if not c.is_fixed]
        position = {c.index: i for i, c in enumerate(moving)}
        by_depth: dict[int, list[Connection]] = {}
        for c in moving:
            by_depth.setdefault(int(moving_depth[c.child]), []).append(c)
        self._levels = [
            (
                np.array([anchor[c.parent] for c in cs], dtype=np.int64),
                np.array([c.child for c in cs], dtype=np.int64),
                np.array([position[c.index] for c in cs], dtype=np.int64),
            )
            for _, cs in sorted(by_depth.items())
        ]
        followers = [b.index for b in world.bodies if anchor[b.index] != b.index]
        self._followers = np.array(followers, dtype=np.int64)
        self._follower_anchor = anchor[self._followers]
        self._follower_const = const[self._followers]
        return [(c, const[c.parent] @ c.origin) for c in moving]

    # ------------------------------------------------------------------ local transforms
    def _local(self, q: F64) -> F64:
        """Anchor-to-child transforms of every moving joint for configurations ``q`` (N, D)."""
        n = q.shape[0]
        local = np.broadcast_to(self._origin, (n, *self._origin.shape)).copy()
        if self._rev_idx.size:
            v = q[:, self._rev_dof] * self._rev_mul + self._rev_off
            s = np.sin(v)[..., None, None]
            c1 = (1.0 - np.cos(v))[..., None, None]
            local[:, self._rev_idx, :3, :3] = self._rev_o + s * self._rev_ok + c1 * self._rev_okk
        if self._pri_idx.size:
            v = q[:, self._pri_dof] * self._pri_mul + self._pri_off
            local[:, self._pri_idx, :3, 3:4] += (v[..., None] * self._pri_dir)[..., None]
        for idx, multi in self._multi:
            local[:, idx] = local[:, idx] @ multi.matrices(q)
        return local

    def _check_q(self, q: object, batch: bool) -> F64:
        arr = np.asarray(q, dtype=np.float64)
        want = 2 if batch else 1
        if arr.ndim != want or arr.shape[-1] != self._nd:
            shape = "(N, D)" if batch else "(D,)"
            raise KinematicsError(
                f"configuration must have shape {shape} with D = {self._nd} degrees of freedom "
                f"of world '{self.world.name}', got {arr.shape}"
            )
        if not np.all(np.isfinite(arr)):
            raise KinematicsError("configuration contains NaN or infinite values")
        return arr

    # -------------------------------------------------------------------------- queries
    def forward(self, q: object) -> F64:
        """``root_T_body`` for every body (B, 4, 4) at configuration ``q`` (D,)."""
        arr = self._check_q(q, batch=False)
        poses: F64 = self._compose(arr[None, :])[0]
        return poses

    def forward_batch(self, q: object) -> F64:
        """``root_T_body`` for every body of every sample: (N, B, 4, 4) from ``q`` (N, D).

        Samples are processed in blocks, body by body: each fixed connection is one
        ``(4·n x 4) @ (4 x 4)`` product over the whole block (a single BLAS call), and each
        revolute one is three such products combined with the per-sample sine and cosine
        (Rodrigues' formula distributed over the parent pose), so no Python loop runs per sample.
        """
        arr = self._check_q(q, batch=True)
        if arr.shape[0] < _SMALL_BATCH:
            return self._compose(arr)
        # Computed body-major so each body's block is contiguous for BLAS; returned as a
        # sample-major view (no copy).
        return self._compose_blocked(arr).transpose(1, 0, 2, 3)

    def _compose_blocked(self, q: F64) -> F64:
        n = q.shape[0]
        poses = np.empty((self._nb, n, 4, 4))
        poses[0] = np.eye(4)
        flat = poses.reshape(self._nb, n * 4, 4)
        for kind, parent, child, data in self._plan:
            p = flat[parent]
            if kind == _FIXED_PLAN:
                np.matmul(p, data[0], out=flat[child])
                continue
            if kind == _MULTI_PLAN:
                a = (p @ data[0]).reshape(n, 4, 4)
                poses[child] = a @ data[1].matrices(q)
                continue
            dof, mul, off = data[1]
            v = q[:, dof] * mul + off
            if kind == _AXIS_REVOLUTE:
                # Rotation about a frame axis only mixes two columns of the pose.
                i, j, sign = data[2]
                res = poses[child]
                np.matmul(p, data[0], out=flat[child])
                c = np.cos(v)[:, None]
                sn = np.sin(v)[:, None] * sign
                ai = res[:, :, i].copy()
                aj = res[:, :, j]
                res[:, :, i] = c * ai + sn * aj
                res[:, :, j] = c * aj - sn * ai
            elif kind == _AXIS_PRISMATIC:
                k, sign = data[2]
                res = poses[child]
                np.matmul(p, data[0], out=flat[child])
                res[:, :, 3] += (v * sign)[:, None] * res[:, :, k]
            elif kind == _REVOLUTE:
                s = np.sin(v)[:, None, None]
                c1 = (1.0 - np.cos(v))[:, None, None]
                res = poses[child]
                np.matmul(p, data[0], out=flat[child])
                res += s * (p @ data[2]).reshape(n, 4, 4)
                res += c1 * (p @ data[3]).reshape(n, 4, 4)
            else:
                res = poses[child]
                np.matmul(p, data[0], out=flat[child])
                res += v[:, None, None] * (p @ data[2]).reshape(n, 4, 4)
        return poses

    def _compose(self, q: F64) -> F64:
        """Small batches: moving joints level by level, then every fixed-joint body at once."""
        local = self._local(q)
        poses = np.empty((q.shape[0], self._nb, 4, 4))
        poses[:, 0] = np.eye(4)
        for anchors, children, moving in self._levels:
            poses[:, children] = poses[:, anchors] @ local[:, moving]
        if self._followers.size:
            poses[:, self._followers] = poses[:, self._follower_anchor] @ self._follower_const
        return poses

    def pose(self, q: object, body: str, relative_to: str | None = None) -> F64:
        """The pose of ``body`` in the frame of ``relative_to`` (default: the world root)."""
        poses = self.forward(q)
        b = self.world.get_body_by_name(body).index
        if relative_to is None:
            pose: F64 = poses[b]
            return pose
        r = self.world.get_body_by_name(relative_to).index
        return np.linalg.solve(poses[r], poses[b])

    def chain(self, root: Body | str, tip: Body | str) -> ChainKinematics:
        """Kinematics of the root-to-tip chain (cached per pair)."""
        r = self.world.get_body_by_name(root) if isinstance(root, str) else root
        t = self.world.get_body_by_name(tip) if isinstance(tip, str) else tip
        key = (r.index, t.index)
        if key not in self._chains:
            self._chains[key] = ChainKinematics(self.world, r, t)
        return self._chains[key]


def _plan_entry(c: Connection) -> tuple[int, int, int, tuple[Any, ...]]:
    """Constant matrices of one connection for the blocked batch path."""
    o = np.asarray(c.origin, dtype=np.float64)
    if c.type is ConnectionType.FIXED:
        return (_FIXED_PLAN, c.parent, c.child, (o,))
    if c.type.dof_count > 1:
        return (_MULTI_PLAN, c.parent, c.child, (o, _MultiMotion.of(c)))
    m = _motions(c)[0]
    axis = np.asarray(m.axis, dtype=np.float64)
    scal = (m.dof, m.multiplier, m.offset)
    k = int(np.argmax(np.abs(axis)))
    if abs(abs(axis[k]) - 1.0) < 1e-12:
        sign = float(np.sign(axis[k]))
        if m.kind == _REVOLUTE:
            i, j = {0: (1, 2), 1: (2, 0), 2: (0, 1)}[k]
            return (_AXIS_REVOLUTE, c.parent, c.child, (o, scal, (i, j, sign)))
        return (_AXIS_PRISMATIC, c.parent, c.child, (o, scal, (k, sign)))
    if m.kind == _REVOLUTE:
        k4 = np.zeros((4, 4))
        k4[:3, :3] = _skew(axis)
        return (_REVOLUTE, c.parent, c.child, (o, scal, o @ k4, o @ k4 @ k4))
    d4 = np.zeros((4, 4))
    d4[:3, 3] = axis
    return (_PRISMATIC, c.parent, c.child, (o, scal, o @ d4))


@dataclass(frozen=True)
class _MultiMotion:
    """A planar or floating connection's motion in closed form, for N samples at once.

    Why not the product of its elementary motions: for a base joint that product costs five
    or six batched 4x4 products per call, more than all the arm joints together.
    """

    planar: bool
    dofs: tuple[int, ...]
    u: F64  # planar: the two in-plane translation axes and the normal's skew matrices
    w: F64
    k: F64
    kk: F64

    @classmethod
    def of(cls, c: Connection) -> _MultiMotion:
        if c.type is ConnectionType.PLANAR:
            u, w = _in_plane_axes(c.axis)
            k = _skew(np.asarray(c.axis, dtype=np.float64) / np.linalg.norm(c.axis))
            return cls(True, tuple(c.dofs), u, w, k, k @ k)
        z = np.zeros(3)
        return cls(False, tuple(c.dofs), z, z, np.zeros((3, 3)), np.zeros((3, 3)))

    def matrices(self, q: F64) -> F64:
        out = np.zeros((q.shape[0], 4, 4))
        out[:, 3, 3] = 1.0
        if self.planar:
            x, y, th = (q[:, d] for d in self.dofs)
            s = np.sin(th)[:, None, None]
            c1 = (1.0 - np.cos(th))[:, None, None]
            out[:, :3, :3] = np.eye(3) + s * self.k + c1 * self.kk
            out[:, :3, 3] = x[:, None] * self.u + y[:, None] * self.w
            return out
        # Floating: translation, then Rz(yaw) @ Ry(pitch) @ Rx(roll).
        x, y, z, roll, pitch, yaw = (q[:, d] for d in self.dofs)
        cr, sr, cp, sp, cy, sy = (
            np.cos(roll),
            np.sin(roll),
            np.cos(pitch),
            np.sin(pitch),
            np.cos(yaw),
            np.sin(yaw),
        )
        out[:, 0, 0] = cy * cp
        out[:, 0, 1] = cy * sp * sr - sy * cr
        out[:, 0, 2] = cy * sp * cr + sy * sr
        out[:, 1, 0] = sy * cp
        out[:, 1, 1] = sy * sp * sr + cy * cr
        out[:, 1, 2] = sy * sp * cr - cy * sr
        out[:, 2, 0] = -sp
        out[:, 2, 1] = cp * sr
        out[:, 2, 2] = cp * cr
        out[:, 0, 3], out[:, 1, 3], out[:, 2, 3] = x, y, z
        return out


class ChainKinematics:
    """FK and the geometric Jacobian of one root-to-tip chain, fixed segments pre-fused.

    Why a class: a controller evaluates the same chain thousands of times, so everything that does
    not depend on the configuration (fused fixed transforms, axes, DOF columns) is computed once.
    """

    def __init__(self, world: World, root: Body, tip: Body) -> None:
        self.root = root
        self.tip = tip
        connections = world.compute_chain_of_connections(root, tip)
        self.connections: tuple[Connection, ...] = tuple(connections)
        pre: list[F64] = []  # fixed transform before each elementary motion
        kinds: list[int] = []
        axes: list[tuple[float, float, float]] = []
        dofs: list[int] = []
        mults: list[float] = []
        offs: list[float] = []
        acc = np.eye(4)
        for c in connections:
            acc = acc @ c.origin
            for m in _motions(c):
                pre.append(acc)
                acc = np.eye(4)
                kinds.append(m.kind)
                axes.append(m.axis)
                dofs.append(m.dof)
                mults.append(m.multiplier)
                offs.append(m.offset)
        self._pre = np.array(pre).reshape(-1, 4, 4)
        self._post = acc
        self._kind = np.array(kinds, dtype=np.int64)
        self._axis = np.array(axes, dtype=np.float64).reshape(-1, 3)
        self._dof = np.array(dofs, dtype=np.int64)
        self._mul = np.array(mults)
        self._off = np.array(offs)
        self._rev = self._kind == _REVOLUTE
        k = _skew(self._axis)
        self._k = k
        self._kk = k @ k
        # Unique DOFs in chain order: the Jacobian's columns.
        self.dof_indices: tuple[int, ...] = tuple(dict.fromkeys(dofs))
        col = {d: i for i, d in enumerate(self.dof_indices)}
        self._col = np.array([col[d] for d in dofs], dtype=np.int64)
        self.dof_names: tuple[str, ...] = tuple(
            world.degrees_of_freedom[d].name for d in self.dof_indices
        )

    def _locals(self, q: F64) -> F64:
        v = q[self._dof] * self._mul + self._off
        m = np.broadcast_to(np.eye(4), (v.shape[0], 4, 4)).copy()
        s = np.sin(v)[:, None, None]
        c1 = (1.0 - np.cos(v))[:, None, None]
        rot = np.eye(3) + s * self._k + c1 * self._kk
        m[self._rev, :3, :3] = rot[self._rev]
        pri = ~self._rev
        m[pri, :3, 3] = v[pri, None] * self._axis[pri]
        return self._pre @ m

    def fk(self, q: F64) -> F64:
        """``root_T_tip`` (4, 4) for the world configuration ``q`` (D,)."""
        t = np.eye(4)
        for loc in self._locals(np.asarray(q, dtype=np.float64)):
            t = t @ loc
        return t @ self._post

    def jacobian(self, q: F64) -> F64:
        """Geometric Jacobian (6, n) of the tip origin in the root frame; columns = dof_indices.

        A mimic joint adds its multiplier times its own column to its leader's column.
        """
        qa = np.asarray(q, dtype=np.float64)
        locs = self._locals(qa)
        n = len(locs)
        frames = np.empty((n, 4, 4))  # root_T_(joint frame before its motion)
        t = np.eye(4)
        for i in range(n):
            frames[i] = t @ self._pre[i]
            t = t @ locs[i]
        tip = (t @ self._post)[:3, 3]
        z = np.einsum("nij,nj->ni", frames[:, :3, :3], self._axis)
        p = frames[:, :3, 3]
        cols = np.zeros((6, n))
        rev = self._rev
        cols[:3, rev] = np.cross(z[rev], tip - p[rev]).T
        cols[3:, rev] = z[rev].T
        cols[:3, ~rev] = z[~rev].T
        cols *= self._mul
        jac = np.zeros((6, len(self.dof_indices)))
        np.add.at(jac.T, self._col, cols.T)
        return jac
