"""Free balls: mesh pairs proven apart by a coal distance asked at a nearby relative pose.

Why (issue 34): without the C mesh core, coal answers every broad-phase candidate, and the
collision matrix's "Never" pass spends nearly all its time on mesh pairs that nearly touch and
never collide (PR2: the upper arm against the shoulder, the fingers, 200-1000 us per call), asked
at every sample because only pairs seen colliding are dropped. Many such pairs have a relative
pose that depends on one or two joints, so their relative poses fill a small set that a few
balls cover.

A ball: coal says meshes a and b are ``d`` apart with b at relative pose ``T0`` (b's frame in
a's). At a relative pose ``T``, each point of b moves (in a's frame) by at most ``delta``, the
largest displacement of a corner of b's vertex box (the displacement is affine in the point, so
its largest length over the box is at a corner, and b's surface lies in the box). If
``delta < d - eps`` every point of b is still more than ``eps`` from a's surface: the meshes are
apart by more than ``eps``, which is what the C core's proofs establish before skipping coal
(``scan.APART_SLACK``: coal then calls them apart too). The same holds with a's box moved in b's
frame; a ball keeps both and uses the smaller bound. ``d`` is stored, ``eps`` applied at each
test, so one store serves any margin.

Per geometry pair, candidates are tested against its balls (numpy, over all of a block's
candidates of the pair at once). An uncovered one is asked to coal: by its distance (which adds
a ball) while recent balls pay for themselves, else by its plain collision test. Which one is
decided from measured costs and how many candidates recent balls covered; that choice changes
only the speed, never an answer: a candidate is dropped here only when a ball or coal itself
shows it free, and everything else goes on to the narrow phase's walk unchanged. Pairs whose
collision calls are cheap (far apart, or primitives) are left alone after a few probes.

The store (:class:`FreeBalls`) belongs to one thread's :class:`~.compiled.Scratch` of one
checker (the matrix builds its checker per run): no global state, bounded in size.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from robotspec.arrays import F64, I64
from robotspec.collision.compiled import Compiled, Scratch
from robotspec.collision.shapes import import_coal

Bools = NDArray[np.bool_]

__all__ = [
    "FreeBalls",
    "ball_covers",
    "box_centres",
    "box_corners",
    "relative_corners",
    "sift",
]

#: Collision calls timed on a pair before deciding whether balls may pay for it.
_PROBES = 4
#: Mean collision call (s) below which a pair is left to the walk: a ball test would cost as much.
_CHEAP = 30e-6
#: Distance calls asked of a pair before its balls' covering rate decides, unless a distance
#: costs more than this many collision calls (Talos' arms: 40; the PR2's nesting pairs 1-5).
_EXPLORE = 4
_DEAREST = 8.0
#: How many times its cost a new ball must be expected to save (the estimate is rough: a
#: distance asked for nothing costs up to 40 collision calls).
_MARGIN = 2.0
#: Collision calls between two looks at whether a distance would pay (the estimate moves slowly).
_RECONSIDER = 16
#: Recent balls whose covering rate estimates what the next ball would cover.
_RECENT = 16
#: Candidates assumed still to come for a pair, at least (then: as many as were seen).
_HORIZON = 256
#: Fewest candidates per candidate seen that a pair's balls must cover to be tested at all.
_USEFUL = 0.05
#: Balls kept per pair and in a whole store (bounds its memory: 57 floats a ball).
_MAX_PER_PAIR = 1024
_MAX_TOTAL = 16384


def box_corners(vertices: F64) -> F64:
    """The eight corners (8, 3) of the axis-aligned box of ``vertices`` (V, 3)."""
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    pick = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=np.bool_)
    out: F64 = np.where(pick, hi, lo)
    return out


def relative_corners(pose_a: F64, pose_b: F64, corners_a: F64, corners_b: F64) -> F64:
    """(n, 16, 3): b's box corners in a's frame, then a's in b's frame, at poses (n, 4, 4) each."""
    ra, rb = pose_a[:, :3, :3], pose_b[:, :3, :3]
    dt = pose_b[:, :3, 3] - pose_a[:, :3, 3]
    rot = np.einsum("nji,njk->nik", ra, rb)  # Ra^T Rb
    t = np.einsum("nji,nj->ni", ra, dt)  # Ra^T (tb - ta)
    b_in_a = np.einsum("nij,cj->nci", rot, corners_b) + t[:, None, :]
    a_in_b = np.einsum("nji,ncj->nci", rot, corners_a[None, :, :] - t[:, None, :])
    out: F64 = np.concatenate([b_in_a, a_in_b], axis=1)
    return out


def box_centres(corners: F64) -> F64:
    """(n, 2, 3): the centres of the two boxes of corner sets (n, 16, 3).

    A centre is the midpoint of two opposite corners (the first and the last of each eight:
    the low and the high one of :func:`box_corners`).
    """
    out: F64 = (corners[:, [0, 8]] + corners[:, [7, 15]]) * 0.5
    return out


def ball_covers(
    points: F64, centres: F64, corners: F64, ball_centres: F64, radii: F64, eps: float
) -> Bools:
    """(n, B): whether ball ``b`` proves candidate ``n`` more than ``eps`` apart.

    ``points`` (n, 16, 3) are the candidates' corners and ``centres`` (n, 2, 3) their boxes'
    centres; ``corners``, ``ball_centres`` and ``radii`` (B,) the balls' and coal's distances.
    The centres first: a centre is a midpoint of corners, so it moves no more than the farthest
    corner, and a ball whose centres are too far off cannot cover (most are: 2 points, not 16).
    """
    room = radii - eps
    diff = centres[:, None] - ball_centres[None]  # (n, B, 2, 3)
    gap = np.einsum("nbhx,nbhx->nbh", diff, diff).min(axis=2)  # squared
    rows, balls = np.nonzero(gap < np.where(room > 0.0, room * room, -1.0)[None, :])
    out = np.zeros((len(points), len(radii)), dtype=np.bool_)
    if len(rows):
        moved = points[rows] - corners[balls]  # (m, 16, 3)
        moved = np.einsum("mcx,mcx->mc", moved, moved)
        delta = np.minimum(moved[:, :8].max(axis=1), moved[:, 8:].max(axis=1))
        out[rows, balls] = delta < room[balls] ** 2
    return out


@dataclass
class _Pair:
    """What a store knows of one geometry pair: its balls and what its coal calls cost.

    Mutable: it is the store's working state, one per pair, written by one thread.
    """

    n: int = 0  # balls
    room: F64 = field(default_factory=lambda: np.zeros((0, 19, 3)))  # corners, centres, radius
    born: list[int] = field(default_factory=list)  # candidates seen when each ball was made
    credit: list[int] = field(default_factory=list)  # candidates each ball was first to cover
    seen: int = 0
    collided: int = 0
    collide_time: float = 0.0
    asked: int = 0
    distance_time: float = 0.0
    cheap: bool = False

    @property
    def corners(self) -> F64:
        """(n, 16, 3): each ball's box corners (b's in a's frame, then a's in b's)."""
        return self.room[: self.n, :16]

    @property
    def centres(self) -> F64:
        """(n, 2, 3): the boxes' centres."""
        return self.room[: self.n, 16:18]

    @property
    def radii(self) -> F64:
        """(n,): coal's distance at each ball's pose."""
        return self.room[: self.n, 18, 0]

    def add(self, corners: F64, centres: F64, d: float) -> None:
        if self.n == len(self.room):  # room for twice as many: no copy per ball
            grown = np.zeros((max(16, 2 * self.n), 19, 3))
            grown[: self.n] = self.room[: self.n]
            self.room = grown
        self.room[self.n, :16] = corners
        self.room[self.n, 16:18] = centres
        self.room[self.n, 18, 0] = d
        self.n += 1
        self.born.append(self.seen)
        self.credit.append(0)

    def drop_balls(self) -> int:
        """Forget the balls (the pair is left to the walk); how many there were."""
        n, self.n = self.n, 0
        self.room = np.zeros((0, 19, 3))
        self.born, self.credit = [], []
        return n

    def useless(self) -> bool:
        """Whether the balls covered too few candidates to pay for testing them.

        The PR2's forearm against its palm: a relative pose of two joints, the meshes 1 mm
        apart, so a ball covers almost nothing of the next samples.
        """
        return self.seen >= _HORIZON and sum(self.credit) < _USEFUL * self.seen

    def worth_asking(self) -> bool:
        """Whether a coal distance (a new ball) is expected to save more than it costs.

        A recent ball's covering rate (candidates it was first to cover, per candidate seen
        since it was made) times the candidates still to come (as many as were seen, at least
        ``_HORIZON``) times a collision call's cost, against a distance call's cost.
        """
        collide = self.collide_time / max(self.collided, 1)
        distance = self.distance_time / max(self.asked, 1)
        if self.asked < _EXPLORE:
            return not self.asked or distance < _DEAREST * collide
        recent = slice(-_RECENT, None)
        tests = sum(self.seen - b for b in self.born[recent])
        rate = sum(self.credit[recent]) / max(tests, 1)
        return rate * max(self.seen, _HORIZON) * collide > _MARGIN * distance


class FreeBalls:
    """One thread's balls, per geometry pair of one checker (see the module's doc)."""

    def __init__(self, c: Compiled) -> None:
        coal = import_coal()
        self._coal = coal
        geoms = c.model.geometries
        self._corners = [
            None if g.triangles is None else box_corners(g.triangles[0]) for g in geoms
        ]
        self._pairs: dict[int, _Pair] = {}
        self._distance: dict[int, Any] = {}
        self._request = coal.DistanceRequest()
        self.balls = 0

    def _pair(self, k: int) -> _Pair:
        p = self._pairs.get(k)
        if p is None:
            p = self._pairs[k] = _Pair()
        return p

    def sift(
        self, c: Compiled, scratch: Scratch, poses: F64, rows: I64, ks: I64, eps: float
    ) -> Bools:
        """Bool (len(ks),): the candidates left for the walk (the others are proven free)."""
        keep = np.ones(len(ks), dtype=np.bool_)
        if not len(ks):
            return keep
        two = np.asarray(c.two_meshes, dtype=np.bool_)[ks]
        order = np.argsort(ks, kind="stable")  # by pair, rows in order within each
        sorted_ks = ks[order]
        starts = np.flatnonzero(np.r_[True, sorted_ks[1:] != sorted_ks[:-1]])
        ends = np.r_[starts[1:], len(ks)]
        for s, e in zip(starts.tolist(), ends.tolist(), strict=True):
            at = order[s:e]
            if not two[at[0]]:
                continue
            k = int(sorted_ks[s])
            p = self._pair(k)
            if p.cheap:
                continue
            keep[at] = self._sift_pair(c, scratch, poses, rows[at], k, p, eps)
        return keep

    def _sift_pair(
        self, c: Compiled, scratch: Scratch, poses: F64, rows: I64, k: int, p: _Pair, eps: float
    ) -> Bools:
        """Bool per candidate row of pair ``k``: left for the walk.

        Balls first; then row by row, the uncovered ones: coal's distance (a new ball, tested at
        once on the rows after it) while :meth:`_Pair.worth_asking`, else coal's collision test.
        Free by either, a candidate is dropped; at the first touching or colliding one, it and
        the pair's later rows in the block are left to the walk (which asks coal's collision
        test: its answer, whatever the balls).
        """
        i, j = c.pair_geom1_list[k], c.pair_geom2_list[k]
        n = len(rows)
        keep = np.ones(n, dtype=np.bool_)
        start = 0
        while p.collided < _PROBES and start < n:  # probes: no ball yet, no numpy
            p.seen += 1
            self._place(scratch, poses, int(rows[start]), i, j)
            if not self._collision_free(c, scratch, k, p):
                return keep  # a hit: this and the rest of the block go to the walk
            keep[start] = False
            start += 1
        if p.collided == _PROBES and p.collide_time < _CHEAP * _PROBES:
            p.cheap = True  # the walk asks its calls from now on
        if start == n or p.cheap:
            return keep
        rows = rows[start:]
        kept = self._sift_rows(c, scratch, poses, rows, k, p, eps)
        keep[start:] = kept
        return keep

    def _place(self, scratch: Scratch, poses: F64, r: int, i: int, j: int) -> None:
        """Geometries ``i`` and ``j`` where row ``r`` puts them, in this thread's transforms."""
        tf = scratch.transforms
        pose_i, pose_j = poses[r, i], poses[r, j]
        tf[i].setRotation(pose_i[:3, :3])
        tf[i].setTranslation(pose_i[:3, 3])
        tf[j].setRotation(pose_j[:3, :3])
        tf[j].setTranslation(pose_j[:3, 3])

    def _sift_rows(
        self, c: Compiled, scratch: Scratch, poses: F64, rows: I64, k: int, p: _Pair, eps: float
    ) -> Bools:
        """:meth:`_sift_pair` once the pair's probes are done."""
        i, j = c.pair_geom1_list[k], c.pair_geom2_list[k]
        ca, cb = self._corners[i], self._corners[j]
        assert ca is not None and cb is not None  # two meshes: sift passes no other
        pts = relative_corners(poses[rows, i], poses[rows, j], ca, cb)
        mid = box_centres(pts)
        n = len(rows)
        keep = np.ones(n, dtype=np.bool_)
        if len(p.radii):
            cover = ball_covers(pts, mid, p.corners, p.centres, p.radii, eps)
            hit = cover.any(axis=1)
            balls, counts = np.unique(cover.argmax(axis=1)[hit], return_counts=True)
            for b, cnt in zip(balls.tolist(), counts.tolist(), strict=True):
                p.credit[b] += cnt
            keep[hit] = False
        todo = np.flatnonzero(keep).tolist()
        p.seen += n - len(todo)
        tf = scratch.transforms
        ask = self._may_ask(p)
        for pos in todo:
            p.seen += 1
            if not keep[pos]:  # covered by a ball made at an earlier row of this block
                continue
            self._place(scratch, poses, int(rows[pos]), i, j)
            if not ask:
                if not self._collision_free(c, scratch, k, p):
                    return keep  # a hit: this and the rest of the block go to the walk
                keep[pos] = False
                if p.collided % _RECONSIDER == 0:
                    ask = self._may_ask(p)
                    if not ask and p.useless():
                        p.cheap = True  # the walk asks coal, without the balls' numpy
                        self.balls -= p.drop_balls()
                        return keep
                continue
            d = self._distance_of(c, k, tf[i], tf[j], p)
            if not d > eps:
                return keep  # touching: coal's collision test decides, in the walk
            keep[pos] = False
            p.add(pts[pos], mid[pos], d)
            self.balls += 1
            rest = np.flatnonzero(keep[pos + 1 :]) + pos + 1
            if len(rest):
                one = slice(pos, pos + 1)
                now = ball_covers(pts, mid, pts[one], mid[one], p.radii[-1:], eps)[rest, 0]
                keep[rest[now]] = False
                p.credit[-1] += int(now.sum())
            ask = self._may_ask(p)
        return keep

    def _may_ask(self, p: _Pair) -> bool:
        """Whether the next uncovered candidate of ``p`` is asked by distance (a new ball)."""
        if p.collided < _PROBES or self.balls >= _MAX_TOTAL or len(p.radii) >= _MAX_PER_PAIR:
            return False
        return p.worth_asking()

    def _collision_free(self, c: Compiled, scratch: Scratch, k: int, p: _Pair) -> bool:
        """Coal's collision test of pair ``k`` at the transforms set, timed."""
        i, j = c.pair_geom1_list[k], c.pair_geom2_list[k]
        req, res = scratch.request, scratch.result
        res.clear()
        t = time.perf_counter()
        c.collide[k](scratch.transforms[i], scratch.transforms[j], req, res)
        p.collide_time += time.perf_counter() - t
        p.collided += 1
        return not res.isCollision()

    def _distance_of(self, c: Compiled, k: int, tf_i: Any, tf_j: Any, p: _Pair) -> float:
        """Coal's distance between the meshes of pair ``k`` at the transforms given, timed."""
        fn = self._distance.get(k)
        if fn is None:
            geoms = c.model.geometries
            i, j = c.pair_geom1_list[k], c.pair_geom2_list[k]
            fn = self._distance[k] = self._coal.ComputeDistance(
                geoms[i].geometry, geoms[j].geometry
            )
        res = self._coal.DistanceResult()
        t = time.perf_counter()
        fn(tf_i, tf_j, self._request, res)
        p.distance_time += time.perf_counter() - t
        p.asked += 1
        return float(res.min_distance)


def sift(c: Compiled, scratch: Scratch, poses: F64, rows: I64, ks: I64, eps: float) -> Bools:
    """The candidates (bool per candidate) left once free balls prove some free (see above).

    The store is this thread's scratch's, made on first use.
    """
    store: FreeBalls | None = scratch.free_balls
    if store is None:
        store = scratch.free_balls = FreeBalls(c)
    return store.sift(c, scratch, poses, rows, ks, eps)
