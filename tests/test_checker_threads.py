"""A SelfCollisionChecker shared by threads answers as in one thread (issue 24, item 4).

Each thread used to write the same coal transforms and the same collision result: a thread
could move a geometry between another's pose update and its coal call, or clear its result
before it was read (wrong distances, missed collisions). The queries here run in 4 threads at
once on the PR2, with Python switching threads every 10 microseconds to make such interleavings
frequent, and must give the single-thread answers.

Distances are compared to 1e-9 m, not bit for bit: coal's GJK starts from the support vertices of
its previous call, so even one thread gets last-bit differences when it visits configurations in
another order (measured: under 1e-13 m).
"""

from __future__ import annotations

import sys
import threading
from collections.abc import Callable, Iterator
from typing import Any

import numpy as np
import pytest

from robotspec.collision import MeshLibrary, SelfCollisionChecker
from robotspec.collision.sampling import random_configurations
from robotspec.compiler import compile_robot

from .conftest import erd_robots

THREADS = 4


@pytest.fixture(scope="module")
def pr2() -> Any:
    erd_robots()
    return compile_robot("pr2")


@pytest.fixture(scope="module")
def meshes() -> MeshLibrary:
    """The PR2's meshes, read once for the module's checkers."""
    return MeshLibrary()


@pytest.fixture(autouse=True)
def _switch_often() -> Iterator[None]:
    """Threads switch every 10 µs (Python's default is 5 ms): many more interleavings."""
    before = sys.getswitchinterval()
    sys.setswitchinterval(1e-5)
    yield
    sys.setswitchinterval(before)


def _in_threads(fn: Callable[[int], Any]) -> list[Any]:
    """``fn(k)`` in ``THREADS`` threads started together; their results, or the first error."""
    results: list[Any] = [None] * THREADS
    errors: list[BaseException] = []
    start = threading.Barrier(THREADS)

    def run(k: int) -> None:
        try:
            start.wait()
            results[k] = fn(k)
        except BaseException as exc:  # noqa: BLE001 - handed to the main thread
            errors.append(exc)

    threads = [threading.Thread(target=run, args=(k,)) for k in range(THREADS)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    if errors:
        raise errors[0]
    return results


def test_shared_checker_collisions_are_the_single_thread_ones(
    pr2: Any, meshes: MeshLibrary
) -> None:
    checker = SelfCollisionChecker.from_robot(pr2, meshes=meshes)
    qs = random_configurations(pr2.world, 200, seed=11)
    want = checker.collisions_batch(qs)
    want_margin = checker.collisions_batch(qs, margin=0.02)
    assert 0 < want.any(axis=1).sum() < len(qs)  # some configurations collide, some do not

    def queries(k: int) -> tuple[Any, ...]:
        # Each thread its own order and margins, so the threads' coal calls interleave.
        order = np.roll(np.arange(len(qs)), 50 * k)
        one = [checker.in_collision(qs[i]) for i in order]
        pairs = [checker.colliding_pairs(qs[i], margin=0.02 * (k % 2)) for i in order]
        batch = checker.collisions_batch(qs[order])
        return order, one, pairs, batch

    for k, (order, one, pairs, batch) in enumerate(_in_threads(queries)):
        assert np.array_equal(batch, want[order]), k
        assert one == want[order].any(axis=1).tolist(), k
        table = want_margin if k % 2 else want
        assert [set(p) for p in pairs] == [
            {checker.active_pairs[j] for j in np.flatnonzero(table[i])} for i in order
        ], k


def test_shared_checker_distances_are_the_single_thread_ones(pr2: Any, meshes: MeshLibrary) -> None:
    checker = SelfCollisionChecker.from_robot(pr2, meshes=meshes)
    qs = random_configurations(pr2.world, 6, seed=12)
    want = checker.distances_batch(qs)
    want_points = [checker.distances(q) for q in qs[:2]]

    def queries(k: int) -> tuple[Any, ...]:
        order = np.roll(np.arange(len(qs)), 2 * k)
        return order, checker.distances_batch(qs[order]), [checker.distances(q) for q in qs[:2]]

    for k, (order, got, points) in enumerate(_in_threads(queries)):
        np.testing.assert_allclose(got, want[order], rtol=0, atol=1e-9, err_msg=str(k))
        for mine, theirs in zip(points, want_points, strict=True):
            for a, b in zip(mine, theirs, strict=True):
                assert (a.link1, a.link2) == (b.link1, b.link2)
                assert a.distance == pytest.approx(b.distance, abs=1e-9)
                assert a.point1 == pytest.approx(b.point1, abs=1e-6)
                assert a.point2 == pytest.approx(b.point2, abs=1e-6)


def test_threads_build_a_fresh_checker_once(pr2: Any, meshes: MeshLibrary) -> None:
    """The first queries, all at once: one build, every thread the same answers."""
    checker = SelfCollisionChecker.from_robot(pr2, meshes=meshes)
    q = random_configurations(pr2.world, 1, seed=13)[0]
    got = _in_threads(lambda k: (checker.geometry, checker.distances_batch(q[None, :])))
    assert all(model is got[0][0] for model, _ in got)
    for _, d in got[1:]:
        np.testing.assert_allclose(d, got[0][1], rtol=0, atol=1e-9)
