"""The narrow phase's C walk gives the answers of the Python walk it replaced (issue 34).

``_meshcore.walk`` proves a whole block of broad-phase candidates in one C call without the GIL
and leaves coal only what it cannot prove; before it, Python walked the candidates one by one
(or in waves) between C calls, and it still does where the mesh core has no walk (the numpy
fallback). Both ways must give every answer alike, bit for bit: each query below runs with the C
core and with the same core stripped of ``walk``, on real robots (their own SRDF rules), random
configurations (more than one 512-sample block), with and without a margin and a pair mask.
The walk's own argument checks close the file: a wrong array is an error, never a misread.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType, SimpleNamespace
from typing import Any

import numpy as np
import pytest

from robotspec.accel import using
from robotspec.collision import (
    CollisionRules,
    SelfCollisionChecker,
    meshcore,
    random_configurations,
)
from robotspec.description.srdf_reader import load_srdf
from robotspec.description.urdf import load_urdf
from robotspec.errors import CollisionError, KinematicsError
from robotspec.files.packages import PackageResolver

from .conftest import erd_robots

#: Samples per robot: more than one block of the batch queries.
SAMPLES = 700


def _compiled_core() -> ModuleType:
    if not meshcore.accelerated():
        pytest.skip("the C mesh core is not built (or ROBOTSPEC_NO_ACCEL is set)")
    return meshcore.core()


def _without_walk(core: ModuleType) -> Any:
    """The C core's other entry points, with no walk: the checker then walks in Python."""
    names = ("mesh_set", "apart", "apart_one", "on_surface", "INTERFACE")
    return SimpleNamespace(__name__=core.__name__, **{n: getattr(core, n) for n in names})


def _checker(urdf: Path, srdf: Path) -> SelfCollisionChecker:
    world = load_urdf(urdf)
    return SelfCollisionChecker(world, CollisionRules.for_world(world, srdf=load_srdf(srdf)))


@pytest.fixture(scope="module", params=["pr2", "talos"])
def robot_files(request: pytest.FixtureRequest) -> tuple[Path, Path]:
    robots = erd_robots()
    if request.param == "pr2":
        d = robots / "pr2_description"
        return d / "urdf" / "pr2.urdf", d / "srdf" / "pr2.srdf"
    d = robots / "talos_data"
    return d / "robots" / "talos_full_v2.urdf", d / "srdf" / "talos.srdf"


def _answers(checker: SelfCollisionChecker, qs: np.ndarray) -> Iterator[tuple[str, Any]]:
    mask = np.arange(len(checker.active_pairs)) % 3 != 0
    yield "all pairs", checker.collisions_batch(qs)
    yield "all pairs, margin", checker.collisions_batch(qs, margin=0.01)
    yield "all pairs, mask", checker.collisions_batch(qs, pair_mask=mask)
    yield "any hit", checker.in_collision_batch(qs)
    yield "any hit, margin", checker.in_collision_batch(qs, margin=0.01)
    yield "any hit, 2 threads", checker.in_collision_batch(qs, threads=2)
    yield "ever", checker.ever_colliding(qs)
    yield "ever, mask", checker.ever_colliding(qs, pair_mask=mask)
    yield "single", [checker.in_collision(q) for q in qs[:60]]
    yield "single, margin", [checker.in_collision(q, margin=0.02) for q in qs[:60]]


def test_the_walk_answers_as_the_python_walk(robot_files: tuple[Path, Path]) -> None:
    core = _compiled_core()
    qs = random_configurations(load_urdf(robot_files[0]), SAMPLES, seed=11)
    with_walk = dict(_answers(_checker(*robot_files), qs))
    with using((meshcore.CHOICE, _without_walk(core))):
        python = dict(_answers(_checker(*robot_files), qs))
    hits = with_walk["all pairs"].any(axis=1)
    assert 0 < hits.sum() < SAMPLES, "the samples must mix free and colliding"
    for name, answer in with_walk.items():
        np.testing.assert_array_equal(answer, python[name], err_msg=name)
    np.testing.assert_array_equal(with_walk["any hit"], hits)
    np.testing.assert_array_equal(with_walk["ever"], with_walk["all pairs"].any(axis=0))


def test_touching_meshes_go_to_coal_row_by_row() -> None:
    """Every body pair of the Z1 arm, no rules: adjacent meshes touch, so proofs leave them to coal.

    An any-hit row then stops at its first candidate left to coal and is walked on only when
    coal finds it free (proving the rest of the row first cost 10-60 times coal's answer); the
    answers stay coal's alone (the checker without its mesh proofs), and the walk is resumed.
    """
    core = _compiled_core()
    urdf = erd_robots() / "z1_description" / "urdf" / "z1.urdf"
    world = load_urdf(urdf, resolver=PackageResolver.create(urdf))
    names = tuple(b.name for b in world.bodies if b.collisions)
    pairs = [(a, b) for i, a in enumerate(names) for b in names[i + 1 :]]
    ours = SelfCollisionChecker(world, CollisionRules(bodies=names), pairs=pairs)
    coal_only = SelfCollisionChecker(world, CollisionRules(bodies=names), pairs=pairs)
    built = ours._build()
    coal_only._compiled = dataclasses.replace(
        built, meshes=None, two_meshes=[False] * len(built.two_meshes)
    )
    calls = []

    def counted(*args: Any) -> Any:
        calls.append(len(args[2]))
        return core.walk(*args)

    spy = SimpleNamespace(**{n: getattr(core, n) for n in dir(core) if not n.startswith("__")})
    spy.__name__, spy.walk = core.__name__, counted
    qs = random_configurations(world, 300, seed=5)
    with using((meshcore.CHOICE, spy)):
        anyhit = ours.in_collision_batch(qs)  # one block: one walk, then the rows coal freed
        assert len(calls) > 1, "no row was walked on after coal"
        single = [ours.in_collision(q, margin=0.005) for q in qs[:40]]
        every = ours.collisions_batch(qs)
    np.testing.assert_array_equal(anyhit, coal_only.in_collision_batch(qs))
    assert single == [coal_only.in_collision(q, margin=0.005) for q in qs[:40]]
    np.testing.assert_array_equal(every, coal_only.collisions_batch(qs))


def test_a_single_query_keeps_every_check(robot_files: tuple[Path, Path]) -> None:
    """The single query's short path refuses what every query refuses, with the same words."""
    checker = _checker(*robot_files)
    q = np.zeros(len(checker.world.degrees_of_freedom))
    bad = q.copy()
    bad[2] = np.nan
    with pytest.raises(KinematicsError, match=r"NaN or infinite values \(nan at index 2\)"):
        checker.in_collision(bad)
    bad[2] = np.inf
    with pytest.raises(KinematicsError, match=r"\(inf at index 2\)"):
        checker.in_collision(bad)
    with pytest.raises(KinematicsError, match="in_collision_batch"):
        checker.in_collision(q[None, :])
    with pytest.raises(KinematicsError, match=r"got \(3,\)"):
        checker.in_collision(q[:3])
    with pytest.raises(KinematicsError, match="dtype complex128"):
        checker.in_collision(q.astype(np.complex128))
    with pytest.raises(CollisionError, match="margin must be finite, got nan"):
        checker.in_collision(q, margin=float("nan"))
    with pytest.raises(CollisionError, match="margin must be >= 0, got -0.1"):
        checker.in_collision(q, margin=-0.1)
    assert checker.in_collision(q.tolist()) == checker.in_collision(q)
    assert checker.in_collision(q[::1].astype(np.float32)) == checker.in_collision(q)


# ------------------------------------------------------------------------- argument checks
def _walk_args(**change: Any) -> tuple[Any, list[Any]]:
    """A valid walk over two unit tetrahedra one metre apart, with ``change`` applied."""
    core = _compiled_core()
    v = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    f = np.array([[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]])
    poses = np.tile(np.eye(4), (1, 2, 1, 1))
    poses[0, 1, 0, 3] = 3.0
    args = {
        "meshes": core.mesh_set([(v, f), (v, f)]),
        "poses": poses,
        "rows": np.zeros(1, dtype=np.int64),
        "pairs": np.zeros(1, dtype=np.int64),
        "g1": np.zeros(1, dtype=np.int64),
        "g2": np.ones(1, dtype=np.int64),
        "owner": np.zeros(1, dtype=np.int64),
        "found": np.zeros(1, dtype=np.uint8),
        "eps": 1e-5,
        "mode": 0,
    }
    args.update(change)
    return core, list(args.values())


def test_walk_answers_valid_arguments() -> None:
    core, args = _walk_args()
    rows, pairs, left = core.walk(*args)
    assert (rows.tolist(), pairs.tolist(), left.tolist()) == ([], [], [])  # proven apart
    c, s = np.cos(0.5), np.sin(0.5)  # turned about z and moved into the first: they cross
    args[1][0, 1] = [[c, -s, 0, 0.2], [s, c, 0, 0.1], [0, 0, 1, 0.1], [0, 0, 0, 1]]
    rows, pairs, left = core.walk(*args)
    assert (rows.tolist(), pairs.tolist(), left.tolist()) == ([0], [0], [])
    found = args[7]
    core.walk(*args[:9], 2)  # WALK_DROP_FOUND marks the body pair found ...
    assert found.tolist() == [1]
    assert [a.tolist() for a in core.walk(*args[:9], 2)] == [[], [], []]  # ... and skips it


READONLY = np.zeros(1, dtype=np.uint8)
READONLY.flags.writeable = False


@pytest.mark.parametrize(
    ("change", "kind", "match"),
    [
        ({"meshes": object()}, TypeError, "expected a mesh set"),
        ({"poses": [[np.eye(4)] * 2]}, TypeError, "poses must be a float64 numpy array"),
        ({"poses": np.tile(np.eye(4), (1, 3, 1, 1))}, ValueError, "poses of the wrong shape"),
        ({"rows": np.zeros(1)}, TypeError, "rows must be a C-contiguous 1-D int64"),
        ({"rows": [0]}, TypeError, "rows must be a C-contiguous 1-D int64"),
        ({"pairs": np.zeros((1, 1), dtype=np.int64)}, TypeError, "pairs must be"),
        ({"owner": np.zeros(1, dtype=np.int32)}, TypeError, "owner must be"),
        ({"found": np.zeros(1, dtype=bool)}, TypeError, "found must be a C-contiguous 1-D uint8"),
        ({"found": READONLY}, ValueError, "found must be writeable"),
        ({"eps": 0.0}, ValueError, "eps must be finite and >= 1e-9"),
        ({"eps": np.nan}, ValueError, "eps must be finite and >= 1e-9"),
        ({"mode": 3}, ValueError, "mode must be 0, 1 or 2"),
        ({"rows": np.zeros(2, dtype=np.int64)}, ValueError, "arrays of the wrong shape"),
        ({"g2": np.ones(2, dtype=np.int64)}, ValueError, "arrays of the wrong shape"),
        ({"g2": np.full(1, 2, dtype=np.int64)}, ValueError, "geometry pair is out of range"),
        ({"owner": np.ones(1, dtype=np.int64)}, ValueError, "geometry pair is out of range"),
        ({"rows": np.ones(1, dtype=np.int64)}, ValueError, "out of range or out of row order"),
        ({"pairs": np.ones(1, dtype=np.int64)}, ValueError, "out of range or out of row order"),
    ],
    ids=lambda x: str(x)[:40] if not isinstance(x, dict) else next(iter(x)),
)
def test_walk_refuses_bad_arguments(change: dict[str, Any], kind: type, match: str) -> None:
    core, args = _walk_args(**change)
    with pytest.raises(kind, match=match):
        core.walk(*args)


def test_walk_refuses_rows_out_of_order() -> None:
    core, args = _walk_args(
        poses=np.tile(np.eye(4), (2, 2, 1, 1)),
        rows=np.array([1, 0], dtype=np.int64),
        pairs=np.zeros(2, dtype=np.int64),
    )
    with pytest.raises(ValueError, match="out of row order"):
        core.walk(*args)
