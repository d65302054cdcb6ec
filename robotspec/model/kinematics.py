"""Forward kinematics and Jacobians over a :class:`~robotspec.model.world.World`.

Why this shape: the world is compiled once into flat tables (one row per elementary motion, in
topological order) that a small C core (``_kincore.c``) runs, one call per query: one
configuration of a real robot is a few thousand floating-point operations, which numpy would
spend tens of microseconds dispatching. Multi-DOF connections (planar, floating) are expanded
into elementary one-axis motions, so the same code handles a mobile base and an arm.

Conventions: configurations are vectors over ``world.degrees_of_freedom`` (radians and metres);
poses are 4x4 homogeneous transforms ``root_T_body``; a Jacobian is 6 x n with the linear part on
top, expressed in the chain root's frame, for the velocity of the tip frame's origin.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from robotspec.arrays import F64, finite_array, real_array
from robotspec.errors import KinematicsError
from robotspec.model import kincore
from robotspec.model.world import Body, Connection, ConnectionType, World

__all__ = ["ChainKinematics", "Kinematics"]

_NDARRAY = np.ndarray  # a module global: the queries' one test of their argument


# Motion kinds, as the C core (_kincore.c) numbers them.
_FIXED = 0
_REVOLUTE = 1
_PRISMATIC = 2


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


class Kinematics:
    """Forward kinematics of every body of a world, for one configuration or a batch.

    Built once per world: the connections become a flat program (one row per elementary
    motion, see :func:`_tree_program`) that the C core runs for each configuration.
    """

    def __init__(self, world: World) -> None:
        self.world = world
        self._nb = len(world.bodies)
        self._nd = len(world.degrees_of_freedom)
        self._tree = _tree_program(world)
        # The core's entry point, bound once: the table above is that core's (a query never
        # looks the core up again), and a bound call is the cheapest Python can make.
        self._core = kincore.core()
        self._fk = self._core.fk
        self._chains: dict[tuple[int, int], ChainKinematics] = {}
        self._from_root: dict[str, ChainKinematics] = {}  # pose()'s chains, by body name

    # -------------------------------------------------------------------------- queries
    def forward(self, q: object) -> F64:
        """``root_T_body`` for every body (B, 4, 4) at configuration ``q`` (D,)."""
        if type(q) is not _NDARRAY:  # an array goes to the core as it is (see _numbers)
            q = _numbers(q, self._nd, self.world.name, False)
        try:
            poses: F64 = self._fk(self._tree, q)
        except (ValueError, TypeError):
            raise _bad_configuration(q, self._nd, self.world.name, False) from None
        return poses

    def forward_batch(
        self, q: object, *, out: F64 | None = None, threads: int | None = None
    ) -> F64:
        """``root_T_body`` for every body of every sample: (N, B, 4, 4) from ``q`` (N, D).

        One C loop over the samples with the GIL released, split over ``threads`` (default: every
        CPU this process may use, for batches of at least ``PARALLEL_BATCH`` samples; one
        otherwise). ``out``, an (N, B, 4, 4) float64 C-contiguous array, receives the poses in
        place and is returned: a caller that runs batch after batch then writes into memory that
        is already mapped (a fresh 100 MB result costs a third of the time in page faults).
        An ``out`` that shares memory with ``q`` is refused: the poses would overwrite
        configurations not yet read.
        """
        arr = real_array(q, f"configuration of {_want(self._nd, self.world.name, True)}", _error)
        n = arr.shape[0] if arr.ndim == 2 else 0
        if threads is None:
            threads = default_threads() if n >= PARALLEL_BATCH else 1
        if (
            isinstance(threads, bool | np.bool_)
            or not isinstance(threads, int | np.integer)
            or not 1 <= threads <= 64
        ):
            raise KinematicsError(f"threads must be an integer between 1 and 64, got {threads!r}")
        threads = int(threads)
        if out is not None:
            _check_out(out, (n, len(self.world.bodies), 4, 4))
            if _overlap(out, arr):
                # The core writes each sample's poses while later samples are still to be read.
                raise KinematicsError(
                    "out must not share memory with the configurations q: writing the poses "
                    "would overwrite configurations not yet read; pass a separate array"
                )
        try:
            poses: F64 = kincore.fk_batch(self._tree, arr, threads, out, self._core)
        except (ValueError, TypeError):
            raise _bad_configuration(q, self._nd, self.world.name, True) from None
        return poses

    def configuration_array(self, q: object, *, batch: bool = False, hint: str = "") -> F64:
        """``q`` as a checked float64 configuration (D,) or, with ``batch``, batch (N, D).

        For callers that read ``q`` before the core does (the collision checker): a wrong type,
        shape or value is a KinematicsError that says which. ``hint`` ends the message when a
        batch is given where one configuration is expected (the method that takes the batch).
        """
        return _checked_configuration(q, self._nd, self.world.name, batch, hint)

    def pose(self, q: object, body: str, relative_to: str | None = None) -> F64:
        """The pose of ``body`` in the frame of ``relative_to`` (default: the world root).

        Only the connections above ``body`` are composed (its chain from the root), so one
        frame costs less than every body.
        """
        chain = self._from_root.get(body) if type(body) is str else None
        if chain is None:
            chain = self.chain(self.world.bodies[0], body)
            if type(body) is str:
                self._from_root[body] = chain
        pose = chain.fk(q)
        if relative_to is None:
            return pose
        ref = self.chain(self.world.bodies[0], relative_to).fk(q)
        relative: F64 = np.asarray(np.linalg.solve(ref, pose), dtype=np.float64)
        return relative

    def chain(self, root: Body | str, tip: Body | str) -> ChainKinematics:
        """Kinematics of the root-to-tip chain (cached per pair)."""
        for end in (root, tip):
            if not isinstance(end, str | Body):
                raise KinematicsError(f"a chain end must be a body name, got {type(end).__name__}")
        r = self.world.get_body_by_name(root) if isinstance(root, str) else root
        t = self.world.get_body_by_name(tip) if isinstance(tip, str) else tip
        key = (r.index, t.index)
        chain = self._chains.get(key)
        if chain is None:
            chain = self._chains[key] = ChainKinematics(self.world, r, t)
        return chain


def _error(message: str) -> KinematicsError:
    return KinematicsError(message)


def _want(nd: int, world: str, batch: bool) -> str:
    shape = "(N, D)" if batch else "(D,)"
    return f"shape {shape} with D = {nd} degrees of freedom of world '{world}'"


def _numbers(q: object, nd: int, world: str, batch: bool) -> object:
    """``q`` for the core when it is not a numpy array: converted only if float64 holds it.

    The core checks the shape, the values and an array's dtype: it casts an array only where no
    value can change (numpy's safe rule), so a complex, longdouble or string array is its
    TypeError. A list is another matter: both cores would read ``["1", "2"]`` as numbers, so
    anything but an array is converted here, refused when float64 would change it. Why the
    queries test ``type(q) is np.ndarray`` before calling this: that test is the whole cost an
    array pays in front of the core (tens of nanoseconds; a call here and a dtype comparison
    cost several hundred, a third of a small query, measured by benchmarks/bench_percall.py).
    """
    if type(q) is _NDARRAY:
        return q
    return real_array(q, f"configuration of {_want(nd, world, batch)}", _error)


def _checked_configuration(q: object, nd: int, world: str, batch: bool, hint: str = "") -> F64:
    """``q`` as float64 of the right shape, finite; else the KinematicsError that says why."""
    want = _want(nd, world, batch)
    arr = real_array(q, f"configuration of {want}", _error)
    if arr.ndim != (2 if batch else 1) or arr.shape[-1] != nd:
        more = f"; for a batch of configurations use {hint}" if hint and arr.ndim == 2 else ""
        raise KinematicsError(f"configuration must have {want}, got {arr.shape}{more}")
    return finite_array(arr, "configuration", _error)


def _bad_configuration(q: object, nd: int, world: str, batch: bool) -> KinematicsError:
    """The error for a configuration the core refused: what is wrong with it, in words."""
    try:
        _checked_configuration(q, nd, world, batch)
    except KinematicsError as exc:
        return exc
    return KinematicsError(f"configuration of {_want(nd, world, batch)} refused by the core")


def _overlap(a: F64, b: F64) -> bool:
    """Whether two arrays share memory (bounds first, then numpy's exact test: a few strides)."""
    return bool(np.may_share_memory(a, b) and np.shares_memory(a, b))


def _tree_program(world: World) -> object:
    """The C core's program for every body: one row per elementary motion, parents first.

    Row k sets slot ``child`` to slot ``parent`` times ``origin`` times the row's motion. Slots
    are the bodies (slot 0, the root, is the identity) and, after them, one scratch slot per
    intermediate frame of a planar or floating connection (expanded into one-axis motions).
    """
    parent: list[int] = []
    child: list[int] = []
    kind: list[int] = []
    origin: list[F64] = []
    axis: list[tuple[float, float, float]] = []
    dof: list[int] = []
    mul: list[float] = []
    off: list[float] = []
    n_slots = len(world.bodies)
    eye = np.eye(4)
    for c in world.connections:
        motions = _motions(c)
        if not motions:
            parent.append(c.parent)
            child.append(c.child)
            kind.append(_FIXED)
            origin.append(np.asarray(c.origin, dtype=np.float64))
            axis.append((0.0, 0.0, 0.0))
            dof.append(0)
            mul.append(0.0)
            off.append(0.0)
            continue
        src = c.parent
        for i, m in enumerate(motions):
            last = i == len(motions) - 1
            dst = c.child if last else n_slots
            if not last:
                n_slots += 1
            parent.append(src)
            child.append(dst)
            kind.append(m.kind)
            origin.append(np.asarray(c.origin, dtype=np.float64) if i == 0 else eye)
            axis.append(m.axis)
            dof.append(m.dof)
            mul.append(m.multiplier)
            off.append(m.offset)
            src = dst
    return kincore.core().tree(
        np.array(parent, dtype=np.int64),
        np.array(child, dtype=np.int64),
        np.array(kind, dtype=np.int64),
        np.array(origin, dtype=np.float64).reshape(-1, 4, 4),
        np.array(axis, dtype=np.float64).reshape(-1, 3),
        np.array(dof, dtype=np.int64),
        np.array(mul, dtype=np.float64),
        np.array(off, dtype=np.float64),
        n_slots,
        len(world.bodies),
        len(world.degrees_of_freedom),
    )


class ChainKinematics:
    """FK and the geometric Jacobian of one root-to-tip chain, fixed segments pre-fused.

    Why a class: a controller evaluates the same chain thousands of times, so everything that does
    not depend on the configuration (fused fixed transforms, axes, DOF columns) is computed once,
    into a program the C core runs in one call.
    """

    def __init__(self, world: World, root: Body, tip: Body) -> None:
        self.root = root
        self.tip = tip
        self._world_name = world.name
        self._nd = len(world.degrees_of_freedom)
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
        # Unique DOFs in chain order: the Jacobian's columns.
        self.dof_indices: tuple[int, ...] = tuple(dict.fromkeys(dofs))
        col = {d: i for i, d in enumerate(self.dof_indices)}
        self.dof_names: tuple[str, ...] = tuple(
            world.degrees_of_freedom[d].name for d in self.dof_indices
        )
        core = kincore.core()
        # Bound once, with the table they run (see Kinematics.__init__).
        self._fk, self._jacobian = core.chain_fk, core.chain_jacobian
        self._fk_batch = core.chain_fk_batch
        self._program = core.chain(
            np.array(pre, dtype=np.float64).reshape(-1, 4, 4),
            acc,
            np.array(kinds, dtype=np.int64),
            np.array(axes, dtype=np.float64).reshape(-1, 3),
            np.array(dofs, dtype=np.int64),
            np.array(mults, dtype=np.float64),
            np.array(offs, dtype=np.float64),
            np.array([col[d] for d in dofs], dtype=np.int64),
            len(self.dof_indices),
            self._nd,
        )

    def fk(self, q: object) -> F64:
        """``root_T_tip`` (4, 4) for the world configuration ``q`` (D,)."""
        if type(q) is not _NDARRAY:  # an array goes to the core as it is (see _numbers)
            q = _numbers(q, self._nd, self._world_name, False)
        try:
            pose: F64 = self._fk(self._program, q)
        except (ValueError, TypeError):
            raise _bad_configuration(q, self._nd, self._world_name, False) from None
        return pose

    def fk_batch(self, q: object) -> F64:
        """``root_T_tip`` (N, 4, 4) for each configuration of ``q`` (N, D), in one C loop."""
        try:
            poses: F64 = self._fk_batch(
                self._program, _numbers(q, self._nd, self._world_name, True)
            )
        except (ValueError, TypeError):
            raise _bad_configuration(q, self._nd, self._world_name, True) from None
        return poses

    def jacobian(self, q: object) -> F64:
        """Geometric Jacobian (6, n) of the tip origin in the root frame; columns = dof_indices.

        Linear velocity on top. A mimic joint adds its multiplier times its own column to its
        leader's column.
        """
        if type(q) is not _NDARRAY:  # an array goes to the core as it is (see _numbers)
            q = _numbers(q, self._nd, self._world_name, False)
        try:
            jac: F64 = self._jacobian(self._program, q)
        except (ValueError, TypeError):
            raise _bad_configuration(q, self._nd, self._world_name, False) from None
        return jac


#: Batches of at least this many samples are split over threads by default.
PARALLEL_BATCH = 2048


def available_cpus() -> int:
    """The CPUs this process may run on."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not on Linux
        return max(1, os.cpu_count() or 1)


def default_threads() -> int:
    """Threads for a large batch: every available CPU, at most 8 (memory-bound beyond that)."""
    return min(8, available_cpus())


def _check_out(out: object, shape: tuple[int, ...]) -> None:
    ok = (
        isinstance(out, np.ndarray)
        and out.dtype == np.float64
        and out.shape == shape
        and out.flags.c_contiguous
        and out.flags.aligned
        and out.flags.writeable
    )
    if not ok:
        got = (
            f"{out.dtype} array of shape {out.shape}"
            if isinstance(out, np.ndarray)
            else type(out).__name__
        )
        raise KinematicsError(
            f"out must be a writeable, aligned C-contiguous float64 array of shape {shape}, "
            f"got {got}"
        )
