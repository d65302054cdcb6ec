"""``robotspec init`` writes references the spec can resolve where it is, on layouts as they come.

Why these layouts: a clone folder is rarely named like the package its ``package.xml`` declares
(``hsr_description@9281be0``), and many descriptions have no ``package.xml`` at all. The draft
used to write ``package://robots/...`` (the robot file's own sub-folder, known only by its name
while drafting), which no resolver finds from the spec: not valid as written.
"""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from robotspec.cli.app import app
from robotspec.cli.output import run_app

_STL = """solid tetra
facet normal 0 0 -1
 outer loop
  vertex 0 0 0
  vertex 0.1 0 0
  vertex 0 0.1 0
 endloop
endfacet
facet normal 0 -1 0
 outer loop
  vertex 0 0 0
  vertex 0 0 0.1
  vertex 0.1 0 0
 endloop
endfacet
endsolid tetra
"""


def _urdf(mesh_uri: str) -> str:
    return f"""<robot name="lab_arm">
  <link name="base_link">
    <visual><geometry><mesh filename="{mesh_uri}"/></geometry></visual>
  </link>
  <link name="link1"><visual><geometry><box size="0.05 0.05 0.3"/></geometry></visual></link>
  <link name="link2"><visual><geometry><box size="0.05 0.05 0.3"/></geometry></visual></link>
  <joint name="joint1" type="revolute">
    <parent link="base_link"/><child link="link1"/><origin xyz="0 0 0.1"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="10" velocity="1"/>
  </joint>
  <joint name="joint2" type="revolute">
    <parent link="link1"/><child link="link2"/><origin xyz="0 0 0.3"/>
    <axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="10" velocity="1"/>
  </joint>
</robot>
"""


def _package_xml(name: str) -> str:
    return f'<?xml version="1.0"?>\n<package format="2"><name>{name}</name></package>\n'


def _init_and_validate(
    capsys: pytest.CaptureFixture[str], urdf: Path, allow: Path, project: Path
) -> dict[str, object]:
    """Draft as a user does (``-P`` the clone), then validate with the -P init's note asks."""
    out = project / "robot.yaml"
    assert run_app(app, ["init", str(urdf), "-P", str(allow), "-o", str(out)]) == 0
    err = capsys.readouterr().err
    notes = [w for line in err.splitlines() if line.startswith("note:") for w in line.split()]
    allowed = [notes[i + 1] for i, w in enumerate(notes) if w == "-P"]
    argv = ["validate", str(out), *(a for p in allowed for a in ("-P", p))]
    assert run_app(app, argv) == 0, capsys.readouterr().out  # valid as written
    capsys.readouterr()
    data = yaml.safe_load(out.read_text())
    assert isinstance(data, dict)
    return data


def test_clone_folder_not_named_like_its_package(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    # The robot file in a sub-folder (robots/) of a package whose folder is a clone's name.
    clone = tmp_path / "downloads" / "lab_arm_description@9281be0"
    (clone / "robots").mkdir(parents=True)
    (clone / "meshes").mkdir()
    (clone / "package.xml").write_text(_package_xml("lab_arm_description"))
    (clone / "meshes" / "base.stl").write_text(_STL)
    urdf = clone / "robots" / "lab_arm.urdf"
    urdf.write_text(_urdf("package://lab_arm_description/meshes/base.stl"))
    project = tmp_path / "project"
    project.mkdir()
    data = _init_and_validate(capsys, urdf, clone, project)
    desc = data["description"]
    assert isinstance(desc, dict)
    # The package the spec finds through its package_paths, never the sub-folder's name.
    assert desc["urdf"] == "package://lab_arm_description/robots/lab_arm.urdf"
    assert [(project / p).resolve() for p in desc["package_paths"]] == [clone.resolve()]


@pytest.mark.parametrize("allow_level", ["description", "parent"])
def test_description_folder_without_package_xml(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, allow_level: str
) -> None:
    # No package.xml anywhere: lab/lab_arm/urdf/lab_arm.urdf, its mesh named relatively.
    description = tmp_path / "lab" / "lab_arm"
    (description / "urdf").mkdir(parents=True)
    (description / "meshes").mkdir()
    (description / "meshes" / "base.stl").write_text(_STL)
    urdf = description / "urdf" / "lab_arm.urdf"
    urdf.write_text(_urdf("../meshes/base.stl"))
    project = tmp_path / "project"
    project.mkdir()
    allow = description if allow_level == "description" else description.parent
    data = _init_and_validate(capsys, urdf, allow, project)
    desc = data["description"]
    assert isinstance(desc, dict)
    if allow_level == "parent":  # -P lab: lab_arm is a package by its folder's name
        assert desc["urdf"] == "package://lab_arm/urdf/lab_arm.urdf"
    else:  # -P lab_arm: "package://urdf/..." would name no package a person looks for
        assert not str(desc["urdf"]).startswith("package://")
        assert (project / str(desc["urdf"])).resolve() == urdf.resolve()
