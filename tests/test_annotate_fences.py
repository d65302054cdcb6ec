"""``annotate mjcf`` never lets a user's MJCF make MuJoCo read outside the model's fence.

A downloaded model may name any file as a mesh, texture or include; MuJoCo would open it.
The check runs before MuJoCo sees the model, on real paths (a planted link counts where it
points).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from robotspec.errors import RobotSpecError
from robotspec.interop.mujoco_files import check_model_files

BODY = '<worldbody><body name="b"><geom type="sphere" size="0.1"/></body></worldbody>'


def _model(folder: Path, assets: str, compiler: str = "") -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / "robot.xml"
    path.write_text(f"<mujoco>{compiler}<asset>{assets}</asset>{BODY}</mujoco>")
    return path


def test_a_mesh_outside_the_model_folder_is_refused(tmp_path: Path) -> None:
    (tmp_path / "secret").mkdir()
    (tmp_path / "secret" / "key.stl").write_bytes(b"x" * 84)
    path = _model(tmp_path / "download", '<mesh name="m" file="../secret/key.stl"/>')
    with pytest.raises(RobotSpecError, match=r"mesh file='../secret/key.stl'.*outside"):
        check_model_files(path)


def test_a_meshdir_pointing_away_is_refused(tmp_path: Path) -> None:
    path = _model(
        tmp_path / "download", '<mesh name="m" file="a.stl"/>', '<compiler meshdir="/etc"/>'
    )
    with pytest.raises(RobotSpecError, match="system folder /etc"):
        check_model_files(path)


def test_a_planted_link_in_the_asset_folder_is_judged_where_it_points(tmp_path: Path) -> None:
    (tmp_path / "elsewhere").mkdir()
    folder = tmp_path / "download"
    path = _model(folder, '<mesh name="m" file="assets/m.stl"/>')
    (folder / "assets").symlink_to(tmp_path / "elsewhere")
    with pytest.raises(RobotSpecError, match="outside"):
        check_model_files(path)


def test_an_included_file_is_checked_too(tmp_path: Path) -> None:
    folder = tmp_path / "download"
    path = _model(folder, "")
    path.write_text(f'<mujoco><include file="parts.xml"/>{BODY}</mujoco>')
    (folder / "parts.xml").write_text(
        '<mujoco><asset><texture name="t" file="../../x.png"/></asset></mujoco>'
    )
    with pytest.raises(RobotSpecError, match="texture file='../../x.png'"):
        check_model_files(path)


def test_files_inside_the_model_folder_pass(tmp_path: Path) -> None:
    folder = tmp_path / "download"
    path = _model(folder, '<mesh name="m" file="m.stl"/>', '<compiler meshdir="assets"/>')
    check_model_files(path)
