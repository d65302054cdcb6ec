"""The fallback mesh core's crossing proofs give coal's answer, never another (issue 34).

``_meshcore_py.apart`` answers CROSS for a mesh pair whose surfaces must meet (a piece of one
surface reaches inside the other, closed one and outside its box), and the narrow phase then
skips coal. Coal's mesh-mesh test reports surface contact only (a mesh wholly inside another is
free), so each proof is checked against coal itself: constructed boxes (nested, crossing, open),
random poses of two real meshes (hypothesis), and every candidate of random PR2 and Talos
configurations under their SRDF rules, where the proofs must also find some collisions.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robotspec.collision import (
    CollisionRules,
    SelfCollisionChecker,
    _crossing_py,
    random_configurations,
)
from robotspec.collision import _meshcore_py as mesh_py
from robotspec.collision.scan import APART_SLACK, place
from robotspec.description.srdf_reader import load_srdf
from robotspec.description.urdf import load_urdf

from .conftest import erd_robots

coal = pytest.importorskip("coal")
trimesh = pytest.importorskip("trimesh")

CROSS = 2


def _pose(t: tuple[float, float, float], rot: Any = None) -> np.ndarray:
    p = np.eye(4)
    if rot is not None:
        p[:3, :3] = rot
    p[:3, 3] = t
    return p


def _bvh(v: np.ndarray, f: np.ndarray) -> Any:
    m = coal.BVHModelOBBRSS()
    m.beginModel(len(f), len(v))
    m.addVertices(np.asarray(v, dtype=np.float64))
    m.addTriangles(np.asarray(f, dtype=np.int64))
    m.endModel()
    return m


def _coal_collides(a: Any, b: Any, pa: np.ndarray, pb: np.ndarray, margin: float = 0.0) -> bool:
    req, res = coal.CollisionRequest(), coal.CollisionResult()
    req.security_margin = margin
    ta, tb = coal.Transform3s(pa[:3, :3], pa[:3, 3]), coal.Transform3s(pb[:3, :3], pb[:3, 3])
    return bool(coal.collide(a, ta, b, tb, req, res))


def _proof(meshes: list[tuple[np.ndarray, np.ndarray]], pa: np.ndarray, pb: np.ndarray) -> int:
    """The fallback's code for geometry 0 at ``pa`` against geometry 1 at ``pb``."""
    s = mesh_py.mesh_set(meshes)
    poses = np.stack([pa, pb])[None]
    one = np.zeros(1, dtype=np.int64)
    code = mesh_py.apart(s, poses, one - 0, one, one, one + 1, APART_SLACK)
    return int(code[0])


def _box(size: float) -> tuple[np.ndarray, np.ndarray]:
    m = trimesh.creation.box((size, size, size))
    return np.asarray(m.vertices, dtype=np.float64), np.asarray(m.faces, dtype=np.int64)


def test_a_box_wholly_inside_another_is_free_and_not_proven() -> None:
    big, small = _box(1.0), _box(0.2)
    at = _pose((0.1, -0.05, 0.02))
    assert not _coal_collides(_bvh(*big), _bvh(*small), np.eye(4), at)
    assert _proof([big, small], np.eye(4), at) == 0
    assert _proof([small, big], at, np.eye(4)) == 0


def test_crossing_boxes_are_proven_both_ways() -> None:
    big, small = _box(1.0), _box(0.2)
    at = _pose((0.5, 0.0, 0.0))  # half the small box through the big one's face
    assert _coal_collides(_bvh(*big), _bvh(*small), np.eye(4), at)
    assert _proof([big, small], np.eye(4), at) == CROSS
    assert _proof([small, big], at, np.eye(4)) == CROSS


def test_an_open_mesh_gets_no_inside_and_two_open_meshes_are_never_proven() -> None:
    v, f = _box(1.0)
    open_big = (v, f[2:])  # one face (two triangles) removed
    assert not _crossing_py.stack([_crossing_py.prepare(*open_big)]).closed[0]
    small = _box(0.2)
    at = _pose((0.5, 0.0, 0.0))
    assert _coal_collides(_bvh(*open_big), _bvh(*small), np.eye(4), at)
    # The small box is closed, but no vertex of the open one lies inside it: not proven.
    assert _proof([open_big, small], np.eye(4), at) == 0
    sv, sf = small
    open_small = (sv, sf[2:])
    assert _coal_collides(_bvh(*open_big), _bvh(*open_small), np.eye(4), at)
    assert _proof([open_big, open_small], np.eye(4), at) == 0


def test_an_open_mesh_reaching_into_a_closed_one_is_proven() -> None:
    v, f = _box(0.2)
    open_small, big = (v, f[2:]), _box(1.0)
    at = _pose((0.5, 0.0, 0.0))
    assert _coal_collides(_bvh(*big), _bvh(*open_small), np.eye(4), at)
    assert _proof([big, open_small], np.eye(4), at) == CROSS
    assert _proof([open_small, big], at, np.eye(4)) == CROSS


def test_a_margin_beyond_the_clearance_proves_nothing() -> None:
    big, small = _box(1.0), _box(0.2)
    s = mesh_py.mesh_set([big, small])
    poses = np.stack([np.eye(4), _pose((0.5, 0.0, 0.0))])[None]
    one = np.zeros(1, dtype=np.int64)
    for eps, want in ((APART_SLACK, CROSS), (_crossing_py.CLEARANCE, 0), (0.05, 0)):
        assert mesh_py.apart(s, poses, one, one, one, one + 1, eps)[0] == want


# ------------------------------------------------------------------------------ real meshes
def _checker(name: str) -> SelfCollisionChecker:
    robots = erd_robots()
    if name == "pr2":
        urdf = robots / "pr2_description" / "urdf" / "pr2.urdf"
        srdf = robots / "pr2_description" / "srdf" / "pr2.srdf"
    else:
        urdf = robots / "talos_data" / "robots" / "talos_full_v2.urdf"
        srdf = robots / "talos_data" / "srdf" / "talos.srdf"
    world = load_urdf(Path(urdf))
    return SelfCollisionChecker(world, CollisionRules.for_world(world, srdf=load_srdf(srdf)))


Robot = tuple[str, SelfCollisionChecker, Any, object]


@pytest.fixture(scope="module", params=["pr2", "talos"])
def robot(request: pytest.FixtureRequest) -> Robot:
    checker = _checker(request.param)
    c = checker._build()
    meshes = mesh_py.mesh_set([g.triangles for g in c.model.geometries])
    return request.param, checker, c, meshes


def test_every_proof_on_random_configurations_is_a_coal_collision(robot: Robot) -> None:
    _, checker, c, meshes = robot
    qs = np.asarray(random_configurations(checker.world, 96, seed=34))
    rows, ks, poses = place(c, checker.kinematics, qs, 0.0, None)
    two = np.asarray(c.two_meshes, dtype=np.bool_)[ks]
    rows, ks = rows[two], ks[two]
    codes = mesh_py.apart(meshes, poses, rows, ks, c.pair_geom1, c.pair_geom2, APART_SLACK)
    scratch = checker._scratch(c)
    req, res = scratch.collision(0.0)
    tf = scratch.transforms
    collides = []
    for r, k in zip(rows.tolist(), ks.tolist(), strict=True):
        i, j = c.pair_geom1_list[k], c.pair_geom2_list[k]
        for g in (i, j):
            tf[g].setRotation(poses[r, g, :3, :3])
            tf[g].setTranslation(poses[r, g, :3, 3])
        res.clear()
        c.collide[k](tf[i], tf[j], req, res)
        collides.append(res.isCollision())
    hit = np.asarray(collides, dtype=np.bool_)
    proven = codes == CROSS
    assert set(np.unique(codes).tolist()) <= {0, CROSS}
    assert not (proven & ~hit).any(), "a proof coal does not confirm"
    assert proven.sum() >= hit.sum() // 5, (proven.sum(), hit.sum())  # the proofs pay


def test_collisions_batch_on_the_fallback_equals_coal_alone(
    robot: Robot, monkeypatch: pytest.MonkeyPatch
) -> None:
    from robotspec.accel import using
    from robotspec.collision import meshcore

    name, checker, _, _ = robot
    qs = np.asarray(random_configurations(checker.world, 200, seed=35))
    with using((meshcore.CHOICE, mesh_py)):
        fallback = _checker(name)
        got = fallback.collisions_batch(qs)
        anyhit = fallback.in_collision_batch(qs)
        found = fallback.ever_colliding(qs)
        monkeypatch.setattr(
            _crossing_py, "crossing", lambda s, p, r, *_: np.zeros(len(r), dtype=np.bool_)
        )
        coal_only = _checker(name)
        want = coal_only.collisions_batch(qs)
        want_found = coal_only.ever_colliding(qs)
    assert want.any()
    np.testing.assert_array_equal(got, want)
    np.testing.assert_array_equal(anyhit, want.any(axis=1))
    np.testing.assert_array_equal(found, want_found)


@pytest.fixture(scope="module")
def two_meshes() -> tuple[list[tuple[np.ndarray, np.ndarray]], list[Any]]:
    """Two closed PR2 meshes (upper arm, forearm) as the fallback and coal read them."""
    c = _checker("pr2")._build()
    by_body = {g.body: g for g in c.model.geometries}
    picked = [by_body["r_upper_arm_link"], by_body["r_forearm_link"]]
    meshes = [g.triangles for g in picked]
    assert all(m is not None for m in meshes)
    return meshes, [g.geometry for g in picked]  # type: ignore[misc]


def _random_pose(rng: np.random.Generator) -> np.ndarray:
    w = rng.normal(size=4)
    return _pose(
        tuple(rng.uniform(-0.25, 0.25, 3)), coal.Quaternion(*(w / np.linalg.norm(w))).matrix()
    )


def test_poses_of_two_real_meshes_prove_only_coal_collisions(
    two_meshes: tuple[list[tuple[np.ndarray, np.ndarray]], list[Any]],
) -> None:
    meshes, geoms = two_meshes
    s = mesh_py.mesh_set(meshes)
    rng = np.random.default_rng(34)
    n = 300
    poses = np.stack([np.stack([np.eye(4), _random_pose(rng)]) for _ in range(n)])
    zero = np.zeros(n, dtype=np.int64)
    codes = mesh_py.apart(s, poses, np.arange(n), zero, zero[:1], zero[:1] + 1, APART_SLACK)
    hit = np.array([_coal_collides(geoms[0], geoms[1], p[0], p[1]) for p in poses])
    proven = codes == CROSS
    assert not (proven & ~hit).any()
    assert proven.sum() >= hit.sum() // 4 > 0, (proven.sum(), hit.sum())


@settings(max_examples=150, deadline=None)
@given(
    t=st.tuples(*[st.floats(-0.25, 0.25) for _ in range(3)]),
    q=st.tuples(*[st.floats(-1.0, 1.0) for _ in range(4)]),
)
def test_random_poses_of_two_real_meshes(
    two_meshes: tuple[list[tuple[np.ndarray, np.ndarray]], list[Any]],
    t: tuple[float, float, float],
    q: tuple[float, float, float, float],
) -> None:
    meshes, geoms = two_meshes
    w = np.asarray(q)
    if np.linalg.norm(w) < 1e-3:
        w = np.array([1.0, 0.0, 0.0, 0.0])
    rot = coal.Quaternion(*(w / np.linalg.norm(w))).matrix()
    pb = _pose(t, rot)
    if _proof(meshes, np.eye(4), pb) == CROSS:
        assert _coal_collides(geoms[0], geoms[1], np.eye(4), pb)
