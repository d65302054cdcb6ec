"""``export bundle`` writes a bundle that validates and finds its meshes wherever it is copied.

Meshes the description names by a path of the user's machine (``../meshes/base.stl``) travel
with the bundle, named relative to it; ``package://`` meshes stay (their package is how every
tool finds them); a mesh outside the allowed folders is never carried along.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from robotspec.cli.app import app
from robotspec.cli.output import run_app

STL = "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 0.1 0 0\nvertex 0 0.1 0\n"
STL += "endloop\nendfacet\nendsolid t\n"


def cli(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str]:
    code = run_app(app, list(argv))
    out = capsys.readouterr()
    return code, out.out + out.err


def project(tmp_path: Path, secret_mesh: str | None = None) -> Path:
    arm = tmp_path / "proj" / "robots" / "arm"
    (arm / "urdf").mkdir(parents=True)
    (arm / "meshes" / "sub").mkdir(parents=True)
    (arm / "meshes" / "base.stl").write_text(STL)
    (arm / "meshes" / "sub" / "base.stl").write_text(STL)  # same name, other file
    link2 = secret_mesh or "../meshes/sub/base.stl"
    (arm / "urdf" / "arm.urdf").write_text(
        '<robot name="arm">\n'
        '<link name="a"><collision><geometry><mesh filename="../meshes/base.stl"/>'
        "</geometry></collision></link>\n"
        '<link name="b"><visual><geometry><mesh filename="../meshes/base.stl"/></geometry>'
        f'</visual><collision><geometry><mesh filename="{link2}"/></geometry></collision>'
        "</link>\n"
        '<joint name="j" type="revolute"><parent link="a"/><child link="b"/>'
        '<origin xyz="0 0 0.5"/><axis xyz="0 1 0"/>'
        '<limit lower="-1" upper="1" velocity="1" effort="1"/></joint>\n</robot>\n'
    )
    spec = tmp_path / "proj" / "arm.yaml"
    spec.write_text(
        "robotspec: 1\nname: Arm\ndescription: {urdf: robots/arm/urdf/arm.urdf}\nroot: a\n"
    )
    return spec


def test_the_bundle_works_where_it_is_copied(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    spec = project(tmp_path)
    out = tmp_path / "out"
    code, text = cli(capsys, "export", "bundle", str(spec), "-o", str(out))
    assert code == 0, text
    assert "and 2 mesh files in arm_meshes/" in text
    urdf = (out / "arm.urdf").read_text()
    assert 'filename="arm_meshes/base.stl"' in urdf
    assert 'filename="arm_meshes/base_2.stl"' in urdf
    assert str(tmp_path) not in urdf
    moved = tmp_path / "elsewhere" / "bundle"
    shutil.copytree(out, moved)
    shutil.rmtree(tmp_path / "proj")  # the sources are gone
    code, text = cli(capsys, "validate", str(moved / "arm.yaml"))
    assert code == 0 and "0 warnings" in text, text
    code, text = cli(capsys, "collisions", "check", str(moved / "arm.yaml"))
    assert code == 0, text
    # A second export into the same folder keeps what is there unless --force.
    spec = project(tmp_path)
    code, text = cli(capsys, "export", "bundle", str(spec), "-o", str(out))
    assert code == 1 and "pass --force" in text
    code, text = cli(capsys, "export", "bundle", str(spec), "-o", str(out), "--force")
    assert code == 0, text


def test_a_mesh_outside_the_allowed_folders_is_not_carried(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    secret = tmp_path / "secret.stl"
    secret.write_text(STL.replace("solid t", "solid SECRET"))
    spec = project(tmp_path, secret_mesh=str(secret))
    out = tmp_path / "out"
    code, text = cli(capsys, "export", "bundle", str(spec), "-o", str(out))
    assert code == 0, text
    assert "and 1 mesh file in arm_meshes/" in text
    carried = b"".join(p.read_bytes() for p in (out / "arm_meshes").iterdir())
    assert b"SECRET" not in carried
