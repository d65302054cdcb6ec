"""The numpy tree program against the C core on programs hypothesis makes, and on Solo12 (issue 34).

Why: the fallback does not run a program's rows as given. It folds fixed rows into constants,
stores a turn about y with its columns permuted, turns two columns as one complex number, keeps
Rodrigues' terms for any other axis, reads a group's parents as slices or broadcasts, and
computes a fixed body as its node's pose times a constant; the PR2 and Talos
(tests/test_fallback_batch.py) take only some of those paths. Random programs take all of them:
frame axes of both signs, unit and non-unit general axes, slides, fixed chains, scratch slots, a
slot written twice, rows sharing a DOF, origins whose last row is not 0 0 0 1 (the C core reads
three rows). Each is compared with the C core to 1e-9, and each row of a batch with the single
call bit for bit. Solo12, a robot no spec names, is compared the same way through the public API.
"""

from __future__ import annotations

from types import ModuleType
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robotspec.accel import using
from robotspec.collision import random_configurations
from robotspec.model import _kincore_py as kin_py
from robotspec.model import kincore
from robotspec.model.kinematics import Kinematics
from tests.conftest import erd_robots

FRAME_AXES = [np.eye(3)[k] * s for k in range(3) for s in (1.0, -1.0)]


def _c_core() -> ModuleType:
    if kincore.accelerators_disabled():
        pytest.skip("compares the fallback with the C core; ROBOTSPEC_NO_ACCEL turns C off")
    return pytest.importorskip("robotspec.model._kincore", reason="the C core is not built")


def _rotation(rng: np.random.Generator) -> np.ndarray:
    quat = rng.normal(size=4)
    w, x, y, z = quat / np.linalg.norm(quat)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def _program(seed: int, n_out: int, n_scratch: int, n_extra: int, n_dof: int) -> list[Any]:
    """A valid tree program: every slot written once in a random order, then ``n_extra`` rows
    writing any slot again; each row's parent already written."""
    rng = np.random.default_rng(seed)
    n_slots = n_out + n_scratch
    again = rng.integers(1, n_slots, n_extra) if n_slots > 1 else []
    children = list(rng.permutation(np.arange(1, n_slots))) + list(again)
    written = [0]
    parent, kind, origin, axis, dof, mul, off = [], [], [], [], [], [], []
    for ch in children:
        choices = [s for s in written if s != ch]
        parent.append(int(rng.choice(choices)))
        written.append(int(ch))
        k = int(rng.choice([0, 1, 1, 1, 2]))
        kind.append(k)
        o = np.eye(4)
        if rng.random() < 0.7:
            o[:3, :3] = _rotation(rng) if rng.random() < 0.5 else np.eye(3)
            o[:3, 3] = rng.uniform(-1, 1, 3)
        if rng.random() < 0.2:
            o[3] = rng.uniform(-1, 1, 4)  # the C core never reads it
        origin.append(o)
        pick = rng.random()
        if k == 0:
            a = np.zeros(3)
        elif pick < 0.7:
            a = FRAME_AXES[int(rng.integers(6))]
        else:
            a = rng.normal(size=3)
            a *= (1.0 if pick < 0.85 else rng.uniform(0.9, 1.1)) / np.linalg.norm(a)
        axis.append(a)
        dof.append(int(rng.integers(n_dof)))
        mul.append(float(rng.choice([1.0, -1.0, 0.5, rng.uniform(-2, 2)])))
        off.append(float(rng.choice([0.0, rng.uniform(-1, 1)])))
    return [
        np.array(parent, dtype=np.int64),
        np.array(children, dtype=np.int64),
        np.array(kind, dtype=np.int64),
        np.array(origin),
        np.array(axis),
        np.array(dof, dtype=np.int64),
        np.array(mul),
        np.array(off),
        n_slots,
        n_out,
        n_dof,
    ]


@settings(max_examples=60, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    n_out=st.integers(1, 14),
    n_scratch=st.integers(0, 3),
    n_extra=st.integers(0, 4),
    n_dof=st.integers(1, 6),
    n=st.integers(0, 40),
)
def test_random_programs_equal_the_c_core(
    seed: int, n_out: int, n_scratch: int, n_extra: int, n_dof: int, n: int
) -> None:
    kin_c = _c_core()
    args = _program(seed, n_out, n_scratch, n_extra, n_dof)
    tree_c, tree_py = kin_c.tree(*args), kin_py.tree(*args)
    qs = np.random.default_rng(seed + 1).uniform(-4.0, 4.0, (n, n_dof))
    got = kin_py.fk_batch(tree_py, qs)
    want = kin_c.fk_batch(tree_c, qs, None, False)
    np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-9)
    np.testing.assert_array_equal(got[:, :, 3], np.tile([0.0, 0.0, 0.0, 1.0], (n, n_out, 1)))
    for i in range(min(n, 3)):  # a row of the batch is the single call's bits
        np.testing.assert_array_equal(kin_py.fk(tree_py, qs[i]), got[i])


@settings(max_examples=25, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    n_out=st.integers(1, 14),
    n_scratch=st.integers(0, 3),
    n_extra=st.integers(0, 4),
    n=st.integers(32, 700),
)
def test_random_programs_in_steps_equal_the_c_core_and_the_single_call(
    seed: int, n_out: int, n_scratch: int, n_extra: int, n: int
) -> None:
    """A batch's steps (a plan: bodies' rows in body order, groups as strided views, a short
    last step) on random programs: the C core's poses, and every row the single call's bits."""
    kin_c = _c_core()
    args = _program(seed, n_out, n_scratch, n_extra, 3)
    tree_c, tree_py = kin_c.tree(*args), kin_py.tree(*args)
    qs = np.random.default_rng(seed + 2).uniform(-4.0, 4.0, (n, 3))
    got = kin_py.fk_batch(tree_py, qs)
    np.testing.assert_allclose(got, kin_c.fk_batch(tree_c, qs, None, False), rtol=1e-9, atol=1e-9)
    np.testing.assert_array_equal(got[:, :, 3], np.tile([0.0, 0.0, 0.0, 1.0], (n, n_out, 1)))
    for i in range(n):
        np.testing.assert_array_equal(kin_py.fk(tree_py, qs[i]), got[i])


def test_a_long_batch_across_the_steps_equals_the_c_core() -> None:
    kin_c = _c_core()
    args = _program(7, 12, 2, 3, 4)
    tree_c, tree_py = kin_c.tree(*args), kin_py.tree(*args)
    qs = np.random.default_rng(8).uniform(-4.0, 4.0, (1500, 4))  # several steps, a short last
    got = kin_py.fk_batch(tree_py, qs)
    np.testing.assert_allclose(got, kin_c.fk_batch(tree_c, qs, None, False), rtol=0, atol=1e-12)
    out = np.full_like(got, np.nan)  # into a caller's array: the same poses
    np.testing.assert_array_equal(kin_py.fk_batch(tree_py, qs, out, True), got)


@pytest.fixture(scope="module")
def solo() -> tuple[Kinematics, Kinematics, int, Any]:
    from robotspec.description.urdf import load_urdf

    world = load_urdf(erd_robots() / "solo_description" / "robots" / "solo12.urdf", meshes="keep")
    with using((kincore.CHOICE, _c_core())):
        c = Kinematics(world)
    with using((kincore.CHOICE, kin_py)):
        py = Kinematics(world)
    return c, py, len(world.degrees_of_freedom), world


@settings(max_examples=20, deadline=None)
@given(n=st.integers(0, 300), seed=st.integers(0, 2**16))
def test_solo12_batches_and_single_calls_equal_the_c_core(
    solo: tuple[Kinematics, Kinematics, int, Any], n: int, seed: int
) -> None:
    c, py, nd, world = solo
    qs = np.asarray(random_configurations(world, n, seed=seed), dtype=np.float64).reshape(n, nd)
    got = py.forward_batch(qs, threads=1)
    np.testing.assert_allclose(got, c.forward_batch(qs, threads=1), rtol=0, atol=1e-12)
    for i in range(min(n, 2)):
        np.testing.assert_array_equal(py.forward(qs[i]), got[i])
        np.testing.assert_allclose(py.forward(qs[i]), c.forward(qs[i]), rtol=0, atol=1e-12)


@pytest.fixture(scope="module")
def pr2_broad() -> tuple[Any, Any, Any, Any]:
    """The PR2's broad-phase table on both cores, and its kinematics (C)."""
    from robotspec import robots
    from robotspec.collision import SelfCollisionChecker

    kin_c = _c_core()
    robot = robots.PR2.load()
    checker = SelfCollisionChecker.from_robot(robot)
    c = checker._build()
    geoms = c.model.geometries
    args = (
        np.array([g.body_index for g in geoms], dtype=np.int64),
        np.array([g.body_T_geometry for g in geoms], dtype=np.float64).reshape(-1, 4, 4),
        np.array([g.aabb_center for g in geoms], dtype=np.float64).reshape(-1, 3),
        np.array([g.aabb_half for g in geoms], dtype=np.float64).reshape(-1, 3),
        c.pair_geom1,
        c.pair_geom2,
        len(robot.world.bodies),
    )
    table_c, table_py = kin_c.geoms(*args), kin_py.geoms(*args)
    return kin_c, table_c, table_py, checker


@settings(max_examples=25, deadline=None)
@given(
    n=st.integers(1, 40),
    seed=st.integers(0, 2**16),
    margin=st.sampled_from([0.0, 0.01, 0.05]),
    masked=st.booleans(),
)
def test_broad_phase_equals_the_c_core_bit_for_bit(
    pr2_broad: tuple[Any, Any, Any, Any], n: int, seed: int, margin: float, masked: bool
) -> None:
    """Same candidates, same geometry poses: the fallback's sums run in the C core's order."""
    kin_c, table_c, table_py, checker = pr2_broad
    world = checker.kinematics.world
    qs = np.asarray(random_configurations(world, n, seed=seed), dtype=np.float64)
    with using((kincore.CHOICE, kin_c)):
        bodies = Kinematics(world).forward_batch(qs, threads=1)
    mask = None
    if masked:
        mask = (np.random.default_rng(seed).random(len(table_py.g1)) < 0.7).astype(np.uint8)
    for poses in (bodies, bodies[0]):  # a batch, and one configuration (3-D)
        got = kin_py.broad(table_py, poses, margin, mask)
        want = kin_c.broad(table_c, poses, margin, mask)
        for a, b in zip(got, want, strict=True):
            np.testing.assert_array_equal(a, b)
