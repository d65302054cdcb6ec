"""Collision geometry and rules on small hand-written URDFs (exact answers, no robot files)."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from robotspec.cli.progress import Progress
from robotspec.collision import (
    CollisionRules,
    MeshLibrary,
    SelfCollisionChecker,
    adjacent_pairs,
    build_geometry_model,
)
from robotspec.description.srdf_reader import parse_srdf_bytes
from robotspec.description.urdf import load_urdf
from robotspec.errors import CollisionError

URDF = """<?xml version="1.0"?>
<robot name="toy">
  <link name="base"><collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link>
  <link name="frame"/>
  <link name="a">
    <collision><origin xyz="0 0 0.5"/><geometry><sphere radius="0.1"/></geometry></collision>
  </link>
  <link name="b">
    <collision><geometry><cylinder radius="0.05" length="0.4"/></geometry></collision>
  </link>
  <link name="c">
    <collision><geometry>{mesh}</geometry></collision>
  </link>
  <joint name="base_frame" type="fixed"><parent link="base"/><child link="frame"/></joint>
  <joint name="frame_a" type="revolute">
    <parent link="frame"/><child link="a"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/>
  </joint>
  <joint name="frame_b" type="prismatic">
    <parent link="frame"/><child link="b"/><origin xyz="1 0 0"/><axis xyz="1 0 0"/>
    <limit lower="-2" upper="1" effort="1" velocity="1"/>
  </joint>
  <joint name="b_c" type="fixed"><parent link="b"/><child link="c"/><origin xyz="0 0 1"/></joint>
</robot>
"""


def _cube_stl(path: Path, size: float = 0.1) -> None:
    import trimesh

    trimesh.creation.box(extents=(size, size, size)).export(str(path))


def toy(
    tmp_path: Path, mesh: str = '<mesh filename="cube.stl" scale="2 2 2"/>', write: bool = True
) -> Path:
    if write:
        _cube_stl(tmp_path / "cube.stl")
    p = tmp_path / "toy.urdf"
    p.write_text(URDF.format(mesh=mesh))
    return p


def test_adjacency_contracts_bodies_without_geometry(tmp_path: Path) -> None:
    world = load_urdf(toy(tmp_path))
    adj = adjacent_pairs(world, ["base", "a", "b", "c"])
    # 'frame' has no geometry: base, a and b all become adjacent (MoveIt's rule); c hangs on b.
    assert adj == {("a", "base"), ("b", "base"), ("a", "b"), ("b", "c")}


def test_rule_precedence(tmp_path: Path) -> None:
    world = load_urdf(toy(tmp_path))
    srdf = parse_srdf_bytes(
        b"""<robot name="toy">
        <disable_default_collisions link="c"/>
        <enable_collisions link1="c" link2="a" reason="wanted"/>
        <enable_collisions link1="a" link2="b"/>
        <disable_collisions link1="base" link2="c" reason="Never"/>
        <disable_collisions link1="ghost" link2="c" reason="Never"/>
        </robot>""",
        strict=False,
    )
    rules = CollisionRules.for_world(world, srdf=srdf, buffer_distance=0.02)
    assert rules.why_disabled("c", "base") == "Never"
    assert rules.why_disabled("a", "c") is None  # enabled over disable_default
    assert rules.why_disabled("a", "b") is None  # enabled over adjacency
    assert rules.why_disabled("b", "c") == "Adjacent"
    assert rules.why_disabled("base", "a") == "Adjacent"
    assert set(rules.active_pairs()) == {("a", "b"), ("a", "c")}
    off = CollisionRules.for_world(world, srdf=srdf, disabled_bodies=["a"])
    assert off.why_disabled("a", "c") == "body disabled"
    with pytest.raises(CollisionError):
        CollisionRules(bodies=("a",), buffer_distance=-1.0)


def test_primitives_and_scaled_mesh_distances(tmp_path: Path) -> None:
    world = load_urdf(toy(tmp_path))
    rules = CollisionRules.for_world(world, adjacency=False)
    checker = SelfCollisionChecker(world, rules)
    q = world.configuration()
    d = {(x.link1, x.link2): x for x in checker.distances(q)}
    # Sphere of radius 0.1 at z=0.5 over a 0.2 box: 0.5 - 0.1 - 0.1.
    assert d[("base", "a")].distance == pytest.approx(0.3, abs=1e-9)
    assert d[("base", "a")].point1[2] == pytest.approx(0.1, abs=1e-9)
    assert d[("base", "a")].point2[2] == pytest.approx(0.4, abs=1e-9)
    # The cube is scaled to 0.2: its bottom face is at z = 1 - 0.1; cylinder top at 0.2.
    assert d[("b", "c")].distance == pytest.approx(0.7, abs=1e-6)  # STL stores float32
    # Cylinder (radius 0.05) at x = 1 against the box: 1 - 0.05 - 0.1.
    assert d[("base", "b")].distance == pytest.approx(0.85, abs=1e-9)
    assert not checker.in_collision(q)
    # Slide b into the base: collides; a margin catches it earlier.
    q2 = world.configuration({"frame_b": -0.9})
    assert ("base", "b") in checker.colliding_pairs(q2)
    q3 = world.configuration({"frame_b": -0.8})
    assert ("base", "b") not in checker.colliding_pairs(q3)
    assert ("base", "b") in checker.colliding_pairs(q3, margin=0.06)


def test_mesh_loaded_once_and_errors_name_body_and_path(tmp_path: Path) -> None:
    library = MeshLibrary()
    world = load_urdf(toy(tmp_path))
    build_geometry_model(world, meshes=library)
    build_geometry_model(world, meshes=library)
    assert len(library) == 1
    (tmp_path / "cube.stl").write_bytes(b"solid nothing\nendsolid nothing\n")
    with pytest.raises(CollisionError) as err:
        build_geometry_model(world)
    assert err.value.name == "c" and "cube.stl" in str(err.value)
    model = build_geometry_model(world, on_missing_mesh="skip")
    assert model.bodies == ("base", "a", "b")
    assert len(model.skipped) == 1 and model.skipped[0].severity == "warning"
    (tmp_path / "cube.stl").unlink()
    with pytest.raises(CollisionError, match="link 'c'"):
        build_geometry_model(world)


def test_unresolved_mesh_is_reported_not_silently_skipped(tmp_path: Path) -> None:
    world = load_urdf(toy(tmp_path, '<mesh filename="missing.obj"/>', write=False), meshes="keep")
    with pytest.raises(CollisionError, match="was not resolved"):
        SelfCollisionChecker(world, CollisionRules.for_world(world)).geometry  # noqa: B018
    checker = SelfCollisionChecker(
        world, CollisionRules.for_world(world, adjacency=False), on_missing_mesh="skip"
    )
    assert len(checker.skipped) == 1
    dist = {(d.link1, d.link2): d.distance for d in checker.distances(world.configuration())}
    assert dist[("b", "c")] == np.inf


def test_obj_mesh(tmp_path: Path) -> None:
    # DAE goes through the same reader (pycollada); the HSR-B test loads its head_camera.dae.
    import trimesh

    trimesh.creation.icosphere(radius=0.1).export(str(tmp_path / "ball.obj"))
    world = load_urdf(toy(tmp_path, '<mesh filename="ball.obj"/>', write=False))
    checker = SelfCollisionChecker(world, CollisionRules.for_world(world, adjacency=False))
    d = {(x.link1, x.link2): x.distance for x in checker.distances(world.configuration())}
    assert d[("b", "c")] == pytest.approx(1.0 - 0.1 - 0.2, abs=2e-3)  # polygonal sphere


@given(st.lists(st.floats(-2.0, 1.0), min_size=1, max_size=6), st.floats(-3.0, 3.0))
def test_batch_equals_single_queries(
    tmp_path_factory: pytest.TempPathFactory, bs: list[float], a: float
) -> None:
    tmp = tmp_path_factory.getbasetemp() / "toy_batch"
    tmp.mkdir(exist_ok=True)
    world = load_urdf(toy(tmp))
    checker = SelfCollisionChecker(world, CollisionRules.for_world(world, adjacency=False))
    qs = np.array([world.configuration({"frame_b": b, "frame_a": a}) for b in bs])
    batch = checker.collisions_batch(qs)
    for q, row in zip(qs, batch, strict=True):
        single = checker.colliding_pairs(q)
        assert tuple(p for p, hit in zip(checker.active_pairs, row, strict=True) if hit) == single
    assert list(checker.in_collision_batch(qs)) == [bool(r.any()) for r in batch]


def test_progress_bar_only_when_asked() -> None:
    quiet = io.StringIO()
    with Progress(10, "x", stream=quiet) as bar:
        bar.update(10)
    assert quiet.getvalue() == ""  # not a terminal
    loud = io.StringIO()
    with Progress(4, "matrix", stream=loud, enabled=True) as bar:
        bar.update(4)
    assert "matrix [" in loud.getvalue() and "4/4" in loud.getvalue()
    assert loud.getvalue().endswith("\n")
