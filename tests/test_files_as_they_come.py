"""Robot files as users bring them (issue 30, "files as they come"), each on a small layout.

A description folder without ``package.xml`` found by its name; the user's own package of a
name the installed ``example-robot-data`` also has; a xacro including a sibling file; ``init -P``
writing a spec that validates as written; meshes in a sibling folder of the project; an SRDF
declaring one virtual joint twice.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from robotspec.compiler import check_spec
from robotspec.description.srdf_reader import parse_srdf_bytes

URDF = """<robot name="r">
  <link name="base_link"/>
  <link name="arm"/>
  <joint name="j1" type="revolute"><parent link="base_link"/><child link="arm"/>
    <origin xyz="0 0 0.2"/><axis xyz="0 1 0"/><limit lower="-1" upper="1" velocity="1" effort="1"/>
  </joint>
</robot>
"""

TWICE = """<robot name="r">
  <group name="arm"><joint name="j1"/></group>
  <virtual_joint name="world_joint" type="fixed" parent_frame="world" child_link="base_link"/>
  <virtual_joint name="world_joint" type="floating" parent_frame="world" child_link="base_link"/>
</robot>
"""


def write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


# ----------------------------------------------------------------------------- f. SRDF repeats
def test_a_virtual_joint_declared_twice_is_read_once_with_a_located_warning() -> None:
    srdf = parse_srdf_bytes(TWICE.encode(), "r.srdf")
    assert [(v.name, v.type, v.line) for v in srdf.virtual_joints] == [("world_joint", "fixed", 3)]
    assert srdf.group_names == ("arm",)  # the rest of the file is kept
    assert [str(w) for w in srdf.warnings] == [
        "r.srdf:4: warning: virtual_joint 'world_joint' is declared again (first on line 3) "
        "(this one: floating from 'world' to 'base_link'; the first: fixed from 'world' to "
        "'base_link'); read as MoveIt does, the first declaration only (delete this one)"
    ]


def test_a_spec_with_that_srdf_validates_and_says_where(tmp_path: Path) -> None:
    write(tmp_path / "r.urdf", URDF)
    write(tmp_path / "r.srdf", TWICE)
    spec = write(
        tmp_path / "r.yaml",
        "robotspec: 1\nname: R\ndescription: {urdf: r.urdf, srdf: r.srdf}\nroot: base_link\n"
        "chains: {arm: {root: base_link, tip: arm}}\n",
    )
    result = check_spec(spec)
    warned = [str(w) for w in result.warnings if "declared again" in str(w)]
    assert len(warned) == 1 and warned[0].startswith(f"{tmp_path}/r.srdf:4: warning:"), warned
    assert result.robot.drive is None  # the first declaration: fixed


def test_names_repeated_in_other_elements_stay_errors() -> None:
    text = TWICE.replace("world_joint", "a", 1).replace('"arm"><joint', '"arm"><joint', 1)
    text = text.replace("</robot>", '<group name="arm"><joint name="j1"/></group></robot>')
    with pytest.raises(Exception, match="group 'arm' is defined twice"):
        parse_srdf_bytes(text.encode(), "r.srdf")


# ------------------------------------------------------------------- a-e. packages and folders
STL = "solid b\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
STL += "endloop\nendfacet\nendsolid b\n"


def meshed(mesh: str) -> str:
    """The two-link robot with a mesh on its base."""
    return URDF.replace(
        '<link name="base_link"/>',
        f'<link name="base_link"><collision><geometry><mesh filename="{mesh}"/></geometry>'
        "</collision></link>",
    )


def mesh_path(spec: Path, package_paths: tuple[Path, ...] = ()) -> Path:
    """Where the base's mesh was found, for a spec that must validate without warnings."""
    result = check_spec(spec, package_paths=package_paths)
    assert not result.warnings, [str(w) for w in result.warnings]
    geometry = result.robot.world.get_body_by_name("base_link").collisions[0].geometry
    return Path(geometry.path)  # type: ignore[union-attr, arg-type]


def spec_for(folder: Path, urdf: str, extra: str = "") -> Path:
    return write(
        folder / "r.yaml",
        f"robotspec: 1\nname: R\ndescription: {{urdf: {urdf}{extra}}}\nroot: base_link\n",
    )


@pytest.mark.parametrize("layout", ["beside", "around"])
def test_a_description_folder_without_package_xml_is_found_by_its_name(
    tmp_path: Path, layout: str
) -> None:
    # beside: robot.urdf next to my_robot/; around: my_robot/urdf/robot.urdf inside it.
    pkg = tmp_path / "my_robot"
    write(pkg / "meshes" / "base.stl", STL)
    urdf = tmp_path / "robot.urdf" if layout == "beside" else pkg / "urdf" / "robot.urdf"
    write(urdf, meshed("package://my_robot/meshes/base.stl"))
    spec = spec_for(urdf.parent, urdf.name)
    assert mesh_path(spec) == (pkg / "meshes" / "base.stl").resolve()


def test_a_xacro_finds_its_own_package_and_a_sibling_file_without_p(tmp_path: Path) -> None:
    urdf = tmp_path / "my_robot" / "urdf"
    write(
        urdf / "robot.urdf.xacro",
        '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'
        '<xacro:include filename="$(find my_robot)/urdf/arm.xacro"/>'
        '<xacro:include filename="parts.xacro"/><xacro:arm/></robot>\n',
    )
    body = URDF.split(">", 1)[1].rsplit("</robot>", 1)[0]
    write(
        urdf / "arm.xacro",
        '<robot xmlns:xacro="http://www.ros.org/wiki/xacro"><xacro:macro name="arm">'
        f"{body}</xacro:macro></robot>\n",
    )
    write(urdf / "parts.xacro", '<robot xmlns:xacro="http://www.ros.org/wiki/xacro"/>\n')
    robot = check_spec(spec_for(urdf, "robot.urdf.xacro")).robot
    assert robot.world.has_connection("j1")


def test_the_package_holding_the_file_wins_over_installed_and_p_ones(tmp_path: Path) -> None:
    from .conftest import erd_robots

    if not (erd_robots() / "kinova_description").is_dir():
        pytest.skip("example-robot-data without kinova_description")
    own = tmp_path / "mine" / "kinova_description"
    write(own / "meshes" / "mine.stl", STL)
    urdf = write(own / "urdf" / "gen3.urdf", meshed("package://kinova_description/meshes/mine.stl"))
    other = tmp_path / "other" / "kinova_description"  # on the user's path: still below
    write(other / "package.xml", "<package><name>kinova_description</name></package>\n")
    spec = spec_for(urdf.parent, urdf.name)
    assert mesh_path(spec, (tmp_path / "other",)) == (own / "meshes" / "mine.stl").resolve()
    # With a manifest naming it otherwise, the folder's name still says which package it is.
    write(own / "package.xml", "<package><name>kortex_description</name></package>\n")
    assert mesh_path(spec, (tmp_path / "other",)) == (own / "meshes" / "mine.stl").resolve()


@pytest.mark.parametrize("marker", ["pyproject.toml", ".git", None])
def test_meshes_beside_the_description_are_read_inside_its_project(
    tmp_path: Path, marker: str | None
) -> None:
    project = tmp_path / "project"
    write(project / "robots" / "hands" / "meshes" / "palm.stl", STL)
    urdf = write(
        project / "robots" / "arm" / "urdf" / "arm.urdf", meshed("../../hands/meshes/palm.stl")
    )
    if marker is not None:
        (project / marker).mkdir() if marker.startswith(".") else write(project / marker, "")
        assert mesh_path(spec_for(urdf.parent, urdf.name)).name == "palm.stl"
        return
    # No project marker (a download): the description stays in its own folder.
    result = check_spec(spec_for(urdf.parent, urdf.name))
    assert any("outside the allowed folders" in str(w) for w in result.warnings)
    # -P naming the folder above still allows it.
    assert mesh_path(spec_for(urdf.parent, urdf.name), (project / "robots",)).name == "palm.stl"


def test_a_project_keeps_its_hidden_folders_closed_to_a_description(tmp_path: Path) -> None:
    project = tmp_path / "project"
    (project / ".git").mkdir(parents=True)
    write(project / ".secret" / "palm.stl", STL)
    urdf = write(
        project / "robots" / "arm" / "urdf" / "arm.urdf", meshed("../../../.secret/palm.stl")
    )
    result = check_spec(spec_for(urdf.parent, urdf.name))
    assert any("outside the allowed folders" in str(w) for w in result.warnings)


def test_init_with_p_writes_package_paths_so_the_spec_validates_as_written(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    from robotspec.cli.app import app
    from robotspec.cli.output import run_app

    src = tmp_path / "ws" / "src"
    write(src / "my_description" / "package.xml", "<package><name>my_description</name></package>")
    write(src / "my_meshes" / "package.xml", "<package><name>my_meshes</name></package>")
    write(src / "my_meshes" / "meshes" / "base.stl", STL)
    write(src / "my_description" / "urdf" / "r.urdf", meshed("package://my_meshes/meshes/base.stl"))
    for where, entry in [("ws/specs", "../src"), ("elsewhere/specs", "../../ws/src")]:
        project = tmp_path / where.split("/")[0]
        if where.startswith("ws"):
            (project / ".git").mkdir(exist_ok=True)  # the workspace is the spec's project
        monkeypatch.chdir(tmp_path)
        out = tmp_path / where / "r.yaml"
        code = run_app(
            app,
            ["init", "package://my_description/urdf/r.urdf", "-P", str(src), "-o", str(out)],
        )
        err = capsys.readouterr().err
        assert code == 0, err
        assert f"package_paths: [{entry}]" in out.read_text().replace('"', "")
        monkeypatch.chdir(tmp_path / "elsewhere" if where.startswith("e") else tmp_path)
        if where.startswith("ws"):
            assert "note:" not in err
            assert mesh_path(out).name == "base.stl"  # valid as written, from anywhere
        else:
            assert f"pass -P {src}" in err  # outside its project: the note says which -P
            assert run_app(app, ["validate", str(out)]) == 1
            assert mesh_path(out, (src,)).name == "base.stl"
        capsys.readouterr()


# ------------------------------------------------------------------------------- real robots
def test_the_shared_pr2_reads_its_own_package_not_the_installed_one() -> None:
    from robotspec.files.packages import PackageResolver

    from .conftest import SHARED, erd_robots

    xacro = SHARED / "robots" / "pr2" / "pr2_description" / "robots" / "pr2.urdf.xacro"
    if not xacro.is_file():
        pytest.skip(f"{xacro} is absent (the shared robots are not on this machine)")
    if not (erd_robots() / "pr2_description").is_dir():
        pytest.skip("example-robot-data has no pr2_description to shadow it")
    resolver = PackageResolver.create(xacro, extra_paths=[erd_robots()])  # even behind -P
    assert resolver.find_package("pr2_description") == xacro.parents[1]


def test_the_shared_ur5e_drafted_outside_its_project_validates_with_the_noted_p(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from robotspec.cli.app import app
    from robotspec.cli.output import run_app

    from .conftest import SHARED

    xacro = SHARED / "robots" / "ur5e" / "ur_description" / "urdf" / "ur5e.xacro"
    if not xacro.is_file():
        pytest.skip(f"{xacro} is absent (the shared robots are not on this machine)")
    out = tmp_path / "ur5e.yaml"
    assert run_app(app, ["init", str(xacro), "-o", str(out)]) == 0
    note = capsys.readouterr().err
    allow = note.split("pass -P ", 1)[1].split(" ", 1)[0]
    assert run_app(app, ["validate", str(out), "-P", allow]) == 0, capsys.readouterr()
