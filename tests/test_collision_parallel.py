"""Worker processes give the answers of one process, whichever way they start.

Under ``fork`` a worker adopts the parent's built checker; under ``spawn`` it rebuilds one from
plain records. Both must agree with the single-process answer on a real robot, pair by pair.
"""

from __future__ import annotations

import multiprocessing
from typing import cast

import numpy as np
import pytest

from robotspec.collision import SelfCollisionChecker, random_configurations
from robotspec.collision.parallel import ever_colliding_parallel
from tests.conftest import all_pairs_checker


@pytest.fixture(scope="module")
def checker() -> SelfCollisionChecker:
    return cast(SelfCollisionChecker, all_pairs_checker("pr2"))


@pytest.mark.parametrize("method", ["fork", "spawn"])
def test_workers_agree_with_one_process(checker: SelfCollisionChecker, method: str) -> None:
    if method not in multiprocessing.get_all_start_methods():
        pytest.skip(f"start method {method} is not available here")
    qs = random_configurations(checker.world, 240, seed=9)
    mask = np.ones(len(checker.active_pairs), dtype=np.bool_)
    alone = ever_colliding_parallel(checker, qs, mask.copy(), processes=1, chunk=60)
    starts: list[int] = []
    pooled = ever_colliding_parallel(
        checker,
        qs,
        mask.copy(),
        processes=2,
        chunk=60,
        start_method=method,
        on_chunk=lambda start, _hits: starts.append(start),
    )
    assert alone.any() and not alone.all()
    np.testing.assert_array_equal(pooled, alone)
    assert starts == [0, 60, 120, 180]
