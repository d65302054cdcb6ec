"""Samples through a collision query's three phases: kinematics, broad phase, narrow phase.

Why a module of its own: the checker (:mod:`.checker`) decides what is asked (any hit, every
pair, pairs never seen colliding; on which threads); this runs it, block by block of samples,
each phase one C call that releases the GIL (the kinematics core, its broad phase, the mesh
core's walk, :func:`.narrow.walk`). Python only joins the calls and asks coal about what the
proofs leave, so threads scanning their own samples run side by side (issue 34).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from robotspec.arrays import F64, I64
from robotspec.collision.compiled import Compiled, Scratch
from robotspec.collision.narrow import WALK_DROP_FOUND, WALK_FIRST, narrow_block
from robotspec.model import kincore
from robotspec.model.kinematics import Kinematics

__all__ = ["APART_SLACK", "BLOCK", "first_hit", "place", "scan_rows"]

Bools = NDArray[np.bool_]

#: Samples per block in batch queries: bounds the memory of the pose arrays (~10 MB).
BLOCK = 512
#: Room (m) beyond the margin by which a mesh pair must be proven apart before coal is skipped:
#: coal's own collision test between triangles stops within about 1e-6 m, so a pair proven this far
#: apart is one coal calls apart too, and the answers stay coal's.
APART_SLACK = 1e-5


def place(
    c: Compiled, kin: Kinematics, qs: F64, margin: float, mask: NDArray[np.uint8] | None
) -> tuple[I64, I64, F64]:
    """Candidate (sample, geometry pair)s of ``qs`` and every geometry's pose (n, G, 4, 4).

    A candidate's boxes come within ``margin``; every other pair is farther apart than that, so
    the narrow phase on the candidates gives the exact answer. ``mask`` (uint8 per geometry
    pair) leaves pairs out.
    """
    bodies = kin.forward(qs[0]) if qs.shape[0] == 1 else kin.forward_batch(qs, threads=1)
    rows, ks, poses = kincore.core().broad(c.broad, bodies, margin, mask)
    return rows, ks, poses


def scan_rows(
    c: Compiled,
    kin: Kinematics,
    scratch: Scratch,
    qs: F64,
    hits: Bools,
    margin: float,
    geom_mask: NDArray[np.uint8] | None,
    mode: int,
    batch_proofs: bool,
) -> None:
    """Set ``hits`` (n, P) for the samples ``qs`` (n, D), block by block, on this thread.

    ``mode`` is the walk's (:data:`.narrow.WALK_FIRST` and the others); ``batch_proofs`` only
    matters where the mesh core has no walk (:func:`.narrow.narrow_block`).
    """
    req, _ = scratch.collision(margin)
    found = np.zeros(hits.shape[1], dtype=np.uint8)
    eps = margin + APART_SLACK
    hit_rows: list[int] = []
    hit_pairs: list[int] = []
    for start in range(0, qs.shape[0], BLOCK):
        block = qs[start : start + BLOCK]
        if mode == WALK_DROP_FOUND and start:
            left = (found == 0)[c.pair_of]
            geom_mask = left.astype(np.uint8) if geom_mask is None else geom_mask & left
        rows, ks, poses = place(c, kin, block, margin, geom_mask)
        rs, ps = narrow_block(c, scratch, req, poses, rows, ks, found, eps, mode, batch_proofs)
        hit_rows += [start + r for r in rs] if start else rs
        hit_pairs += ps
    hits[hit_rows, hit_pairs] = True


def first_hit(
    c: Compiled, kin: Kinematics, scratch: Scratch, q: F64, margin: float, n_pairs: int
) -> bool:
    """Whether one configuration ``q`` (D,) collides: the single query's path, nothing else.

    Why apart from :func:`scan_rows`: ``in_collision`` is called thousands of times a second,
    and most calls end in the broad phase (no boxes meet), where a batch's bookkeeping would
    cost more than the two C calls.
    """
    rows, ks, poses = kincore.core().broad(c.broad, kin.forward(q), margin, None)
    if not len(ks):
        return False
    req, _ = scratch.collision(margin)
    found = np.zeros(n_pairs, dtype=np.uint8)
    eps = margin + APART_SLACK
    rs, _ = narrow_block(c, scratch, req, poses, rows, ks, found, eps, WALK_FIRST, False)
    return bool(rs)
