"""A robot's files as users keep them: specs beside robot folders, meshes beside ``urdf/``.

The layout most projects have: ``specs/arm.yaml`` and ``robots/arm/urdf/arm.urdf`` naming
``../meshes/base.stl``. ``init`` writes a spec ``validate`` accepts from any working folder, the
meshes are found, and nothing wider than the robot's own folder becomes readable.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from robotspec.cli.app import app
from robotspec.cli.output import run_app
from robotspec.compiler import check_spec
from robotspec.errors import SpecError

STL = (
    "solid box\n"
    + "".join(
        f"facet normal 0 0 1\nouter loop\nvertex {a}\nvertex {b}\nvertex {c}\nendloop\nendfacet\n"
        for a, b, c in [
            ("0 0 0", "0.1 0 0", "0 0.1 0"),
            ("0 0 0", "0 0.1 0", "0 0 0.1"),
            ("0 0 0", "0 0 0.1", "0.1 0 0"),
            ("0.1 0 0", "0 0.1 0", "0 0 0.1"),
        ]
    )
    + "endsolid box\n"
)


def arm_urdf(mesh: str = "../meshes/base.stl") -> str:
    return f"""<?xml version="1.0"?>
<robot name="arm">
  <link name="base_link">
    <collision><geometry><mesh filename="{mesh}"/></geometry></collision>
  </link>
  <link name="link1"><collision><geometry><box size="0.05 0.05 0.3"/></geometry></collision></link>
  <link name="tool0"/>
  <joint name="j1" type="revolute"><parent link="base_link"/><child link="link1"/>
    <origin xyz="0 0 0.3"/><axis xyz="0 1 0"/><limit lower="-2" upper="2" velocity="2" effort="1"/>
  </joint>
  <joint name="flange" type="fixed">
    <parent link="link1"/><child link="tool0"/><origin xyz="0 0 0.2"/>
  </joint>
</robot>
"""


@pytest.fixture
def project(tmp_path: Path) -> Path:
    root = tmp_path / "home" / "me" / "project"
    (root / "robots" / "arm" / "urdf").mkdir(parents=True)
    (root / "robots" / "arm" / "meshes").mkdir()
    (root / "specs").mkdir()
    (root / "robots" / "arm" / "meshes" / "base.stl").write_text(STL)
    (root / "robots" / "arm" / "urdf" / "arm.urdf").write_text(arm_urdf())
    return root


def cli(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str]:
    code = run_app(app, list(argv))
    out = capsys.readouterr()
    return code, out.out + out.err


def test_meshes_beside_urdf_folder_are_found(project: Path) -> None:
    urdf = os.path.relpath(project / "robots" / "arm" / "urdf" / "arm.urdf", project / "specs")
    (project / "specs" / "arm.yaml").write_text(
        f"robotspec: 1\nname: Arm\ndescription: {{urdf: {urdf}}}\nroot: base_link\n"
    )
    result = check_spec(project / "specs" / "arm.yaml")
    assert not [w for w in result.warnings if "outside the allowed" in str(w)]
    base = result.robot.world.get_body_by_name("base_link")
    assert base.collisions and base.collisions[0].geometry.path is not None  # type: ignore[union-attr]


def test_init_from_another_folder_writes_a_spec_validate_accepts(
    project: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(project / "robots")
    code, text = cli(capsys, "init", "arm/urdf/arm.urdf", "-o", "../specs/arm.yaml")
    assert code == 0, text
    assert "note: package_paths" not in text
    for where in (project, project / "specs", project / "robots" / "arm" / "meshes"):
        monkeypatch.chdir(where)
        code, text = cli(capsys, "validate", str(project / "specs" / "arm.yaml"))
        assert code == 0, text
        assert "outside the allowed" not in text
        code, text = cli(capsys, "collisions", "check", str(project / "specs" / "arm.yaml"))
        assert code == 0 and "mesh files not found" not in text, text


def test_a_spec_may_name_package_folders_beside_it(project: Path) -> None:
    pkg = project / "robots" / "arm_description"
    (pkg / "meshes").mkdir(parents=True)
    (pkg / "package.xml").write_text("<package><name>arm_description</name></package>\n")
    (pkg / "meshes" / "base.stl").write_text(STL)
    urdf = project / "robots" / "arm" / "urdf" / "arm.urdf"
    urdf.write_text(arm_urdf("package://arm_description/meshes/base.stl"))
    spec = project / "specs" / "arm.yaml"
    spec.write_text(
        "robotspec: 1\nname: Arm\n"
        "description: {urdf: ../robots/arm/urdf/arm.urdf, package_paths: [../robots]}\n"
        "root: base_link\n"
    )
    result = check_spec(spec)
    assert not [w for w in result.warnings if "arm_description" in str(w)], result.warnings
    base = result.robot.world.get_body_by_name("base_link")
    assert base.collisions and base.collisions[0].geometry.path is not None  # type: ignore[union-attr]


@pytest.mark.parametrize(
    "entry",
    ["../../../../../../../../../../..", "/", "/etc", "../../..", "../../"],
    ids=["root-by-dots", "root", "etc", "home-by-dots", "home-slash"],
)
def test_too_wide_or_absolute_package_folders_stay_refused(
    project: Path, monkeypatch: pytest.MonkeyPatch, entry: str
) -> None:
    monkeypatch.setenv("HOME", str(project.parent))  # ~ is tmp/home/me
    spec = project / "specs" / "arm.yaml"
    spec.write_text(
        "robotspec: 1\nname: Arm\n"
        f"description: {{urdf: ../robots/arm/urdf/arm.urdf, package_paths: ['{entry}']}}\n"
        "root: base_link\n"
    )
    with pytest.raises(SpecError) as info:
        check_spec(spec)
    assert f"package path '{entry}' resolves to" in str(info.value)
    assert "which a spec may not name" in str(info.value)


def test_the_description_root_ends_at_the_folder_above_urdf(project: Path) -> None:
    (project / "robots" / "secret.stl").write_text(STL)
    urdf = project / "robots" / "arm" / "urdf" / "arm.urdf"
    urdf.write_text(arm_urdf("../../secret.stl"))
    spec = project / "specs" / "arm.yaml"
    spec.write_text(
        "robotspec: 1\nname: Arm\n"
        "description: {urdf: ../robots/arm/urdf/arm.urdf}\nroot: base_link\n"
    )
    result = check_spec(spec)
    text = "\n".join(str(w) for w in result.warnings)
    assert "outside the allowed folders" in text and str(project / "robots" / "arm") in text
