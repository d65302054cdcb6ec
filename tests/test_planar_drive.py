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


# ------------------------------------------------------------------- a URDF planar joint as drive
def wheel(name: str, x: float, y: float, *, radius: float = 0.08, axis: str = "0 1 0") -> str:
    """A continuous joint turning a flat cylinder about its own axis (no 'wheel' in its name)."""
    turn = "1.5708 0 0" if axis == "0 1 0" else "0 0 0"
    return f"""
  <link name="{name}_link"><collision><origin rpy="{turn}"/>
    <geometry><cylinder radius="{radius}" length="0.04"/></geometry></collision></link>
  <joint name="{name}" type="continuous"><parent link="base_link"/><child link="{name}_link"/>
    <origin xyz="{x} {y} 0"/><axis xyz="{axis}"/></joint>"""


def planar_urdf(wheels: str = "", above: str = "") -> str:
    """world -(fixed)-> odom -(planar)-> base_link with an arm joint, and the given wheels."""
    return f"""<robot name="omni">
  <link name="world"/><link name="odom"/>
  <link name="base_link">
    <collision><geometry><box size="0.6 0.5 0.2"/></geometry></collision></link>
  <link name="arm"/>
  <joint name="world_odom" type="fixed"><parent link="world"/><child link="odom"/></joint>
  <joint name="base_joint" type="planar"><parent link="odom"/><child link="base_link"/>
    <axis xyz="0 0 1"/></joint>
  <joint name="j1" type="revolute"><parent link="base_link"/><child link="arm"/>
    <origin xyz="0.2 0 0.1"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" velocity="1" effort="1"/></joint>{wheels}{above}
</robot>
"""


FOUR = "".join(
    wheel(n, x, y)
    for n, x, y in [("fl", 0.2, 0.2), ("fr", 0.2, -0.2), ("rl", -0.2, 0.2), ("rr", -0.2, -0.2)]
)


def planar_spec(tmp_path: Path, drive: str) -> Path:
    (tmp_path / "omni.urdf").write_text(planar_urdf(FOUR))
    path = tmp_path / "omni.yaml"
    path.write_text(
        "robotspec: 1\nname: O\ndescription: {urdf: omni.urdf}\nroot: base_link\n"
        f"drive: {drive}\n"
    )
    return path


@pytest.mark.parametrize("drive", ["{type: omni}", "{type: differential, joint: base_joint}"])
def test_a_urdf_planar_joint_is_declared_as_the_drive(tmp_path: Path, drive: str) -> None:
    robot = check_spec(planar_spec(tmp_path, drive)).robot
    assert robot.drive is not None and robot.drive.name == "base_joint"
    assert robot.drive.type is ConnectionType.PLANAR and robot.root.name == "base_link"


def test_a_drive_that_cannot_be_the_planar_joint_is_refused_at_its_keys(tmp_path: Path) -> None:
    with pytest.raises(RobotSpecError) as info:
        check_spec(planar_spec(tmp_path, "{type: floating, joint: base, parent_frame: world}"))
    text = str(info.value).replace(f"{tmp_path}/", "")
    what = "the URDF's planar joint 'base_joint' above the root 'base_link'"
    assert f"omni.yaml:5:15: error: drive.type: {what} is the drive: its type is omni or" in text
    assert f"drive.joint: {what} is the drive; name it 'base_joint' or leave joint out" in text
    assert f"drive.parent_frame: {what} moves it in 'odom'; write 'odom'" in text


def test_a_drive_above_the_planar_joint_says_which_root_to_take(tmp_path: Path) -> None:
    path = planar_spec(tmp_path, "{type: omni}")
    path.write_text(path.read_text().replace("root: base_link", "root: world"))
    with pytest.raises(RobotSpecError, match="make its child 'base_link' the robot's root"):
        check_spec(path)


# ------------------------------------------------------------------------------- drafting it
def drafted(tmp_path: Path, urdf_text: str, srdf: str | None = None):  # type: ignore[no-untyped-def]
    """The draft of a URDF (and SRDF) in tmp_path, written and validated as written."""
    from robotspec.spec.draft import render_draft
    from robotspec.spec.draft.run import draft_from_files

    (tmp_path / "r.urdf").write_text(urdf_text)
    srdf_ref = None
    if srdf is not None:
        (tmp_path / "r.srdf").write_text(srdf)
        srdf_ref = str(tmp_path / "r.srdf")
    draft, _ = draft_from_files(str(tmp_path / "r.urdf"), srdf_ref, folder=tmp_path)
    (tmp_path / "draft.yaml").write_text(render_draft(draft))
    check_spec(tmp_path / "draft.yaml")
    return draft


def test_an_omni_base_of_four_wheels_and_a_planar_joint_is_drafted_as_that_drive(
    tmp_path: Path,
) -> None:
    d = drafted(tmp_path, planar_urdf(FOUR))
    assert d.root == "base_link" and d.drive is not None
    assert (d.drive.type, d.drive.joint, d.drive.joints) == ("omni", "base_joint", None)
    assert d.drive.decide is not None and "4 wheels: omni?" in d.drive.decide


def test_two_wheels_make_the_planar_joint_differential(tmp_path: Path) -> None:
    d = drafted(tmp_path, planar_urdf(wheel("left_drive", 0, 0.2) + wheel("right_drive", 0, -0.2)))
    assert d.drive is not None and d.drive.type == "differential"


def caster(name: str, x: float, y: float) -> str:
    """A swivel (continuous, vertical axis) holding a wheel that rolls about a level axis."""
    rolling = wheel(f"{name}_roll", 0, 0)
    rolling = rolling.replace('parent link="base_link"', f'parent link="{name}"')
    return f"""
  <link name="{name}"/>
  <joint name="{name}_swivel" type="continuous"><parent link="base_link"/><child link="{name}"/>
    <origin xyz="{x} {y} -0.05"/><axis xyz="0 0 1"/></joint>{rolling}"""


def test_casters_beside_two_driven_wheels_keep_the_base_differential(tmp_path: Path) -> None:
    from robotspec.spec.draft.base import wheel_joints

    two = wheel("left_drive", 0, 0.2) + wheel("right_drive", 0, -0.2)
    casters = "".join(caster(n, x, y) for n, x, y in [("cb", -0.2, 0.15), ("cf", 0.2, -0.15)])
    urdf = planar_urdf(two + casters)
    assert [c.name for c in wheel_joints(world_of(urdf))] == ["left_drive", "right_drive"]
    d = drafted(tmp_path, urdf)
    assert d.drive is not None and d.drive.type == "differential"


def test_a_spinning_part_about_a_vertical_axis_is_no_wheel(tmp_path: Path) -> None:
    from robotspec.spec.draft.base import wheel_joints

    rotor = wheel("spinner", 0, 0, axis="0 0 1")
    assert [c.name for c in wheel_joints(world_of(planar_urdf(FOUR + rotor)))] == [
        "fl",
        "fr",
        "rl",
        "rr",
    ]


def renamed(text: str) -> str:
    """The x, y, theta base under other names, below a fixed joint from a 'map' frame."""
    text = text.replace('<link name="odom"/>', '<link name="map"/><link name="odom"/>', 1)
    text = text.replace(
        '<joint name="odom_x"',
        '<joint name="map_odom" type="fixed"><parent link="map"/><child link="odom"/></joint>\n'
        '  <joint name="joint_a"',
        1,
    )
    return text.replace('"odom_y"', '"joint_b"').replace('"odom_theta"', '"joint_c"')


def test_x_y_theta_joints_are_drafted_as_the_drive_by_their_axes_not_names(
    tmp_path: Path,
) -> None:
    d = drafted(tmp_path, renamed(urdf()))
    assert d.root == "base_link" and d.drive is not None
    assert (d.drive.type, d.drive.joints) == ("omni", ("joint_a", "joint_b", "joint_c"))


def test_the_urdf_base_joints_win_over_an_srdf_virtual_joint_above_them(tmp_path: Path) -> None:
    srdf = (
        '<robot name="r"><virtual_joint name="vj" type="floating" parent_frame="world" '
        'child_link="map"/></robot>'
    )
    d = drafted(tmp_path, renamed(urdf()), srdf)
    assert d.root == "base_link" and d.drive is not None
    assert d.drive.joints == ("joint_a", "joint_b", "joint_c")
