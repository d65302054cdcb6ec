"""The narrow phase of a block of samples: which broad-phase candidates collide.

A candidate is a (sample row, geometry pair) whose bounding boxes come within the margin. Two
meshes are first proven apart or crossing by the C mesh core (tens of times cheaper than coal
when they nearly touch); coal's ``ComputeCollision`` decides every candidate the proofs leave.

With the C mesh core, :func:`walk` proves a whole block in one C call without the GIL (every
row's candidates in order) and leaves coal the few candidates it cannot prove. When only "does
it collide" is asked, a row stops at its first proven crossing, or at its first candidate left
to coal, and is walked on (one more C call for all such rows) only when coal finds that one
free: touching meshes are the costliest to prove and coal often finds them colliding. Why one
C call: on the PR2 coal is asked about one candidate in a thousand, so the GIL is held only for
a few Python steps per block, and threads checking a batch run side by side instead of taking
turns (issue 34).

Without it (the fallback core proves nothing) two ways walk the candidates, with the same
answers (:func:`narrow_block` picks one):

- :func:`block_hits` walks them in order in Python (every colliding pair, or the first of each
  sample), proving mesh pairs one by one as it reaches them unless they were proven in one call
  beforehand (:func:`prove_apart`).
- :func:`first_hits` answers "does the sample collide" in waves: the first candidate of every
  sample, then the next one, two, four... of the samples not yet seen colliding, each wave's mesh
  proofs in one C call. The C call releases the GIL, so threads sharing a checker run their
  proofs at once; the waves keep the work near the one-by-one walk's, which stops each sample at
  its first hit (proving every candidate of a block at once costs twice as much on the PR2).

Before either, a "Never" pass (pairs never seen colliding, asked at every sample) lets
:mod:`.free_balls` drop the mesh candidates it proves free from coal distances asked at nearby
relative poses (the PR2's shoulder and fingers: tens of distances for thousands of samples).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from robotspec.arrays import F64, I64
from robotspec.collision import free_balls, meshcore
from robotspec.collision.compiled import Compiled, Scratch

__all__ = [
    "APART",
    "CROSS",
    "UNKNOWN",
    "UNTRIED",
    "WALK_ALL",
    "WALK_DROP_FOUND",
    "WALK_FIRST",
    "batch_proofs_for",
    "block_hits",
    "first_hits",
    "narrow_block",
    "prove_apart",
    "walk",
]

#: What the mesh core proved of a candidate (its codes), and "not asked".
UNKNOWN, APART, CROSS, UNTRIED = 0, 1, 2, -1
#: What a walk reports per row (the mesh core's modes): every colliding body pair; the first one
#: only; every body pair not found colliding before (in any row: ``found`` is read and written).
WALK_ALL, WALK_FIRST, WALK_DROP_FOUND = 0, 1, 2
#: No candidate (an index array).
_NONE = np.zeros(0, dtype=np.int64)
#: Fewest samples of an any-hit block whose fallback proofs go in waves (see narrow_block).
_WAVES_FROM = 64
#: Candidates of a block from which the fallback's mesh proofs run in one call, not one by one.
_BATCH_PROOFS = 64
#: Fewest candidates (counted before dropping the samples already seen colliding) a wave of
#: :func:`first_hits` takes, several positions at once if need be.
_WAVE_MIN = 64

Hits = tuple[list[int], list[int]]


def prove_apart(
    c: Compiled, poses: F64, rows: list[int], ks: list[int], eps: float
) -> tuple[list[int], list[int], list[int]]:
    """The candidates left once the mesh pairs proven apart are dropped, and their proofs.

    Each is ``UNKNOWN`` or ``CROSS`` (coal decides the first, the second is a collision), or
    ``UNTRIED`` for a pair that is not two meshes.
    """
    r = np.asarray(rows, dtype=np.int64)
    k = np.asarray(ks, dtype=np.int64)
    at = np.flatnonzero(np.asarray(c.two_meshes, dtype=np.bool_)[k])
    proofs = np.full(len(k), UNTRIED, dtype=np.int64)
    if not len(at):
        return rows, ks, proofs.tolist()
    proofs[at] = meshcore.core().apart(
        c.meshes, poses, r[at], k[at], c.pair_geom1, c.pair_geom2, eps
    )
    keep = proofs != APART
    return r[keep].tolist(), k[keep].tolist(), proofs[keep].tolist()


def block_hits(
    c: Compiled,
    scratch: Scratch,
    req: Any,
    poses: F64,
    candidates: tuple[list[int], list[int], list[int]],
    found: list[bool] | None,
    eps: float,
    *,
    first_only: bool,
    drop_found: bool,
) -> Hits:
    """The (row, body pair)s that collide among ``candidates`` (rows, geometry pairs, proofs).

    ``first_only`` stops a row at its first colliding pair; ``drop_found`` skips a pair that has
    collided before (``found``, per body pair, is updated when given).
    """
    res = scratch.result
    clear, is_collision = res.clear, res.isCollision
    tf = scratch.transforms
    fns = c.collide
    owner = c.pair_of_list
    g1s, g2s = c.pair_geom1_list, c.pair_geom2_list
    meshes, two_meshes = c.meshes, c.two_meshes
    apart = meshcore.core().apart_one
    hit_rows: list[int] = []
    hit_pairs: list[int] = []
    stamp = [-1] * len(tf)
    last_row = -1
    skip_row = False
    row_hits: set[int] = set()
    for r, k, proof in zip(*candidates, strict=True):
        if r != last_row:
            last_row, skip_row = r, False
            row_hits = set()
        elif skip_row:
            continue
        p = owner[k]
        if p in row_hits or (drop_found and found is not None and found[p]):
            continue
        i, j = g1s[k], g2s[k]
        if proof == UNTRIED and two_meshes[k]:
            proof = apart(meshes, poses, r, i, j, eps)
            if proof == APART:
                continue
        if proof != CROSS:
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
        hit_rows.append(r)
        hit_pairs.append(p)
        if found is not None:
            found[p] = True
        skip_row = first_only
    return hit_rows, hit_pairs


def first_hits(
    c: Compiled, scratch: Scratch, req: Any, poses: F64, rows: I64, ks: I64, eps: float
) -> Hits:
    """One colliding (row, body pair) per row that collides, in waves (see the module's doc).

    ``rows`` (sorted) and ``ks`` are the broad phase's candidates of the block. Wave after wave
    takes the next candidate of every row not yet seen colliding; once fewer than
    ``_WAVE_MIN`` candidates are left per position, a wave takes several positions at once (a
    C call and a few numpy steps cost more than the proofs they would spare).
    """
    n_cand = len(ks)
    if not n_cand:
        return [], []
    starts = np.flatnonzero(np.r_[True, rows[1:] != rows[:-1]])
    pos = np.arange(n_cand) - np.repeat(starts, np.diff(np.r_[starts, n_cand]))
    order = np.argsort(pos, kind="stable")
    most = int(pos[order[-1]])
    bounds = np.searchsorted(pos[order], np.arange(most + 2))
    two = np.asarray(c.two_meshes, dtype=np.bool_)[ks] if c.meshes is not None else None
    done = np.zeros(poses.shape[0], dtype=np.bool_)
    hit_rows: list[int] = []
    hit_pairs: list[int] = []
    p = 0
    while p <= most:
        q = p + 1
        while q <= most and bounds[q + 1] - bounds[p] < _WAVE_MIN:
            q += 1
        sel = np.sort(order[bounds[p] : bounds[q]])  # by row again, as block_hits walks them
        p = q
        sel = sel[~done[rows[sel]]]
        if not len(sel):
            continue
        r, k = rows[sel], ks[sel]
        proofs = np.full(len(sel), UNTRIED, dtype=np.int64)
        if two is not None:
            at = np.flatnonzero(two[sel])
            if len(at):
                proofs[at] = meshcore.core().apart(
                    c.meshes, poses, r[at], k[at], c.pair_geom1, c.pair_geom2, eps
                )
        # Proven crossing: a hit, no coal (numpy, no Python per candidate; rows are sorted, so
        # np.unique's first index is each row's first crossing pair).
        cross = proofs == CROSS
        if cross.any():
            cr, first = np.unique(r[cross], return_index=True)
            done[cr] = True
            hit_rows += cr.tolist()
            hit_pairs += c.pair_of[k[cross][first]].tolist()
        ask = (proofs != APART) & ~cross & ~done[r]  # coal decides these, one by one
        if not ask.any():
            continue
        wave = (r[ask].tolist(), k[ask].tolist(), proofs[ask].tolist())
        rs, ps = block_hits(
            c, scratch, req, poses, wave, None, eps, first_only=True, drop_found=False
        )
        done[rs] = True
        hit_rows += rs
        hit_pairs += ps
    return hit_rows, hit_pairs


def walk(
    c: Compiled,
    scratch: Scratch,
    req: Any,
    poses: F64,
    rows: I64,
    ks: I64,
    found: NDArray[np.uint8],
    eps: float,
    mode: int,
) -> Hits | None:
    """The (row, body pair)s that collide among a block's candidates, proofs in one C call.

    ``rows`` (non-decreasing) and ``ks`` are the broad phase's candidates, ``found`` (P,) the
    body pairs found colliding so far (updated under ``WALK_DROP_FOUND``). Coal decides what the
    proofs leave, row by row in order. None when the mesh core has no walk (the fallback) or the
    checker no mesh: :func:`narrow_block` answers then.
    """
    fn = getattr(meshcore.core(), "walk", None)
    if fn is None or c.meshes is None:
        return None

    def proofs(sel: I64 | None) -> tuple[I64, I64, I64]:
        """The walk over candidates ``sel`` (all: None): proven hits, indices left to coal."""
        r, k = (rows, ks) if sel is None else (rows[sel], ks[sel])
        hr, hp, left = fn(
            c.meshes, poses, r, k, c.pair_geom1, c.pair_geom2, c.pair_of, found, eps, mode
        )
        return hr, hp, left if sel is None else sel[left]

    hr, hp, left = proofs(None)
    hit_rows: list[int] = hr.tolist()
    hit_pairs: list[int] = hp.tolist()
    first = mode == WALK_FIRST
    drop = mode == WALK_DROP_FOUND
    seen = found.astype(np.bool_).tolist() if drop and len(left) else None
    while len(left):
        cand = (rows[left].tolist(), ks[left].tolist(), [UNKNOWN] * len(left))
        rs, ps = block_hits(
            c, scratch, req, poses, cand, seen, eps, first_only=first, drop_found=drop
        )
        hit_rows += rs
        hit_pairs += ps
        if drop:
            found[ps] = 1
        if not first or len(rs) == len(left):  # any hit: every waiting row has its hit
            break
        # Any hit: one candidate per row waited for coal; the rows coal found free walk on.
        hit = set(rs)
        on = left[[r not in hit for r in rows[left].tolist()]]
        ends = np.searchsorted(rows, rows[on], side="right")
        rest = np.concatenate(
            [np.arange(i + 1, e) for i, e in zip(on, ends, strict=True)] + [_NONE]
        )
        if not len(rest):
            break
        hr, hp, left = proofs(rest)
        hit_rows += hr.tolist()
        hit_pairs += hp.tolist()
    return hit_rows, hit_pairs


def narrow_block(
    c: Compiled,
    scratch: Scratch,
    req: Any,
    poses: F64,
    rows: I64,
    ks: I64,
    found: NDArray[np.uint8],
    eps: float,
    mode: int,
    batch_proofs: bool,
) -> Hits:
    """As :func:`walk`, for any mesh core: the walk where there is one, else Python's ways.

    ``batch_proofs`` (Python's ways only): the mesh proofs run in calls over many candidates
    (an any-hit query then goes in waves, :func:`first_hits`) rather than one by one.
    """
    walked = walk(c, scratch, req, poses, rows, ks, found, eps, mode)
    if walked is not None:
        return walked
    if mode == WALK_FIRST and batch_proofs:
        return first_hits(c, scratch, req, poses, rows, ks, eps)
    drop = mode == WALK_DROP_FOUND
    seen = found.astype(np.bool_).tolist()
    if drop and c.meshes is not None and batch_proofs and len(ks):
        # Pairs never seen colliding are asked at every sample: free balls prove most of the
        # nearly touching ones free from a few coal distances (see free_balls).
        keep = free_balls.sift(c, scratch, poses, rows, ks, eps)
        rows, ks = rows[keep], ks[keep]
    cand = (rows.tolist(), ks.tolist(), [UNTRIED] * len(ks))
    if c.meshes is not None and batch_proofs and len(ks) >= _BATCH_PROOFS:
        # Every candidate is tested, so the mesh proofs run in one call (no Python per
        # candidate); a few candidates are proven one by one (numpy's fixed cost would exceed
        # the calls saved).
        cand = prove_apart(c, poses, cand[0], cand[1], eps)
    rs, ps = block_hits(
        c, scratch, req, poses, cand, seen, eps, first_only=mode == WALK_FIRST, drop_found=drop
    )
    if drop:
        found[ps] = 1
    return rs, ps


def batch_proofs_for(n: int, mode: int, threads: int) -> bool:
    """Whether the fallback's proofs of ``n`` samples run in calls over many candidates.

    An any-hit batch proves in waves of calls too (:func:`first_hits`): their numpy steps cost
    what the one-by-one walk does on one thread, and let other threads run between them; a few
    configurations keep the walk (numpy's fixed cost per wave would show).
    """
    return mode != WALK_FIRST or threads > 1 or n >= _WAVES_FROM
