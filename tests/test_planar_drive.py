"""A base the URDF models as x, y and theta joints, declared as the drive (LoCoBot, Boxy)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robotspec.compiler import check_spec
from robotspec.description.urdf import world_from_urdf_xml
from robotspec.errors import RobotSpecError
from robotspec.files.xmlsafe import parse_xml_bytes
from robotspec.model.entities import ConnectionType
from robotspec.model.kinematics import Kinematics
from robotspec.model.planar_drive import collapse_planar_joints

LIMIT = '<limit lower="-50" upper="50" velocity="0.7" effort="1"/>'


def urdf(
    *,
    y_axis: str = "0 1 0",
    theta_origin: str = "",
    y_link: str = '<link name="y_link"/>',
    offset: str = '<origin xyz="0.1 0 0.05" rpy="0 0 0.3"/>',
) -> str:
    return f"""<robot name="r">
  <link name="odom"/><link name="x_link"/>{y_link}
  <link name="base_link">
    <collision><geometry><box size="0.5 0.5 0.2"/></geometry></collision>
  </link>
  <link name="arm"/>
  <joint name="odom_x" type="prismatic"><parent link="odom"/><child link="x_link"/>{offset}
    <axis xyz="1 0 0"/>{LIMIT}</joint>
  <joint name="odom_y" type="prismatic"><parent link="x_link"/><child link="y_link"/>
    <axis xyz="{y_axis}"/>{LIMIT}</joint>
  <joint name="odom_theta" type="continuous"><parent link="y_link"/><child link="base_link"/>
    {theta_origin}<axis xyz="0 0 1"/><limit velocity="1.5" effort="1"/></joint>
  <joint name="j1" type="revolute"><parent link="base_link"/><child link="arm"/>
    <origin xyz="0.2 0 0.1"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" velocity="1" effort="1"/>
  </joint>
</robot>
"""


def world_of(text: str):  # type: ignore[no-untyped-def]
    return world_from_urdf_xml(parse_xml_bytes(text.encode(), "r.urdf"), "r.urdf")


JOINTS = ("odom_x", "odom_y", "odom_theta")


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(-3, 3), min_size=4, max_size=4))
def test_the_planar_connection_moves_every_body_as_the_three_joints_did(
    values: list[float],
) -> None:
    before = world_of(urdf())
    after = collapse_planar_joints(before, JOINTS)
    q0 = before.configuration(dict(zip([*JOINTS, "j1"], values, strict=True)))
    drive = after.get_connection_by_name("odom_T_base_link")
    names = [after.degrees_of_freedom[d].name for d in drive.dofs]
    q1 = after.configuration(dict(zip([*names, "j1"], values, strict=True)))
    p0, p1 = Kinematics(before).forward(q0), Kinematics(after).forward(q1)
    for body in after.bodies:
        np.testing.assert_allclose(
            p1[body.index], p0[before.get_body_by_name(body.name).index], atol=1e-12
        )


def test_limits_are_kept_and_the_links_between_dropped() -> None:
    after = collapse_planar_joints(world_of(urdf()), JOINTS, "base_drive")
    drive = after.get_connection_by_name("base_drive")
    assert drive.type is ConnectionType.PLANAR
    dofs = [after.degrees_of_freedom[d] for d in drive.dofs]
    assert [d.name for d in dofs] == ["base_drive/x", "base_drive/y", "base_drive/theta"]
    assert [(d.lower, d.upper, d.velocity) for d in dofs[:2]] == [(-50, 50, 0.7)] * 2
    assert dofs[2].velocity == 1.5 and not np.isfinite(dofs[2].upper)
    assert [b.name for b in after.bodies] == ["odom", "base_link", "arm"]


@pytest.mark.parametrize(
    ("text", "joints", "message"),
    [
        (urdf(), ("odom_y", "odom_x", "odom_theta"), "drive joint 'odom_y' (x) must move along"),
        (urdf(y_axis="0 -1 0"), JOINTS, "drive joint 'odom_y' (y) must move along [0.0, 1.0, 0.0]"),
        (
            urdf(theta_origin='<origin xyz="0.1 0 0"/>'),
            JOINTS,
            "drive joint 'odom_theta' must sit at its parent's origin",
        ),
        (
            urdf(
                y_link='<link name="y_link"><collision><geometry><sphere radius="1"/>'
                "</geometry></collision></link>"
            ),
            JOINTS,
            "link 'y_link' between the drive joints has collision geometry",
        ),
        (urdf(), ("odom_x", "odom_theta", "j1"), "drive joint 'odom_theta' (y) must be prismatic"),
    ],
)
def test_joints_that_are_not_a_planar_base_are_refused(
    text: str, joints: tuple[str, str, str], message: str
) -> None:
    with pytest.raises(
        RobotSpecError, match=message.replace("(", r"\(").replace(")", r"\)").replace("[", r"\[")
    ):
        collapse_planar_joints(world_of(text), joints)


def spec(tmp_path: Path, drive: str, root: str = "base_link") -> Path:
    (tmp_path / "r.urdf").write_text(urdf())
    path = tmp_path / "r.yaml"
    path.write_text(
        f"robotspec: 1\nname: R\ndescription: {{urdf: r.urdf}}\nroot: {root}\ndrive: {drive}\n"
    )
    return path


def test_a_spec_declares_the_urdf_joints_as_its_drive(tmp_path: Path) -> None:
    robot = check_spec(spec(tmp_path, "{type: omni, joints: [odom_x, odom_y, odom_theta]}")).robot
    assert robot.drive is not None and robot.drive.name == "odom_T_base_link"
    assert robot.root.name == "base_link"


@pytest.mark.parametrize(
    ("drive", "root", "message"),
    [
        (
            "{type: omni, joints: [odom_x, odom_y, odom_thet]}",
            "base_link",
            "r.yaml:5:46: error: joint 'odom_thet' not found in r.urdf; did you mean 'odom_theta'",
        ),
        (
            "{type: floating, joints: [odom_x, odom_y, odom_theta]}",
            "base_link",
            "r.yaml:5:15: error: drive.type: a drive of URDF joints is planar",
        ),
        (
            "{type: omni, joints: [odom_x, odom_y, odom_theta]}",
            "arm",
            "r.yaml:4:7: error: root: the drive's theta joint 'odom_theta' moves 'base_link'",
        ),
        (
            "{type: omni}",
            "odom",
            "r.yaml:5:8: error: drive.parent_frame: virtual joint parent frame 'odom' is already "
            "a link of the robot; if the URDF models the base's motion itself",
        ),
    ],
)
def test_drive_errors_are_located_in_the_spec(
    tmp_path: Path, drive: str, root: str, message: str
) -> None:
    with pytest.raises(RobotSpecError) as info:
        check_spec(spec(tmp_path, drive, root))
    assert str(info.value).replace(f"{tmp_path}/", "").startswith(message)
