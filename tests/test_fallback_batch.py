"""The numpy fallback's vectorised kinematics against the C core, on real robots (issue 34).

Why: the fallback now computes a batch with one matrix product per depth of the tree for every
sample (``_kintree_py``) and a chain by running products (``_kincore_py``), a different order
of sums than the C core's per-sample loop. So its answers are checked against the C core's to
1e-12 on the PR2 (a planar base: scratch slots, mimic joints) and Talos (a floating base, 50
bodies): every body's pose for batches of any size (empty, one, across the fallback's steps),
chain poses and Jacobians; and each row of a batch is the single call's answer bit for bit.
"""

from __future__ import annotations

from types import ModuleType

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robotspec import robots
from robotspec.accel import using
from robotspec.collision import random_configurations
from robotspec.errors import KinematicsError
from robotspec.model import _kincore_py as kin_py
from robotspec.model import _kintree_py, kincore
from robotspec.model.kinematics import Kinematics
from robotspec.model.world import World
from tests.conftest import erd_robots


def _c_core() -> ModuleType:
    if kincore.accelerators_disabled():
        pytest.skip("compares the fallback with the C core; ROBOTSPEC_NO_ACCEL turns C off")
    return pytest.importorskip("robotspec.model._kincore", reason="the C core is not built")


def _world(name: str) -> World:
    robots_dir = erd_robots()
    if name == "Talos":
        from robotspec.description.urdf import load_urdf

        return load_urdf(robots_dir / "talos_data" / "robots" / "talos_full_v2.urdf", meshes="keep")
    world: World = getattr(robots, name).load().world
    return world


class _Pair:
    """One world's kinematics on the C core and on the fallback."""

    def __init__(self, world: World) -> None:
        self.world = world
        with using((kincore.CHOICE, _c_core())):
            self.c = Kinematics(world)
        with using((kincore.CHOICE, kin_py)):
            self.py = Kinematics(world)
        self.nd = len(world.degrees_of_freedom)

    def configurations(self, n: int, seed: int) -> np.ndarray:
        return np.asarray(random_configurations(self.world, n, seed=seed), dtype=np.float64)


@pytest.fixture(scope="module", params=["PR2", "Talos"])
def pair(request: pytest.FixtureRequest) -> _Pair:
    return _Pair(_world(request.param))


# A batch runs in equal steps of at most _CHUNK samples, one plan for all: 333 samples in steps
# of 167 and 166 (a short last step runs its calls on zeros past its samples), 261 in 131 and
# 130, 512 in two full steps.
@pytest.mark.parametrize("last", [77, 5, _kintree_py._CHUNK])
def test_batches_across_the_steps_equal_the_c_core(pair: _Pair, last: int) -> None:
    qs = pair.configurations(_kintree_py._CHUNK + last, seed=34)
    qs[0] = 0.0
    want = pair.c.forward_batch(qs, threads=1)
    got = pair.py.forward_batch(qs, threads=1)
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(got[:, :, 3], np.tile([0.0, 0.0, 0.0, 1.0], got.shape[:2] + (1,)))
    for i in (0, 1, _kintree_py._CHUNK, len(qs) - 1):  # a row is the single call's bits
        np.testing.assert_array_equal(pair.py.forward(qs[i]), got[i])


def test_chains_and_jacobians_equal_the_c_core(pair: _Pair) -> None:
    qs = pair.configurations(40, seed=35)
    names = [b.name for b in pair.world.bodies]
    for tip in (names[len(names) // 2], names[-1]):
        for root in (names[0], names[1]):
            try:
                chain_c, chain_py = pair.c.chain(root, tip), pair.py.chain(root, tip)
            except KinematicsError:  # not every pair of bodies is a chain
                continue
            np.testing.assert_allclose(
                chain_py.fk_batch(qs), chain_c.fk_batch(qs), rtol=0, atol=1e-12
            )
            for q in qs[:5]:
                np.testing.assert_allclose(chain_py.fk(q), chain_c.fk(q), rtol=0, atol=1e-12)
                np.testing.assert_allclose(
                    chain_py.jacobian(q), chain_c.jacobian(q), rtol=0, atol=1e-12
                )
                np.testing.assert_allclose(
                    pair.py.pose(q, tip), pair.c.pose(q, tip), rtol=0, atol=1e-12
                )


@pytest.fixture(scope="module")
def pr2() -> _Pair:
    return _Pair(_world("PR2"))


@settings(max_examples=25)
@given(n=st.integers(0, 70), seed=st.integers(0, 2**16), scale=st.sampled_from([1.0, 10.0]))
def test_any_batch_size_and_values_equal_the_c_core(
    pr2: _Pair, n: int, seed: int, scale: float
) -> None:
    qs = np.random.default_rng(seed).uniform(-scale, scale, (n, pr2.nd))
    got = pr2.py.forward_batch(qs, threads=1)
    assert got.shape == (n, len(pr2.world.bodies), 4, 4)
    np.testing.assert_allclose(got, pr2.c.forward_batch(qs, threads=1), rtol=0, atol=1e-12)
