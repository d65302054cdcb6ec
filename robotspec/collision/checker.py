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
transform, coal's request and result) is per thread (:class:`_Scratch`). Coal's own calls hold the
GIL, so the functors' internal solver state is used by one call at a time.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, cast

import numpy as np
from numpy.typing import NDArray

from robotspec.arrays import F64, I64, real_array, real_number
from robotspec.collision import meshcore
from robotspec.collision.rules import CollisionRules, pair_key
from robotspec.collision.shapes import (
    CollisionGeometry,
    GeometryModel,
    MeshLibrary,
    MissingMeshPolicy,
    build_geometry_model,
    import_coal,
)
from robotspec.errors import CollisionError, KinematicsError, RobotSpecError
from robotspec.model import kincore
from robotspec.model.kinematics import Kinematics
from robotspec.model.world import World
from robotspec.semantic.states import state_configuration

if TYPE_CHECKING:
    from robotspec.semantic.robot import AbstractRobot

__all__ = ["PairDistance", "SelfCollisionChecker"]

Bools = NDArray[np.bool_]
Point = tuple[float, float, float]

#: Samples per block in batch queries: bounds the memory of the pose arrays (~10 MB).
_BLOCK = 512
#: Hull distances: GJK's tolerance (polytopes end exactly; curved primitives need it tight to agree
#: with coal's exact mesh distances), the gap below which hulls count as touching (coal answers,
#: with its conventions for contact), and how near a hull's closest point must be to the mesh.
_HULL_TOLERANCE = 1e-10
_HULL_GAP = 1e-5
_ON_SURFACE = 1e-9
#: Relative thickness below which a mesh counts as flat and gets no hull (see ``_solid``).
_FLAT = 1e-6
#: What the mesh core proved of a candidate (its codes), and "not asked".
_UNKNOWN, _APART, _CROSS, _UNTRIED = 0, 1, 2, -1
#: Candidates of a block from which mesh proofs run in one C call rather than one by one.
_BATCH_PROOFS = 64
#: Room (m) beyond the margin by which a mesh pair must be proven apart before coal is skipped:
#: coal's own collision test between triangles stops within about 1e-6 m, so a pair proven this far
#: apart is one coal calls apart too, and the answers stay coal's.
_APART_SLACK = 1e-5


@dataclass(frozen=True)
class PairDistance:
    """The minimum distance between two bodies and the closest points (world root frame, m).

    ``distance`` is coal's: negative for penetrating primitives, 0 or coal's estimate for meshes
    in contact; ``inf`` when a body has no geometry left (a skipped mesh).
    """

    link1: str
    link2: str
    distance: float
    point1: tuple[float, float, float]
    point2: tuple[float, float, float]


@dataclass(frozen=True)
class _Compiled:
    """Arrays of the built checker: geometries and the pairs to test, in flat index form."""

    model: GeometryModel
    pair_geom1: I64  # (Q,) geometry indices of each geometry pair
    pair_geom2: I64
    pair_of: I64  # (Q,) index of the body pair each geometry pair belongs to
    collide: tuple[Any, ...]  # coal.ComputeCollision per geometry pair
    broad: object  # the C core's table of geometries and pairs (_kincore.geoms)
    meshes: object | None  # box trees of the mesh geometries (_meshcore.mesh_set), if any pair
    two_meshes: list[bool]  # per geometry pair: both are meshes (so `meshes` can prove them apart)

    # Python lists for the per-pair loop (indexing a list is several times cheaper).
    pair_geom1_list: list[int] = field(init=False)
    pair_geom2_list: list[int] = field(init=False)
    pair_of_list: list[int] = field(init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "pair_geom1_list", self.pair_geom1.tolist())
        object.__setattr__(self, "pair_geom2_list", self.pair_geom2.tolist())
        object.__setattr__(self, "pair_of_list", self.pair_of.tolist())


class _Scratch:
    """One thread's coal objects that a query writes: transforms, a request and a result.

    Why per thread: a query writes every geometry's pose into its transform and then asks coal,
    and reads coal's answer from the result after the call; a second thread writing the same
    transforms, or clearing the same result, in between changes the first one's answer (a shared
    checker gave wrong distances and missed collisions). Kept rather than made per query: the
    PR2's 32 transforms cost more to create than a whole ``in_collision``.
    """

    def __init__(self, coal: Any, n_geometries: int) -> None:
        self.transforms = tuple(coal.Transform3s() for _ in range(n_geometries))
        self.margin = math.nan
        self.request = coal.CollisionRequest()
        self.result = coal.CollisionResult()

    def collision(self, margin: float) -> tuple[Any, Any]:
        """Coal's collision request for ``margin`` and the result to reuse."""
        if margin != self.margin:
            self.request.security_margin = margin
            self.margin = margin
        return self.request, self.result


class SelfCollisionChecker:
    """Self-collision of one world under a set of rules (see :class:`CollisionRules`).

    ``pairs`` restricts the checked body pairs (default: the rules' active pairs); the matrix
    generator uses it to check every pair with no rules at all.

    A checker may be shared by threads: every query answers as if it ran alone. The first query
    builds the geometry (under a lock, once); each thread then writes only its own coal
    transforms and results. Coal holds the GIL, so threads do not check faster than one thread,
    except in the kinematics and the mesh proofs of batches (C loops without the GIL); for
    throughput on many configurations use worker processes (``collisions generate --jobs``).
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
        self._compiled: _Compiled | None = None
        self._distance_fns: tuple[Any, ...] | None = None
        self._hull_fns: tuple[Any, ...] | None = None
        self._robot: AbstractRobot | None = None
        # Built-once state is built under the lock; what queries write is per thread.
        self._lock = threading.RLock()
        self._local = threading.local()
        self._n_dof = len(world.degrees_of_freedom)

    @classmethod
    def from_robot(
        cls,
        robot: AbstractRobot,
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
        return state_configuration(self._robot, states, values)

    def _build(self) -> _Compiled:
        compiled = self._compiled
        if compiled is None:
            with self._lock:  # one thread builds (meshes read once); the others wait for it
                compiled = self._compiled if self._compiled is not None else self._compile()
        return compiled

    def _scratch(self, c: _Compiled) -> _Scratch:
        """This thread's transforms, request and result (made on its first query)."""
        scratch: _Scratch | None = getattr(self._local, "scratch", None)
        if scratch is None:
            scratch = self._local.scratch = _Scratch(import_coal(), len(c.model.geometries))
        return scratch

    def _compile(self) -> _Compiled:
        coal = import_coal()
        bodies = sorted({b for p in self._pairs for b in p}, key=self._body_order)
        model = build_geometry_model(
            self.world, bodies, meshes=self._meshes, on_missing_mesh=self._on_missing
        )
        geoms = model.geometries
        g1, g2, owner = model.pair_indices(self._pairs)
        pair_geom1 = np.array(g1, dtype=np.int64)
        pair_geom2 = np.array(g2, dtype=np.int64)
        self._compiled = _Compiled(
            model=model,
            pair_geom1=pair_geom1,
            pair_geom2=pair_geom2,
            pair_of=np.array(owner, dtype=np.int64),
            collide=tuple(
                coal.ComputeCollision(geoms[i].geometry, geoms[j].geometry)
                for i, j in zip(g1, g2, strict=True)
            ),
            broad=kincore.core().geoms(
                np.array([g.body_index for g in geoms], dtype=np.int64),
                np.array([g.body_T_geometry for g in geoms], dtype=np.float64).reshape(-1, 4, 4),
                np.array([g.aabb_center for g in geoms], dtype=np.float64).reshape(-1, 3),
                np.array([g.aabb_half for g in geoms], dtype=np.float64).reshape(-1, 3),
                pair_geom1,
                pair_geom2,
                len(self.world.bodies),
            ),
            meshes=_mesh_trees(geoms, g1, g2),
            two_meshes=[
                geoms[i].triangles is not None and geoms[j].triangles is not None
                for i, j in zip(g1, g2, strict=True)
            ],
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

    def _broad(
        self, c: _Compiled, qs: F64, margin: float, mask: NDArray[np.uint8] | None
    ) -> tuple[list[int], list[int], F64]:
        """Candidate (sample, geometry pair)s of ``qs`` and every geometry's pose (n, G, 4, 4).

        A candidate's boxes come within ``margin``; every other pair is farther apart than that,
        so the narrow phase on the candidates gives the exact answer.
        """
        kin = self.kinematics
        bodies = kin.forward(qs[0]) if qs.shape[0] == 1 else kin.forward_batch(qs)
        rows, ks, poses = kincore.core().broad(c.broad, bodies, margin, mask)
        return rows.tolist(), ks.tolist(), poses

    # ------------------------------------------------------------------------- queries
    def _scan(
        self,
        qs: F64,
        *,
        margin: float = 0.0,
        first_only: bool = False,
        pair_mask: Bools | None = None,
        drop_found: bool = False,
    ) -> Bools:
        """Which body pairs collide, per sample: (n, P).

        ``first_only`` stops a sample at its first colliding pair (for "is it in collision").
        ``pair_mask`` limits the pairs tested. ``drop_found`` stops testing a pair once it has
        collided in any sample (the matrix generator only asks whether a pair *ever* collides).
        """
        margin = real_number(margin, "margin", _config_error, minimum=0.0)
        pair_mask = None if pair_mask is None else self._pair_mask(pair_mask)
        c = self._build()
        n = qs.shape[0]
        hits = np.zeros((n, len(self._pairs)), dtype=np.bool_)
        if not len(c.pair_of):
            return hits
        geom_mask = None if pair_mask is None else pair_mask[c.pair_of].astype(np.uint8)
        scratch = self._scratch(c)
        req, res = scratch.collision(margin)
        clear, is_collision = res.clear, res.isCollision
        found = [False] * len(self._pairs)
        tf = scratch.transforms
        fns = c.collide
        owner = c.pair_of_list
        g1s, g2s = c.pair_geom1_list, c.pair_geom2_list
        meshes, two_meshes = c.meshes, c.two_meshes
        apart, eps = meshcore.core().apart_one, margin + _APART_SLACK
        hit_rows: list[int] = []
        hit_pairs: list[int] = []
        for start in range(0, n, _BLOCK):
            block = qs[start : start + _BLOCK]
            if drop_found and geom_mask is not None and start:
                geom_mask &= ~np.asarray(found, dtype=np.bool_)[c.pair_of]
            elif drop_found and start:
                geom_mask = (~np.asarray(found, dtype=np.bool_)[c.pair_of]).astype(np.uint8)
            rows, ks, poses = self._broad(c, block, margin, geom_mask)
            proofs = [_UNTRIED] * len(ks)
            if meshes is not None and not first_only and len(ks) >= _BATCH_PROOFS:
                # Every candidate is tested, so the mesh proofs run in one C call (no Python per
                # candidate); an any-hit query proves them one by one instead, and stops early,
                # and so do a few candidates (numpy's fixed cost would exceed the calls saved).
                rows, ks, proofs = self._prove_apart(c, poses, rows, ks, eps)
            stamp = [-1] * len(tf)
            last_row = -1
            skip_row = False
            row_hits: set[int] = set()
            for r, k, proof in zip(rows, ks, proofs, strict=True):
                if r != last_row:
                    last_row, skip_row = r, False
                    row_hits = set()
                elif skip_row:
                    continue
                p = owner[k]
                if p in row_hits or (drop_found and found[p]):
                    continue
                i, j = g1s[k], g2s[k]
                # Two meshes: the C core proves them apart or crossing first (tens of times
                # cheaper than coal when they nearly touch); coal decides what it cannot.
                if proof == _UNTRIED and two_meshes[k]:
                    proof = apart(meshes, poses, r, i, j, eps)
                    if proof == _APART:
                        continue
                if proof != _CROSS:
                    if stamp[i] != r:
                        stamp[i] = r
                        pose = poses[r, i]
                        tf[i].setRotation(pose[:3, :3])
                        tf[i].setTranslation(pose[:3, 3])
                    if stamp[j] != r:
                        stamp[j] = r
                        pose = poses[r, j]
                        tf[j].setRotation(pose[:3, :3])
                        tf[j].setTranslation(pose[:3, 3])
                    clear()
                    fns[k](tf[i], tf[j], req, res)
                    if not is_collision():
                        continue
                row_hits.add(p)
                hit_rows.append(start + r)
                hit_pairs.append(p)
                found[p] = True
                skip_row = first_only
        hits[hit_rows, hit_pairs] = True
        return hits

    def _prove_apart(
        self, c: _Compiled, poses: F64, rows: list[int], ks: list[int], eps: float
    ) -> tuple[list[int], list[int], list[int]]:
        """The candidates left once the mesh pairs proven apart are dropped, and their proofs.

        Each is ``_UNKNOWN`` or ``_CROSS`` (coal decides the first, the second is a collision).
        """
        r = np.asarray(rows, dtype=np.int64)
        k = np.asarray(ks, dtype=np.int64)
        at = np.flatnonzero(np.asarray(c.two_meshes, dtype=np.bool_)[k])
        proofs = np.full(len(k), _UNTRIED, dtype=np.int64)
        if not len(at):
            return rows, ks, proofs.tolist()
        proofs[at] = meshcore.core().apart(
            c.meshes, poses, r[at], k[at], c.pair_geom1, c.pair_geom2, eps
        )
        keep = proofs != _APART
        return r[keep].tolist(), k[keep].tolist(), proofs[keep].tolist()

    def in_collision(self, q: object, *, margin: float = 0.0) -> bool:
        """Whether any checked pair collides (or comes closer than ``margin``) at ``q``."""
        return bool(
            self._scan(self._one(q, "in_collision_batch"), margin=margin, first_only=True).any()
        )

    def colliding_pairs(self, q: object, *, margin: float = 0.0) -> tuple[tuple[str, str], ...]:
        """The checked pairs that collide (or are closer than ``margin``) at ``q``."""
        hits = self._scan(self._one(q, "collisions_batch"), margin=margin)[0]
        return tuple(self._pairs[i] for i in np.flatnonzero(hits))

    def buffer_violations(self, q: object) -> tuple[tuple[str, str], ...]:
        """Pairs closer than the rules' buffer distance (the spec's ``buffer_distance``)."""
        return self.colliding_pairs(q, margin=self.rules.buffer_distance)

    def in_collision_batch(self, qs: object, *, margin: float = 0.0) -> Bools:
        """Per configuration of ``qs`` (N, D): whether any checked pair collides."""
        hits = self._scan(self._as_batch(qs), margin=margin, first_only=True)
        return np.asarray(hits.any(axis=1), dtype=np.bool_)

    def collisions_batch(
        self, qs: object, *, margin: float = 0.0, pair_mask: Bools | None = None
    ) -> Bools:
        """Per configuration and checked pair (N, P): whether the pair collides.

        ``pair_mask`` (P,) limits the pairs tested; the others read ``False``.
        """
        return self._scan(self._as_batch(qs), margin=margin, pair_mask=pair_mask)

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
    def _distance_functors(self, c: _Compiled) -> tuple[Any, ...]:
        if self._distance_fns is None:
            coal = import_coal()
            geoms = c.model.geometries
            self._distance_fns = tuple(
                coal.ComputeDistance(geoms[i].geometry, geoms[j].geometry)
                for i, j in zip(c.pair_geom1_list, c.pair_geom2_list, strict=True)
            )
        return self._distance_fns

    def _hull_functors(self, c: _Compiled) -> tuple[Any, ...]:
        """Per geometry pair with a mesh: coal's distance with each mesh replaced by its hull."""
        if self._hull_fns is None:
            coal = import_coal()
            geoms = c.model.geometries
            hulls = {
                k: h
                for k in {*c.pair_geom1_list, *c.pair_geom2_list}
                if geoms[k].triangles is not None and (h := _hull(geoms[k])) is not None
            }

            def hulled(i: int, j: int) -> bool:
                """The pair has a mesh, and every mesh of it has a hull."""
                mesh = [k for k in (i, j) if geoms[k].triangles is not None]
                return bool(mesh) and all(k in hulls for k in mesh)

            self._hull_fns = tuple(
                coal.ComputeDistance(
                    hulls.get(i, geoms[i].geometry), hulls.get(j, geoms[j].geometry)
                )
                if hulled(i, j)
                else None
                for i, j in zip(c.pair_geom1_list, c.pair_geom2_list, strict=True)
            )
        return self._hull_fns

    def _distance_rows(
        self, qs: F64, with_points: bool
    ) -> Iterator[tuple[list[float], list[tuple[list[float], list[float]] | None]]]:
        """Per configuration of ``qs``: each pair's distance and (``with_points``) closest points.

        A pair with a mesh asks coal first for the distance of the meshes' convex hulls (GJK on
        two convex sets: a few microseconds, where the meshes' own distance costs coal 50-600).
        The hulls enclose the meshes, so their distance is at most the meshes'; when both closest
        points lie on the meshes themselves (checked in the C core, within ``_ON_SURFACE``), the
        meshes are no nearer than those two points, so the hulls' answer is the meshes' (to a
        nanometre). Otherwise (a closest point across a concavity, or hulls that touch) coal
        computes the meshes' distance. Everything per pair stays in Python lists: numpy scalar
        indexing and small arrays per pair cost more than coal's own time on robots with many
        small pairs.
        """
        c = self._build()
        coal = import_coal()
        with self._lock:  # built by one thread, once (qhull on meshes shared by checkers)
            fns = self._distance_functors(c)
            hulls = self._hull_functors(c)
        npairs = len(self._pairs)
        req = coal.DistanceRequest()  # coal >= 3 always fills the nearest points
        res = coal.DistanceResult()
        hreq = coal.DistanceRequest()
        hreq.gjk_tolerance = _HULL_TOLERANCE
        hres = coal.DistanceResult()
        tf = self._scratch(c).transforms
        geoms = c.model.geometries
        # The transforms are updated in place, so each pair's functors and transforms are bound
        # once.
        work = tuple(
            zip(
                fns,
                hulls,
                (tf[i] for i in c.pair_geom1_list),
                (tf[j] for j in c.pair_geom2_list),
                c.pair_of_list,
                c.pair_geom1_list,
                c.pair_geom2_list,
                (geoms[i].triangles is not None for i in c.pair_geom1_list),
                (geoms[j].triangles is not None for j in c.pair_geom2_list),
                strict=True,
            )
        )
        clear, near1, near2 = res.clear, res.getNearestPoint1, res.getNearestPoint2
        hclear, hnear1, hnear2 = hres.clear, hres.getNearestPoint1, hres.getNearestPoint2
        meshes, on_surface = c.meshes, meshcore.core().on_surface
        none = np.zeros(len(c.pair_of), dtype=np.uint8)  # poses only, no broad phase
        for start in range(0, qs.shape[0], _BLOCK):
            _, _, poses = self._broad(c, qs[start : start + _BLOCK], 0.0, none)
            for r in range(poses.shape[0]):
                for g, pose in enumerate(poses[r]):
                    tf[g].setRotation(pose[:3, :3])
                    tf[g].setTranslation(pose[:3, 3])
                best = [math.inf] * npairs
                near: list[tuple[list[float], list[float]] | None] = [None] * npairs
                for fn, hull, t1, t2, p, i, j, mesh1, mesh2 in work:
                    if hull is not None:
                        hclear()
                        d = hull(t1, t2, hreq, hres)
                        if d > _HULL_GAP:
                            x1, x2 = hnear1(), hnear2()
                            if (not mesh1 or on_surface(meshes, poses, r, i, x1, _ON_SURFACE)) and (
                                not mesh2 or on_surface(meshes, poses, r, j, x2, _ON_SURFACE)
                            ):
                                if d < best[p]:
                                    best[p] = d
                                    if with_points:
                                        near[p] = (x1.tolist(), x2.tolist())
                                continue
                    clear()
                    d = fn(t1, t2, req, res)
                    if d < best[p]:
                        best[p] = d
                        if with_points:
                            near[p] = (near1().tolist(), near2().tolist())
                yield best, near

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


def _mesh_trees(geoms: Sequence[CollisionGeometry], g1: list[int], g2: list[int]) -> object | None:
    """Box trees of the meshes in some pair (None if no pair has a mesh)."""
    used = {k for k in (*g1, *g2) if geoms[k].triangles is not None}
    if not used:
        return None
    # The triangles are finite and in range: MeshLibrary refused any mesh that is not.
    trees: object = meshcore.core().mesh_set(
        [g.triangles if k in used else None for k, g in enumerate(geoms)]
    )
    return trees


def _hull(geom: CollisionGeometry) -> Any:
    """The convex hull of a mesh geometry as a coal convex, or None (a flat mesh has none).

    A mesh with no volume (a plate, a sliver, collinear or repeated points) never reaches qhull:
    coal 3.0 does not turn qhull's refusal of a flat point set into an exception but crashes the
    process (SIGSEGV). Such a mesh gets no hull, so its pairs use coal's mesh distance.
    """
    model = geom.geometry
    if getattr(model, "convex", None) is None and (
        geom.triangles is None or not _solid(geom.triangles[0])
    ):
        return None
    try:
        if getattr(model, "convex", None) is None:
            model.buildConvexHull(False, "Qt")  # qhull: the hull's vertices are mesh vertices
        return model.convex
    except Exception:  # noqa: BLE001 - qhull refuses flat or degenerate point sets
        return None


def _solid(vertices: F64) -> bool:
    """Whether qhull can hull ``vertices`` (V, 3): at least four points, not (nearly) flat.

    The test: the points' extent across their plane of best fit (the last principal axis) must
    exceed ``_FLAT`` times their size (their largest extent, or their distance from the origin
    if larger: qhull's rounding grows with the coordinates). Random near-flat point sets crash
    qhull up to about 1e-8 and never from 1e-7 on, so ``_FLAT`` keeps a factor of ten.
    """
    points = np.unique(np.asarray(vertices, dtype=np.float64).reshape(-1, 3), axis=0)
    if len(points) < 4:
        return False
    centred = points - points.mean(axis=0)
    axes = np.linalg.svd(centred, full_matrices=False)[2]
    along = centred @ axes.T
    extent = along.max(axis=0) - along.min(axis=0)
    size = max(float(extent[0]), float(np.abs(points).max()))
    return bool(extent[2] > _FLAT * size)
