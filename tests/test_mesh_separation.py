"""The C proof that two meshes are apart (robotspec/collision/_meshcore.c) against coal.

A "proven apart" that coal would call a collision changes an answer, so the proof is checked
three ways: random triangle soups against coal's exact mesh distance (hypothesis), the real
meshes of the PR2's most nearly touching pairs against coal at configurations where they are
millimetres apart, and whole checkers with and without the proof on every pair of real robots.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import cast

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from robotspec.collision import (
    CollisionRules,
    SelfCollisionChecker,
    random_configurations,
)
from robotspec.model.kincore import accelerators_disabled
from robotspec.model.rotations import rpy_to_matrix
from tests.conftest import all_pairs_checker, erd_robots

coal = pytest.importorskip("coal")
if accelerators_disabled():
    pytest.skip(
        "about the C mesh core, which ROBOTSPEC_NO_ACCEL turns off", allow_module_level=True
    )
_meshcore = pytest.importorskip(
    "robotspec.collision._meshcore", reason="the C mesh core is not built (no compiler at install)"
)


def _bvh(vertices: np.ndarray, faces: np.ndarray) -> object:
    m = coal.BVHModelOBBRSS()
    m.beginModel(len(faces), len(vertices))
    m.addVertices(vertices)
    m.addTriangles(faces)
    m.endModel()
    return m


def _transform(pose: np.ndarray) -> object:
    t = coal.Transform3s()
    t.setRotation(pose[:3, :3])
    t.setTranslation(pose[:3, 3])
    return t


def _coal_distance(mesh_a: object, pose_a: np.ndarray, mesh_b: object, pose_b: np.ndarray) -> float:
    req, res = coal.DistanceRequest(), coal.DistanceResult()
    return float(coal.distance(mesh_a, _transform(pose_a), mesh_b, _transform(pose_b), req, res))


def _coal_collides(mesh_a: object, pose_a: np.ndarray, mesh_b: object, pose_b: np.ndarray) -> bool:
    req, res = coal.CollisionRequest(), coal.CollisionResult()
    coal.collide(mesh_a, _transform(pose_a), mesh_b, _transform(pose_b), req, res)
    return bool(res.isCollision())


def _apart(
    meshes: list[tuple[np.ndarray, np.ndarray]], poses: np.ndarray, eps: float
) -> np.ndarray:
    """apart() of geometry 0 against geometry 1 for every sample of ``poses`` (n, 2, 4, 4)."""
    n = len(poses)
    return np.asarray(
        _meshcore.apart(
            _meshcore.mesh_set(meshes),
            poses,
            np.arange(n, dtype=np.int64),
            np.zeros(n, dtype=np.int64),
            np.array([0], dtype=np.int64),
            np.array([1], dtype=np.int64),
            eps,
        )
    )


def _pose(xyz: tuple[float, float, float], rpy: tuple[float, float, float]) -> np.ndarray:
    pose = np.eye(4)
    pose[:3, :3] = rpy_to_matrix(*rpy)
    pose[:3, 3] = xyz
    return pose


coords = st.floats(-0.1, 0.1, allow_nan=False, allow_infinity=False)
points = st.tuples(coords, coords, coords)
soups = st.lists(st.tuples(points, points, points), min_size=1, max_size=12)
angles = st.floats(-np.pi, np.pi, allow_nan=False)
offsets = st.floats(-0.25, 0.25, allow_nan=False)


@given(
    soups,
    soups,
    st.tuples(offsets, offsets, offsets),
    st.tuples(angles, angles, angles),
    st.sampled_from([1e-5, 1e-3, 0.02]),
)
def test_proven_apart_soups_are_apart_for_coal(
    a: list[tuple[tuple[float, ...], ...]],
    b: list[tuple[tuple[float, ...], ...]],
    xyz: tuple[float, float, float],
    rpy: tuple[float, float, float],
    eps: float,
) -> None:
    va = np.array(a, dtype=np.float64).reshape(-1, 3)
    vb = np.array(b, dtype=np.float64).reshape(-1, 3)
    fa = np.arange(len(va), dtype=np.int64).reshape(-1, 3)
    fb = np.arange(len(vb), dtype=np.int64).reshape(-1, 3)
    pose_a, pose_b = _pose((0.01, -0.02, 0.03), (0.3, -0.2, 0.1)), _pose(xyz, rpy)
    poses = np.array([[pose_a, pose_b]])
    proof = int(_apart([(va, fa), (vb, fb)], poses, eps)[0])
    one = _meshcore.apart_one(_meshcore.mesh_set([(va, fa), (vb, fb)]), poses, 0, 0, 1, eps)
    assert one == proof  # the one-by-one entry point gives the batch's answer
    ma, mb = _bvh(va, fa), _bvh(vb, fb)
    if proof == 1:  # apart by more than eps
        assert _coal_distance(ma, pose_a, mb, pose_b) > eps - 1e-9
        assert not _coal_collides(ma, pose_a, mb, pose_b)
    elif proof == 2:  # two triangles cross
        assert _coal_collides(ma, pose_a, mb, pose_b)


@pytest.fixture(scope="module")
def pr2_checker() -> SelfCollisionChecker:
    return cast(SelfCollisionChecker, all_pairs_checker("pr2"))


@pytest.mark.parametrize(
    "pair",
    [
        ("r_forearm_link", "r_gripper_palm_link"),  # 0.4 mm at their closest
        ("r_shoulder_lift_link", "r_upper_arm_link"),  # a sleeve: 4.5 mm all round
        ("r_shoulder_pan_link", "r_upper_arm_roll_link"),  # touching now and then
    ],
)
def test_nearly_touching_real_meshes_agree_with_coal(
    pr2_checker: SelfCollisionChecker, pair: tuple[str, str]
) -> None:
    checker = pr2_checker
    compiled = checker._build()
    geoms = compiled.model.geometries
    (i,) = [k for k, g in enumerate(geoms) if g.body == pair[0]]
    (j,) = [k for k, g in enumerate(geoms) if g.body == pair[1]]
    a, b = geoms[i], geoms[j]
    assert a.triangles is not None and b.triangles is not None
    qs = random_configurations(checker.world, 150, seed=7)
    bodies = checker.kinematics.forward_batch(qs)
    pose_a = bodies[:, a.body_index] @ a.body_T_geometry
    pose_b = bodies[:, b.body_index] @ b.body_T_geometry
    poses = np.stack([pose_a, pose_b], axis=1)
    for eps in (1e-5, 2e-3):
        proven = _apart([a.triangles, b.triangles], poses, eps)
        assert proven.dtype == np.uint8
        for s in range(len(qs)):
            d = _coal_distance(a.geometry, pose_a[s], b.geometry, pose_b[s])
            hit = _coal_collides(a.geometry, pose_a[s], b.geometry, pose_b[s])
            if proven[s] == 1:
                assert d > eps - 1e-9 and not hit, (pair, s, d)
            elif proven[s] == 2:
                assert hit, (pair, s, d)
            # Room to spare is proven: the proof is useful, not only safe.
            if d > 2 * eps + 5e-3:
                assert proven[s] == 1, (pair, s, d)


def _without_proof(checker: SelfCollisionChecker) -> SelfCollisionChecker:
    twin = SelfCollisionChecker(checker.world, checker.rules, pairs=checker.active_pairs)
    compiled = checker._build()
    twin._compiled = dataclasses.replace(
        compiled, meshes=None, two_meshes=[False] * len(compiled.two_meshes)
    )
    return twin


@pytest.mark.parametrize("margin", [0.0, 0.02])
def test_checker_answers_are_coals_on_every_pr2_pair(
    pr2_checker: SelfCollisionChecker, margin: float
) -> None:
    qs = random_configurations(pr2_checker.world, 120, seed=3)
    twin = _without_proof(pr2_checker)
    ours = pr2_checker.collisions_batch(qs, margin=margin)  # proofs in one C call per block
    theirs = twin.collisions_batch(qs, margin=margin)
    assert ours.any() and not ours.all()
    np.testing.assert_array_equal(ours, theirs)
    # One configuration at a time, and "any hit": proofs one candidate at a time.
    for q in qs[:25]:
        assert pr2_checker.colliding_pairs(q, margin=margin) == twin.colliding_pairs(
            q, margin=margin
        )
    np.testing.assert_array_equal(
        pr2_checker.in_collision_batch(qs, margin=margin),
        twin.in_collision_batch(qs, margin=margin),
    )


def test_checker_answers_are_coals_on_tiago() -> None:
    checker = cast(SelfCollisionChecker, all_pairs_checker("tiago"))
    qs = random_configurations(checker.world, 40, seed=5)
    np.testing.assert_array_equal(
        checker.collisions_batch(qs), _without_proof(checker).collisions_batch(qs)
    )


def test_crossing_triangles_are_proven_and_touching_ones_left_to_coal() -> None:
    a = (np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]), np.array([[0, 1, 2]]))
    b = (np.array([[0.2, 0.2, -0.5], [0.35, 0.25, 0.5], [0.15, 0.3, 0.5]]), np.array([[0, 1, 2]]))
    poses = np.array([[np.eye(4), np.eye(4)]])
    s = _meshcore.mesh_set([a, b])
    assert _meshcore.apart_one(s, poses, 0, 0, 1, 1e-5) == 2  # b pierces a
    touching = (np.array([[0.0, 0, 0], [-1, 0, 0.5], [0, -1, 0.5]]), np.array([[0, 1, 2]]))
    s = _meshcore.mesh_set([a, touching])  # one shared corner: coal's to call
    assert _meshcore.apart_one(s, poses, 0, 0, 1, 1e-5) == 0
    far = poses.copy()
    far[0, 1, 2, 3] = 1.0
    s = _meshcore.mesh_set([a, b])
    assert _meshcore.apart_one(s, far, 0, 0, 1, 1e-5) == 1


def test_bad_meshes_and_arguments_are_refused() -> None:
    v = np.eye(3)
    with pytest.raises(ValueError, match="out of range"):
        _meshcore.mesh_set([(v, np.array([[0, 1, 3]]))])
    with pytest.raises(ValueError, match="not finite"):
        _meshcore.mesh_set(
            [(np.array([[0, 0, np.nan], [1, 0, 0], [0, 1, 0]]), np.array([[0, 1, 2]]))]
        )
    with pytest.raises(ValueError, match="triangles"):
        _meshcore.mesh_set([(v, np.zeros((0, 3), dtype=np.int64))])
    meshes = [(v, np.array([[0, 1, 2]])), (v, np.array([[0, 1, 2]]))]
    poses = np.array([[np.eye(4), np.eye(4)]])
    with pytest.raises(ValueError, match="eps"):
        _apart(meshes, poses, 0.0)
    with pytest.raises(ValueError, match="eps"):
        _apart(meshes, poses, float("nan"))
    with pytest.raises(ValueError, match="shape"):
        _apart(meshes, np.zeros((1, 3, 4, 4)), 1e-5)
    s = _meshcore.mesh_set(meshes)
    one = np.array([0], dtype=np.int64)
    with pytest.raises(ValueError, match="out of range"):
        _meshcore.apart(s, poses, np.array([1]), np.array([0]), one, one + 1, 1e-5)
    # A geometry that is not a mesh (None) is never proven apart: coal decides.
    s = _meshcore.mesh_set([meshes[0], None])
    far = np.array([[np.eye(4), _pose((5.0, 0.0, 0.0), (0.0, 0.0, 0.0))]])
    assert _meshcore.apart(s, far, np.array([0]), np.array([0]), one, one + 1, 1e-5)[0] == 0
    assert _apart(meshes, far, 1e-5)[0] == 1


def test_a_mesh_scaled_past_float_range_is_a_located_error(tmp_path: Path) -> None:
    import trimesh

    from robotspec.description.urdf import load_urdf
    from robotspec.errors import CollisionError

    # Scales are bounded (at most 1e6 each), so the overflow comes from the vertices: an OBJ
    # holds float64 coordinates, 1e305 of them times 1e6 is past the float range.
    (tmp_path / "big.obj").write_text(
        "v 0 0 0\nv 1e305 0 0\nv 0 1e305 0\nv 0 0 1e305\nf 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n"
    )
    trimesh.creation.box(extents=(0.1, 0.1, 0.1)).export(str(tmp_path / "cube.stl"))
    (tmp_path / "two.urdf").write_text(
        '<robot name="two">'
        '<link name="a"><collision><geometry>'
        '<mesh filename="big.obj" scale="1e6 1e6 1e6"/></geometry></collision></link>'
        '<link name="b"><collision><geometry><mesh filename="cube.stl"/></geometry></collision>'
        '</link><joint name="j" type="revolute"><parent link="a"/><child link="b"/>'
        '<origin xyz="3 0 0"/><axis xyz="0 0 1"/>'
        '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>'
    )
    world = load_urdf(tmp_path / "two.urdf")
    checker = SelfCollisionChecker(world, CollisionRules(bodies=("a", "b")), pairs=[("a", "b")])
    with pytest.raises(CollisionError, match=r"link 'a'.*beyond the float range") as info:
        checker.in_collision(world.configuration())
    assert info.value.file is not None and info.value.file.endswith("big.obj")


def _without_hulls(checker: SelfCollisionChecker) -> SelfCollisionChecker:
    twin = SelfCollisionChecker(checker.world, checker.rules, pairs=checker.active_pairs)
    twin._compiled = checker._build()
    twin._hull_fns = (None,) * len(twin._compiled.pair_of)
    return twin


@pytest.mark.parametrize("name", ["pr2", "tiago", "b1_ur5_allegro"])
def test_hull_first_distances_are_coals_mesh_distances(name: str) -> None:
    from robotspec.compiler import compile_robot

    erd_robots()
    robot = compile_robot(name)
    checker = SelfCollisionChecker.from_robot(robot)
    compiled = checker._build()
    hulls = checker._hull_functors(compiled)
    with_mesh = [g.triangles is not None for g in compiled.model.geometries]
    pairs = zip(compiled.pair_geom1_list, compiled.pair_geom2_list, strict=True)
    meshy = [k for k, (i, j) in enumerate(pairs) if with_mesh[i] or with_mesh[j]]
    assert meshy and sum(hulls[k] is not None for k in meshy) >= 0.9 * len(meshy)
    twin = _without_hulls(checker)
    for q in random_configurations(robot.world, 3, seed=13):
        ours, theirs = checker.distances(q), twin.distances(q)
        got = np.array([d.distance for d in ours])
        want = np.array([d.distance for d in theirs])
        # Mesh to mesh both are exact; against a curved primitive coal's GJK stops within 1e-6.
        np.testing.assert_allclose(got, want, atol=2e-6, rtol=0)
        for d in ours:
            if d.distance > 1e-5:  # closest points as far apart as the distance says
                gap = float(np.linalg.norm(np.subtract(d.point1, d.point2)))
                assert gap == pytest.approx(d.distance, abs=1e-8)


def test_points_on_a_mesh_are_told_from_points_off_it() -> None:
    v = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    f = np.array([[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]])  # a tetrahedron's surface
    s = _meshcore.mesh_set([(v, f)])
    pose = _pose((1.0, 2.0, 3.0), (0.4, -0.3, 1.2))
    poses = np.array([[pose]])

    def world(p: list[float]) -> np.ndarray:
        return np.asarray(pose[:3, :3] @ np.asarray(p) + pose[:3, 3])

    for p in ([0.0, 0, 0], [0.25, 0.25, 0], [1 / 3, 1 / 3, 1 / 3], [0.5, 0, 0.5]):
        assert _meshcore.on_surface(s, poses, 0, 0, world(p), 1e-9), p
    for p in ([0.1, 0.1, 0.1], [0.5, 0.5, 0.5], [0.25, 0.25, 1e-6]):  # inside, outside, just off
        assert not _meshcore.on_surface(s, poses, 0, 0, world(p), 1e-9), p
    with pytest.raises(ValueError, match="wrong shape"):
        _meshcore.on_surface(s, poses, 0, 0, np.zeros(2), 1e-9)
    with pytest.raises(ValueError, match="out of range"):
        _meshcore.on_surface(s, poses, 1, 0, np.zeros(3), 1e-9)
