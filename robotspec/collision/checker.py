"""Self-collision queries of a robot on one configuration or a batch, with coal.

How a query runs: forward kinematics (the C core) gives every body pose; each geometry's
body-frame bounding box is moved with its body and tested against its partners' (a broad phase
over all samples and all pairs in one C call: world-aligned bounds, then the oriented boxes'
separating axes); coal's narrow phase (a precomputed ``ComputeCollision`` per geometry pair, the
functor pinocchio uses) runs only for pairs whose boxes come within the margin. Results are per
*body* pair: a pair collides when any of their geometries do, and its distance is the minimum
over them.

Everything is built on the first query (meshes read once), so constructing a checker is cheap.

Threads: one checker may be shared by threads. What is built once (geometries, coal functors,
trees) is built under a lock and only read afterwards; what a query writes (each geometry's coal
transform, coal's request and result) is per thread (:class:`Scratch`); the C mesh core gives
each of its calls a scratch of its own. Coal's own calls hold the GIL, so the functors' internal
solver state is used by one call at a time. A batch spends its time in three C calls per block
of samples that release the GIL (kinematics, broad phase, the narrow phase's proofs,
:func:`.narrow.walk`); coal is asked only about what the proofs leave (on the PR2, about one
candidate in a thousand), so threads checking batches run side by side.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any, cast

import numpy as np
from numpy.typing import NDArray

from robotspec.arrays import F64, real_array, real_number
from robotspec.collision.compiled import Compiled, Scratch, compile_pairs
from robotspec.collision.distances import (
    PairDistance,
    Rows,
    distance_functors,
    distance_rows,
    hull_functors,
)
from robotspec.collision.narrow import WALK_ALL, WALK_DROP_FOUND, WALK_FIRST, batch_proofs_for
from robotspec.collision.rules import CollisionRules, pair_key
from robotspec.collision.scan import first_hit, place, scan_rows
from robotspec.collision.shapes import GeometryModel, MeshLibrary, MissingMeshPolicy, import_coal
from robotspec.collision.slices import checked_threads, run_in_slices
from robotspec.errors import CollisionError, KinematicsError, RobotSpecError
from robotspec.model.kinematics import Kinematics
from robotspec.model.world import World

if TYPE_CHECKING:
    from robotspec.collision.robot_view import CollisionRobot

__all__ = ["PairDistance", "SelfCollisionChecker"]

Bools = NDArray[np.bool_]
Point = tuple[float, float, float]


class SelfCollisionChecker:
    """Self-collision of one world under a set of rules (see :class:`CollisionRules`).

    ``pairs`` restricts the checked body pairs (default: the rules' active pairs); the matrix
    generator uses it to check every pair with no rules at all.

    A checker may be shared by threads: every query answers as if it ran alone. The first query
    builds the geometry (under a lock, once); each thread then writes only its own coal
    transforms and results. Kinematics, broad phase and the mesh proofs run in C without the
    GIL, so threads check faster than one thread where those hold the work (meshes: the PR2);
    pairs the proofs leave, and every pair with a primitive shape, go to coal, which holds the
    GIL. ``threads=`` splits a batch over threads; worker processes (``collisions generate
    --jobs``) scale whatever the geometry.
    """

    def __init__(
        self,
        world: World,
        rules: CollisionRules,
        *,
        pairs: Sequence[tuple[str, str]] | None = None,
        meshes: MeshLibrary | None = None,
        on_missing_mesh: MissingMeshPolicy = "error",
    ) -> None:
        self.world = world
        self.rules = rules
        chosen = rules.active_pairs() if pairs is None else tuple(pairs)
        # Each pair is spelled parent-side first (world order), whatever order it came in.
        self._pairs: tuple[tuple[str, str], ...] = tuple(
            (a, b) if self._body_order(a) <= self._body_order(b) else (b, a) for a, b in chosen
        )
        self._pair_index = {pair_key(a, b): i for i, (a, b) in enumerate(self._pairs)}
        self._meshes = meshes if meshes is not None else MeshLibrary()
        if on_missing_mesh not in ("error", "skip"):  # any other word read as "skip"
            raise CollisionError(
                f"on_missing_mesh must be 'error' or 'skip', got {on_missing_mesh!r}",
                kind="config",
            )
        self._on_missing = on_missing_mesh
        self._kin: Kinematics | None = None
        self._compiled: Compiled | None = None
        self._distance_fns: tuple[Any, ...] | None = None
        self._hull_fns: tuple[Any, ...] | None = None
        self._robot: CollisionRobot | None = None
        # Built-once state is built under the lock; what queries write is per thread.
        self._lock = threading.RLock()
        self._local = threading.local()
        self._n_dof = len(world.degrees_of_freedom)

    @classmethod
    def from_robot(
        cls,
        robot: CollisionRobot,
        *,
        adjacency: bool = True,
        meshes: MeshLibrary | None = None,
        on_missing_mesh: MissingMeshPolicy = "error",
    ) -> SelfCollisionChecker:
        """A checker with the robot's own rules (SRDF, disabled bodies, buffer distance)."""
        checker = cls(
            robot.world,
            CollisionRules.from_robot(robot, adjacency=adjacency),
            meshes=meshes,
            on_missing_mesh=on_missing_mesh,
        )
        checker._robot = robot
        return checker

    # ------------------------------------------------------------------------ structure
    @property
    def active_pairs(self) -> tuple[tuple[str, str], ...]:
        """The body pairs checked, in the order of every per-pair result."""
        return self._pairs

    @property
    def geometry(self) -> GeometryModel:
        """The coal geometries (built, and meshes read, on first use)."""
        return self._build().model

    @property
    def skipped(self) -> tuple[RobotSpecError, ...]:
        """Meshes left out under ``on_missing_mesh="skip"``, as warnings to report."""
        return self._build().model.skipped

    @property
    def kinematics(self) -> Kinematics:
        """The forward kinematics the checker uses."""
        if self._kin is None:
            with self._lock:
                if self._kin is None:
                    self._kin = Kinematics(self.world)
        return self._kin

    def configuration(
        self, states: Sequence[str] = (), values: Mapping[str, float] | None = None
    ) -> F64:
        """A configuration from named joint states and joint values (needs ``from_robot``)."""
        if self._robot is None:
            raise CollisionError(
                "named states need a robot: build the checker with SelfCollisionChecker.from_robot"
            )
        return self._robot.state_configuration(states, values)

    def _build(self) -> Compiled:
        compiled = self._compiled
        if compiled is None:
            with self._lock:  # one thread builds (meshes read once); the others wait for it
                compiled = self._compiled if self._compiled is not None else self._compile()
        return compiled

    def _scratch(self, c: Compiled) -> Scratch:
        """This thread's transforms, request and result (made on its first query)."""
        scratch: Scratch | None = getattr(self._local, "scratch", None)
        if scratch is None:
            scratch = self._local.scratch = Scratch(import_coal(), len(c.model.geometries))
        return scratch

    def _compile(self) -> Compiled:
        bodies = sorted({b for p in self._pairs for b in p}, key=self._body_order)
        self._compiled = compile_pairs(
            self.world,
            self._pairs,
            bodies,
            meshes=self._meshes,
            on_missing_mesh=self._on_missing,
        )
        return self._compiled

    def _body_order(self, name: str) -> int:
        return self.world.get_body_by_name(name).index

    # ------------------------------------------------------------------------- geometry
    def _as_batch(self, qs: object) -> F64:
        """``qs`` as a checked batch (N, D) of configurations; one configuration (D,) is one row."""
        arr = real_array(qs, "configurations", KinematicsError)
        return self.kinematics.configuration_array(
            arr[None, :] if arr.ndim == 1 else arr, batch=True
        )

    def _one(self, q: object, batch: str) -> F64:
        """``q`` as a batch of one (1, D), checked; a batch is refused, naming the method for it.

        Why: a single-configuration query once answered for the first row of a batch alone.
        A float64 vector of the right length is passed on as it is (the hot path: its values
        are checked by the kinematics core, whose refusal names the bad value as this would).
        """
        if type(q) is np.ndarray and q.dtype == np.float64 and q.shape == (self._n_dof,):
            return q[None, :]
        return self.kinematics.configuration_array(q, hint=f"SelfCollisionChecker.{batch}")[None, :]

    def _pair_mask(self, pair_mask: object) -> Bools:
        """``pair_mask`` checked: booleans, one per checked pair."""
        want = f"pair_mask must be booleans of shape ({len(self._pairs)},), one per checked pair"
        try:
            mask = np.asarray(pair_mask)
        except (ValueError, TypeError) as exc:
            raise CollisionError(f"{want}: {exc}", kind="config") from None
        if mask.dtype != np.bool_ or mask.shape != (len(self._pairs),):
            raise CollisionError(
                f"{want}, got a {mask.dtype} array of shape {mask.shape}", kind="config"
            )
        return mask

    # ------------------------------------------------------------------------- queries
    def _scan(
        self,
        qs: F64,
        *,
        margin: float = 0.0,
        first_only: bool = False,
        pair_mask: Bools | None = None,
        drop_found: bool = False,
        threads: object = 1,
    ) -> Bools:
        """Which body pairs collide, per sample: (n, P).

        ``first_only`` stops a sample at its first colliding pair (for "is it in collision").
        ``pair_mask`` limits the pairs tested. ``drop_found`` stops testing a pair once it has
        collided in any sample (the matrix generator only asks whether a pair *ever* collides).
        ``threads`` splits the samples into that many ranges, each scanned on its own thread
        (:mod:`.slices`); each range writes its own rows, so the answer is the one-thread one.
        """
        margin = real_number(margin, "margin", _config_error, minimum=0.0)
        pair_mask = None if pair_mask is None else self._pair_mask(pair_mask)
        if threads != 1 or type(threads) is not int:  # one thread: the single queries' path
            threads = checked_threads(threads)
        c = self._build()
        n = qs.shape[0]
        hits = np.zeros((n, len(self._pairs)), dtype=np.bool_)
        if not len(c.pair_of):
            return hits
        geom_mask = None if pair_mask is None else pair_mask[c.pair_of].astype(np.uint8)
        mode = WALK_FIRST if first_only else WALK_DROP_FOUND if drop_found else WALK_ALL
        batch_proofs = batch_proofs_for(n, mode, threads)

        kin = self.kinematics
        if threads == 1:
            scan_rows(c, kin, self._scratch(c), qs, hits, margin, geom_mask, mode, batch_proofs)
            return hits

        def scan(lo: int, hi: int) -> None:
            mask = None if geom_mask is None else geom_mask.copy()  # drop_found narrows it
            scratch = self._scratch(c)  # this thread's
            scan_rows(c, kin, scratch, qs[lo:hi], hits[lo:hi], margin, mask, mode, batch_proofs)

        run_in_slices(n, threads, scan)
        return hits

    def in_collision(self, q: object, *, margin: float = 0.0) -> bool:
        """Whether any checked pair collides (or comes closer than ``margin``) at ``q``.

        The single query's own path (issue 34: it is called thousands of times a second): the
        configuration and margin are checked as every query checks them, then forward
        kinematics, the broad phase and (only when boxes meet) the narrow phase's walk, with no
        batch bookkeeping in between.
        """
        if type(q) is np.ndarray and q.dtype == np.float64 and q.shape == (self._n_dof,):
            one: F64 = q  # values are checked by the kinematics core (NaN and inf refused)
        else:
            one = self._one(q, "in_collision_batch")[0]
        if type(margin) is not float or not 0.0 <= margin < math.inf:
            margin = real_number(margin, "margin", _config_error, minimum=0.0)
        c = self._compiled
        if c is None:
            c = self._build()
        return first_hit(c, self.kinematics, self._scratch(c), one, margin, len(self._pairs))

    def colliding_pairs(self, q: object, *, margin: float = 0.0) -> tuple[tuple[str, str], ...]:
        """The checked pairs that collide (or are closer than ``margin``) at ``q``."""
        hits = self._scan(self._one(q, "collisions_batch"), margin=margin)[0]
        return tuple(self._pairs[i] for i in np.flatnonzero(hits))

    def buffer_violations(self, q: object) -> tuple[tuple[str, str], ...]:
        """Pairs closer than the rules' buffer distance (the spec's ``buffer_distance``)."""
        return self.colliding_pairs(q, margin=self.rules.buffer_distance)

    def in_collision_batch(self, qs: object, *, margin: float = 0.0, threads: int = 1) -> Bools:
        """Per configuration of ``qs`` (N, D): whether any checked pair collides.

        ``threads`` (1 to 64) splits the batch into that many sample ranges checked at once on
        as many threads, sharing the built geometry (ranges under 64 samples are not split).
        """
        hits = self._scan(self._as_batch(qs), margin=margin, first_only=True, threads=threads)
        return np.asarray(hits.any(axis=1), dtype=np.bool_)

    def collisions_batch(
        self,
        qs: object,
        *,
        margin: float = 0.0,
        pair_mask: Bools | None = None,
        threads: int = 1,
    ) -> Bools:
        """Per configuration and checked pair (N, P): whether the pair collides.

        ``pair_mask`` (P,) limits the pairs tested; the others read ``False``. ``threads`` as in
        :meth:`in_collision_batch`.
        """
        return self._scan(self._as_batch(qs), margin=margin, pair_mask=pair_mask, threads=threads)

    def ever_colliding(
        self, qs: object, *, pair_mask: Bools | None = None, margin: float = 0.0
    ) -> Bools:
        """Per checked pair (P,): whether it collides in any configuration of ``qs``.

        Faster than :meth:`collisions_batch` on many samples: a pair is not tested again once it
        has collided.
        """
        hits = self._scan(self._as_batch(qs), margin=margin, pair_mask=pair_mask, drop_found=True)
        return np.asarray(hits.any(axis=0), dtype=np.bool_)

    # ------------------------------------------------------------------------ distances
    def _distance_functors(self, c: Compiled) -> tuple[Any, ...]:
        if self._distance_fns is None:
            self._distance_fns = distance_functors(c)
        return self._distance_fns

    def _hull_functors(self, c: Compiled) -> tuple[Any, ...]:
        """Per geometry pair with a mesh: coal's distance with each mesh replaced by its hull."""
        if self._hull_fns is None:
            self._hull_fns = hull_functors(c)
        return self._hull_fns

    def _distance_rows(self, qs: F64, with_points: bool) -> Rows:
        """Per configuration of ``qs``: each pair's distance and closest points (see distances)."""
        c = self._build()
        with self._lock:  # built by one thread, once (qhull on meshes shared by checkers)
            functors = (self._distance_functors(c), self._hull_functors(c))
        none = np.zeros(len(c.pair_of), dtype=np.uint8)  # poses only, no broad phase

        kin = self.kinematics

        def poses(block: F64) -> F64:
            return place(c, kin, block, 0.0, none)[2]

        transforms = self._scratch(c).transforms
        return distance_rows(c, functors, transforms, len(self._pairs), poses, qs, with_points)

    def distances(self, q: object) -> tuple[PairDistance, ...]:
        """Minimum distance and closest points of every checked pair at ``q``."""
        nan: Point = (math.nan, math.nan, math.nan)
        out: list[PairDistance] = []
        for best, near in self._distance_rows(self._one(q, "distances_batch"), with_points=True):
            for (a, b), d, x in zip(self._pairs, best, near, strict=True):
                p1, p2 = (cast(Point, tuple(x[0])), cast(Point, tuple(x[1]))) if x else (nan, nan)
                out.append(PairDistance(a, b, d, p1, p2))
        return tuple(out)

    def distances_batch(self, qs: object) -> F64:
        """Minimum distance of every checked pair (N, P) for each configuration of ``qs``."""
        batch = self._as_batch(qs)
        dist = np.full((batch.shape[0], len(self._pairs)), np.inf)
        for row, (best, _) in enumerate(self._distance_rows(batch, with_points=False)):
            dist[row] = best
        return dist

    def pair_index(self, a: str, b: str) -> int:
        """The position of a checked pair in per-pair results; CollisionError if not checked."""
        key = pair_key(a, b)
        if key not in self._pair_index:
            reason = self.rules.why_disabled(a, b)
            why = f" ({reason})" if reason else ""
            raise CollisionError(
                f"pair '{a}' - '{b}' is not checked{why}", kind="pair", name=f"{a} {b}"
            )
        return self._pair_index[key]


def _config_error(message: str) -> CollisionError:
    return CollisionError(message, kind="config")
