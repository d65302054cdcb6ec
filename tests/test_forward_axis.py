"""A robot modelled facing -y (ARMAR-4, Stretch) says so: its left, its front view follow."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from robotspec.compiler import check_spec
from robotspec.errors import RobotSpecError
from robotspec.render.raster import view_axes

ARM = """  <link name="{s}_link"/><link name="{s}_hand"/>
  <joint name="{s}_j" type="revolute"><parent link="base"/><child link="{s}_link"/>
    <origin xyz="{x} 0 0.5"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" velocity="1" effort="1"/></joint>
  <joint name="{s}_fix" type="fixed"><parent link="{s}_link"/><child link="{s}_hand"/>
    <origin xyz="0 -0.3 0"/></joint>
"""


def spec(tmp_path: Path, forward: str) -> Path:
    # Facing -y: the arm at +x is the robot's left one (named 'b' so names do not tell).
    arms = ARM.format(s="a", x=-0.2) + ARM.format(s="b", x=0.2)
    (tmp_path / "r.urdf").write_text(f'<robot name="r"><link name="base"/>\n{arms}</robot>\n')
    path = tmp_path / "r.yaml"
    path.write_text(
        "robotspec: 1\nname: R\ndescription: {urdf: r.urdf}\nroot: base\n"
        f"{forward}"
        "chains:\n"
        "  one: {root: base, tip: a_link, manipulator: ha}\n"
        "  two: {root: base, tip: b_link, manipulator: hb}\n"
        "manipulators:\n"
        "  ha: {type: generic, root: a_link, tool_frame: a_hand}\n"
        "  hb: {type: generic, root: b_link, tool_frame: b_hand}\n"
    )
    return path


def test_the_left_arm_is_on_the_robot_s_left_whichever_way_it_faces(tmp_path: Path) -> None:
    default = check_spec(spec(tmp_path, "")).robot
    with pytest.raises(RobotSpecError, match="lie side by side on the forward axis"):
        default.left_arm  # noqa: B018 - facing +x, the arms are one behind the other
    facing = check_spec(spec(tmp_path, "forward: [0, -1, 0]\n")).robot
    assert facing.forward_axis == (0.0, -1.0, 0.0)
    assert facing.left_axis == (1.0, 0.0, 0.0)
    assert facing.left_arm.name == "two" and facing.right_arm.name == "one"


@pytest.mark.parametrize(
    ("forward", "message"),
    [
        ("[0, -2, 0]", "forward: must be a unit vector, its length is 2"),
        ("[0, 0, 1]", "forward: must be horizontal (z = 0) in the root's frame"),
    ],
)
def test_a_forward_axis_that_is_no_direction_on_the_ground_is_refused(
    tmp_path: Path, forward: str, message: str
) -> None:
    with pytest.raises(RobotSpecError) as info:
        check_spec(spec(tmp_path, f"forward: {forward}\n"))
    assert f"r.yaml:5:10: error: {message}" in str(info.value)


def test_the_front_view_looks_at_the_robot_s_face() -> None:
    np.testing.assert_allclose(view_axes("front")[2], (-1.0, 0.0, 0.0))
    # Facing -y: the camera stands at -y and looks along +y, the robot's left (+x) on the
    # image's right as in the default front view.
    axes = view_axes("front", (0.0, -1.0, 0.0))
    np.testing.assert_allclose(axes[2], (0.0, 1.0, 0.0), atol=1e-12)
    np.testing.assert_allclose(axes[0], (1.0, 0.0, 0.0), atol=1e-12)
    np.testing.assert_allclose(view_axes("front")[0], (0.0, 1.0, 0.0), atol=1e-12)
