"""A mesh outside the allowed folders is named as such, apart from a mesh that is missing.

Issue 31: ``render`` with a mesh outside the allowed folders said "mesh files not found", named
no file and advised widening ``description.package_paths``. It must name the mesh, its URDF line,
the folders it lies outside of and the flags that allow it (``-P``, ``ROS_PACKAGE_PATH``); a
mesh that does not exist keeps its own "not found" message. No example-robot-data needed: the
robot is written here, with a real mesh file outside its folder.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from robotspec.cli.app import app
from robotspec.cli.output import run_app
from robotspec.compiler import compile_robot
from robotspec.description.mesh_report import unresolved_meshes
from robotspec.errors import DescriptionError

URDF = """<robot name="r">
  <link name="base">
    <visual><geometry><mesh filename="../meshes/ok.stl"/></geometry></visual>
  </link>
  <link name="arm">
    <visual><geometry><mesh filename="../../../outside/part.stl"/></geometry></visual>
    <collision><geometry><mesh filename="../../../outside/part.stl"/></geometry></collision>
  </link>
  <link name="hand">
    <visual><geometry><mesh filename="../meshes/gone.stl"/></geometry></visual>
    <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>
  </link>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="k" type="fixed"><parent link="arm"/><child link="hand"/>
    <origin xyz="0 0 1"/></joint>
</robot>
"""
#: Lines of the URDF above: the outside mesh's visual element, the missing one's.
OUTSIDE_LINE, MISSING_LINE = 6, 10

SPEC = "robotspec: 1\nname: R\nroot: base\ndescription:\n  urdf: robot/urdf/r.urdf\n"

STL = """solid t
facet normal 0 0 1
outer loop
vertex 0 0 0
vertex 0.1 0 0
vertex 0 0.1 0
endloop
endfacet
endsolid t
"""


@pytest.fixture
def robot_tree(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """``proj/r.yaml`` + ``proj/robot/{urdf,meshes}``, and ``outside/part.stl`` beside ``proj``."""
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    monkeypatch.delenv("AMENT_PREFIX_PATH", raising=False)
    proj = tmp_path / "proj"
    (proj / "robot" / "urdf").mkdir(parents=True)
    (proj / "robot" / "meshes").mkdir()
    (tmp_path / "outside").mkdir()
    (tmp_path / "outside" / "part.stl").write_text(STL)
    (proj / "robot" / "meshes" / "ok.stl").write_text(STL)
    (proj / "robot" / "urdf" / "r.urdf").write_text(URDF)
    (proj / "r.yaml").write_text(SPEC)
    return proj


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = run_app(app, list(argv))
    out = capsys.readouterr()
    return code, out.out, out.err


def outside_line(proj: Path, severity: str, line: int = OUTSIDE_LINE) -> str:
    """The start of the located problem about the outside mesh, up to the allowed folders."""
    urdf = proj / "robot" / "urdf" / "r.urdf"
    real = (proj.parent / "outside" / "part.stl").resolve()
    return (
        f"{urdf}:{line}: {severity}: mesh '../../../outside/part.stl' of body 'arm' resolves "
        f"to {real}, outside the allowed folders ("
    )


def test_render_names_the_outside_mesh_its_line_and_the_flags_that_allow_it(
    robot_tree: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    pytest.importorskip("PIL")
    png = robot_tree / "r.png"
    code, out, err = run(capsys, "render", str(robot_tree / "r.yaml"), "-o", str(png))
    assert (code, out) == (1, "") and not png.exists()
    lines = err.splitlines()
    assert len(lines) == 2, err
    missing, outside = lines
    # The missing mesh keeps its own message: not found, make the package findable.
    assert missing.startswith(
        "error: 1 body loses its geometry, mesh files not found (hand; meshes of '../meshes')"
    )
    assert "outside" not in missing
    # The outside one: its URDF line, the mesh, the folders, the flags; no "not found".
    assert outside.startswith(outside_line(robot_tree, "error")), outside
    assert str(robot_tree / "robot") in outside  # one of the allowed folders is named
    assert outside.endswith(
        "); robotspec reads no file outside those folders: allow a folder that holds it with "
        "-P FOLDER or ROS_PACKAGE_PATH, or pass --skip-missing-meshes to render without it"
    )
    assert "not found" not in outside and "package_paths" not in outside


def test_render_skipping_says_the_same_as_warnings(
    robot_tree: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    pytest.importorskip("PIL")
    png = robot_tree / "r.png"
    code, _, err = run(
        capsys, "render", str(robot_tree / "r.yaml"), "-o", str(png), "--skip-missing-meshes"
    )
    assert code == 0 and png.is_file()
    lines = err.splitlines()
    assert len(lines) == 2, err
    assert lines[0].startswith("warning: 1 body loses its geometry, mesh files not found (hand;")
    assert lines[1].startswith(outside_line(robot_tree, "warning"))
    assert lines[1].endswith(
        "); render goes on without it (allow a folder that holds it with -P FOLDER or "
        "ROS_PACKAGE_PATH)"
    )


def test_the_flag_named_allows_it(robot_tree: Path, capsys: pytest.CaptureFixture[str]) -> None:
    pytest.importorskip("PIL")
    png = robot_tree / "r.png"
    folder = str(robot_tree.parent / "outside")
    code, _, err = run(capsys, "render", str(robot_tree / "r.yaml"), "-o", str(png), "-P", folder)
    assert code == 1 and "outside" not in err
    assert err.startswith("error: 1 body loses its geometry, mesh files not found (hand;")


def test_collisions_check_names_the_outside_collision_mesh(
    robot_tree: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code, _, err = run(capsys, "collisions", "check", str(robot_tree / "r.yaml"))
    assert code == 1
    assert len(err.splitlines()) == 1, err  # the hand's collision is a box: nothing missing
    assert err.startswith(outside_line(robot_tree, "error", OUTSIDE_LINE + 1))
    assert err.rstrip().endswith("or pass --skip-missing-meshes to check collisions without it")


def test_validate_warns_with_the_flags_not_the_spec(
    robot_tree: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code, out, _ = run(capsys, "validate", str(robot_tree / "r.yaml"))
    assert code == 0
    outside = next(ln for ln in out.splitlines() if ":6: warning:" in ln)
    assert outside.endswith(
        "2 meshes of 1 body (arm) have no geometry; allow a folder that holds it with "
        "-P FOLDER or ROS_PACKAGE_PATH"
    )
    gone = next(ln for ln in out.splitlines() if f":{MISSING_LINE}: warning:" in ln)
    assert "which does not exist" in gone and "outside" not in gone


def test_the_loaded_mesh_keeps_why_it_has_no_file(robot_tree: Path) -> None:
    robot = compile_robot(robot_tree / "r.yaml")
    meshes = unresolved_meshes(robot.world, collision=False)
    assert [(m.body, m.line, m.outside) for m in meshes] == [
        ("arm", OUTSIDE_LINE, True),
        ("hand", MISSING_LINE, False),
    ]
    assert all(m.file == str(robot_tree / "robot" / "urdf" / "r.urdf") for m in meshes)


def test_the_scene_builder_says_why(robot_tree: Path) -> None:
    from robotspec.render import build_scene

    robot = compile_robot(robot_tree / "r.yaml")
    with pytest.raises(DescriptionError, match="outside the allowed folders"):
        build_scene(robot)
