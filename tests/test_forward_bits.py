"""One configuration and a batch give the same poses, bit for bit, on both cores (issue 31).

Why exact: a caller that checks one configuration with ``forward(q)`` and then samples it in a
batch (or the collision checker, which uses both) must not see two answers for one ``q``. The
numpy fallback computed one configuration with ``np.matmul`` (BLAS, whose sums may be fused or
reordered) and a batch term by term, so the two differed in the last bit under
``ROBOTSPEC_NO_ACCEL=1``; it now runs one configuration as a batch of one. The C core runs the
same per-sample loop for both. Checked on PR2 (planar base: scratch slots), Panda and Talos
(a floating base, 50 bodies), over random configurations and more than one of the fallback's
256-sample steps, for the batch on one and on two threads and into a caller's array.
"""

from __future__ import annotations

from collections.abc import Iterator
from types import ModuleType

import numpy as np
import pytest

from robotspec import robots
from robotspec.accel import using
from robotspec.collision import random_configurations
from robotspec.model import _kincore_py as kin_py
from robotspec.model import kincore
from robotspec.model.kinematics import Kinematics
from robotspec.model.world import World
from tests.conftest import erd_robots

#: Samples per robot: more than one of the fallback's batch steps (_kincore_py._CHUNK = 256).
N = 300


def _cores() -> Iterator[tuple[str, ModuleType]]:
    yield "numpy fallback", kin_py
    try:
        from robotspec.model import _kincore
    except ImportError:
        return
    yield "C core", _kincore


CORES = list(_cores())


@pytest.fixture(scope="module", params=["PR2", "Panda", "Talos"])
def world(request: pytest.FixtureRequest) -> World:
    robots_dir = erd_robots()
    if request.param == "Talos":
        from robotspec.description.urdf import load_urdf

        return load_urdf(robots_dir / "talos_data" / "robots" / "talos_full_v2.urdf", meshes="keep")
    loaded: World = getattr(robots, request.param).load().world
    return loaded


def _configurations(world: World) -> np.ndarray:
    q = np.asarray(random_configurations(world, N, seed=31), dtype=np.float64)
    q[0] = 0.0  # the zero configuration too (a sign of zero is a bit as well)
    return q


@pytest.mark.parametrize(("core", "module"), CORES, ids=[c for c, _ in CORES])
def test_forward_equals_its_row_of_forward_batch(
    world: World, core: str, module: ModuleType
) -> None:
    qs = _configurations(world)
    with using((kincore.CHOICE, module)):
        kin = Kinematics(world)
        batch = kin.forward_batch(qs, threads=1)
        np.testing.assert_array_equal(kin.forward_batch(qs, threads=2), batch)
        out = np.full_like(batch, np.nan)
        np.testing.assert_array_equal(kin.forward_batch(qs, out=out, threads=1), batch)
        for i, q in enumerate(qs):
            one = kin.forward(q)
            assert np.array_equal(one, batch[i]), (
                f"{core}: forward(q) and forward_batch(Q)[{i}] differ by up to "
                f"{np.abs(one - batch[i]).max():.3g}"
            )


@pytest.mark.parametrize(("core", "module"), CORES, ids=[c for c, _ in CORES])
def test_chain_fk_equals_its_row_of_chain_fk_batch(
    world: World, core: str, module: ModuleType
) -> None:
    qs = _configurations(world)
    tip = max(world.bodies, key=world.depth)  # the longest chain from the root
    with using((kincore.CHOICE, module)):
        chain = Kinematics(world).chain(world.bodies[0], tip)
        batch = chain.fk_batch(qs)
        for i, q in enumerate(qs):
            assert np.array_equal(chain.fk(q), batch[i]), f"{core}: chain to '{tip.name}', row {i}"
