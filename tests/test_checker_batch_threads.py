"""A collision batch split over threads gives the one-thread answers, bit for bit (issue 34).

``threads=2`` cuts the batch into two sample ranges checked at once, and an any-hit query then
proves its mesh pairs in waves of C calls (robotspec/collision/narrow.py) instead of one by one:
both must leave every answer as it was. Real robots, their own SRDF rules, random configurations
(more than one block of samples per thread, so blocks and slices both have edges).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from robotspec.collision import CollisionRules, SelfCollisionChecker, random_configurations
from robotspec.description.srdf_reader import load_srdf
from robotspec.description.urdf import load_urdf
from robotspec.errors import CollisionError

from .conftest import erd_robots

#: Samples per robot: each of two threads gets more than one 512-sample block.
SAMPLES = 1300


def _checker(urdf: Path, srdf: Path) -> SelfCollisionChecker:
    world = load_urdf(urdf)
    return SelfCollisionChecker(world, CollisionRules.for_world(world, srdf=load_srdf(srdf)))


@pytest.fixture(scope="module", params=["pr2", "talos"])
def checker(request: pytest.FixtureRequest) -> SelfCollisionChecker:
    robots = erd_robots()
    if request.param == "pr2":
        return _checker(
            robots / "pr2_description" / "urdf" / "pr2.urdf",
            robots / "pr2_description" / "srdf" / "pr2.srdf",
        )
    return _checker(
        robots / "talos_data" / "robots" / "talos_full_v2.urdf",
        robots / "talos_data" / "srdf" / "talos.srdf",
    )


def test_two_threads_give_the_one_thread_answers(checker: SelfCollisionChecker) -> None:
    qs = random_configurations(checker.world, SAMPLES, seed=3)
    every = checker.collisions_batch(qs, threads=1)
    assert 0 < every.any(axis=1).sum() < SAMPLES, "the samples must mix free and colliding"
    np.testing.assert_array_equal(checker.collisions_batch(qs, threads=2), every)
    anyhit = checker.in_collision_batch(qs, threads=1)
    np.testing.assert_array_equal(anyhit, every.any(axis=1))
    np.testing.assert_array_equal(checker.in_collision_batch(qs, threads=2), anyhit)
    # with a margin, and against the single-configuration queries on a few samples
    near = checker.in_collision_batch(qs, margin=0.01, threads=2)
    np.testing.assert_array_equal(near, checker.in_collision_batch(qs, margin=0.01))
    for q, hit in zip(qs[:40], anyhit[:40], strict=True):
        assert checker.in_collision(q) == hit


def test_threads_must_be_a_small_positive_integer(checker: SelfCollisionChecker) -> None:
    qs = random_configurations(checker.world, 2, seed=0)
    for bad in (0, 65, 1.5, True, "2"):
        with pytest.raises(CollisionError, match="threads must be an integer between 1 and 64"):
            checker.in_collision_batch(qs, threads=bad)  # type: ignore[arg-type]
