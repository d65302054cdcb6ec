"""Flat and degenerate collision meshes (issue 24, item 4): right answers, never a crash.

A plate of two triangles is common in real URDFs (a sensor's mounting plate, a caster's cover).
Coal's qhull crashed the whole process (SIGSEGV) when the distance path asked it for the convex
hull of such a mesh; the checker now gives a flat mesh no hull and uses coal's mesh distance.
The command line runs in a subprocess, so a crash there fails one test instead of the run.

Triangles without area (needles, points) are left out of every mesh: with one of them, coal's
distance from the mesh to any sphere read minus the radius. A mesh with no triangle of any area
is refused, naming its link and file.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from robotspec.collision import CollisionRules, SelfCollisionChecker
from robotspec.collision.distances import _solid
from robotspec.description.urdf import load_urdf
from robotspec.errors import CollisionError

#: Degenerate point sets: (vertices, triangles), each 0.1 m across, in the mesh's frame.
MESHES: dict[str, tuple[list[list[float]], list[list[int]]]] = {
    "plate": ([[0, 0, 0], [0.1, 0, 0], [0.1, 0.1, 0], [0, 0.1, 0]], [[0, 1, 2], [0, 2, 3]]),
    "sliver": (
        [[0, 0, 0], [0.1, 0, 0], [0.05, 0.1, 0], [0.05, 0.05, 1e-10]],
        [[0, 1, 2], [0, 1, 3], [1, 2, 3], [2, 0, 3]],
    ),
    "needled": (  # the plate, and a needle along its edge
        [[0, 0, 0], [0.1, 0, 0], [0.1, 0.1, 0], [0, 0.1, 0], [0.05, 0, 0]],
        [[0, 1, 2], [0, 2, 3], [0, 4, 1]],
    ),
    "collinear": ([[0, 0, 0], [0.05, 0, 0], [0.1, 0, 0], [0.1, 0, 0]], [[0, 1, 2], [1, 2, 3]]),
    "repeated": ([[0, 0, 0], [0, 0, 0], [0, 0, 0], [0.1, 0, 0]], [[0, 1, 3], [1, 2, 3]]),
}

#: Two meshes on prismatic joints over a box, and a second box s (x, y in [0, 0.1], z in [0.55,
#: 0.65]): the pairs a-b (mesh, mesh), a-s and b-s (mesh, box) are checked; the base is adjacent
#: to everything.
URDF = """<?xml version="1.0"?>
<robot name="flat">
  <link name="base"><collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link>
  <link name="a"><collision><geometry><mesh filename="{a}"/></geometry></collision></link>
  <link name="b"><collision><geometry><mesh filename="{b}"/></geometry></collision></link>
  <link name="s"><collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
  <joint name="base_a" type="prismatic">
    <parent link="base"/><child link="a"/><origin xyz="0 0 1"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
  <joint name="base_b" type="prismatic">
    <parent link="base"/><child link="b"/><origin xyz="0 0 1.5"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
  <joint name="base_s" type="fixed">
    <parent link="base"/><child link="s"/><origin xyz="0.05 0.05 0.6"/>
  </joint>
</robot>
"""


def _write_stl(path: Path, name: str) -> None:
    import trimesh

    vertices, faces = MESHES[name]
    trimesh.Trimesh(np.array(vertices), np.array(faces), process=False).export(str(path))


def _robot(tmp_path: Path, a: str, b: str) -> Path:
    """The URDF above with mesh ``a`` on link a and ``b`` on link b (a name of ``MESHES``)."""
    _write_stl(tmp_path / f"{a}.stl", a)
    _write_stl(tmp_path / f"{b}.stl", b)
    path = tmp_path / "flat.urdf"
    path.write_text(URDF.format(a=f"{a}.stl", b=f"{b}.stl"))
    return path


#: Meshes with no triangle of any area.
NO_AREA = ("collinear", "repeated")


@pytest.mark.parametrize("name", ["needled", "plate", "sliver"])
def test_distances_of_a_flat_mesh_are_its_mesh_distances(tmp_path: Path, name: str) -> None:
    world = load_urdf(_robot(tmp_path, name, "plate"))
    checker = SelfCollisionChecker(world, CollisionRules.for_world(world))
    assert checker.active_pairs == (("a", "b"), ("a", "s"), ("b", "s"))
    q = world.configuration()
    found = {(d.link1, d.link2): d for d in checker.distances(q)}
    # Every test mesh lies in its link's plane z = 0 (to 1e-10), within x, y in [0, 0.1].
    assert found[("a", "b")].distance == pytest.approx(0.5, abs=1e-9)
    assert found[("a", "s")].distance == pytest.approx(0.35, abs=1e-9)
    assert found[("b", "s")].distance == pytest.approx(0.85, abs=1e-9)
    assert found[("b", "s")].point1[2] == pytest.approx(1.5, abs=1e-9)
    assert found[("b", "s")].point2[2] == pytest.approx(0.65, abs=1e-9)
    qs = np.array([q, world.configuration({"base_a": -0.3, "base_b": -0.6})])  # at 0.7 and 0.9
    batch = checker.distances_batch(qs)
    assert batch[0] == pytest.approx([0.5, 0.35, 0.85], abs=1e-9)
    assert batch[1] == pytest.approx([0.2, 0.05, 0.25], abs=1e-9)
    assert not checker.in_collision(q)


@pytest.mark.parametrize("name", NO_AREA)
def test_a_mesh_without_area_is_refused_naming_link_and_file(tmp_path: Path, name: str) -> None:
    world = load_urdf(_robot(tmp_path, name, "plate"))
    checker = SelfCollisionChecker(world, CollisionRules.for_world(world))
    with pytest.raises(CollisionError, match=r"link 'a': mesh has no triangle with an area") as err:
        checker.distances(world.configuration())
    assert err.value.file is not None and err.value.file.endswith(f"{name}.stl")
    skipping = SelfCollisionChecker(world, CollisionRules.for_world(world), on_missing_mesh="skip")
    assert skipping.distances_batch(world.configuration()[None, :])[0] == pytest.approx(
        [np.inf, np.inf, 0.85], abs=1e-9
    )
    assert len(skipping.skipped) == 1 and skipping.skipped[0].severity == "warning"


def test_needle_triangles_do_not_spoil_sphere_queries(tmp_path: Path) -> None:
    """A plate and a cube, each with needles, and a ball near each (a ball over the plate moves).

    The flat plate has no hull, so its distance is coal's mesh distance; the ball by the cube's
    corner is inside the cube's bounding box, so coal's narrow phase decides its collision.
    """
    import trimesh

    _write_stl(tmp_path / "needled.stl", "needled")
    cube = trimesh.creation.box(extents=(0.1, 0.1, 0.1))  # each coordinate in [-0.05, 0.05]
    top = [[0.05, 0.05, 0.05], [0.05, 0.0, 0.05], [0.05, 0.025, 0.05]]
    faces = np.vstack([cube.faces, [[8, 10, 9], [8, 8, 9]]])  # needles on the top face
    mesh = trimesh.Trimesh(np.vstack([cube.vertices, top]), faces, process=False)
    mesh.export(str(tmp_path / "cube.stl"))
    (tmp_path / "balls.urdf").write_text(
        """<robot name="balls">
  <link name="plate"><collision><geometry><mesh filename="needled.stl"/></geometry></collision>
  </link>
  <link name="cube"><collision><geometry><mesh filename="cube.stl"/></geometry></collision></link>
  <link name="ball"><collision><geometry><sphere radius="0.05"/></geometry></collision></link>
  <link name="corner"><collision><geometry><sphere radius="0.05"/></geometry></collision></link>
  <joint name="plate_cube" type="fixed">
    <parent link="plate"/><child link="cube"/><origin xyz="1 0 0"/>
  </joint>
  <joint name="drop" type="prismatic">
    <parent link="plate"/><child link="ball"/><origin xyz="0.05 0.05 0.07"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
  <joint name="cube_corner" type="fixed">
    <parent link="cube"/><child link="corner"/><origin xyz="0.09 0.09 0.09"/>
  </joint>
</robot>"""
    )
    world = load_urdf(tmp_path / "balls.urdf")
    pairs = [("plate", "ball"), ("cube", "corner")]
    checker = SelfCollisionChecker(world, CollisionRules.for_world(world), pairs=pairs)
    corner = 3**0.5 * 0.04 - 0.05  # from (0.09, 0.09, 0.09) to the cube's corner, less the radius
    qs = np.array([[0.0], [-0.03]])  # the ball 2 cm over the plate, then 1 cm through it
    got = checker.distances_batch(qs)
    assert got == pytest.approx(np.array([[0.02, corner], [-0.01, corner]]), abs=1e-6)
    assert checker.collisions_batch(qs).tolist() == [[False, False], [True, False]]
    kept = [len(g.triangles[1]) for g in checker.geometry.geometries if g.triangles is not None]
    assert kept == [2, 12]  # the needles left out


def test_flat_mesh_collides_through_a_primitive(tmp_path: Path) -> None:
    world = load_urdf(_robot(tmp_path, "plate", "plate"))
    checker = SelfCollisionChecker(world, CollisionRules.for_world(world))
    q = world.configuration({"base_a": -0.38})  # the plate at z = 0.62 cuts the box s
    assert checker.colliding_pairs(q) == (("a", "s"),)
    assert checker.distances_batch(q[None, :])[0, 1] <= 0.0


def test_solid_point_sets_keep_their_hull_and_flat_ones_get_none() -> None:
    rng = np.random.default_rng(3)
    rotation = np.linalg.qr(rng.normal(size=(3, 3)))[0]
    plate = np.c_[rng.uniform(0, 0.1, (50, 2)), np.zeros(50)]
    for name, (vertices, _) in MESHES.items():
        assert not _solid(np.array(vertices, dtype=np.float64)), name
    assert NO_AREA
    assert not _solid(plate @ rotation.T)  # flat in any orientation
    bumped = plate.copy()
    bumped[0, 2] = 1e-9  # thinner than qhull can hull
    assert not _solid(bumped @ rotation.T)
    bumped[0, 2] = 1e-4
    assert _solid(bumped @ rotation.T)
    # Far from the origin the same bump is below qhull's rounding: flat.
    assert not _solid(bumped @ rotation.T + 1e3)
    cube = np.array([[x, y, z] for x in (0, 0.1) for y in (0, 0.1) for z in (0, 0.1)], dtype=float)
    assert _solid(cube)


def test_collisions_check_distances_command_on_a_flat_mesh(tmp_path: Path) -> None:
    _robot(tmp_path, "plate", "sliver")
    spec = tmp_path / "flat.yaml"
    spec.write_text("robotspec: 1\nname: Flat\ndescription:\n  urdf: flat.urdf\nroot: base\n")
    run = subprocess.run(
        [sys.executable, "-m", "robotspec", "collisions", "check", str(spec), "--distances"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 0, (run.returncode, run.stderr)
    assert run.stdout.startswith("collision-free (3 pairs checked)")
    assert "0.500000" in run.stdout and "0.350000" in run.stdout
