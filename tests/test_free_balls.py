"""Free balls (robotspec/collision/free_balls.py) leave every answer as coal gives it (issue 34).

The fallback's "Never" pass drops a mesh pair's candidate when a ball (a coal distance at a
nearby relative pose) proves it apart. Two things are checked on real robots and meshes: the
collision matrix is the same, pair for pair and reason for reason (with counts), with the balls,
without them, and on the C core (PR2 and Talos, more than one block of samples); and on random
relative poses of two real meshes, a pose a ball covers is one coal finds apart by more than the
checker's slack, and not colliding (hypothesis).
"""

from __future__ import annotations

from collections.abc import Iterator
from types import ModuleType
from typing import Any

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from robotspec.accel import using
from robotspec.collision import _meshcore_py, free_balls, meshcore
from robotspec.collision.matrix import CollisionMatrix, generate_collision_matrix
from robotspec.collision.scan import APART_SLACK
from robotspec.collision.shapes import build_geometry_model, import_coal
from robotspec.compiler import compile_robot
from robotspec.description.urdf import load_urdf
from robotspec.model.kinematics import Kinematics
from robotspec.model.world import World

from .conftest import erd_robots

#: Samples: two blocks of the "Never" pass, so balls made in one serve the next.
SAMPLES = 700


def _world(name: str) -> World:
    robots = erd_robots()
    if name == "talos":
        return load_urdf(robots / "talos_data" / "robots" / "talos_full_v2.urdf")
    world: World = compile_robot(name).world
    return world


def _matrix(world: World, core: ModuleType) -> CollisionMatrix:
    with using((meshcore.CHOICE, core)):
        return generate_collision_matrix(world, samples=SAMPLES, seed=5, processes=1)


def _entries(m: CollisionMatrix) -> tuple[Any, ...]:
    return m.disabled, m.checked, m.first_collision


@pytest.fixture(scope="module", params=["pr2", "talos"])
def world(request: pytest.FixtureRequest) -> World:
    return _world(request.param)


@pytest.fixture
def dropped(monkeypatch: pytest.MonkeyPatch) -> Iterator[list[int]]:
    """Counts the candidates the balls (and the sift's own coal calls) took from the walk."""
    counts: list[int] = []
    real = free_balls.sift

    def counting(*args: Any) -> Any:
        keep = real(*args)
        counts.append(int((~keep).sum()))
        return keep

    monkeypatch.setattr(free_balls, "sift", counting)
    yield counts


def test_the_matrix_is_the_same_with_balls_without_and_on_the_c_core(
    world: World, dropped: list[int], monkeypatch: pytest.MonkeyPatch
) -> None:
    with_balls = _matrix(world, _meshcore_py)
    assert sum(dropped) > 0, "the balls were not used"
    if meshcore.accelerated():
        assert _entries(_matrix(world, meshcore.core())) == _entries(with_balls)
    monkeypatch.setattr(free_balls, "sift", lambda *a: np.ones(len(a[4]), dtype=np.bool_))
    assert _entries(_matrix(world, _meshcore_py)) == _entries(with_balls)


class _Meshes:
    """The PR2's right shoulder lift and upper arm meshes (they nest 4.5 mm apart)."""

    def __init__(self) -> None:
        world = _world("pr2")
        a, b = "r_shoulder_lift_link", "r_upper_arm_link"
        model = build_geometry_model(world, [a, b])
        ga, gb = (next(g for g in model.geometries if g.body == n) for n in (a, b))
        q = world.configuration()
        poses = Kinematics(world).forward(q)
        # b's geometry frame in a's geometry frame, at the default configuration
        pa = poses[ga.body_index] @ ga.body_T_geometry
        pb = poses[gb.body_index] @ gb.body_T_geometry
        self.rel = np.linalg.inv(pa) @ pb
        assert ga.triangles is not None and gb.triangles is not None
        self.corners = (
            free_balls.box_corners(ga.triangles[0]),
            free_balls.box_corners(gb.triangles[0]),
        )
        coal = import_coal()
        self.coal = coal
        self.model = model  # coal's functors below hold its geometries by address
        self.distance = coal.ComputeDistance(ga.geometry, gb.geometry)
        self.collide = coal.ComputeCollision(ga.geometry, gb.geometry)

    def points(self, rel: np.ndarray) -> np.ndarray:
        """(1, 16, 3): the boxes' corners at relative pose ``rel`` (a at the origin)."""
        return free_balls.relative_corners(np.eye(4)[None], rel[None], *self.corners)

    def apart(self, rel: np.ndarray) -> tuple[float, bool]:
        """Coal's distance and collision answer with b at ``rel`` in a's frame."""
        one = self.coal.Transform3s()
        tf = self.coal.Transform3s(rel[:3, :3], rel[:3, 3])
        res = self.coal.DistanceResult()
        self.distance(one, tf, self.coal.DistanceRequest(), res)
        hit = self.coal.CollisionResult()
        self.collide(one, tf, self.coal.CollisionRequest(), hit)
        return float(res.min_distance), bool(hit.isCollision())


@pytest.fixture(scope="module")
def meshes() -> _Meshes:
    return _Meshes()


def _moved(rel: np.ndarray, axis: list[float], angle: float, shift: list[float]) -> np.ndarray:
    """``rel`` turned by ``angle`` about ``axis`` (through b's origin) and shifted."""
    k = np.asarray(axis) / np.linalg.norm(axis)
    cross = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    turn = np.eye(3) + np.sin(angle) * cross + (1 - np.cos(angle)) * cross @ cross
    out = rel.copy()
    out[:3, :3] = rel[:3, :3] @ turn
    out[:3, 3] += shift
    return out


def test_corners_are_the_boxes_moved_by_the_relative_pose(meshes: _Meshes) -> None:
    rel = _moved(meshes.rel, [1.0, 2.0, 3.0], 0.7, [0.01, -0.02, 0.03])
    ca, cb = meshes.corners
    pts = meshes.points(rel)[0]
    np.testing.assert_allclose(pts[:8], cb @ rel[:3, :3].T + rel[:3, 3], atol=1e-15)
    inv = np.linalg.inv(rel)
    np.testing.assert_allclose(pts[8:], ca @ inv[:3, :3].T + inv[:3, 3], atol=1e-15)


AXIS = st.lists(st.floats(-1.0, 1.0), min_size=3, max_size=3).filter(
    lambda v: float(np.linalg.norm(v)) > 0.1
)


def _shift(size: float) -> st.SearchStrategy[list[float]]:
    return st.lists(st.floats(-size, size), min_size=3, max_size=3)


# The ball's pose: the meshes' own (4.5 mm apart) moved by up to 5 mrad and 1 mm; the pose
# tested: that moved by up to 20 mrad and 3 mm (about two thirds are covered).
@given(AXIS, st.floats(-0.005, 0.005), _shift(0.001), AXIS, st.floats(-0.02, 0.02), _shift(0.003))
def test_a_pose_a_ball_covers_is_apart_by_coal(
    meshes: _Meshes,
    axis0: list[float],
    angle0: float,
    shift0: list[float],
    axis: list[float],
    angle: float,
    shift: list[float],
) -> None:
    eps = APART_SLACK
    ball = _moved(meshes.rel, axis0, angle0, shift0)
    d, _ = meshes.apart(ball)
    near = _moved(ball, axis, angle, shift)
    pts, at = meshes.points(near), meshes.points(ball)
    moved = np.linalg.norm(pts[0] - at[0], axis=1)
    delta = min(moved[:8].max(), moved[8:].max())  # the bound: no point of a mesh moved more
    d_near, hit_near = meshes.apart(near)
    if d - delta > 0.0:
        assert d_near >= d - delta - 1e-9
    covered = free_balls.ball_covers(
        pts, free_balls.box_centres(pts), at, free_balls.box_centres(at), np.array([d]), eps
    )[0, 0]
    assert covered == (d - delta > eps)
    if covered:
        assert d_near > eps and not hit_near


def test_the_ball_covers_its_own_pose_and_not_a_far_one(meshes: _Meshes) -> None:
    d, hit = meshes.apart(meshes.rel)
    assert d > 0.004 and not hit
    at = meshes.points(meshes.rel)
    far = meshes.points(_moved(meshes.rel, [0.0, 0.0, 1.0], 0.5, [0.0, 0.0, 0.0]))
    centres = free_balls.box_centres
    both = np.concatenate([at, far])
    covered = free_balls.ball_covers(both, centres(both), at, centres(at), np.array([d]), 1e-5)
    assert covered[:, 0].tolist() == [True, False]


def test_a_pairs_balls_grow_without_losing_one() -> None:
    pair = free_balls._Pair()
    rng = np.random.default_rng(0)
    corners = rng.normal(size=(40, 16, 3))
    for n in range(40):
        pair.add(corners[n], free_balls.box_centres(corners[n : n + 1])[0], 0.001 * (n + 1))
    assert pair.n == 40 and len(pair.credit) == 40
    np.testing.assert_array_equal(pair.corners, corners)
    np.testing.assert_array_equal(pair.centres, free_balls.box_centres(corners))
    np.testing.assert_array_equal(pair.radii, 0.001 * np.arange(1, 41))
    assert pair.drop_balls() == 40 and pair.n == 0 and not len(pair.radii)
